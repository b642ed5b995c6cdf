//! Regular motion: a sinusoid per degree of freedom, q = r(t) A sin(2π t / T + φ), started by a smooth ramp.

use super::{ramp, Dof6, Dof6Motion};
use serde::{Deserialize, Serialize};

#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct RegularDof {
    /// m or rad.
    pub amplitude: f64,
    /// s.
    pub period: f64,
    /// rad.
    pub phase: f64,
}

#[derive(Clone, Debug, PartialEq)]
pub struct RegularMotion {
    /// x, y, z, roll, pitch, yaw.
    pub dofs: [RegularDof; 6],
    /// Duration of the half-cosine ramp of the amplitudes, s (0: none).
    pub ramp: f64,
}

impl Dof6Motion for RegularMotion {
    fn dof(&self, t: f64) -> Dof6 {
        let (r, dr, ddr) = ramp(t, self.ramp);
        let mut d = Dof6::default();
        for (i, dof) in self.dofs.iter().enumerate() {
            if dof.amplitude == 0.0 || dof.period <= 0.0 {
                continue;
            }
            let w = 2.0 * std::f64::consts::PI / dof.period;
            let (s, c) = (w * t + dof.phase).sin_cos();
            let a = dof.amplitude;
            d.q[i] = r * a * s;
            d.dq[i] = dr * a * s + r * a * w * c;
            d.ddq[i] = ddr * a * s + 2.0 * dr * a * w * c - r * a * w * w * s;
        }
        d
    }
}
