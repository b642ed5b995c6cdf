//! The liquid's force on each particle of a floating body: the reaction of the pressure and viscous terms the
//! body's particles put on the liquid in [`crate::scheme::wcsph`], pair by pair, so the liquid and the bodies
//! exchange equal and opposite forces.

use super::wcsph::Coefficients;
use crate::kernel::Kernel;
use crate::neighbours::{Grid, NO_RANGES};
use crate::particles::{Boundary, Fluid, HALO};
use crate::vector::to3;
use rayon::prelude::*;

/// Calls `pair(j, dx, vd, r2)` for every liquid particle j of this rank (halo copies, MPI, are left out:
/// each rank adds its own liquid's part) within the support of boundary particle b, with dx = x_j − x_b,
/// vd = v_j − v_b and r2 = |dx|².
fn each_liquid_neighbour<const D: usize>(
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    bound: &Boundary<D>,
    b: usize,
    support2: f32,
    mut pair: impl FnMut(usize, [f32; D], [f32; D], f32),
) {
    let xb: [f32; D] = std::array::from_fn(|d| bound.x[d][b]);
    let vb: [f32; D] = std::array::from_fn(|d| bound.v[d][b]);
    let mut ranges = NO_RANGES;
    let n = grid.ranges(bound.cell[b], &fluid.starts, &mut ranges);
    for &(lo, hi) in &ranges[..n] {
        for j in lo as usize..hi as usize {
            if fluid.id[j] & HALO != 0 {
                continue;
            }
            let dx: [f32; D] = std::array::from_fn(|d| fluid.x32[d][j] - xb[d]);
            let vd: [f32; D] = std::array::from_fn(|d| fluid.v32[d][j] - vb[d]);
            let r2: f32 = (0..D).map(|d| dx[d] * dx[d]).sum();
            if r2 < support2 {
                pair(j, dx, vd, r2);
            }
        }
    }
}

/// Force of the liquid on the boundary particles at `slots` (x, y, z; per unit breadth in 2D), into `out`.
pub fn liquid_forces<const D: usize, K: Kernel>(
    k: &K,
    c: &Coefficients,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    bound: &Boundary<D>,
    slots: &[u32],
    out: &mut Vec<[f64; 3]>,
) {
    slots
        .par_iter()
        .map(|&b| {
            let b = b as usize;
            let (rb, pb_r2) = (bound.r[b], bound.pr2[b]);
            let mut force = [0.0f64; D];
            each_liquid_neighbour(grid, fluid, bound, b, c.support2, |j, dx, vd, r2| {
                let vr: f32 = (0..D).map(|d| vd[d] * dx[d]).sum();
                let f = k.grad_factor(r2.sqrt());
                let ra = fluid.rho32[j];
                let inv_r2e = 1.0 / (r2 + c.eta2);
                let mu = c.h * vr.min(0.0) * inv_r2e;
                let s = fluid.pr2[j]
                    + pb_r2
                    + (-c.alpha_bound * c.c0 * mu + c.beta_bound * mu * mu) * 2.0 / (ra + rb);
                let lam = if c.nu4 > 0.0 {
                    c.m_bound * c.nu4 * f * r2 * inv_r2e / (ra + rb)
                } else {
                    0.0
                };
                // The acceleration the body particle gives liquid particle j, and its reaction.
                for d in 0..D {
                    let pair = -c.m_bound * s * f * dx[d] + lam * vd[d];
                    force[d] -= (c.m_fluid * pair) as f64;
                }
            });
            to3(force)
        })
        .collect_into_vec(out);
}

/// Force of the liquid on the boundary particles at `slots` over a divergence-free step (see
/// [`crate::scheme::dfsph`]): the reaction of the walls' push-back with each liquid particle's total k
/// (`k(a)`, the step's density and divergence solves), `MIRROR · m_b k_a ∇W_ab`, and of the artificial
/// viscosity's wall term, from the positions and velocities the step was solved at.
#[allow(clippy::too_many_arguments)]
pub fn liquid_forces_dfsph<const D: usize, K: Kernel>(
    k: &K,
    c: &super::dfsph::Coefficients,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    bound: &Boundary<D>,
    kappa: impl Fn(usize) -> f32 + Sync,
    slots: &[u32],
    out: &mut Vec<[f64; 3]>,
) {
    let p = &c.pair;
    slots
        .par_iter()
        .map(|&b| {
            let mut force = [0.0f64; D];
            each_liquid_neighbour(
                grid,
                fluid,
                bound,
                b as usize,
                p.support2,
                |j, dx, vd, r2| {
                    let vr: f32 = (0..D).map(|d| vd[d] * dx[d]).sum();
                    let gf = k.grad_factor(r2.sqrt());
                    let mu = p.h * vr.min(0.0) / (r2 + p.eta2);
                    let pi = -p.alpha_bound * p.c0 * mu / c.rho_rest;
                    let ka = kappa(j);
                    for d in 0..D {
                        // Liquid particle j's acceleration from the body particle, and its reaction.
                        let acc = -super::dfsph::MIRROR * ka * p.m_bound * gf * dx[d]
                            - p.m_bound * pi * gf * dx[d];
                        force[d] -= (p.m_fluid * acc) as f64;
                    }
                },
            );
            to3(force)
        })
        .collect_into_vec(out);
}
