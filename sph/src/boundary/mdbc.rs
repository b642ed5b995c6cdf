//! Modified dynamic boundary conditions (English, Domínguez, Vacondio, Crespo, Stansby, Lind, Chiapponi &
//! Gómez-Gesteira 2022, "Modified dynamic boundary conditions (mDBC) for general-purpose smoothed particle
//! hydrodynamics (SPH)", Comp. Part. Mech. 9, as DualSPHysics ships them), for the tank's wall layers: each
//! wall particle w takes the density of the liquid extrapolated to it from its ghost node g, its mirror image
//! across the wall face (across both faces by an edge, all three by a corner):
//!
//! ρ_w = ρ_g + (x_w − x_g)·∇ρ_g,
//!
//! with ρ_g and ∇ρ_g from the liquid around g by a first-order consistent interpolation (Liu & Liu 2006):
//! the (D+1)×(D+1) system Σ_b V_b [W_gb; ∇W_gb] [1, (x_b − x_g)] · [ρ_g; ∇ρ_g] = Σ_b m_b [W_gb; ∇W_gb]. Where
//! the liquid around g is too sparse for that system (a wall above the liquid, a splash), Shepard's
//! interpolation, and ρ0 where there is none; never below ρ0, so walls do not pull.
//!
//! The walls then hold the pressure of the liquid at their own depth, and the liquid's distribution along them
//! is right (with the continuity density of the plain dynamic walls the liquid along a deep wall thins, and a
//! tilted tank's moment comes out low). Each point of the wall lattice is split along its face into
//! [`REFINE`]^(D−1) ([`crate::tank::wall_lattice`]): a liquid sliding along wall particles one spacing apart
//! feels their bumps, which damp sloshing; the layers stay where the liquid's lattice continues, so the
//! liquid at rest stands half a spacing from the faces (see the manual's decisions).

use crate::eos::Tait;
use crate::kernel::Kernel;
use crate::neighbours::{Grid, NO_RANGES};
use crate::particles::{Boundary, Fluid, NOT_BODY};
use crate::tank::TankBox;
use rayon::prelude::*;

/// Each point of the tank's wall lattice is split this many times along each axis of its face.
pub const REFINE: usize = 2;

/// Σ_b V_b W_gb below which the liquid around a ghost node is too sparse for the gradient: Shepard's
/// interpolation instead (a full neighbourhood sums to ≈ 1; a node at a flat free surface to ≈ 0.5).
const MIN_SHEPARD_FOR_GRADIENT: f64 = 0.3;

/// Sets the density, pressure and p/ρ² of the tank's wall particles (those outside the tank's inside box
/// and not a body's) from the liquid at their ghost nodes.
pub fn refresh<const D: usize, K: Kernel>(
    kernel: &K,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    tank: &TankBox<D>,
    m_fluid: f32,
    eos: &Tait,
    b: &mut Boundary<D>,
) {
    let rho0 = eos.rho0 as f64;
    let Boundary {
        x,
        tag,
        rho,
        r,
        p,
        pr2,
        ..
    } = b;
    (rho, r, p, pr2)
        .into_par_iter()
        .enumerate()
        .for_each(|(w, (rho, r, p, pr2))| {
            let xw: [f64; D] = std::array::from_fn(|k| x[k][w] as f64);
            if tag[w] != NOT_BODY || tank.contains(xw) {
                return;
            }
            let xg = ghost(tank, xw);
            let extrapolated = match interpolate(kernel, grid, fluid, m_fluid as f64, xg) {
                Interpolated::Gradient(r, g) => {
                    r + (0..D).map(|k| g[k] * (xw[k] - xg[k])).sum::<f64>()
                }
                Interpolated::Shepard(r) => r,
                Interpolated::Empty => rho0,
            };
            *rho = extrapolated.max(rho0);
            *r = *rho as f32;
            *p = eos.pressure(*r);
            *pr2 = *p / (*r * *r);
        });
}

/// The mirror image of `xw` (outside the tank) across every face it lies beyond.
pub fn ghost<const D: usize>(tank: &TankBox<D>, xw: [f64; D]) -> [f64; D] {
    std::array::from_fn(|k| {
        if xw[k] < tank.lo[k] {
            2.0 * tank.lo[k] - xw[k]
        } else if xw[k] > tank.hi[k] {
            2.0 * tank.hi[k] - xw[k]
        } else {
            xw[k]
        }
    })
}

/// What the liquid around a point gives.
#[derive(Debug, PartialEq)]
enum Interpolated<const D: usize> {
    /// Density and its gradient (first-order consistent).
    Gradient(f64, [f64; D]),
    /// Density only (too few neighbours for a gradient).
    Shepard(f64),
    /// No liquid in reach.
    Empty,
}

fn interpolate<const D: usize, K: Kernel>(
    kernel: &K,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    m: f64,
    xg: [f64; D],
) -> Interpolated<D> {
    let support = kernel.support() as f64;
    let mut ranges = NO_RANGES;
    let n = grid.ranges_around(xg, &fluid.starts, &mut ranges);
    // Rows: the test functions W and ∇W; columns: the unknowns ρ_g and ∇ρ_g.
    let mut a = [[0.0f64; 4]; 4];
    let mut rhs = [0.0f64; 4];
    for &(lo, hi) in &ranges[..n] {
        for j in lo as usize..hi as usize {
            let dx: [f64; D] = std::array::from_fn(|k| fluid.x32[k][j] as f64 - xg[k]);
            let r = dx.iter().map(|v| v * v).sum::<f64>().sqrt();
            if r >= support {
                continue;
            }
            let gf = kernel.grad_factor(r as f32) as f64;
            let mut t = [0.0f64; 4];
            t[0] = kernel.w(r as f32) as f64;
            for k in 0..D {
                // ∇W with respect to the neighbour's position (any consistent test function serves).
                t[1 + k] = gf * dx[k];
            }
            let vol = m / fluid.rho32[j] as f64;
            for row in 0..=D {
                rhs[row] += m * t[row];
                a[row][0] += vol * t[row];
                for k in 0..D {
                    a[row][1 + k] += vol * t[row] * dx[k];
                }
            }
        }
    }
    if a[0][0] <= 0.0 {
        return Interpolated::Empty;
    }
    if a[0][0] >= MIN_SHEPARD_FOR_GRADIENT {
        if let Some(s) = solve::<D>(&a, &rhs) {
            return Interpolated::Gradient(s[0], std::array::from_fn(|k| s[1 + k]));
        }
    }
    Interpolated::Shepard(rhs[0] / a[0][0])
}

/// Solves the leading (D+1)×(D+1) block of `a` x = `r` by Gaussian elimination with partial pivoting, each
/// row scaled by its largest entry first (the rows of W and of ∇W differ by 1/h); None if it is singular.
fn solve<const D: usize>(a: &[[f64; 4]; 4], r: &[f64; 4]) -> Option<[f64; 4]> {
    let n = D + 1;
    let (mut m, mut x) = (*a, *r);
    for i in 0..n {
        let s = m[i][..n].iter().fold(0.0f64, |s, v| s.max(v.abs()));
        if s == 0.0 {
            return None;
        }
        m[i].iter_mut().for_each(|v| *v /= s);
        x[i] /= s;
    }
    for c in 0..n {
        let p = (c..n).max_by(|&i, &j| m[i][c].abs().total_cmp(&m[j][c].abs()))?;
        if m[p][c].abs() < 1e-6 {
            return None;
        }
        m.swap(c, p);
        x.swap(c, p);
        for i in c + 1..n {
            let f = m[i][c] / m[c][c];
            for k in c..n {
                m[i][k] -= f * m[c][k];
            }
            x[i] -= f * x[c];
        }
    }
    let mut out = [0.0; 4];
    for i in (0..n).rev() {
        let s: f64 = (i + 1..n).map(|k| m[i][k] * out[k]).sum();
        out[i] = (x[i] - s) / m[i][i];
    }
    Some(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::{CubicSpline, Kernel};
    use crate::particles::SortScratch;

    #[test]
    fn the_ghost_node_is_the_mirror_image_across_the_faces_beyond() {
        let tank = TankBox::<2> {
            lo: [-0.4, 0.0],
            hi: [0.4, 0.6],
        };
        assert_eq!(ghost(&tank, [0.1, -0.01]), [0.1, 0.01]);
        let g = ghost(&tank, [0.41, -0.02]);
        assert!((g[0] - 0.39).abs() < 1e-12 && (g[1] - 0.02).abs() < 1e-12);
    }

    #[test]
    fn a_linear_density_is_extrapolated_exactly_from_a_lattice_cut_by_a_wall() {
        // Liquid on a lattice above the floor z = 0 with ρ = ρ0 (1 + 0.01 (3 − 20 z) + 0.002 x): a wall
        // particle below the floor gets the linear field's value at its own place, where the liquid never is.
        let dp = 0.01;
        let h = 1.3 * dp;
        let kernel = CubicSpline::new(2, h as f32);
        let grid = Grid::<2>::new([-0.3, -0.05], [0.3, 0.3], 2.0 * h);
        let rho = |x: [f64; 2]| 1000.0 * (1.0 + 0.01 * (3.0 - 20.0 * x[1]) + 0.002 * x[0]);
        let mut pts = vec![];
        for i in 0..40 {
            for j in 0..20 {
                pts.push([-0.2 + (i as f64 + 0.5) * dp, (j as f64 + 0.5) * dp]);
            }
        }
        let mut fluid = Fluid::new(&pts, rho);
        let m = 1000.0 * dp * dp;
        let mut scratch = SortScratch::default();
        fluid.sort(&grid, &mut scratch);
        fluid.refresh(|r, _| r);
        for xw in [[0.005, -0.005], [0.0, -0.015], [-0.03, -0.025]] {
            let xg = [xw[0], -xw[1]];
            match interpolate(&kernel, &grid, &fluid, m, xg) {
                Interpolated::Gradient(r, g) => {
                    let at_w = r + g[0] * (xw[0] - xg[0]) + g[1] * (xw[1] - xg[1]);
                    // The lattice's masses stand for ρ0 dp² whatever the density: the interpolation reads
                    // Σ m W / Σ V W with V = m / ρ, exact for the field the particles carry.
                    assert!(
                        (at_w - rho(xw)).abs() < 1e-3 * 1000.0,
                        "at {xw:?}: {at_w} against {}",
                        rho(xw)
                    );
                }
                other => panic!("at {xg:?}: {other:?}"),
            }
        }
    }
}
