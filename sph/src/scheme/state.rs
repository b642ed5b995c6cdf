//! The state every pressure scheme advances: the liquid, the wall particles, the neighbour grid, the floating
//! bodies and this rank's part of a decomposition, with the time and the statistics; and the stages the
//! schemes share (the frame terms of the motion, sorting, placing and accelerating the bodies).

use super::wcsph::Coefficients;
use super::PassTotals;
use crate::body::{Bodies, RigidBody};
use crate::domain::{Op, Processes};
use crate::eos::Tait;
use crate::error::SimError;
use crate::kernel::Kernel;
use crate::motion::{FrameTerms, TankMotion};
use crate::neighbours::Grid;
use crate::params::SimParams;
use crate::particles::{Boundary, Fluid, SortScratch};
use crate::tank::TankBox;
use crate::vector::to3;

/// Subdomains are rebalanced (if the largest holds more than `1 + REBALANCE_TOLERANCE` times the mean
/// count) at the start of every `REBALANCE_EVERY`th step.
const REBALANCE_EVERY: u64 = 20;
const REBALANCE_TOLERANCE: f64 = 0.1;

/// Statistics of the run so far.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct Stats {
    pub steps: u64,
    pub force_evaluations: u64,
    pub last_dt: f64,
    pub min_dt: f64,
    /// Pressure-solver iterations (incompressible scheme): all steps, and the last step's (density +
    /// divergence solver).
    pub solver_iterations: u64,
    pub last_iterations: u32,
    /// Mean predicted density error after the last step's solve, and the largest over all steps (fraction
    /// of the rest density).
    pub last_density_error: f64,
    pub max_density_error: f64,
    /// Steps whose solve stopped at `max_iterations` above the tolerance.
    pub unconverged_steps: u64,
    /// Steps solved again at half the step because their solve did not converge (`target_iterations`).
    pub retried_steps: u64,
}

/// What a scheme advances (see the module's documentation).
pub struct State<const D: usize, K: Kernel> {
    pub(crate) params: SimParams,
    pub(crate) kernel: K,
    /// The constants of the pair interactions (masses, smoothing length, viscosity, diffusion).
    pub(crate) coef: Coefficients,
    pub(crate) eos: Tait,
    pub(crate) grid: Grid<D>,
    pub(crate) tank: TankBox<D>,
    pub(crate) fluid: Fluid<D>,
    /// Wall layers (dynamic method) or mirror ghosts, and the floating bodies' particles.
    pub(crate) bound: Boundary<D>,
    pub(crate) time: f64,
    pub(crate) stats: Stats,
    /// Liquid particles that left the tank (this rank).
    pub(crate) lost: usize,
    pub(crate) dt_min: f64,
    /// The density a liquid particle inside the initial lattice sums to (the incompressible scheme holds
    /// it).
    pub(crate) rest_density: f32,
    /// Totals of the last force evaluation or solve, and whether the rates belong to the current state.
    pub(crate) last: PassTotals,
    pub(crate) rates_current: bool,
    pub(crate) scratch: SortScratch,
    /// A time the current step must not pass ([`crate::Simulation::step_to`]; ∞ otherwise).
    pub(crate) step_limit: f64,
    /// The processes the simulation spans: one, or this rank's part of a decomposition (MPI).
    pub(crate) processes: Processes,
    /// Floating bodies (their particles are among `bound`).
    pub(crate) bodies: Bodies,
}

impl<const D: usize, K: Kernel> State<D, K> {
    /// The error of a non-finite rate or body state at time t.
    pub(crate) fn non_finite(&self, t: f64) -> SimError {
        SimError::NonFinite {
            time: t,
            step: self.stats.steps,
        }
    }

    /// The error of a step `dt` shorter than the shortest allowed, taken from the current time.
    pub(crate) fn step_collapsed(&self, dt: f64) -> SimError {
        SimError::TimeStepCollapsed {
            time: self.time,
            step: self.stats.steps,
            dt,
            dt_min: self.dt_min,
        }
    }

    /// The frame terms of the motion at t (across ranks: rank 0's motion, broadcast).
    pub(crate) fn frame(&self, motion: &dyn TankMotion, t: f64) -> FrameTerms {
        // As the passes use them, in f32 (exact through the f64 of a broadcast).
        let v: [f64; 9] = self.processes.root_values(|| {
            let s = motion.state(t);
            let g = s.apparent_gravity(self.params.gravity);
            let terms = [g, s.angular_velocity, s.angular_acceleration];
            std::array::from_fn(|k| f64::from(terms[k / 3][k % 3] as f32))
        });
        let f = |k: usize| std::array::from_fn(|d| v[3 * k + d] as f32);
        FrameTerms {
            g: f(0),
            w: f(1),
            dw: f(2),
        }
    }

    /// When the motion ends, or the step must end ([`crate::Simulation::step_to`]) if sooner (across ranks:
    /// rank 0's).
    pub(crate) fn end_time(&self, motion: &dyn TankMotion) -> f64 {
        self.processes
            .root_values(|| [motion.end_time().min(self.step_limit)])[0]
    }

    /// Counts a finished step of `dt` from t: the time lands exactly on `end` when the step was cut to it
    /// (t + (end − t) may round off it).
    pub(crate) fn finish_step(&mut self, t: f64, dt: f64, end: f64) {
        self.time = if dt == end - t { end } else { t + dt };
        let st = &mut self.stats;
        st.steps += 1;
        st.last_dt = dt;
        st.min_dt = st.min_dt.min(dt);
    }

    /// Re-bins the liquid (across ranks: redistributes it) at time t; with `walls`, the halo walls'
    /// densities come along.
    pub(crate) fn rebin(&mut self, t: f64, walls: bool) -> Result<(), SimError> {
        if self.processes.domain().is_some() {
            return self.redistribute(t, walls);
        }
        self.lost += self.fluid.sort(&self.grid, &mut self.scratch);
        if self.fluid.is_empty() {
            return Err(SimError::AllParticlesLost { time: t });
        }
        Ok(())
    }

    /// Across ranks, where one process sorts its cells: particles move to their slab's rank, the halos
    /// (and with `walls`, the halo walls' densities) are rebuilt, the slabs rebalanced now and then.
    fn redistribute(&mut self, t: f64, walls: bool) -> Result<(), SimError> {
        let Some(dom) = self.processes.domain_mut() else {
            return Ok(());
        };
        let rebalance = self
            .stats
            .steps
            .is_multiple_of(REBALANCE_EVERY)
            .then_some(REBALANCE_TOLERANCE);
        let lost = dom.exchange(
            &self.grid,
            &mut self.fluid,
            walls.then_some(&mut self.bound),
            rebalance,
        );
        self.fluid.sort(&self.grid, &mut self.scratch);
        dom.index_halos(&self.grid, &self.fluid);
        self.lost += lost;
        dom.count(&self.fluid, self.lost);
        if dom.fluid_total == 0 {
            return Err(SimError::AllParticlesLost { time: t });
        }
        Ok(())
    }

    /// Bodies rest on the tank's walls: their particles stay a spacing inside the inner faces.
    pub(crate) fn contain_bodies(&mut self) {
        let (lo, hi) = (to3(self.tank.lo).into(), to3(self.tank.hi).into());
        for b in self.bodies.list.iter_mut() {
            b.contain(lo, hi, self.params.particle_spacing);
        }
    }

    /// Sums the per-particle forces of the last evaluation into each body's force and moment (over all
    /// ranks) and sets the bodies' accelerations (`relaxed`: with the artificial added mass of a
    /// partitioned step, [`RigidBody::accelerate_relaxed`]).
    pub(crate) fn accelerate_bodies(&mut self, frame: &FrameTerms, relaxed: bool) {
        let mut wrenches = self.bodies.sum_forces();
        if self.processes.domain().is_some() {
            // Each rank summed its own liquid's part: the totals, the same on every rank, so every rank
            // moves the bodies alike.
            let mut v: Vec<f64> = wrenches
                .iter()
                .flat_map(|(f, m)| f.iter().chain(m.iter()).copied().collect::<Vec<_>>())
                .chain(self.bodies.total_force)
                .chain(self.bodies.total_moment)
                .collect();
            self.processes.reduce(&mut v, Op::Sum);
            for (i, w) in wrenches.iter_mut().enumerate() {
                w.0 = nalgebra::Vector3::from_fn(|k, _| v[6 * i + k]);
                w.1 = nalgebra::Vector3::from_fn(|k, _| v[6 * i + 3 + k]);
            }
            let n = 6 * wrenches.len();
            self.bodies.total_force.copy_from_slice(&v[n..n + 3]);
            self.bodies.total_moment.copy_from_slice(&v[n + 3..n + 6]);
        }
        let rho = self.params.fluid.density;
        for (body, (f, m)) in self.bodies.list.iter_mut().zip(wrenches) {
            if relaxed {
                let (ma, ia) = body.liquid_of_box(rho, D);
                body.accelerate_relaxed(f, m, frame, ma, ia);
            } else {
                body.accelerate(f, m, frame);
            }
        }
    }

    /// Moves the bodies' particles to where the bodies are and sorts the boundary particles again.
    pub(crate) fn place_bodies(&mut self, t: f64) -> Result<(), SimError> {
        let finite = |b: &RigidBody| {
            let p = &b.now;
            p.cog
                .iter()
                .chain(p.vel.iter())
                .chain(p.omega.iter())
                .all(|v| v.is_finite())
        };
        if !self.bodies.list.iter().all(finite) {
            return Err(self.non_finite(t));
        }
        self.bodies.place(&mut self.bound);
        let before = self.bound.len();
        self.bound.sort(&self.grid, &mut self.scratch);
        if self.bound.len() < before {
            let lost = (0..self.bodies.which.len() as u32)
                .find(|g| !self.bound.tag.contains(g))
                .map_or(0, |g| self.bodies.which[g as usize].0 as usize);
            return Err(SimError::BodyLeftTank {
                name: self.bodies.list[lost].name.clone(),
                time: t,
            });
        }
        self.bodies.reindex(&self.bound);
        Ok(())
    }

    /// The walls' force and moment on the liquid in the last evaluation: the tank's walls alone, the force
    /// of all boundary particles on the liquid less the bodies' (the reaction of the liquid's force on them).
    pub(crate) fn tank_wall_totals(&self) -> ([f64; 3], [f64; 3]) {
        let b = &self.bodies;
        (
            std::array::from_fn(|k| self.last.force[k] + b.total_force[k]),
            std::array::from_fn(|k| self.last.moment[k] + b.total_moment[k]),
        )
    }
}
