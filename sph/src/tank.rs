//! Tank geometry in the tank frame and the particle lattices that fill it. Axis k of a D-dimensional point is
//! x, z in 2D and x, y, z in 3D; [`crate::vector::to3`] and [`crate::vector::from3`] convert.

use crate::params::SimParams;
use crate::vector::from3;

/// The inside of the tank as an axis-aligned box in the tank frame.
#[derive(Clone, Copy, Debug)]
pub struct TankBox<const D: usize> {
    pub lo: [f64; D],
    pub hi: [f64; D],
}

impl<const D: usize> TankBox<D> {
    pub fn new(p: &SimParams) -> Self {
        let (lo, hi) = p.tank.inside();
        Self {
            lo: from3(lo),
            hi: from3(hi),
        }
    }

    pub fn contains(&self, x: [f64; D]) -> bool {
        (0..D).all(|k| x[k] >= self.lo[k] && x[k] <= self.hi[k])
    }
}

/// Lattice spacing along one axis: the number of cells nearest to extent/dp, and the spacing that fits exactly.
fn axis(extent: f64, dp: f64) -> (usize, f64) {
    let n = ((extent / dp).round() as usize).max(1);
    (n, extent / n as f64)
}

/// Initial liquid particles (a block against the −x wall) and the volume each stands for
/// (m³, or m² per unit breadth in 2D). Spacing is adjusted per axis so the block is filled exactly.
pub fn fluid_lattice<const D: usize>(p: &SimParams) -> (Vec<[f64; D]>, f64) {
    let dp = p.particle_spacing;
    let tank = TankBox::<D>::new(p);
    let extent: [f64; D] = from3([p.fill_length(), p.tank.breadth, p.fill.height]);
    let ax: Vec<(usize, f64)> = (0..D).map(|k| axis(extent[k], dp)).collect();
    let volume: f64 = ax.iter().map(|a| a.1).product();
    let total: usize = ax.iter().map(|a| a.0).product();
    let mut out = Vec::with_capacity(total);
    for i in 0..total {
        let mut rest = i;
        let mut x = [0.0; D];
        for k in 0..D {
            let (n, s) = ax[k];
            x[k] = tank.lo[k] + ((rest % n) as f64 + 0.5) * s;
            rest /= n;
        }
        out.push(x);
    }
    (out, volume)
}

/// `layers` of lattice points outside the tank's inner faces, corners included, and the volume of each.
/// With `refine` > 1 each point is split into `refine`^(D−1) points along the face it lies beyond (a point
/// beyond a face keeps its layer, the continuation of the liquid's lattice normal to the face, and is
/// spread over its cell's extent along the face; by an edge or a corner along the first axes): the same wall,
/// smoother to a liquid sliding along it.
pub fn wall_lattice<const D: usize>(
    p: &SimParams,
    layers: u32,
    refine: usize,
) -> (Vec<[f64; D]>, f64) {
    let (points, volume) = wall_lattice_points::<D>(p, layers);
    if refine <= 1 {
        return (points, volume);
    }
    let tank = TankBox::<D>::new(p);
    let spacing = wall_spacing::<D>(p);
    let mut out = Vec::with_capacity(points.len() * refine.pow(D as u32 - 1));
    for x in points {
        // The axes to split along: those the point lies within, then the first others.
        let within = (0..D).filter(|&k| x[k] > tank.lo[k] && x[k] < tank.hi[k]);
        let beyond = (0..D).filter(|&k| !(x[k] > tank.lo[k] && x[k] < tank.hi[k]));
        let axes: Vec<usize> = within.chain(beyond).take(D - 1).collect();
        for i in 0..refine.pow(axes.len() as u32) {
            let mut y = x;
            let mut rest = i;
            for &k in &axes {
                let j = rest % refine;
                rest /= refine;
                y[k] += ((j as f64 + 0.5) / refine as f64 - 0.5) * spacing[k];
            }
            out.push(y);
        }
    }
    (out, volume / refine.pow(D as u32 - 1) as f64)
}

fn wall_lattice_points<const D: usize>(p: &SimParams, layers: u32) -> (Vec<[f64; D]>, f64) {
    let dp = p.particle_spacing;
    let tank = TankBox::<D>::new(p);
    let ax: Vec<(usize, f64)> = (0..D).map(|k| axis(tank.hi[k] - tank.lo[k], dp)).collect();
    let volume: f64 = ax.iter().map(|a| a.1).product();
    let l = layers as i64;
    let counts: Vec<i64> = ax.iter().map(|a| a.0 as i64 + 2 * l).collect();
    let total: i64 = counts.iter().product();
    let mut out = Vec::new();
    for i in 0..total {
        let mut rest = i;
        let mut x = [0.0; D];
        let mut inside = true;
        for k in 0..D {
            let idx = rest % counts[k] - l;
            rest /= counts[k];
            let (n, s) = ax[k];
            inside &= idx >= 0 && idx < n as i64;
            x[k] = tank.lo[k] + (idx as f64 + 0.5) * s;
        }
        if !inside {
            out.push(x);
        }
    }
    (out, volume)
}

/// The points of the tank's wall lattice (the inside continued, so they line up with the wall layers) that
/// fill the obstacles: solid blocks of wall particles fixed to the tank.
pub fn obstacle_lattice<const D: usize>(p: &SimParams) -> Vec<[f64; D]> {
    if p.obstacles.is_empty() {
        return vec![];
    }
    let dp = p.particle_spacing;
    let tank = TankBox::<D>::new(p);
    let ax: Vec<(usize, f64)> = (0..D).map(|k| axis(tank.hi[k] - tank.lo[k], dp)).collect();
    let total: usize = ax.iter().map(|a| a.0).product();
    (0..total)
        .map(|i| {
            let mut rest = i;
            std::array::from_fn(|k| {
                let (n, s) = ax[k];
                let x = tank.lo[k] + ((rest % n) as f64 + 0.5) * s;
                rest /= n;
                x
            })
        })
        .filter(|x| p.obstacles.iter().any(|o| o.within(*x, 0.0)))
        .collect()
}

/// The spacing of the tank's wall lattice along each axis (the inside's extent over a whole number of
/// spacings nearest `particle_spacing`).
pub fn wall_spacing<const D: usize>(p: &SimParams) -> [f64; D] {
    let tank = TankBox::<D>::new(p);
    std::array::from_fn(|k| axis(tank.hi[k] - tank.lo[k], p.particle_spacing).1)
}

/// The obstacle as its particles make it: the box whose faces lie half a spacing beyond its outermost
/// particles, i.e. each face of the given box moved to the nearest plane between two layers of the tank's wall
/// lattice (at most half a spacing). The liquid starts off these faces and a pressure sensor on an obstacle
/// reads them.
pub fn obstacle_as_built<const D: usize>(
    p: &SimParams,
    o: &crate::params::RegionSpec,
) -> crate::params::RegionSpec {
    let tank = TankBox::<D>::new(p);
    let mut out = o.clone();
    for k in 0..D {
        let a = if D == 2 { 2 * k } else { k };
        let (n, s) = axis(tank.hi[k] - tank.lo[k], p.particle_spacing);
        // The lattice coordinates inside the box, by the test `obstacle_lattice` makes.
        let inside: Vec<f64> = (0..n)
            .map(|i| tank.lo[k] + (i as f64 + 0.5) * s)
            .filter(|x| (x - o.centre[a]).abs() < 0.5 * o.size[a])
            .collect();
        if let (Some(first), Some(last)) = (inside.first(), inside.last()) {
            let (lo, hi) = (first - 0.5 * s, last + 0.5 * s);
            out.centre[a] = 0.5 * (lo + hi);
            out.size[a] = hi - lo;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::*;

    fn params(dim: usize) -> SimParams {
        let tank = TankSpec {
            length: 0.8,
            breadth: 0.25,
            height: 0.6,
        };
        SimParams::filled_tank(dim, tank, 0.39, 0.02)
    }

    #[test]
    fn fluid_block_fills_exactly_the_requested_volume() {
        let p = params(3);
        let (pts, v) = fluid_lattice::<3>(&p);
        // 0.25 / 0.02 = 12.5 rounds to 13 cells of 19.2 mm across the breadth.
        assert_eq!(pts.len(), 40 * 13 * 20);
        assert!((pts.len() as f64 * v - 0.8 * 0.25 * 0.39).abs() < 1e-12);
        let p2 = params(2);
        let (pts2, v2) = fluid_lattice::<2>(&p2);
        assert!((pts2.len() as f64 * v2 - 0.8 * 0.39).abs() < 1e-12);
        assert!(pts2
            .iter()
            .all(|x| x[0] > -0.4 && x[0] < 0.4 && x[1] > 0.0 && x[1] < 0.39));
    }

    #[test]
    fn walls_surround_the_tank() {
        let p = params(2);
        let (w, _) = wall_lattice::<2>(&p, 3, 1);
        // (40 + 6) × (30 + 6) − 40 × 30
        assert_eq!(w.len(), 46 * 36 - 40 * 30);
        let b = TankBox::<2>::new(&p);
        assert!(w.iter().all(|x| !b.contains(*x)));
        // Refined: each point split in two along its face, the same wall (volume, layers, thickness).
        let (w2, v2) = wall_lattice::<2>(&p, 3, 2);
        let (_, v1) = wall_lattice::<2>(&p, 3, 1);
        assert_eq!(w2.len(), 2 * w.len());
        assert!((w2.len() as f64 * v2 - w.len() as f64 * v1).abs() < 1e-12);
        assert!(w2.iter().all(|x| !b.contains(*x)));
        let dp = p.particle_spacing;
        // Below the floor: the layers of the liquid's lattice continued, two points a cell along x.
        let floor: Vec<&[f64; 2]> = w2
            .iter()
            .filter(|x| x[0].abs() < 0.2 && x[1] < 0.0)
            .collect();
        assert!(floor.iter().all(|x| {
            let layer = -x[1] / dp - 0.5;
            (layer - layer.round()).abs() < 1e-9
        }));
        // 20 cells of the first layer, two points each.
        assert_eq!(floor.iter().filter(|x| x[1] > -dp).count(), 40);
        // Beside the end walls: the same along z.
        let side: Vec<&[f64; 2]> = w2
            .iter()
            .filter(|x| x[0] < -0.4 && x[1] > 0.0 && x[1] < 0.3)
            .collect();
        assert_eq!(side.len(), 3 * 2 * 15);
        assert!(side.iter().all(|x| {
            let layer = (-0.4 - x[0]) / dp - 0.5;
            (layer - layer.round()).abs() < 1e-9
        }));
    }

    #[test]
    fn an_obstacle_is_built_from_the_wall_lattice_points_inside_it() {
        let mut p = params(3);
        let o = crate::params::RegionSpec {
            name: "block".into(),
            centre: [0.0215, 0.0, 0.0415],
            size: [0.103, 0.1, 0.083],
        };
        p.obstacles = vec![o.clone()];
        let b = obstacle_as_built::<3>(&p, &o);
        // x: the tank's 40 spacings of 0.02 m, points at ±0.01, ±0.03, ... inside (−0.03, 0.073): faces at −0.02,
        // 0.08; y: 13 spacings of 0.25 / 13 m, five points inside (−0.05, 0.05); z: 0.01 ... 0.07.
        let sy = 0.25 / 13.0;
        let lo: [f64; 3] = std::array::from_fn(|k| b.centre[k] - 0.5 * b.size[k]);
        let hi: [f64; 3] = std::array::from_fn(|k| b.centre[k] + 0.5 * b.size[k]);
        for (got, want) in
            lo.iter()
                .zip([-0.02, -2.5 * sy, 0.0])
                .chain(hi.iter().zip([0.08, 2.5 * sy, 0.08]))
        {
            assert!((got - want).abs() < 1e-12, "{lo:?} {hi:?}");
        }
        // Every particle of the obstacle lies inside the box as built, half a spacing or more off its faces.
        let pts = obstacle_lattice::<3>(&p);
        assert_eq!(pts.len(), 5 * 5 * 4);
        for x in &pts {
            assert!(
                (0..3).all(|k| x[k] > lo[k] + 0.45 * sy && x[k] < hi[k] - 0.45 * sy),
                "{x:?}"
            );
        }
    }
}
