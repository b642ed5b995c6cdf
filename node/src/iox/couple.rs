//! `slosh couple CASE`: the case as a co-simulation server over iceoryx2. A ship-motion solver sends the
//! vessel's state at its time t ([`MotionSample`]) and blocks until the answer: the liquid advanced to t
//! and its wrench, probes and pressures there ([`StepOutputs`]). Between two samples the tank follows the
//! quintic Hermite path through both states ([`sph::motion::CoupledMotion`]); the first sample starts the
//! simulation (its time is the simulation's zero). Every answer is also published on `NAME/outputs`, and
//! particle frames on `NAME/particles` at `--particles HZ` of sample time.
//!
//! A refused sample (NaN, not later than the last, not a unit quaternion, a move or turn from the last
//! sample faster than `input.max_speed` / `input.max_rotation_rate`) is answered with
//! [`STATUS_REJECTED`] and the field named; nothing is simulated. A solver failure is answered with
//! [`STATUS_FAILED`] and stops the server with the error. A client that dies mid-step disturbs nothing:
//! its answer is dropped and its resources are cleaned up.

use super::*;
use crate::config::Loaded;
use crate::drive::{deliver_frame, Delivery, Grid};
use crate::output::CsvOutputs;
use crate::sinks::{Output, Sink, SinkError, TimeBase};
use nalgebra::{UnitQuaternion, Vector3};
use slosh_msgs::builtin_interfaces::Time;
use sph::motion::{CoupledMotion, TankMotion};
use sph::observe::snapshot::Snapshot;
use sph::observe::Observation;
use sph::params::SimParams;
use sph::{Counts, SimError, Solver, Stats};
use std::path::PathBuf;
use std::time::{Duration, Instant};

#[derive(Debug, Clone)]
pub struct CoupleOptions {
    /// Service prefix.
    pub service: String,
    /// Particle frames per second of sample time (0: none).
    pub particles_hz: f64,
    /// Answer without simulating (the initial state's outputs): to time the transport alone.
    pub dry: bool,
    /// Also write the CSV outputs here (one row per answered step, time from the first sample).
    pub out: Option<PathBuf>,
    /// Stop after this many steps past the first sample, which only starts the simulation: N + 1 answers,
    /// what a client's `--steps N` sends (None: until SIGINT/SIGTERM).
    pub max_steps: Option<u64>,
}

/// What a serving session did.
#[derive(Debug, Clone, Default, serde::Serialize)]
pub struct Served {
    pub steps_answered: u64,
    pub samples_rejected: u64,
    pub solver_steps: u64,
    pub particle_frames: u64,
    /// Sample time of the last answered step, s.
    pub last_time: Option<f64>,
}

/// Serves the case until stopped; `ready` is called once the services are up.
pub fn serve(cfg: &Loaded, opts: &CoupleOptions, ready: impl FnOnce()) -> anyhow::Result<Served> {
    let params = cfg.sim_params()?;
    check_sensors(
        &cfg.source_name,
        params.probes.len(),
        params.pressure_sensors.len(),
    )?;
    if !(opts.particles_hz.is_finite() && opts.particles_hz >= 0.0) {
        anyhow::bail!(
            "--particles {}: frames per second of sample time, 0 or more",
            opts.particles_hz
        );
    }
    if let Some(b) = params.bodies.first() {
        anyhow::bail!(
            "{}: bodies.{}: floating bodies are not served over iceoryx2 yet (their motion has no place in \
             the step reply); run the case with `slosh run` or `slosh node`",
            cfg.source_of("bodies"),
            b.name
        );
    }
    if params.wave_maker.is_some() {
        anyhow::bail!(
            "{}: wave_maker: not served over iceoryx2 yet; run the case with `slosh run` or `slosh node`",
            cfg.source_of("wave_maker")
        );
    }
    let tp = cfg.config.frames.tank_pose;
    let mount = Mount {
        offset: Vector3::new(tp.x, tp.y, tp.z),
        rotation: UnitQuaternion::from_euler_angles(tp.roll, tp.pitch, tp.yaw),
    };
    let limits = crate::input::live_motion::Limits {
        max_speed: cfg.config.input.max_speed,
        max_rotation_rate: cfg.config.input.max_rotation_rate,
    };
    let mut sim: Box<dyn Solver> = match opts.dry {
        false => sph::build(params.clone())?,
        true => Box::new(Frozen::new(sph::build(params.clone())?)),
    };
    let mut csv = match &opts.out {
        Some(d) => {
            let c = CsvOutputs::create(d, &params, false)?;
            if !c.replaced.is_empty() {
                eprintln!(
                    "slosh couple: {}: removed what an earlier run there left and this one would not replace: {}",
                    d.display(),
                    c.replaced.join(", ")
                );
            }
            Some(c)
        }
        None => None,
    };

    let node = node("slosh_couple")?;
    let svc = coupling_services(&node, &opts.service)?;
    let server: CouplingServer = svc.rr.server_builder().create().map_err(|e| {
        use iceoryx2::service::port_factory::server::ServerCreateError;
        match e {
            ServerCreateError::ExceedsMaxSupportedServers => anyhow::anyhow!(
                "{}/coupling is already served by another process (one server per service): stop that \
                 one, or serve this case under another name with --service NAME (and its clients with the \
                 same name)",
                opts.service
            ),
            e => e.into(),
        }
    })?;
    let listener = svc.request.listener_builder().create()?;
    let notifier = svc.response.notifier_builder().create()?;
    let total = sim.counts().fluid + sim.counts().boundary;
    let mut ports = OutputPorts::new(
        &node,
        &opts.service,
        (opts.particles_hz > 0.0).then_some(total),
    )?;
    let stop = crate::signals::shutdown_flag().map_err(std::io::Error::other)?;
    ready();

    // Every answered sample is an output: to the client first (its reply), then to the outputs service
    // and the CSV files; particle frames on their own grid of sample time.
    let mut delivery = Delivery::new(&params, &cfg.config.frames.tank);
    let mut frames = Grid::new(opts.particles_hz);
    let mut served = Served::default();
    let mut motion: Option<(f64, CoupledMotion)> = None;
    let mut last_cleanup = Instant::now();
    let result: anyhow::Result<()> = 'serve: loop {
        if stop.load(std::sync::atomic::Ordering::Relaxed)
            || opts.max_steps.is_some_and(|m| served.steps_answered > m)
        {
            break Ok(());
        }
        if last_cleanup.elapsed() > Duration::from_secs(1) {
            // Clients killed mid-run leave resources behind; remove them.
            let _ = node.try_cleanup_dead_nodes();
            last_cleanup = Instant::now();
        }
        if let Err(e) = listener.timed_wait(|_| {}, Duration::from_millis(100)) {
            // A signal interrupts the wait: the loop's top decides whether it was a stop.
            if e != iceoryx2::port::listener::ListenerWaitError::InterruptSignal {
                break Err(anyhow::anyhow!("waiting for requests: {e}"));
            }
        }
        loop {
            let req = match server.receive() {
                Ok(Some(r)) => r,
                Ok(None) => break,
                Err(e) => break 'serve Err(anyhow::anyhow!("receiving a request: {e}")),
            };
            let s: MotionSample = *req.payload();
            let observation = match step(sim.as_mut(), &mut motion, &s, &mount, &limits) {
                Ok(o) => o,
                Err(why) => {
                    let (status, text, failure) = match why {
                        Unanswered::Rejected(text) => {
                            served.samples_rejected += 1;
                            (STATUS_REJECTED, text, None)
                        }
                        Unanswered::Failed(e) => (STATUS_FAILED, e.to_string(), Some(e)),
                    };
                    let mut answer = StepOutputs {
                        time: s.time,
                        status,
                        ..Default::default()
                    };
                    answer.set_message(&text);
                    // A client that has gone does not get its answer: nothing else to do.
                    let _ = req.send_copy(answer);
                    let _ = notifier.notify();
                    match failure {
                        Some(e) => break 'serve Err(e),
                        None => continue,
                    }
                }
            };
            let (t0, m) = motion
                .as_ref()
                .expect("a state is observed only once started");
            let mut reply = Reply {
                request: &req,
                notifier: &notifier,
            };
            let sinks: &mut [&mut dyn Sink] = &mut [&mut reply, &mut ports, &mut csv];
            let stamp = (Time::from_secs_f64(s.time), s.time);
            let steps = sim.stats().steps;
            if let Err(e) = delivery.hand_out(&observation, m, stamp, steps, sinks) {
                break 'serve Err(e.into());
            }
            served.steps_answered += 1;
            served.solver_steps = steps;
            served.last_time = Some(s.time);
            let base = TimeBase::Seconds(*t0);
            if let Err(e) = deliver_frame(&mut frames, sim.as_ref(), m, base, &mut [&mut ports]) {
                break 'serve Err(e.into());
            }
            served.particle_frames = ports.frames;
        }
    };
    if let Some(c) = csv {
        c.close()?;
    }
    result.map(|()| served)
}

/// The client's reply, as the first sink of an answered sample: the outputs at the sample's time.
struct Reply<'a> {
    request: &'a iceoryx2::active_request::ActiveRequest<
        ipc::Service,
        MotionSample,
        (),
        StepOutputs,
        (),
    >,
    notifier: &'a iceoryx2::port::notifier::Notifier<ipc::Service>,
}

impl Sink for Reply<'_> {
    fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
        // A client that has gone does not get its answer: nothing else to do.
        let _ = self.request.send_copy(outputs_at(out));
        let _ = self.notifier.notify();
        Ok(())
    }
}

/// Why a sample has no state to answer with.
enum Unanswered {
    /// Refused (the field named, and why): answered so; nothing was simulated.
    Rejected(String),
    /// The solver stopped: answered so, and the server stops with the error.
    Failed(anyhow::Error),
}

/// Takes one sample: the state at its time (the simulation's clock starts at the first sample), or why
/// there is none.
fn step(
    sim: &mut dyn Solver,
    motion: &mut Option<(f64, CoupledMotion)>,
    s: &MotionSample,
    mount: &Mount,
    limits: &crate::input::live_motion::Limits,
) -> Result<Observation, Unanswered> {
    check(s).map_err(Unanswered::Rejected)?;
    let state = tank_state(s, mount);
    let t_sim = match motion {
        None => {
            *motion = Some((s.time, CoupledMotion::new(0.0, state)));
            0.0
        }
        Some((t0, m)) => {
            let t = s.time - *t0;
            if t <= m.newest() {
                return Err(Unanswered::Rejected(format!(
                    "time: {} s is not after the last sample's {} s",
                    s.time,
                    m.newest() + *t0
                )));
            }
            // The node's check of its iceoryx2 input.
            let last = m.state(m.newest());
            crate::input::live_state::check_jump(limits, t - m.newest(), &last, &state)
                .map_err(|e| Unanswered::Rejected(e.to_string()))?;
            m.push(t, state);
            t
        }
    };
    let (_, m) = motion.as_ref().expect("set above");
    sim.advance_to(m as &dyn TankMotion, t_sim)
        .and_then(|()| sim.observe(m))
        .map_err(|e| {
            Unanswered::Failed(anyhow::anyhow!(
                "solver stopped at t = {:.4} s: {e}",
                sim.time()
            ))
        })
}

/// `--dry`: the simulation held in its initial state. Advancing moves only its clock (no solver steps),
/// and every observation is the first one, at the clock's time.
struct Frozen {
    sim: Box<dyn Solver>,
    time: f64,
    first: Option<Observation>,
}

impl Frozen {
    fn new(sim: Box<dyn Solver>) -> Self {
        Self {
            sim,
            time: 0.0,
            first: None,
        }
    }
}

impl Solver for Frozen {
    fn step(&mut self, _: &dyn TankMotion) -> Result<f64, SimError> {
        Ok(0.0)
    }
    fn step_to(&mut self, _: &dyn TankMotion, limit: f64) -> Result<f64, SimError> {
        let dt = (limit - self.time).max(0.0);
        self.time += dt;
        Ok(dt)
    }
    fn advance_to(&mut self, _: &dyn TankMotion, t_end: f64) -> Result<(), SimError> {
        self.time = self.time.max(t_end);
        Ok(())
    }
    fn observe(&mut self, motion: &dyn TankMotion) -> Result<Observation, SimError> {
        let first = match &self.first {
            Some(o) => o,
            None => self.first.insert(self.sim.observe(motion)?),
        };
        Ok(Observation {
            time: self.time,
            ..first.clone()
        })
    }
    fn time(&self) -> f64 {
        self.time
    }
    fn stats(&self) -> Stats {
        self.sim.stats()
    }
    fn counts(&self) -> Counts {
        self.sim.counts()
    }
    fn params(&self) -> &SimParams {
        self.sim.params()
    }
    fn liquid_mass(&self) -> f64 {
        self.sim.liquid_mass()
    }
    fn fluid_positions(&self) -> Vec<[f64; 3]> {
        self.sim.fluid_positions()
    }
    fn fluid_velocities(&self) -> Vec<[f64; 3]> {
        self.sim.fluid_velocities()
    }
    fn set_fluid_velocity(&mut self, f: &dyn Fn([f64; 3]) -> [f64; 3]) {
        self.sim.set_fluid_velocity(f)
    }
    fn snapshot(&self) -> Snapshot {
        self.sim.snapshot()
    }
    fn ranks(&self) -> usize {
        self.sim.ranks()
    }
    fn rebalances(&self) -> u64 {
        self.sim.rebalances()
    }
}
