//! The neighbours of one particle, sifted straight from the particle arrays: for each row of grid cells
//! around it (one contiguous range of the cell-sorted arrays), the candidates closer than the reach are
//! packed, in candidate order, into contiguous struct-of-arrays buffers (offset x_a − x_b, the neighbour's
//! velocity along it, index) padded to whole blocks of [`LANES`]. The pair loop then reads whole blocks of
//! neighbours with plain loads: no copy of the candidates, no gather of the selected ones. (Measured on the
//! 3D seed tank, one thread: the neighbourhood pass 10 % shorter than copying the candidates of a run of
//! three cells once and gathering each particle's selection from the copy; storing the velocities and
//! squared distances too, instead of v_b·(x_a − x_b), was no faster than the copy.)
//!
//! On x86_64 with AVX2 each block of eight candidates is packed with one permutation per array (the
//! selected lanes to the front, `PACK`) and one 32-byte store; elsewhere lane by lane. Both compute the
//! offsets, squared lengths and velocities along the offsets with the same operations in the same order (no
//! fused multiply-add), so they select the same neighbours and store the same values to the bit.

use super::candidates::{Room, LANES};

/// Where padding entries sit (offset in every dimension): far outside any support, small enough that
/// squares stay finite in f32. Their velocity is 0 and their index `u32::MAX`.
const FAR: f32 = 1.0e15;

/// For each 8-bit mask of lanes, the set lanes in order (the rest: don't care), as the lane permutation
/// that packs them to the front of a block.
#[repr(align(32))]
pub(crate) struct Pack(pub(crate) [[u32; LANES]; 1 << LANES]);

pub(crate) static PACK: Pack = {
    let mut t = [[0u32; LANES]; 1 << LANES];
    let mut m = 0;
    while m < 1 << LANES {
        let mut n = 0;
        let mut l = 0;
        while l < LANES {
            if m & (1 << l) != 0 {
                t[m][n] = l as u32;
                n += 1;
            }
            l += 1;
        }
        m += 1;
    }
    Pack(t)
};

/// The selected neighbours of one particle ([`Near::select`]), padded to whole blocks of [`LANES`].
#[derive(Clone, Debug)]
pub struct Near<const D: usize> {
    /// x_a − x_b per dimension.
    pub dx: [Vec<f32>; D],
    /// v_b·(x_a − x_b): the neighbour's velocity along the offset (all a pair sum needs of it).
    pub w: Vec<f32>,
    /// The neighbour's index in the particle arrays.
    pub idx: Vec<u32>,
    /// The most candidates (plus a block) a selection has had to make room for ([`Room`]).
    peak: usize,
}

impl<const D: usize> Default for Near<D> {
    fn default() -> Self {
        Self {
            dx: std::array::from_fn(|_| Vec::new()),
            w: Vec::new(),
            idx: Vec::new(),
            peak: 0,
        }
    }
}

impl<const D: usize> Room for Near<D> {
    fn peak(&self) -> usize {
        self.peak
    }
    fn capacity(&self) -> usize {
        let dx = self
            .dx
            .iter()
            .map(Vec::capacity)
            .min()
            .unwrap_or(usize::MAX);
        dx.min(self.w.capacity()).min(self.idx.capacity())
    }
    fn reserve(&mut self, room: usize) {
        fn to<T>(v: &mut Vec<T>, room: usize) {
            v.reserve(room.saturating_sub(v.len()));
        }
        for d in 0..D {
            to(&mut self.dx[d], room);
        }
        to(&mut self.w, room);
        to(&mut self.idx, room);
    }
}

impl<const D: usize> Near<D> {
    /// Selects, among the particles of `rows` (ranges of the arrays `x`, `v`), those closer to `xa` than
    /// √`reach2` (`xa` itself included if it is among them), in order, and pads them to whole blocks.
    /// `wide`: pack with AVX2 (where [`super::candidates::wide_lanes`] holds; checked again here).
    #[inline(always)]
    pub fn select(
        &mut self,
        xa: [f32; D],
        reach2: f32,
        rows: &[(u32, u32)],
        (x, v): (&[Vec<f32>; D], &[Vec<f32>; D]),
        wide: bool,
    ) {
        let len = x[0].len();
        assert!(x.iter().chain(v).all(|a| a.len() == len));
        assert!(rows.iter().all(|&(lo, hi)| lo <= hi && hi as usize <= len));
        let total: usize = rows.iter().map(|&(lo, hi)| (hi - lo) as usize).sum();
        // Every block writes a whole block at the end of the selection, and the padding fills the last.
        let room = total + LANES;
        self.peak = self.peak.max(room);
        if self.capacity() < room {
            self.reserve(2 * room);
        }
        let n = {
            #[cfg(target_arch = "x86_64")]
            if wide && len >= LANES && super::candidates::wide_lanes() {
                // SAFETY: the CPU has AVX2 and popcnt (checked just above); the arrays hold a block, the rows
                // lie within them (asserted above) and every array has room for `total + LANES`
                // (reserved above).
                unsafe { self.pack_avx2(xa, reach2, rows, (x, v)) }
            } else {
                self.pack(xa, reach2, rows, (x, v))
            }
            #[cfg(not(target_arch = "x86_64"))]
            {
                let _ = wide;
                self.pack(xa, reach2, rows, (x, v))
            }
        };
        // SAFETY: the first n entries of every array were written, and n + padding ≤ total + LANES.
        unsafe { self.pad_from(n) };
    }

    /// Lane by lane.
    fn pack(
        &mut self,
        xa: [f32; D],
        reach2: f32,
        rows: &[(u32, u32)],
        (x, v): (&[Vec<f32>; D], &[Vec<f32>; D]),
    ) -> usize {
        for d in 0..D {
            self.dx[d].clear();
        }
        self.w.clear();
        self.idx.clear();
        for &(lo, hi) in rows {
            for b in lo as usize..hi as usize {
                let dx: [f32; D] = std::array::from_fn(|d| xa[d] - x[d][b]);
                let mut r2 = dx[0] * dx[0];
                for d in 1..D {
                    r2 += dx[d] * dx[d];
                }
                let mut w = v[0][b] * dx[0];
                for d in 1..D {
                    w += v[d][b] * dx[d];
                }
                if r2 < reach2 {
                    for d in 0..D {
                        self.dx[d].push(dx[d]);
                    }
                    self.w.push(w);
                    self.idx.push(b as u32);
                }
            }
        }
        self.idx.len()
    }

    /// Eight candidates at a time, packed with a lane permutation and written as whole blocks; returns the
    /// number selected (the arrays' lengths are left for [`Self::pad_from`] to set). A block is loaded
    /// from at most `len − 8` (no copy at the arrays' end) and keeps only its lanes within its row.
    ///
    /// # Safety
    /// The CPU has AVX2 and popcnt, the arrays hold at least [`LANES`] particles, every row lies within
    /// them, and every array of `self` has capacity for the rows' particles plus [`LANES`].
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2,popcnt")]
    unsafe fn pack_avx2(
        &mut self,
        xa: [f32; D],
        reach2: f32,
        rows: &[(u32, u32)],
        (x, v): (&[Vec<f32>; D], &[Vec<f32>; D]),
    ) -> usize {
        use std::arch::x86_64::*;
        let last = x[0].len() - LANES;
        let odx: [*mut f32; D] = std::array::from_fn(|d| self.dx[d].as_mut_ptr());
        let ow = self.w.as_mut_ptr();
        let oidx = self.idx.as_mut_ptr();
        let reach = _mm256_set1_ps(reach2);
        let own: [__m256; D] = std::array::from_fn(|d| _mm256_set1_ps(xa[d]));
        let lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
        let mut n = 0usize;
        // Candidates s..hi, those of the block loaded from min(s, last): lanes below s (where the load
        // was moved back) and from hi on are not kept.
        let block = |s: usize, hi: usize, n: &mut usize| {
            let at = s.min(last);
            let below = (s - at).min(LANES) as u32;
            let upto = hi.saturating_sub(at).min(LANES) as u32;
            let valid = ((1u32 << upto) - 1) & !((1u32 << below) - 1);
            let dx: [__m256; D] = std::array::from_fn(|d| {
                _mm256_sub_ps(own[d], _mm256_loadu_ps(x[d].as_ptr().add(at)))
            });
            let mut r2 = _mm256_mul_ps(dx[0], dx[0]);
            for d in 1..D {
                r2 = _mm256_add_ps(r2, _mm256_mul_ps(dx[d], dx[d]));
            }
            let inside = _mm256_movemask_ps(_mm256_cmp_ps::<_CMP_LT_OQ>(r2, reach)) as u32;
            let mask = (inside & valid) as usize;
            let perm = _mm256_load_si256(PACK.0[mask].as_ptr() as *const __m256i);
            let vs = |d: usize| _mm256_loadu_ps(v[d].as_ptr().add(at));
            let mut w = _mm256_mul_ps(vs(0), dx[0]);
            for d in 1..D {
                w = _mm256_add_ps(w, _mm256_mul_ps(vs(d), dx[d]));
            }
            for d in 0..D {
                _mm256_storeu_ps(odx[d].add(*n), _mm256_permutevar8x32_ps(dx[d], perm));
            }
            _mm256_storeu_ps(ow.add(*n), _mm256_permutevar8x32_ps(w, perm));
            let idx = _mm256_add_epi32(_mm256_set1_epi32(at as i32), lane);
            _mm256_storeu_si256(
                oidx.add(*n) as *mut __m256i,
                _mm256_permutevar8x32_epi32(idx, perm),
            );
            *n += mask.count_ones() as usize;
        };
        for &(lo, hi) in rows {
            let (mut s, hi) = (lo as usize, hi as usize);
            while s < hi {
                block(s, hi, &mut n);
                s += LANES;
            }
        }
        n
    }

    /// Pads the selection of `n` to whole blocks with far-away entries and sets the arrays' lengths.
    ///
    /// # Safety
    /// The first `n` entries of every array are written, and every array has capacity for `n` rounded up
    /// to whole blocks.
    unsafe fn pad_from(&mut self, n: usize) {
        let padded = n.div_ceil(LANES) * LANES;
        for i in n..padded {
            for d in 0..D {
                self.dx[d].as_mut_ptr().add(i).write(FAR);
            }
            self.w.as_mut_ptr().add(i).write(0.0);
            self.idx.as_mut_ptr().add(i).write(u32::MAX);
        }
        for d in 0..D {
            self.dx[d].set_len(padded);
        }
        self.w.set_len(padded);
        self.idx.set_len(padded);
    }

    /// Number of blocks of [`LANES`] selected.
    #[inline]
    pub fn blocks(&self) -> usize {
        self.idx.len() / LANES
    }

    /// Block `b`: offsets x_a − x_b, v_b·(x_a − x_b) and indices of its lanes.
    #[inline(always)]
    pub fn block(&self, b: usize) -> ([[f32; LANES]; D], [f32; LANES], [u32; LANES]) {
        let s = b * LANES..(b + 1) * LANES;
        let lane = |v: &[f32]| -> [f32; LANES] { v[s.clone()].try_into().expect("whole block") };
        (
            std::array::from_fn(|d| lane(&self.dx[d])),
            lane(&self.w),
            self.idx[s.clone()].try_into().expect("whole block"),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::super::candidates::{test_noise, wide_lanes};
    use super::*;

    /// Every way through `select` (lane by lane, packed, rows ending at the arrays' end, empty rows) keeps
    /// exactly the particles in reach, in order, with their offsets and velocities along them to the bit.
    fn check<const D: usize>() {
        let mut rnd = test_noise(3 + D as u64);
        let n = 61;
        let x: [Vec<f32>; D] = std::array::from_fn(|_| (0..n).map(|_| rnd()).collect());
        let v: [Vec<f32>; D] = std::array::from_fn(|_| (0..n).map(|_| rnd()).collect());
        let rows = [(0u32, 20u32), (20, 20), (23, 35), (40, n as u32)];
        let xa: [f32; D] = std::array::from_fn(|d| [0.1f32, -0.05, 0.0][d]);
        let reach2 = 0.16f32;
        let want: Vec<usize> = rows
            .iter()
            .flat_map(|&(lo, hi)| lo as usize..hi as usize)
            .filter(|&i| {
                let dx: [f32; D] = std::array::from_fn(|d| xa[d] - x[d][i]);
                let mut r2 = dx[0] * dx[0];
                for d in 1..D {
                    r2 += dx[d] * dx[d];
                }
                r2 < reach2
            })
            .collect();
        assert!(want.len() > 8 && want.len() < n - 20, "{}", want.len());
        let mut ways = vec![false];
        if wide_lanes() {
            ways.push(true);
        }
        for wide in ways {
            let mut near = Near::<D>::default();
            // Twice: a second selection forgets the first.
            for _ in 0..2 {
                near.select(xa, reach2, &rows, (&x, &v), wide);
                assert_eq!(near.idx.len() % LANES, 0);
                let mut got = Vec::new();
                for b in 0..near.blocks() {
                    let (dx, w, idx) = near.block(b);
                    for l in 0..LANES {
                        if idx[l] == u32::MAX {
                            assert!(
                                dx.iter().all(|x| x[l] > 1e14) && w[l] == 0.0,
                                "far and still"
                            );
                            continue;
                        }
                        let i = idx[l] as usize;
                        let mut vx = 0.0f32;
                        for d in 0..D {
                            let e = xa[d] - x[d][i];
                            assert_eq!(dx[d][l].to_bits(), e.to_bits());
                            vx = if d == 0 {
                                v[d][i] * e
                            } else {
                                vx + v[d][i] * e
                            };
                        }
                        assert_eq!(w[l].to_bits(), vx.to_bits());
                        got.push(i);
                    }
                }
                assert_eq!(got, want, "wide {wide}");
                assert!(near.blocks() * LANES < got.len() + LANES);
            }
        }
    }

    #[test]
    fn select_keeps_exactly_the_particles_in_reach_in_order() {
        check::<2>();
        check::<3>();
    }
}
