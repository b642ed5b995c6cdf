//! Kernel gradient correction (Bonet & Lok 1999; in its symmetric form as in Schulze et al. 2025 for water
//! waves): each particle's kernel gradients are multiplied by L_a = M_a⁻¹, with
//! M_a = Σ_b V_b (x_b − x_a) ⊗ ∇W_ab over its liquid and wall neighbours, so that the pressure force of a
//! linear pressure field is exact whatever the particles' arrangement. A pair uses ½(L_a + L_b): the pair
//! terms stay antisymmetric (momentum is conserved) and the divergence and pressure passes stay each
//! other's adjoints (the projection does no work).
//!
//! Without it a liquid at rest is a lattice whose pressure forces resist shear: a small sloshing wave sees
//! a stiffer, lossy medium (the 2D seed tank's first mode 2 % short and damped at ζ ≈ 0.025, against
//! ζ ≈ 0.0007 from laminar theory). Where the kernel is cut by the free surface M is deficient and its
//! inverse unreliable: the correction fades out with det M (from [`FULL_DET`] down to [`MIN_DET`]).

/// A D × D matrix, rows first.
pub type Mat<const D: usize> = [[f32; D]; D];

/// det M below which a particle keeps its plain gradients, and from which on it takes the whole
/// correction (det M ≈ 1 inside the liquid).
pub const MIN_DET: f32 = 0.6;
pub const FULL_DET: f32 = 0.9;

/// The identity.
#[inline(always)]
pub fn identity<const D: usize>() -> Mat<D> {
    std::array::from_fn(|r| std::array::from_fn(|c| if r == c { 1.0 } else { 0.0 }))
}

/// Adds V (x_b − x_a) ⊗ ∇W_ab to `m` (`dx` = x_b − x_a).
#[inline(always)]
pub fn add_pair<const D: usize>(m: &mut Mat<D>, v: f32, dx: [f32; D], g: [f32; D]) {
    for r in 0..D {
        for c in 0..D {
            m[r][c] += v * dx[r] * g[c];
        }
    }
}

/// The correction of a particle with M: I + w (M⁻¹ − I), w rising smoothly from 0 at det M =
/// [`MIN_DET`] to 1 at [`FULL_DET`], so that a particle's correction does not jump as it nears the free
/// surface (a jump is a force discontinuity: noise).
pub fn inverse_or_identity<const D: usize>(m: &Mat<D>) -> Mat<D> {
    let id = identity::<D>();
    let (det, inv) = match D {
        2 => {
            let det = m[0][0] * m[1][1] - m[0][1] * m[1][0];
            let mut inv = id;
            if det > 0.0 {
                inv[0][0] = m[1][1] / det;
                inv[0][1] = -m[0][1] / det;
                inv[1][0] = -m[1][0] / det;
                inv[1][1] = m[0][0] / det;
            }
            (det, inv)
        }
        3 => {
            let c = |r: usize, k: usize| {
                let (r1, r2) = ((r + 1) % 3, (r + 2) % 3);
                let (k1, k2) = ((k + 1) % 3, (k + 2) % 3);
                m[r1][k1] * m[r2][k2] - m[r1][k2] * m[r2][k1]
            };
            let det = m[0][0] * c(0, 0) + m[0][1] * c(0, 1) + m[0][2] * c(0, 2);
            let mut inv = id;
            if det > 0.0 {
                for r in 0..3 {
                    for k in 0..3 {
                        // (M⁻¹)_rk = cofactor_kr / det.
                        inv[r][k] = c(k, r) / det;
                    }
                }
            }
            (det, inv)
        }
        _ => (0.0, id),
    };
    let t = ((det - MIN_DET) / (FULL_DET - MIN_DET)).clamp(0.0, 1.0);
    let w = t * t * (3.0 - 2.0 * t);
    std::array::from_fn(|r| std::array::from_fn(|k| id[r][k] + w * (inv[r][k] - id[r][k])))
}

/// ½(a + b).
#[inline(always)]
pub fn mean<const D: usize>(a: &Mat<D>, b: &Mat<D>) -> Mat<D> {
    std::array::from_fn(|r| std::array::from_fn(|c| 0.5 * (a[r][c] + b[r][c])))
}

/// m g.
#[inline(always)]
pub fn apply<const D: usize>(m: &Mat<D>, g: [f32; D]) -> [f32; D] {
    std::array::from_fn(|r| (0..D).map(|c| m[r][c] * g[c]).sum())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::{CubicSpline, Kernel};

    /// M of a particle in a lattice of spacing dp sheared by `s` (x += s z), from the cubic spline.
    fn lattice_m<const D: usize>(dp: f32, s: f32) -> Mat<D> {
        let h = 1.3 * dp;
        let k = CubicSpline::new(D, h);
        let mut m = [[0.0f32; D]; D];
        let n = 4i32;
        let v = dp.powi(D as i32);
        let range = |d: usize| if d < D { -n..=n } else { 0..=0 };
        for i in range(0) {
            for j in range(1) {
                for l in range(2) {
                    let mut x = [0.0f32; D];
                    x[0] = i as f32 * dp;
                    x[1] = j as f32 * dp;
                    if D == 3 {
                        x[2] = l as f32 * dp;
                    }
                    x[0] += s * x[D - 1];
                    let r = x.iter().map(|v| v * v).sum::<f32>().sqrt();
                    if r == 0.0 || r >= k.support() {
                        continue;
                    }
                    // ∇_a W_ab with a at the origin and b at x: F(r) (x_a − x_b).
                    let g: [f32; D] = std::array::from_fn(|d| -k.grad_factor(r) * x[d]);
                    add_pair(&mut m, v, x, g);
                }
            }
        }
        m
    }

    /// L M = I for the lattice sheared by `s`.
    fn inverts<const D: usize>(s: f32) {
        let m = lattice_m::<D>(0.01, s);
        let l = inverse_or_identity(&m);
        for r in 0..D {
            for c in 0..D {
                let lm: f32 = (0..D).map(|k| l[r][k] * m[k][c]).sum();
                let want = if r == c { 1.0 } else { 0.0 };
                assert!(
                    (lm - want).abs() < 1e-4,
                    "{D}D shear {s}: L M = {lm} at {r}{c}"
                );
            }
        }
    }

    #[test]
    fn corrected_gradients_reproduce_the_identity_in_a_sheared_lattice() {
        for s in [0.0f32, 0.1, 0.25] {
            inverts::<2>(s);
            inverts::<3>(s);
        }
        // The uncorrected M of the unsheared lattice is near the identity already.
        let m = lattice_m::<2>(0.01, 0.0);
        assert!(
            (m[0][0] - 1.0).abs() < 0.05 && m[0][1].abs() < 1e-6,
            "{m:?}"
        );
    }

    #[test]
    fn a_deficient_neighbourhood_keeps_the_plain_gradient() {
        let m = [[0.3f32, 0.0], [0.0, 0.9]];
        assert_eq!(inverse_or_identity(&m), identity::<2>());
        let m3 = [[1.0f32, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 1.0]];
        assert_eq!(inverse_or_identity(&m3), identity::<3>());
    }
}
