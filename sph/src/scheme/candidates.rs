//! Neighbour candidates of one cell, copied into contiguous struct-of-arrays buffers padded to whole blocks
//! of [`LANES`], so the pair loop runs branch-free over fixed-size blocks that the compiler vectorises.
//!
//! All particles of a cell share the same candidates (the cells of the 5^D block around it), so a buffer is
//! filled once per cell and reused by every particle in it. Padding entries sit far away with zero velocity
//! and reference density, so every kernel-weighted term they produce is exactly zero.

use crate::neighbours::Ranges;

/// Width of a block of pairs.
pub const LANES: usize = 8;

/// Sum of the lanes, in lane order.
#[inline(always)]
pub fn lane_sum(l: &[f32; LANES]) -> f32 {
    l.iter().sum()
}

/// Whether this CPU runs the pair loops with 256-bit lanes, fused multiply-add and popcnt (checked once, cached by
/// std).
#[inline]
pub fn wide_lanes() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("popcnt")
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        false
    }
}

/// Uniform numbers in [−0.5, 0.5) from a fixed seed, for the pair-loop tests' jittered lattices.
#[cfg(test)]
pub fn test_noise(mut seed: u64) -> impl FnMut() -> f32 {
    move || {
        seed = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((seed >> 33) as f32 / (1u64 << 31) as f32) - 0.5
    }
}

/// For each 8-bit mask of lanes, the set lanes in order (the rest: don't care), so a block's selected slots
/// are written as one block of 8 without branches.
const COMPRESS: [[u8; LANES]; 1 << LANES] = {
    let mut t = [[0u8; LANES]; 1 << LANES];
    let mut m = 0;
    while m < 1 << LANES {
        let mut n = 0;
        let mut l = 0;
        while l < LANES {
            if m & (1 << l) != 0 {
                t[m][n] = l as u8;
                n += 1;
            }
            l += 1;
        }
        m += 1;
    }
    t
};

/// Gives every chunk's candidates (liquid and walls separately) room for 2.5 times the most any of them has
/// needed so far, once theirs falls below 1.25 times that: each chunk's own storage grows only to what its
/// own runs of cells have held, and a chunk that meets a fuller run later in the flow would allocate inside
/// a step. Called before each pass; after a growth the most needed must double before the next.
pub fn share_room<const D: usize>(pairs: &mut [(Candidates<D>, Candidates<D>)]) {
    let peak = |f: fn(&(Candidates<D>, Candidates<D>)) -> &Candidates<D>| {
        pairs.iter().map(|p| f(p).peak).max().unwrap_or(0)
    };
    let (pf, pb) = (peak(|p| &p.0), peak(|p| &p.1));
    for (f, b) in pairs.iter_mut() {
        for (c, peak) in [(f, pf), (b, pb)] {
            if 4 * c.x[0].capacity() < 5 * peak {
                c.reserve(5 * peak / 2);
            }
        }
    }
}

/// Where padding entries are put: far outside any support, small enough that squares stay finite in f32.
const FAR: f32 = 1.0e15;

/// Candidate neighbours (positions, velocities, densities, p/ρ², particle indices) in contiguous storage.
#[derive(Clone, Debug)]
pub struct Candidates<const D: usize> {
    pub x: [Vec<f32>; D],
    pub v: [Vec<f32>; D],
    pub r: Vec<f32>,
    pub pr2: Vec<f32>,
    /// Index of each candidate in the particle arrays (padding: `u32::MAX`); filled by [`Self::fill_motion`].
    pub idx: Vec<u32>,
    /// Slots of the candidates within reach of one particle, padded to whole blocks ([`Self::select`]).
    sel: Vec<u32>,
    /// The most candidates (padded) a fill has needed ([`share_room`]), and whether the fills are
    /// [`Self::fill_motion`]'s (positions, velocities, indices) rather than [`Self::fill`]'s (positions,
    /// velocities, densities, p/ρ²).
    peak: usize,
    motion: bool,
}

impl<const D: usize> Default for Candidates<D> {
    fn default() -> Self {
        Self {
            x: std::array::from_fn(|_| Vec::new()),
            v: std::array::from_fn(|_| Vec::new()),
            r: Vec::new(),
            pr2: Vec::new(),
            idx: Vec::new(),
            sel: Vec::new(),
            peak: 0,
            motion: false,
        }
    }
}

impl<const D: usize> Candidates<D> {
    /// Copies the particles in `ranges` and pads to a multiple of [`LANES`]. Storage grows to the largest
    /// neighbourhood seen and is then reused without allocating.
    #[allow(clippy::too_many_arguments)]
    pub fn fill(
        &mut self,
        ranges: &Ranges,
        n: usize,
        x: &[Vec<f32>; D],
        v: &[Vec<f32>; D],
        r: &[f32],
        pr2: &[f32],
        rho_pad: f32,
    ) {
        for d in 0..D {
            self.x[d].clear();
            self.v[d].clear();
        }
        self.r.clear();
        self.pr2.clear();
        let total: usize = ranges[..n].iter().map(|&(lo, hi)| (hi - lo) as usize).sum();
        self.motion = false;
        self.grow(total.div_ceil(LANES) * LANES);
        for &(lo, hi) in &ranges[..n] {
            let (lo, hi) = (lo as usize, hi as usize);
            for d in 0..D {
                self.x[d].extend_from_slice(&x[d][lo..hi]);
                self.v[d].extend_from_slice(&v[d][lo..hi]);
            }
            self.r.extend_from_slice(&r[lo..hi]);
            self.pr2.extend_from_slice(&pr2[lo..hi]);
        }
        let padded = self.r.len().div_ceil(LANES) * LANES;
        for d in 0..D {
            self.x[d].resize(padded, FAR);
            self.v[d].resize(padded, 0.0);
        }
        self.r.resize(padded, rho_pad);
        self.pr2.resize(padded, 0.0);
    }

    /// Notes a fill of `want` candidates (padded) and, if the storage is too small for it, grows it to
    /// twice that: the candidates of a run of cells vary more than a cell's, and a step should stop
    /// allocating soon after the flow has got going.
    fn grow(&mut self, want: usize) {
        self.peak = self.peak.max(want);
        if self.x[0].capacity() < want {
            self.reserve(2 * want);
        }
    }

    /// Room for `room` candidates in every array the fills use. (Every caller asks for more than twice
    /// the capacity, so std's growth gives exactly `room`, and `x[0]`'s capacity stands for all.)
    fn reserve(&mut self, room: usize) {
        fn to<T>(v: &mut Vec<T>, room: usize) {
            v.reserve(room.saturating_sub(v.len()));
        }
        for d in 0..D {
            to(&mut self.x[d], room);
            to(&mut self.v[d], room);
        }
        if self.motion {
            to(&mut self.idx, room);
            to(&mut self.sel, room + LANES);
        } else {
            to(&mut self.r, room);
            to(&mut self.pr2, room);
        }
    }

    /// The most candidates (padded) a fill has needed.
    pub fn peak(&self) -> usize {
        self.peak
    }

    /// Copies positions, velocities and indices only (densities and p/ρ² are left empty: use
    /// [`Self::motion_blocks`] and [`Self::motion_block`]), padded like [`Self::fill`] but always with at
    /// least one padding entry, which [`Self::select`] pads its selection with.
    pub fn fill_motion(&mut self, ranges: &Ranges, n: usize, x: &[Vec<f32>; D], v: &[Vec<f32>; D]) {
        for d in 0..D {
            self.x[d].clear();
            self.v[d].clear();
        }
        self.idx.clear();
        self.r.clear();
        self.pr2.clear();
        let total: usize = ranges[..n].iter().map(|&(lo, hi)| (hi - lo) as usize).sum();
        self.motion = true;
        self.grow((total + 1).div_ceil(LANES) * LANES);
        for &(lo, hi) in &ranges[..n] {
            let (lo, hi) = (lo as usize, hi as usize);
            for d in 0..D {
                self.x[d].extend_from_slice(&x[d][lo..hi]);
                self.v[d].extend_from_slice(&v[d][lo..hi]);
            }
            self.idx.extend(lo as u32..hi as u32);
        }
        let padded = (self.idx.len() + 1).div_ceil(LANES) * LANES;
        for d in 0..D {
            self.x[d].resize(padded, FAR);
            self.v[d].resize(padded, 0.0);
        }
        self.idx.resize(padded, u32::MAX);
    }

    /// Selects the candidates (after [`Self::fill_motion`]) closer to `xa` than √`reach2`, in candidate
    /// order, and pads the selection to whole blocks with a padding entry: the expensive part of a pair
    /// loop then runs over [`Self::selected_block`]s of neighbours only, instead of every candidate of the
    /// (2·REACH + 1)^D cells around (a quarter of them are in reach in 3D). Branch-free: every slot is
    /// written and kept only if it is in reach.
    #[inline(always)]
    pub fn select(&mut self, xa: [f32; D], reach2: f32) {
        let blocks = self.motion_blocks();
        self.sel.clear();
        // Each block writes a whole block of slots at the end of the selection.
        self.sel.reserve(blocks * LANES + LANES);
        let out = self.sel.as_mut_ptr();
        let mut n = 0;
        for b in 0..blocks {
            let s = b * LANES;
            let xs: [&[f32; LANES]; D] =
                std::array::from_fn(|d| self.x[d][s..s + LANES].try_into().expect("whole block"));
            let mut r2 = [0.0f32; LANES];
            for d in 0..D {
                for l in 0..LANES {
                    let dx = xa[d] - xs[d][l];
                    r2[l] += dx * dx;
                }
            }
            let mut mask = 0usize;
            for (l, &r2) in r2.iter().enumerate() {
                mask |= ((r2 < reach2) as usize) << l;
            }
            let lanes = &COMPRESS[mask];
            for (l, &lane) in lanes.iter().enumerate() {
                // SAFETY: n ≤ s, so n + l < blocks · LANES + LANES, the reserved capacity.
                unsafe { out.add(n + l).write((s + lane as usize) as u32) };
            }
            n += mask.count_ones() as usize;
        }
        // The last slot is always padding (`fill_motion`).
        let pad = (blocks * LANES - 1) as u32;
        while n % LANES != 0 {
            // SAFETY: n < blocks · LANES + LANES, within the reserved capacity.
            unsafe { out.add(n).write(pad) };
            n += 1;
        }
        // SAFETY: the first n entries were written above.
        unsafe { self.sel.set_len(n) };
    }

    /// Number of blocks of [`LANES`] of the last [`Self::select`].
    #[inline]
    pub fn selected_blocks(&self) -> usize {
        self.sel.len() / LANES
    }

    /// Block `b` of the last [`Self::select`]: positions, velocities and particle indices of its lanes,
    /// gathered from the candidates.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    pub fn selected_block(&self, b: usize) -> ([[f32; LANES]; D], [[f32; LANES]; D], [u32; LANES]) {
        let slots: &[u32; LANES] = self.sel[b * LANES..(b + 1) * LANES]
            .try_into()
            .expect("whole block");
        let n = self.idx.len();
        // Slots come from `select` over this fill: all below n (checked once per block, not per load).
        assert!(slots.iter().all(|&s| (s as usize) < n));
        let gather = |v: &[f32]| -> [f32; LANES] {
            // SAFETY: every slot is below n = v.len() (asserted above; x, v and idx have one length).
            std::array::from_fn(|l| unsafe { *v.get_unchecked(slots[l] as usize) })
        };
        (
            std::array::from_fn(|d| gather(&self.x[d])),
            std::array::from_fn(|d| gather(&self.v[d])),
            // SAFETY: as above.
            std::array::from_fn(|l| unsafe { *self.idx.get_unchecked(slots[l] as usize) }),
        )
    }

    /// Number of blocks of [`LANES`] (after [`Self::fill`]).
    #[inline]
    pub fn blocks(&self) -> usize {
        self.r.len() / LANES
    }

    /// Number of blocks of [`LANES`] (after [`Self::fill_motion`]).
    #[inline]
    pub fn motion_blocks(&self) -> usize {
        self.idx.len() / LANES
    }

    /// Block `b` after [`Self::fill_motion`]: positions, velocities and indices of its lanes.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    pub fn motion_block(&self, b: usize) -> ([[f32; LANES]; D], [[f32; LANES]; D], &[u32]) {
        let s = b * LANES..(b + 1) * LANES;
        let lane = |v: &[f32]| -> [f32; LANES] { v[s.clone()].try_into().expect("whole block") };
        (
            std::array::from_fn(|d| lane(&self.x[d])),
            std::array::from_fn(|d| lane(&self.v[d])),
            &self.idx[s.clone()],
        )
    }

    /// Block `b`: positions, velocities, densities and p/ρ² of its lanes.
    #[inline(always)]
    #[allow(clippy::type_complexity)]
    pub fn block(
        &self,
        b: usize,
    ) -> (
        [[f32; LANES]; D],
        [[f32; LANES]; D],
        [f32; LANES],
        [f32; LANES],
    ) {
        let s = b * LANES..(b + 1) * LANES;
        let lane = |v: &[f32]| -> [f32; LANES] { v[s.clone()].try_into().expect("whole block") };
        (
            std::array::from_fn(|d| lane(&self.x[d])),
            std::array::from_fn(|d| lane(&self.v[d])),
            lane(&self.r),
            lane(&self.pr2),
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::neighbours::NO_RANGES;

    #[test]
    fn fill_concatenates_ranges_and_pads_far_away() {
        let x = [vec![0.0, 1.0, 2.0, 3.0, 4.0], vec![5.0, 6.0, 7.0, 8.0, 9.0]];
        let v = [vec![1.0; 5], vec![2.0; 5]];
        let r = vec![1000.0, 1001.0, 1002.0, 1003.0, 1004.0];
        let p = vec![0.5; 5];
        let mut ranges = NO_RANGES;
        ranges[0] = (0, 2);
        ranges[1] = (3, 5);
        let mut c = Candidates::<2>::default();
        c.fill(&ranges, 2, &x, &v, &r, &p, 1000.0);
        assert_eq!(c.blocks(), 1);
        let (bx, bv, br, bp) = c.block(0);
        assert_eq!(&bx[0][..4], &[0.0, 1.0, 3.0, 4.0]);
        assert_eq!(&br[..4], &[1000.0, 1001.0, 1003.0, 1004.0]);
        assert!(bx[0][4..].iter().all(|&p| p == FAR));
        assert!(bv[1][4..].iter().all(|&p| p == 0.0));
        assert!(bp[4..].iter().all(|&p| p == 0.0));
        c.fill_motion(&ranges, 2, &x, &v);
        assert_eq!(c.motion_blocks(), 1);
        let (bx, _, idx) = c.motion_block(0);
        assert_eq!(idx, &[0, 1, 3, 4, u32::MAX, u32::MAX, u32::MAX, u32::MAX]);
        assert_eq!(&bx[1][..4], &[5.0, 6.0, 8.0, 9.0]);
        assert!(bx[1][4..].iter().all(|&p| p == FAR));
        c.fill(&ranges, 2, &x, &v, &r, &p, 1000.0);
        // Refilling with fewer candidates forgets the old ones.
        c.fill(&ranges, 1, &x, &v, &r, &p, 1000.0);
        assert_eq!(c.r.len(), LANES);
        assert_eq!(c.block(0).0[0][2], FAR);
    }

    #[test]
    fn select_keeps_exactly_the_candidates_in_reach_in_order() {
        let mut rnd = test_noise(3);
        let n = 37;
        let x: [Vec<f32>; 3] = std::array::from_fn(|_| (0..n).map(|_| rnd()).collect());
        let v: [Vec<f32>; 3] = std::array::from_fn(|_| (0..n).map(|_| rnd()).collect());
        let mut ranges = NO_RANGES;
        ranges[0] = (0, 20);
        ranges[1] = (25, n as u32);
        let mut c = Candidates::<3>::default();
        c.fill_motion(&ranges, 2, &x, &v);
        let xa = [0.1f32, -0.05, 0.0];
        let reach2 = 0.16f32;
        c.select(xa, reach2);
        let mut got = Vec::new();
        for b in 0..c.selected_blocks() {
            let (bx, bv, idx) = c.selected_block(b);
            for l in 0..LANES {
                if idx[l] == u32::MAX {
                    assert_eq!(bx[0][l], FAR, "padding is far away");
                    continue;
                }
                let i = idx[l] as usize;
                assert_eq!(bv[2][l], v[2][i]);
                got.push(i);
            }
        }
        let want: Vec<usize> = (0..20)
            .chain(25..n)
            .filter(|&i| (0..3).map(|d| (xa[d] - x[d][i]).powi(2)).sum::<f32>() < reach2)
            .collect();
        assert!(!want.is_empty() && want.len() < 37 - 5);
        assert_eq!(got, want);
    }
}
