//! Flooding as a damage-stability engineer measures it: water pouring through an opening at the orifice
//! law's rate, Q = C_d · b · sqrt(2 g Δh) per metre of breadth, with the discharge coefficient C_d read from
//! the simulated flow and head (a sharp-edged slot contracts its jet to π / (π + 2) ≈ 0.61 of its width).
//!
//! Two experiments:
//! - [`slot_case`] / [`slot_discharge`]: the discharge coefficient itself, in a quasi-steady flow. A 2D
//!   reservoir 0.5 m long filled 0.5 m deep empties through a slot in its wall (3 spacings thick) into a dry
//!   compartment 0.685 m long; the slot's centre 0.2 m + half its width above the floor. The head is read by a
//!   probe 0.35 m from the wall, the flow from the volume left behind the wall; the reservoir is large enough
//!   that the head falls by a fifth over the run and the tail water stays below the slot. The wall is made
//!   of fixed obstacles ([`SlotWall::Obstacles`]) or is the side of a fixed hollow body whose inside is the
//!   compartment ([`SlotWall::Body`]: the same slot as a damaged body's opening).
//! - [`case`] / [`discharge`]: a damaged body filling. A 2D basin 0.8 m long filled 0.25 m deep holds a fixed
//!   closed box 0.2 × 0.2 m (walls 15 mm) floating 0.15 m deep, with a slot of `opening` spacings in its
//!   bottom; the basin's level is read by a probe 0.3 m from the box, the level inside from the flooded
//!   volume. The box fills in tenths of a second and the water inside overshoots the basin's level (a U-tube):
//!   a check of the body's flooding (its inflow, Q ∝ √Δh at first), not a measure of C_d.

use crate::body::BodyState;
use crate::motion::AtRest;
use crate::params::{BodySpec, Dof, ProbeSpec, RegionSpec, Scheme, SimParams, TankSpec};
use crate::SimError;
use crate::Solver;

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
    let series: Vec<(f64, f64, f64)> = samples
        .iter()
        .map(|s| {
            let head = s.level - (floor + s.body.flooded_volume / inner);
            (s.time, head, s.body.flooded_volume)
        })
        .collect();
    let windows = windows(
        &series,
        width,
        g,
        (settle / every).round() as usize,
        window / every,
    );
    Ok(Discharge {
        width,
        samples,
        windows,
        lost: sim.counts().lost as u64,
    })
}

/// The slot experiment's reservoir: its length and depth, where its wall begins, the slot's lower edge, m.
pub const RESERVOIR: f64 = 0.5;
pub const FILL: f64 = 0.5;
pub const SLOT_WALL_X: f64 = -0.1;
pub const SLOT_SILL: f64 = 0.2;

/// What the slot experiment's wall is made of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SlotWall {
    /// Two fixed obstacles, below and above the slot (the tank's own kind of wall).
    Obstacles,
    /// The −x side of a fixed hollow body (the compartment is its inside; a floating body's kind of wall,
    /// the slot one of its openings). It stands on an obstacle three spacings high (as thick as the wall, so
    /// no liquid sees through it) that seals the gap under it.
    Body,
}

/// The reservoir and the dry compartment, the slot `opening` spacings wide in a wall 3 spacings thick made
/// of `wall`, at spacing `dp`, with `scheme`.
pub fn slot_case(scheme: Scheme, wall: SlotWall, opening: f64, dp: f64) -> SimParams {
    let tank = TankSpec {
        length: 1.2,
        breadth: 1.0,
        height: 0.7,
    };
    let mut p = SimParams::filled_tank(2, tank, FILL, dp);
    p.fill.length = RESERVOIR;
    p.solver.scheme = scheme;
    let (thick, width) = (3.0 * dp, opening * dp);
    let region = |name: &str, x: [f64; 2], z: [f64; 2]| RegionSpec {
        name: name.into(),
        centre: [0.5 * (x[0] + x[1]), 0.0, 0.5 * (z[0] + z[1])],
        size: [x[1] - x[0], 1.0, z[1] - z[0]],
    };
    let wall_x = [SLOT_WALL_X, SLOT_WALL_X + thick];
    match wall {
        SlotWall::Obstacles => {
            p.obstacles = vec![
                region("sill", wall_x, [0.0, SLOT_SILL]),
                region("lintel", wall_x, [SLOT_SILL + width, 0.65]),
            ];
        }
        SlotWall::Body => {
            // The body from the wall to 3 spacings short of the tank's +x end, 0.65 m high.
            let (x0, x1, z0, z1) = (SLOT_WALL_X, 0.6 - 3.0 * dp, thick, 0.66);
            let length = x1 - x0;
            p.obstacles = vec![region("seal", [x0, x1], [0.0, z0])];
            p.bodies = vec![BodySpec {
                name: "compartment".into(),
                size: [length, 1.0, z1 - z0],
                wall_thickness: thick,
                position: [0.5 * (x0 + x1), 0.0, z0],
                mass: 100.0,
                inertia: [10.0; 3],
                centre_of_gravity: [0.0, 0.0, 0.3],
                velocity: [0.0; 3],
                angular_velocity: [0.0; 3],
                fixed: Dof::ALL.to_vec(),
                openings: vec![RegionSpec {
                    name: "slot".into(),
                    centre: [
                        -0.5 * length + 0.5 * thick,
                        0.0,
                        SLOT_SILL + 0.5 * width - z0,
                    ],
                    size: [2.0 * thick, 1.0, width],
                }],
                bulkheads: vec![],
                springs: vec![],
            }];
        }
    }
    p.probes = vec![ProbeSpec {
        name: "reservoir".into(),
        x: SLOT_WALL_X - 0.35,
        y: 0.0,
    }];
    p
}

/// The slot experiment's record: the slot's width and the discharge coefficient over windows.
#[derive(Clone, Debug)]
pub struct SlotDischarge {
    pub width: f64,
    /// Time, the reservoir's level, the liquid's volume behind the wall (m² per metre of breadth).
    pub samples: Vec<(f64, f64, f64)>,
    pub windows: Vec<Window>,
    pub lost: u64,
}

/// Runs `params` (a [`slot_case`]) for `duration` seconds, observing every `every` seconds, and reads the
/// discharge coefficient over windows of `window` seconds from `settle` seconds on: the outflow over the
/// window against the mean head over the slot's centre.
pub fn slot_discharge(
    params: SimParams,
    duration: f64,
    every: f64,
    (settle, window): (f64, f64),
) -> Result<SlotDischarge, SimError> {
    let sill = SLOT_SILL;
    let width = match params.bodies.first() {
        Some(body) => body.openings[0].size[2],
        None => params.obstacles[1].centre[2] - 0.5 * params.obstacles[1].size[2] - sill,
    };
    let (g, cell) = (params.gravity, params.particle_spacing.powi(2));
    let mut sim = crate::build(params)?;
    let behind = |sim: &dyn Solver| {
        let x = sim.fluid_positions();
        x.iter().filter(|x| x[0] < SLOT_WALL_X).count() as f64 * cell
    };
    let mut samples = Vec::new();
    let n = (duration / every).round() as usize;
    for i in 1..=n {
        sim.advance_to(&AtRest, i as f64 * every)?;
        let o = sim.observe(&AtRest)?;
        samples.push((o.time, o.probes[0], behind(sim.as_ref())));
    }
    // The head over the slot's centre, and the volume that has passed it.
    let centre = sill + 0.5 * width;
    let series: Vec<(f64, f64, f64)> = samples
        .iter()
        .map(|&(t, level, behind)| (t, level - centre, -behind))
        .collect();
    let first = ((settle / every).round() as usize).saturating_sub(1);
    let windows = windows(&series, width, g, first, window / every);
    Ok(SlotDischarge {
        width,
        samples,
        windows,
        lost: sim.counts().lost as u64,
    })
}

/// C_d over windows of `per` samples from sample `first` on, of a series of (time, head across the slot,
/// the volume that has passed it): the flow over each window against its mean head.
fn windows(series: &[(f64, f64, f64)], width: f64, g: f64, first: usize, per: f64) -> Vec<Window> {
    let w = per.round() as usize;
    (first..series.len().saturating_sub(w))
        .step_by(w.max(1))
        .map(|i| {
            let (a, b) = (series[i], series[i + w]);
            let inflow = (b.2 - a.2) / (b.0 - a.0);
            let head = 0.5 * (a.1 + b.1);
            Window {
                from: a.0,
                to: b.0,
                head,
                inflow,
                cd: inflow / (width * (2.0 * g * head.max(0.0)).sqrt()),
            }
        })
        .collect()
}
