//! The offline run: step the solver under the configured motion, observe at the output rate, write the
//! outputs as it goes, and always leave a summary — also when the solver fails.

use crate::config::Loaded;
use crate::motion_source;
use crate::output::{write_summary, CsvOutputs, Summary};
use crate::record::{record_state, RecordError, Recorder};
use indicatif::{ProgressBar, ProgressStyle};
use sph::motion::TankMotion;
use sph::params::SimParams;
use sph::Solver;
use std::path::Path;
use std::time::{Duration, Instant};

#[derive(Debug, thiserror::Error)]
pub enum RunError {
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    #[error(transparent)]
    Motion(#[from] motion_source::MotionError),
    #[error("{0}")]
    Output(#[from] std::io::Error),
    #[error(transparent)]
    Record(#[from] RecordError),
    #[error(
        "interrupted at t = {time:.4} s; outputs so far (and the recording, finished) are in {dir}"
    )]
    Interrupted { time: f64, dir: String },
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
}

/// Runs a case headless into `out`; returns the summary that was also written to `out/summary.json`.
pub fn run(cfg: &Loaded, out: &Path, opts: &RunOptions) -> Result<Summary, RunError> {
    let params = cfg.sim_params()?;
    let motion = motion_source::build(cfg)?;
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
        return Err(crate::config::ConfigError::Key {
            source_name: cfg.source_name.clone(),
            key: "motion.file".into(),
            message: format!("the motion ends at t = {} s, before the requested duration of {duration} s: shorten --duration", motion.end_time()),
        }
        .into());
    }
    let mut outputs = CsvOutputs::create(out, &params)?;
    let mut recorder = if cfg.config.record.path.is_empty() {
        None
    } else {
        Some(Recorder::create(&cfg.config.record, &cfg.parameters)?)
    };
    let mut sim = sph::build(params.clone()).map_err(|e| RunError::Solver {
        error: e,
        time: 0.0,
        dir: out.display().to_string(),
    })?;
    let stop = crate::ros::shutdown_flag().map_err(std::io::Error::other)?;
    let bar = progress_bar(opts.progress, duration);
    let start = Instant::now();
    let result = run_loop(
        sim.as_mut(),
        motion.as_ref(),
        &mut outputs,
        recorder
            .as_mut()
            .map(|r| (r, &params, cfg.config.frames.tank.as_str())),
        &stop,
        duration,
        cfg.config.output_rate_hz,
        &bar,
    );
    let wall = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    outputs.flush()?;
    // The bag is finished on every path, also when the solver stopped.
    if let Some(mut r) = recorder {
        r.finish()?;
    }
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
        error: result.as_ref().err().map(|e| e.to_string()),
        parameters: cfg.parameters.clone(),
    };
    write_summary(out, &summary)?;
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

#[allow(clippy::too_many_arguments)]
fn run_loop(
    sim: &mut dyn Solver,
    motion: &dyn TankMotion,
    out: &mut CsvOutputs,
    mut rec: Option<(&mut Recorder, &SimParams, &str)>,
    stop: &std::sync::atomic::AtomicBool,
    duration: f64,
    rate: f64,
    bar: &ProgressBar,
) -> Result<(), LoopError> {
    let mut k = 0u64;
    let start = Instant::now();
    let mut last_draw = Instant::now();
    let mut last_flush = Instant::now();
    loop {
        let t = sim.time();
        if t >= k as f64 / rate - 1e-9 {
            let o = sim.observe(motion).map_err(LoopError::Solver)?;
            out.write(&o).map_err(LoopError::Io)?;
            if let Some((r, params, frame)) = rec.as_mut() {
                record_state(r, params, frame, &o, motion).map_err(LoopError::Record)?;
            }
            k = (t * rate + 1e-9).floor() as u64 + 1;
        }
        if t >= duration - 1e-9 {
            return Ok(());
        }
        if stop.load(std::sync::atomic::Ordering::Relaxed) {
            return Err(LoopError::Interrupted(t));
        }
        sim.step(motion).map_err(LoopError::Solver)?;
        if last_draw.elapsed() > Duration::from_millis(200) {
            last_draw = Instant::now();
            let rtf = sim.time() / start.elapsed().as_secs_f64();
            bar.set_position((sim.time() * 1000.0) as u64);
            bar.set_message(format!("real-time factor {rtf:.3}"));
        }
        if last_flush.elapsed() > Duration::from_secs(2) {
            last_flush = Instant::now();
            out.flush().map_err(LoopError::Io)?;
        }
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
