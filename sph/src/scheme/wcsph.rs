//! Weakly-compressible SPH rates (the paper's §1.2–1.5): continuity for density, the symmetric pressure
//! gradient with Monaghan's artificial viscosity, eq. (10)–(12), an optional laminar term (Lo & Shao 2002)
//! and δ-SPH density diffusion (Molteni & Colagrossi 2009, or Fourtakas et al. 2019 on the dynamic density).
//!
//! Gather form: every liquid particle loops over its neighbours in cell-sorted order and writes only its own
//! rates, so threads never share a write; chunks of fixed size make the sums independent of the thread count.

use super::{FrameTerms, PassTotals};
use crate::kernel::Kernel;
use crate::neighbours::{Grid, Ranges, NO_RANGES};
use crate::params::DiffusionKind;
use crate::particles::{Boundary, Fluid};
use crate::tank::{from3, to3};
use rayon::prelude::*;

/// Particles per parallel work item (fixed, so reductions do not depend on the number of threads).
pub const CHUNK: usize = 256;

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

struct Acc<const D: usize> {
    acc: [f32; D],
    drho: f32,
    max_mu: f32,
    force: [f32; D],
    moment: [f32; 3],
}

/// Sums the interactions of liquid particle `a` (position xa, velocity va, density ra, pa/ra²) with the
/// particles `lo..hi` of one neighbour set.
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
    x: &[Vec<f32>; D],
    v: &[Vec<f32>; D],
    rho: &[f32],
    pr2: &[f32],
    (lo, hi): (u32, u32),
    out: &mut Acc<D>,
) {
    let (lo, n) = (lo as usize, (hi - lo) as usize);
    let xs: [&[f32]; D] = std::array::from_fn(|d| &x[d][lo..lo + n]);
    let vs: [&[f32]; D] = std::array::from_fn(|d| &v[d][lo..lo + n]);
    let rs = &rho[lo..lo + n];
    let ps = &pr2[lo..lo + n];
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
    for j in 0..n {
        let mut dx = [0.0f32; D];
        let mut r2 = 0.0f32;
        for d in 0..D {
            dx[d] = xa[d] - xs[d][j];
            r2 += dx[d] * dx[d];
        }
        if r2 >= c.support2 {
            continue;
        }
        let mut vd = [0.0f32; D];
        let mut vr = 0.0f32;
        for d in 0..D {
            vd[d] = va[d] - vs[d][j];
            vr += vd[d] * dx[d];
        }
        let f = k.grad_factor(r2.sqrt());
        let (rb, pb_r2) = (rs[j], ps[j]);
        let inv_r2e = 1.0 / (r2 + c.eta2);
        let mut s = pa_r2 + pb_r2;
        if vr < 0.0 {
            let mu = c.h * vr * inv_r2e;
            out.max_mu = out.max_mu.max(-mu);
            s += (-alpha * c.c0 * mu + beta * mu * mu) * 2.0 / (ra + rb);
        }
        let sf = -m * s * f;
        let lam = if c.nu4 > 0.0 {
            m * c.nu4 * f * r2 * inv_r2e / (ra + rb)
        } else {
            0.0
        };
        let mut pair = [0.0f32; D];
        for d in 0..D {
            pair[d] = sf * dx[d] + lam * vd[d];
            out.acc[d] += pair[d];
        }
        out.drho += m * vr * f;
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
            out.drho -= dhc * diff * f * r2 * inv_r2e / rb;
        }
        if !FLUID {
            for d in 0..D {
                out.force[d] += pair[d];
            }
            let xb = to3(std::array::from_fn::<f32, D, _>(|d| xs[d][j]));
            let fp = to3(pair);
            out.moment[0] += xb[1] * fp[2] - xb[2] * fp[1];
            out.moment[1] += xb[2] * fp[0] - xb[0] * fp[2];
            out.moment[2] += xb[0] * fp[1] - xb[1] * fp[0];
        }
    }
}

/// Rates of the liquid: fills `fluid.acc` and `fluid.drho` (including gravity and the frame's inertial terms)
/// and returns the totals. `partials` is reused storage.
pub fn fluid_rates<const D: usize, K: Kernel>(
    k: &K,
    c: &Coefficients,
    grid: &Grid<D>,
    frame: &FrameTerms,
    fluid: &mut Fluid<D>,
    bound: &Boundary<D>,
    partials: &mut Vec<PassTotals>,
) -> PassTotals {
    let Fluid {
        x,
        v,
        r,
        pr2,
        cell,
        starts,
        acc,
        drho,
        ..
    } = fluid;
    let (x, v, r, pr2, cell, starts) = (&*x, &*v, &*r, &*pr2, &*cell, &*starts);
    let g: [f32; D] = from3(frame.g);
    let mass = c.m_fluid as f64;
    acc.par_chunks_mut(CHUNK)
        .zip(drho.par_chunks_mut(CHUNK))
        .enumerate()
        .map(|(ci, (acc_c, drho_c))| {
            let mut tot = PassTotals::default();
            let mut fr: Ranges = NO_RANGES;
            let mut br: Ranges = NO_RANGES;
            for (o, (acc_a, drho_a)) in acc_c.iter_mut().zip(drho_c.iter_mut()).enumerate() {
                let a = ci * CHUNK + o;
                let xa: [f32; D] = std::array::from_fn(|d| x[d][a]);
                let va: [f32; D] = std::array::from_fn(|d| v[d][a]);
                let (ra, pa_r2) = (r[a], pr2[a]);
                let mut out = Acc {
                    acc: [0.0; D],
                    drho: 0.0,
                    max_mu: 0.0,
                    force: [0.0; D],
                    moment: [0.0; 3],
                };
                let nf = grid.ranges(cell[a], starts, &mut fr);
                for &rg in &fr[..nf] {
                    interact::<D, K, true>(k, c, g, xa, va, ra, pa_r2, x, v, r, pr2, rg, &mut out);
                }
                let nb = grid.ranges(cell[a], &bound.starts, &mut br);
                for &rg in &br[..nb] {
                    interact::<D, K, false>(
                        k, c, g, xa, va, ra, pa_r2, &bound.x, &bound.v, &bound.r, &bound.pr2, rg,
                        &mut out,
                    );
                }
                let fa = frame.acceleration(to3(xa), to3(va));
                let fa: [f32; D] = from3(fa);
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
        })
        .collect_into_vec(partials);
    let mut total = PassTotals::default();
    for t in partials.iter() {
        total.merge(t);
    }
    total
}

/// Density rate of dynamic wall particles by continuity with the liquid (walls at rest in the tank frame).
pub fn wall_density_rates<const D: usize, K: Kernel>(
    k: &K,
    c: &Coefficients,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    bound: &mut Boundary<D>,
) {
    let Boundary {
        x: bx,
        cell: bcell,
        drho,
        ..
    } = bound;
    let (bx, bcell) = (&*bx, &*bcell);
    drho.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(ci, chunk)| {
            let mut fr: Ranges = NO_RANGES;
            for (o, out) in chunk.iter_mut().enumerate() {
                let b = ci * CHUNK + o;
                let xb: [f32; D] = std::array::from_fn(|d| bx[d][b]);
                let n = grid.ranges(bcell[b], &fluid.starts, &mut fr);
                let mut s = 0.0f32;
                for &(lo, hi) in &fr[..n] {
                    for j in lo as usize..hi as usize {
                        let mut r2 = 0.0f32;
                        let mut vr = 0.0f32;
                        for d in 0..D {
                            let dx = xb[d] - fluid.x[d][j];
                            r2 += dx * dx;
                            vr -= fluid.v[d][j] * dx;
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
