//! Pressure sensors: Shepard interpolation of the liquid's pressure at a point,
//! p = Σ p_j V_j W / Σ V_j W. A sensor with too little liquid in reach (Σ V_j W < 0.1) reads 0 (dry).

use crate::kernel::Kernel;
use crate::neighbours::Grid;
use crate::particles::Fluid;

pub fn pressure<const D: usize, K: Kernel>(
    k: &K,
    grid: &Grid<D>,
    fluid: &Fluid<D>,
    m_fluid: f32,
    p: [f64; D],
) -> f64 {
    let (mut num, mut den) = (0.0f64, 0.0f64);
    super::for_each_in_reach(k, grid, &fluid.x32, &fluid.starts, p, |j, wk| {
        let w = (m_fluid / fluid.rho32[j] * wk) as f64;
        num += w * fluid.p32[j] as f64;
        den += w;
    });
    if den < 0.1 {
        0.0
    } else {
        num / den
    }
}
