//! Weakly-compressible SPH, the seed paper's scheme (Shen & Vassalos): the liquid's density follows the
//! continuity equation and its pressure the Tait equation of state, so a step is bounded by the speed of
//! sound. A step is
//!
//! 1. the time step from the CFL condition on the last rates (sound speed, accelerations, viscosity);
//! 2. the symplectic predictor–corrector (or Verlet): a half step of the liquid (and of the dynamic walls'
//!    density) on the last rates, the rates at the half step ([`rates`]: continuity with δ-SPH, momentum with
//!    artificial viscosity; the walls' density rates; the liquid's force on the bodies), the correction to
//!    the full step;
//! 3. the walls: dynamic walls' densities clamped at rest density, or mirror walls' liquid kept off the
//!    faces.
//!
//! Walls are the dynamic boundary's particle layers (Crespo et al. 2007, [`crate::boundary::dynamic`]) or
//! mirror ghosts rebuilt from the liquid at every evaluation ([`crate::boundary::mirror`]).

pub mod rates;

pub use rates::Coefficients;

use super::{coupling, landing, PressureScheme, State};
use crate::boundary::{dynamic, mdbc, mirror};
use crate::domain::Op;
use crate::error::SimError;
use crate::integrate;
use crate::kernel::Kernel;
use crate::motion::TankMotion;
use crate::observe::wall_pressure::FaceSpot;
use crate::params::{BoundaryMethod, Integrator};
use crate::vector::from3;

/// The weakly-compressible scheme's own storage.
#[derive(Default)]
pub struct Wcsph<const D: usize> {
    work: rates::Workspace<D>,
}

impl<const D: usize, K: Kernel> PressureScheme<D, K> for Wcsph<D> {
    fn step(&mut self, s: &mut State<D, K>, motion: &dyn TankMotion) -> Result<f64, SimError> {
        let t = s.time;
        if !s.rates_current {
            self.evaluate(s, motion, t, true)?;
        }
        s.rates_current = false;
        let mut dt = time_step(s)?;
        let end = s.end_time(motion);
        // Steps land on the end of the motion or the time `step_to` asked for, without a sliver of a step
        // after (a shorter step is always stable).
        if t < end {
            dt = landing::landing_step(dt, end - t);
        }
        if t + dt > end + 1e-12 {
            return Err(SimError::MotionEnded { time: t + dt, end });
        }
        let walls = s.params.solver.boundary.method.has_wall_particles();
        match s.params.solver.integrator {
            Integrator::Symplectic => {
                integrate::symplectic_predict(&mut s.fluid, walls.then_some(&mut s.bound), dt);
                for b in &mut s.bodies.list {
                    b.predict(t, dt);
                }
                if walls {
                    dynamic::clamp(&mut s.bound, s.eos.rho0 as f64);
                }
                self.evaluate(s, motion, t + 0.5 * dt, false)?;
                integrate::symplectic_correct(&mut s.fluid, walls.then_some(&mut s.bound), dt);
                for b in s.bodies.list.iter_mut() {
                    b.correct(t, dt);
                }
                s.contain_bodies();
            }
            Integrator::Verlet => {
                let euler = s
                    .stats
                    .steps
                    .is_multiple_of(s.params.solver.verlet_reset_steps as u64);
                integrate::verlet(&mut s.fluid, walls.then_some(&mut s.bound), dt, euler);
            }
        }
        if walls {
            dynamic::clamp(&mut s.bound, s.eos.rho0 as f64);
        } else {
            mirror::restrain(&mut s.fluid, &s.tank, 0.25 * s.params.particle_spacing);
        }
        s.finish_step(t, dt, end);
        Ok(dt)
    }

    fn prepare_observation(
        &mut self,
        s: &mut State<D, K>,
        motion: &dyn TankMotion,
    ) -> Result<(), SimError> {
        if !s.rates_current {
            self.evaluate(s, motion, s.time, true)?;
            s.rates_current = true;
        }
        Ok(())
    }

    fn wall_wrench(&mut self, s: &State<D, K>) -> ([f64; 3], [f64; 3]) {
        s.tank_wall_totals()
    }

    fn face_pressure(
        &self,
        _: &State<D, K>,
        _: &FaceSpot<D>,
        _: &dyn Fn(f64) -> bool,
    ) -> Option<f64> {
        None
    }

    fn liquid_pressure(&self, s: &State<D, K>, a: usize) -> f32 {
        s.eos.pressure(s.fluid.rho[a] as f32)
    }

    fn wall_reading(&self, s: &State<D, K>, rho: f32) -> (f32, f32) {
        (s.eos.pressure(rho), rho)
    }
}

impl<const D: usize> Wcsph<D> {
    /// Evaluates the rates at time t for the current state. `sort` re-bins the liquid first (once a step).
    fn evaluate<K: Kernel>(
        &mut self,
        s: &mut State<D, K>,
        motion: &dyn TankMotion,
        t: f64,
        sort: bool,
    ) -> Result<(), SimError> {
        let frame = s.frame(motion, t);
        let walls = s.params.solver.boundary.method.has_wall_particles();
        if sort {
            s.rebin(t, walls)?;
        } else if let Some(dom) = s.processes.domain_mut() {
            // Across ranks, in the middle of a step: the halo copies are brought up to date in place.
            dom.refresh(&s.grid, &mut s.fluid, walls.then_some(&mut s.bound));
        }
        let eos = s.eos;
        s.fluid.refresh(|r, _| eos.pressure(r));
        if !s.bodies.is_empty() {
            s.place_bodies(t)?;
        }
        match s.params.solver.boundary.method {
            BoundaryMethod::Dynamic => dynamic::refresh(&mut s.bound, &eos),
            BoundaryMethod::Mdbc => {
                // Bodies' and obstacles' particles from their continuity density, the tank's walls from
                // the liquid.
                dynamic::refresh(&mut s.bound, &eos);
                let m = s.coef.m_fluid;
                mdbc::refresh(&s.kernel, &s.grid, &s.fluid, &s.tank, m, &eos, &mut s.bound);
            }
            BoundaryMethod::Mirror => {
                let g: [f64; D] = from3(frame.g.map(|v| v as f64));
                let support = s.kernel.support() as f64;
                mirror::build_ghosts(&s.fluid, &s.tank, support, g, &eos, &mut s.bound);
                s.bound.sort(&s.grid, &mut s.scratch);
            }
        }
        s.last = rates::fluid_rates(
            &s.kernel,
            &s.coef,
            &s.grid,
            &frame,
            &mut s.fluid,
            &s.bound,
            &mut self.work,
        );
        s.last.reduce_with(|v| s.processes.reduce(v, Op::Sum));
        if walls {
            rates::wall_density_rates(
                &s.kernel,
                &s.coef,
                &s.grid,
                &s.fluid,
                &mut s.bound,
                s.processes.domain().map(|d| d.slabs.columns(d.comm.rank())),
            );
        }
        if !s.bodies.is_empty() {
            coupling::liquid_forces(
                &s.kernel,
                &s.coef,
                &s.grid,
                &s.fluid,
                &s.bound,
                &s.bodies.slots,
                &mut s.bodies.forces,
            );
            s.accelerate_bodies(&frame, false);
        }
        s.stats.force_evaluations += 1;
        if s.last.non_finite {
            return Err(s.non_finite(t));
        }
        Ok(())
    }
}

/// CFL time step from the last evaluation: dt = CFL · min(sqrt(h/|a|max), h/(c_max + max|μ|)).
fn time_step<const D: usize, K: Kernel>(s: &State<D, K>) -> Result<f64, SimError> {
    let spec = &s.params.solver;
    let h = s.coef.h as f64;
    let rmax = s.fluid.rho32.iter().fold(s.coef.rho0, |m, &r| m.max(r));
    let mut max = [rmax as f64, s.last.max_acc as f64, s.last.max_mu as f64];
    // The maxima over all ranks (not the least of each rank's step: c and μ add up).
    s.processes.reduce(&mut max, Op::Max);
    let [rmax, max_acc, max_mu] = max;
    let cmax = s.eos.sound_speed(rmax as f32) as f64;
    let dt_f = if max_acc > 0.0 {
        (h / max_acc).sqrt()
    } else {
        f64::INFINITY
    };
    let dt_cv = h / (cmax + max_mu);
    let mut dt = spec.cfl * dt_f.min(dt_cv);
    if spec.laminar_viscosity {
        dt = dt.min(0.125 * h * h / s.params.fluid.kinematic_viscosity);
    }
    dt = dt.min(spec.dt_max);
    if !(dt >= s.dt_min) {
        return Err(s.step_collapsed(dt));
    }
    Ok(dt)
}
