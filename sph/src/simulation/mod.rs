//! A liquid in a moving tank: one [`State`] and the [`PressureScheme`] that advances it (each scheme's step
//! reads top to bottom in its folder under [`crate::scheme`]), and the observables read from both.
//!
//! The liquid is integrated in the tank frame. The tank's motion enters only as the apparent gravity
//! R^T (g − a) and the rotation terms (Euler, centrifugal, Coriolis), so the result does not depend on where
//! the tank is in the world, and positions keep their precision relative to the tank origin.

mod setup;
mod snapshot;

pub use crate::scheme::Stats;

use crate::body::BodyState;
use crate::domain::{Comm, Op};
use crate::error::SimError;
use crate::kernel::Kernel;
use crate::motion::TankMotion;
use crate::observe::probes::Shell;
use crate::observe::snapshot::Snapshot;
use crate::observe::{pressure, probes, wall_pressure, Observation, Wrench};
use crate::params::SimParams;
use crate::scheme::{PressureScheme, State};
use crate::vector::{from3, to3};
use std::sync::Arc;

/// Particle counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counts {
    pub fluid: usize,
    pub boundary: usize,
    /// Liquid particles that left the tank (removed).
    pub lost: usize,
}

/// A simulation of dimension D with kernel K: the state, the pressure scheme that advances it, and what the
/// observables read besides.
pub struct Simulation<const D: usize, K: Kernel> {
    state: State<D, K>,
    scheme: Box<dyn PressureScheme<D, K>>,
    /// A static lattice of wall points that normalises the liquid fraction near walls (the probes).
    shell: Shell<D>,
    /// Per pressure sensor, the wall face it reads, if it sits on one.
    spots: Vec<Option<wall_pressure::FaceSpot<D>>>,
}

impl<const D: usize, K: Kernel> Simulation<D, K> {
    /// Advances one time step; returns its length.
    pub fn step(&mut self, motion: &dyn TankMotion) -> Result<f64, SimError> {
        // The step runs on a thread of rayon's pool: its parallel passes (some 40 a step for the
        // incompressible scheme) then fork and join among the pool's own threads, instead of each waking the
        // pool from outside and putting the calling thread to sleep until it is done.
        rayon::scope(|_| self.scheme.step(&mut self.state, motion))
    }

    /// Advances one time step, cut short where it would pass `limit`, so that it lands on it (an output
    /// time: outputs then come at exactly their times, whatever the step). A limit closer than twice the
    /// shortest allowed step is not worth a step of its own: the step then runs whole. With several ranks,
    /// rank 0's limit holds.
    pub fn step_to(&mut self, motion: &dyn TankMotion, limit: f64) -> Result<f64, SimError> {
        if limit - self.state.time > 2.0 * self.state.dt_min {
            self.state.step_limit = limit;
        }
        let r = self.step(motion);
        self.state.step_limit = f64::INFINITY;
        r
    }

    /// Steps until the simulation time reaches `t_end`.
    pub fn advance_to(&mut self, motion: &dyn TankMotion, t_end: f64) -> Result<(), SimError> {
        // One entry into rayon's pool for all the steps (see `step`): entering from outside hands a job to a
        // pool thread and wakes it, and rayon's queue allocates a block every 63 such entries.
        rayon::scope(|_| {
            while self.state.time < t_end {
                self.scheme.step(&mut self.state, motion)?;
            }
            Ok(())
        })
    }

    /// Observables of the current state (evaluates the rates of the current state if the last step did not).
    pub fn observe(&mut self, motion: &dyn TankMotion) -> Result<Observation, SimError> {
        self.scheme.prepare_observation(&mut self.state, motion)?;
        let s = &self.state;
        let (k, grid, fluid) = (&s.kernel, &s.grid, &s.fluid);
        let m = s.coef.m_fluid;
        let dp = s.params.particle_spacing;
        let top = s.params.tank.height;
        // Across ranks, each probe and sensor is read by the rank whose slab holds it (its halo holds all
        // the liquid in reach), the others add zero.
        let mine = |x: f64| s.processes.owns(grid, x);
        let mut probes: Vec<f64> = (s.params.probes.iter())
            .map(|p| {
                if !mine(p.x) {
                    return 0.0;
                }
                let at = [p.x, p.y];
                probes::elevation(k, grid, fluid, m, &self.shell, at, top, 0.25 * dp)
            })
            .collect();
        let mut pressures: Vec<f64> = (s.params.pressure_sensors.iter())
            .zip(&self.spots)
            .map(|(sensor, spot)| {
                let own = spot
                    .as_ref()
                    .and_then(|spot| self.scheme.face_pressure(s, spot, &mine));
                match own {
                    Some(p) => p,
                    None if !mine(sensor.x) => 0.0,
                    // On a face: at the face as built.
                    None => {
                        let at = from3([sensor.x, sensor.y, sensor.z]);
                        let at = spot.as_ref().map_or(at, |spot| spot.at);
                        pressure::pressure(k, grid, fluid, m, at)
                    }
                }
            })
            .collect();
        if s.processes.domain().is_some() {
            let np = probes.len();
            let mut v: Vec<f64> = probes.iter().chain(&pressures).copied().collect();
            s.processes.reduce(&mut v, Op::Sum);
            probes.copy_from_slice(&v[..np]);
            pressures.copy_from_slice(&v[np..]);
        }
        // The boundary's force on the liquid, reversed; a 2D result stands for the tank's breadth.
        let scale = if D == 2 { -s.params.tank.breadth } else { -1.0 };
        let (force, moment) = self.scheme.wall_wrench(&self.state);
        let wrench = Wrench {
            force: force.map(|v| v * scale),
            moment: moment.map(|v| v * scale),
        };
        let bodies = self.body_states();
        Ok(Observation {
            time: self.state.time,
            probes,
            pressures,
            wrench,
            bodies,
        })
    }

    /// Each body's motion, the liquid's force on it and the liquid inside it now (2D: per metre of breadth).
    fn body_states(&mut self) -> Vec<BodyState> {
        if self.state.bodies.is_empty() {
            return Vec::new();
        }
        let flooded = flooded_volumes(&self.state);
        let rates: Vec<f64> = match &self.state.bodies.last_flooded {
            Some((t0, v0)) if self.state.time > *t0 => flooded
                .iter()
                .zip(v0)
                .map(|(v, v0)| (v - v0) / (self.state.time - t0))
                .collect(),
            _ => vec![0.0; flooded.len()],
        };
        self.state.bodies.last_flooded = Some((self.state.time, flooded.clone()));
        self.state
            .bodies
            .list
            .iter()
            .zip(flooded.iter().zip(rates))
            .map(|(b, (&flooded_volume, inflow_rate))| {
                let q = nalgebra::UnitQuaternion::from_rotation_matrix(&b.now.rot);
                let (roll, pitch, yaw) = b.now.rot.euler_angles();
                BodyState {
                    name: b.name.clone(),
                    position: b.now.cog.into(),
                    quaternion: [q.i, q.j, q.k, q.w],
                    roll_pitch_yaw: [roll, pitch, yaw],
                    velocity: b.now.vel.into(),
                    angular_velocity: b.now.omega.into(),
                    force: b.liquid_force.into(),
                    moment: b.liquid_moment.into(),
                    flooded_volume,
                    inflow_rate,
                }
            })
            .collect()
    }

    pub fn time(&self) -> f64 {
        self.state.time
    }

    pub fn stats(&self) -> Stats {
        self.state.stats
    }

    pub fn counts(&self) -> Counts {
        match self.state.processes.domain() {
            None => Counts {
                fluid: self.state.fluid.len(),
                boundary: self.state.bound.len(),
                lost: self.state.lost,
            },
            // Totals of the last exchange; wall particles are the same on every rank (mirror ghosts: rank
            // 0's).
            Some(d) => Counts {
                fluid: d.fluid_total,
                boundary: self.state.bound.len(),
                lost: d.lost_total,
            },
        }
    }

    /// Ranks the simulation runs on.
    pub fn ranks(&self) -> usize {
        self.state.processes.size()
    }

    /// Times the subdomains were moved to even out the particle counts.
    pub fn rebalances(&self) -> u64 {
        self.state.processes.domain().map_or(0, |d| d.rebalances)
    }

    pub fn params(&self) -> &SimParams {
        &self.state.params
    }

    /// Mass of the liquid, kg (a 2D run: for the tank's breadth).
    pub fn liquid_mass(&self) -> f64 {
        let m = self.counts().fluid as f64 * self.state.coef.m_fluid as f64;
        if D == 2 {
            m * self.state.params.tank.breadth
        } else {
            m
        }
    }

    /// Sets every liquid particle's velocity from its position (x, y, z in, x, y, z out): initial conditions.
    pub fn set_fluid_velocity(&mut self, f: &dyn Fn([f64; 3]) -> [f64; 3]) {
        for i in 0..self.state.fluid.len() {
            let v: [f64; D] = from3(f(to3(self.state.fluid.position(i))));
            for k in 0..D {
                self.state.fluid.vel[k][i] = v[k];
                self.state.fluid.vel0[k][i] = v[k];
            }
        }
        self.state.rates_current = false;
    }
}

/// The liquid in each body's hollow, m³ (2D: m² = m³ per metre of breadth; across ranks: summed).
pub(super) fn flooded_volumes<const D: usize, K: Kernel>(s: &State<D, K>) -> Vec<f64> {
    let cell = s.coef.m_fluid as f64 / s.coef.rho0 as f64;
    let f = &s.fluid;
    let mut v: Vec<f64> = (s.bodies.list.iter())
        .map(|b| {
            let n = (0..f.len())
                .filter(|&i| {
                    let x = to3(f.position(i));
                    f.owned(i) && b.inside(nalgebra::Vector3::from(x), D)
                })
                .count();
            n as f64
        })
        .collect();
    s.processes.reduce(&mut v, Op::Sum);
    v.iter().map(|n| n * cell).collect()
}

/// A simulation of any dimension and kernel, chosen at run time.
pub trait Solver: Send {
    fn step(&mut self, motion: &dyn TankMotion) -> Result<f64, SimError>;
    /// One step that does not pass `limit` (see [`Simulation::step_to`]).
    fn step_to(&mut self, motion: &dyn TankMotion, limit: f64) -> Result<f64, SimError>;
    fn advance_to(&mut self, motion: &dyn TankMotion, t_end: f64) -> Result<(), SimError>;
    fn observe(&mut self, motion: &dyn TankMotion) -> Result<Observation, SimError>;
    fn time(&self) -> f64;
    fn stats(&self) -> Stats;
    fn counts(&self) -> Counts;
    fn params(&self) -> &SimParams;
    fn liquid_mass(&self) -> f64;
    fn fluid_positions(&self) -> Vec<[f64; 3]>;
    fn fluid_velocities(&self) -> Vec<[f64; 3]>;
    fn set_fluid_velocity(&mut self, f: &dyn Fn([f64; 3]) -> [f64; 3]);
    fn snapshot(&self) -> Snapshot;
    /// Ranks (processes) the simulation is spread over.
    fn ranks(&self) -> usize;
    /// Times the subdomains were moved to even out the particle counts.
    fn rebalances(&self) -> u64;
}

impl<const D: usize, K: Kernel> Solver for Simulation<D, K> {
    fn step(&mut self, motion: &dyn TankMotion) -> Result<f64, SimError> {
        Simulation::step(self, motion)
    }
    fn step_to(&mut self, motion: &dyn TankMotion, limit: f64) -> Result<f64, SimError> {
        Simulation::step_to(self, motion, limit)
    }
    fn advance_to(&mut self, motion: &dyn TankMotion, t_end: f64) -> Result<(), SimError> {
        Simulation::advance_to(self, motion, t_end)
    }
    fn observe(&mut self, motion: &dyn TankMotion) -> Result<Observation, SimError> {
        Simulation::observe(self, motion)
    }
    fn time(&self) -> f64 {
        self.state.time
    }
    fn stats(&self) -> Stats {
        self.state.stats
    }
    fn counts(&self) -> Counts {
        Simulation::counts(self)
    }
    fn params(&self) -> &SimParams {
        &self.state.params
    }
    fn liquid_mass(&self) -> f64 {
        Simulation::liquid_mass(self)
    }
    fn fluid_positions(&self) -> Vec<[f64; 3]> {
        Simulation::fluid_positions(self)
    }
    fn fluid_velocities(&self) -> Vec<[f64; 3]> {
        Simulation::fluid_velocities(self)
    }
    fn set_fluid_velocity(&mut self, f: &dyn Fn([f64; 3]) -> [f64; 3]) {
        Simulation::set_fluid_velocity(self, f)
    }
    fn snapshot(&self) -> Snapshot {
        Simulation::snapshot(self)
    }
    fn ranks(&self) -> usize {
        Simulation::ranks(self)
    }
    fn rebalances(&self) -> u64 {
        Simulation::rebalances(self)
    }
}

/// This process's simulation (its part of one decomposed over `comm`).
pub fn build_local(
    params: SimParams,
    comm: Option<Arc<dyn Comm>>,
) -> Result<Box<dyn Solver>, SimError> {
    use crate::kernel::{CubicSpline, KernelKind, WendlandC2};
    params.validate()?;
    Ok(match (params.dimension, params.solver.kernel) {
        (2, KernelKind::CubicSpline) => {
            Box::new(Simulation::<2, CubicSpline>::new_in(params, comm)?)
        }
        (2, KernelKind::Wendland) => Box::new(Simulation::<2, WendlandC2>::new_in(params, comm)?),
        (3, KernelKind::CubicSpline) => {
            Box::new(Simulation::<3, CubicSpline>::new_in(params, comm)?)
        }
        (_, KernelKind::Wendland) => Box::new(Simulation::<3, WendlandC2>::new_in(params, comm)?),
        (_, KernelKind::CubicSpline) => {
            Box::new(Simulation::<3, CubicSpline>::new_in(params, comm)?)
        }
    })
}
