//! Weakly-compressible SPH rates (the paper's §1.2–1.5): continuity for density, the symmetric pressure
//! gradient with Monaghan's artificial viscosity, eq. (10)–(12), an optional laminar term (Lo & Shao 2002)
//! and δ-SPH density diffusion (Molteni & Colagrossi 2009, or Fourtakas et al. 2019 on the dynamic density).
//!
//! Gather form: every liquid particle loops over its neighbours in cell-sorted order and writes only its own
//! rates, so threads never share a write; chunks of fixed size make the sums independent of the thread count.

use crate::fast::candidates::{lane_sum, share_room, wide_lanes, Candidates, LANES};
use crate::kernel::Kernel;
use crate::motion::FrameTerms;
use crate::neighbours::{Grid, Ranges, NO_RANGES};
use crate::params::DiffusionKind;
use crate::particles::{Boundary, Fluid, HALO};
use crate::scheme::{PassTotals, CHUNK};
use crate::vector::{cross, from3, to3};
use rayon::prelude::*;

/// Constants of the scheme in the precision of the loops.
#[derive(Clone, Copy, Debug)]
pub struct Coefficients {
    pub h: f32,
    pub support2: f32,
    /// Mass of a liquid particle, of a boundary particle.
    pub m_fluid: f32,
    pub m_bound: f32,
    pub rho0: f32,
    pub c0: f32,
    pub alpha: f32,
    pub beta: f32,
    /// α and β between liquid and boundary particles.
    pub alpha_bound: f32,
    pub beta_bound: f32,
    pub eta2: f32,
    pub diffusion: DiffusionKind,
    /// δ h c0.
    pub delta_h_c0: f32,
    /// 4ν with the laminar term, else 0.
    pub nu4: f32,
}

/// Per-lane partial sums of one liquid particle's interactions; lanes are summed in a fixed order at the end.
struct Acc<const D: usize> {
    acc: [[f32; LANES]; D],
    drho: [f32; LANES],
    max_mu: [f32; LANES],
    force: [[f32; LANES]; D],
    moment: [[f32; LANES]; 3],
}

impl<const D: usize> Acc<D> {
    fn new() -> Self {
        Self {
            acc: [[0.0; LANES]; D],
            drho: [0.0; LANES],
            max_mu: [0.0; LANES],
            force: [[0.0; LANES]; D],
            moment: [[0.0; LANES]; 3],
        }
    }
}

/// Sums the interactions of liquid particle `a` (position xa, velocity va, density ra, pa/ra²) with the
/// candidates `nb` of its cell. Branch-free over blocks of [`LANES`]: pairs beyond the support get a zero
/// kernel gradient and add nothing.
#[inline(always)]
#[allow(clippy::too_many_arguments)]
fn interact<const D: usize, K: Kernel, const FLUID: bool>(
    k: &K,
    c: &Coefficients,
    g: [f32; D],
    xa: [f32; D],
    va: [f32; D],
    ra: f32,
    pa_r2: f32,
    nb: &Candidates<D>,
    out: &mut Acc<D>,
) {
    let m = if FLUID { c.m_fluid } else { c.m_bound };
    let (alpha, beta) = if FLUID {
        (c.alpha, c.beta)
    } else {
        (c.alpha_bound, c.beta_bound)
    };
    let diffusion = FLUID && c.diffusion != DiffusionKind::None;
    let fourtakas = c.diffusion == DiffusionKind::Fourtakas;
    let inv_c0_sq = 1.0 / (c.c0 * c.c0);
    let dhc = 2.0 * c.delta_h_c0 * m;
    let laminar = c.nu4 > 0.0;
    for b in 0..nb.blocks() {
        let (xs, vs, rs, ps) = nb.block(b);
        for l in 0..LANES {
            let mut dx = [0.0f32; D];
            let mut r2 = 0.0f32;
            let mut vd = [0.0f32; D];
            let mut vr = 0.0f32;
            for d in 0..D {
                dx[d] = xa[d] - xs[d][l];
                r2 += dx[d] * dx[d];
                vd[d] = va[d] - vs[d][l];
                vr += vd[d] * dx[d];
            }
            let inside = if r2 < c.support2 { 1.0f32 } else { 0.0 };
            let f = k.grad_factor(r2.sqrt()) * inside;
            let (rb, pb_r2) = (rs[l], ps[l]);
            let inv_r2e = 1.0 / (r2 + c.eta2);
            // Monaghan's term acts on approaching pairs only (μ ≤ 0).
            let mu = c.h * vr.min(0.0) * inv_r2e * inside;
            out.max_mu[l] = out.max_mu[l].max(-mu);
            let s = pa_r2 + pb_r2 + (-alpha * c.c0 * mu + beta * mu * mu) * 2.0 / (ra + rb);
            let sf = -m * s * f;
            let lam = if laminar {
                m * c.nu4 * f * r2 * inv_r2e / (ra + rb)
            } else {
                0.0
            };
            let mut pair = [0.0f32; D];
            for d in 0..D {
                pair[d] = sf * dx[d] + lam * vd[d];
                out.acc[d][l] += pair[d];
            }
            out.drho[l] += m * vr * f;
            if diffusion {
                let mut diff = rb - ra;
                if fourtakas {
                    // Remove the hydrostatic density difference ρ0 g·(x_b − x_a) / c0².
                    let mut gd = 0.0f32;
                    for d in 0..D {
                        gd -= g[d] * dx[d];
                    }
                    diff -= c.rho0 * gd * inv_c0_sq;
                }
                out.drho[l] -= dhc * diff * f * r2 * inv_r2e / rb;
            }
            if !FLUID {
                for d in 0..D {
                    out.force[d][l] += pair[d];
                }
                let m = cross(
                    to3(std::array::from_fn::<f32, D, _>(|d| xs[d][l])),
                    to3(pair),
                );
                for (acc, m) in out.moment.iter_mut().zip(m) {
                    acc[l] += m;
                }
            }
        }
    }
}

/// The liquid particle whose interactions are summed: position, velocity, density and p/ρ².
struct Own<const D: usize> {
    x: [f32; D],
    v: [f32; D],
    r: f32,
    pr2: f32,
}

/// What one liquid particle's interactions add up to.
struct Sums<const D: usize> {
    acc: [f32; D],
    drho: f32,
    max_mu: f32,
    force: [f32; D],
    moment: [f32; 3],
}

/// All interactions of one liquid particle with the candidates of its cell (liquid `fc`, boundary `bc`).
#[inline(always)]
fn sums<const D: usize, K: Kernel>(
    k: &K,
    c: &Coefficients,
    g: [f32; D],
    a: &Own<D>,
    fc: &Candidates<D>,
    bc: &Candidates<D>,
) -> Sums<D> {
    let mut out = Acc::new();
    interact::<D, K, true>(k, c, g, a.x, a.v, a.r, a.pr2, fc, &mut out);
    interact::<D, K, false>(k, c, g, a.x, a.v, a.r, a.pr2, bc, &mut out);
    Sums {
        acc: std::array::from_fn(|d| lane_sum(&out.acc[d])),
        drho: lane_sum(&out.drho),
        max_mu: out.max_mu.iter().fold(0.0f32, |m, &u| m.max(u)),
        force: std::array::from_fn(|d| lane_sum(&out.force[d])),
        moment: std::array::from_fn(|d| lane_sum(&out.moment[d])),
    }
}

/// [`sums`] compiled for AVX2 + FMA: the same source, its pair loop vectorised 8 wide. Kept to one
/// particle so that the loop stays small enough for the vectoriser.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn sums_avx2<const D: usize, K: Kernel>(
    k: &K,
    c: &Coefficients,
    g: [f32; D],
    a: &Own<D>,
    fc: &Candidates<D>,
    bc: &Candidates<D>,
) -> Sums<D> {
    sums(k, c, g, a, fc, bc)
}

/// Reused storage of [`fluid_rates`]: one pair of candidate buffers and one partial total per chunk.
#[derive(Debug, Default)]
pub struct Workspace<const D: usize> {
    candidates: Vec<(Candidates<D>, Candidates<D>)>,
    partials: Vec<PassTotals>,
}

/// The read-only inputs of one force evaluation.
struct Pass<'a, const D: usize, K> {
    k: &'a K,
    c: &'a Coefficients,
    grid: &'a Grid<D>,
    frame: &'a FrameTerms,
    g: [f32; D],
    x: &'a [Vec<f32>; D],
    v: &'a [Vec<f32>; D],
    r: &'a [f32],
    pr2: &'a [f32],
    cell: &'a [u32],
    starts: &'a [u32],
    /// Ids: halo copies ([`HALO`]) are skipped (zero rates, out of the totals).
    id: &'a [u32],
    bound: &'a Boundary<D>,
    /// Run the pair loop with AVX2 + FMA ([`wide_lanes`]).
    wide: bool,
}

/// Rates of the liquid particles `first..first + acc.len()` and their totals.
#[inline(always)]
fn chunk<const D: usize, K: Kernel>(
    p: &Pass<'_, D, K>,
    first: usize,
    acc: &mut [[f32; D]],
    drho: &mut [f32],
    (fc, bc): &mut (Candidates<D>, Candidates<D>),
) -> PassTotals {
    let (c, bound) = (p.c, p.bound);
    let mass = c.m_fluid as f64;
    let mut tot = PassTotals::default();
    let (mut ranges, mut walls): (Ranges, Ranges) = (NO_RANGES, NO_RANGES);
    let mut filled = u32::MAX;
    for (o, (acc_a, drho_a)) in acc.iter_mut().zip(drho.iter_mut()).enumerate() {
        let a = first + o;
        if p.id[a] & HALO != 0 {
            // A halo copy: its owner computes its rates.
            *acc_a = [0.0; D];
            *drho_a = 0.0;
            continue;
        }
        if p.cell[a] != filled {
            // Particles are sorted by cell: the candidates change only when the cell does.
            filled = p.cell[a];
            let (nf, nb) =
                p.grid
                    .ranges_of_two(filled, (p.starts, &mut ranges), (&bound.starts, &mut walls));
            fc.fill(&ranges, nf, p.x, p.v, p.r, p.pr2, c.rho0);
            bc.fill(&walls, nb, &bound.x, &bound.v, &bound.r, &bound.pr2, c.rho0);
        }
        let own = Own {
            x: std::array::from_fn(|d| p.x[d][a]),
            v: std::array::from_fn(|d| p.v[d][a]),
            r: p.r[a],
            pr2: p.pr2[a],
        };
        let out = if p.wide {
            // SAFETY: `wide` is true only where the CPU reports AVX2 and FMA.
            #[cfg(target_arch = "x86_64")]
            unsafe {
                sums_avx2(p.k, c, p.g, &own, fc, bc)
            }
            #[cfg(not(target_arch = "x86_64"))]
            unreachable!("wide lanes are x86_64 only")
        } else {
            sums(p.k, c, p.g, &own, fc, bc)
        };
        let fa: [f32; D] = from3(p.frame.acceleration(to3(own.x), to3(own.v)));
        let mut a2 = 0.0f32;
        for d in 0..D {
            acc_a[d] = out.acc[d] + fa[d];
            a2 += acc_a[d] * acc_a[d];
        }
        *drho_a = out.drho;
        if !(a2.is_finite() && out.drho.is_finite()) {
            tot.non_finite = true;
        }
        tot.max_acc = tot.max_acc.max(a2.sqrt());
        tot.max_mu = tot.max_mu.max(out.max_mu);
        let f3 = to3(out.force);
        for d in 0..3 {
            tot.force[d] += f3[d] as f64 * mass;
            tot.moment[d] += out.moment[d] as f64 * mass;
        }
    }
    tot
}

/// Rates of the liquid: fills `fluid.acc` and `fluid.drho` (including gravity and the frame's inertial terms)
/// and returns the totals.
pub fn fluid_rates<const D: usize, K: Kernel>(
    k: &K,
    c: &Coefficients,
    grid: &Grid<D>,
    frame: &FrameTerms,
    fluid: &mut Fluid<D>,
    bound: &Boundary<D>,
    work: &mut Workspace<D>,
) -> PassTotals {
    let Fluid {
        x32: x,
        v32: v,
        rho32: r,
        pr2,
        cell,
        starts,
        acc,
        drho,
        id,
        ..
    } = fluid;
    let pass = Pass {
        k,
        c,
        grid,
        frame,
        g: from3(frame.g),
        x,
        v,
        r,
        pr2,
        cell,
        starts,
        id,
        bound,
        wide: wide_lanes(),
    };
    work.candidates
        .resize_with(acc.len().div_ceil(CHUNK), Default::default);
    share_room(&mut work.candidates);
    acc.par_chunks_mut(CHUNK)
        .zip(drho.par_chunks_mut(CHUNK))
        .zip(work.candidates.par_iter_mut())
        .enumerate()
        .map(|(ci, ((acc_c, drho_c), cand))| chunk(&pass, ci * CHUNK, acc_c, drho_c, cand))
        .collect_into_vec(&mut work.partials);
    let mut total = PassTotals::default();
    for t in work.partials.iter() {
        total.merge(t);
    }
    total
}

/// Density rate of dynamic wall particles by continuity with the liquid (walls move with their velocities:
/// at rest in the tank frame, or with a floating body);
/// with `columns`, only of the walls in those grid columns (a subdomain's own), the others get 0.
pub fn wall_density_rates<const D: usize, K: Kernel>(
    k: &K,
    c: &Coefficients,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    bound: &mut Boundary<D>,
    columns: Option<(i64, i64)>,
) {
    let Boundary {
        x: bx,
        v: bv,
        cell: bcell,
        drho,
        ..
    } = bound;
    let (bx, bv, bcell) = (&*bx, &*bv, &*bcell);
    drho.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(ci, chunk)| {
            let mut fr: Ranges = NO_RANGES;
            for (o, out) in chunk.iter_mut().enumerate() {
                let b = ci * CHUNK + o;
                if let Some((lo, hi)) = columns {
                    let col = grid.column(bx[0][b] as f64);
                    if col < lo || col >= hi {
                        *out = 0.0;
                        continue;
                    }
                }
                let xb: [f32; D] = std::array::from_fn(|d| bx[d][b]);
                let vb: [f32; D] = std::array::from_fn(|d| bv[d][b]);
                let n = grid.ranges(bcell[b], &fluid.starts, &mut fr);
                let mut s = 0.0f32;
                for &(lo, hi) in &fr[..n] {
                    for j in lo as usize..hi as usize {
                        let mut r2 = 0.0f32;
                        let mut vr = 0.0f32;
                        for d in 0..D {
                            let dx = xb[d] - fluid.x32[d][j];
                            r2 += dx * dx;
                            vr += (vb[d] - fluid.v32[d][j]) * dx;
                        }
                        if r2 < c.support2 {
                            s += vr * k.grad_factor(r2.sqrt());
                        }
                    }
                }
                *out = c.m_fluid * s;
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kernel::{CubicSpline, WendlandC2};

    /// The pair sums written the plain way: one pair at a time in f64, skipping pairs beyond the support.
    #[allow(clippy::too_many_arguments)]
    fn naive<const D: usize, K: Kernel>(
        k: &K,
        c: &Coefficients,
        g: [f32; D],
        xa: [f32; D],
        va: [f32; D],
        ra: f32,
        pa_r2: f32,
        nb: &Candidates<D>,
        fluid: bool,
    ) -> ([f64; D], f64, [f64; D]) {
        let (m, alpha, beta) = if fluid {
            (c.m_fluid, c.alpha, c.beta)
        } else {
            (c.m_bound, c.alpha_bound, c.beta_bound)
        };
        let (m, c0, h) = (m as f64, c.c0 as f64, c.h as f64);
        let (mut acc, mut drho, mut force) = ([0.0; D], 0.0, [0.0; D]);
        for j in 0..nb.r.len() {
            let dx: [f64; D] = std::array::from_fn(|d| (xa[d] - nb.x[d][j]) as f64);
            let vd: [f64; D] = std::array::from_fn(|d| (va[d] - nb.v[d][j]) as f64);
            let r2: f64 = dx.iter().map(|a| a * a).sum();
            if r2 >= c.support2 as f64 {
                continue;
            }
            let vr: f64 = (0..D).map(|d| vd[d] * dx[d]).sum();
            let f = k.grad_factor(r2.sqrt() as f32) as f64;
            let (ra, rb) = (ra as f64, nb.r[j] as f64);
            let mut s = pa_r2 as f64 + nb.pr2[j] as f64;
            if vr < 0.0 {
                let mu = h * vr / (r2 + c.eta2 as f64);
                s += (-alpha as f64 * c0 * mu + beta as f64 * mu * mu) * 2.0 / (ra + rb);
            }
            for d in 0..D {
                acc[d] -= m * s * f * dx[d];
                if !fluid {
                    force[d] -= m * s * f * dx[d];
                }
            }
            drho += m * vr * f;
            if fluid {
                let gd: f64 = (0..D).map(|d| -(g[d] as f64) * dx[d]).sum();
                let diff = rb - ra - c.rho0 as f64 * gd / (c0 * c0);
                drho -= 2.0 * c.delta_h_c0 as f64 * m * diff * f * r2 / (r2 + c.eta2 as f64) / rb;
            }
        }
        (acc, drho, force)
    }

    fn check<const D: usize, K: Kernel>() {
        let dp = 0.01f32;
        let h = 1.3 * dp;
        let k = K::new(D, h);
        let c = Coefficients {
            h,
            support2: 4.0 * h * h,
            m_fluid: 1000.0 * dp.powi(D as i32),
            m_bound: 1000.0 * dp.powi(D as i32),
            rho0: 1000.0,
            c0: 20.0,
            alpha: 0.02,
            beta: 0.0,
            alpha_bound: 0.01,
            beta_bound: 0.0,
            eta2: 0.01 * h * h,
            diffusion: DiffusionKind::Fourtakas,
            delta_h_c0: 0.1 * h * 20.0,
            nu4: 0.0,
        };
        // A jittered lattice of 7^D particles around the origin, with made-up velocities and densities.
        let mut rnd = crate::fast::candidates::test_noise(12345);
        let n1 = 7usize;
        let n = n1.pow(D as u32);
        let mut x: [Vec<f32>; D] = std::array::from_fn(|_| Vec::new());
        let mut v: [Vec<f32>; D] = std::array::from_fn(|_| Vec::new());
        let (mut r, mut pr2) = (Vec::new(), Vec::new());
        for i in 0..n {
            let mut rest = i;
            for d in 0..D {
                x[d].push(((rest % n1) as f32 - 3.0) * dp + 0.3 * dp * rnd());
                v[d].push(0.5 * rnd());
                rest /= n1;
            }
            let rho = 1000.0 + 20.0 * rnd();
            r.push(rho);
            pr2.push(400.0 * rnd() / (rho * rho));
        }
        let mut ranges = NO_RANGES;
        ranges[0] = (0, n as u32);
        let mut nb = Candidates::<D>::default();
        nb.fill(&ranges, 1, &x, &v, &r, &pr2, 1000.0);
        let g: [f32; D] = std::array::from_fn(|d| if d == D - 1 { -9.81 } else { 0.0 });
        let a = n / 2; // the middle particle
        let xa = std::array::from_fn(|d| x[d][a]);
        let va = std::array::from_fn(|d| v[d][a]);
        let empty = Candidates::<D>::default();
        for fluid in [true, false] {
            let (fc, bc) = if fluid { (&nb, &empty) } else { (&empty, &nb) };
            let (acc, drho, force) = naive(&k, &c, g, xa, va, r[a], pr2[a], &nb, fluid);
            let own = Own {
                x: xa,
                v: va,
                r: r[a],
                pr2: pr2[a],
            };
            let mut fast = vec![sums(&k, &c, g, &own, fc, bc)];
            #[cfg(target_arch = "x86_64")]
            if wide_lanes() {
                // SAFETY: checked just above.
                fast.push(unsafe { sums_avx2(&k, &c, g, &own, fc, bc) });
            }
            let scale = acc.iter().map(|a| a.abs()).fold(1e-3, f64::max);
            for s in &fast {
                for d in 0..D {
                    assert!((s.acc[d] as f64 - acc[d]).abs() < 1e-4 * scale, "acc {d}");
                    assert!(
                        (s.force[d] as f64 - force[d]).abs() < 1e-4 * scale,
                        "force {d}"
                    );
                }
                assert!(
                    (s.drho as f64 - drho).abs() < 1e-4 * drho.abs().max(1.0),
                    "drho"
                );
            }
            assert!(scale > 1.0, "the test set must produce real forces");
        }
    }

    #[test]
    fn lane_loop_matches_naive_pair_sums() {
        check::<2, WendlandC2>();
        check::<2, CubicSpline>();
        check::<3, WendlandC2>();
        check::<3, CubicSpline>();
    }
}
