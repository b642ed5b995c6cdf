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

/// Whether this CPU runs the pair loops with 256-bit lanes, fused multiply-add, popcnt and F16C (half
/// precision conversions; every CPU with AVX2 has it) (checked once, cached by std).
#[inline]
pub fn wide_lanes() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        std::arch::is_x86_feature_detected!("avx2")
            && std::arch::is_x86_feature_detected!("fma")
            && std::arch::is_x86_feature_detected!("popcnt")
            && std::arch::is_x86_feature_detected!("f16c")
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

/// Storage sized by the most it has needed so far ([`share_room`]).
pub trait Room {
    /// The most entries a fill has needed.
    fn peak(&self) -> usize;
    /// Entries there is room for now.
    fn capacity(&self) -> usize;
    /// Room for `room` entries in every array.
    fn reserve(&mut self, room: usize);
}

/// Gives every chunk's candidates (liquid and walls separately) room for 2.5 times the most any of them has
/// needed so far, once theirs falls below 1.25 times that: each chunk's own storage grows only to what its
/// own cells have held, and a chunk that meets a fuller neighbourhood later in the flow would allocate
/// inside a step. Called before each pass; after a growth the most needed must double before the next.
pub fn share_room<T: Room>(pairs: &mut [(T, T)]) {
    let peak = |f: fn(&(T, T)) -> &T| pairs.iter().map(|p| f(p).peak()).max().unwrap_or(0);
    let (pf, pb) = (peak(|p| &p.0), peak(|p| &p.1));
    for (f, b) in pairs.iter_mut() {
        for (c, peak) in [(f, pf), (b, pb)] {
            if 4 * c.capacity() < 5 * peak {
                c.reserve(5 * peak / 2);
            }
        }
    }
}

/// Where padding entries are put: far outside any support, small enough that squares stay finite in f32.
const FAR: f32 = 1.0e15;

/// Candidate neighbours (positions, velocities, densities, p/ρ²) in contiguous storage.
#[derive(Clone, Debug)]
pub struct Candidates<const D: usize> {
    pub x: [Vec<f32>; D],
    pub v: [Vec<f32>; D],
    pub r: Vec<f32>,
    pub pr2: Vec<f32>,
    /// The most candidates (padded) a fill has needed ([`share_room`]).
    peak: usize,
}

impl<const D: usize> Default for Candidates<D> {
    fn default() -> Self {
        Self {
            x: std::array::from_fn(|_| Vec::new()),
            v: std::array::from_fn(|_| Vec::new()),
            r: Vec::new(),
            pr2: Vec::new(),
            peak: 0,
        }
    }
}

impl<const D: usize> Room for Candidates<D> {
    fn peak(&self) -> usize {
        self.peak
    }
    fn capacity(&self) -> usize {
        self.x[0].capacity()
    }
    fn reserve(&mut self, room: usize) {
        fn to<T>(v: &mut Vec<T>, room: usize) {
            v.reserve(room.saturating_sub(v.len()));
        }
        for d in 0..D {
            to(&mut self.x[d], room);
            to(&mut self.v[d], room);
        }
        to(&mut self.r, room);
        to(&mut self.pr2, room);
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
    /// twice that: a step should stop allocating soon after the flow has got going.
    fn grow(&mut self, want: usize) {
        self.peak = self.peak.max(want);
        if self.x[0].capacity() < want {
            self.reserve(2 * want);
        }
    }

    /// Number of blocks of [`LANES`].
    #[inline]
    pub fn blocks(&self) -> usize {
        self.r.len() / LANES
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
        c.fill(&ranges, 2, &x, &v, &r, &p, 1000.0);
        // Refilling with fewer candidates forgets the old ones.
        c.fill(&ranges, 1, &x, &v, &r, &p, 1000.0);
        assert_eq!(c.r.len(), LANES);
        assert_eq!(c.block(0).0[0][2], FAR);
    }
}
