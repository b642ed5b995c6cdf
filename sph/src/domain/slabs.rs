//! Slabs: the tank cut across its length into runs of whole grid-cell columns, one per rank.

use crate::neighbours::REACH;

/// Rank k owns the cell columns `cuts[k]..cuts[k + 1]`; the first and the last slab run on without end.
/// A particle is copied into the halo of the ranks owning columns within `halo` of its own.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Slabs {
    cuts: Vec<i64>,
    halo: i64,
}

impl Slabs {
    /// One slab for everything.
    pub fn whole() -> Self {
        Self {
            cuts: vec![i64::MIN, i64::MAX],
            halo: REACH,
        }
    }

    /// Cuts that share `counts` (particles per grid column) evenly among `ranks`, with halos `halo`
    /// columns wide (at least [`REACH`], a kernel support), every slab at least that wide so that a
    /// particle's halo copies go to the adjacent slabs only.
    pub fn balanced(counts: &[f64], ranks: usize, halo: i64) -> Result<Self, String> {
        let columns = counts.len() as i64;
        let w = halo.max(REACH);
        if ranks as i64 * w > columns {
            return Err(format!(
                "{ranks} ranks do not fit across this tank: it is {columns} neighbour-grid columns long and each rank needs at least {w}; run on at most {} ranks",
                (columns / w).max(1)
            ));
        }
        let total: f64 = counts.iter().sum();
        let mut cuts = vec![i64::MIN; ranks + 1];
        cuts[ranks] = i64::MAX;
        let mut sum = 0.0;
        let mut c = 0usize;
        for (k, cut) in cuts.iter_mut().enumerate().take(ranks).skip(1) {
            let target = total * k as f64 / ranks as f64;
            while c < counts.len() && sum + 0.5 * counts[c] < target {
                sum += counts[c];
                c += 1;
            }
            *cut = c as i64;
        }
        // Every slab at least REACH columns, within the grid (the later ones pushed along, then back).
        for k in 1..ranks {
            let lo = if k == 1 { w } else { cuts[k - 1] + w };
            cuts[k] = cuts[k].max(lo);
        }
        for k in (1..ranks).rev() {
            let hi = if k == ranks - 1 {
                columns - w
            } else {
                cuts[k + 1] - w
            };
            cuts[k] = cuts[k].min(hi);
        }
        Ok(Self { cuts, halo: w })
    }

    pub fn ranks(&self) -> usize {
        self.cuts.len() - 1
    }

    /// The rank owning column `col`.
    #[inline]
    pub fn owner(&self, col: i64) -> usize {
        self.cuts[1..].partition_point(|&c| c <= col)
    }

    /// The columns of rank r (unbounded ends as i64::MIN / MAX).
    pub fn columns(&self, r: usize) -> (i64, i64) {
        (self.cuts[r], self.cuts[r + 1])
    }

    /// The ranks besides `owner` (the owner of `col`) that need a copy of a particle in column `col`: the
    /// adjacent slabs within the halo width.
    #[inline]
    pub fn halo_of(&self, owner: usize, col: i64) -> [Option<usize>; 2] {
        let (lo, hi) = self.columns(owner);
        [
            (owner > 0 && col < lo + self.halo).then(|| owner - 1),
            (owner + 1 < self.ranks() && col >= hi - self.halo).then_some(owner + 1),
        ]
    }

    /// Columns of the halo.
    pub fn halo(&self) -> i64 {
        self.halo
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn balanced_cuts_share_the_particles_and_keep_slabs_wide_enough() {
        // 40 columns, particles piled up at the right end.
        let counts: Vec<f64> = (0..40).map(|c| if c < 30 { 1.0 } else { 20.0 }).collect();
        let s = Slabs::balanced(&counts, 4, REACH).unwrap();
        assert_eq!(s.ranks(), 4);
        let share = |r: usize| -> f64 {
            (0..40i64)
                .filter(|&c| s.owner(c) == r)
                .map(|c| counts[c as usize])
                .sum()
        };
        let total: f64 = counts.iter().sum();
        for r in 0..4 {
            let (lo, hi) = s.columns(r);
            assert!(hi.min(40) - lo.max(0) >= REACH, "{s:?}");
            // Within one heavy column of an even share.
            assert!(
                (share(r) - total / 4.0).abs() <= 20.0,
                "rank {r}: {}",
                share(r)
            );
        }
        // Owners and halos are consistent with the cuts.
        for c in -3..45 {
            let o = s.owner(c);
            let (lo, hi) = s.columns(o);
            assert!(lo <= c && c < hi);
            for r in s.halo_of(o, c).into_iter().flatten() {
                let (rlo, rhi) = s.columns(r);
                assert!(c >= rlo.saturating_sub(REACH) && c < rhi.saturating_add(REACH));
            }
            // Every rank within reach of c (other than the owner) is listed.
            for r in 0..4 {
                let (rlo, rhi) = s.columns(r);
                if r != o && c >= rlo.saturating_sub(REACH) && c < rhi.saturating_add(REACH) {
                    assert!(s.halo_of(o, c).contains(&Some(r)), "column {c} rank {r}");
                }
            }
        }
        // Even counts: equal slabs.
        let flat = Slabs::balanced(&[1.0; 12], 3, REACH).unwrap();
        assert_eq!((flat.columns(1).0, flat.columns(2).0), (4, 8));
        // Too many ranks for the tank is an error that names the limit.
        let e = Slabs::balanced(&[1.0; 5], 3, REACH).unwrap_err();
        assert!(e.contains("at most 2 ranks"), "{e}");
        // Wider halos (mirror ghosts): wider slabs, copies still to the adjacent ranks only.
        let wide = Slabs::balanced(&[1.0; 12], 3, REACH + 1).unwrap();
        assert_eq!(wide.halo_of(1, 4), [Some(0), None]);
        assert_eq!(wide.halo_of(1, 7), [None, Some(2)]);
        assert_eq!(wide.halo_of(1, 5), [Some(0), Some(2)]);
        assert!(Slabs::balanced(&[1.0; 8], 3, REACH + 1).is_err());
    }
}
