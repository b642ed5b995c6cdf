//! Pressure on a wall face measured as a transducer would: the normal force the liquid exerts on the wall
//! particles behind the sensor, spread over the face by a (D−1)-dimensional cubic-spline weight. Used by the
//! incompressible scheme, whose liquid particles next to a wall carry the wall's share of the pressure as
//! well, so interpolating their pressure would over-read.

use crate::kernel::Kernel;
use crate::neighbours::{Grid, NO_RANGES};
use crate::params::RegionSpec;
use crate::particles::{Boundary, Fluid};
use crate::tank::TankBox;
use crate::vector::from3;

/// The wall face a pressure sensor sits on.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Face {
    /// The axis normal to the face (0..D).
    pub axis: usize,
    /// The direction from the liquid into the wall along `axis`: +1 where the wall lies towards +axis (the
    /// tank's `hi` faces, an obstacle's `lo` faces).
    pub sign: f64,
    /// `None`: a face of the tank; `Some(k)`: a face of obstacle k.
    pub obstacle: Option<usize>,
}

/// The face of the tank the point `p` lies on (within `tol`): its axis and outward sign (+1: the `hi` face);
/// the nearest where `p` is within `tol` of two (in a corner).
pub fn face_of<const D: usize>(tank: &TankBox<D>, p: [f64; D], tol: f64) -> Option<(usize, f64)> {
    (0..D)
        .filter(|&a| {
            (0..D).all(|d| d == a || (p[d] >= tank.lo[d] - tol && p[d] <= tank.hi[d] + tol))
        })
        .flat_map(|a| {
            [
                (a, -1.0, (p[a] - tank.lo[a]).abs()),
                (a, 1.0, (p[a] - tank.hi[a]).abs()),
            ]
        })
        .filter(|f| f.2 <= tol)
        .min_by(|x, y| x.2.total_cmp(&y.2))
        .map(|(a, sign, _)| (a, sign))
}

/// The face of an obstacle box (tank frame) the point `p` lies on within `tol`, with its distance from it;
/// the nearest where `p` is within `tol` of two (by an edge).
pub fn obstacle_face_of<const D: usize>(
    o: &RegionSpec,
    p: [f64; D],
    tol: f64,
) -> Option<(usize, f64, f64)> {
    let (centre, size): ([f64; D], [f64; D]) = (from3(o.centre), from3(o.size));
    let half = |d: usize| 0.5 * size[d];
    let off = |d: usize| p[d] - centre[d];
    if (0..D).any(|d| off(d).abs() > half(d) + tol) {
        return None;
    }
    (0..D)
        .filter_map(|a| {
            let dist = (off(a).abs() - half(a)).abs();
            // The liquid is on the side of the face away from the centre: the wall lies back towards it.
            (dist <= tol).then(|| (a, -off(a).signum(), dist))
        })
        .min_by(|x, y| x.2.total_cmp(&y.2))
}

/// The face `p` lies on within `tol`, of the tank or an obstacle: the nearest where it is within `tol` of
/// two (a sensor in the corner between an obstacle and the floor reads the face it is closer to).
pub fn face_at<const D: usize>(
    tank: &TankBox<D>,
    obstacles: &[RegionSpec],
    p: [f64; D],
    tol: f64,
) -> Option<Face> {
    let on_tank = face_of(tank, p, tol).map(|(axis, sign)| {
        let plane = if sign > 0.0 {
            tank.hi[axis]
        } else {
            tank.lo[axis]
        };
        let face = Face {
            axis,
            sign,
            obstacle: None,
        };
        (face, (p[axis] - plane).abs())
    });
    let on_obstacles = obstacles.iter().enumerate().filter_map(|(k, o)| {
        obstacle_face_of(o, p, tol).map(|(axis, sign, dist)| {
            let face = Face {
                axis,
                sign,
                obstacle: Some(k),
            };
            (face, dist)
        })
    });
    on_tank
        .into_iter()
        .chain(on_obstacles)
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .map(|(face, _)| face)
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

/// Where a sensor reads: its face, its point moved onto the face's plane as the particles make it (an
/// obstacle's faces lie on the tank's wall lattice, up to half a spacing off the given ones), and the weight the
/// face's columns of wall particles (one per lattice point of the face, the layers behind it) give a pressure
/// of 1 (≈ 1 in the middle of a face, less by an edge or a corner, where the sensor's reach runs off the
/// face).
#[derive(Clone, Debug, PartialEq)]
pub struct FaceSpot<const D: usize> {
    pub face: Face,
    pub at: [f64; D],
    /// The face's extent along the other axes (its own axis: the plane).
    pub lo: [f64; D],
    pub hi: [f64; D],
    pub norm: f64,
}

impl<const D: usize> FaceSpot<D> {
    /// The spot of a sensor at `p` on the face of the tank or of an obstacle (`given`, as configured) it lies on
    /// within `tol`, read on that face as built (`built`, [`crate::tank::obstacle_as_built`]) with the
    /// lateral weight of smoothing length `h`; `spacing` is the tank's wall lattice spacing per axis.
    pub fn locate(
        tank: &TankBox<D>,
        (given, built): (&[RegionSpec], &[RegionSpec]),
        p: [f64; D],
        tol: f64,
        spacing: [f64; D],
        h: f64,
    ) -> Option<Self> {
        let face = face_at(tank, given, p, tol)?;
        let (lo, hi) = match face.obstacle {
            None => (tank.lo, tank.hi),
            Some(k) => {
                let (centre, size): ([f64; D], [f64; D]) =
                    (from3(built[k].centre), from3(built[k].size));
                (
                    std::array::from_fn(|d| centre[d] - 0.5 * size[d]),
                    std::array::from_fn(|d| centre[d] + 0.5 * size[d]),
                )
            }
        };
        let a = face.axis;
        // The liquid lies on the side away from the wall: a tank's hi face (sign +1) is at hi, an obstacle's
        // face towards −x (sign +1, the solid towards +x) at lo.
        let plane = match (face.obstacle, face.sign > 0.0) {
            (None, true) | (Some(_), false) => hi[a],
            (None, false) | (Some(_), true) => lo[a],
        };
        let mut at = p;
        at[a] = plane;
        // Σ over the face's columns (lattice points of the face, spacing apart) of the lateral weight times
        // each column's area.
        let lateral: Vec<usize> = (0..D).filter(|&d| d != a).collect();
        let coords = |d: usize| -> Vec<f64> {
            let n = ((hi[d] - lo[d]) / spacing[d]).round().max(1.0) as usize;
            (0..n)
                .map(|i| lo[d] + (i as f64 + 0.5) * spacing[d])
                .filter(|x| (x - at[d]).abs() < 2.0 * h)
                .collect()
        };
        let area: f64 = lateral.iter().map(|&d| spacing[d]).product();
        let mut norm = 0.0;
        match lateral.as_slice() {
            [d] => {
                for x in coords(*d) {
                    norm += lateral_w(1, h, (x - at[*d]).abs()) * area;
                }
            }
            [d, e] => {
                let (xs, ys) = (coords(*d), coords(*e));
                for x in &xs {
                    for y in &ys {
                        let r = ((x - at[*d]).powi(2) + (y - at[*e]).powi(2)).sqrt();
                        norm += lateral_w(2, h, r) * area;
                    }
                }
            }
            _ => unreachable!("a face of a 2D or 3D box"),
        }
        Some(Self {
            face,
            at,
            lo,
            hi,
            norm,
        })
    }

    /// Whether the wall particle at `x` is in one of the face's columns: behind its plane, within its extent.
    pub fn column(&self, x: [f64; D]) -> bool {
        let a = self.face.axis;
        (x[a] - self.at[a]) * self.face.sign > 0.0
            && (0..D).all(|d| d == a || (x[d] > self.lo[d] && x[d] < self.hi[d]))
    }
}

/// Pressure at a sensor's spot on a face, from the liquid's wall forces: particle i pushes wall particle b with
/// `mirror · m_i m_b k_i ∇_i W_ib`, k_i (p/ρ²) from `kappa`. The normal forces on the wall particles of the
/// face's columns (those with `walls(b)`: across ranks, each rank's own, so the parts add up), pushed by the
/// liquid in front of the face's plane or less than `slack` behind it (half a spacing: the liquid next to a
/// face may come that close to the wall particles half a spacing behind it), weighted by a (D−1)-dimensional
/// cubic spline along the face and divided by the weight the face's columns give a pressure of 1
/// ([`FaceSpot::norm`]): by an edge the reading is the mean over the part of the face in reach.
#[allow(clippy::too_many_arguments)]
pub fn wall_pressure<const D: usize, K: Kernel>(
    k: &K,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    bound: &Boundary<D>,
    kappa: impl Fn(usize) -> f64,
    walls: impl Fn(usize) -> bool,
    (m_fluid, m_bound, mirror): (f64, f64, f64),
    spot: &FaceSpot<D>,
    slack: f64,
) -> f64 {
    let (axis, sign, p) = (spot.face.axis, spot.face.sign, spot.at);
    let h = k.h() as f64;
    let support = k.support() as f64;
    let s2 = (support * support) as f32;
    let (pa, sign32, slack) = (p[axis] as f32, sign as f32, slack as f32);
    let mut ranges = NO_RANGES;
    let mut total = 0.0;
    for b in 0..bound.len() {
        let xb: [f64; D] = std::array::from_fn(|d| bound.x[d][b] as f64);
        if !spot.column(xb) || !walls(b) {
            continue;
        }
        // Within a support of the sensor along the face.
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
                let dx: [f32; D] = std::array::from_fn(|d| fluid.x32[d][i] - bound.x[d][b]);
                let r2: f32 = dx.iter().map(|v| v * v).sum();
                // Only the liquid in front of the face (an obstacle's other faces have liquid too, which
                // pushes its particles from other sides), up to `slack` behind its plane.
                let front = (fluid.x32[axis][i] - pa) * sign32 < slack;
                if r2 < s2 && front {
                    let g = k.grad_factor(r2.sqrt()) * dx[axis];
                    fn_b += kappa(i) * g as f64 * sign;
                }
            }
        }
        total += fn_b * lateral_w(D - 1, h, lateral);
    }
    if spot.norm <= 0.0 {
        return 0.0;
    }
    total * mirror * m_fluid * m_bound / spot.norm
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block() -> RegionSpec {
        RegionSpec {
            name: "block".into(),
            centre: [0.1, 0.0, 0.05],
            size: [0.1, 0.2, 0.1],
        }
    }

    #[test]
    fn sensors_find_the_tank_or_obstacle_face_they_sit_on() {
        let tank = TankBox::<3> {
            lo: [-0.5, -0.25, 0.0],
            hi: [0.5, 0.25, 0.6],
        };
        let obs = [block()];
        let at = |p: [f64; 3]| face_at(&tank, &obs, p, 0.005);
        let face = |axis, sign, obstacle| {
            Some(Face {
                axis,
                sign,
                obstacle,
            })
        };
        // Tank walls: the +x wall lies towards +x, the floor towards −z.
        assert_eq!(at([0.5, 0.0, 0.2]), face(0, 1.0, None));
        assert_eq!(at([0.0, 0.0, 0.002]), face(2, -1.0, None));
        // The block's faces: towards the water from −x the block lies at +x; under its top, at −z.
        assert_eq!(at([0.05, 0.03, 0.04]), face(0, 1.0, Some(0)));
        assert_eq!(at([0.152, 0.03, 0.04]), face(0, -1.0, Some(0)));
        assert_eq!(at([0.1, -0.1, 0.04]), face(1, 1.0, Some(0)));
        assert_eq!(at([0.12, 0.0, 0.1]), face(2, -1.0, Some(0)));
        // By an edge, the nearer face; in the corner with the floor, the nearer of the two.
        assert_eq!(at([0.053, 0.0, 0.099]), face(2, -1.0, Some(0)));
        assert_eq!(at([0.051, 0.0, 0.004]), face(0, 1.0, Some(0)));
        assert_eq!(at([0.054, 0.0, 0.002]), face(2, -1.0, None));
        // In a corner of the tank, the nearer of its two walls, whichever axis comes first.
        assert_eq!(at([0.497, 0.0, 0.001]), face(2, -1.0, None));
        assert_eq!(at([0.499, 0.0, 0.003]), face(0, 1.0, None));
        assert_eq!(at([-0.496, 0.249, 0.3]), face(1, 1.0, None));
        // In the liquid, or beside the block but beyond its extent: no face.
        assert_eq!(at([0.0, 0.0, 0.2]), None);
        assert_eq!(at([0.05, 0.0, 0.12]), None);
        // 2D: (x, z), the block's y ignored.
        let tank2 = TankBox::<2> {
            lo: [-0.5, 0.0],
            hi: [0.5, 0.6],
        };
        let f2 = face_at(&tank2, &obs, [0.15, 0.05], 0.005);
        assert_eq!(f2, face(0, -1.0, Some(0)));
        let f2 = face_at(&tank2, &obs, [0.1, 0.1], 0.005);
        assert_eq!(f2, face(1, -1.0, Some(0)));
    }

    #[test]
    fn a_spot_reads_the_face_as_built_and_weighs_the_columns_in_reach() {
        let (dp, h) = (0.01, 0.013);
        let tank = TankBox::<3> {
            lo: [-0.5, -0.25, 0.0],
            hi: [0.5, 0.25, 0.6],
        };
        let spacing = [dp; 3];
        // The block as given, and as its particles (on the wall lattice) make it.
        let given = [RegionSpec {
            name: "block".into(),
            centre: [0.1, 0.0, 0.0515],
            size: [0.1, 0.2, 0.103],
        }];
        let built = [RegionSpec {
            size: [0.1, 0.2, 0.1],
            centre: [0.1, 0.0, 0.05],
            ..given[0].clone()
        }];
        let spot = |p: [f64; 3]| {
            FaceSpot::locate(&tank, (&given, &built), p, 0.5 * dp, spacing, h).expect("on a face")
        };
        // The middle of a tank wall: the columns' weight is 1 (the lattice sum of the normalised spline).
        let wall = spot([0.5, 0.0, 0.3]);
        assert_eq!(wall.at, [0.5, 0.0, 0.3]);
        assert!((wall.norm - 1.0).abs() < 0.01, "{}", wall.norm);
        // The block's top, given at 0.103, read at 0.1; its columns end at its edges.
        let top = spot([0.1, 0.0, 0.103]);
        assert_eq!(top.face.axis, 2);
        assert!((top.at[2] - 0.1).abs() < 1e-12, "{:?}", top.at);
        assert!((top.norm - 1.0).abs() < 0.01, "{}", top.norm);
        assert!(top.column([0.1, 0.0, 0.095]) && top.column([0.145, 0.09, 0.075]));
        assert!(!top.column([0.1, 0.0, 0.105]) && !top.column([0.155, 0.0, 0.095]));
        // By an edge half the kernel's reach runs off the face; in a corner three quarters (the lattice's
        // nearest columns, half a spacing off each edge, weigh a little more).
        let edge = spot([0.051, 0.0, 0.103]);
        assert_eq!(edge.face.axis, 2);
        assert!((0.5..0.6).contains(&edge.norm), "{}", edge.norm);
        let corner = spot([0.051, -0.099, 0.103]);
        assert_eq!(corner.face.axis, 2);
        assert!((0.25..0.36).contains(&corner.norm), "{}", corner.norm);
        // A tank wall's columns end at the floor.
        let low = spot([-0.5, 0.0, 0.0]);
        assert!((low.norm - 0.5).abs() < 0.05, "{}", low.norm);
        assert!(!low.column([-0.505, 0.0, -0.005]) && low.column([-0.505, 0.0, 0.005]));
    }
}
