//! Pressure on a wall face measured as a transducer would: the normal force the liquid exerts on the wall
//! particles behind the sensor, spread over the face by a (D−1)-dimensional cubic-spline weight. Used by the
//! incompressible scheme, whose liquid particles next to a wall carry the wall's share of the pressure as
//! well, so interpolating their pressure would over-read.

use crate::kernel::Kernel;
use crate::neighbours::{Grid, NO_RANGES};
use crate::particles::{Boundary, Fluid};
use crate::tank::TankBox;

/// The face of the tank the point `p` lies on (within `tol`): its axis and outward sign (+1: the `hi` face).
pub fn face_of<const D: usize>(tank: &TankBox<D>, p: [f64; D], tol: f64) -> Option<(usize, f64)> {
    (0..D).find_map(|a| {
        let inside =
            (0..D).all(|d| d == a || (p[d] >= tank.lo[d] - tol && p[d] <= tank.hi[d] + tol));
        if !inside {
            None
        } else if (p[a] - tank.lo[a]).abs() <= tol {
            Some((a, -1.0))
        } else if (p[a] - tank.hi[a]).abs() <= tol {
            Some((a, 1.0))
        } else {
            None
        }
    })
}

/// Cubic spline in `dim` = 1 or 2 dimensions with smoothing length h.
fn lateral_w(dim: usize, h: f64, r: f64) -> f64 {
    let sigma = if dim == 1 {
        2.0 / (3.0 * h)
    } else {
        10.0 / (7.0 * std::f64::consts::PI * h * h)
    };
    let q = r / h;
    sigma
        * if q < 1.0 {
            1.0 - 1.5 * q * q + 0.75 * q * q * q
        } else if q < 2.0 {
            0.25 * (2.0 - q).powi(3)
        } else {
            0.0
        }
}

/// Pressure on the face (`axis`, outward `sign`) at `p`, from the liquid's wall forces: particle i pushes wall
/// particle b with `mirror · m_i m_b k_i ∇_i W_ib`, k_i (p/ρ²) from `kappa`. Only the wall particles b with
/// `walls(b)` count (across ranks, each rank's own: the parts add up).
#[allow(clippy::too_many_arguments)]
pub fn wall_pressure<const D: usize, K: Kernel>(
    k: &K,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    bound: &Boundary<D>,
    kappa: impl Fn(usize) -> f64,
    walls: impl Fn(usize) -> bool,
    (m_fluid, m_bound, mirror): (f64, f64, f64),
    p: [f64; D],
    (axis, sign): (usize, f64),
) -> f64 {
    let h = k.h() as f64;
    let support = k.support() as f64;
    let s2 = (support * support) as f32;
    let mut ranges = NO_RANGES;
    let mut total = 0.0;
    for b in 0..bound.len() {
        if !walls(b) {
            continue;
        }
        let xb: [f64; D] = std::array::from_fn(|d| bound.x[d][b] as f64);
        // Behind the face, within a support of the sensor along it.
        if (xb[axis] - p[axis]) * sign <= 0.0 {
            continue;
        }
        let lateral = (0..D)
            .filter(|&d| d != axis)
            .map(|d| (xb[d] - p[d]).powi(2))
            .sum::<f64>()
            .sqrt();
        if lateral >= support {
            continue;
        }
        let mut fn_b = 0.0f64;
        let n = grid.ranges_around(xb, &fluid.starts, &mut ranges);
        for &(lo, hi) in &ranges[..n] {
            for i in lo as usize..hi as usize {
                let dx: [f32; D] = std::array::from_fn(|d| fluid.x[d][i] - bound.x[d][b]);
                let r2: f32 = dx.iter().map(|v| v * v).sum();
                if r2 < s2 {
                    let g = k.grad_factor(r2.sqrt()) * dx[axis];
                    fn_b += kappa(i) * g as f64 * sign;
                }
            }
        }
        total += fn_b * lateral_w(D - 1, h, lateral);
    }
    total * mirror * m_fluid * m_bound
}
