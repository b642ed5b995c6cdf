//! A liquid in a moving tank: the stage sequence of one step, readable top to bottom.
//!
//! The liquid is integrated in the tank frame. The tank's motion enters only as the apparent gravity
//! R^T (g − a) and the rotation terms (Euler, centrifugal, Coriolis), so the result does not depend on where
//! the tank is in the world, and positions keep their precision relative to the tank origin.

use crate::body::{coupling, piston, shell, BodyState, RigidBody};
use crate::boundary::{dynamic, mirror};
use crate::domain::{Comm, Domain, Op};
use crate::eos::Tait;
use crate::error::SimError;
use crate::integrate;
use crate::kernel::Kernel;
use crate::motion::TankMotion;
use crate::neighbours::Grid;
use crate::observe::probes::Shell;
use crate::observe::snapshot::Snapshot;
use crate::observe::{pressure, probes, wall_pressure, Observation, Wrench};
use crate::params::{BoundaryMethod, Integrator, Scheme, SimParams};
use crate::particles::{Boundary, Fluid, SortScratch};
use crate::scheme::dfsph;
use crate::scheme::wcsph::{self, Coefficients};
use crate::scheme::{FrameTerms, PassTotals};
use crate::tank::{fluid_lattice, from3, to3, wall_lattice, TankBox};
use std::sync::Arc;

/// Subdomains are rebalanced (if the largest holds more than `1 + REBALANCE_TOLERANCE` times the mean
/// count) at the start of every `REBALANCE_EVERY`th step.
const REBALANCE_EVERY: u64 = 20;
const REBALANCE_TOLERANCE: f64 = 0.1;

/// Particle counts.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct Counts {
    pub fluid: usize,
    pub boundary: usize,
    /// Liquid particles that left the tank (removed).
    pub lost: usize,
}

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

pub struct Simulation<const D: usize, K: Kernel> {
    params: SimParams,
    kernel: K,
    coef: Coefficients,
    eos: Tait,
    grid: Grid<D>,
    tank: TankBox<D>,
    fluid: Fluid<D>,
    /// Wall layers (dynamic method) or mirror ghosts.
    bound: Boundary<D>,
    shell: Shell<D>,
    time: f64,
    stats: Stats,
    lost: usize,
    dt_min: f64,
    /// Totals of the last force evaluation, and whether the rates belong to the current state.
    last: PassTotals,
    rates_current: bool,
    scratch: SortScratch,
    work: wcsph::Workspace<D>,
    dcoef: dfsph::Coefficients,
    dwork: dfsph::Workspace<D>,
    /// Incompressible scheme: the walls' force and moment on the liquid integrated over the steps since the
    /// last observation, and their duration (the observed wrench is their mean).
    impulse: PassTotals,
    impulse_time: f64,
    /// A time the current step must not pass ([`Simulation::step_to`]; ∞ otherwise).
    step_limit: f64,
    /// This rank's part of a decomposition over several processes (MPI), if any.
    dom: Option<Domain>,
    /// Floating bodies (their particles are among `bound`).
    bodies: crate::body::Bodies,
    /// Per pressure sensor, the wall face it reads, if it sits on one.
    spots: Vec<Option<wall_pressure::FaceSpot<D>>>,
}

impl<const D: usize, K: Kernel> Simulation<D, K> {
    pub fn new(params: SimParams) -> Result<Self, SimError> {
        Self::new_in(params, None)
    }

    /// This rank's part of the simulation decomposed over `comm`'s ranks (see [`crate::domain`]); serial
    /// without `comm` or with a single rank.
    pub fn new_in(params: SimParams, comm: Option<Arc<dyn Comm>>) -> Result<Self, SimError> {
        params.validate()?;
        assert_eq!(params.dimension, D, "dimension mismatch");
        let dp = params.particle_spacing;
        let h = params.h();
        let c0 = params.sound_speed();
        let rho0 = params.fluid.density;
        let eos = Tait::new(rho0, c0);
        let kernel = K::new(D, h as f32).with_gradient(params.solver.kernel_gradient());
        let tank = TankBox::<D>::new(&params);
        let layers = params.wall_layers();
        let support = kernel.support() as f64;

        // Grid over the tank, its wall layers and one kernel support beyond.
        let shell_layers = layers.max((support / dp).ceil() as u32 + 1);
        let margin = shell_layers as f64 * dp + support;
        let lo: [f64; D] = std::array::from_fn(|k| tank.lo[k] - margin);
        let hi: [f64; D] = std::array::from_fn(|k| tank.hi[k] + margin);
        let grid = Grid::new(lo, hi, 0.5 * support);

        // Liquid at rest with hydrostatic pressure below its own top.
        let (mut points, volume) = fluid_lattice::<D>(&params);
        // Floating bodies start where their box and half a spacing around it hold no liquid (liquid exactly
        // half a spacing off a face stays: one spacing from the body's outer particles, as at a wall).
        let mut bodies = crate::body::Bodies::default();
        let mut body_points: Vec<Vec<[f64; 3]>> = Vec::new();
        for spec in &params.bodies {
            let pts = shell::wall_points(spec, D, dp);
            points.retain(|x| {
                let x = to3(*x);
                let b = std::array::from_fn(|k| x[k] - spec.position[k]);
                !shell::covers(spec, D, b, 0.499 * dp)
            });
            bodies.list.push(RigidBody::new(spec, D, &pts));
            body_points.push(
                pts.iter()
                    .map(|p| std::array::from_fn(|k| p[k] + spec.position[k]))
                    .collect(),
            );
        }
        // A wave maker's plate at the −x end, the liquid in front of it.
        if let (Some(wm), Some((thickness, face))) = (&params.wave_maker, params.wave_maker_plate())
        {
            let n = ((thickness / dp).round() as usize).max(2);
            let pts = piston::plate_points(face, n, params.tank.height, params.tank.breadth, D, dp);
            points.retain(|x| x[0] > face + 0.499 * dp);
            bodies.list.push(RigidBody::driven("wave_maker", wm, &pts));
            body_points.push(pts);
        }
        // Fixed obstacles, as their particles make them: the liquid starts where they and half a spacing
        // around them hold none (one spacing from their outer particles, as at a wall).
        let built: Vec<crate::body::RegionSpec> = params
            .obstacles
            .iter()
            .map(|o| crate::tank::obstacle_as_built::<D>(&params, o))
            .collect();
        points.retain(|x| {
            !built
                .iter()
                .any(|o| crate::tank::in_obstacle(o, *x, 0.499 * dp))
        });
        let (g, top) = (params.gravity, params.fill.height);
        // (A liquid block against the −x wall: walls beyond its end start without pressure. A tank filled
        // end to end: every wall layer, the +x wall's outer ones too, starts hydrostatic; were those beyond
        // its face to start at ρ0, the liquid's first force on the tank would lean 1.3 % of its weight
        // towards −x.)
        let fill_x1 = if params.fill_length() < params.tank.length {
            tank.lo[0] + params.fill_length()
        } else {
            f64::INFINITY
        };
        let hydro = move |x: [f64; D]| -> f64 {
            let z = x[D - 1];
            if x[0] <= fill_x1 + 0.5 * dp {
                eos.density(rho0 * g * (top - z.min(top)))
            } else {
                rho0
            }
        };
        let mut fluid = Fluid::new(&points, hydro);
        let m_fluid = rho0 * volume;

        let (mut wall_pts, wall_volume) = wall_lattice::<D>(&params, layers);
        wall_pts.extend(crate::tank::obstacle_lattice::<D>(&params));
        let mut scratch = SortScratch::default();
        let mut bound = match params.solver.boundary.method {
            BoundaryMethod::Dynamic => dynamic::build(&wall_pts, hydro, &eos),
            BoundaryMethod::Mirror => Boundary::default(),
        };
        for (b, pts) in body_points.iter().enumerate() {
            for (i, p) in pts.iter().enumerate() {
                let x: [f64; D] = from3(*p);
                let rho = hydro(x).max(rho0);
                bound.push(x, [0.0; D], rho, eos.pressure(rho as f32));
                *bound.tag.last_mut().expect("just pushed") = bodies.which.len() as u32;
                bodies.which.push((b as u32, i as u32));
            }
        }
        if bound.sort(&grid, &mut scratch) > 0 && !bodies.is_empty() {
            return Err(SimError::BodyLeftTank {
                name: bodies.list[0].name.clone(),
                time: 0.0,
            });
        }
        bodies.reindex(&bound);
        let (shell_pts, shell_volume) = wall_lattice::<D>(&params, shell_layers);
        let mut shell = Shell {
            points: dynamic::build(&shell_pts, |_| rho0, &eos),
            volume: shell_volume as f32,
        };
        shell.points.sort(&grid, &mut scratch);
        let rho_rest = {
            let m_bound = (rho0 * wall_volume) as f32;
            // Not a particle by a body or the wave maker's plate, whose neighbourhood may be cut short (a
            // hole, a corner) where the middle of the liquid falls.
            let near_body = |x: [f64; D]| {
                let x = to3(x);
                params.bodies.iter().any(|b| {
                    let p = std::array::from_fn(|k| x[k] - b.position[k]);
                    shell::covers(b, D, p, support)
                }) || built
                    .iter()
                    .any(|o| crate::tank::in_obstacle::<3>(o, x, support))
                    || params.wave_maker_plate().is_some_and(|(_, face)| {
                        x[0] < face + support + params.wave_maker.as_ref().map_or(0.0, |w| w.stroke)
                    })
            };
            rest_density(&kernel, &fluid, &bound, m_fluid as f32, m_bound, near_body) as f32
        };
        let dom = match comm.filter(|c| c.size() > 1) {
            None => None,
            Some(c) => {
                // Mirror ghosts are rebuilt from where particles are mid-step, which may be a column
                // beyond where they were sorted: one more halo column brings their sources.
                let halo = match params.solver.boundary.method {
                    BoundaryMethod::Mirror => crate::neighbours::REACH + 1,
                    BoundaryMethod::Dynamic => crate::neighbours::REACH,
                };
                Some(Domain::split(c, &grid, &mut fluid, halo).map_err(SimError::Decomposition)?)
            }
        };
        fluid.sort(&grid, &mut scratch);

        let s = &params.solver;
        let coef = Coefficients {
            h: h as f32,
            support2: (support * support) as f32,
            m_fluid: m_fluid as f32,
            m_bound: (rho0 * wall_volume) as f32,
            rho0: rho0 as f32,
            c0: c0 as f32,
            alpha: s.artificial_viscosity.alpha as f32,
            beta: s.artificial_viscosity.beta as f32,
            alpha_bound: (s.artificial_viscosity.alpha * s.artificial_viscosity.boundary_factor)
                as f32,
            beta_bound: (s.artificial_viscosity.beta * s.artificial_viscosity.boundary_factor)
                as f32,
            eta2: (s.artificial_viscosity.eta_factor * h * h) as f32,
            diffusion: s.density_diffusion.kind,
            delta_h_c0: (s.density_diffusion.delta * h * c0) as f32,
            nu4: if s.laminar_viscosity {
                (4.0 * params.fluid.kinematic_viscosity) as f32
            } else {
                0.0
            },
        };
        let dcoef = dfsph::Coefficients {
            pair: coef,
            rho_rest,
            full_neighbourhood: {
                let q = support / dp;
                let full = if D == 2 {
                    std::f64::consts::PI * q * q
                } else {
                    4.0 / 3.0 * std::f64::consts::PI * q * q * q
                };
                (0.6 * full) as u32
            },
            relaxation: s.dfsph.relaxation(params.gradients_corrected()) as f32,
            corrected: params.gradients_corrected(),
        };
        let dt_min = if s.dt_min > 0.0 {
            s.dt_min
        } else {
            1e-4 * s.cfl * h / c0
        };
        let spacing = crate::tank::wall_spacing::<D>(&params);
        let spots = params
            .pressure_sensors
            .iter()
            .map(|s| {
                let at: [f64; D] = from3([s.x, s.y, s.z]);
                let obstacles = (params.obstacles.as_slice(), built.as_slice());
                wall_pressure::FaceSpot::locate(&tank, obstacles, at, 0.5 * dp, spacing, h)
            })
            .collect();
        let mut sim = Self {
            params,
            kernel,
            coef,
            eos,
            grid,
            tank,
            fluid,
            bound,
            shell,
            time: 0.0,
            stats: Stats {
                min_dt: f64::INFINITY,
                ..Default::default()
            },
            lost: 0,
            dt_min,
            last: PassTotals::default(),
            rates_current: false,
            scratch,
            work: Default::default(),
            dcoef,
            dwork: Default::default(),
            impulse: PassTotals::default(),
            impulse_time: 0.0,
            step_limit: f64::INFINITY,
            dom,
            bodies,
            spots,
        };
        sim.dwork
            .correct_gradients(sim.params.gradients_corrected());
        if !sim.bodies.is_empty() {
            sim.bodies.last_flooded = Some((0.0, sim.flooded_volumes()));
            // Bodies start from rest with forces the liquid has not balanced yet (a hole, a kick): the
            // incompressible scheme's steps start a tenth of their longest and grow as the solves allow.
            sim.dwork.start_at(0.1 * sim.params.solver.dfsph.dt_max);
            sim.dwork.plain_warm_start();
        }
        Ok(sim)
    }

    /// One step of the divergence-free scheme (see [`dfsph`]).
    fn step_dfsph(&mut self, motion: &dyn TankMotion) -> Result<f64, SimError> {
        let t = self.time;
        let end = self.end_time(motion);
        let room = end - t;
        if room <= 0.0 {
            return Err(SimError::MotionEnded {
                time: t + self.stats.last_dt.max(self.dt_min),
                end,
            });
        }
        let frame_at_start = self.frame(motion, t);
        if !self.bodies.is_empty() {
            let limit = self.body_step_limit();
            self.dwork.bound(limit);
        }
        let r = self.solve_dfsph(motion, room, false)?;
        let spec = &self.params.solver.dfsph;
        let st = &mut self.stats;
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
        debug_assert!(r.dt <= spec.dt_max);
        if !(r.dt >= self.dt_min) {
            return Err(SimError::TimeStepCollapsed {
                time: t,
                step: st.steps,
                dt: r.dt,
                dt_min: self.dt_min,
            });
        }
        if !self.bodies.is_empty() {
            self.move_bodies_dfsph(&frame_at_start, t, r.dt);
        }
        // The tank's walls alone: less the bodies' share of the boundary's force.
        let b = &self.bodies;
        for k in 0..3 {
            self.impulse.force[k] += (r.totals.force[k] + b.total_force[k]) * r.dt;
            self.impulse.moment[k] += (r.totals.moment[k] + b.total_moment[k]) * r.dt;
        }
        self.impulse_time += r.dt;
        self.time = if r.dt == room { end } else { t + r.dt };
        let st = &mut self.stats;
        st.steps += 1;
        st.last_dt = r.dt;
        st.min_dt = st.min_dt.min(r.dt);
        Ok(r.dt)
    }

    /// Sorts and refreshes the liquid, then runs the DFSPH solve of the current state: a step of at most
    /// `room` seconds, or with `prime` only the pressures and wall force of the state (nothing moves).
    fn solve_dfsph(
        &mut self,
        motion: &dyn TankMotion,
        room: f64,
        prime: bool,
    ) -> Result<dfsph::StepReport, SimError> {
        let t = self.time;
        let frame = self.frame(motion, t);
        self.rebin(t, false)?;
        self.fluid.refresh(|_, p| p as f32);
        if !self.bodies.is_empty() {
            self.place_bodies(t)?;
        }
        let r = dfsph::step(
            &self.kernel,
            &self.dcoef,
            &self.params.solver.dfsph,
            self.params.particle_spacing,
            &self.grid,
            &frame,
            &mut self.fluid,
            &self.bound,
            &mut self.dwork,
            room,
            prime,
            self.dom
                .as_mut()
                .map(|d| d as &mut dyn crate::scheme::Ranks<D>),
        );
        if r.totals.non_finite {
            return Err(SimError::NonFinite {
                time: t,
                step: self.stats.steps,
            });
        }
        self.last = r.totals;
        self.rates_current = true;
        Ok(r)
    }

    /// The frame terms of the motion at t (across ranks: rank 0's motion, broadcast).
    fn frame(&self, motion: &dyn TankMotion, t: f64) -> FrameTerms {
        let local = || {
            let s = motion.state(t);
            let f = |v: nalgebra::Vector3<f64>| [v.x as f32, v.y as f32, v.z as f32];
            FrameTerms {
                g: f(s.apparent_gravity(self.params.gravity)),
                w: f(s.angular_velocity),
                dw: f(s.angular_acceleration),
            }
        };
        let Some(dom) = &self.dom else {
            return local();
        };
        let mut buf = Vec::new();
        if dom.is_root() {
            let f = local();
            buf.extend(f.g.iter().chain(&f.w).chain(&f.dw).map(|&v| v as f64));
        }
        dom.comm.broadcast(&mut buf);
        let v = |k: usize| std::array::from_fn(|d| buf[3 * k + d] as f32);
        FrameTerms {
            g: v(0),
            w: v(1),
            dw: v(2),
        }
    }

    /// When the motion ends, or the step must end ([`Simulation::step_to`]) if sooner (across ranks: rank
    /// 0's).
    fn end_time(&self, motion: &dyn TankMotion) -> f64 {
        match &self.dom {
            None => motion.end_time().min(self.step_limit),
            Some(dom) => {
                let mut buf = Vec::new();
                if dom.is_root() {
                    buf.push(motion.end_time().min(self.step_limit));
                }
                dom.comm.broadcast(&mut buf);
                buf[0]
            }
        }
    }

    /// Evaluates the rates at time t for the current state. `sort` re-bins the liquid first (once a step).
    fn evaluate(&mut self, motion: &dyn TankMotion, t: f64, sort: bool) -> Result<(), SimError> {
        let frame = self.frame(motion, t);
        let walls = self.params.solver.boundary.method == BoundaryMethod::Dynamic;
        if sort {
            self.rebin(t, walls)?;
        } else if let Some(dom) = &mut self.dom {
            // Across ranks, in the middle of a step: the halo copies are brought up to date in place.
            dom.refresh(
                &self.grid,
                &mut self.fluid,
                walls.then_some(&mut self.bound),
            );
        }
        let eos = self.eos;
        self.fluid.refresh(|r, _| eos.pressure(r));
        if !self.bodies.is_empty() {
            self.place_bodies(t)?;
        }
        match self.params.solver.boundary.method {
            BoundaryMethod::Dynamic => dynamic::refresh(&mut self.bound, &eos),
            BoundaryMethod::Mirror => {
                let g: [f64; D] = from3(frame.g.map(|v| v as f64));
                mirror::build_ghosts(
                    &self.fluid,
                    &self.tank,
                    self.kernel.support() as f64,
                    g,
                    &eos,
                    &mut self.bound,
                );
                self.bound.sort(&self.grid, &mut self.scratch);
            }
        }
        self.last = wcsph::fluid_rates(
            &self.kernel,
            &self.coef,
            &self.grid,
            &frame,
            &mut self.fluid,
            &self.bound,
            &mut self.work,
        );
        if let Some(dom) = &self.dom {
            self.last.reduce_with(|v| dom.comm.reduce(v, Op::Sum));
        }
        if walls {
            wcsph::wall_density_rates(
                &self.kernel,
                &self.coef,
                &self.grid,
                &self.fluid,
                &mut self.bound,
                self.dom.as_ref().map(|d| d.slabs.columns(d.comm.rank())),
            );
        }
        if !self.bodies.is_empty() {
            coupling::liquid_forces(
                &self.kernel,
                &self.coef,
                &self.grid,
                &self.fluid,
                &self.bound,
                &self.bodies.slots,
                &mut self.bodies.forces,
            );
            self.accelerate_bodies(&frame, false);
        }
        self.stats.force_evaluations += 1;
        if self.last.non_finite {
            return Err(SimError::NonFinite {
                time: t,
                step: self.stats.steps,
            });
        }
        Ok(())
    }

    /// The longest divergence-free step the bodies allow: their fastest particle moves at most `cfl` of a
    /// spacing, also under their accelerations (the liquid's own limit knows nothing of them).
    fn body_step_limit(&self) -> f64 {
        let cfl = self.params.solver.dfsph.cfl;
        let dp = self.params.particle_spacing;
        let mut dt = f64::INFINITY;
        for b in &self.bodies.list {
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

    /// After a divergence-free step of `dt` from t: the liquid's force on the bodies over the step (from the
    /// positions it was solved at and each particle's total k), and the bodies moved with it.
    fn move_bodies_dfsph(&mut self, frame: &FrameTerms, t: f64, dt: f64) {
        self.bodies_feel_the_solve(frame);
        for b in self.bodies.list.iter_mut() {
            b.advance(t, dt);
        }
        self.contain_bodies();
    }

    /// The liquid's force on the bodies from the last divergence-free solve (each liquid particle's total k,
    /// at the positions it was solved at), and the bodies' accelerations from it.
    fn bodies_feel_the_solve(&mut self, frame: &FrameTerms) {
        let w = &self.dwork;
        coupling::liquid_forces_dfsph(
            &self.kernel,
            &self.dcoef,
            &self.grid,
            &self.fluid,
            &self.bound,
            |a| w.total_k(a),
            &self.bodies.slots,
            &mut self.bodies.forces,
        );
        self.accelerate_bodies(frame, true);
    }

    /// Bodies rest on the tank's walls: their particles stay a spacing inside the inner faces.
    fn contain_bodies(&mut self) {
        let (lo, hi) = (to3(self.tank.lo).into(), to3(self.tank.hi).into());
        for b in self.bodies.list.iter_mut() {
            b.contain(lo, hi, self.params.particle_spacing);
        }
    }

    /// Sums the per-particle forces of the last evaluation into each body's force and moment (over all
    /// ranks) and sets the bodies' accelerations (`relaxed`: with the artificial added mass of a
    /// partitioned step, [`RigidBody::accelerate_relaxed`]).
    fn accelerate_bodies(&mut self, frame: &FrameTerms, relaxed: bool) {
        let mut wrenches = self.bodies.sum_forces();
        if let Some(dom) = &self.dom {
            // Each rank summed its own liquid's part: the totals, the same on every rank, so every rank
            // moves the bodies alike.
            let mut v: Vec<f64> = wrenches
                .iter()
                .flat_map(|(f, m)| f.iter().chain(m.iter()).copied().collect::<Vec<_>>())
                .chain(self.bodies.total_force)
                .chain(self.bodies.total_moment)
                .collect();
            dom.comm.reduce(&mut v, Op::Sum);
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
    fn place_bodies(&mut self, t: f64) -> Result<(), SimError> {
        let finite = |b: &RigidBody| {
            let p = &b.now;
            p.cog
                .iter()
                .chain(p.vel.iter())
                .chain(p.omega.iter())
                .all(|v| v.is_finite())
        };
        if !self.bodies.list.iter().all(finite) {
            return Err(SimError::NonFinite {
                time: t,
                step: self.stats.steps,
            });
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

    /// Across ranks, where one process sorts its cells: particles move to their slab's rank, the halos
    /// (and with `walls`, the halo walls' densities) are rebuilt, the slabs rebalanced now and then.
    fn redistribute(&mut self, t: f64, walls: bool) -> Result<(), SimError> {
        let Some(dom) = &mut self.dom else {
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

    /// Re-bins the liquid (across ranks: redistributes it) at time t.
    fn rebin(&mut self, t: f64, walls: bool) -> Result<(), SimError> {
        if self.dom.is_some() {
            return self.redistribute(t, walls);
        }
        self.lost += self.fluid.sort(&self.grid, &mut self.scratch);
        if self.fluid.is_empty() {
            return Err(SimError::AllParticlesLost { time: t });
        }
        Ok(())
    }

    /// CFL time step from the last evaluation: dt = CFL · min(sqrt(h/|a|max), h/(c_max + max|μ|)).
    fn time_step(&self) -> Result<f64, SimError> {
        let s = &self.params.solver;
        let h = self.coef.h as f64;
        let rmax = self.fluid.r.iter().fold(self.coef.rho0, |m, &r| m.max(r));
        let mut max = [
            rmax as f64,
            self.last.max_acc as f64,
            self.last.max_mu as f64,
        ];
        if let Some(dom) = &self.dom {
            // The maxima over all ranks (not the least of each rank's step: c and μ add up).
            dom.comm.reduce(&mut max, Op::Max);
        }
        let [rmax, max_acc, max_mu] = max;
        let cmax = self.eos.sound_speed(rmax as f32) as f64;
        let dt_f = if max_acc > 0.0 {
            (h / max_acc).sqrt()
        } else {
            f64::INFINITY
        };
        let dt_cv = h / (cmax + max_mu);
        let mut dt = s.cfl * dt_f.min(dt_cv);
        if s.laminar_viscosity {
            dt = dt.min(0.125 * h * h / self.params.fluid.kinematic_viscosity);
        }
        dt = dt.min(s.dt_max);
        if !(dt >= self.dt_min) {
            return Err(SimError::TimeStepCollapsed {
                time: self.time,
                step: self.stats.steps,
                dt,
                dt_min: self.dt_min,
            });
        }
        Ok(dt)
    }

    /// Advances one time step; returns its length.
    pub fn step(&mut self, motion: &dyn TankMotion) -> Result<f64, SimError> {
        // The step runs on a thread of rayon's pool: its parallel passes (some 40 a step for the
        // incompressible scheme) then fork and join among the pool's own threads, instead of each waking the
        // pool from outside and putting the calling thread to sleep until it is done.
        rayon::scope(|_| self.step_here(motion))
    }

    /// Advances one time step, cut short where it would pass `limit`, so that it lands on it (an output
    /// time: outputs then come at exactly their times, whatever the step). A limit closer than twice the
    /// shortest allowed step is not worth a step of its own: the step then runs whole. With several ranks,
    /// rank 0's limit holds.
    pub fn step_to(&mut self, motion: &dyn TankMotion, limit: f64) -> Result<f64, SimError> {
        if limit - self.time > 2.0 * self.dt_min {
            self.step_limit = limit;
        }
        let r = self.step(motion);
        self.step_limit = f64::INFINITY;
        r
    }

    fn step_here(&mut self, motion: &dyn TankMotion) -> Result<f64, SimError> {
        if self.params.solver.scheme == Scheme::Dfsph {
            return self.step_dfsph(motion);
        }
        let t = self.time;
        if !self.rates_current {
            self.evaluate(motion, t, true)?;
        }
        self.rates_current = false;
        let mut dt = self.time_step()?;
        let end = self.end_time(motion);
        // Steps land on the end of the motion or the time `step_to` asked for, without a sliver of a step
        // after (a shorter step is always stable).
        if t < end {
            dt = crate::scheme::landing::landing_step(dt, end - t);
        }
        if t + dt > end + 1e-12 {
            return Err(SimError::MotionEnded { time: t + dt, end });
        }
        let walls = self.params.solver.boundary.method == BoundaryMethod::Dynamic;
        match self.params.solver.integrator {
            Integrator::Symplectic => {
                integrate::symplectic_predict(
                    &mut self.fluid,
                    walls.then_some(&mut self.bound),
                    dt,
                );
                for b in &mut self.bodies.list {
                    b.predict(t, dt);
                }
                if walls {
                    dynamic::clamp(&mut self.bound, self.eos.rho0 as f64);
                }
                self.evaluate(motion, t + 0.5 * dt, false)?;
                integrate::symplectic_correct(
                    &mut self.fluid,
                    walls.then_some(&mut self.bound),
                    dt,
                );
                for b in self.bodies.list.iter_mut() {
                    b.correct(t, dt);
                }
                self.contain_bodies();
            }
            Integrator::Verlet => {
                let euler = self
                    .stats
                    .steps
                    .is_multiple_of(self.params.solver.verlet_reset_steps as u64);
                integrate::verlet(&mut self.fluid, walls.then_some(&mut self.bound), dt, euler);
            }
        }
        if walls {
            dynamic::clamp(&mut self.bound, self.eos.rho0 as f64);
        } else {
            mirror::restrain(
                &mut self.fluid,
                &self.tank,
                0.25 * self.params.particle_spacing,
            );
        }
        // (Exactly on the landing time: t + (end − t) may round off it.)
        self.time = if dt == end - t { end } else { t + dt };
        self.stats.steps += 1;
        self.stats.last_dt = dt;
        self.stats.min_dt = self.stats.min_dt.min(dt);
        Ok(dt)
    }

    /// Steps until the simulation time reaches `t_end`.
    pub fn advance_to(&mut self, motion: &dyn TankMotion, t_end: f64) -> Result<(), SimError> {
        // One entry into rayon's pool for all the steps (see `step`): entering from outside hands a job to a
        // pool thread and wakes it, and rayon's queue allocates a block every 63 such entries.
        rayon::scope(|_| {
            while self.time < t_end {
                self.step_here(motion)?;
            }
            Ok(())
        })
    }

    /// Observables of the current state (evaluates the rates of the current state if the last step did not).
    pub fn observe(&mut self, motion: &dyn TankMotion) -> Result<Observation, SimError> {
        if self.params.solver.scheme == Scheme::Dfsph {
            // The last step's pressures and wall force (or a solve of this state if no step made them),
            // with the particles where they are now.
            if !self.rates_current {
                self.solve_dfsph(motion, self.params.solver.dfsph.dt_max, true)?;
                if !self.bodies.is_empty() {
                    // The liquid's force on the bodies in this state (no step made it yet).
                    let frame = self.frame(motion, self.time);
                    self.bodies_feel_the_solve(&frame);
                }
            }
            self.rebin(self.time, false)?;
            self.fluid.refresh(|_, p| p as f32);
        } else if !self.rates_current {
            self.evaluate(motion, self.time, true)?;
            self.rates_current = true;
        }
        let k = &self.kernel;
        let m = self.coef.m_fluid;
        let dp = self.params.particle_spacing;
        let top = self.params.tank.height;
        // Across ranks, each probe and sensor is read by the rank whose slab holds it (its halo holds all
        // the liquid in reach), the others add zero.
        let mine = |x: f64| self.dom.as_ref().is_none_or(|d| d.owns(&self.grid, x));
        let mut probes: Vec<f64> = self
            .params
            .probes
            .iter()
            .map(|p| {
                if !mine(p.x) {
                    return 0.0;
                }
                probes::elevation(
                    k,
                    &self.grid,
                    &self.fluid,
                    m,
                    &self.shell,
                    [p.x, p.y],
                    top,
                    0.25 * dp,
                )
            })
            .collect();
        let dfsph = self.params.solver.scheme == Scheme::Dfsph;
        let mut pressures: Vec<f64> = self
            .params
            .pressure_sensors
            .iter()
            .zip(&self.spots)
            .map(|(s, spot)| {
                let at: [f64; D] = from3([s.x, s.y, s.z]);
                match spot {
                    Some(spot) if dfsph => {
                        // A sum over the wall particles behind the sensor, which may reach further than a
                        // halo: across ranks, each adds its own walls' part.
                        let f = &self.fluid;
                        let b = &self.bound;
                        wall_pressure::wall_pressure(
                            k,
                            &self.grid,
                            f,
                            b,
                            |i| f.kappa[i] + f.kappa_div[i],
                            |j| mine(b.x[0][j] as f64),
                            (
                                self.coef.m_fluid as f64,
                                self.coef.m_bound as f64,
                                dfsph::MIRROR as f64,
                            ),
                            spot,
                            0.5 * dp,
                        )
                    }
                    _ if !mine(s.x) => 0.0,
                    // On a face: at the face as built.
                    _ => {
                        let at = spot.as_ref().map_or(at, |s| s.at);
                        pressure::pressure(k, &self.grid, &self.fluid, m, at)
                    }
                }
            })
            .collect();
        if let Some(dom) = &self.dom {
            let np = probes.len();
            let mut v: Vec<f64> = probes.iter().chain(&pressures).copied().collect();
            dom.comm.reduce(&mut v, Op::Sum);
            probes.copy_from_slice(&v[..np]);
            pressures.copy_from_slice(&v[np..]);
        }
        // The boundary's force on the liquid, reversed; a 2D result stands for the tank's breadth.
        let scale = if D == 2 {
            -self.params.tank.breadth
        } else {
            -1.0
        };
        // The incompressible scheme's wall force comes in impulses of one step: its wrench is the mean over
        // the steps since the last observation.
        let (force, moment) = if dfsph && self.impulse_time > 0.0 {
            let t = self.impulse_time;
            let f = (
                self.impulse.force.map(|v| v / t),
                self.impulse.moment.map(|v| v / t),
            );
            self.impulse = PassTotals::default();
            self.impulse_time = 0.0;
            f
        } else {
            // The tank's walls alone: the force of all boundary particles on the liquid, less the bodies'
            // (the reaction of the liquid's force on them).
            let b = &self.bodies;
            (
                std::array::from_fn(|k| self.last.force[k] + b.total_force[k]),
                std::array::from_fn(|k| self.last.moment[k] + b.total_moment[k]),
            )
        };
        let wrench = Wrench {
            force: force.map(|v| v * scale),
            moment: moment.map(|v| v * scale),
        };
        let bodies = self.body_states();
        Ok(Observation {
            time: self.time,
            probes,
            pressures,
            wrench,
            bodies,
        })
    }

    /// The liquid in each body's hollow, m³ (2D: m² = m³ per metre of breadth; across ranks: summed).
    fn flooded_volumes(&self) -> Vec<f64> {
        let cell = self.coef.m_fluid as f64 / self.coef.rho0 as f64;
        let mut v: Vec<f64> = self
            .bodies
            .list
            .iter()
            .map(|b| {
                let n = (0..self.fluid.len())
                    .filter(|&i| {
                        let x = to3(self.fluid.position(i));
                        self.fluid.owned(i) && b.inside(nalgebra::Vector3::from(x), D)
                    })
                    .count();
                n as f64
            })
            .collect();
        if let Some(dom) = &self.dom {
            dom.comm.reduce(&mut v, Op::Sum);
        }
        v.iter().map(|n| n * cell).collect()
    }

    /// Each body's motion, the liquid's force on it and the liquid inside it now (2D: per metre of breadth).
    fn body_states(&mut self) -> Vec<BodyState> {
        if self.bodies.is_empty() {
            return Vec::new();
        }
        let flooded = self.flooded_volumes();
        let rates: Vec<f64> = match &self.bodies.last_flooded {
            Some((t0, v0)) if self.time > *t0 => flooded
                .iter()
                .zip(v0)
                .map(|(v, v0)| (v - v0) / (self.time - t0))
                .collect(),
            _ => vec![0.0; flooded.len()],
        };
        self.bodies.last_flooded = Some((self.time, flooded.clone()));
        self.bodies
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
        self.time
    }

    pub fn stats(&self) -> Stats {
        self.stats
    }

    pub fn counts(&self) -> Counts {
        match &self.dom {
            None => Counts {
                fluid: self.fluid.len(),
                boundary: self.bound.len(),
                lost: self.lost,
            },
            // Totals of the last exchange; wall particles are the same on every rank (mirror ghosts: rank
            // 0's).
            Some(d) => Counts {
                fluid: d.fluid_total,
                boundary: self.bound.len(),
                lost: d.lost_total,
            },
        }
    }

    /// Ranks the simulation runs on.
    pub fn ranks(&self) -> usize {
        self.dom.as_ref().map_or(1, |d| d.comm.size())
    }

    /// Times the subdomains were moved to even out the particle counts.
    pub fn rebalances(&self) -> u64 {
        self.dom.as_ref().map_or(0, |d| d.rebalances)
    }

    pub fn params(&self) -> &SimParams {
        &self.params
    }

    /// Mass of the liquid, kg (a 2D run: for the tank's breadth).
    pub fn liquid_mass(&self) -> f64 {
        let m = self.counts().fluid as f64 * self.coef.m_fluid as f64;
        if D == 2 {
            m * self.params.tank.breadth
        } else {
            m
        }
    }

    /// Liquid particle positions in the tank frame as x, y, z (across ranks: all of them on rank 0, in the
    /// order of their ids, none elsewhere).
    pub fn fluid_positions(&self) -> Vec<[f64; 3]> {
        self.fluid_field(|f, i| to3(f.position(i)))
    }

    /// Liquid particle velocities relative to the tank as x, y, z (across ranks as [`Self::fluid_positions`]).
    pub fn fluid_velocities(&self) -> Vec<[f64; 3]> {
        self.fluid_field(|f, i| to3(std::array::from_fn::<f64, D, _>(|k| f.vel[k][i])))
    }

    fn fluid_field(&self, at: impl Fn(&Fluid<D>, usize) -> [f64; 3]) -> Vec<[f64; 3]> {
        let f = &self.fluid;
        let Some(dom) = &self.dom else {
            return (0..f.len()).map(|i| at(f, i)).collect();
        };
        let mut local = Vec::new();
        for i in (0..f.len()).filter(|&i| f.owned(i)) {
            local.push(f.id[i] as f64);
            local.extend(at(f, i));
        }
        let mut all: Vec<(u32, [f64; 3])> = dom
            .gather(local)
            .iter()
            .flat_map(|v| v.chunks_exact(4))
            .map(|r| (r[0] as u32, [r[1], r[2], r[3]]))
            .collect();
        all.sort_unstable_by_key(|r| r.0);
        all.into_iter().map(|r| r.1).collect()
    }

    /// Every particle's position, velocity, pressure and density now, in the tank frame (changes nothing).
    /// Across ranks: on rank 0, the liquid of all ranks in the order of the ids (one process: in cell order)
    /// and the wall layers with their owners' densities (mirror ghosts: rank 0's own); empty elsewhere.
    pub fn snapshot(&self) -> Snapshot {
        let (f, b) = (&self.fluid, &self.bound);
        let (nf, nb) = (f.len(), b.len());
        let dfsph = self.params.solver.scheme == Scheme::Dfsph;
        let mut s = Snapshot {
            time: self.time,
            dimension: D,
            fluid: nf,
            position: Vec::with_capacity(nf + nb),
            velocity: Vec::with_capacity(nf + nb),
            pressure: Vec::with_capacity(nf + nb),
            density: Vec::with_capacity(nf + nb),
            id: Vec::with_capacity(nf + nb),
        };
        for i in (0..nf).filter(|&i| f.owned(i)) {
            s.position.push(to3(std::array::from_fn::<f32, D, _>(|k| {
                f.pos[k][i] as f32
            })));
            s.velocity.push(to3(std::array::from_fn::<f32, D, _>(|k| {
                f.vel[k][i] as f32
            })));
            let rho = f.rho[i] as f32;
            s.pressure.push(if dfsph {
                f.pressure[i] as f32
            } else {
                self.eos.pressure(rho)
            });
            s.density.push(rho);
            s.id.push(f.id[i]);
        }
        s.fluid = s.id.len();
        if let Some(dom) = &self.dom {
            return self.gather_snapshot(dom, s);
        }
        for j in 0..nb {
            let (x, v) = self.wall_particle(j);
            s.position.push(x);
            s.velocity.push(v);
            let rho = b.rho.get(j).map_or(self.eos.rho0, |&r| r as f32);
            s.pressure
                .push(if dfsph { 0.0 } else { self.eos.pressure(rho) });
            s.density
                .push(if dfsph { self.dcoef.rho_rest } else { rho });
            s.id.push(j as u32);
        }
        s
    }

    /// Position and velocity of boundary particle j now (x, y, z): a floating body's where the body is
    /// (its particles were last placed at the half step), a wall's where it stands.
    fn wall_particle(&self, j: usize) -> ([f32; 3], [f32; 3]) {
        let b = &self.bound;
        match b
            .tag
            .get(j)
            .copied()
            .filter(|&t| t != crate::particles::NOT_BODY)
        {
            Some(t) => {
                let (body, i) = self.bodies.which[t as usize];
                let (x, v) = self.bodies.list[body as usize].particle(i as usize);
                (x.map(|c| c as f32).into(), v.map(|c| c as f32).into())
            }
            None => (
                to3(std::array::from_fn::<f32, D, _>(|k| b.x[k][j])),
                to3(std::array::from_fn::<f32, D, _>(|k| b.v[k][j])),
            ),
        }
    }

    /// Rank 0: the liquid of every rank (in the order of the ids) and the walls with their owners'
    /// densities. Other ranks send theirs and get an empty snapshot.
    fn gather_snapshot(&self, dom: &Domain, mut s: Snapshot) -> Snapshot {
        let b = &self.bound;
        let dfsph = self.params.solver.scheme == Scheme::Dfsph;
        // Wall layers carry their owner's density; mirror ghosts differ from rank to rank: rank 0's are
        // written.
        let walls = self.params.solver.boundary.method == BoundaryMethod::Dynamic;
        let mut local = Vec::with_capacity(s.fluid * 9 + 1);
        local.push(s.fluid as f64);
        for i in 0..s.fluid {
            local.push(s.id[i] as f64);
            local.extend(
                s.position[i]
                    .iter()
                    .chain(&s.velocity[i])
                    .map(|&v| v as f64),
            );
            local.extend([s.pressure[i] as f64, s.density[i] as f64]);
        }
        for j in (0..b.rho.len()).filter(|_| walls) {
            if dom.owns(&self.grid, b.x[0][j] as f64) {
                local.extend([j as f64, b.rho[j]]);
            }
        }
        let all = dom.gather(local);
        if !dom.is_root() {
            return Snapshot::default();
        }
        let mut fluid: Vec<&[f64]> = Vec::new();
        let mut wall_rho: Vec<f64> = b.rho.clone();
        for msg in &all {
            let n = msg[0] as usize;
            fluid.extend(msg[1..1 + 9 * n].chunks_exact(9));
            for p in msg[1 + 9 * n..].chunks_exact(2) {
                wall_rho[p[0] as usize] = p[1];
            }
        }
        fluid.sort_unstable_by(|a, b| a[0].total_cmp(&b[0]));
        let f32s = |r: &[f64]| -> [f32; 3] { [r[0] as f32, r[1] as f32, r[2] as f32] };
        s = Snapshot {
            time: s.time,
            dimension: D,
            fluid: fluid.len(),
            id: fluid.iter().map(|r| r[0] as u32).collect(),
            position: fluid.iter().map(|r| f32s(&r[1..4])).collect(),
            velocity: fluid.iter().map(|r| f32s(&r[4..7])).collect(),
            pressure: fluid.iter().map(|r| r[7] as f32).collect(),
            density: fluid.iter().map(|r| r[8] as f32).collect(),
        };
        for j in 0..b.len() {
            let (x, v) = self.wall_particle(j);
            s.position.push(x);
            s.velocity.push(v);
            let rho = wall_rho.get(j).map_or(self.eos.rho0, |&r| r as f32);
            s.pressure
                .push(if dfsph { 0.0 } else { self.eos.pressure(rho) });
            s.density
                .push(if dfsph { self.dcoef.rho_rest } else { rho });
            s.id.push(j as u32);
        }
        s
    }

    /// Sets every liquid particle's velocity from its position (x, y, z in, x, y, z out): initial conditions.
    pub fn set_fluid_velocity(&mut self, f: &dyn Fn([f64; 3]) -> [f64; 3]) {
        for i in 0..self.fluid.len() {
            let v: [f64; D] = from3(f(to3(self.fluid.position(i))));
            for k in 0..D {
                self.fluid.vel[k][i] = v[k];
                self.fluid.vel0[k][i] = v[k];
            }
        }
        self.rates_current = false;
    }
}

/// The density a liquid particle inside the initial lattice sums to (the incompressible scheme holds it):
/// that of the particle nearest the middle of the liquid block, of those not `excluded`.
fn rest_density<const D: usize, K: Kernel>(
    k: &K,
    fluid: &Fluid<D>,
    bound: &Boundary<D>,
    m_fluid: f32,
    m_bound: f32,
    excluded: impl Fn([f64; D]) -> bool,
) -> f64 {
    let n = fluid.len();
    let centre: [f64; D] =
        std::array::from_fn(|d| fluid.pos[d].iter().sum::<f64>() / n.max(1) as f64);
    let dist2 = |i: usize| {
        (0..D)
            .map(|d| (fluid.pos[d][i] - centre[d]).powi(2))
            .sum::<f64>()
    };
    // (If every particle is excluded, the nearest of all.)
    let Some(a) = (0..n)
        .filter(|&i| !excluded(fluid.position(i)))
        .min_by(|&i, &j| dist2(i).total_cmp(&dist2(j)))
        .or_else(|| (0..n).min_by(|&i, &j| dist2(i).total_cmp(&dist2(j))))
    else {
        return 0.0;
    };
    let xa = fluid.position(a);
    let support = k.support() as f64;
    let sum = |m: f32, count: usize, at: &dyn Fn(usize) -> [f64; D]| {
        (0..count)
            .map(|j| {
                let x = at(j);
                let r = (0..D).map(|d| (x[d] - xa[d]).powi(2)).sum::<f64>().sqrt();
                if r < support {
                    m as f64 * k.w(r as f32) as f64
                } else {
                    0.0
                }
            })
            .sum::<f64>()
    };
    sum(m_fluid, n, &|j| fluid.position(j))
        + sum(m_bound, bound.len(), &|j| {
            std::array::from_fn(|d| bound.x[d][j] as f64)
        })
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
        self.time
    }
    fn stats(&self) -> Stats {
        self.stats
    }
    fn counts(&self) -> Counts {
        Simulation::counts(self)
    }
    fn params(&self) -> &SimParams {
        &self.params
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

/// Builds the simulation the parameters ask for: in one process, or spread over the ranks of an MPI
/// program ([`crate::domain::install`]; called on rank 0, the others follow in [`crate::domain::serve`]).
pub fn build(params: SimParams) -> Result<Box<dyn Solver>, SimError> {
    params.validate()?;
    match crate::domain::world() {
        Some(comm) => Ok(Box::new(crate::domain::Distributed::build(
            comm.clone(),
            params,
        )?)),
        None => build_local(params, None),
    }
}

/// This process's simulation (its part of one decomposed over `comm`).
pub(crate) fn build_local(
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
