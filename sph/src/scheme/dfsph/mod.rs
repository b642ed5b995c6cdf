//! Divergence-free SPH (Bender & Koschier 2015, 2017): an incompressible scheme whose time step follows the
//! flow speed, not the speed of sound. Each step
//!
//! 1. builds every liquid particle's list of liquid neighbours with their kernel gradients, sums the density,
//!    the DFSPH factor α = 1 / (|Σ m∇W|² + Σ|m∇W|²), the walls' Σ m_b∇W (walls keep their velocity through
//!    the step, so every wall term of the solver is this sum times the particle's own k or velocity, plus
//!    the moving walls' constant Σ m_b v_b·∇W), and adds
//!    the non-pressure accelerations (the tank frame's apparent gravity and rotation terms, Monaghan's
//!    artificial viscosity as in the weakly-compressible scheme);
//! 2. takes dt = CFL · dp / |v|max (also bounded by the accelerations, `dt_max`, and the iteration control:
//!    0.8× the last step after one that needed more than `target_iterations`, growing back 1.1× a step);
//! 3. makes the velocity field divergence-free (the divergence solver), then predicts v* = v + dt·a and
//!    corrects it until the mean predicted density error is below the tolerance (the constant-density
//!    solver). The divergence solve starts from half its last pressure, the constant-density solve from the
//!    hydrostatic part of its last pressure whole and 0.6 of the rest ([`warm_start`]); both iterate
//!    `k_i = ω · max(error_i, 0) · α_i / dt^n` (ω = `relaxation`, 0.7, or 0.5 with corrected gradients: at 1
//!    the Jacobi iterations amplify the particle-to-particle pressure modes of the 3D kernel's 81 neighbours
//!    and a tank at rest stirs itself),
//!    `Δv_i = −dt Σ_j m_j (k_i + k_j) ∇W_ij − dt Σ_b m_b k_i ∇W_ib` (k plays p/ρ², so p = ρ² Σ k);
//!    A constant-density solve that stops at `max_iterations` above the tolerance is done again, with the
//!    divergence solve, at half the step (nothing has moved yet), allowed twice the iterations of its last
//!    try (an error the step starts with, as under a body landing on the floor, is not lowered by a shorter
//!    step);
//! 4. moves the particles with the corrected velocity.
//!
//! Walls are the dynamic boundary's particle layers (at rest in the tank frame, or moving with a floating
//! body or a wave maker: their velocities enter the density rate and the viscosity), taking part in the
//! density sums with their volume and pushing back with the liquid particle's own k (Akinci et al. 2012, as
//! SPlisHSPlasH's DFSPH). Their reaction, summed once from the final k, gives the wrench; wall pressure
//! sensors read the liquid's force on the wall particles ([`crate::observe::wall_pressure`]). The iterations reuse
//! the neighbour lists; every pass is a gather over fixed chunks that writes only its own particles, so
//! results do not depend on the number of threads.

pub mod gradient_correction;
pub mod solver;
pub mod warm_start;

pub use solver::{Coefficients, StepReport, Workspace, MIRROR};

use super::{coupling, PassTotals, PressureScheme, State};
use crate::error::SimError;
use crate::kernel::Kernel;
use crate::motion::{FrameTerms, TankMotion};
use crate::observe::wall_pressure::{self, FaceSpot};

/// The divergence-free scheme's own state.
pub struct Dfsph<const D: usize> {
    coef: Coefficients,
    work: Workspace<D>,
    /// The walls' force and moment on the liquid integrated over the steps since the last observation, and
    /// their duration (the observed wrench is their mean: the wall force comes in impulses of one step).
    impulse: PassTotals,
    impulse_time: f64,
}

impl<const D: usize> Dfsph<D> {
    /// The scheme for the state as it starts.
    pub fn new<K: Kernel>(s: &State<D, K>) -> Self {
        let p = &s.params;
        let (support, dp) = (s.kernel.support() as f64, p.particle_spacing);
        let coef = Coefficients {
            pair: s.coef,
            rho_rest: s.rest_density,
            full_neighbourhood: {
                let q = support / dp;
                let full = if D == 2 {
                    std::f64::consts::PI * q * q
                } else {
                    4.0 / 3.0 * std::f64::consts::PI * q * q * q
                };
                (0.6 * full) as u32
            },
            relaxation: p.solver.dfsph.relaxation(p.gradients_corrected()) as f32,
            corrected: p.gradients_corrected(),
        };
        let mut work = Workspace::default();
        work.correct_gradients(p.gradients_corrected());
        Self {
            coef,
            work,
            impulse: PassTotals::default(),
            impulse_time: 0.0,
        }
    }

    /// Sorts and refreshes the liquid, then runs the solve of the current state: a step of at most `room`
    /// seconds, or with `prime` only the pressures and wall force of the state (nothing moves).
    fn solve<K: Kernel>(
        &mut self,
        s: &mut State<D, K>,
        motion: &dyn TankMotion,
        room: f64,
        prime: bool,
    ) -> Result<StepReport, SimError> {
        let t = s.time;
        let frame = s.frame(motion, t);
        s.rebin(t, false)?;
        s.fluid.refresh(|_, p| p as f32);
        if !s.bodies.is_empty() {
            s.place_bodies(t)?;
        }
        let r = solver::step(&mut self.work, s, &self.coef, &frame, room, prime);
        if r.totals.non_finite {
            return Err(s.non_finite(t));
        }
        s.last = r.totals;
        s.rates_current = true;
        Ok(r)
    }

    /// The longest step the bodies allow: their fastest particle moves at most `cfl` of a spacing, also
    /// under their accelerations (the liquid's own limit knows nothing of them).
    fn body_step_limit<K: Kernel>(s: &State<D, K>) -> f64 {
        let cfl = s.params.solver.dfsph.cfl;
        let dp = s.params.particle_spacing;
        let mut dt = f64::INFINITY;
        for b in &s.bodies.list {
            let reach = b.local.iter().fold(0.0f64, |m, r| m.max(r.norm()));
            let v = b.now.vel.norm() + b.now.omega.norm() * reach;
            let a = b.acc.norm() + b.alpha.norm() * reach;
            if v > 0.0 {
                dt = dt.min(cfl * dp / v);
            }
            if a > 0.0 {
                dt = dt.min(cfl * (dp / a).sqrt());
            }
        }
        dt
    }

    /// The liquid's force on the bodies from the last solve (each liquid particle's total k, at the
    /// positions it was solved at), and the bodies' accelerations from it.
    fn bodies_feel_the_solve<K: Kernel>(&self, s: &mut State<D, K>, frame: &FrameTerms) {
        let w = &self.work;
        coupling::liquid_forces_dfsph(
            &s.kernel,
            &self.coef,
            &s.grid,
            &s.fluid,
            &s.bound,
            |a| w.total_k(a),
            &s.bodies.slots,
            &mut s.bodies.forces,
        );
        s.accelerate_bodies(frame, true);
    }

    /// Counts a step's solve in the statistics.
    fn count<K: Kernel>(s: &mut State<D, K>, r: &StepReport) {
        let st = &mut s.stats;
        let its = r.density_iterations + r.divergence_iterations;
        st.solver_iterations += its as u64;
        st.last_iterations = its;
        st.last_density_error = r.density_error;
        st.max_density_error = st.max_density_error.max(r.density_error);
        if !r.converged {
            st.unconverged_steps += 1;
        }
        if r.retries > 0 {
            st.retried_steps += 1;
        }
        st.force_evaluations += 1 + its as u64;
    }
}

impl<const D: usize, K: Kernel> PressureScheme<D, K> for Dfsph<D> {
    fn step(&mut self, s: &mut State<D, K>, motion: &dyn TankMotion) -> Result<f64, SimError> {
        let t = s.time;
        let end = s.end_time(motion);
        let room = end - t;
        if room <= 0.0 {
            return Err(SimError::MotionEnded {
                time: t + s.stats.last_dt.max(s.dt_min),
                end,
            });
        }
        let frame_at_start = s.frame(motion, t);
        if !s.bodies.is_empty() {
            self.work.bound(Self::body_step_limit(s));
        }
        let r = self.solve(s, motion, room, false)?;
        Self::count(s, &r);
        debug_assert!(r.dt <= s.params.solver.dfsph.dt_max);
        if !(r.dt >= s.dt_min) {
            return Err(s.step_collapsed(r.dt));
        }
        if !s.bodies.is_empty() {
            // The bodies move with the liquid's force over the step, from the positions it was solved at.
            self.bodies_feel_the_solve(s, &frame_at_start);
            for b in s.bodies.list.iter_mut() {
                b.advance(t, r.dt);
            }
            s.contain_bodies();
        }
        // The tank's walls alone (the solve's totals are the state's last ones).
        let (force, moment) = s.tank_wall_totals();
        for k in 0..3 {
            self.impulse.force[k] += force[k] * r.dt;
            self.impulse.moment[k] += moment[k] * r.dt;
        }
        self.impulse_time += r.dt;
        s.finish_step(t, r.dt, end);
        Ok(r.dt)
    }

    fn prepare_observation(
        &mut self,
        s: &mut State<D, K>,
        motion: &dyn TankMotion,
    ) -> Result<(), SimError> {
        // The last step's pressures and wall force (or a solve of this state if no step made them), with
        // the particles where they are now.
        if !s.rates_current {
            self.solve(s, motion, s.params.solver.dfsph.dt_max, true)?;
            if !s.bodies.is_empty() {
                // The liquid's force on the bodies in this state (no step made it yet).
                let frame = s.frame(motion, s.time);
                self.bodies_feel_the_solve(s, &frame);
            }
        }
        s.rebin(s.time, false)?;
        s.fluid.refresh(|_, p| p as f32);
        Ok(())
    }

    fn wall_wrench(&mut self, s: &State<D, K>) -> ([f64; 3], [f64; 3]) {
        if self.impulse_time == 0.0 {
            return s.tank_wall_totals();
        }
        let t = self.impulse_time;
        let mean = (
            self.impulse.force.map(|v| v / t),
            self.impulse.moment.map(|v| v / t),
        );
        self.impulse = PassTotals::default();
        self.impulse_time = 0.0;
        mean
    }

    fn face_pressure(
        &self,
        s: &State<D, K>,
        spot: &FaceSpot<D>,
        mine: &dyn Fn(f64) -> bool,
    ) -> Option<f64> {
        // A sum over the wall particles behind the sensor, which may reach further than a halo: across
        // ranks, each adds its own walls' part.
        let (f, b) = (&s.fluid, &s.bound);
        Some(wall_pressure::wall_pressure(
            &s.kernel,
            &s.grid,
            f,
            b,
            |i| f.kappa[i] + f.kappa_div[i],
            |j| mine(b.x[0][j] as f64),
            (s.coef.m_fluid as f64, s.coef.m_bound as f64, MIRROR as f64),
            spot,
            0.5 * s.params.particle_spacing,
        ))
    }

    fn liquid_pressure(&self, s: &State<D, K>, a: usize) -> f32 {
        s.fluid.pressure[a] as f32
    }

    fn wall_reading(&self, _: &State<D, K>, _: f32) -> (f32, f32) {
        (0.0, self.coef.rho_rest)
    }
}
