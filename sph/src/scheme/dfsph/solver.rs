//! The divergence-free scheme's solver: the neighbourhood pass, the divergence and constant-density solves
//! and the move of one step (see [`super`]).

use super::gradient_correction::{self as correction, Mat};
use super::warm_start::{Columns, Setting, WARM};
use crate::domain::{Op, Ranks};
use crate::fast::candidates::{lane_sum, share_room, wide_lanes, Room, LANES};
use crate::fast::half::Half4;
use crate::fast::near::Near;
use crate::fast::pair_sums::Grad;
use crate::kernel::Kernel;
use crate::motion::FrameTerms;
use crate::neighbours::{Grid, Ranges, NO_RANGES};
use crate::particles::{Boundary, Fluid, HALO};
use crate::scheme::landing::landing_step;
use crate::scheme::{PassTotals, State, CHUNK};
use crate::vector::{cross, from3, to3};
use rayon::prelude::*;

/// How strongly walls push back on a liquid particle with k_i: `MIRROR · m_b k_i ∇W_ib` (1: Akinci et al.'s
/// boundary term, as SPlisHSPlasH's DFSPH; full pressure mirroring, 2, stirs a tank at rest, relaxed
/// iterations or not).
pub const MIRROR: f32 = 1.0;

/// Density errors are summed in units of 2^-20 kg/m³, as integers: the sum (and so the iteration count)
/// does not depend on the order of the additions, which differs between one process and several ranks.
const ERR_SCALE: f64 = (1u64 << 20) as f64;

/// Constants of the scheme in the precision of the loops.
#[derive(Clone, Copy, Debug)]
pub struct Coefficients {
    /// The pair constants shared with the weakly-compressible scheme: h, support², masses, and the
    /// artificial viscosity's c0, α (liquid and wall pairs) and η².
    pub pair: crate::scheme::wcsph::Coefficients,
    /// The density the solver holds: the summed density of a particle inside the initial lattice.
    pub rho_rest: f32,
    /// Neighbours (liquid and wall) a particle needs for the divergence solver to act on it (fewer: it is
    /// at the free surface).
    pub full_neighbourhood: u32,
    /// The Jacobi iterations' relaxation ω: each takes ω times the step to its own particle's target
    /// (`solver.dfsph.relaxation`).
    pub relaxation: f32,
    /// Whether the kernel gradients are corrected (`gradient_correction`): the neighbourhood pass then
    /// sums the walls' part of each particle's M.
    pub corrected: bool,
}

/// Neighbour lists of one chunk of liquid particles, with the kernel gradients ∇_a W_ab.
#[derive(Debug, Default)]
struct Lists<const D: usize> {
    /// Offsets into `j`/`g` per particle of the chunk (len + 1).
    start: Vec<u32>,
    j: Vec<u32>,
    /// ∇_a W_ab in 2D; in 3D `gh` holds them instead, times h⁴ in half precision (`half`), four lanes
    /// (the last 0): 8 bytes a pair, two pairs' in one 16-byte load and one conversion (the neighbour's
    /// velocity is one 16-byte load too, `Workspace::vel4`).
    g: Vec<[f32; D]>,
    gh: Vec<Half4>,
    /// One past the largest index in `j` (0 if none): the passes check it once against the arrays they
    /// read the neighbours from, then read them unchecked.
    end_j: usize,
    /// Per particle of the chunk: Σ_b m_b ∇W_ab over its wall neighbours (every wall term of the solver is
    /// this sum times the particle's own k or velocity, and `wall_flux`), the
    /// walls' moment about the tank origin per unit k, Σ_b x_b × (−MIRROR m_b ∇W_ab), and whether the
    /// particle has a full neighbourhood (not at the free surface).
    wall_grad: Vec<[f32; D]>,
    wall_moment: Vec<[f32; 3]>,
    full: Vec<bool>,
    /// Per particle: the walls' part of the gradient correction's M, Σ_b V_b (x_b − x_a) ⊗ ∇W_ab
    /// (`gradient_correction`).
    wall_shape: Vec<Mat<D>>,
    /// Per particle: Σ_b m_b v_b·∇W_ab, what moving walls (floating bodies, a wave maker) add to the rate of
    /// change of its density (0 beside walls at rest).
    wall_flux: Vec<f32>,
}

/// What the passes over the chunks return, merged in chunk order.
#[derive(Clone, Copy, Debug, Default)]
struct Partial {
    totals: PassTotals,
    max_speed: f32,
    /// Summed error in units of 1 / [`ERR_SCALE`].
    error: u64,
}

impl Partial {
    fn merge(&mut self, o: &Partial) {
        self.totals.merge(&o.totals);
        self.max_speed = self.max_speed.max(o.max_speed);
        self.error = self.error.saturating_add(o.error);
    }
}

/// Storage reused from step to step (nothing is allocated once the sizes have settled).
#[derive(Debug, Default)]
pub struct Workspace<const D: usize> {
    lists: Vec<Lists<D>>,
    /// The selected liquid and wall neighbours of the particle being built, one pair per chunk.
    near: Vec<(Near<D>, Near<D>)>,
    /// Summed density, DFSPH factor, non-pressure acceleration, working velocity, k, Σk, per particle.
    rho: Vec<f32>,
    factor: Vec<f32>,
    acc: Vec<[f32; D]>,
    vel: Vec<[f32; D]>,
    k: Vec<f32>,
    ksum: Vec<f32>,
    /// In 3D, `vel` padded to four lanes for the error pass's neighbour loads (refreshed before each).
    vel4: Vec<[f32; 4]>,
    /// The divergence solver's total k.
    kdiv: Vec<f32>,
    /// Longest step the iteration control allows now (0: no limit yet).
    dt_cap: f64,
    /// Longest step something else (moving bodies) allows (0: none).
    dt_bound: f64,
    partials: Vec<Partial>,
    /// Where the constant-density solve starts (per particle), and the columns that make it.
    start: Vec<f64>,
    columns: Columns,
    /// Correct the kernel gradients (`gradient_correction`), and each particle's L = M⁻¹ when it does.
    corrected: bool,
    corr: Vec<Mat<D>>,
    /// One component of `corr` at a time, for the halo exchange.
    component: Vec<f32>,
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
    /// Run the neighbourhood sums with AVX2 + FMA (and F16C for the 3D lists' half records).
    wide: bool,
}

/// What one liquid particle's neighbourhood sums to (pass 1).
#[derive(Clone, Copy, Debug, PartialEq)]
struct Neighbourhood<const D: usize> {
    /// Summed density (the particle itself included).
    density: f32,
    /// Σ m∇W over liquid and over wall neighbours, Σ|m∇W|² over liquid neighbours.
    grad: [f32; D],
    grad_b: [f32; D],
    sq: f32,
    /// Artificial viscosity's acceleration (all neighbours), its wall part, and that part's moment.
    visc: [f32; D],
    wall: [f32; D],
    moment: [f32; 3],
    /// Σ_b x_b × (−MIRROR m_b ∇W_ab): the walls' pressure moment per unit k. (Every pair force acts along
    /// x_a − x_b, so Σ_b x_b × f_b = x_a × Σ_b f_b: the moments are the particle's position crossed with
    /// the summed forces, not sums over the pairs.)
    wall_moment: [f32; 3],
    /// Σ_b m_b v_b·∇W_ab.
    wflux: f32,
    /// Σ_b V_b (x_b − x_a) ⊗ ∇W_ab over the wall neighbours.
    shape_b: Mat<D>,
    /// Liquid and wall neighbours within the support.
    liquid: u32,
    walls: u32,
}

/// Per-lane partial sums of a [`Neighbourhood`].
struct NeighbourhoodLanes<const D: usize> {
    density: [f32; LANES],
    grad: [[f32; LANES]; D],
    grad_b: [[f32; LANES]; D],
    sq: [f32; LANES],
    visc: [[f32; LANES]; D],
    wall: [[f32; LANES]; D],
    wflux: [f32; LANES],
    walls: [f32; LANES],
    shape_b: [[[f32; LANES]; D]; D],
}

/// Where a particle's neighbours are: the rows of cells around it (ranges of the cell-sorted arrays) of the
/// liquid and of the walls, and those arrays (positions, velocities).
#[derive(Clone, Copy)]
struct Rows<'a, const D: usize> {
    liquid: &'a [(u32, u32)],
    walls: &'a [(u32, u32)],
    fluid: (&'a [Vec<f32>; D], &'a [Vec<f32>; D]),
    bound: (&'a [Vec<f32>; D], &'a [Vec<f32>; D]),
}

/// The neighbourhood of liquid particle (xa, va) among the particles `around` it, selected into `fs`
/// (liquid) and `bs` (walls) (packed with AVX2 where `wide`); appends its liquid neighbours (not itself)
/// and their ∇W_ab times `R::scale(h)` to `j`/`g` as records R (of W lanes, those beyond D 0).
/// Branch-free over blocks of [`LANES`]: padding beyond the support adds nothing.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn neighbourhood<const D: usize, const W: usize, R: Grad<D, W>, K: Kernel>(
    k: &K,
    c: &Coefficients,
    (xa, va): ([f32; D], [f32; D]),
    around: Rows<'_, D>,
    (fs, bs): (&mut Near<D>, &mut Near<D>),
    j: &mut Vec<u32>,
    g: &mut Vec<R>,
    wide: bool,
) -> Neighbourhood<D> {
    fs.select(xa, c.pair.support2, around.liquid, around.fluid, wide);
    bs.select(xa, c.pair.support2, around.walls, around.bound, wide);
    let z = [0.0f32; LANES];
    let mut s = NeighbourhoodLanes {
        density: z,
        grad: [z; D],
        grad_b: [z; D],
        sq: z,
        visc: [z; D],
        wall: [z; D],
        wflux: z,
        walls: z,
        shape_b: [[z; D]; D],
    };
    let first = j.len();
    // What the records hold: ∇W times this.
    let scale = R::scale(c.pair.h);
    // Every lane is written after the end of the list and kept only if it is a neighbour (no branches on
    // whether it is).
    // Room for every selected lane, padding included.
    j.reserve(fs.blocks() * LANES);
    g.reserve(fs.blocks() * LANES);
    let (js, gs) = (j.spare_capacity_mut(), g.spare_capacity_mut());
    let mut n = 0;
    let (mf, wall_shape) = (c.pair.m_fluid, c.pair.m_bound);
    // Monaghan's Π_ab = −α c0 h min(v_ab·x_ab, 0) / ((r² + η²) ρ_rest): the constant factor of each.
    let visc = c.pair.alpha * c.pair.c0 * c.pair.h / c.rho_rest;
    let visc_b = c.pair.alpha_bound * c.pair.c0 * c.pair.h / c.rho_rest;
    let vol_b = wall_shape / c.rho_rest;
    for blk in 0..fs.blocks() {
        let (dxs, ws, idx) = fs.block(blk);
        let mut gl = [z; D];
        let mut hit = [false; LANES];
        for l in 0..LANES {
            let dx: [f32; D] = std::array::from_fn(|d| dxs[d][l]);
            let (mut r2, mut vr) = (0.0f32, 0.0f32);
            for d in 0..D {
                r2 += dx[d] * dx[d];
                vr += va[d] * dx[d];
            }
            // (v_a − v_b)·(x_a − x_b)
            let vr = vr - ws[l];
            let inside = r2 < c.pair.support2;
            let fin = if inside { 1.0f32 } else { 0.0 };
            let r = r2.sqrt();
            let gf = k.grad_factor(r) * fin;
            s.density[l] += mf * k.w(r) * fin;
            // Monaghan's artificial viscosity on approaching pairs, densities at ρ_rest.
            let pi = -visc * vr.min(0.0) / (r2 + c.pair.eta2);
            let mut g2 = 0.0f32;
            for d in 0..D {
                let gd = gf * dx[d];
                gl[d][l] = gd;
                g2 += gd * gd;
                s.grad[d][l] += mf * gd;
                s.visc[d][l] -= mf * pi * gd;
            }
            s.sq[l] += mf * mf * g2;
            hit[l] = inside && r2 > 0.0;
        }
        #[cfg(target_arch = "x86_64")]
        if wide && D == 3 && R::AVX_BLOCKS {
            // (Only `Half4` stores blocks: eight 8-byte records.)
            assert_eq!(std::mem::size_of::<R>(), 8);
            let mask = (0..LANES).fold(0usize, |m, l| m | (hit[l] as usize) << l);
            // SAFETY: `wide` holds only where the CPU has AVX2 and F16C; n + LANES ≤ (blk + 1) · LANES ≤
            // the room reserved above (n ≤ blk · LANES); D == 3, and records of `AVX_BLOCKS` types are
            // `Half4`s.
            unsafe {
                store_block_avx2(
                    mask,
                    [&gl[0], &gl[1], &gl[2 % D]],
                    scale,
                    &idx,
                    js.as_mut_ptr().add(n).cast(),
                    gs.as_mut_ptr().add(n).cast(),
                )
            };
            n += mask.count_ones() as usize;
            continue;
        }
        for l in 0..LANES {
            js[n].write(idx[l]);
            gs[n].write(R::pack(std::array::from_fn(|d| gl[d][l] * scale)));
            n += hit[l] as usize;
        }
    }
    // SAFETY: the first n entries of the spare capacity were written above.
    unsafe {
        j.set_len(first + n);
        g.set_len(first + n);
    }
    for blk in 0..bs.blocks() {
        let (dxs, ws, _) = bs.block(blk);
        for l in 0..LANES {
            let dx: [f32; D] = std::array::from_fn(|d| dxs[d][l]);
            let (mut r2, mut vr) = (0.0f32, 0.0f32);
            for d in 0..D {
                r2 += dx[d] * dx[d];
                vr += va[d] * dx[d];
            }
            let vr = vr - ws[l];
            let fin = if r2 < c.pair.support2 { 1.0f32 } else { 0.0 };
            let r = r2.sqrt();
            let gf = k.grad_factor(r) * fin;
            s.density[l] += wall_shape * k.w(r) * fin;
            let pi = -visc_b * vr.min(0.0) / (r2 + c.pair.eta2);
            for d in 0..D {
                let gd = gf * dx[d];
                s.grad_b[d][l] += wall_shape * gd;
                s.wall[d][l] -= wall_shape * pi * gd;
            }
            // m_b v_b·∇W_ab = m_b F(r) v_b·(x_a − x_b)
            s.wflux[l] += wall_shape * gf * ws[l];
            s.walls[l] += fin;
            // V_b (x_b − x_a) ⊗ ∇W_ab = −V_b F(r) dx ⊗ dx
            if c.corrected {
                for r in 0..D {
                    for q in 0..D {
                        s.shape_b[r][q][l] -= vol_b * gf * dx[r] * dx[q];
                    }
                }
            }
        }
    }
    let wall: [f32; D] = std::array::from_fn(|d| lane_sum(&s.wall[d]));
    let grad_b: [f32; D] = std::array::from_fn(|d| lane_sum(&s.grad_b[d]));
    let push: [f32; D] = std::array::from_fn(|d| -MIRROR * grad_b[d]);
    Neighbourhood {
        density: lane_sum(&s.density),
        grad: std::array::from_fn(|d| lane_sum(&s.grad[d])),
        grad_b,
        sq: lane_sum(&s.sq),
        visc: std::array::from_fn(|d| lane_sum(&s.visc[d]) + wall[d]),
        wall,
        moment: cross(to3(xa), to3(wall)),
        wall_moment: cross(to3(xa), to3(push)),
        wflux: lane_sum(&s.wflux),
        shape_b: std::array::from_fn(|r| std::array::from_fn(|q| lane_sum(&s.shape_b[r][q]))),
        liquid: n as u32,
        walls: lane_sum(&s.walls) as u32,
    }
}

/// The lanes of one block of 3D neighbours set in `mask`, packed to the front (one lane permutation,
/// `near::PACK`), as eight [`Half4`] records of the gradients times `scale` (x, y, z, 0) and eight
/// indices, stored whole at `j` and `g` (what lies beyond the kept lanes is overwritten by the next block
/// or cut off): the same bits in the same order as `neighbourhood`'s lane-by-lane writes (F16C rounds as
/// `half::to_half`), in ~30 instructions instead of ~150.
///
/// # Safety
/// The CPU has AVX2 and F16C; `j` has room for 8 u32 and `g` for 32 u16.
#[cfg(target_arch = "x86_64")]
#[inline(always)]
unsafe fn store_block_avx2(
    mask: usize,
    gl: [&[f32; LANES]; 3],
    scale: f32,
    idx: &[u32; LANES],
    j: *mut u32,
    g: *mut u16,
) {
    use std::arch::x86_64::*;
    const { assert!(LANES == 8, "one 256-bit register of f32 lanes") };
    // SAFETY: AVX2 and F16C (the caller); the loads read whole arrays of 8 lanes, the stores stay within
    // the room the caller guarantees; the table is 32-byte aligned.
    unsafe {
        let perm = _mm256_load_si256(crate::fast::near::PACK.0[mask].as_ptr() as *const __m256i);
        let s = _mm256_set1_ps(scale);
        // (No closures here: a closure would not inherit AVX2, and the intrinsics would not be inlined.)
        let x = _mm256_permutevar8x32_ps(_mm256_mul_ps(_mm256_loadu_ps(gl[0].as_ptr()), s), perm);
        let y = _mm256_permutevar8x32_ps(_mm256_mul_ps(_mm256_loadu_ps(gl[1].as_ptr()), s), perm);
        let z = _mm256_permutevar8x32_ps(_mm256_mul_ps(_mm256_loadu_ps(gl[2].as_ptr()), s), perm);
        let zero = _mm256_setzero_ps();
        // Per 128-bit half: (x0 y0 x1 y1), (x2 y2 x3 y3), (z0 0 z1 0), (z2 0 z3 0) …
        let (t0, t1) = (_mm256_unpacklo_ps(x, y), _mm256_unpackhi_ps(x, y));
        let (t2, t3) = (_mm256_unpacklo_ps(z, zero), _mm256_unpackhi_ps(z, zero));
        // … then records 0 | 4, 1 | 5, 2 | 6, 3 | 7.
        let r0 = _mm256_shuffle_ps::<0x44>(t0, t2);
        let r1 = _mm256_shuffle_ps::<0xEE>(t0, t2);
        let r2 = _mm256_shuffle_ps::<0x44>(t1, t3);
        let r3 = _mm256_shuffle_ps::<0xEE>(t1, t3);
        // Two records (8 binary16, rounded to nearest even) per store.
        const NEAREST: i32 = _MM_FROUND_TO_NEAREST_INT;
        let (a, b) = (
            _mm256_permute2f128_ps::<0x20>(r0, r1),
            _mm256_permute2f128_ps::<0x20>(r2, r3),
        );
        _mm_storeu_si128(g as *mut __m128i, _mm256_cvtps_ph::<NEAREST>(a));
        _mm_storeu_si128(g.add(8) as *mut __m128i, _mm256_cvtps_ph::<NEAREST>(b));
        let (a, b) = (
            _mm256_permute2f128_ps::<0x31>(r0, r1),
            _mm256_permute2f128_ps::<0x31>(r2, r3),
        );
        _mm_storeu_si128(g.add(16) as *mut __m128i, _mm256_cvtps_ph::<NEAREST>(a));
        _mm_storeu_si128(g.add(24) as *mut __m128i, _mm256_cvtps_ph::<NEAREST>(b));
        let i = _mm256_loadu_si256(idx.as_ptr() as *const __m256i);
        _mm256_storeu_si256(j as *mut __m256i, _mm256_permutevar8x32_epi32(i, perm));
    }
}

/// [`neighbourhood`] compiled for AVX2 + FMA (popcnt, F16C): the same source, its lane loops vectorised 8 wide.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma,popcnt,f16c")]
fn neighbourhood_avx2<const D: usize, const W: usize, R: Grad<D, W>, K: Kernel>(
    k: &K,
    c: &Coefficients,
    own: ([f32; D], [f32; D]),
    around: Rows<'_, D>,
    near: (&mut Near<D>, &mut Near<D>),
    j: &mut Vec<u32>,
    g: &mut Vec<R>,
) -> Neighbourhood<D> {
    neighbourhood(k, c, own, around, near, j, g, true)
}

/// Pass 1 for one chunk: neighbour lists, density, factor and non-pressure acceleration.
fn build_chunk<const D: usize, K: Kernel>(
    p: &Ctx<'_, D, K>,
    first: usize,
    lists: &mut Lists<D>,
    (fs, bs): &mut (Near<D>, Near<D>),
    (rho, factor, acc): (&mut [f32], &mut [f32], &mut [[f32; D]]),
) -> Partial {
    let (c, f, b) = (p.c, p.fluid, p.bound);
    let mut out = Partial::default();
    let (mut liquid, mut walls): (Ranges, Ranges) = (NO_RANGES, NO_RANGES);
    let (mut nl, mut nw) = (0, 0);
    lists.start.clear();
    lists.j.clear();
    lists.g.clear();
    lists.gh.clear();
    // Until the lists are whole again (a build cut short leaves no bound the passes would trust).
    lists.end_j = usize::MAX;
    lists.wall_grad.clear();
    lists.wall_flux.clear();
    lists.wall_moment.clear();
    lists.full.clear();
    lists.wall_shape.clear();
    // The cell whose rows of neighbouring cells are in `liquid` and `walls`.
    let mut cell = u32::MAX;
    for o in 0..rho.len() {
        let a = first + o;
        if f.id[a] & HALO != 0 {
            // A halo copy (across ranks): its owner solves for it; it takes no part here but as a
            // neighbour, with no error and no k of its own until its owner's arrive.
            lists.start.push(lists.j.len() as u32);
            rho[o] = c.rho_rest;
            factor[o] = 0.0;
            acc[o] = [0.0; D];
            lists.wall_grad.push([0.0; D]);
            lists.wall_flux.push(0.0);
            lists.wall_moment.push([0.0; 3]);
            lists.full.push(false);
            lists.wall_shape.push([[0.0; D]; D]);
            continue;
        }
        if f.cell[a] != cell {
            // Particles are sorted by cell: the rows around change only with the cell.
            cell = f.cell[a];
            (nl, nw) =
                p.grid
                    .ranges_of_two(cell, (&f.starts, &mut liquid), (&b.starts, &mut walls));
        }
        lists.start.push(lists.j.len() as u32);
        let xa: [f32; D] = std::array::from_fn(|d| f.x32[d][a]);
        let va: [f32; D] = std::array::from_fn(|d| f.v32[d][a]);
        let own = (xa, va);
        let around = Rows {
            liquid: &liquid[..nl],
            walls: &walls[..nw],
            fluid: (&f.x32, &f.v32),
            bound: (&b.x, &b.v),
        };
        let near = (&mut *fs, &mut *bs);
        let (j, g, gh) = (&mut lists.j, &mut lists.g, &mut lists.gh);
        let hd = match (p.wide, D == 3) {
            // SAFETY: `wide` is true only where the CPU reports AVX2, FMA, popcnt and F16C.
            #[cfg(target_arch = "x86_64")]
            (true, true) => unsafe {
                neighbourhood_avx2::<D, 4, Half4, K>(p.k, c, own, around, near, j, gh)
            },
            #[cfg(target_arch = "x86_64")]
            (true, false) => unsafe {
                neighbourhood_avx2::<D, D, _, K>(p.k, c, own, around, near, j, g)
            },
            #[cfg(not(target_arch = "x86_64"))]
            (true, _) => unreachable!("wide lanes are x86_64 only"),
            (false, true) => {
                neighbourhood::<D, 4, Half4, K>(p.k, c, own, around, near, j, gh, false)
            }
            (false, false) => neighbourhood::<D, D, _, K>(p.k, c, own, around, near, j, g, false),
        };
        rho[o] = hd.density;
        lists.wall_grad.push(hd.grad_b);
        lists.wall_flux.push(hd.wflux);
        lists.wall_moment.push(hd.wall_moment);
        lists
            .full
            .push(hd.liquid + hd.walls >= c.full_neighbourhood);
        lists.wall_shape.push(hd.shape_b);
        factor[o] = dfsph_factor(c, hd.grad, hd.grad_b, hd.sq);
        let fa: [f32; D] = from3(p.frame.acceleration(to3(xa), to3(va)));
        let mut a2 = 0.0f32;
        let mut v2 = 0.0f32;
        for d in 0..D {
            acc[o][d] = hd.visc[d] + fa[d];
            a2 += acc[o][d] * acc[o][d];
            v2 += va[d] * va[d];
        }
        if !(a2.is_finite() && hd.density.is_finite()) {
            out.totals.non_finite = true;
        }
        out.totals.max_acc = out.totals.max_acc.max(a2.sqrt());
        out.max_speed = out.max_speed.max(v2.sqrt());
        let w3 = to3(hd.wall);
        for d in 0..3 {
            out.totals.force[d] += (w3[d] * c.pair.m_fluid) as f64;
            out.totals.moment[d] += (hd.moment[d] * c.pair.m_fluid) as f64;
        }
    }
    lists.start.push(lists.j.len() as u32);
    lists.end_j = lists.j.iter().max().map_or(0, |m| *m as usize + 1);
    out
}

/// The relaxed DFSPH factor ω / (|Σ_f m∇W + Σ_b m∇W|·… + Σ_f |m∇W|²) of a particle whose liquid and wall
/// neighbours' gradients sum to `grad` and `grad_b` (times m) and whose liquid ones' squares to `sq`: its
/// own k changes its density through (Σ_f m∇W + Σ_b m∇W)·(Σ_f m∇W + MIRROR Σ_b m∇W) (the walls push back
/// with the particle's own k). The Jacobi diagonal, kept positive where liquid and wall gradients oppose;
/// 0 where it vanishes (a lone particle).
fn dfsph_factor<const D: usize>(
    c: &Coefficients,
    grad: [f32; D],
    grad_b: [f32; D],
    sq: f32,
) -> f32 {
    let denom = (0..D)
        .map(|d| (grad[d] + grad_b[d]) * (grad[d] + MIRROR * grad_b[d]))
        .sum::<f32>()
        .max(0.0)
        + sq;
    if denom > 1e-6 * c.pair.m_fluid * c.pair.m_fluid / (c.pair.h * c.pair.h) {
        c.relaxation / denom
    } else {
        0.0
    }
}

/// Correction pass, first half, for one chunk: each particle's L (`gradient_correction`) from its liquid
/// neighbours' records and positions and its walls' part `wall_shape` (halo copies' are replaced by their owners'
/// afterwards).
fn correction_chunk<const D: usize, const W: usize, R: Grad<D, W>>(
    c: &Coefficients,
    (lists, g): (&Lists<D>, &[R]),
    x: &[Vec<f32>; D],
    first: usize,
    out: &mut [Mat<D>],
) {
    let vol = c.pair.m_fluid / c.rho_rest;
    let unscale = 1.0 / R::scale(c.pair.h);
    for (o, l) in out.iter_mut().enumerate() {
        let a = first + o;
        let mut m = lists.wall_shape[o];
        let (lo, hi) = (lists.start[o] as usize, lists.start[o + 1] as usize);
        for q in lo..hi {
            let b = lists.j[q] as usize;
            let lanes = g[q].lanes();
            let gr: [f32; D] = std::array::from_fn(|d| lanes[d] * unscale);
            let dx: [f32; D] = std::array::from_fn(|d| x[d][b] - x[d][a]);
            correction::add_pair(&mut m, vol, dx, gr);
        }
        *l = correction::inverse_or_identity(&m);
    }
}

/// Correction pass, second half, for one chunk: every record ∇W_ab becomes ½(L_a + L_b)∇W_ab, the walls'
/// Σ m_b∇W_ab becomes L_a Σ m_b∇W_ab (and its moment with it), and the DFSPH factor is made again from the
/// corrected gradients.
fn corrected_chunk<const D: usize, const W: usize, R: Grad<D, W>>(
    c: &Coefficients,
    lists: &mut Lists<D>,
    g: &mut [R],
    corr: &[Mat<D>],
    x: &[Vec<f32>; D],
    first: usize,
    factor: &mut [f32],
) {
    let m = c.pair.m_fluid;
    let unscale = 1.0 / R::scale(c.pair.h);
    for (o, f) in factor.iter_mut().enumerate() {
        let a = first + o;
        let la = &corr[a];
        let (lo, hi) = (lists.start[o] as usize, lists.start[o + 1] as usize);
        let (mut grad, mut sq) = ([0.0f32; D], 0.0f32);
        for q in lo..hi {
            let b = lists.j[q] as usize;
            let lanes = g[q].lanes();
            let gr: [f32; D] = std::array::from_fn(|d| lanes[d]);
            let gc = correction::apply(&correction::mean(la, &corr[b]), gr);
            g[q] = R::pack(gc);
            let back = g[q].lanes();
            for d in 0..D {
                let gd = m * back[d] * unscale;
                grad[d] += gd;
                sq += gd * gd;
            }
        }
        let wall_grad = correction::apply(la, lists.wall_grad[o]);
        lists.wall_grad[o] = wall_grad;
        let xa: [f32; D] = std::array::from_fn(|d| x[d][a]);
        let push: [f32; D] = std::array::from_fn(|d| -MIRROR * wall_grad[d]);
        lists.wall_moment[o] = cross(to3(xa), to3(push));
        // (0 for halo copies and lone particles, which have no neighbours: as in the first pass.)
        *f = dfsph_factor(c, grad, wall_grad, sq);
    }
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
#[inline(always)]
fn error_chunk<const D: usize, const W: usize, R: Grad<D, W>>(
    wide: bool,
    c: &Coefficients,
    mode: Mode,
    dt: f32,
    (lists, g): (&Lists<D>, &[R]),
    vel: &[[f32; W]],
    first: usize,
    (rho, factor): (&[f32], &[f32]),
    k: &mut [f32],
) -> Partial {
    let mut err = 0u64;
    let (inv_dt, inv_dt2) = (1.0 / dt, 1.0 / (dt * dt));
    // The records hold ∇W times the scale (1 for f32 records: then m exactly).
    let m = c.pair.m_fluid / R::scale(c.pair.h);
    assert!(lists.end_j <= vel.len() && lists.start.len() == k.len() + 1);
    for o in 0..k.len() {
        let a = first + o;
        let va = vel[a];
        let (lo, hi) = (lists.start[o] as usize, lists.start[o + 1] as usize);
        // SAFETY: every index in the lists is below `end_j` (asserted above); `wide` (from `wide_lanes()`)
        // only where the CPU has AVX2, so AVX, and F16C.
        let mut s = m * unsafe { R::divergence(&lists.j[lo..hi], &g[lo..hi], vel, va, wide) }
            .iter()
            .take(D)
            .sum::<f32>();
        let wall_grad = lists.wall_grad[o];
        for d in 0..D {
            s += va[d] * wall_grad[d];
        }
        s -= lists.wall_flux[o];
        let (e, kk) = match mode {
            Mode::Density => {
                let e = (rho[o] + dt * s - c.rho_rest).max(0.0);
                (e, e * factor[o] * inv_dt2)
            }
            Mode::Divergence => {
                // At the free surface (too few neighbours) the density may fall: no divergence to remove.
                let e = if lists.full[o] { s.max(0.0) } else { 0.0 };
                (e * dt, e * factor[o] * inv_dt)
            }
        };
        k[o] = kk;
        // e ≥ 0: adding ½ and truncating rounds, and through i64 it is one instruction (no libm call).
        // (A non-finite error saturates instead of wrapping round to a small sum.)
        err = err.saturating_add((e as f64 * ERR_SCALE + 0.5) as i64 as u64);
    }
    Partial {
        error: err,
        ..Default::default()
    }
}

/// Pass 3 for one chunk: the velocity change from k (the walls push back with the particle's own k), also
/// written padded to four lanes into `vel4` unless that is empty.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn update_chunk<const D: usize, const W: usize, R: Grad<D, W>>(
    wide: bool,
    c: &Coefficients,
    dt: f32,
    (lists, g): (&Lists<D>, &[R]),
    kall: &[f32],
    first: usize,
    vel: &mut [[f32; D]],
    ksum: &mut [f32],
    vel4: &mut [[f32; 4]],
) {
    assert!(lists.end_j <= kall.len() && lists.start.len() == vel.len() + 1);
    let m = c.pair.m_fluid / R::scale(c.pair.h);
    assert!(vel4.is_empty() || vel4.len() == vel.len());
    for o in 0..vel.len() {
        let a = first + o;
        let ka = kall[a];
        ksum[o] += ka;
        let (lo, hi) = (lists.start[o] as usize, lists.start[o + 1] as usize);
        // SAFETY: every index in the lists is below `end_j` (asserted above); `wide` only with AVX, as in
        // `error_chunk`.
        let acc = unsafe { R::push(&lists.j[lo..hi], &g[lo..hi], kall, ka, wide) };
        let wall_grad = lists.wall_grad[o];
        for d in 0..D {
            vel[o][d] -= dt * (m * acc[d] + MIRROR * ka * wall_grad[d]);
        }
        if let Some(p) = vel4.get_mut(o) {
            *p = std::array::from_fn(|d| if d < D { vel[o][d] } else { 0.0 });
        }
    }
}

/// Runs `f` compiled with AVX where `wide` (three-operand instructions, fewer register copies: `f` and what
/// it inlines are compiled into the AVX function), plainly elsewhere.
#[inline(always)]
fn maybe_avx<R>(wide: bool, f: impl FnOnce() -> R) -> R {
    #[cfg(target_arch = "x86_64")]
    if wide {
        #[target_feature(enable = "avx,f16c")]
        fn avx<R>(f: impl FnOnce() -> R) -> R {
            f()
        }
        // SAFETY: `wide` is true only where the CPU reports AVX2 (and so AVX) and F16C.
        return unsafe { avx(f) };
    }
    let _ = wide;
    f()
}

/// [`error_chunk`] kept out of line (called once per chunk: the passes show by name in profiles, with AVX
/// as `maybe_avx::avx` instantiated for this function's closure), with AVX where `wide`.
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn error_pass<const D: usize, const W: usize, R: Grad<D, W>>(
    wide: bool,
    c: &Coefficients,
    mode: Mode,
    dt: f32,
    lists: (&Lists<D>, &[R]),
    vel: &[[f32; W]],
    first: usize,
    own: (&[f32], &[f32]),
    k: &mut [f32],
) -> Partial {
    maybe_avx(wide, || {
        error_chunk(wide, c, mode, dt, lists, vel, first, own, k)
    })
}

/// [`update_chunk`] out of line and with AVX where `wide`, as [`error_pass`].
#[allow(clippy::too_many_arguments)]
#[inline(never)]
fn update_pass<const D: usize, const W: usize, R: Grad<D, W>>(
    wide: bool,
    c: &Coefficients,
    dt: f32,
    lists: (&Lists<D>, &[R]),
    kall: &[f32],
    first: usize,
    (vel, ksum, vel4): (&mut [[f32; D]], &mut [f32], &mut [[f32; 4]]),
) {
    maybe_avx(wide, || {
        update_chunk(wide, c, dt, lists, kall, first, vel, ksum, vel4)
    })
}

/// The walls' force and moment on one chunk's liquid from its total k.
fn wall_chunk<const D: usize>(c: &Coefficients, lists: &Lists<D>, ksum: &[f32]) -> Partial {
    let mut tot = PassTotals::default();
    for (o, k) in ksum.iter().enumerate() {
        let f = to3(std::array::from_fn::<f32, D, _>(|d| {
            -MIRROR * k * lists.wall_grad[o][d]
        }));
        for d in 0..3 {
            tot.force[d] += (f[d] * c.pair.m_fluid) as f64;
            tot.moment[d] += (k * lists.wall_moment[o][d] * c.pair.m_fluid) as f64;
        }
    }
    Partial {
        totals: tot,
        ..Default::default()
    }
}

impl<const D: usize> Workspace<D> {
    /// Bounds the next steps by `dt` (∞: no bound), beside the flow's own limits and the iteration control.
    pub fn bound(&mut self, dt: f64) {
        self.dt_bound = if dt.is_finite() { dt } else { 0.0 };
    }

    /// Each particle's total k of the last solve: the constant-density and divergence solves' (what the
    /// walls' push-back used).
    pub fn total_k(&self, a: usize) -> f32 {
        self.ksum[a] + self.kdiv[a]
    }

    fn resize(&mut self, n: usize) {
        self.lists.resize_with(n.div_ceil(CHUNK), Default::default);
        self.near.resize_with(n.div_ceil(CHUNK), Default::default);
        self.rho.resize(n, 0.0);
        self.factor.resize(n, 0.0);
        self.acc.resize(n, [0.0; D]);
        self.vel.resize(n, [0.0; D]);
        self.k.resize(n, 0.0);
        self.ksum.resize(n, 0.0);
        self.vel4.resize(if D == 3 { n } else { 0 }, [0.0; 4]);
    }

    /// Turns the kernel gradient correction on or off (`solver.dfsph.kernel_correction`; off with bodies).
    pub fn correct_gradients(&mut self, on: bool) {
        self.corrected = on;
    }

    /// The correction pass (after pass 1): every particle's L, its halo copies' from their owners, then the
    /// corrected records, wall sums and factors.
    fn correct<K: Kernel>(&mut self, p: &Ctx<'_, D, K>, ranks: Option<&mut (dyn Ranks<D> + '_)>) {
        let Workspace {
            lists,
            factor,
            corr,
            component,
            ..
        } = self;
        let (c, x) = (p.c, &p.fluid.x32);
        corr.resize(factor.len(), correction::identity());
        corr.par_chunks_mut(CHUNK)
            .zip(lists.par_iter())
            .enumerate()
            .for_each(|(ci, (out, l))| {
                if D == 3 {
                    correction_chunk(c, (l, &l.gh), x, ci * CHUNK, out)
                } else {
                    correction_chunk(c, (l, &l.g), x, ci * CHUNK, out)
                }
            });
        if let Some(r) = ranks {
            component.resize(corr.len(), 0.0);
            for row in 0..D {
                for col in 0..D {
                    for (v, m) in component.iter_mut().zip(corr.iter()) {
                        *v = m[row][col];
                    }
                    r.sync_scalar(component);
                    for (v, m) in component.iter().zip(corr.iter_mut()) {
                        m[row][col] = *v;
                    }
                }
            }
        }
        let corr = &*corr;
        factor
            .par_chunks_mut(CHUNK)
            .zip(lists.par_iter_mut())
            .enumerate()
            .for_each(|(ci, (f, l))| {
                if D == 3 {
                    let mut gh = std::mem::take(&mut l.gh);
                    corrected_chunk(c, l, &mut gh, corr, x, ci * CHUNK, f);
                    l.gh = gh;
                } else {
                    let mut g = std::mem::take(&mut l.g);
                    corrected_chunk(c, l, &mut g, corr, x, ci * CHUNK, f);
                    l.g = g;
                }
            });
    }

    /// Pass 1 over all particles; returns the merged totals.
    fn build<K: Kernel>(&mut self, p: &Ctx<'_, D, K>) -> Partial {
        let Workspace {
            lists,
            near,
            rho,
            factor,
            acc,
            partials,
            ..
        } = self;
        share_room(near);
        // The same for the neighbour lists, more tightly (they are most of the solver's memory): room for
        // the longest list any chunk has held plus a quarter, plus one particle's candidates (more than
        // what `neighbourhood` reserves beyond the end), once a chunk's falls below the longest plus a sixteenth.
        let peak = lists.iter().map(|l| l.j.len()).max().unwrap_or(0);
        let cands = near.iter().map(|c| c.0.peak()).max().unwrap_or(0);
        for l in lists.iter_mut() {
            if l.j.capacity() < peak + peak / 16 + cands {
                let room = peak + peak / 4 + cands;
                l.j.reserve_exact(room.saturating_sub(l.j.len()));
                if D == 3 {
                    l.gh.reserve_exact(room.saturating_sub(l.gh.len()));
                } else {
                    l.g.reserve_exact(room.saturating_sub(l.g.len()));
                }
            }
        }
        rho.par_chunks_mut(CHUNK)
            .zip(factor.par_chunks_mut(CHUNK))
            .zip(acc.par_chunks_mut(CHUNK))
            .zip(lists.par_iter_mut().zip(near.par_iter_mut()))
            .enumerate()
            .map(|(ci, (((r, f), a), (l, cb)))| build_chunk(p, ci * CHUNK, l, cb, (r, f, a)))
            .collect_into_vec(partials);
        merged(partials)
    }

    /// Pass 2: errors and k; returns the summed error in units of 1 / [`ERR_SCALE`].
    fn errors(&mut self, c: &Coefficients, mode: Mode, dt: f32) -> f64 {
        let wide = wide_lanes();
        let Workspace {
            lists,
            rho,
            factor,
            vel,
            vel4,
            k,
            partials,
            ..
        } = self;
        let (vel, vel4) = (&*vel, &*vel4);
        k.par_chunks_mut(CHUNK)
            .zip(lists.par_iter())
            .enumerate()
            .map(|(ci, (kc, l))| {
                let r = ci * CHUNK..(ci * CHUNK + kc.len());
                let own = (&rho[r.clone()], &factor[r]);
                if D == 3 {
                    error_pass(wide, c, mode, dt, (l, &l.gh), vel4, ci * CHUNK, own, kc)
                } else {
                    error_pass(wide, c, mode, dt, (l, &l.g), vel, ci * CHUNK, own, kc)
                }
            })
            .collect_into_vec(partials);
        merged(partials).error as f64
    }

    /// Pass 3 (velocity update) over all particles; in 3D it also refreshes `vel4` (halo copies' velocities,
    /// which a halo exchange changes afterwards, need [`Self::pad_velocities`]).
    fn update(&mut self, c: &Coefficients, dt: f32) {
        let wide = wide_lanes();
        let Workspace {
            lists,
            vel,
            vel4,
            k,
            ksum,
            ..
        } = self;
        let k = &*k;
        if D == 3 {
            assert_eq!(vel4.len(), vel.len());
            vel.par_chunks_mut(CHUNK)
                .zip(ksum.par_chunks_mut(CHUNK))
                .zip(vel4.par_chunks_mut(CHUNK))
                .zip(lists.par_iter())
                .enumerate()
                .for_each(|(ci, (((v, ks), v4), l))| {
                    update_pass(wide, c, dt, (l, &l.gh), k, ci * CHUNK, (v, ks, v4))
                });
        } else {
            vel.par_chunks_mut(CHUNK)
                .zip(ksum.par_chunks_mut(CHUNK))
                .zip(lists.par_iter())
                .enumerate()
                .for_each(|(ci, ((v, ks), l))| {
                    update_pass(wide, c, dt, (l, &l.g), k, ci * CHUNK, (v, ks, &mut []))
                });
        }
    }

    /// In 3D: `vel4` from `vel`, for the halo copies' velocities a halo exchange has changed since the
    /// update pass wrote it.
    fn pad_velocities(&mut self) {
        if D != 3 {
            return;
        }
        self.vel4.resize(self.vel.len(), [0.0; 4]);
        self.vel4
            .par_chunks_mut(CHUNK)
            .zip(self.vel.par_chunks(CHUNK))
            .for_each(|(w, v)| {
                for (w, v) in w.iter_mut().zip(v) {
                    *w = std::array::from_fn(|d| if d < D { v[d] } else { 0.0 });
                }
            });
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

    /// Starts from `share` × `warm` (p/ρ², applied as a first velocity update), then
    /// iterates passes 2 and 3 until the mean error is below `tol` (at least `min` iterations, at most
    /// `max`). Returns (iterations, final error, wall totals); `ksum` holds the solve's total k. Across
    /// `ranks`, the halo copies take their owners' k and velocities after every pass and the error is the
    /// mean over all ranks.
    #[allow(clippy::too_many_arguments)]
    fn solve<'r>(
        &mut self,
        c: &Coefficients,
        mode: Mode,
        dt: f32,
        tol: f64,
        (min, max): (u32, u32),
        (warm, share): (&[f64], f32),
        mut ranks: Option<&mut (dyn Ranks<D> + 'r)>,
    ) -> (u32, f64, PassTotals) {
        self.ksum.iter_mut().for_each(|k| *k = 0.0);
        for (k, w) in self.k.iter_mut().zip(warm) {
            *k = share * *w as f32;
        }
        if let (Some(r), Mode::Density) = (ranks.as_deref_mut(), mode) {
            // A halo copy's start may depend on particles beyond the halo (the hydrostatic warm start's
            // columns): its owner's.
            r.sync_scalar(&mut self.k);
        }
        self.update(c, dt);
        if let Some(r) = ranks.as_deref_mut() {
            r.sync_vector(&mut self.vel);
            self.pad_velocities();
        }
        let total = ranks.as_ref().map_or(self.rho.len(), |r| r.total());
        let mut it = 0;
        loop {
            let mut sum = [self.errors(c, mode, dt)];
            if let Some(r) = ranks.as_deref_mut() {
                r.sync_scalar(&mut self.k);
                r.reduce(&mut sum, Op::Sum);
            }
            let err = sum[0] / ERR_SCALE / (total.max(1) as f64 * c.rho_rest as f64);
            if (it >= min && err <= tol) || it >= max {
                return (it, err, self.wall_totals(c));
            }
            self.update(c, dt);
            if let Some(r) = ranks.as_deref_mut() {
                r.sync_vector(&mut self.vel);
                self.pad_velocities();
            }
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

/// One DFSPH step of the state's sorted, refreshed liquid (`fluid.x32`, `fluid.v32` current), at most
/// `dt_limit` long: solves, then moves `fluid.pos`/`fluid.vel` (f64) by dt, or, when `prime` is set, only
/// computes the pressures and wall force of the current state and leaves it where it is. Fills `fluid.rho32`
/// (summed density) and `fluid.p32`.
pub fn step<const D: usize, K: Kernel>(
    work: &mut Workspace<D>,
    s: &mut State<D, K>,
    c: &Coefficients,
    frame: &FrameTerms,
    dt_limit: f64,
    prime: bool,
) -> StepReport {
    let spec = &s.params.solver.dfsph;
    let tolerance = s.params.density_tolerance();
    let dp = s.params.particle_spacing;
    let (kernel, grid, bound, fluid) = (&s.kernel, &s.grid, &s.bound, &mut s.fluid);
    let mut ranks = s.processes.ranks::<D>();
    let n = fluid.len();
    work.resize(n);
    let p = Ctx {
        k: kernel,
        c,
        grid,
        frame,
        fluid,
        bound,
        wide: wide_lanes(),
    };
    // Where the constant-density solve starts (the same for every try of the step): the warm start's
    // columns are a serial pass over the liquid, which runs beside the parallel neighbourhood pass (both only
    // read the particles) instead of leaving the other threads idle after it.
    let mut start = std::mem::take(&mut work.start);
    let mut columns = std::mem::take(&mut work.columns);
    let setting = Setting {
        dp,
        rho_rest: c.rho_rest,
        gz: -frame.g[2],
        beta: if !Setting::applies(grid.cell_size(), dp) {
            0.0
        } else {
            spec.hydrostatic_warm_start
        },
    };
    let (built, ()) = rayon::join(
        || work.build(&p),
        || columns.warm_start(grid, p.fluid, setting, &mut start),
    );
    work.columns = columns;
    if work.corrected {
        work.correct(&p, ranks.as_deref_mut());
    }
    let mut report = StepReport {
        totals: built.totals,
        ..Default::default()
    };
    // dt from the flow speed and the accelerations (over all ranks).
    let mut max = [built.max_speed as f64, built.totals.max_acc as f64];
    if let Some(r) = ranks.as_deref_mut() {
        r.reduce(&mut max, Op::Max);
    }
    let [vmax, amax] = max;
    let mut dt = spec.dt_max;
    if vmax > 0.0 {
        dt = dt.min(spec.cfl * dp / vmax);
    }
    if amax > 0.0 {
        dt = dt.min(spec.cfl * (dp / amax).sqrt());
    }
    if work.dt_bound > 0.0 {
        dt = dt.min(work.dt_bound);
    }
    let mut control = spec.target_iterations > 0 && !prime;
    if control && work.dt_cap > 0.0 {
        dt = dt.min(work.dt_cap);
    }
    // Land on an output time or the end of the motion (`dt_limit` ahead) without a sliver of a step: a step
    // much shorter than the flow's corrects the density error it starts with within that sliver, and flings
    // particles. Within two steps of it, the rest is split evenly (each at least half a step).
    let landing = landing_step(dt, dt_limit);
    if landing < dt {
        // Cut short: says nothing about the step the flow allows.
        dt = landing;
        control = false;
    }
    // Shortest step a solve that does not converge is retried at.
    let dt_floor = dt / 16.0;
    loop {
        report.totals = built.totals;
        let dtf = dt as f32;
        for (a, v) in work.vel.iter_mut().enumerate() {
            *v = std::array::from_fn(|d| fluid.v32[d][a]);
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
                (&fluid.kappa_div, WARM),
                ranks.as_deref_mut(),
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
        if let Some(r) = ranks.as_deref_mut() {
            r.sync_vector(&mut work.vel);
        }
        // A retried step's solve may take twice the iterations of the try before: a shorter step lowers
        // the error the flow makes within it, not one the step starts with (the liquid under a body that
        // lands on the floor), which only more iterations remove.
        let most = spec
            .max_iterations
            .saturating_mul(1 << report.retries.min(4));
        let (it, err, t) = work.solve(
            c,
            Mode::Density,
            dtf,
            tolerance,
            (spec.min_iterations, most),
            (&start, 1.0),
            ranks.as_deref_mut(),
        );
        report.density_iterations += it;
        report.density_error = err;
        report.converged = err <= tolerance;
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
            if control {
                work.dt_cap = dt;
            }
            report.retries += 1;
            continue;
        }
        break;
    }
    work.start = start;
    report.dt = dt;
    if work.vel.iter().any(|v| !v.iter().all(|x| x.is_finite())) {
        report.totals.non_finite = true;
    }
    if let Some(r) = ranks {
        report.totals.reduce_with(|v| r.reduce(v, Op::Sum));
    }
    // Pressures of the state (p = ρ² Σk) and its summed densities, for the observables.
    for (a, ((k, kd), r)) in work.ksum.iter().zip(&work.kdiv).zip(&work.rho).enumerate() {
        if !prime {
            fluid.kappa[a] = *k as f64;
            fluid.kappa_div[a] = *kd as f64;
        }
        let p = (k + kd) * r * r;
        fluid.rho32[a] = c.rho_rest;
        fluid.p32[a] = p;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::{CubicSpline, WendlandC2};
    use crate::params::DiffusionKind;

    /// The neighbourhood sums written the plain way: one pair at a time in f64 over every particle, skipping
    /// itself and pairs beyond the support. Returns (density, Σ m∇W liquid, Σ m∇W walls, Σ|m∇W|², viscous
    /// acceleration, liquid neighbours in order, the moving walls' Σ m_b v_b·∇W), and the walls' viscous
    /// acceleration with its moment and the pressure moment per unit k, each pair's taken at the wall
    /// particle (Σ_b x_b × f_b).
    #[allow(clippy::type_complexity)]
    fn naive<const D: usize, K: Kernel>(
        k: &K,
        c: &Coefficients,
        a: usize,
        (x, v): (&[Vec<f32>; D], &[Vec<f32>; D]),
        (xb, vw): (&[Vec<f32>; D], &[Vec<f32>; D]),
    ) -> (
        (f64, [f64; D], [f64; D], f64, [f64; D], Vec<u32>, f64),
        ([f64; D], [f64; 3], [f64; 3]),
    ) {
        let xa: [f64; D] = std::array::from_fn(|d| x[d][a] as f64);
        let va: [f64; D] = std::array::from_fn(|d| v[d][a] as f64);
        let (mf, wall_shape) = (c.pair.m_fluid as f64, c.pair.m_bound as f64);
        let mut density = mf * k.w(0.0) as f64;
        let (mut grad, mut grad_b, mut sq, mut visc) = ([0.0; D], [0.0; D], 0.0, [0.0; D]);
        let mut list = Vec::new();
        let mut wflux = 0.0;
        let (mut wall_visc, mut moment, mut wall_moment) = ([0.0; D], [0.0f64; 3], [0.0f64; 3]);
        for (wall, xs, n) in [(false, x, x[0].len()), (true, xb, xb[0].len())] {
            for j in 0..n {
                if !wall && j == a {
                    continue;
                }
                let dx: [f64; D] = std::array::from_fn(|d| xa[d] - xs[d][j] as f64);
                let r2: f64 = dx.iter().map(|q| q * q).sum();
                if r2 >= c.pair.support2 as f64 {
                    continue;
                }
                let vb: [f64; D] = std::array::from_fn(|d| {
                    if wall {
                        vw[d][j] as f64
                    } else {
                        v[d][j] as f64
                    }
                });
                let vr: f64 = (0..D).map(|d| (va[d] - vb[d]) * dx[d]).sum();
                let r = r2.sqrt();
                let gf = k.grad_factor(r as f32) as f64;
                let (m, alpha) = if wall {
                    (wall_shape, c.pair.alpha_bound as f64)
                } else {
                    (mf, c.pair.alpha as f64)
                };
                density += m * k.w(r as f32) as f64;
                let mu = c.pair.h as f64 * vr.min(0.0) / (r2 + c.pair.eta2 as f64);
                let pi = -alpha * c.pair.c0 as f64 * mu / c.rho_rest as f64;
                for d in 0..D {
                    let g = gf * dx[d];
                    if wall {
                        grad_b[d] += m * g;
                        wflux += m * vb[d] * g;
                    } else {
                        grad[d] += m * g;
                        sq += m * m * g * g;
                    }
                    visc[d] -= m * pi * g;
                }
                if wall {
                    let fd: [f64; D] = std::array::from_fn(|d| -m * pi * gf * dx[d]);
                    let xw = to3(std::array::from_fn::<f64, D, _>(|d| xs[d][j] as f64));
                    let f = to3(fd);
                    let fk = to3(std::array::from_fn::<f64, D, _>(|d| {
                        -MIRROR as f64 * m * gf * dx[d]
                    }));
                    let cross = |p: [f64; 3], q: [f64; 3]| {
                        [
                            p[1] * q[2] - p[2] * q[1],
                            p[2] * q[0] - p[0] * q[2],
                            p[0] * q[1] - p[1] * q[0],
                        ]
                    };
                    for e in 0..3 {
                        moment[e] += cross(xw, f)[e];
                        wall_moment[e] += cross(xw, fk)[e];
                    }
                    for d in 0..D {
                        wall_visc[d] += fd[d];
                    }
                } else {
                    list.push(j as u32);
                }
            }
        }
        (
            (density, grad, grad_b, sq, visc, list, wflux),
            (wall_visc, moment, wall_moment),
        )
    }

    /// [`neighbourhood`] (AVX2 lanes where `wide`) with gradient records R of W lanes: its sums, its neighbour
    /// list, the sum of the listed gradients (whose lanes beyond D must be 0) and of their magnitudes
    /// (unscaled), and the records' bits.
    #[allow(clippy::type_complexity)]
    fn listed<const D: usize, const W: usize, R: Grad<D, W>, K: Kernel>(
        k: &K,
        c: &Coefficients,
        own: ([f32; D], [f32; D]),
        around: Rows<'_, D>,
        wide: bool,
    ) -> (Neighbourhood<D>, Vec<u32>, [(f64, f64); D], Vec<u32>) {
        let (mut j, mut g) = (Vec::new(), Vec::<R>::new());
        let (mut fs, mut bs) = (Near::default(), Near::default());
        let near = (&mut fs, &mut bs);
        let s = if wide {
            #[cfg(target_arch = "x86_64")]
            // SAFETY: only where `wide_lanes()` holds.
            unsafe {
                neighbourhood_avx2(k, c, own, around, near, &mut j, &mut g)
            }
            #[cfg(not(target_arch = "x86_64"))]
            unreachable!()
        } else {
            neighbourhood(k, c, own, around, near, &mut j, &mut g, false)
        };
        assert_eq!(g.len(), j.len());
        let g: Vec<[f32; W]> = g.into_iter().map(R::lanes).collect();
        assert!(g.iter().all(|g| g[D..].iter().all(|x| *x == 0.0)));
        let scale = R::scale(c.pair.h) as f64;
        let sum = std::array::from_fn(|d| {
            let (s, a) = g.iter().fold((0.0, 0.0), |(s, a), g| {
                (s + g[d] as f64, a + (g[d] as f64).abs())
            });
            (s / scale, a / scale)
        });
        let bits = g.iter().flat_map(|g| g.map(f32::to_bits)).collect();
        (s, j, sum, bits)
    }

    fn check<const D: usize, K: Kernel>() {
        let dp = 0.01f32;
        let h = 1.3 * dp;
        let k = K::new(D, h);
        let c = Coefficients {
            pair: crate::scheme::wcsph::Coefficients {
                h,
                support2: 4.0 * h * h,
                m_fluid: 1000.0 * dp.powi(D as i32),
                m_bound: 900.0 * dp.powi(D as i32),
                rho0: 1000.0,
                c0: 20.0,
                alpha: 0.02,
                beta: 0.0,
                alpha_bound: 0.05,
                beta_bound: 0.0,
                eta2: 0.01 * h * h,
                diffusion: DiffusionKind::None,
                delta_h_c0: 0.0,
                nu4: 0.0,
            },
            rho_rest: 1000.0,
            full_neighbourhood: 1,
            relaxation: 1.0,
            corrected: false,
        };
        // A jittered lattice of 7^D liquid particles with made-up velocities, and a row of wall particles
        // through its lower half.
        let mut rnd = crate::fast::candidates::test_noise(777);
        let n1 = 7usize;
        let mut x: [Vec<f32>; D] = std::array::from_fn(|_| Vec::new());
        let mut v: [Vec<f32>; D] = std::array::from_fn(|_| Vec::new());
        let mut xb: [Vec<f32>; D] = std::array::from_fn(|_| Vec::new());
        for i in 0..n1.pow(D as u32) {
            let mut rest = i;
            for d in 0..D {
                x[d].push(((rest % n1) as f32 - 3.0) * dp + 0.3 * dp * rnd());
                v[d].push(0.5 * rnd());
                rest /= n1;
            }
        }
        for i in 0..n1.pow(D as u32 - 1) {
            let mut rest = i;
            for d in 0..D {
                xb[d].push(if d == D - 1 {
                    -1.5 * dp
                } else {
                    let q = ((rest % n1) as f32 - 3.0) * dp;
                    rest /= n1;
                    q
                });
            }
        }
        // The walls move (a floating body's): their velocities enter the viscosity and the wall flux.
        let vb: [Vec<f32>; D] =
            std::array::from_fn(|_| (0..xb[0].len()).map(|_| 0.3 * rnd()).collect());
        // The liquid in three rows, as the grid gives them.
        let n = x[0].len() as u32;
        let liquid = [(0, n / 3), (n / 3, 2 * n / 3), (2 * n / 3, n)];
        let walls = [(0, xb[0].len() as u32)];
        let around = Rows {
            liquid: &liquid,
            walls: &walls,
            fluid: (&x, &v),
            bound: (&xb, &vb),
        };
        // The middle particle and one in the bottom row.
        let n = x[0].len();
        let mut viscous_walls = false;
        for a in [n / 2, n1 / 2] {
            let ((density, grad, grad_b, sq, visc, list, wflux), (wall, moment, wall_moment)) =
                naive(&k, &c, a, (&x, &v), (&xb, &vb));
            let own = (
                std::array::from_fn(|d| x[d][a]),
                std::array::from_fn(|d| v[d][a]),
            );
            // Plain and AVX2 lanes, gradients in f32 (D lanes and 4) and in half precision (4 lanes).
            let mut fast = vec![
                listed::<D, D, [f32; D], K>(&k, &c, own, around, false),
                listed::<D, 4, [f32; 4], K>(&k, &c, own, around, false),
                listed::<D, 4, Half4, K>(&k, &c, own, around, false),
            ];
            if wide_lanes() {
                fast.push(listed::<D, D, [f32; D], K>(&k, &c, own, around, true));
                fast.push(listed::<D, 4, [f32; 4], K>(&k, &c, own, around, true));
                fast.push(listed::<D, 4, Half4, K>(&k, &c, own, around, true));
                // The AVX2 lists (in 3D the half records written by `store_block_avx2`) hold the plain
                // lists' neighbours and gradients to the bit.
                for (plain, wide) in [
                    (&fast[0], &fast[3]),
                    (&fast[1], &fast[4]),
                    (&fast[2], &fast[5]),
                ] {
                    assert_eq!(plain.1, wide.1, "listed neighbours, plain and AVX2");
                    assert_eq!(plain.3, wide.3, "listed gradients, plain and AVX2");
                }
            }
            let gs = grad
                .iter()
                .chain(&grad_b)
                .map(|q| q.abs())
                .fold(1e-9, f64::max);
            let vs = visc.iter().map(|q| q.abs()).fold(1e-9, f64::max);
            for (i, (s, j, gsum, _)) in fast.iter().enumerate() {
                assert!(
                    (s.density as f64 - density).abs() < 1e-5 * density,
                    "density"
                );
                assert!((s.sq as f64 - sq).abs() < 1e-4 * sq, "Σ|m∇W|²");
                for d in 0..D {
                    assert!((s.grad[d] as f64 - grad[d]).abs() < 1e-4 * gs, "grad {d}");
                    assert!(
                        (s.grad_b[d] as f64 - grad_b[d]).abs() < 1e-4 * gs,
                        "grad_b {d}"
                    );
                    assert!((s.visc[d] as f64 - visc[d]).abs() < 1e-3 * vs, "visc {d}");
                }
                let fs = gs * 0.3 * D as f64;
                assert!((s.wflux as f64 - wflux).abs() < 1e-4 * fs, "wall flux");
                // Moments about the lattice's corner, 3 dp away: arms of a few dp.
                let arm = 10.0 * dp as f64;
                for d in 0..D {
                    assert!(
                        (s.wall[d] as f64 - wall[d]).abs() < 1e-3 * vs,
                        "wall viscosity {d}"
                    );
                }
                for e in 0..3 {
                    assert!(
                        (s.moment[e] as f64 - moment[e]).abs() < 1e-3 * vs * arm,
                        "moment {e}"
                    );
                    assert!(
                        (s.wall_moment[e] as f64 - wall_moment[e]).abs() < 1e-4 * gs * arm,
                        "moment per unit k {e}"
                    );
                }
                assert_eq!(j, &list, "liquid neighbours");
                for d in 0..D {
                    let m = c.pair.m_fluid as f64;
                    // Half records: each within 2⁻¹¹ of its f32 value (relatively; at the kernel's edge
                    // 2⁻²⁵ h⁻⁴ absolutely).
                    let half = if i % 3 == 2 {
                        m * (gsum[d].1 / 2048.0
                            + j.len() as f64 / 3.3554432e7 / (c.pair.h as f64).powi(4))
                    } else {
                        0.0
                    };
                    assert!(
                        (m * gsum[d].0 - grad[d]).abs() < 1e-4 * gs + half,
                        "listed ∇W {d}"
                    );
                }
                assert_eq!(s.liquid as usize, list.len());
            }
            assert!(
                density > 500.0 && sq > 0.0 && vs > 0.0,
                "a real neighbourhood"
            );
            assert!(grad_b.iter().any(|q| q.abs() > 0.0), "walls in reach");
            assert!(wflux.abs() > 0.0, "moving walls in reach");
            assert!(
                wall_moment.iter().any(|q| q.abs() > 0.0),
                "wall moments to compare"
            );
            viscous_walls |= wall.iter().any(|q| q.abs() > 1e-3 * vs);
        }
        assert!(viscous_walls, "approaching walls to compare");
    }

    #[test]
    fn lane_loop_matches_naive_neighbourhood_sums() {
        check::<2, WendlandC2>();
        check::<2, CubicSpline>();
        check::<3, WendlandC2>();
        check::<3, CubicSpline>();
    }
}
