//! Pressure sensors: Shepard interpolation of the liquid's pressure at a point,
//! p = Σ p_j V_j W / Σ V_j W. A sensor with too little liquid in reach (Σ V_j W < 0.1) reads 0 (dry).

use crate::kernel::Kernel;
use crate::neighbours::{Grid, Ranges, NO_RANGES};
use crate::particles::Fluid;

pub fn pressure<const D: usize, K: Kernel>(
    k: &K,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    m_fluid: f32,
    p: [f64; D],
) -> f64 {
    let mut ranges: Ranges = NO_RANGES;
    let s2 = k.support() * k.support();
    let pf: [f32; D] = std::array::from_fn(|d| p[d] as f32);
    let n = grid.ranges_around(p, &fluid.starts, &mut ranges);
    let (mut num, mut den) = (0.0f64, 0.0f64);
    for &(lo, hi) in &ranges[..n] {
        for j in lo as usize..hi as usize {
            let r2: f32 = (0..D).map(|d| (pf[d] - fluid.x[d][j]).powi(2)).sum();
            if r2 < s2 {
                let w = (m_fluid / fluid.r[j] * k.w(r2.sqrt())) as f64;
                num += w * fluid.p[j] as f64;
                den += w;
            }
        }
    }
    if den < 0.1 {
        0.0
    } else {
        num / den
    }
}
