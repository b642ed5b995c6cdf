//! Builds the tank motion a run asks for: none, regular, irregular (JONSWAP) or a CSV file of samples.

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
