//! Where the incompressible scheme's constant-density solve starts: the hydrostatic warm start.
//!
//! The solve only ever adds pressure where the liquid is compressed (a monotone Jacobi update), so it starts
//! below the last step's pressure: from half of it, the plain warm start of Bender & Koschier (2017), which
//! lets the solve undo last step's pressure where the flow relaxes and damps the particle-to-particle noise of
//! the pressure field. But half the last pressure is also half the *hydrostatic* pressure, the smoothest mode
//! of the field and the one a Jacobi iteration rebuilds slowest (one particle layer per iteration): on the 2D
//! seed tank the solve spent most of its iterations rebuilding it, every step, and the wall force carried the
//! step-to-step differences of how far it got.
//!
//! So the part of the last pressure that a hydrostatic column explains is carried over whole, and only a share
//! `REST` = 0.6 of the rest. Per column of liquid (along the tank's z), with z_top its highest particle (connected to
//! the liquid below it) and g the apparent gravity's downward component in the tank frame,
//!
//! `k_hyd = g (z_top − z) / ρ_rest` (k plays p/ρ²: a hydrostatic pressure ρ g d),
//! `R = min(1, Σ k_last / Σ k_hyd)` over the column's particles,
//! `carried = max(0, min(β R k_hyd, k_last))`, `k_start = carried + REST (k_last − carried)`.
//!
//! Every start of a k ≥ 0 (the solve's are) lies between REST times the last k and the last k, so no particle
//! starts above what it had. The carried part is a smooth field (the column's depth, scaled per column), so
//! the particle-to-particle noise is still cut every step (to 0.6 of it; the plain warm start halves it: 0.6
//! takes 12 % fewer iterations than 0.5 on the 3D seed benchmark with the same answer and a tank at rest as
//! still, where 0.7 stirs a 3D tank at rest at 1.5 ms steps); β < 1 leaves a
//! little hydrostatic pressure to rebuild every step, and R (the column's pressure relative to hydrostatic)
//! makes a column whose pressure falls below hydrostatic (a collapsing dam-break column, free fall) start from
//! its own, lower level, so that its pressure can keep falling, by (1 − β)(1 − REST) = 2 % a step at least:
//! with β·k_hyd alone the column held on to the pressure of earlier steps (the monotone update cannot lower it)
//! and the dam-break front ran 20 % ahead of the experiment (then 9 %, 8 % with the plain warm start, and 8 %
//! since the relaxed iterations; the test allows 10 %).
//!
//! Columns are one particle spacing wide (x, and y in 3D), counted from the neighbour grid's corner: on a
//! sloping surface (a dam-break front) wider columns would take a higher top for all their particles. A
//! subdomain of several ranks is a run of whole columns of grid cells with a halo of two cells; a particle's
//! start depends on its own column and the next one on either side (up to two spacings from it), so where a
//! grid cell is at least a spacing (`smoothing_ratio` ≥ 1, `Setting::applies`) every rank sees all of them and
//! starts its particles where a single process would; the sums are taken in fixed point, so that they do not
//! depend on the order of the particles (a rank keeps its halo copies apart from its own particles). Columns
//! and rows come from the f64 positions, depths from the f32 copies the solver uses.

use crate::neighbours::Grid;
use crate::particles::Fluid;

/// The share of the last k the plain warm start begins from: the divergence solve's.
/// Share of the last step's pressure the divergence solve starts from. Each iteration only adds pressure
/// where the liquid is compressed (a monotone update that keeps the Jacobi iteration stable and never sucks
/// liquid together), so a fuller warm start could never be undone where the flow relaxes. (Measured: a
/// projected two-sided update from the full pressure with Chebyshev acceleration needs 2–3× fewer iterations,
/// but its pressure field is noisy enough to shift the first sloshing mode's period by 5 %.) The
/// constant-density solve carries the hydrostatic part of its last pressure whole ([`Columns::warm_start`]).
pub(crate) const WARM: f32 = 0.5;

const HALF: f64 = WARM as f64;

/// The share of the last k above the carried hydrostatic part that the constant-density solve starts from.
pub const REST: f64 = 0.6;

/// What the hydrostatic warm start needs besides the particles.
#[derive(Clone, Copy, Debug)]
pub struct Setting {
    /// Particle spacing: the columns' width, m.
    pub dp: f64,
    /// The density the solver holds, kg/m³.
    pub rho_rest: f32,
    /// The apparent gravity's downward component in the tank frame, m/s².
    pub gz: f32,
    /// Share of the hydrostatic pressure carried whole (0: half the whole last pressure).
    pub beta: f64,
}

impl Setting {
    /// Whether a grid of `cell` wide cells lets every rank see the columns its particles' starts depend on
    /// (see the module's notes); elsewhere the plain half warm start.
    pub fn applies(cell: f64, dp: f64) -> bool {
        cell >= dp
    }
}

/// Per column: the highest liquid particle (z) connected to the liquid below, and the sums of the last k and
/// of the hydrostatic k over the column's particles up to it; per column and row (one spacing high):
/// whether it holds a liquid particle; per particle: its column and row.
#[derive(Debug, Default)]
pub struct Columns {
    top: Vec<f32>,
    top_row: Vec<u32>,
    col_last: Vec<i64>,
    col_hydro: Vec<i64>,
    occupied: Vec<bool>,
    cell: Vec<(u32, u32)>,
}

/// k in units of 2^-40 of its SI unit (p/ρ², m⁵/(kg s²)) per particle: sums exact in any order; a
/// hydrostatic k of g/ρ ≈ 1e-2 per metre of depth leaves room for 10^5 particles 80 m deep (the sums
/// saturate beyond, and a non-finite k counts as the largest).
const FIXED: f64 = (1u64 << 40) as f64;

impl Columns {
    /// Fills `start` (one value per particle of `fluid`) with where the constant-density solve starts, from
    /// the last step's k (`fluid.kappa`): the hydrostatic part whole, [`REST`] of the rest (of the last k above
    /// a column's top).
    pub fn warm_start<const D: usize>(
        &mut self,
        grid: &Grid<D>,
        fluid: &Fluid<D>,
        set: Setting,
        start: &mut Vec<f64>,
    ) {
        start.clear();
        if set.beta <= 0.0 || set.gz <= 0.0 {
            start.extend(fluid.kappa.iter().map(|k| HALF * k));
            return;
        }
        let (lo, hi) = grid.bounds();
        let across = |k: usize| (((hi[k] - lo[k]) / set.dp).ceil() as usize).max(1);
        let (nx, ny, rows) = (across(0), if D == 3 { across(1) } else { 1 }, across(D - 1));
        let columns = nx * ny;
        let index =
            |k: usize, x: f64, n: usize| (((x - lo[k]) / set.dp).max(0.0) as usize).min(n - 1);
        let column = |x: &dyn Fn(usize) -> f64| {
            let ix = index(0, x(0), nx);
            if D == 3 {
                ix * ny + index(1, x(1), ny)
            } else {
                ix
            }
        };
        self.cell.clear();
        self.cell.extend((0..fluid.len()).map(|a| {
            let x = |k: usize| fluid.pos[k][a];
            (column(&x) as u32, index(D - 1, x(D - 1), rows) as u32)
        }));
        self.occupied.clear();
        self.occupied.resize(columns * rows, false);
        for &(col, row) in &self.cell {
            self.occupied[col as usize * rows + row as usize] = true;
        }
        // The column's top row: the highest row connected to the column's lowest particle without two empty
        // rows between, so that a droplet or a crest over an air gap does not set the depth of the liquid
        // under it (whose last pressure would then be carried whole: a pressure spike there would not
        // decay). A row counts as liquid where the column or one beside it holds a particle: a line of
        // particles on a column's edge sways from one column to the next without leaving a gap.
        let occupied = &self.occupied;
        let liquid = |col: usize, r: usize| {
            let (ix, iy) = (col / ny, col % ny);
            (ix.saturating_sub(1)..=(ix + 1).min(nx - 1)).any(|x| {
                (iy.saturating_sub(1)..=(iy + 1).min(ny - 1))
                    .any(|y| occupied[(x * ny + y) * rows + r])
            })
        };
        self.top_row.clear();
        self.top_row.extend((0..columns).map(|col| {
            let own = &occupied[col * rows..(col + 1) * rows];
            let Some(mut top) = own.iter().position(|&o| o) else {
                return 0;
            };
            for r in top + 1..rows {
                if liquid(col, r) {
                    top = r;
                } else if r >= top + 2 {
                    break;
                }
            }
            top as u32
        }));
        let z = &fluid.x32[D - 1];
        let below_top = |&(col, row): &(u32, u32)| row <= self.top_row[col as usize];
        self.top.clear();
        self.top.resize(columns, f32::MIN);
        for (a, c) in self.cell.iter().enumerate().filter(|(_, c)| below_top(c)) {
            let t = &mut self.top[c.0 as usize];
            *t = t.max(z[a]);
        }
        let scale = set.gz as f64 / set.rho_rest as f64;
        let hydro = |a: usize, col: usize| scale * (self.top[col] - z[a]) as f64;
        self.col_last.clear();
        self.col_last.resize(columns, 0);
        self.col_hydro.clear();
        self.col_hydro.resize(columns, 0);
        for (a, c) in self.cell.iter().enumerate().filter(|(_, c)| below_top(c)) {
            let col = c.0 as usize;
            let (l, h) = (&mut self.col_last[col], &mut self.col_hydro[col]);
            *l = l.saturating_add((fluid.kappa[a] * FIXED) as i64);
            *h = h.saturating_add((hydro(a, col) * FIXED) as i64);
        }
        start.extend(self.cell.iter().enumerate().map(|(a, c)| {
            let col = c.0 as usize;
            let last = fluid.kappa[a];
            if self.col_hydro[col] <= 0 || !below_top(c) {
                return REST * last;
            }
            let ratio = (self.col_last[col] as f64 / self.col_hydro[col] as f64).min(1.0);
            let carried = (set.beta * ratio * hydro(a, col)).min(last).max(0.0);
            carried + REST * (last - carried)
        }));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const DP: f64 = 0.1;
    const RHO: f32 = 1000.0;
    const G: f32 = 9.81;

    /// Two columns of liquid 5 particles deep, at 0.05 and 0.35 along `axis` (0 at 0.05 along the other
    /// horizontal axis in 3D), with last pressures `k(position along axis, depth)`.
    fn columns<const D: usize>(axis: usize, k: impl Fn(f64, f64) -> f64) -> (Grid<D>, Fluid<D>) {
        let grid = Grid::new([-1.0; D], [1.0; D], 0.13);
        let pts: Vec<[f64; D]> = [0.05, 0.35]
            .iter()
            .flat_map(|&s| {
                (0..5).map(move |i| {
                    let mut p = [0.05; D];
                    p[axis] = s;
                    p[D - 1] = 0.05 + i as f64 * DP;
                    p
                })
            })
            .collect();
        let mut f = Fluid::new(&pts, |_| RHO as f64);
        for d in 0..D {
            f.x32[d] = f.pos[d].iter().map(|v| *v as f32).collect();
        }
        for (a, p) in pts.iter().enumerate() {
            f.kappa[a] = k(p[axis], 0.45 - p[D - 1]);
        }
        (grid, f)
    }

    /// [`columns`] in 2D, along x.
    fn liquid(k: impl Fn(f64, f64) -> f64) -> (Grid<2>, Fluid<2>) {
        columns(0, k)
    }

    fn setting(gz: f32, beta: f64) -> Setting {
        Setting {
            dp: DP,
            rho_rest: RHO,
            gz,
            beta,
        }
    }

    fn hydro(depth: f64) -> f64 {
        G as f64 * depth / RHO as f64
    }

    fn starts<const D: usize>(f: &Fluid<D>, grid: &Grid<D>, beta: f64) -> Vec<f64> {
        let mut out = Vec::new();
        Columns::default().warm_start(grid, f, setting(G, beta), &mut out);
        assert_eq!(out.len(), f.len());
        for (s, k) in out.iter().zip(&f.kappa) {
            assert!(
                *s >= 0.5 * k - 1e-15 && *s <= k + 1e-15,
                "start {s} outside [k/2, k], k = {k}"
            );
        }
        out
    }

    #[test]
    fn a_hydrostatic_column_keeps_beta_of_its_pressure_whole_and_a_share_of_the_rest() {
        let (grid, f) = liquid(|_, d| hydro(d));
        for (s, k) in starts(&f, &grid, 0.95).iter().zip(&f.kappa) {
            assert!((s - 0.98 * k).abs() <= 1e-6 * k, "{s} vs {k}");
        }
        // Off: half the last pressure, the plain warm start.
        for (s, k) in starts(&f, &grid, 0.0).iter().zip(&f.kappa) {
            assert_eq!(*s, 0.5 * k);
        }
    }

    #[test]
    fn pressure_above_hydrostatic_carries_only_the_hydrostatic_part() {
        // Column x = 0.05 at twice hydrostatic, the other at hydrostatic: a column's excess is cut to REST, and
        // the other column is unaffected by it.
        let (grid, f) = liquid(|x, d| if x < 0.2 { 2.0 * hydro(d) } else { hydro(d) });
        let s = starts(&f, &grid, 0.95);
        for a in 0..f.len() {
            let d = 0.45 - f.pos[1][a];
            let expect = if f.pos[0][a] < 0.2 {
                0.95 * hydro(d) + REST * (2.0 - 0.95) * hydro(d)
            } else {
                0.98 * hydro(d)
            };
            // (z is f32 in the interaction copies)
            assert!(
                (s[a] - expect).abs() <= 1e-6 * expect,
                "{} vs {expect}",
                s[a]
            );
        }
    }

    #[test]
    fn in_3d_the_columns_stand_on_x_and_y() {
        // Two columns side by side in y, one at hydrostatic, one at twice: each keeps its own start.
        let (grid, f) = columns::<3>(1, |y, d| if y < 0.2 { hydro(d) } else { 2.0 * hydro(d) });
        let out = starts(&f, &grid, 0.95);
        for a in 0..f.len() {
            let h = hydro(0.45 - f.pos[2][a]);
            let expect = if f.pos[1][a] < 0.2 {
                0.98 * h
            } else {
                0.95 * h + REST * 1.05 * h
            };
            assert!(
                (out[a] - expect).abs() <= 1e-6 * expect,
                "{} vs {expect}",
                out[a]
            );
        }
    }

    #[test]
    fn a_droplet_over_an_air_gap_does_not_deepen_the_column_under_it() {
        // A droplet 3 spacings above column x = 0.05, with its own pressure spike: the column under it keeps
        // its hydrostatic start (its depth from its own top), and the droplet starts from REST of its k.
        let (grid, mut f) = liquid(|_, d| hydro(d));
        let reference = starts(&f, &grid, 0.95);
        f.pos[0].push(0.05);
        f.pos[1].push(0.75);
        for d in 0..2 {
            f.x32[d].push(f.pos[d][f.pos[d].len() - 1] as f32);
        }
        f.kappa.push(0.01);
        f.rho.push(RHO as f64);
        let s = starts(&f, &grid, 0.95);
        assert_eq!(s[..reference.len()], reference[..]);
        assert_eq!(s[reference.len()], REST * 0.01);
    }

    #[test]
    fn a_column_below_hydrostatic_starts_from_its_own_lower_level() {
        // A collapsing column at 40 % of hydrostatic: the carried part scales with the column's level, so
        // the start stays a fixed share below the last pressure (the pressure can keep falling) instead of
        // being carried whole.
        let (grid, f) = liquid(|_, d| 0.4 * hydro(d));
        for (s, k) in starts(&f, &grid, 0.95).iter().zip(&f.kappa) {
            assert!((s - 0.98 * k).abs() <= 1e-6 * k, "{s} vs {k}");
        }
        // Without apparent gravity (free fall) the plain half warm start.
        let mut out = Vec::new();
        Columns::default().warm_start(&grid, &f, setting(0.0, 0.95), &mut out);
        for (s, k) in out.iter().zip(&f.kappa) {
            assert_eq!(*s, 0.5 * k);
        }
    }
}
