//! `slosh replay`: drives the tank with the vessel motion recorded in a rosbag2 MCAP bag, faster than real
//! time, writing the same CSV outputs as `slosh run` and a new bag with the motion as it was recorded plus
//! every output, all on the source bag's time axis.

pub mod motion;

use crate::bag::{self, BagError};
use crate::config::Loaded;
use crate::config::{ChosenBy, RecordCfg};
use crate::input::frames::Frames;
use crate::input::gravity_check::{GravityCheck, InputKind};
use crate::output::Summary;
use crate::record::{output_topics, Recorder};
use crate::runner::{drive, Drive, RunError, RunOptions};
use crate::sinks::{Output, RecordState, TimeBase};
use slosh_msgs::builtin_interfaces::Time;
use std::path::Path;

/// Options of one replay.
#[derive(Debug, Clone, Default)]
pub struct ReplayOptions {
    /// The motion topic (None: the only one in the bag).
    pub topic: Option<String>,
    /// Simulated seconds (None: the whole recorded motion).
    pub duration: Option<f64>,
    /// Simulated seconds per wall-clock second at most (None: as fast as possible).
    pub rate: Option<f64>,
    pub progress: bool,
    /// Particle frames for ParaView (None: off).
    pub snapshots: Option<crate::snapshot::SnapshotOptions>,
}

#[derive(Debug, thiserror::Error)]
pub enum ReplayError {
    #[error(transparent)]
    Bag(#[from] BagError),
    #[error(transparent)]
    Config(#[from] crate::config::ConfigError),
    #[error(transparent)]
    Run(#[from] RunError),
}

/// The motion a replay found, as reported before it starts.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Found {
    pub bag: String,
    pub topic: String,
    #[serde(rename = "type")]
    pub type_name: String,
    pub messages: usize,
    pub samples: usize,
    pub dropped: Vec<String>,
    /// `header` (header stamps) or `log` (the bag's log times).
    pub time_source: String,
    /// Stamp of the first sample (s since the epoch): the replay's t = 0.
    pub start_stamp_s: f64,
    /// s of motion.
    pub span_s: f64,
    /// The new recording.
    pub recording: String,
    /// The frame conventions' plausibility check over the first half second (see
    /// [`crate::input::gravity_check`]): `ok` or its warning.
    pub input_check: String,
}

/// Replays `bag` through the case `cfg` into `out`; `announce` is told what motion was found once the
/// run's options are checked and its outputs created, before the simulation starts (not at all when the
/// replay is refused).
pub fn replay(
    bag_path: &Path,
    cfg: &Loaded,
    out: &Path,
    opts: &ReplayOptions,
    announce: impl FnOnce(&Found),
) -> Result<Summary, ReplayError> {
    let c = &cfg.config;
    let params = cfg.sim_params()?;
    let files = bag::files(bag_path)?;
    let frames = Frames::new(c.input.world_frame, c.input.body_frame, c.frames.tank_pose);
    let how = motion::Reading::of(c, &frames, opts.topic.as_deref(), params.gravity);
    let bm = motion::read(bag_path, &files, &how)?;
    let record_cfg = if c.record.path.is_empty() {
        RecordCfg {
            path: out.join("bag").display().to_string(),
            chosen_by: ChosenBy::ReplayOut,
            ..c.record.clone()
        }
    } else {
        c.record.clone()
    };
    let span = bm.motion.end_time();
    let kind = match bm.kind {
        motion::Kind::Imu => InputKind::Imu,
        _ => InputKind::Pose,
    };
    let mut check = GravityCheck::default();
    let input_check = (0..)
        .map(|k| k as f64 * 0.01)
        .take_while(|t| *t <= span)
        .find_map(|t| {
            let g = bm.motion.state(t).apparent_gravity(params.gravity);
            check.add(t, g, params.gravity, kind)
        })
        .map_or_else(
            || "too short to check".to_string(),
            |r| r.err().unwrap_or_else(|| "ok".into()),
        );
    let found = Found {
        bag: bag_path.display().to_string(),
        topic: bm.topic.clone(),
        type_name: bm.kind.type_name(),
        messages: bm.total,
        samples: bm.messages.len(),
        dropped: bm.dropped.clone(),
        time_source: bm.time_source.into(),
        start_stamp_s: Time::from_nanos(bm.t0_ns).as_secs_f64(),
        span_s: span,
        recording: record_cfg.path.clone(),
        input_check,
    };
    let topics = output_topics();
    let mut next = 0;
    let mut record = |r: &mut Recorder, out: &Output| {
        // The motion that drove the tank up to this state, as recorded, then the outputs.
        let stamp_ns = out.stamp.as_nanos();
        while let Some((t, data)) = bm.messages.get(next).filter(|m| m.0 <= stamp_ns) {
            r.write_raw(
                &bm.topic,
                &found.type_name,
                &bm.schema,
                (*t).max(0) as u64,
                data,
            )?;
            next += 1;
        }
        r.write_outputs(&topics, out.stamp, out.messages())
    };
    let run = RunOptions {
        duration: Some(opts.duration.unwrap_or(span)),
        progress: opts.progress,
        rate: opts.rate,
        snapshots: opts.snapshots.clone(),
    };
    let input = serde_json::to_value(&found).expect("serialises");
    Ok(drive(
        cfg,
        out,
        &run,
        Drive {
            motion: bm.motion.as_ref(),
            record: Some((record_cfg, &mut record as &mut RecordState)),
            time_base: TimeBase::Nanos(bm.t0_ns),
            input: Some(input),
            // Said once the outputs exist: a replay refused by its options writes nothing and says so.
            started: Some(Box::new(|| announce(&found))),
        },
    )?)
}
