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
use crate::output::CsvOutputs;
use nalgebra::{UnitQuaternion, Vector3};
use sph::motion::{CoupledMotion, TankMotion};
use sph::observe::Observation;
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
    let mut sim = sph::build(params.clone())?;
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

    let mut served = Served::default();
    let mut motion: Option<(f64, CoupledMotion)> = None;
    let mut initial: Option<StepOutputs> = None;
    let mut next_frame = 0u64;
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
            let (answer, failure) = step(
                sim.as_mut(),
                &mut motion,
                &mut initial,
                &s,
                &mount,
                &limits,
                opts.dry,
            );
            if answer.status == STATUS_REJECTED {
                served.samples_rejected += 1;
            } else {
                served.steps_answered += 1;
                served.solver_steps = sim.stats().steps;
                served.last_time = Some(s.time);
            }
            // A client that has gone does not get its answer: nothing else to do.
            let _ = req.send_copy(answer);
            let _ = notifier.notify();
            if answer.status == STATUS_OK {
                if let Err(e) = ports.publish(&answer) {
                    break 'serve Err(e);
                }
                if let (Some(c), Some((t0, _))) = (csv.as_mut(), motion.as_ref()) {
                    let mut o = Observation {
                        time: s.time - t0,
                        probes: answer.probes().to_vec(),
                        pressures: answer.pressures().to_vec(),
                        ..Default::default()
                    };
                    o.wrench.force = answer.force;
                    o.wrench.moment = answer.moment;
                    if let Err(e) = c.write(&o) {
                        break 'serve Err(e.into());
                    }
                }
                if let (true, Some((t0, _))) = (opts.particles_hz > 0.0, motion.as_ref()) {
                    if s.time - t0 >= next_frame as f64 / opts.particles_hz - 1e-9 {
                        if let Err(e) = ports.publish_particles(s.time, &sim.snapshot()) {
                            break 'serve Err(e);
                        }
                        served.particle_frames = ports.frames;
                        next_frame = ((s.time - t0) * opts.particles_hz + 1e-9).floor() as u64 + 1;
                    }
                }
            }
            if let Some(e) = failure {
                break 'serve Err(e);
            }
        }
    };
    if let Some(c) = csv {
        c.close()?;
    }
    result.map(|()| served)
}

/// Answers one sample: the outputs, and the error that must stop the server (solver failure).
fn step(
    sim: &mut dyn sph::Solver,
    motion: &mut Option<(f64, CoupledMotion)>,
    initial: &mut Option<StepOutputs>,
    s: &MotionSample,
    mount: &Mount,
    limits: &crate::input::live_motion::Limits,
    dry: bool,
) -> (StepOutputs, Option<anyhow::Error>) {
    let reject = |msg: String| {
        let mut o = StepOutputs {
            time: s.time,
            status: STATUS_REJECTED,
            ..Default::default()
        };
        o.set_message(&msg);
        (o, None)
    };
    if let Err(e) = check(s) {
        return reject(e);
    }
    let state = tank_state(s, mount);
    let steps_before = sim.stats().steps;
    let t_sim = match motion {
        None => {
            *motion = Some((s.time, CoupledMotion::new(0.0, state)));
            0.0
        }
        Some((t0, m)) => {
            let t = s.time - *t0;
            if t <= m.newest() {
                return reject(format!(
                    "time: {} s is not after the last sample's {} s",
                    s.time,
                    m.newest() + *t0
                ));
            }
            // The node's check of its iceoryx2 input.
            let last = m.state(m.newest());
            if let Err(e) =
                crate::input::live_state::check_jump(limits, t - m.newest(), &last, &state)
            {
                return reject(e.to_string());
            }
            m.push(t, state);
            t
        }
    };
    let (_, m) = motion.as_ref().expect("set above");
    let observed = if dry {
        match initial {
            Some(o) => Ok(*o),
            None => sim.observe(m).map(|o| outputs_of(s.time, &o)),
        }
    } else {
        sim.advance_to(m as &dyn TankMotion, t_sim)
            .and_then(|()| sim.observe(m))
            .map(|o| outputs_of(s.time, &o))
    };
    match observed {
        Ok(mut o) => {
            if initial.is_none() {
                *initial = Some(o);
            }
            o.time = s.time;
            o.steps = (sim.stats().steps - steps_before) as u32;
            (o, None)
        }
        Err(e) => {
            let mut o = StepOutputs {
                time: s.time,
                status: STATUS_FAILED,
                ..Default::default()
            };
            let text = format!("solver stopped at t = {:.4} s: {e}", sim.time());
            o.set_message(&text);
            (o, Some(anyhow::anyhow!(text)))
        }
    }
}
