//! Flooding as a damage-stability engineer measures it: water pouring through an opening into a damaged
//! compartment at the orifice law's rate, Q = C_d · b · sqrt(2 g Δh) per metre of breadth, with the discharge
//! coefficient C_d read from the simulated inflow and head (a sharp-edged slot contracts its jet to
//! π / (π + 2) ≈ 0.61 of its width).
//!
//! The experiment: a 2D basin 0.8 m long filled 0.25 m deep holds a fixed closed box 0.2 × 0.2 m (walls
//! 15 mm) floating 0.15 m deep, with a slot of `opening` spacings in its bottom; the basin's level is read by a
//! probe 0.3 m from the box, the level inside from the flooded volume.

use crate::body::BodyState;
use crate::motion::AtRest;
use crate::params::{BodySpec, Dof, ProbeSpec, RegionSpec, Scheme, SimParams, TankSpec};
use crate::SimError;

/// The basin's water depth, the box's outer width and its walls' thickness, its draught, m.
pub const DEPTH: f64 = 0.25;
pub const BOX: f64 = 0.2;
pub const WALL: f64 = 0.015;
pub const DRAUGHT: f64 = 0.15;

/// One observation of the run: time, the basin's level, the box.
#[derive(Clone, Debug)]
pub struct Sample {
    pub time: f64,
    pub level: f64,
    pub body: BodyState,
}

/// The discharge coefficient over one window of the run.
#[derive(Clone, Copy, Debug)]
pub struct Window {
    pub from: f64,
    pub to: f64,
    /// Mean head across the slot (m) and inflow (m²/s per metre of breadth).
    pub head: f64,
    pub inflow: f64,
    pub cd: f64,
}

/// What the run gives.
#[derive(Clone, Debug)]
pub struct Discharge {
    /// The slot's width, m.
    pub width: f64,
    pub samples: Vec<Sample>,
    pub windows: Vec<Window>,
    /// Liquid particles lost from the domain.
    pub lost: u64,
}

/// The basin with the damaged box, the slot `opening` spacings wide, at spacing `dp`, with `scheme`.
pub fn case(scheme: Scheme, opening: f64, dp: f64) -> SimParams {
    let tank = TankSpec {
        length: 0.8,
        breadth: 1.0,
        height: 0.4,
    };
    let mut p = SimParams::filled_tank(2, tank, DEPTH, dp);
    p.solver.scheme = scheme;
    p.probes = vec![ProbeSpec {
        name: "far".into(),
        x: -0.3,
        y: 0.0,
    }];
    p.bodies = vec![BodySpec {
        name: "box".into(),
        size: [BOX, 1.0, BOX],
        wall_thickness: WALL,
        position: [0.0, 0.0, DEPTH - DRAUGHT],
        mass: 1000.0 * BOX * DRAUGHT,
        inertia: [0.147; 3],
        centre_of_gravity: [0.0, 0.0, 0.05],
        velocity: [0.0; 3],
        angular_velocity: [0.0; 3],
        fixed: Dof::ALL.to_vec(),
        openings: vec![RegionSpec {
            name: "bottom".into(),
            centre: [0.0, 0.0, 0.5 * WALL],
            size: [opening * dp, 1.0, 2.0 * WALL],
        }],
        bulkheads: vec![],
        springs: vec![],
    }];
    p
}

/// Runs `params` (a [`case`]) for `duration` seconds, observing every `every` seconds, and reads the
/// discharge coefficient over windows of `window` seconds from `settle` seconds on (the jet established).
pub fn discharge(
    params: SimParams,
    duration: f64,
    every: f64,
    (settle, window): (f64, f64),
) -> Result<Discharge, SimError> {
    let width = params.bodies[0].openings[0].size[0];
    let g = params.gravity;
    let mut sim = crate::build(params)?;
    let mut samples = Vec::new();
    let n = (duration / every).round() as usize;
    for i in 1..=n {
        sim.advance_to(&AtRest, i as f64 * every)?;
        let o = sim.observe(&AtRest)?;
        samples.push(Sample {
            time: o.time,
            level: o.probes[0],
            body: o.bodies[0].clone(),
        });
    }
    let floor = DEPTH - DRAUGHT + WALL;
    let inner = BOX - 2.0 * WALL;
    // Head across the slot: the basin's level over the level inside (its volume over its width).
    let head = |s: &Sample| s.level - (floor + s.body.flooded_volume / inner);
    let w = (window / every).round() as usize;
    let mut i = (settle / every).round() as usize;
    let mut windows = Vec::new();
    while i + w < samples.len() {
        let (a, b) = (&samples[i], &samples[i + w]);
        let inflow = (b.body.flooded_volume - a.body.flooded_volume) / (b.time - a.time);
        let dh = 0.5 * (head(a) + head(b));
        windows.push(Window {
            from: a.time,
            to: b.time,
            head: dh,
            inflow,
            cd: inflow / (width * (2.0 * g * dh.max(0.0)).sqrt()),
        });
        i += w;
    }
    Ok(Discharge {
        width,
        samples,
        windows,
        lost: sim.counts().lost as u64,
    })
}
