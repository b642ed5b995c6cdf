//! Irregular motion: per degree of freedom a sum of sines whose amplitudes follow a JONSWAP spectrum,
//! with random phases from a seeded generator, so a run is reproducible.

use super::{ramp, Dof6, Dof6Motion};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct JonswapDof {
    /// Significant amplitude 2·sqrt(m0), m or rad (half the "significant height" 4·sqrt(m0)); 0: still.
    pub significant_amplitude: f64,
    /// Peak period Tp, s.
    pub peak_period: f64,
}

#[derive(Clone, Debug)]
pub struct IrregularMotion {
    /// Per DOF: (amplitude, angular frequency, phase) of each component.
    components: [Vec<(f64, f64, f64)>; 6],
    ramp: f64,
}

/// SplitMix64: a small, well-mixed generator; enough for phases and frequency jitter.
struct SplitMix(u64);

impl SplitMix {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// Unnormalised JONSWAP spectral shape at ω for peak frequency ωp and peak enhancement γ.
fn jonswap_shape(w: f64, wp: f64, gamma: f64) -> f64 {
    let sigma = if w <= wp { 0.07 } else { 0.09 };
    let r = (-(w - wp).powi(2) / (2.0 * sigma * sigma * wp * wp)).exp();
    w.powi(-5) * (-1.25 * (wp / w).powi(4)).exp() * gamma.powf(r)
}

impl IrregularMotion {
    /// `components` sines per DOF between 0.5 ωp and 3 ωp, peak enhancement `gamma` (3.3 is typical).
    pub fn new(
        dofs: &[JonswapDof; 6],
        gamma: f64,
        components: usize,
        seed: u64,
        ramp: f64,
    ) -> Self {
        let mut out: [Vec<(f64, f64, f64)>; 6] = Default::default();
        for (i, dof) in dofs.iter().enumerate() {
            if dof.significant_amplitude == 0.0 || dof.peak_period <= 0.0 || components == 0 {
                continue;
            }
            let mut rng = SplitMix(seed ^ (0xA076_1D64_78BD_642F_u64.wrapping_mul(i as u64 + 1)));
            let wp = 2.0 * PI / dof.peak_period;
            let (w0, w1) = (0.5 * wp, 3.0 * wp);
            let dw = (w1 - w0) / components as f64;
            let mut comps: Vec<(f64, f64, f64)> = (0..components)
                .map(|k| {
                    // Jitter each frequency inside its bin so the record does not repeat.
                    let w = w0 + (k as f64 + rng.next_f64()) * dw;
                    let a = (2.0 * jonswap_shape(w, wp, gamma) * dw).sqrt();
                    (a, w, 2.0 * PI * rng.next_f64())
                })
                .collect();
            // Scale so that m0 = Σ a²/2 gives the requested significant amplitude 2 sqrt(m0).
            let m0: f64 = comps.iter().map(|c| 0.5 * c.0 * c.0).sum();
            let scale = 0.5 * dof.significant_amplitude / m0.sqrt();
            for c in &mut comps {
                c.0 *= scale;
            }
            out[i] = comps;
        }
        Self {
            components: out,
            ramp,
        }
    }
}

impl Dof6Motion for IrregularMotion {
    fn dof(&self, t: f64) -> Dof6 {
        let (r, dr, ddr) = ramp(t, self.ramp);
        let mut d = Dof6::default();
        for (i, comps) in self.components.iter().enumerate() {
            let (mut q, mut dq, mut ddq) = (0.0, 0.0, 0.0);
            for &(a, w, p) in comps {
                let (s, c) = (w * t + p).sin_cos();
                q += a * s;
                dq += a * w * c;
                ddq -= a * w * w * s;
            }
            d.q[i] = r * q;
            d.dq[i] = dr * q + r * dq;
            d.ddq[i] = ddr * q + 2.0 * dr * dq + r * ddq;
        }
        d
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn irregular_motion_is_reproducible_and_has_the_requested_statistics() {
        let mut dofs = [JonswapDof::default(); 6];
        dofs[3] = JonswapDof {
            significant_amplitude: 0.1,
            peak_period: 2.0,
        };
        let a = IrregularMotion::new(&dofs, 3.3, 200, 7, 0.0);
        let b = IrregularMotion::new(&dofs, 3.3, 200, 7, 0.0);
        let c = IrregularMotion::new(&dofs, 3.3, 200, 8, 0.0);
        assert_eq!(a.dof(12.3).q, b.dof(12.3).q);
        assert_ne!(a.dof(12.3).q[3], c.dof(12.3).q[3]);
        // Standard deviation over a long record ≈ sqrt(m0) = 0.05.
        let n = 200_000;
        let dt = 0.01;
        let var: f64 = (0..n)
            .map(|k| a.dof(k as f64 * dt).q[3].powi(2))
            .sum::<f64>()
            / n as f64;
        assert!((var.sqrt() - 0.05).abs() < 0.005, "std {}", var.sqrt());
        assert_eq!(a.dof(3.0).q[0], 0.0);
        // Derivatives consistent.
        let e = 1e-5;
        let t = 4.2;
        let fd = (a.dof(t + e).q[3] - a.dof(t - e).q[3]) / (2.0 * e);
        assert!((fd - a.dof(t).dq[3]).abs() < 1e-6);
    }
}
