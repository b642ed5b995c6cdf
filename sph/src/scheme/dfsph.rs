//! Divergence-free SPH (Bender & Koschier 2015, 2017): an incompressible scheme whose time step follows the
//! flow speed, not the speed of sound. Each step
//!
//! 1. builds every liquid particle's list of liquid neighbours with their kernel gradients, sums the density,
//!    the DFSPH factor α = 1 / (|Σ m∇W|² + Σ|m∇W|²), the walls' Σ m_b∇W (walls are at rest in the tank
//!    frame, so every wall term of the solver is this sum times the particle's own k or velocity), and adds
//!    the non-pressure accelerations (the tank frame's apparent gravity and rotation terms, Monaghan's
//!    artificial viscosity as in the weakly-compressible scheme);
//! 2. takes dt = CFL · dp / |v|max (also bounded by the accelerations and `dt_max`);
//! 3. makes the velocity field divergence-free (the divergence solver), then predicts v* = v + dt·a and
//!    corrects it until the mean predicted density error is below the tolerance (the constant-density
//!    solver). Both start from half the last step's pressure (warm start) and iterate
//!    `k_i = max(error_i, 0) · α_i / dt^n`,
//!    `Δv_i = −dt Σ_j m_j (k_i + k_j) ∇W_ij − dt Σ_b m_b k_i ∇W_ib` (k plays p/ρ², so p = ρ² Σ k);
//! 4. moves the particles with the corrected velocity.
//!
//! Walls are the dynamic boundary's particle layers, static in the tank frame, taking part in the density
//! sums with their volume and pushing back with the liquid particle's own k (Akinci et al. 2012, as
//! SPlisHSPlasH's DFSPH). Their reaction, summed once from the final k, gives the wrench; wall pressure
//! sensors read the liquid's force on the wall particles (`observe::wall_pressure`). The iterations reuse
//! the neighbour lists; every pass is a gather over fixed chunks that writes only its own particles, so
//! results do not depend on the number of threads.

use super::{FrameTerms, PassTotals, CHUNK};
use crate::kernel::Kernel;
use crate::neighbours::{Grid, Ranges, NO_RANGES};
use crate::params::DfsphSpec;
use crate::particles::{Boundary, Fluid};
use crate::tank::{from3, to3};
use rayon::prelude::*;

/// How strongly walls push back on a liquid particle with k_i: `MIRROR · m_b k_i ∇W_ib` (1: Akinci et al.'s
/// boundary term, as SPlisHSPlasH's DFSPH; full pressure mirroring, 2, makes wall particles jitter here).
pub const MIRROR: f32 = 1.0;

/// Share of the last step's pressure a solve starts from. Each iteration only adds pressure where the
/// liquid is compressed (a monotone update that keeps the Jacobi iteration stable and never sucks liquid
/// together), so a fuller warm start could never be undone where the flow relaxes. (Measured: a projected
/// two-sided update from the full pressure with Chebyshev acceleration needs 2–3× fewer iterations, but its
/// pressure field is noisy enough to shift the first sloshing mode's period by 5 %.)
const WARM: f32 = 0.5;

/// Constants of the scheme in the precision of the loops.
#[derive(Clone, Copy, Debug)]
pub struct Coefficients {
    /// The pair constants shared with the weakly-compressible scheme: h, support², masses, and the
    /// artificial viscosity's c0, α (liquid and wall pairs) and η².
    pub pair: super::wcsph::Coefficients,
    /// The density the solver holds: the summed density of a particle inside the initial lattice.
    pub rho_rest: f32,
    /// Neighbours (liquid and wall) a particle needs for the divergence solver to act on it (fewer: it is
    /// at the free surface).
    pub full_neighbourhood: u32,
}

/// Neighbour lists of one chunk of liquid particles, with the kernel gradients ∇_a W_ab.
#[derive(Debug, Default)]
struct Lists<const D: usize> {
    /// Offsets into `j`/`g` per particle of the chunk (len + 1).
    start: Vec<u32>,
    j: Vec<u32>,
    g: Vec<[f32; D]>,
    /// Per particle of the chunk: Σ_b m_b ∇W_ab over its wall neighbours (walls are at rest in the tank
    /// frame, so every wall term of the solver is this sum times the particle's own k or velocity), the
    /// walls' moment about the tank origin per unit k, Σ_b x_b × (−MIRROR m_b ∇W_ab), and whether the
    /// particle has a full neighbourhood (not at the free surface).
    gb: Vec<[f32; D]>,
    mb: Vec<[f32; 3]>,
    full: Vec<bool>,
}

/// What the passes over the chunks return, merged in chunk order.
#[derive(Clone, Copy, Debug, Default)]
struct Partial {
    totals: PassTotals,
    max_speed: f32,
    error: f64,
}

impl Partial {
    fn merge(&mut self, o: &Partial) {
        self.totals.merge(&o.totals);
        self.max_speed = self.max_speed.max(o.max_speed);
        self.error += o.error;
    }
}

/// Storage reused from step to step (nothing is allocated once the sizes have settled).
#[derive(Debug, Default)]
pub struct Workspace<const D: usize> {
    lists: Vec<Lists<D>>,
    /// Summed density, DFSPH factor, non-pressure acceleration, working velocity, k, Σk, per particle.
    rho: Vec<f32>,
    factor: Vec<f32>,
    acc: Vec<[f32; D]>,
    vel: Vec<[f32; D]>,
    k: Vec<f32>,
    ksum: Vec<f32>,
    /// The divergence solver's total k.
    kdiv: Vec<f32>,
    /// Longest step the iteration control allows now (0: no limit yet).
    dt_cap: f64,
    partials: Vec<Partial>,
}

/// What one step (or a priming solve) did.
#[derive(Clone, Copy, Debug, Default)]
pub struct StepReport {
    pub dt: f64,
    /// Wall force and moment on the liquid over the step, largest acceleration.
    pub totals: PassTotals,
    pub density_iterations: u32,
    pub divergence_iterations: u32,
    /// Mean predicted density error at the end of the constant-density solve (fraction of ρ_rest).
    pub density_error: f64,
    pub converged: bool,
    /// Times the step was solved again at half the step because the solve did not converge.
    pub retries: u32,
}

/// The read-only inputs of the passes.
struct Ctx<'a, const D: usize, K> {
    k: &'a K,
    c: &'a Coefficients,
    grid: &'a Grid<D>,
    frame: &'a FrameTerms,
    fluid: &'a Fluid<D>,
    bound: &'a Boundary<D>,
}

/// Pass 1 for one chunk: neighbour lists, density, factor and non-pressure acceleration.
fn build_chunk<const D: usize, K: Kernel>(
    p: &Ctx<'_, D, K>,
    first: usize,
    lists: &mut Lists<D>,
    (rho, factor, acc): (&mut [f32], &mut [f32], &mut [[f32; D]]),
) -> Partial {
    let (c, f, b) = (p.c, p.fluid, p.bound);
    let mut out = Partial::default();
    let mut ranges: Ranges = NO_RANGES;
    lists.start.clear();
    lists.j.clear();
    lists.g.clear();
    lists.gb.clear();
    lists.mb.clear();
    lists.full.clear();
    let w0 = p.k.w(0.0);
    for o in 0..rho.len() {
        let a = first + o;
        lists.start.push(lists.j.len() as u32);
        let mut walls = 0u32;
        let mut mb = [0.0f32; 3];
        let xa: [f32; D] = std::array::from_fn(|d| f.x[d][a]);
        let va: [f32; D] = std::array::from_fn(|d| f.v[d][a]);
        let mut density = c.pair.m_fluid * w0;
        // Σ m∇W over liquid and over wall neighbours.
        let mut grad = [0.0f32; D];
        let mut grad_b = [0.0f32; D];
        let mut sq = 0.0f32;
        let mut visc = [0.0f32; D];
        let mut wall = [0.0f32; D];
        let mut moment = [0.0f32; 3];
        for (own, starts, xs, m, alpha) in [
            (true, &f.starts, &f.x, c.pair.m_fluid, c.pair.alpha),
            (false, &b.starts, &b.x, c.pair.m_bound, c.pair.alpha_bound),
        ] {
            let n = p.grid.ranges(f.cell[a], starts, &mut ranges);
            for &(lo, hi) in &ranges[..n] {
                for j in lo as usize..hi as usize {
                    if own && j == a {
                        continue;
                    }
                    let mut dx = [0.0f32; D];
                    let mut r2 = 0.0f32;
                    for d in 0..D {
                        dx[d] = xa[d] - xs[d][j];
                        r2 += dx[d] * dx[d];
                    }
                    if r2 >= c.pair.support2 {
                        continue;
                    }
                    let r = r2.sqrt();
                    let gf = p.k.grad_factor(r);
                    let g: [f32; D] = std::array::from_fn(|d| gf * dx[d]);
                    density += m * p.k.w(r);
                    let mut vr = 0.0f32;
                    for d in 0..D {
                        if own {
                            grad[d] += m * g[d];
                        } else {
                            grad_b[d] += m * g[d];
                        }
                        let vb = if own { f.v[d][j] } else { 0.0 };
                        vr += (va[d] - vb) * dx[d];
                    }
                    // Monaghan's artificial viscosity on approaching pairs, densities at ρ_rest.
                    let mu = c.pair.h * vr.min(0.0) / (r2 + c.pair.eta2);
                    let pi = -alpha * c.pair.c0 * mu / c.rho_rest;
                    let mut pair = [0.0f32; D];
                    for d in 0..D {
                        pair[d] = -m * pi * g[d];
                        visc[d] += pair[d];
                    }
                    if own {
                        sq += m * m * (0..D).map(|d| g[d] * g[d]).sum::<f32>();
                        lists.j.push(j as u32);
                        lists.g.push(g);
                    } else {
                        walls += 1;
                        let xb = to3(std::array::from_fn::<f32, D, _>(|d| xs[d][j]));
                        let fk = to3(std::array::from_fn::<f32, D, _>(|d| -MIRROR * m * g[d]));
                        mb[0] += xb[1] * fk[2] - xb[2] * fk[1];
                        mb[1] += xb[2] * fk[0] - xb[0] * fk[2];
                        mb[2] += xb[0] * fk[1] - xb[1] * fk[0];
                        for d in 0..D {
                            wall[d] += pair[d];
                        }
                        let xb = to3(std::array::from_fn::<f32, D, _>(|d| xs[d][j]));
                        let fp = to3(pair);
                        moment[0] += xb[1] * fp[2] - xb[2] * fp[1];
                        moment[1] += xb[2] * fp[0] - xb[0] * fp[2];
                        moment[2] += xb[0] * fp[1] - xb[1] * fp[0];
                    }
                }
            }
        }
        // The particle's own k changes its density through (Σ_f m∇W + Σ_b m∇W)·(Σ_f m∇W + 2 Σ_b m∇W): the
        // walls push back with the mirrored pressure, k_b = k_a.
        // (The Jacobi diagonal; kept positive where liquid and wall gradients oppose.)
        let denom = (0..D)
            .map(|d| (grad[d] + grad_b[d]) * (grad[d] + MIRROR * grad_b[d]))
            .sum::<f32>()
            .max(0.0)
            + sq;
        rho[o] = density;
        lists.gb.push(grad_b);
        lists.mb.push(mb);
        let liquid = (lists.j.len() - lists.start[o] as usize) as u32;
        lists.full.push(liquid + walls >= c.full_neighbourhood);
        factor[o] = if denom > 1e-6 * c.pair.m_fluid * c.pair.m_fluid / (c.pair.h * c.pair.h) {
            1.0 / denom
        } else {
            0.0
        };
        let fa: [f32; D] = from3(p.frame.acceleration(to3(xa), to3(va)));
        let mut a2 = 0.0f32;
        let mut v2 = 0.0f32;
        for d in 0..D {
            acc[o][d] = visc[d] + fa[d];
            a2 += acc[o][d] * acc[o][d];
            v2 += va[d] * va[d];
        }
        if !(a2.is_finite() && density.is_finite()) {
            out.totals.non_finite = true;
        }
        out.totals.max_acc = out.totals.max_acc.max(a2.sqrt());
        out.max_speed = out.max_speed.max(v2.sqrt());
        let w3 = to3(wall);
        for d in 0..3 {
            out.totals.force[d] += (w3[d] * c.pair.m_fluid) as f64;
            out.totals.moment[d] += (moment[d] * c.pair.m_fluid) as f64;
        }
    }
    lists.start.push(lists.j.len() as u32);
    out
}

/// Which error a solve removes.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Mode {
    /// The density predicted after dt (constant-density solver).
    Density,
    /// The rate of change of density (divergence solver).
    Divergence,
}

/// Pass 2 for one chunk: each particle's compression error and its k ≥ 0 (only compression is corrected,
/// which keeps the Jacobi iteration stable and never sucks liquid together). Returns the summed error
/// (density units).
#[allow(clippy::too_many_arguments)]
fn error_chunk<const D: usize>(
    c: &Coefficients,
    mode: Mode,
    dt: f32,
    lists: &Lists<D>,
    vel: &[[f32; D]],
    first: usize,
    (rho, factor): (&[f32], &[f32]),
    k: &mut [f32],
) -> Partial {
    let mut err = 0.0f64;
    for o in 0..k.len() {
        let a = first + o;
        let va = vel[a];
        // One accumulator per dimension: independent chains the CPU can overlap.
        let mut acc = [0.0f32; D];
        let (lo, hi) = (lists.start[o] as usize, lists.start[o + 1] as usize);
        for (j, g) in lists.j[lo..hi].iter().zip(&lists.g[lo..hi]) {
            let vb = vel[*j as usize];
            for d in 0..D {
                acc[d] += (va[d] - vb[d]) * g[d];
            }
        }
        let mut s = c.pair.m_fluid * acc.iter().sum::<f32>();
        let gb = lists.gb[o];
        for d in 0..D {
            s += va[d] * gb[d];
        }
        let (e, kk) = match mode {
            Mode::Density => {
                let e = (rho[o] + dt * s - c.rho_rest).max(0.0);
                (e, e * factor[o] / (dt * dt))
            }
            Mode::Divergence => {
                // At the free surface (too few neighbours) the density may fall: no divergence to remove.
                let e = if lists.full[o] { s.max(0.0) } else { 0.0 };
                (e * dt, e * factor[o] / dt)
            }
        };
        k[o] = kk;
        err += e as f64;
    }
    Partial {
        error: err,
        ..Default::default()
    }
}

/// Pass 3 for one chunk: the velocity change from k (the walls push back with the particle's own k).
fn update_chunk<const D: usize>(
    c: &Coefficients,
    dt: f32,
    lists: &Lists<D>,
    kall: &[f32],
    first: usize,
    vel: &mut [[f32; D]],
    ksum: &mut [f32],
) {
    for o in 0..vel.len() {
        let a = first + o;
        let ka = kall[a];
        ksum[o] += ka;
        let mut acc = [0.0f32; D];
        let (lo, hi) = (lists.start[o] as usize, lists.start[o + 1] as usize);
        for (j, g) in lists.j[lo..hi].iter().zip(&lists.g[lo..hi]) {
            let s = ka + kall[*j as usize];
            for d in 0..D {
                acc[d] -= s * g[d];
            }
        }
        let gb = lists.gb[o];
        for d in 0..D {
            vel[o][d] += dt * (c.pair.m_fluid * acc[d] - MIRROR * ka * gb[d]);
        }
    }
}

/// The walls' force and moment on one chunk's liquid from its total k.
fn wall_chunk<const D: usize>(c: &Coefficients, lists: &Lists<D>, ksum: &[f32]) -> Partial {
    let mut tot = PassTotals::default();
    for (o, k) in ksum.iter().enumerate() {
        let f = to3(std::array::from_fn::<f32, D, _>(|d| {
            -MIRROR * k * lists.gb[o][d]
        }));
        for d in 0..3 {
            tot.force[d] += (f[d] * c.pair.m_fluid) as f64;
            tot.moment[d] += (k * lists.mb[o][d] * c.pair.m_fluid) as f64;
        }
    }
    Partial {
        totals: tot,
        ..Default::default()
    }
}

impl<const D: usize> Workspace<D> {
    fn resize(&mut self, n: usize) {
        self.lists.resize_with(n.div_ceil(CHUNK), Default::default);
        self.rho.resize(n, 0.0);
        self.factor.resize(n, 0.0);
        self.acc.resize(n, [0.0; D]);
        self.vel.resize(n, [0.0; D]);
        self.k.resize(n, 0.0);
        self.ksum.resize(n, 0.0);
    }

    /// Pass 1 over all particles; returns the merged totals.
    fn build<K: Kernel>(&mut self, p: &Ctx<'_, D, K>) -> Partial {
        let Workspace {
            lists,
            rho,
            factor,
            acc,
            partials,
            ..
        } = self;
        rho.par_chunks_mut(CHUNK)
            .zip(factor.par_chunks_mut(CHUNK))
            .zip(acc.par_chunks_mut(CHUNK))
            .zip(lists.par_iter_mut())
            .enumerate()
            .map(|(ci, (((r, f), a), l))| build_chunk(p, ci * CHUNK, l, (r, f, a)))
            .collect_into_vec(partials);
        merged(partials)
    }

    /// Pass 2: errors and k; returns the mean error as a fraction of ρ_rest.
    fn errors(&mut self, c: &Coefficients, mode: Mode, dt: f32) -> f64 {
        let Workspace {
            lists,
            rho,
            factor,
            vel,
            k,
            partials,
            ..
        } = self;
        let n = rho.len();
        let vel = &*vel;
        k.par_chunks_mut(CHUNK)
            .zip(lists.par_iter())
            .enumerate()
            .map(|(ci, (kc, l))| {
                let r = ci * CHUNK..(ci * CHUNK + kc.len());
                error_chunk(
                    c,
                    mode,
                    dt,
                    l,
                    vel,
                    ci * CHUNK,
                    (&rho[r.clone()], &factor[r]),
                    kc,
                )
            })
            .collect_into_vec(partials);
        merged(partials).error / (n.max(1) as f64 * c.rho_rest as f64)
    }

    /// Pass 3: velocity update.
    fn update(&mut self, c: &Coefficients, dt: f32) {
        let Workspace {
            lists,
            vel,
            k,
            ksum,
            ..
        } = self;
        let k = &*k;
        vel.par_chunks_mut(CHUNK)
            .zip(ksum.par_chunks_mut(CHUNK))
            .zip(lists.par_iter())
            .enumerate()
            .for_each(|(ci, ((v, ks), l))| update_chunk(c, dt, l, k, ci * CHUNK, v, ks));
    }

    /// The walls' force and moment on the liquid from the solve's total k.
    fn wall_totals(&mut self, c: &Coefficients) -> PassTotals {
        let Workspace {
            lists,
            ksum,
            partials,
            ..
        } = self;
        ksum.par_chunks(CHUNK)
            .zip(lists.par_iter())
            .map(|(ks, l)| wall_chunk(c, l, ks))
            .collect_into_vec(partials);
        merged(partials).totals
    }

    /// Starts from half the pressure `warm` of the last step (p/ρ², applied as a first velocity update), then
    /// iterates passes 2 and 3 until the mean error is below `tol` (at least `min` iterations, at most
    /// `max`). Returns (iterations, final error, wall totals); `ksum` holds the solve's total k.
    fn solve(
        &mut self,
        c: &Coefficients,
        mode: Mode,
        dt: f32,
        tol: f64,
        (min, max): (u32, u32),
        warm: &[f64],
    ) -> (u32, f64, PassTotals) {
        self.ksum.iter_mut().for_each(|k| *k = 0.0);
        for (k, w) in self.k.iter_mut().zip(warm) {
            *k = WARM * *w as f32;
        }
        self.update(c, dt);
        let mut it = 0;
        loop {
            let err = self.errors(c, mode, dt);
            if (it >= min && err <= tol) || it >= max {
                return (it, err, self.wall_totals(c));
            }
            self.update(c, dt);
            it += 1;
        }
    }
}

fn merged(partials: &[Partial]) -> Partial {
    let mut total = Partial::default();
    for p in partials {
        total.merge(p);
    }
    total
}

/// One DFSPH step of the sorted, refreshed liquid (`fluid.x`, `fluid.v` current): solves, then moves
/// `fluid.pos`/`fluid.vel` (f64) by dt, or, when `prime` is set, only computes the pressures and wall force
/// of the current state and leaves it where it is. Fills `fluid.r` (summed density) and `fluid.p`.
#[allow(clippy::too_many_arguments)]
pub fn step<const D: usize, K: Kernel>(
    kernel: &K,
    c: &Coefficients,
    spec: &DfsphSpec,
    dp: f64,
    grid: &Grid<D>,
    frame: &FrameTerms,
    fluid: &mut Fluid<D>,
    bound: &Boundary<D>,
    work: &mut Workspace<D>,
    dt_limit: f64,
    prime: bool,
) -> StepReport {
    let n = fluid.len();
    work.resize(n);
    let p = Ctx {
        k: kernel,
        c,
        grid,
        frame,
        fluid,
        bound,
    };
    let built = work.build(&p);
    let mut report = StepReport {
        totals: built.totals,
        ..Default::default()
    };
    // dt from the flow speed and the accelerations.
    let vmax = built.max_speed as f64;
    let amax = built.totals.max_acc as f64;
    let mut dt = spec.dt_max;
    if vmax > 0.0 {
        dt = dt.min(spec.cfl * dp / vmax);
    }
    if amax > 0.0 {
        dt = dt.min(spec.cfl * (dp / amax).sqrt());
    }
    let mut control = spec.target_iterations > 0 && !prime;
    if control && work.dt_cap > 0.0 {
        dt = dt.min(work.dt_cap);
    }
    if dt_limit < dt {
        // Cut short to land on an output time or the end of the motion: says nothing about the step the
        // flow allows.
        dt = dt_limit;
        control = false;
    }
    // Shortest step a solve that does not converge is retried at.
    let dt_floor = dt / 16.0;
    loop {
        report.totals = built.totals;
        let dtf = dt as f32;
        for (a, v) in work.vel.iter_mut().enumerate() {
            *v = std::array::from_fn(|d| fluid.v[d][a]);
        }
        work.kdiv.resize(n, 0.0);
        work.kdiv.iter_mut().for_each(|k| *k = 0.0);
        if spec.divergence_solve && !prime {
            let (it, _, t) = work.solve(
                c,
                Mode::Divergence,
                dtf,
                spec.max_divergence_error,
                (1, spec.max_iterations),
                &fluid.kappa_div,
            );
            report.divergence_iterations += it;
            report.totals.force = add(report.totals.force, t.force);
            report.totals.moment = add(report.totals.moment, t.moment);
            work.kdiv.copy_from_slice(&work.ksum);
        }
        for (v, a) in work.vel.iter_mut().zip(&work.acc) {
            for d in 0..D {
                v[d] += dtf * a[d];
            }
        }
        let (it, err, t) = work.solve(
            c,
            Mode::Density,
            dtf,
            spec.max_density_error,
            (spec.min_iterations, spec.max_iterations),
            &fluid.kappa,
        );
        report.density_iterations += it;
        report.density_error = err;
        report.converged = err <= spec.max_density_error;
        report.totals.force = add(report.totals.force, t.force);
        report.totals.moment = add(report.totals.moment, t.moment);
        if control {
            // The next step's limit from this solve's effort.
            if it > spec.target_iterations {
                work.dt_cap = 0.8 * dt;
            } else if 2 * it < spec.target_iterations {
                work.dt_cap = (1.1 * work.dt_cap.max(dt)).min(spec.dt_max);
            } else {
                work.dt_cap = work.dt_cap.max(dt);
            }
        }
        let retry = spec.target_iterations > 0 && !prime && !report.converged;
        if retry && err.is_finite() && 0.5 * dt >= dt_floor {
            // Solve the step again, shorter (nothing has moved yet).
            dt *= 0.5;
            work.dt_cap = dt;
            report.retries += 1;
            continue;
        }
        break;
    }
    report.dt = dt;
    if work.vel.iter().any(|v| !v.iter().all(|x| x.is_finite())) {
        report.totals.non_finite = true;
    }
    // Pressures of the state (p = ρ² Σk) and its summed densities, for the observables.
    for (a, ((k, kd), r)) in work.ksum.iter().zip(&work.kdiv).zip(&work.rho).enumerate() {
        if !prime {
            fluid.kappa[a] = *k as f64;
            fluid.kappa_div[a] = *kd as f64;
        }
        let p = (k + kd) * r * r;
        fluid.r[a] = c.rho_rest;
        fluid.p[a] = p;
        // Incompressible: every particle stands for the volume m / ρ_rest in the observables.
        fluid.rho[a] = c.rho_rest as f64;
        fluid.pressure[a] = p as f64;
    }
    if !prime {
        for (a, v) in work.vel.iter().enumerate() {
            for d in 0..D {
                fluid.vel[d][a] = v[d] as f64;
                fluid.pos[d][a] += dt * v[d] as f64;
            }
        }
    }
    report
}

fn add(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|k| a[k] + b[k])
}
