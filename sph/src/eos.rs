//! Tait equation of state, the paper's eq. (7): p = B [(ρ/ρ0)^γ − 1] with γ = 7 and B = c0² ρ0 / γ.

#[derive(Clone, Copy, Debug)]
pub struct Tait {
    pub rho0: f32,
    pub b: f32,
    pub c0: f32,
}

impl Tait {
    pub const GAMMA: f32 = 7.0;

    pub fn new(rho0: f64, c0: f64) -> Self {
        Self {
            rho0: rho0 as f32,
            b: (c0 * c0 * rho0 / 7.0) as f32,
            c0: c0 as f32,
        }
    }

    #[inline(always)]
    pub fn pressure(&self, rho: f32) -> f32 {
        let x = rho / self.rho0;
        let x2 = x * x;
        let x3 = x2 * x;
        self.b * (x3 * x3 * x - 1.0)
    }

    /// Inverse of [`Tait::pressure`] (in f64 for initial conditions).
    pub fn density(&self, p: f64) -> f64 {
        let b = self.b as f64;
        self.rho0 as f64 * (1.0 + p / b).max(1e-6).powf(1.0 / 7.0)
    }

    /// Local speed of sound c = c0 (ρ/ρ0)^3.
    #[inline]
    pub fn sound_speed(&self, rho: f32) -> f32 {
        let x = rho / self.rho0;
        self.c0 * x * x * x
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tait_round_trip_and_bulk_modulus() {
        let e = Tait::new(1000.0, 20.0);
        assert_eq!(e.pressure(1000.0), 0.0);
        let p = 3924.0;
        let rho = e.density(p);
        assert!(((e.pressure(rho as f32) as f64) - p).abs() < 1.0);
        // dp/dρ at ρ0 equals c0².
        let d = 0.01f32;
        let slope = (e.pressure(1000.0 + d) - e.pressure(1000.0 - d)) / (2.0 * d);
        assert!((slope - 400.0).abs() < 2.0, "{slope}");
    }
}
