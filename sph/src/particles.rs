//! Particle storage, struct of arrays. The integrated state is f64 (positions relative to the tank origin,
//! velocities relative to the tank frame, densities); the interaction loops read f32 copies refreshed before
//! each force evaluation, in the same cell-sorted order.

use crate::neighbours::{counting_sort, order_cells_by, permute, Grid, OUTSIDE};

/// Marks the id of a halo particle: a copy of a particle owned by the neighbouring subdomain (MPI runs), kept
/// for its neighbours' sums and left out of every total.
pub const HALO: u32 = 1 << 31;

/// The tag of a boundary particle that belongs to the tank (not to a floating body).
pub const NOT_BODY: u32 = u32::MAX;

/// The liquid.
#[derive(Clone, Debug)]
pub struct Fluid<const D: usize> {
    // Integrated state (f64).
    pub pos: [Vec<f64>; D],
    pub vel: [Vec<f64>; D],
    pub rho: Vec<f64>,
    /// State at the start of the step (symplectic) or the previous step (Verlet).
    pub pos0: [Vec<f64>; D],
    pub vel0: [Vec<f64>; D],
    pub rho0: Vec<f64>,
    /// Pressure solved for by an incompressible scheme, and its two parts as p/ρ² (constant-density and
    /// divergence solver) to start the next step's solve from (kept through sorting; unused by WCSPH).
    pub pressure: Vec<f64>,
    pub kappa: Vec<f64>,
    pub kappa_div: Vec<f64>,
    /// Original index of each particle (stable through sorting; orders the particles inside a cell), with
    /// [`HALO`] set on halo copies.
    pub id: Vec<u32>,
    // Interaction copies (f32) and cell of each particle, refreshed every force evaluation.
    pub x32: [Vec<f32>; D],
    pub v32: [Vec<f32>; D],
    pub rho32: Vec<f32>,
    pub p32: Vec<f32>,
    /// p / ρ², the per-particle factor of the pressure gradient.
    pub pr2: Vec<f32>,
    pub cell: Vec<u32>,
    /// Cell offsets of the sorted particles.
    pub starts: Vec<u32>,
    // Rates from the last force evaluation.
    pub acc: Vec<[f32; D]>,
    pub drho: Vec<f32>,
}

/// Scratch buffers for sorting, kept to avoid allocating inside a step.
#[derive(Clone, Debug, Default)]
pub struct SortScratch {
    dest: Vec<u32>,
    f64s: Vec<f64>,
    /// A second f64 scratch: the liquid's arrays are permuted in two halves side by side.
    f64s_2: Vec<f64>,
    f32s: Vec<f32>,
    u32s: Vec<u32>,
    order: Vec<u32>,
}

fn vecs<T, const D: usize>() -> [Vec<T>; D] {
    std::array::from_fn(|_| Vec::new())
}

impl<const D: usize> Default for Fluid<D> {
    fn default() -> Self {
        Self {
            pos: vecs(),
            vel: vecs(),
            rho: Vec::new(),
            pos0: vecs(),
            vel0: vecs(),
            rho0: Vec::new(),
            pressure: Vec::new(),
            kappa: Vec::new(),
            kappa_div: Vec::new(),
            id: Vec::new(),
            x32: vecs(),
            v32: vecs(),
            rho32: Vec::new(),
            p32: Vec::new(),
            pr2: Vec::new(),
            cell: Vec::new(),
            starts: Vec::new(),
            acc: Vec::new(),
            drho: Vec::new(),
        }
    }
}

impl<const D: usize> Default for Boundary<D> {
    fn default() -> Self {
        Self {
            x: vecs(),
            v: vecs(),
            rho: Vec::new(),
            rho0: Vec::new(),
            r: Vec::new(),
            p: Vec::new(),
            pr2: Vec::new(),
            cell: Vec::new(),
            starts: Vec::new(),
            drho: Vec::new(),
            tag: Vec::new(),
        }
    }
}

impl<const D: usize> Fluid<D> {
    pub fn new(points: &[[f64; D]], density: impl Fn([f64; D]) -> f64) -> Self {
        let mut f = Self::default();
        for k in 0..D {
            f.pos[k] = points.iter().map(|p| p[k]).collect();
            f.vel[k] = vec![0.0; points.len()];
        }
        f.rho = points.iter().map(|p| density(*p)).collect();
        f.pos0 = f.pos.clone();
        f.vel0 = f.vel.clone();
        f.rho0 = f.rho.clone();
        f.pressure = vec![0.0; points.len()];
        f.kappa = vec![0.0; points.len()];
        f.kappa_div = vec![0.0; points.len()];
        f.id = (0..points.len() as u32).collect();
        f
    }

    pub fn len(&self) -> usize {
        self.rho.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rho.is_empty()
    }

    #[inline]
    pub fn position(&self, i: usize) -> [f64; D] {
        std::array::from_fn(|k| self.pos[k][i])
    }

    /// Whether particle i belongs here (not a halo copy).
    #[inline]
    pub fn owned(&self, i: usize) -> bool {
        self.id[i] & HALO == 0
    }

    /// Sorts all per-particle arrays by cell and drops particles that left the grid. Returns how many left.
    pub fn sort(&mut self, grid: &Grid<D>, scratch: &mut SortScratch) -> usize {
        let n = self.len();
        let mut cells = std::mem::take(&mut self.cell);
        cells.clear();
        cells.extend((0..n).map(|i| grid.cell_of(self.position(i))));
        self.cell = cells;
        let keep = counting_sort(
            grid.n_cells(),
            &self.cell,
            &mut self.starts,
            &mut scratch.dest,
        );
        let id = &self.id;
        order_cells_by(
            |i| id[i] & !HALO,
            &self.starts,
            &mut scratch.dest,
            &mut scratch.order,
            keep,
        );
        let dest = &scratch.dest;
        // Two halves of the arrays at once (on two of rayon's threads where the caller is in its pool; a
        // join allocates nothing): the sort is otherwise a serial stretch of every step.
        let (s, s2, su) = (&mut scratch.f64s, &mut scratch.f64s_2, &mut scratch.u32s);
        let Fluid {
            pos,
            vel,
            pos0,
            vel0,
            rho,
            rho0,
            pressure,
            kappa,
            kappa_div,
            id,
            cell,
            ..
        } = self;
        // (Each array is permuted on its own, so the order within a half does not matter.)
        let (half, half2) = (
            pos.iter_mut().chain(vel).chain([rho, pressure, kappa]),
            pos0.iter_mut().chain(vel0).chain([rho0, kappa_div]),
        );
        rayon::join(
            || half.for_each(|v| permute(v, dest, s, keep)),
            || {
                half2.for_each(|v| permute(v, dest, s2, keep));
                permute(id, dest, su, keep);
                permute(cell, dest, su, keep);
            },
        );
        debug_assert!(self.cell.iter().all(|&c| c != OUTSIDE));
        n - keep
    }

    /// Refreshes the f32 copies from the integrated state, with pressures `eos(ρ, stored pressure)`.
    pub fn refresh(&mut self, eos: impl Fn(f32, f64) -> f32 + Sync) {
        use rayon::prelude::*;
        let n = self.len();
        for k in 0..D {
            self.x32[k].resize(n, 0.0);
            self.v32[k].resize(n, 0.0);
        }
        self.rho32.resize(n, 0.0);
        self.p32.resize(n, 0.0);
        self.pr2.resize(n, 0.0);
        self.acc.resize(n, [0.0; D]);
        self.drho.resize(n, 0.0);
        const CH: usize = 4096;
        for k in 0..D {
            self.x32[k]
                .par_chunks_mut(CH)
                .zip(self.pos[k].par_chunks(CH))
                .for_each(|(o, i)| o.iter_mut().zip(i).for_each(|(o, i)| *o = *i as f32));
            self.v32[k]
                .par_chunks_mut(CH)
                .zip(self.vel[k].par_chunks(CH))
                .for_each(|(o, i)| o.iter_mut().zip(i).for_each(|(o, i)| *o = *i as f32));
        }
        self.rho32
            .par_chunks_mut(CH)
            .zip(self.p32.par_chunks_mut(CH))
            .zip(self.pr2.par_chunks_mut(CH))
            .zip(self.rho.par_chunks(CH).zip(self.pressure.par_chunks(CH)))
            .for_each(|(((r, p), pr2), (rho, stored))| {
                for i in 0..r.len() {
                    r[i] = rho[i] as f32;
                    p[i] = eos(r[i], stored[i]);
                    pr2[i] = p[i] / (r[i] * r[i]);
                }
            });
    }
}

/// Boundary particles: the tank's wall layers (fixed in the tank frame) or mirror ghosts (rebuilt each
/// force evaluation). Velocities are relative to the tank frame, so zero for wall layers.
#[derive(Clone, Debug)]
pub struct Boundary<const D: usize> {
    pub x: [Vec<f32>; D],
    pub v: [Vec<f32>; D],
    /// Density (integrated by continuity for wall layers).
    pub rho: Vec<f64>,
    pub rho0: Vec<f64>,
    pub r: Vec<f32>,
    pub p: Vec<f32>,
    /// p / ρ².
    pub pr2: Vec<f32>,
    pub cell: Vec<u32>,
    pub starts: Vec<u32>,
    pub drho: Vec<f32>,
    /// Body particle index of a floating body's particle, [`NOT_BODY`] for the tank's (kept through
    /// sorting).
    pub tag: Vec<u32>,
}

impl<const D: usize> Boundary<D> {
    pub fn len(&self) -> usize {
        self.r.len()
    }

    pub fn is_empty(&self) -> bool {
        self.r.is_empty()
    }

    pub fn clear(&mut self) {
        for k in 0..D {
            self.x[k].clear();
            self.v[k].clear();
        }
        self.rho.clear();
        self.rho0.clear();
        self.r.clear();
        self.p.clear();
        self.pr2.clear();
        self.tag.clear();
    }

    pub fn push(&mut self, x: [f64; D], v: [f64; D], rho: f64, p: f32) {
        for k in 0..D {
            self.x[k].push(x[k] as f32);
            self.v[k].push(v[k] as f32);
        }
        self.rho.push(rho);
        self.rho0.push(rho);
        self.r.push(rho as f32);
        self.p.push(p);
        self.pr2.push(p / (rho * rho) as f32);
        self.tag.push(NOT_BODY);
    }

    /// Sorts by cell (points off the grid are dropped: they cannot reach any fluid particle); returns how
    /// many were dropped.
    pub fn sort(&mut self, grid: &Grid<D>, scratch: &mut SortScratch) -> usize {
        let n = self.len();
        let mut cells = std::mem::take(&mut self.cell);
        cells.clear();
        cells.extend((0..n).map(|i| grid.cell_of(std::array::from_fn(|k| self.x[k][i] as f64))));
        self.cell = cells;
        let keep = counting_sort(
            grid.n_cells(),
            &self.cell,
            &mut self.starts,
            &mut scratch.dest,
        );
        let dest = &scratch.dest;
        let s32 = &mut scratch.f32s;
        for k in 0..D {
            permute(&mut self.x[k], dest, s32, keep);
            permute(&mut self.v[k], dest, s32, keep);
        }
        permute(&mut self.r, dest, s32, keep);
        permute(&mut self.p, dest, s32, keep);
        permute(&mut self.pr2, dest, s32, keep);
        permute(&mut self.rho, dest, &mut scratch.f64s, keep);
        permute(&mut self.rho0, dest, &mut scratch.f64s, keep);
        permute(&mut self.cell, dest, &mut scratch.u32s, keep);
        permute(&mut self.tag, dest, &mut scratch.u32s, keep);
        self.drho.resize(keep, 0.0);
        n - keep
    }
}
