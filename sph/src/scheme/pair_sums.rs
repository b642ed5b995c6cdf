//! The sums over a particle's neighbour list that the incompressible scheme's pressure iterations repeat:
//! the divergence Σ_b (v_a − v_b)·∇W_ab and the pressure push Σ_b (k_a + k_b) ∇W_ab.
//!
//! [`pair_sum`] is the generic loop; in 3D the lists hold each gradient (and the solver each velocity) in
//! four lanes, and on x86_64 [`divergence`] and [`push`] run the same additions in the same order on
//! 128-bit registers: one load per neighbour's velocity and one per gradient instead of three each (the
//! loops were bound by loads), and where the CPU has AVX two neighbours per 256-bit register. The results
//! are the same to the bit as [`pair_sum`]'s (tested).

/// Independent partial sums a neighbour-list loop keeps, so that consecutive pairs do not wait for each
/// other's additions (one chain per dimension is bound by the adder's latency, not its throughput).
pub const CHAINS: usize = 4;

/// Σ over a particle's neighbour list of `term(j, ∇W)`, summed in [`CHAINS`] interleaved partial sums (a
/// fixed order: the result depends only on the list, not on threads).
#[inline(always)]
pub fn pair_sum<const W: usize>(
    j: &[u32],
    g: &[[f32; W]],
    term: impl Fn(u32, &[f32; W]) -> [f32; W],
) -> [f32; W] {
    let mut acc = [[0.0f32; W]; CHAINS];
    let (jc, jr) = j.split_at(j.len() - j.len() % CHAINS);
    let (gc, gr) = g.split_at(jc.len());
    for (js, gs) in jc.chunks_exact(CHAINS).zip(gc.chunks_exact(CHAINS)) {
        for l in 0..CHAINS {
            let t = term(js[l], &gs[l]);
            for d in 0..W {
                acc[l][d] += t[d];
            }
        }
    }
    for (l, (jj, gg)) in jr.iter().zip(gr).enumerate() {
        let t = term(*jj, gg);
        for d in 0..W {
            acc[l][d] += t[d];
        }
    }
    std::array::from_fn(|d| (acc[0][d] + acc[1][d]) + (acc[2][d] + acc[3][d]))
}

/// Σ_b (v_a − v_b) ∇W_ab per lane (the divergence is the sum of its first D lanes); in four lanes two pairs
/// at a time on 256-bit registers where `wide`.
///
/// # Safety
/// Every index in `j` is below `vel.len()` (the neighbours' velocities are read unchecked); `wide` only
/// where the CPU has AVX.
#[inline(always)]
pub unsafe fn divergence<const W: usize>(
    j: &[u32],
    g: &[[f32; W]],
    vel: &[[f32; W]],
    va: [f32; W],
    wide: bool,
) -> [f32; W] {
    #[cfg(target_arch = "x86_64")]
    if W == 4 {
        let va = std::array::from_fn(|d| va[d]);
        // SAFETY: W == 4, so these are the same types; the caller guarantees j < vel.len() and AVX where
        // `wide`.
        let r = unsafe {
            if wide {
                avx::divergence(j, as4(g), as4(vel), va)
            } else {
                sse::divergence(j, as4(g), as4(vel), va)
            }
        };
        return std::array::from_fn(|d| r[d]);
    }
    let _ = wide;
    pair_sum(j, g, |j, g| {
        // SAFETY: the caller guarantees j < vel.len().
        let vb = unsafe { vel.get_unchecked(j as usize) };
        std::array::from_fn(|d| (va[d] - vb[d]) * g[d])
    })
}

/// Σ_b (k_a + k_b) ∇W_ab (as [`divergence`] where `wide`).
///
/// # Safety
/// Every index in `j` is below `k.len()` (the neighbours' k are read unchecked); `wide` only where the CPU
/// has AVX.
#[inline(always)]
pub unsafe fn push<const W: usize>(
    j: &[u32],
    g: &[[f32; W]],
    k: &[f32],
    ka: f32,
    wide: bool,
) -> [f32; W] {
    #[cfg(target_arch = "x86_64")]
    if W == 4 {
        // SAFETY: W == 4, so these are the same types; the caller guarantees j < k.len() and AVX where
        // `wide`.
        let r = unsafe {
            if wide {
                avx::push(j, as4(g), k, ka)
            } else {
                sse::push(j, as4(g), k, ka)
            }
        };
        return std::array::from_fn(|d| r[d]);
    }
    let _ = wide;
    pair_sum(j, g, |j, g| {
        // SAFETY: the caller guarantees j < k.len().
        let s = ka + unsafe { k.get_unchecked(j as usize) };
        std::array::from_fn(|d| s * g[d])
    })
}

/// `[[f32; W]]` as `[[f32; 4]]`.
///
/// # Safety
/// W must be 4.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn as4<const W: usize>(v: &[[f32; W]]) -> &[[f32; 4]] {
    assert_eq!(W, 4);
    // SAFETY: the caller guarantees W == 4: same size, alignment and layout.
    unsafe { std::slice::from_raw_parts(v.as_ptr().cast(), v.len()) }
}

#[cfg(target_arch = "x86_64")]
mod sse {
    use super::CHAINS;
    use std::arch::x86_64::*;

    #[inline(always)]
    fn load(v: &[f32; 4]) -> __m128 {
        // SAFETY: 16 readable bytes (SSE is part of x86_64).
        unsafe { _mm_loadu_ps(v.as_ptr()) }
    }

    #[inline(always)]
    fn lanes(v: __m128) -> [f32; 4] {
        let mut out = [0.0f32; 4];
        // SAFETY: 16 writable bytes.
        unsafe { _mm_storeu_ps(out.as_mut_ptr(), v) };
        out
    }

    /// [`super::pair_sum`]'s chains and closing additions on four lanes.
    #[inline(always)]
    fn chains(j: &[u32], g: &[[f32; 4]], term: impl Fn(u32, __m128) -> __m128) -> [f32; 4] {
        // SAFETY (the arithmetic intrinsics below): SSE is part of x86_64; they touch no memory (`load` has
        // its own note).
        let mut acc = [unsafe { _mm_setzero_ps() }; CHAINS];
        let (jc, jr) = j.split_at(j.len() - j.len() % CHAINS);
        let (gc, gr) = g.split_at(jc.len());
        for (js, gs) in jc.chunks_exact(CHAINS).zip(gc.chunks_exact(CHAINS)) {
            for l in 0..CHAINS {
                acc[l] = unsafe { _mm_add_ps(acc[l], term(js[l], load(&gs[l]))) };
            }
        }
        for (l, (jj, gg)) in jr.iter().zip(gr).enumerate() {
            acc[l] = unsafe { _mm_add_ps(acc[l], term(*jj, load(gg))) };
        }
        lanes(unsafe { _mm_add_ps(_mm_add_ps(acc[0], acc[1]), _mm_add_ps(acc[2], acc[3])) })
    }

    /// [`super::divergence`] in four lanes.
    ///
    /// # Safety
    /// Every index in `j` is below `vel.len()`.
    #[inline(always)]
    pub(super) unsafe fn divergence(
        j: &[u32],
        g: &[[f32; 4]],
        vel: &[[f32; 4]],
        va: [f32; 4],
    ) -> [f32; 4] {
        let va = load(&va);
        chains(j, g, |j, g| {
            // SAFETY: the caller guarantees j < vel.len().
            let vb = load(unsafe { vel.get_unchecked(j as usize) });
            // SAFETY: SSE is part of x86_64.
            unsafe { _mm_mul_ps(_mm_sub_ps(va, vb), g) }
        })
    }

    /// [`super::push`] in four lanes.
    ///
    /// # Safety
    /// Every index in `j` is below `k.len()`.
    #[inline(always)]
    pub(super) unsafe fn push(j: &[u32], g: &[[f32; 4]], k: &[f32], ka: f32) -> [f32; 4] {
        chains(j, g, |j, g| {
            // SAFETY: SSE is part of x86_64.
            // SAFETY: the caller guarantees j < k.len().
            unsafe { _mm_mul_ps(_mm_set1_ps(ka + k.get_unchecked(j as usize)), g) }
        })
    }
}

/// The four-lane sums two pairs at a time: pairs 4n and 4n + 1 share one 256-bit register (the chains 0 and
/// 1 of [`super::pair_sum`] in its halves), pairs 4n + 2 and 4n + 3 another, so each lane sees the same
/// additions in the same order as the 128-bit loop and the results are the same to the bit (tested); a
/// pair of gradients is one 32-byte load, and the arithmetic is half the instructions.
#[cfg(target_arch = "x86_64")]
mod avx {
    use super::CHAINS;
    use std::arch::x86_64::*;

    /// The chains of [`super::pair_sum`] over `$j`/`$g`: `$two(j0, j1, g01)` gives two pairs' terms from
    /// their gradients (one 256-bit register), `$one(j, g)` one pair's (the remainder, 128 bits). A macro,
    /// not closures: a closure would not inherit the function's AVX, and the intrinsics would be calls.
    macro_rules! chains {
        ($j:expr, $g:expr, |$j0:ident, $j1:ident, $g2:ident| $two:expr, |$j_:ident, $g1:ident| $one:expr) => {{
            let (j, g): (&[u32], &[[f32; 4]]) = ($j, $g);
            let (mut a01, mut a23) = (_mm256_setzero_ps(), _mm256_setzero_ps());
            let (jc, jr) = j.split_at(j.len() - j.len() % CHAINS);
            let (gc, gr) = g.split_at(jc.len());
            for (js, gs) in jc.chunks_exact(CHAINS).zip(gc.chunks_exact(CHAINS)) {
                // SAFETY: 32 readable bytes: two consecutive records (pointers from the slice, which covers
                // both).
                let (g01, g23) = unsafe {
                    (
                        _mm256_loadu_ps(gs[..2].as_ptr().cast()),
                        _mm256_loadu_ps(gs[2..].as_ptr().cast()),
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
                // SAFETY: 16 readable bytes.
                let ($j_, $g1) = (*jj, unsafe { _mm_loadu_ps(gg.as_ptr()) });
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

    /// [`super::divergence`], two pairs at a time.
    ///
    /// # Safety
    /// The CPU has AVX; every index in `j` is below `vel.len()`.
    #[inline]
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn divergence(
        j: &[u32],
        g: &[[f32; 4]],
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

    /// [`super::push`], two pairs at a time.
    ///
    /// # Safety
    /// The CPU has AVX; every index in `j` is below `k.len()`.
    #[inline]
    #[target_feature(enable = "avx")]
    pub(super) unsafe fn push(j: &[u32], g: &[[f32; 4]], k: &[f32], ka: f32) -> [f32; 4] {
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
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A made-up list of `len` neighbours among 50 particles (lanes beyond 3 zero, as the solver keeps
    /// them), their gradients and velocities, and k.
    #[allow(clippy::type_complexity)]
    fn data(len: usize) -> (Vec<u32>, Vec<[f32; 4]>, Vec<[f32; 4]>, Vec<f32>) {
        let mut s = 0x2545_f491_u32;
        let mut r = move || {
            s ^= s << 13;
            s ^= s >> 17;
            s ^= s << 5;
            (s as f32 / u32::MAX as f32) * 2.0 - 1.0
        };
        let v4 = |r: &mut dyn FnMut() -> f32| [r(), r(), r(), 0.0];
        let j = (0..len).map(|i| ((i * 37 + 11) % 50) as u32).collect();
        let g = (0..len).map(|_| v4(&mut r)).collect();
        let vel = (0..50).map(|_| v4(&mut r)).collect();
        let k = (0..50).map(|_| r().abs() * 1e3).collect();
        (j, g, vel, k)
    }

    /// The loops a CPU can run: the 128-bit one always, the 256-bit one where it has AVX.
    fn ways() -> Vec<bool> {
        #[cfg(target_arch = "x86_64")]
        if std::arch::is_x86_feature_detected!("avx") {
            return vec![false, true];
        }
        vec![false]
    }

    #[test]
    fn four_lane_sums_equal_the_generic_loop_to_the_bit() {
        // Every remainder of the chains, and an empty list.
        for len in [0, 1, 2, 3, 4, 5, 7, 8, 61, 74] {
            let (j, g, vel, k) = data(len);
            let va = vel[3];
            let plain = pair_sum(&j, &g, |j, g| {
                let vb = vel[j as usize];
                std::array::from_fn(|d| (va[d] - vb[d]) * g[d])
            });
            for wide in ways() {
                // SAFETY (here and below): every j < 50, the particles' count; AVX where `wide`.
                let fast = unsafe { divergence(&j, &g, &vel, va, wide) };
                assert_eq!(
                    plain.map(f32::to_bits),
                    fast.map(f32::to_bits),
                    "divergence, {len} pairs, wide {wide}"
                );
            }
            let plain = pair_sum(&j, &g, |j, g| {
                let s = k[7] + k[j as usize];
                std::array::from_fn(|d| s * g[d])
            });
            for wide in ways() {
                let fast = unsafe { push(&j, &g, &k, k[7], wide) };
                assert_eq!(
                    plain.map(f32::to_bits),
                    fast.map(f32::to_bits),
                    "push, {len} pairs, wide {wide}"
                );
            }
            assert!(len == 0 || plain.iter().any(|x| *x != 0.0));
        }
    }

    #[test]
    fn three_lane_sums_match_the_four_lane_ones() {
        // 3D without padding (the generic loop) against the padded lanes: same first three lanes.
        let (j, g, vel, k) = data(61);
        let cut = |v: &[[f32; 4]]| v.iter().map(|x| [x[0], x[1], x[2]]).collect::<Vec<_>>();
        let (g3, vel3) = (cut(&g), cut(&vel));
        // SAFETY: every j < 50, the particles' count.
        let (d3, d4, p3, p4) = unsafe {
            (
                divergence(&j, &g3, &vel3, vel3[3], false),
                divergence(&j, &g, &vel, vel[3], false),
                push(&j, &g3, &k, k[7], false),
                push(&j, &g, &k, k[7], false),
            )
        };
        for d in 0..3 {
            assert_eq!(d3[d].to_bits(), d4[d].to_bits());
            assert_eq!(p3[d].to_bits(), p4[d].to_bits());
        }
        assert_eq!(d4[3], 0.0);
    }
}
