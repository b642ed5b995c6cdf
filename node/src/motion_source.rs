//! Builds the tank motion a run asks for: none, regular, irregular (JONSWAP) or a CSV file of samples; and
//! the checked motion of `slosh motion` (either transport).

use crate::config::{Loaded, MotionSource};
use sph::motion::{AtRest, IrregularMotion, RegularMotion, SampledMotion, TankMotion};
use std::path::Path;

/// The header a motion CSV must have.
pub const CSV_HEADER: &str = "time,x,y,z,roll,pitch,yaw";

#[derive(Debug, thiserror::Error)]
pub enum MotionError {
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    #[error("motion.file {path}: {message}")]
    File { path: String, message: String },
}

/// Reads a motion CSV: header `time,x,y,z,roll,pitch,yaw`, then one sample a line (s, m, rad).
pub fn read_csv(path: &Path) -> Result<SampledMotion, MotionError> {
    let p = path.display().to_string();
    let err = |message: String| MotionError::File {
        path: p.clone(),
        message,
    };
    let text = std::fs::read_to_string(path).map_err(|e| err(format!("cannot read: {e}")))?;
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'));
    let header = lines.next().map(|(_, l)| l).unwrap_or("");
    let cols: Vec<String> = header.split(',').map(|c| c.trim().to_string()).collect();
    if cols.join(",") != CSV_HEADER {
        return Err(err(format!("header is `{header}`, expected `{CSV_HEADER}` (s, m, rad; pose of the tank frame in the world, z up)")));
    }
    let (mut times, mut poses) = (Vec::new(), Vec::new());
    let mut line_of = Vec::new();
    for (i, line) in lines {
        let vals: Vec<&str> = line.split(',').map(str::trim).collect();
        if vals.len() != 7 {
            return Err(err(format!(
                "line {}: expected 7 values, got {}",
                i + 1,
                vals.len()
            )));
        }
        let mut row = [0.0; 7];
        for (k, v) in vals.iter().enumerate() {
            row[k] = v.parse::<f64>().map_err(|_| {
                err(format!(
                    "line {}: `{v}` in column {} is not a number",
                    i + 1,
                    cols[k]
                ))
            })?;
        }
        times.push(row[0]);
        poses.push([row[1], row[2], row[3], row[4], row[5], row[6]]);
        line_of.push(i + 1);
    }
    SampledMotion::new(times, &poses).map_err(|e| {
        let msg = e.to_string();
        // Report the file's line, not the sample index.
        let line = match &e {
            sph::motion::SampleError::NotFinite { index, .. }
            | sph::motion::SampleError::NotIncreasing { index, .. } => line_of.get(*index).copied(),
            _ => None,
        };
        match line {
            Some(l) => err(format!("line {l}: {msg}")),
            None => err(msg),
        }
    })
}

/// The motion of a loaded configuration.
pub fn build(cfg: &Loaded) -> Result<Box<dyn TankMotion>, MotionError> {
    let m = &cfg.config.motion;
    Ok(match m.source {
        MotionSource::None => Box::new(AtRest),
        MotionSource::Regular => Box::new(RegularMotion {
            dofs: cfg.regular()?,
            ramp: m.ramp_time,
        }),
        MotionSource::Irregular => {
            let i = &m.irregular;
            Box::new(IrregularMotion::new(
                &cfg.irregular()?,
                i.gamma,
                i.components,
                i.seed,
                m.ramp_time,
            ))
        }
        MotionSource::Csv => Box::new(read_csv(&cfg.motion_file()?)?),
    })
}

/// Options of `slosh motion`.
#[derive(Debug, Clone)]
pub struct MotionOptions {
    /// Samples per second.
    pub rate_hz: f64,
    /// Seconds of motion to publish.
    pub duration: f64,
    /// Also publish PoseStamped on `motion/pose`.
    pub pose: bool,
    /// Also publish sensor_msgs/Imu on `motion/imu` (an IMU at the vessel's frame origin).
    pub imu: bool,
    /// Also publish geometry_msgs/AccelStamped on `motion/accel` (body frame).
    pub accel: bool,
    /// Wait until this many subscribers are on `motion/odom` before the first sample (0: do not wait).
    pub wait_for_subscribers: usize,
    /// Publish ahead of a simulation's `/clock` by `lead` samples instead of pacing by the wall clock.
    pub lockstep: bool,
    /// Stamp of the first sample, s since the epoch (None: now).
    pub start_stamp: Option<f64>,
}

impl MotionOptions {
    /// The stamp of the first sample: `start_stamp`, or now (seconds since the epoch).
    pub fn start_stamp(&self) -> f64 {
        self.start_stamp.unwrap_or_else(|| {
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs_f64())
                .unwrap_or(0.0)
        })
    }
}

/// The case (`config` with `params` overrides) and its motion, once `--rate` and `--duration` are checked and the
/// motion lasts the duration (for either transport of `slosh motion`).
pub fn checked_motion(
    config: &str,
    params: &[String],
    opts: &MotionOptions,
) -> anyhow::Result<(crate::config::Loaded, Box<dyn sph::motion::TankMotion>)> {
    if !(opts.rate_hz.is_finite() && opts.rate_hz > 0.0) {
        anyhow::bail!(
            "--rate: must be a positive number of samples per second, got {}",
            opts.rate_hz
        );
    }
    if !(opts.duration.is_finite() && opts.duration > 0.0) {
        anyhow::bail!(
            "--duration: must be a positive number of seconds, got {}",
            opts.duration
        );
    }
    if let Some(s) = opts.start_stamp {
        // builtin_interfaces/Time holds whole seconds in an i32: the last sample must fit too.
        let last = s + opts.duration;
        if !(s.is_finite() && s >= 0.0 && last < i32::MAX as f64) {
            anyhow::bail!(
                "--start-stamp: must be seconds since the epoch from 0 to {} (less --duration), got {s}",
                i32::MAX
            );
        }
    }
    let cfg = crate::config::load(config, params)?;
    let motion = build(&cfg)?;
    if opts.duration > motion.end_time() {
        anyhow::bail!(
            "--duration {} s: the motion ends at t = {} s",
            opts.duration,
            motion.end_time()
        );
    }
    Ok((cfg, motion))
}
