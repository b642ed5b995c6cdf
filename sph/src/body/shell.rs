//! The particles of a hollow box: every lattice point of the box within `wall_thickness` of its outer
//! faces or in a bulkhead, less those in an opening.

use crate::params::BodySpec;

/// Lattice points of the body's walls in box coordinates (x, y, z; y = 0 in 2D). The spacing along each
/// axis is the one nearest `dp` that fits the box exactly.
pub fn wall_points(spec: &BodySpec, dimension: usize, dp: f64) -> Vec<[f64; 3]> {
    let axes: Vec<usize> = if dimension == 2 {
        vec![0, 2]
    } else {
        vec![0, 1, 2]
    };
    let n: Vec<usize> = axes
        .iter()
        .map(|&k| ((spec.size[k] / dp).round() as usize).max(1))
        .collect();
    let t = spec.wall_thickness;
    let total: usize = n.iter().product();
    let mut out = Vec::new();
    for idx in 0..total {
        let mut rest = idx;
        let mut p = [0.0; 3];
        let mut inner = true;
        for (a, &k) in axes.iter().enumerate() {
            let s = spec.size[k] / n[a] as f64;
            let i = rest % n[a];
            rest /= n[a];
            // Offset from the face at the low end of the axis, and the coordinate.
            let from_low = (i as f64 + 0.5) * s;
            p[k] = if k == 2 {
                from_low
            } else {
                from_low - 0.5 * spec.size[k]
            };
            inner &= from_low > t && from_low < spec.size[k] - t;
        }
        if (!inner || spec.in_bulkhead(p, dimension)) && !spec.in_opening(p, dimension) {
            out.push(p);
        }
    }
    out
}

/// Whether a point in box coordinates is within `margin` of the box or inside it (no liquid starts there).
pub fn covers(spec: &BodySpec, dimension: usize, p: [f64; 3], margin: f64) -> bool {
    (0..3).filter(|&k| dimension == 3 || k != 1).all(|k| {
        let (lo, hi) = if k == 2 {
            (0.0, spec.size[2])
        } else {
            (-0.5 * spec.size[k], 0.5 * spec.size[k])
        };
        p[k] > lo - margin && p[k] < hi + margin
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::RegionSpec;

    fn spec() -> BodySpec {
        BodySpec {
            name: "box".into(),
            size: [0.1, 0.1, 0.1],
            wall_thickness: 0.01,
            position: [0.0, 0.0, 0.0],
            mass: 7.5,
            inertia: [0.075; 3],
            centre_of_gravity: [0.0, 0.0, 0.025],
            velocity: [0.0; 3],
            angular_velocity: [0.0; 3],
            fixed: vec![],
            openings: vec![],
            bulkheads: vec![],
            springs: vec![],
        }
    }

    #[test]
    fn walls_of_a_hollow_box_with_an_opening() {
        let s = spec();
        // 0.1 m at dp 2.5 mm: 40 × 40 points, of which the 32 × 32 inside are hollow.
        let p = wall_points(&s, 2, 0.0025);
        assert_eq!(p.len(), 40 * 40 - 32 * 32);
        let mut o = s.clone();
        o.openings.push(RegionSpec {
            name: "hole".into(),
            centre: [0.05, 0.0, 0.05],
            size: [0.02, 1.0, 0.02],
        });
        // An opening 20 mm high through the 10 mm right wall: 8 rows of 4 points.
        let q = wall_points(&o, 2, 0.0025);
        assert_eq!(p.len() - q.len(), 8 * 4);
        assert!(q
            .iter()
            .all(|x| !(x[0] > 0.04 && (x[2] - 0.05).abs() < 0.01)));
        // A bulkhead 10 mm thick across the middle of the hollow (32 rows of 4), with the opening's rows cut.
        let mut c = o.clone();
        c.bulkheads.push(RegionSpec {
            name: "middle".into(),
            centre: [0.0, 0.0, 0.05],
            size: [0.01, 1.0, 0.1],
        });
        assert_eq!(wall_points(&c, 2, 0.0025).len(), q.len() + 32 * 4);
        // 3D: 40³ − 32³.
        assert_eq!(
            wall_points(&s, 3, 0.0025).len(),
            40 * 40 * 40 - 32 * 32 * 32
        );
    }

    #[test]
    fn liquid_is_kept_out_of_the_box_and_its_margin() {
        let s = spec();
        assert!(covers(&s, 2, [0.0, 5.0, 0.05], 0.0));
        assert!(covers(&s, 2, [0.051, 0.0, 0.05], 0.002));
        assert!(!covers(&s, 2, [0.053, 0.0, 0.05], 0.002));
        assert!(!covers(&s, 2, [0.0, 0.0, -0.003], 0.002));
        assert!(!covers(&s, 3, [0.0, 0.06, 0.05], 0.002));
    }
}
