//! A piston wave maker's settings: a vertical plate of boundary particles across the tank at its −x end, driven along x
//! by X(t) = (S/2) sin(2πt/T), started with a half-cosine ramp. The liquid fills the tank in front of it; the
//! space behind it stays dry. Linear wave-maker theory (Biesel) gives the waves it makes: H/S =
//! 2 (cosh 2kh − 1) / (sinh 2kh + 2kh).

use super::ParamError;
use serde::{Deserialize, Serialize};

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PistonSpec {
    /// Full stroke S (twice the amplitude), m.
    pub stroke: f64,
    /// s.
    pub period: f64,
    /// Half-cosine start over this long, s.
    #[serde(default)]
    pub ramp_time: f64,
    /// Plate thickness, m (0: as many layers as the tank's walls).
    #[serde(default)]
    pub thickness: f64,
}

impl PistonSpec {
    /// Checks the settings against the tank's length, the plate's actual thickness and the spacing.
    pub fn validate(&self, tank_length: f64, thickness: f64, dp: f64) -> Result<(), ParamError> {
        let bad = |field: &str, message: String| ParamError {
            field: format!("wave_maker.{field}"),
            message,
        };
        if !(self.stroke.is_finite() && self.stroke >= 0.0) {
            return Err(bad(
                "stroke",
                format!("must be zero or positive, got {}", self.stroke),
            ));
        }
        if !(self.period.is_finite() && self.period > 0.0) {
            return Err(bad(
                "period",
                format!("must be positive, got {}", self.period),
            ));
        }
        if !(self.ramp_time.is_finite() && self.ramp_time >= 0.0) {
            return Err(bad(
                "ramp_time",
                format!("must be zero or positive, got {}", self.ramp_time),
            ));
        }
        if !(self.thickness.is_finite() && self.thickness >= 0.0) {
            return Err(bad(
                "thickness",
                format!("must be zero or positive, got {}", self.thickness),
            ));
        }
        if self.thickness > 0.0 && self.thickness < 2.0 * dp {
            return Err(bad("thickness", format!("{} m is thinner than two particle spacings: the liquid would leak through (0: as thick as the tank's walls)", self.thickness)));
        }
        if self.stroke + thickness + 4.0 * dp > 0.5 * tank_length {
            return Err(bad(
                "stroke",
                format!(
                    "{} m leaves too little of the {tank_length} m tank in front of the plate",
                    self.stroke
                ),
            ));
        }
        Ok(())
    }

    /// The plate's displacement from its rest position and its velocity at time t.
    pub fn displacement(&self, t: f64) -> (f64, f64) {
        let w = 2.0 * std::f64::consts::PI / self.period;
        let a = 0.5 * self.stroke;
        let (r, dr) = if t < self.ramp_time {
            let p = std::f64::consts::PI / self.ramp_time;
            (0.5 * (1.0 - (p * t).cos()), 0.5 * p * (p * t).sin())
        } else {
            (1.0, 0.0)
        };
        (
            a * (w * t).sin() * r,
            a * (w * (w * t).cos() * r + (w * t).sin() * dr),
        )
    }

    /// Where the plate's front face rests (x, tank frame): far enough from the −x wall for the plate to retract
    /// half a stroke with a spacing to spare.
    pub fn rest_face(&self, tank_lo_x: f64, thickness: f64, dp: f64) -> f64 {
        tank_lo_x + thickness + 0.5 * self.stroke + dp
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_plate_moves_smoothly_from_rest() {
        let s = PistonSpec {
            stroke: 0.04,
            period: 1.0,
            ramp_time: 2.0,
            thickness: 0.0,
        };
        assert_eq!(s.displacement(0.0), (0.0, 0.0));
        // The velocity is the derivative of the displacement, in the ramp and after it.
        for t in [0.3, 1.7, 2.5] {
            let e = 1e-6;
            let num = (s.displacement(t + e).0 - s.displacement(t - e).0) / (2.0 * e);
            assert!((num - s.displacement(t).1).abs() < 1e-6, "t {t}");
        }
        let (x, _) = s.displacement(2.25);
        assert!((x - 0.02).abs() < 1e-12, "full amplitude after the ramp");
    }
}
