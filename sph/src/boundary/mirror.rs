//! Mirror ("dynamic ghost") particles, the paper's second boundary condition: every liquid particle within
//! the kernel support of a wall is reflected across it (twice or three times near edges and corners). A ghost
//! carries its source's density and pressure (plus the hydrostatic difference over the reflection distance,
//! so a liquid at rest sees a continuous pressure field) and its velocity with the normal part reversed
//! (free slip). The anti-penetration restraint keeps particles at least `d_min` from each wall.

use crate::eos::Tait;
use crate::particles::{Boundary, Fluid};
use crate::tank::TankBox;

/// Rebuilds `ghosts` from the liquid's interaction copies. `g` is the apparent gravity in the tank frame.
pub fn build_ghosts<const D: usize>(
    fluid: &Fluid<D>,
    tank: &TankBox<D>,
    support: f64,
    g: [f64; D],
    eos: &Tait,
    ghosts: &mut Boundary<D>,
) {
    ghosts.clear();
    for i in 0..fluid.len() {
        let x: [f64; D] = std::array::from_fn(|k| fluid.x32[k][i] as f64);
        let v: [f64; D] = std::array::from_fn(|k| fluid.v32[k][i] as f64);
        // For each axis: which face (if any) is within reach, and the mirrored coordinate.
        let mut near = [None; D];
        for k in 0..D {
            if x[k] - tank.lo[k] < support {
                near[k] = Some(2.0 * tank.lo[k] - x[k]);
            } else if tank.hi[k] - x[k] < support {
                near[k] = Some(2.0 * tank.hi[k] - x[k]);
            }
        }
        // Every non-empty combination of near faces gives one ghost.
        for mask in 1u32..(1 << D) {
            if (0..D).any(|k| mask & (1 << k) != 0 && near[k].is_none()) {
                continue;
            }
            let mut xg = x;
            let mut vg = v;
            for k in 0..D {
                if mask & (1 << k) != 0 {
                    xg[k] = near[k].unwrap();
                    vg[k] = -v[k];
                }
            }
            let dz: f64 = (0..D).map(|k| g[k] * (xg[k] - x[k])).sum();
            let rho = fluid.rho32[i] as f64;
            let p = fluid.p32[i] as f64 + rho * dz;
            let rg = eos.density(p);
            ghosts.push(xg, vg, rg, p as f32);
        }
    }
}

/// The paper's restraint: no particle closer than `d_min` to a wall, and no velocity into it there.
pub fn restrain<const D: usize>(fluid: &mut Fluid<D>, tank: &TankBox<D>, d_min: f64) {
    for k in 0..D {
        let (lo, hi) = (tank.lo[k] + d_min, tank.hi[k] - d_min);
        for i in 0..fluid.len() {
            let x = fluid.pos[k][i];
            if x < lo {
                fluid.pos[k][i] = lo;
                if fluid.vel[k][i] < 0.0 {
                    fluid.vel[k][i] = 0.0;
                }
            } else if x > hi {
                fluid.pos[k][i] = hi;
                if fluid.vel[k][i] > 0.0 {
                    fluid.vel[k][i] = 0.0;
                }
            }
        }
    }
}
