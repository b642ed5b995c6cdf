//! What the liquid does, in the tank frame: wave probes, pressure sensors, and the force and moment of the
//! liquid on the tank about the tank origin.

pub mod pressure;
pub mod probes;

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
}
