//! The offline run: step the solver under the configured motion, observe at the output rate, write the
//! outputs as it goes, and always leave a summary — also when the solver fails.

use crate::config::Loaded;
use crate::config::RecordCfg;
use crate::drive::{deliver_frame, DriveError, Grid, Outputs};
use crate::motion_source;
use crate::output::{write_summary, CsvOutputs, Summary};
use crate::record::{record_state, RecordError, Recorder};
use crate::sinks::{FrameSink, Output, RecordState, Recording, Sink, SinkError, TimeBase};
use crate::snapshot::{SnapshotOptions, SnapshotWriter};
use indicatif::{ProgressBar, ProgressStyle};
use sph::motion::TankMotion;
use sph::Solver;
use std::path::Path;
use std::time::{Duration, Instant};

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    #[error(transparent)]
    Motion(#[from] motion_source::MotionError),
    #[error(transparent)]
    Output(#[from] std::io::Error),
    #[error(transparent)]
    Record(#[from] RecordError),
    #[error(
        "interrupted at t = {time:.4} s; outputs so far are in {dir}{}",
        .recording.as_ref().map(|r| format!(", the recording (finished) in {r}")).unwrap_or_default()
    )]
    Interrupted {
        time: f64,
        dir: String,
        /// The bag's folder, if the run recorded one.
        recording: Option<String>,
    },
    #[error("solver stopped: {error} (outputs up to t = {time:.4} s are in {dir})")]
    Solver {
        error: sph::SimError,
        time: f64,
        dir: String,
    },
}

/// Options of one run.
#[derive(Debug, Clone, Default)]
pub struct RunOptions {
    /// Simulated seconds (None: the config's `duration`).
    pub duration: Option<f64>,
    /// Show a progress bar (on a terminal).
    pub progress: bool,
    /// Simulated seconds per wall-clock second at most (None: as fast as possible).
    pub rate: Option<f64>,
    /// Particle frames for ParaView (None: off).
    pub snapshots: Option<SnapshotOptions>,
}

/// What drives a run besides its configuration.
pub struct Drive<'a> {
    pub motion: &'a dyn TankMotion,
    /// The recording to create once the run's options are checked (None: off), and how one state is
    /// recorded.
    pub record: Option<(RecordCfg, &'a mut RecordState<'a>)>,
    /// How the recorded outputs are stamped (a run: its simulation time; a replay: on the bag's time base).
    pub time_base: TimeBase,
    /// Extra facts for `summary.json` (e.g. where a replay's motion came from).
    pub input: Option<serde_json::Value>,
    /// Called once the run's options are checked and its outputs created, before the first step (a
    /// replay says there what it replays and where it writes).
    pub started: Option<Box<dyn FnOnce() + 'a>>,
}

/// Runs a case headless into `out`; returns the summary that was also written to `out/summary.json`.
/// `announce` is called once the case and options are checked and the outputs created (not at all when
/// the run is refused).
pub fn run(
    cfg: &Loaded,
    out: &Path,
    opts: &RunOptions,
    announce: impl FnOnce(),
) -> Result<Summary, RunError> {
    // The case's errors are said before the motion's.
    cfg.sim_params()?;
    let motion = motion_source::build(cfg)?;
    let frame = cfg.config.frames.tank.clone();
    let mut record = |r: &mut Recorder, out: &Output| {
        record_state(
            r,
            &frame,
            out.stamp,
            out.messages(),
            &out.motion.state(out.observation.time),
        )
    };
    drive(
        cfg,
        out,
        opts,
        Drive {
            started: Some(Box::new(announce)),
            motion: motion.as_ref(),
            record: (!cfg.config.record.path.is_empty())
                .then(|| (cfg.config.record.clone(), &mut record as &mut RecordState)),
            time_base: TimeBase::Seconds(0.0),
            input: None,
        },
    )
}

/// Runs a case headless into `out` under the motion and recording of `d`.
pub fn drive(
    cfg: &Loaded,
    out: &Path,
    opts: &RunOptions,
    d: Drive<'_>,
) -> Result<Summary, RunError> {
    let params = cfg.sim_params()?;
    let motion = d.motion;
    let duration = opts.duration.unwrap_or(cfg.config.duration);
    if !(duration.is_finite() && duration > 0.0) {
        return Err(crate::config::ConfigError::Key {
            source_name: "--duration".into(),
            key: "duration".into(),
            message: format!("must be a positive number of seconds, got {duration}"),
        }
        .into());
    }
    if duration > motion.end_time() {
        let end = motion.end_time();
        let (source_name, fix) = match opts.duration {
            Some(_) => (
                "--duration".to_string(),
                format!("ask for at most {end:.3} s"),
            ),
            None => (
                cfg.source_name.clone(),
                format!("set `duration` to at most {end:.3} s or pass a shorter --duration"),
            ),
        };
        return Err(crate::config::ConfigError::Key {
            source_name,
            key: "duration".into(),
            message: format!("the motion ends at t = {end:.3} s, before the requested duration of {duration} s: {fix}"),
        }
        .into());
    }
    if let Some(rate) = opts.rate {
        if !(rate.is_finite() && rate > 0.0) {
            return Err(crate::config::ConfigError::Key {
                source_name: "--rate".into(),
                key: "rate".into(),
                message: format!("must be a positive factor of real time, got {rate}"),
            }
            .into());
        }
    }
    if let Some(s) = &opts.snapshots {
        if !(s.rate_hz.is_finite() && s.rate_hz > 0.0) {
            return Err(crate::config::ConfigError::Key {
                source_name: "--snapshots".into(),
                key: "snapshots".into(),
                message: format!(
                    "must be a positive number of frames per simulated second, got {}",
                    s.rate_hz
                ),
            }
            .into());
        }
    }
    // The case as run: `--duration` (or a replay's span) in place of the config's.
    let mut parameters = cfg.parameters.clone();
    if let Some(p) = parameters.as_object_mut() {
        p.insert("duration".into(), duration.into());
    }
    let mut effective = cfg.effective_parameters(&params);
    effective["duration"] = duration.into();
    let mut record = match d.record {
        Some((rc, f)) => Some((Recorder::create(&rc, &parameters, &effective)?, f)),
        None => None,
    };
    let mut csv = CsvOutputs::create(out, &params, opts.snapshots.is_some())?;
    if !csv.replaced.is_empty() {
        eprintln!(
            "{}: removed what an earlier run there left and this one would not replace: {}",
            out.display(),
            csv.replaced.join(", ")
        );
    }
    let mut snapshots = match &opts.snapshots {
        Some(s) => Some((SnapshotWriter::create(s)?, s.rate_hz)),
        None => None,
    };
    if let Some(f) = d.started {
        f();
    }
    for w in params.sensors_beside_walls() {
        eprintln!("warning: pressure_sensors: {w}");
    }
    let mut sim = sph::build(params.clone()).map_err(|e| RunError::Solver {
        error: e,
        time: 0.0,
        dir: out.display().to_string(),
    })?;
    let stop = crate::signals::shutdown_flag().map_err(std::io::Error::other)?;
    let bar = progress_bar(opts.progress, duration);
    let start = Instant::now();
    let mut recording = record.as_mut().map(|(r, f)| Recording {
        recorder: r,
        record: &mut **f,
    });
    let mut sinks: [&mut dyn Sink; 2] = [&mut csv, &mut recording];
    let mut outputs = Outputs::new(cfg.config.output_rate_hz, &params, &cfg.config.frames.tank);
    let result = run_loop(
        sim.as_mut(),
        motion,
        &mut outputs,
        d.time_base,
        &mut sinks,
        snapshots.as_mut().map(|(w, hz)| (w, Grid::new(*hz))),
        &stop,
        Pace {
            duration,
            speed: opts.rate,
        },
        &bar,
    );
    let wall = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    // The CSVs are flushed and the bag finished on every path, also when the solver stopped; the first
    // failure is the one reported (a bag that failed to write usually fails to finish too).
    let flushed = csv.close();
    let recording = record.as_ref().map(|(r, _)| r.dir().display().to_string());
    let finished = record.map_or(Ok(()), |(mut r, _)| r.finish());
    let snapshot_info = snapshots.map(|(w, hz)| {
        let (dir, frame) = (w.dir().to_path_buf(), w.frame());
        (w.finish(), dir, frame, hz)
    });
    let frames_written = match &snapshot_info {
        Some((Err(e), ..)) => Err(LoopError::Io(std::io::Error::other(e.to_string()))),
        _ => Ok(()),
    };
    let result = result
        .and(frames_written)
        .and_then(|()| flushed.map_err(LoopError::Io))
        .and_then(|()| finished.map_err(LoopError::Record));
    let (stats, counts) = (sim.stats(), sim.counts());
    let summary = Summary {
        dimension: params.dimension,
        particles_fluid: counts.fluid,
        particles_boundary: counts.boundary,
        particles_lost: counts.lost,
        steps: stats.steps,
        force_evaluations: stats.force_evaluations,
        sim_time_s: sim.time(),
        wall_time_s: wall,
        realtime_factor: sim.time() / wall,
        particle_steps_per_s: stats.steps as f64 * counts.fluid as f64 / wall,
        min_dt_s: if stats.min_dt.is_finite() {
            stats.min_dt
        } else {
            0.0
        },
        liquid_mass_kg: sim.liquid_mass(),
        mpi_ranks: sim.ranks(),
        rebalances: sim.rebalances(),
        error: result.as_ref().err().map(|e| e.to_string()),
        input: d.input,
        snapshots: snapshot_info.map(|(frames, dir, frame, hz)| {
            serde_json::json!({
                "dir": dir,
                "series": dir.join(crate::snapshot::SERIES),
                "frames": frames.unwrap_or(0),
                "rate_hz": hz,
                "frame": frame,
            })
        }),
        pressure_solver: (params.solver.scheme == sph::params::Scheme::Dfsph).then(|| {
            serde_json::json!({
                "iterations": stats.solver_iterations,
                "iterations_per_step": stats.solver_iterations as f64 / stats.steps.max(1) as f64,
                "max_density_error": stats.max_density_error,
                "tolerance": params.density_tolerance(),
                "unconverged_steps": stats.unconverged_steps,
                "retried_steps": stats.retried_steps,
            })
        }),
        parameters,
        effective_parameters: effective,
    };
    // A failed run's own error is the one reported (a full disk fails the summary as well).
    match (write_summary(out, &summary), &result) {
        (Err(e), Ok(())) => return Err(e.into()),
        (Err(e), Err(_)) => eprintln!("slosh: not written: {e}"),
        (Ok(()), _) => {}
    }
    match result {
        Ok(()) => Ok(summary),
        Err(LoopError::Solver(error)) => Err(RunError::Solver {
            error,
            time: sim.time(),
            dir: out.display().to_string(),
        }),
        Err(LoopError::Io(e)) => Err(e.into()),
        Err(LoopError::Record(e)) => Err(e.into()),
        Err(LoopError::Interrupted(t)) => Err(RunError::Interrupted {
            time: t,
            dir: out.display().to_string(),
            recording,
        }),
    }
}

#[derive(Debug, thiserror::Error)]
enum LoopError {
    #[error(transparent)]
    Solver(sph::SimError),
    #[error(transparent)]
    Io(std::io::Error),
    #[error(transparent)]
    Record(RecordError),
    #[error("interrupted (SIGINT/SIGTERM) at t = {0:.4} s")]
    Interrupted(f64),
}

/// How long and how fast a run goes.
struct Pace {
    /// Simulated seconds.
    duration: f64,
    /// Simulated seconds per wall-clock second at most.
    speed: Option<f64>,
}

/// Steps the solver to each output time and hands every output to the `sinks`, and the particle frames
/// (with their rate) to `snap`, until the duration or a stop.
#[allow(clippy::too_many_arguments)]
fn run_loop(
    sim: &mut dyn Solver,
    motion: &dyn TankMotion,
    outputs: &mut Outputs,
    base: TimeBase,
    sinks: &mut [&mut dyn Sink],
    mut snap: Option<(&mut SnapshotWriter, Grid)>,
    stop: &std::sync::atomic::AtomicBool,
    pace: Pace,
    bar: &ProgressBar,
) -> Result<(), LoopError> {
    let duration = pace.duration;
    let start = Instant::now();
    let mut last_draw = Instant::now();
    let mut last_flush = Instant::now();
    loop {
        let t = sim.time();
        outputs
            .deliver(sim, motion, base, sinks)
            .map_err(|e| match e {
                DriveError::Solver(e) => LoopError::Solver(e),
                DriveError::Sink(e) => at(t, e),
            })?;
        // Frames change nothing the run computes: they are the first state at or after their times, which is
        // theirs exactly where their rate divides the output rate.
        if let Some((w, times)) = snap.as_mut() {
            deliver_frame(times, sim, motion, base, &mut [*w as &mut dyn FrameSink])
                .map_err(|e| at(t, e))?;
        }
        if t >= duration - 1e-9 {
            return Ok(());
        }
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(LoopError::Interrupted(t));
        }
        outputs
            .step(sim, motion, duration)
            .map_err(LoopError::Solver)?;
        if let Some(speed) = pace.speed {
            let ahead = sim.time() / speed - start.elapsed().as_secs_f64();
            if ahead > 1e-3 {
                std::thread::sleep(Duration::from_secs_f64(ahead));
            }
        }
        if last_draw.elapsed() > Duration::from_millis(200) {
            last_draw = Instant::now();
            let rtf = sim.time() / start.elapsed().as_secs_f64();
            bar.set_position((sim.time() * 1000.0) as u64);
            bar.set_message(format!("real-time factor {rtf:.3}"));
        }
        if last_flush.elapsed() > Duration::from_secs(2) {
            last_flush = Instant::now();
            for s in sinks.iter_mut() {
                s.flush().map_err(|e| at(sim.time(), e))?;
            }
        }
    }
}

/// A sink's error at simulation time `t` (an output file's says when).
fn at(t: f64, e: SinkError) -> LoopError {
    match e {
        SinkError::Io(e) => LoopError::Io(std::io::Error::new(
            e.kind(),
            format!("writing the outputs at t = {t:.4} s: {e}"),
        )),
        SinkError::Record(e) => LoopError::Record(e),
        SinkError::Send(e) => LoopError::Io(std::io::Error::other(format!(
            "sending the outputs at t = {t:.4} s: {e}"
        ))),
    }
}

fn progress_bar(enabled: bool, duration: f64) -> ProgressBar {
    if !enabled {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new((duration * 1000.0) as u64);
    bar.set_style(
        ProgressStyle::with_template("{spinner} sim {pos:>7}/{len} ms [{bar:30}] {msg}, ETA {eta}")
            .expect("valid template")
            .progress_chars("=> "),
    );
    bar
}
