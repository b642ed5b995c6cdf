//! Time integration of the liquid (and the wall particles' density), in the form DualSPHysics uses.
//!
//! Symplectic (two force evaluations a step, second order):
//!   predictor  x½ = xⁿ + dt/2 vⁿ,  v½ = vⁿ + dt/2 aⁿ,  ρ½ = ρⁿ + dt/2 Dρⁿ
//!   corrector  vⁿ⁺¹ = vⁿ + dt a½,  xⁿ⁺¹ = xⁿ + dt (vⁿ + vⁿ⁺¹)/2,  ρⁿ⁺¹ = ρⁿ (2 − ε)/(2 + ε), ε = −dt Dρ½/ρ½
//! Verlet (one force evaluation a step): vⁿ⁺¹ = vⁿ⁻¹ + 2 dt aⁿ, ρⁿ⁺¹ = ρⁿ⁻¹ + 2 dt Dρⁿ,
//!   xⁿ⁺¹ = xⁿ + dt vⁿ + dt²/2 aⁿ, with an Euler step (vⁿ⁺¹ = vⁿ + dt aⁿ) every `verlet_reset_steps`.

use crate::particles::{Boundary, Fluid};

/// Saves the state at the start of a symplectic step and advances it half a step.
pub fn symplectic_predict<const D: usize>(
    f: &mut Fluid<D>,
    walls: Option<&mut Boundary<D>>,
    dt: f64,
) {
    let h = 0.5 * dt;
    for d in 0..D {
        f.pos0[d].copy_from_slice(&f.pos[d]);
        f.vel0[d].copy_from_slice(&f.vel[d]);
        for i in 0..f.len() {
            f.pos[d][i] += h * f.vel[d][i];
            f.vel[d][i] += h * f.acc[i][d] as f64;
        }
    }
    f.rho0.copy_from_slice(&f.rho);
    for i in 0..f.len() {
        f.rho[i] += h * f.drho[i] as f64;
    }
    if let Some(b) = walls {
        b.rho0.copy_from_slice(&b.rho);
        for i in 0..b.len() {
            b.rho[i] += h * b.drho[i] as f64;
        }
    }
}

/// Completes a symplectic step from the rates at the half step.
pub fn symplectic_correct<const D: usize>(
    f: &mut Fluid<D>,
    walls: Option<&mut Boundary<D>>,
    dt: f64,
) {
    for d in 0..D {
        for i in 0..f.len() {
            let v0 = f.vel0[d][i];
            let v1 = v0 + dt * f.acc[i][d] as f64;
            f.vel[d][i] = v1;
            f.pos[d][i] = f.pos0[d][i] + 0.5 * dt * (v0 + v1);
        }
    }
    let density = |rho0: f64, rho_half: f64, drho: f32| {
        let eps = -(drho as f64) / rho_half * dt;
        rho0 * (2.0 - eps) / (2.0 + eps)
    };
    for i in 0..f.len() {
        f.rho[i] = density(f.rho0[i], f.rho[i], f.drho[i]);
    }
    if let Some(b) = walls {
        for i in 0..b.len() {
            b.rho[i] = density(b.rho0[i], b.rho[i], b.drho[i]);
        }
    }
}

/// One Verlet step; `euler` selects the first-order restart step.
pub fn verlet<const D: usize>(
    f: &mut Fluid<D>,
    walls: Option<&mut Boundary<D>>,
    dt: f64,
    euler: bool,
) {
    let (w_prev, w_now, gain) = if euler {
        (0.0, 1.0, dt)
    } else {
        (1.0, 0.0, 2.0 * dt)
    };
    for d in 0..D {
        for i in 0..f.len() {
            let v = f.vel[d][i];
            let a = f.acc[i][d] as f64;
            f.pos[d][i] += dt * v + 0.5 * dt * dt * a;
            let vn = w_prev * f.vel0[d][i] + w_now * v + gain * a;
            f.vel0[d][i] = v;
            f.vel[d][i] = vn;
        }
    }
    for i in 0..f.len() {
        let r = f.rho[i];
        f.rho[i] = w_prev * f.rho0[i] + w_now * r + gain * f.drho[i] as f64;
        f.rho0[i] = r;
    }
    if let Some(b) = walls {
        for i in 0..b.len() {
            let r = b.rho[i];
            b.rho[i] = w_prev * b.rho0[i] + w_now * r + gain * b.drho[i] as f64;
            b.rho0[i] = r;
        }
    }
}
