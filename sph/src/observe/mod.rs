//! What the liquid does, in the tank frame: wave probes, pressure sensors, and the force and moment of the
//! liquid on the tank about the tank origin.

pub mod pressure;
pub mod probes;
pub mod snapshot;
pub mod wall_pressure;

use crate::kernel::Kernel;
use crate::neighbours::{Grid, NO_RANGES};

/// Calls `f(j, W(|p − x_j|))` for every particle j of a cell-sorted set (positions `x`, cell offsets
/// `starts`) within the kernel's reach of the point `p`.
pub(crate) fn for_each_in_reach<const D: usize, K: Kernel>(
    k: &K,
    grid: &Grid<D>,
    x: &[Vec<f32>; D],
    starts: &[u32],
    p: [f64; D],
    mut f: impl FnMut(usize, f32),
) {
    let mut ranges = NO_RANGES;
    let s2 = k.support() * k.support();
    let pf: [f32; D] = std::array::from_fn(|d| p[d] as f32);
    let n = grid.ranges_around(p, starts, &mut ranges);
    for &(lo, hi) in &ranges[..n] {
        for j in lo as usize..hi as usize {
            let r2: f32 = (0..D).map(|d| (pf[d] - x[d][j]).powi(2)).sum();
            if r2 < s2 {
                f(j, k.w(r2.sqrt()));
            }
        }
    }
}

/// Force (N) and moment (N·m) of the liquid on the tank, tank frame, about the tank origin.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Wrench {
    pub force: [f64; 3],
    pub moment: [f64; 3],
}

/// Observables of one state.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct Observation {
    /// Simulation time of the state, s.
    pub time: f64,
    /// Free-surface elevation above the tank bottom at each probe, m.
    pub probes: Vec<f64>,
    /// Gauge pressure at each sensor, Pa (0 where the sensor is dry).
    pub pressures: Vec<f64>,
    pub wrench: Wrench,
    /// Floating bodies, in the order of the parameters.
    pub bodies: Vec<crate::body::BodyState>,
}
