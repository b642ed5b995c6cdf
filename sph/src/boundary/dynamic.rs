//! Dynamic boundary particles (the paper's quasi-ghost particles; Dalrymple & Knio 2000, Crespo et al. 2007):
//! layers of particles fixed to the tank whose density evolves by the continuity equation and whose pressure
//! follows the equation of state, clamped at ρ0 so walls never pull the liquid.

use crate::eos::Tait;
use crate::particles::Boundary;

/// Wall particles at `points` with their initial density.
pub fn build<const D: usize>(
    points: &[[f64; D]],
    density: impl Fn([f64; D]) -> f64,
    eos: &Tait,
) -> Boundary<D> {
    let mut b = Boundary::default();
    for p in points {
        let rho = density(*p).max(eos.rho0 as f64);
        b.push(*p, [0.0; D], rho, eos.pressure(rho as f32));
    }
    b
}

/// Refreshes the f32 density and pressure from the integrated density.
pub fn refresh<const D: usize>(b: &mut Boundary<D>, eos: &Tait) {
    for i in 0..b.len() {
        let r = b.rho[i] as f32;
        b.r[i] = r;
        b.p[i] = eos.pressure(r);
        b.pr2[i] = b.p[i] / (r * r);
    }
}

/// Keeps wall densities at or above ρ0 after an update.
pub fn clamp<const D: usize>(b: &mut Boundary<D>, rho0: f64) {
    for r in &mut b.rho {
        if *r < rho0 {
            *r = rho0;
        }
    }
}
