//! Wave probes: the free surface along a vertical line is where the interpolated liquid fraction
//! φ = Σ V_j W / (1 − Σ_wall V_w W) falls through 1/2. The denominator is the part of the kernel that lies
//! inside the tank, so φ ≈ 1 in the liquid also next to walls. The line is scanned from the tank top down in
//! steps of a quarter spacing and the crossing is interpolated linearly.

use crate::kernel::Kernel;
use crate::neighbours::Grid;
use crate::particles::{Boundary, Fluid};

/// Static lattice of wall points used to normalise the liquid fraction near walls.
pub struct Shell<const D: usize> {
    pub points: Boundary<D>,
    pub volume: f32,
}

/// Liquid fraction at `p`.
pub fn fraction<const D: usize, K: Kernel>(
    k: &K,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    m_fluid: f32,
    shell: &Shell<D>,
    p: [f64; D],
) -> f32 {
    let mut liquid = 0.0f32;
    super::for_each_in_reach(k, grid, &fluid.x32, &fluid.starts, p, |j, w| {
        liquid += m_fluid / fluid.rho32[j] * w
    });
    let mut wall = 0.0f32;
    super::for_each_in_reach(k, grid, &shell.points.x, &shell.points.starts, p, |_, w| {
        wall += shell.volume * w
    });
    liquid / (1.0 - wall).max(0.25)
}

/// Elevation of the free surface above the tank bottom on the vertical line through `at` (x, or x and y),
/// for a tank of height `top` scanned in steps of `dz`.
#[allow(clippy::too_many_arguments)]
pub fn elevation<const D: usize, K: Kernel>(
    k: &K,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    m_fluid: f32,
    shell: &Shell<D>,
    at: [f64; 2],
    top: f64,
    dz: f64,
) -> f64 {
    let point = |z: f64| -> [f64; D] {
        let mut p = [0.0; D];
        p[0] = at[0];
        if D == 3 {
            p[1] = at[1];
        }
        p[D - 1] = z;
        p
    };
    let n = (top / dz).ceil() as usize;
    let mut above = 0.0f32;
    for i in (0..=n).rev() {
        let z = (i as f64 * dz).min(top);
        let phi = fraction(k, grid, fluid, m_fluid, shell, point(z));
        if phi >= 0.5 {
            if i == n {
                return top;
            }
            // Linear interpolation between z (φ ≥ 1/2) and z + dz (φ < 1/2).
            let t = ((phi - 0.5) / (phi - above)) as f64;
            return z + t * dz;
        }
        above = phi;
    }
    0.0
}
