//! The sums over a particle's neighbour list that the incompressible scheme's pressure iterations repeat:
//! the divergence Σ_b (v_a − v_b)·∇W_ab and the pressure push Σ_b (k_a + k_b) ∇W_ab, over the gradient
//! records a list holds ([`Grad`]).
//!
//! [`pair_sum`] is the generic loop. In 3D the lists hold each gradient in half precision
//! ([`Half4`], 8 bytes a pair: the lists outgrow the L2 caches and the passes wait on
//! memory) and the solver each velocity in four lanes; on x86_64 with AVX2 and F16C the sums convert
//! two pairs' gradients with one instruction and run two pairs per 256-bit register, one load per
//! neighbour's velocity; the results are the same to the bit as [`pair_sum`]'s over the converted
//! gradients (tested). The 2D lists keep f32 records, summed four pairs per 256-bit register with AVX2 (the
//! same bits as [`pair_sum`]).

use super::half::Half4;

/// Independent partial sums a neighbour-list loop keeps, so that consecutive pairs do not wait for each
/// other's additions (one chain per dimension is bound by the adder's latency, not its throughput).
pub const CHAINS: usize = 4;

/// Σ over a particle's neighbour list of `term(j, ∇W)`, summed in [`CHAINS`] interleaved partial sums (a
/// fixed order: the result depends only on the list, not on threads).
#[inline(always)]
pub fn pair_sum<R: Copy, const W: usize>(
    j: &[u32],
    g: &[R],
    term: impl Fn(u32, R) -> [f32; W],
) -> [f32; W] {
    let mut acc = [[0.0f32; W]; CHAINS];
    let (jc, jr) = j.split_at(j.len() - j.len() % CHAINS);
    let (gc, gr) = g.split_at(jc.len());
    for (js, gs) in jc.chunks_exact(CHAINS).zip(gc.chunks_exact(CHAINS)) {
        for l in 0..CHAINS {
            let t = term(js[l], gs[l]);
            for d in 0..W {
                acc[l][d] += t[d];
            }
        }
    }
    for (l, (jj, gg)) in jr.iter().zip(gr).enumerate() {
        let t = term(*jj, *gg);
        for d in 0..W {
            acc[l][d] += t[d];
        }
    }
    std::array::from_fn(|d| (acc[0][d] + acc[1][d]) + (acc[2][d] + acc[3][d]))
}

/// A kernel gradient as a neighbour list stores it (D dimensions, in W lanes: the velocities the
/// divergence reads have W lanes too), and the two sums of the pressure iterations over such a list.
pub trait Grad<const D: usize, const W: usize>: Copy + PartialEq + std::fmt::Debug {
    /// Whether the 3D neighbourhood pass stores blocks of eight records of this type with AVX2 (F16C).
    const AVX_BLOCKS: bool;

    /// Records hold ∇W · `scale(h)`.
    fn scale(h: f32) -> f32;

    /// The record of the scaled gradient `g`.
    fn pack(g: [f32; D]) -> Self;

    /// The record's lanes in f32.
    fn lanes(self) -> [f32; W];

    /// Σ_b (v_a − v_b) · record_ab per lane (the divergence is the sum of the first D lanes, divided by
    /// the scale).
    ///
    /// # Safety
    /// Every index in `j` is below `vel.len()` (the neighbours' velocities are read unchecked); `wide` only
    /// where [`wide_lanes`](super::candidates::wide_lanes) holds.
    unsafe fn divergence(
        j: &[u32],
        g: &[Self],
        vel: &[[f32; W]],
        va: [f32; W],
        wide: bool,
    ) -> [f32; W];

    /// Σ_b (k_a + k_b) record_ab (as [`Grad::divergence`]).
    ///
    /// # Safety
    /// Every index in `j` is below `k.len()`; `wide` as for [`Grad::divergence`].
    unsafe fn push(j: &[u32], g: &[Self], k: &[f32], ka: f32, wide: bool) -> [f32; W];
}

/// Gradients in f32, the first D of W lanes (the rest 0), unscaled: the 2D lists' records.
impl<const D: usize, const W: usize> Grad<D, W> for [f32; W] {
    const AVX_BLOCKS: bool = false;

    #[inline(always)]
    fn scale(_h: f32) -> f32 {
        1.0
    }

    #[inline(always)]
    fn pack(g: [f32; D]) -> Self {
        std::array::from_fn(|d| if d < D { g[d] } else { 0.0 })
    }

    #[inline(always)]
    fn lanes(self) -> [f32; W] {
        self
    }

    #[inline(always)]
    unsafe fn divergence(
        j: &[u32],
        g: &[Self],
        vel: &[[f32; W]],
        va: [f32; W],
        wide: bool,
    ) -> [f32; W] {
        #[cfg(target_arch = "x86_64")]
        if wide && W == 2 {
            // SAFETY: W == 2, so `[f32; W]` is `[f32; 2]` (same size and alignment); the caller guarantees
            // j < vel.len() and AVX2 (so AVX) where `wide`.
            let r = unsafe { avx::divergence2(j, as_pairs(g), as_pairs(vel), [va[0], va[1]]) };
            return std::array::from_fn(|d| r[d]);
        }
        let _ = wide;
        // SAFETY: as the caller guarantees.
        unsafe { plain_divergence::<D, W, Self>(j, g, vel, va) }
    }

    #[inline(always)]
    unsafe fn push(j: &[u32], g: &[Self], k: &[f32], ka: f32, wide: bool) -> [f32; W] {
        #[cfg(target_arch = "x86_64")]
        if wide && W == 2 {
            // SAFETY: as in `divergence`; the caller guarantees j < k.len().
            let r = unsafe { avx::push2(j, as_pairs(g), k, ka) };
            return std::array::from_fn(|d| r[d]);
        }
        let _ = wide;
        // SAFETY: as the caller guarantees.
        unsafe { plain_push::<D, W, Self>(j, g, k, ka) }
    }
}

/// `[f32; W]` records seen as `[f32; 2]` (the 2D lists').
///
/// # Safety
/// W == 2.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn as_pairs<const W: usize>(v: &[[f32; W]]) -> &[[f32; 2]] {
    debug_assert_eq!(W, 2);
    // SAFETY: with W == 2 the element types are the same.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast(), v.len()) }
}

/// [`Grad::divergence`] by the generic loop over the records' f32 lanes (what every path must equal).
///
/// # Safety
/// Every index in `j` is below `vel.len()`.
#[inline(always)]
unsafe fn plain_divergence<const D: usize, const W: usize, R: Grad<D, W>>(
    j: &[u32],
    g: &[R],
    vel: &[[f32; W]],
    va: [f32; W],
) -> [f32; W] {
    pair_sum(j, g, |j, g| {
        // SAFETY: the caller guarantees j < vel.len().
        let vb = unsafe { vel.get_unchecked(j as usize) };
        let g = g.lanes();
        std::array::from_fn(|d| (va[d] - vb[d]) * g[d])
    })
}

/// [`Grad::push`] by the generic loop over the records' f32 lanes.
///
/// # Safety
/// Every index in `j` is below `k.len()`.
#[inline(always)]
unsafe fn plain_push<const D: usize, const W: usize, R: Grad<D, W>>(
    j: &[u32],
    g: &[R],
    k: &[f32],
    ka: f32,
) -> [f32; W] {
    pair_sum(j, g, |j, g| {
        // SAFETY: the caller guarantees j < k.len().
        let s = ka + unsafe { k.get_unchecked(j as usize) };
        let g = g.lanes();
        std::array::from_fn(|d| s * g[d])
    })
}

/// Gradients × h⁴ in binary16 (D ≤ 3 lanes of four): the 3D lists' records.
impl<const D: usize> Grad<D, 4> for Half4 {
    const AVX_BLOCKS: bool = true;

    #[inline(always)]
    fn scale(h: f32) -> f32 {
        Half4::scale(h)
    }

    #[inline(always)]
    fn pack(g: [f32; D]) -> Self {
        Half4::pack(std::array::from_fn(|d| if d < D { g[d] } else { 0.0 }))
    }

    #[inline(always)]
    fn lanes(self) -> [f32; 4] {
        self.unpack()
    }

    #[inline(always)]
    unsafe fn divergence(
        j: &[u32],
        g: &[Self],
        vel: &[[f32; 4]],
        va: [f32; 4],
        wide: bool,
    ) -> [f32; 4] {
        #[cfg(target_arch = "x86_64")]
        if wide {
            // SAFETY: the caller guarantees j < vel.len() and AVX2 (so AVX and F16C) where `wide`.
            return unsafe { avx::divergence(j, g, vel, va) };
        }
        let _ = wide;
        // SAFETY: as the caller guarantees.
        unsafe { plain_divergence::<D, 4, Self>(j, g, vel, va) }
    }

    #[inline(always)]
    unsafe fn push(j: &[u32], g: &[Self], k: &[f32], ka: f32, wide: bool) -> [f32; 4] {
        #[cfg(target_arch = "x86_64")]
        if wide {
            // SAFETY: the caller guarantees j < k.len() and AVX2 (so AVX and F16C) where `wide`.
            return unsafe { avx::push(j, g, k, ka) };
        }
        let _ = wide;
        // SAFETY: as the caller guarantees.
        unsafe { plain_push::<D, 4, Self>(j, g, k, ka) }
    }
}

/// The half-precision sums two pairs at a time: pairs 4n and 4n + 1 share one 256-bit register (the chains
/// 0 and 1 of [`pair_sum`] in its halves), pairs 4n + 2 and 4n + 3 another, so each lane sees the same
/// additions in the same order as the generic loop and the results are the same to the bit (tested); two
/// records are one 16-byte load and one conversion to f32. The 2D f32 sums take four pairs at a time, the
/// four chains side by side in one register (`divergence2`, `push2`; the same bits too).
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::{Half4, CHAINS};
    use std::arch::x86_64::*;

    /// The chains of [`super::pair_sum`] over `$j`/`$g`: `$two(j0, j1, g01)` gives two pairs' terms from
    /// their gradients (one 256-bit register), `$one(j, g)` one pair's (the remainder, 128 bits). A macro,
    /// not closures: a closure would not inherit the function's target features, and the intrinsics would
    /// be calls.
    macro_rules! chains {
        ($j:expr, $g:expr, |$j0:ident, $j1:ident, $g2:ident| $two:expr, |$j_:ident, $g1:ident| $one:expr) => {{
            let (j, g): (&[u32], &[Half4]) = ($j, $g);
            let (mut a01, mut a23) = (_mm256_setzero_ps(), _mm256_setzero_ps());
            let (jc, jr) = j.split_at(j.len() - j.len() % CHAINS);
            let (gc, gr) = g.split_at(jc.len());
            for (js, gs) in jc.chunks_exact(CHAINS).zip(gc.chunks_exact(CHAINS)) {
                // SAFETY: 16 readable bytes: two consecutive records (pointers from the slice, which covers
                // both).
                let (g01, g23) = unsafe {
                    (
                        _mm256_cvtph_ps(_mm_loadu_si128(gs[..2].as_ptr().cast())),
                        _mm256_cvtph_ps(_mm_loadu_si128(gs[2..].as_ptr().cast())),
                    )
                };
                let ($j0, $j1, $g2) = (js[0], js[1], g01);
                a01 = _mm256_add_ps(a01, $two);
                let ($j0, $j1, $g2) = (js[2], js[3], g23);
                a23 = _mm256_add_ps(a23, $two);
            }
            let mut acc = [
                _mm256_castps256_ps128(a01),
                _mm256_extractf128_ps::<1>(a01),
                _mm256_castps256_ps128(a23),
                _mm256_extractf128_ps::<1>(a23),
            ];
            for (l, (jj, gg)) in jr.iter().zip(gr).enumerate() {
                // SAFETY: 8 readable bytes.
                let ($j_, $g1) = (*jj, _mm_cvtph_ps(unsafe { _mm_loadl_epi64(gg.0.as_ptr().cast()) }));
                acc[l] = _mm_add_ps(acc[l], $one);
            }
            let mut out = [0.0f32; 4];
            // SAFETY: 16 writable bytes.
            unsafe {
                _mm_storeu_ps(
                    out.as_mut_ptr(),
                    _mm_add_ps(_mm_add_ps(acc[0], acc[1]), _mm_add_ps(acc[2], acc[3])),
                )
            };
            out
        }};
    }

    /// Records `a` and `b` in the low and high halves of one register.
    ///
    /// # Safety
    /// The CPU has AVX.
    #[inline]
    #[target_feature(enable = "avx")]
    unsafe fn two(a: &[f32; 4], b: &[f32; 4]) -> __m256 {
        // SAFETY: 16 readable bytes each.
        unsafe {
            _mm256_insertf128_ps::<1>(
                _mm256_castps128_ps256(_mm_loadu_ps(a.as_ptr())),
                _mm_loadu_ps(b.as_ptr()),
            )
        }
    }

    /// [`super::Grad::divergence`] of half records, two pairs at a time.
    ///
    /// # Safety
    /// The CPU has AVX and F16C; every index in `j` is below `vel.len()`.
    #[inline]
    #[target_feature(enable = "avx,f16c")]
    pub(super) unsafe fn divergence(
        j: &[u32],
        g: &[Half4],
        vel: &[[f32; 4]],
        va: [f32; 4],
    ) -> [f32; 4] {
        // SAFETY: 16 readable bytes.
        let va1 = unsafe { _mm_loadu_ps(va.as_ptr()) };
        let va2 = _mm256_set_m128(va1, va1);
        // SAFETY (the neighbours' velocities): the caller guarantees j < vel.len().
        chains!(
            j,
            g,
            |j0, j1, g| unsafe {
                let vb = two(
                    vel.get_unchecked(j0 as usize),
                    vel.get_unchecked(j1 as usize),
                );
                _mm256_mul_ps(_mm256_sub_ps(va2, vb), g)
            },
            |j, g| unsafe {
                let vb = _mm_loadu_ps(vel.get_unchecked(j as usize).as_ptr());
                _mm_mul_ps(_mm_sub_ps(va1, vb), g)
            }
        )
    }

    /// [`super::Grad::push`] of half records, two pairs at a time.
    ///
    /// # Safety
    /// The CPU has AVX and F16C; every index in `j` is below `k.len()`.
    #[inline]
    #[target_feature(enable = "avx,f16c")]
    pub(super) unsafe fn push(j: &[u32], g: &[Half4], k: &[f32], ka: f32) -> [f32; 4] {
        // SAFETY (the neighbours' k): the caller guarantees j < k.len().
        chains!(
            j,
            g,
            |j0, j1, g| unsafe {
                let (s0, s1) = (
                    ka + k.get_unchecked(j0 as usize),
                    ka + k.get_unchecked(j1 as usize),
                );
                _mm256_mul_ps(_mm256_set_m128(_mm_set1_ps(s1), _mm_set1_ps(s0)), g)
            },
            |j, g| unsafe { _mm_mul_ps(_mm_set1_ps(ka + k.get_unchecked(j as usize)), g) }
        )
    }

    /// The chains of [`super::pair_sum`] over 2D f32 records, all four in one 256-bit register (chain l in
    /// lanes 2l and 2l + 1): `$four(js, g)` gives the terms of four pairs (`js` their indices, `g` their four
    /// records, one 32-byte load), the remainder goes pair by pair into chains 0, 1, 2, so every lane sees
    /// the generic loop's additions in its order.
    macro_rules! chains2 {
        ($j:expr, $g:expr, |$js:ident, $g4:ident| $four:expr, |$j1:ident, $gr:ident| $one:expr) => {{
            let (j, g): (&[u32], &[[f32; 2]]) = ($j, $g);
            let mut acc = _mm256_setzero_ps();
            let (jc, jr) = j.split_at(j.len() - j.len() % CHAINS);
            let (gc, gr) = g.split_at(jc.len());
            for ($js, gs) in jc.chunks_exact(CHAINS).zip(gc.chunks_exact(CHAINS)) {
                // SAFETY: 32 readable bytes: four consecutive records.
                let $g4 = unsafe { _mm256_loadu_ps(gs.as_ptr().cast()) };
                acc = _mm256_add_ps(acc, $four);
            }
            let mut c = [0.0f32; 8];
            // SAFETY: 32 writable bytes.
            unsafe { _mm256_storeu_ps(c.as_mut_ptr(), acc) };
            for (l, ($j1, $gr)) in jr.iter().zip(gr).enumerate() {
                let t: [f32; 2] = $one;
                c[2 * l] += t[0];
                c[2 * l + 1] += t[1];
            }
            [(c[0] + c[2]) + (c[4] + c[6]), (c[1] + c[3]) + (c[5] + c[7])]
        }};
    }

    /// The four 2D records (8 bytes each) `p[js[0]]` … `p[js[3]]` in one register, in that order.
    ///
    /// # Safety
    /// The CPU has AVX; `js` holds at least four indices, each below `p.len()`.
    #[inline]
    #[target_feature(enable = "avx")]
    unsafe fn four(p: &[[f32; 2]], js: &[u32]) -> __m256 {
        // SAFETY: the caller guarantees the indices; 8 readable bytes each.
        unsafe {
            let at =
                |l: usize| p.get_unchecked(*js.get_unchecked(l) as usize).as_ptr() as *const f64;
            let lo = _mm_loadh_pd(_mm_load_sd(at(0)), at(1));
            let hi = _mm_loadh_pd(_mm_load_sd(at(2)), at(3));
            _mm256_castpd_ps(_mm256_set_m128d(hi, lo))
        }
    }

    /// [`super::Grad::divergence`] of 2D f32 records, four pairs at a time.
    ///
    /// # Safety
    /// The CPU has AVX; every index in `j` is below `vel.len()`.
    #[inline]
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn divergence2(
        j: &[u32],
        g: &[[f32; 2]],
        vel: &[[f32; 2]],
        va: [f32; 2],
    ) -> [f32; 2] {
        let va4 = _mm256_castpd_ps(_mm256_set1_pd(f64::from_bits(
            (va[0].to_bits() as u64) | (va[1].to_bits() as u64) << 32,
        )));
        // SAFETY (the neighbours' velocities): the caller guarantees j < vel.len().
        chains2!(
            j,
            g,
            |js, g| unsafe { _mm256_mul_ps(_mm256_sub_ps(va4, four(vel, js)), g) },
            |jj, gg| {
                // SAFETY: as above.
                let vb = unsafe { vel.get_unchecked(*jj as usize) };
                [(va[0] - vb[0]) * gg[0], (va[1] - vb[1]) * gg[1]]
            }
        )
    }

    /// [`super::Grad::push`] of 2D f32 records, four pairs at a time.
    ///
    /// # Safety
    /// The CPU has AVX; every index in `j` is below `k.len()`.
    #[inline]
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn push2(j: &[u32], g: &[[f32; 2]], k: &[f32], ka: f32) -> [f32; 2] {
        let ka4 = _mm_set1_ps(ka);
        // SAFETY (the neighbours' k): the caller guarantees j < k.len().
        chains2!(
            j,
            g,
            |js, g| unsafe {
                let kk = |l: usize| *k.get_unchecked(*js.get_unchecked(l) as usize);
                // ka + k_j for the four pairs, each twice (x and y lanes).
                let s = _mm_add_ps(ka4, _mm_set_ps(kk(3), kk(2), kk(1), kk(0)));
                let s2 = _mm256_set_m128(_mm_unpackhi_ps(s, s), _mm_unpacklo_ps(s, s));
                _mm256_mul_ps(s2, g)
            },
            |jj, gg| {
                // SAFETY: as above.
                let s = ka + unsafe { k.get_unchecked(*jj as usize) };
                [s * gg[0], s * gg[1]]
            }
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fast::candidates::wide_lanes;

    /// A made-up list of `len` neighbours among 50 particles (lanes beyond 3 zero, as the solver keeps
    /// them), their gradients as half records and velocities, and k.
    #[allow(clippy::type_complexity)]
    fn data(len: usize) -> (Vec<u32>, Vec<Half4>, Vec<[f32; 4]>, Vec<f32>) {
        let mut s = 0x2545_f491_u32;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s as f32 / u32::MAX as f32) * 2.0 - 1.0
        };
        let v4 = |r: &mut dyn FnMut() -> f32| [r(), r(), r(), 0.0];
        let j = (0..len).map(|i| ((i * 37 + 11) % 50) as u32).collect();
        let g = (0..len)
            .map(|_| <Half4 as Grad<3, 4>>::pack([r(), r(), r()]))
            .collect();
        let vel = (0..50).map(|_| v4(&mut r)).collect();
        let k = (0..50).map(|_| r().abs() * 1e3).collect();
        (j, g, vel, k)
    }

    /// The loops this CPU can run: the generic one always, the AVX2 one where it has it.
    fn ways() -> Vec<bool> {
        if wide_lanes() {
            vec![false, true]
        } else {
            vec![false]
        }
    }

    #[test]
    fn half_record_sums_equal_the_f32_loop_over_their_values_to_the_bit() {
        // Every remainder of the chains, and an empty list.
        for len in [0, 1, 2, 3, 4, 5, 7, 8, 61, 74] {
            let (j, g, vel, k) = data(len);
            // The same gradients as f32 records: the generic loop.
            let g32: Vec<[f32; 4]> = g.iter().map(|h| h.unpack()).collect();
            let va = vel[3];
            // SAFETY (here and below): every j < 50, the particles' count; `wide` only where
            // `wide_lanes()` holds.
            let plain = unsafe { <[f32; 4] as Grad<3, 4>>::divergence(&j, &g32, &vel, va, false) };
            for wide in ways() {
                let fast = unsafe { <Half4 as Grad<3, 4>>::divergence(&j, &g, &vel, va, wide) };
                assert_eq!(
                    plain.map(f32::to_bits),
                    fast.map(f32::to_bits),
                    "divergence, {len} pairs, wide {wide}"
                );
            }
            let plain = unsafe { <[f32; 4] as Grad<3, 4>>::push(&j, &g32, &k, k[7], false) };
            for wide in ways() {
                let fast = unsafe { <Half4 as Grad<3, 4>>::push(&j, &g, &k, k[7], wide) };
                assert_eq!(
                    plain.map(f32::to_bits),
                    fast.map(f32::to_bits),
                    "push, {len} pairs, wide {wide}"
                );
            }
            assert!(len == 0 || plain.iter().any(|x| *x != 0.0));
            assert_eq!(plain[3], 0.0, "the padding lane");
        }
    }

    #[test]
    fn two_dimensional_sums_four_pairs_at_a_time_equal_the_generic_loop_to_the_bit() {
        for len in [0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 19, 22] {
            let (j, g, vel, k) = data(len);
            let two = |v: &[f32; 4]| [v[0], v[1]];
            let g2: Vec<[f32; 2]> = g.iter().map(|h| two(&h.unpack())).collect();
            let vel2: Vec<[f32; 2]> = vel.iter().map(two).collect();
            let va = vel2[3];
            // SAFETY: every j < 50, the particles' count; `wide` only where `wide_lanes()` holds.
            let (d, p) = unsafe {
                (
                    plain_divergence::<2, 2, [f32; 2]>(&j, &g2, &vel2, va),
                    plain_push::<2, 2, [f32; 2]>(&j, &g2, &k, k[7]),
                )
            };
            for wide in ways() {
                // SAFETY: as above.
                let (fd, fp) = unsafe {
                    (
                        <[f32; 2] as Grad<2, 2>>::divergence(&j, &g2, &vel2, va, wide),
                        <[f32; 2] as Grad<2, 2>>::push(&j, &g2, &k, k[7], wide),
                    )
                };
                assert_eq!(
                    d.map(f32::to_bits),
                    fd.map(f32::to_bits),
                    "divergence, {len} pairs, wide {wide}"
                );
                assert_eq!(
                    p.map(f32::to_bits),
                    fp.map(f32::to_bits),
                    "push, {len} pairs, wide {wide}"
                );
            }
            assert!(len == 0 || (d.iter().any(|x| *x != 0.0) && p.iter().any(|x| *x != 0.0)));
        }
    }

    #[test]
    fn three_lane_sums_match_the_four_lane_ones() {
        // 3D without padding against the padded lanes: the same first three lanes.
        let (j, g, vel, k) = data(61);
        let g4: Vec<[f32; 4]> = g.iter().map(|h| h.unpack()).collect();
        let cut = |v: &[[f32; 4]]| v.iter().map(|x| [x[0], x[1], x[2]]).collect::<Vec<_>>();
        let (g3, vel3) = (cut(&g4), cut(&vel));
        // SAFETY: every j < 50, the particles' count.
        let (d3, d4, p3, p4) = unsafe {
            (
                <[f32; 3] as Grad<3, 3>>::divergence(&j, &g3, &vel3, vel3[3], false),
                <[f32; 4] as Grad<3, 4>>::divergence(&j, &g4, &vel, vel[3], false),
                <[f32; 3] as Grad<3, 3>>::push(&j, &g3, &k, k[7], false),
                <[f32; 4] as Grad<3, 4>>::push(&j, &g4, &k, k[7], false),
            )
        };
        for d in 0..3 {
            assert_eq!(d3[d].to_bits(), d4[d].to_bits());
            assert_eq!(p3[d].to_bits(), p4[d].to_bits());
        }
    }
}
