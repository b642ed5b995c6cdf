//! The settings of the program's features that a case carries: recording (`record.*`), replay
//! (`replay.*`), the automatic resolution (`realtime.auto_resolution.*`) and the frame conventions of incoming
//! motion (`input.world_frame`, `input.body_frame`, `input.tank_pose`). The features read them from here.

use serde::Deserialize;

/// The node's default name (`-r __node:=...` changes it).
pub const DEFAULT_NAME: &str = "slosh";

/// What `record.*` configures.
#[derive(Debug, Clone, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RecordCfg {
    /// rosbag2 folder to create (empty: no recording).
    pub path: String,
    /// `zstd` (default) or `none`.
    pub compression: String,
    /// Bytes of messages per chunk.
    pub chunk_size: u64,
    /// Seconds of log time after which the chunk being written is closed and written out even if it is
    /// not full, so that a process killed hard loses at most about this much of its recording
    /// (`slosh bag repair` recovers the rest); 0: only full chunks are written out.
    pub flush_interval_s: f64,
    /// Who chose `path` (for the error messages): `record.path`, or a command's output folder.
    #[serde(skip)]
    pub chosen_by: ChosenBy,
}

/// Where a bag's folder was chosen, which is what an error about it must name, with the fix.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub enum ChosenBy {
    /// The case's `record.path`.
    #[default]
    RecordPath,
    /// `slosh replay`'s output folder (its new bag goes to OUT/bag).
    ReplayOut,
    /// `slosh bag repair --out`.
    RepairOut,
}

impl ChosenBy {
    pub fn label(self) -> &'static str {
        match self {
            Self::RecordPath => "record.path",
            Self::ReplayOut => "the replay's new bag (OUT/bag)",
            Self::RepairOut => "the repaired bag (--out)",
        }
    }

    pub fn choose_another(self) -> &'static str {
        match self {
            Self::RecordPath => "choose a new folder for record.path",
            Self::ReplayOut => "choose another --out (or set record.path)",
            Self::RepairOut => "choose another --out",
        }
    }
}

impl Default for RecordCfg {
    fn default() -> Self {
        Self {
            path: String::new(),
            compression: "zstd".into(),
            chunk_size: 768 * 1024,
            flush_interval_s: 1.0,
            chosen_by: ChosenBy::RecordPath,
        }
    }
}

/// What to do with a sample whose stamp repeats or goes back, that is not finite, or that jumps.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum BadSamples {
    /// Stop with an error naming the message.
    #[default]
    Error,
    /// Skip the sample; the summary lists each one.
    Drop,
}

/// What `replay.*` configures.
#[derive(Debug, Clone, Default, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ReplayCfg {
    pub bad_samples: BadSamples,
}

/// What `realtime.auto_resolution.*` configures.
#[derive(Debug, Clone, Copy, serde::Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct AutoResolutionCfg {
    pub enabled: bool,
    /// Coarsest spacing tried, m (0: 4 × `particle_spacing`). `particle_spacing` is the finest.
    pub max_spacing: f64,
    /// Simulated seconds of each trial.
    pub trial_s: f64,
    /// Real-time factor a spacing must reach in its trial to be chosen.
    pub target_factor: f64,
    /// Let the trials go coarser than the coarsest spacing the manual's convergence table measures accurate
    /// for the case's scheme (first sloshing mode within 1 % of its period, damping ratio at most 0.005;
    /// `crate::accuracy`); the node then warns with the errors the table measures near the spacing chosen.
    pub allow_inaccurate: bool,
}

impl Default for AutoResolutionCfg {
    fn default() -> Self {
        Self {
            enabled: false,
            max_spacing: 0.0,
            trial_s: 0.3,
            target_factor: 1.25,
            allow_inaccurate: false,
        }
    }
}

/// World frame of incoming poses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum WorldFrame {
    /// x east, y north, z up (REP 103).
    #[default]
    Enu,
    /// x north, y east, z down.
    Ned,
}

/// Body frame of incoming poses.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum BodyFrame {
    /// x forward, y left, z up (REP 103).
    #[default]
    Flu,
    /// x forward, y right, z down.
    Frd,
}

/// Pose of the tank frame (origin at the centre of the tank bottom) in the vessel's FLU body frame.
#[derive(Debug, Clone, Copy, Default, PartialEq, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct TankPose {
    /// m.
    pub x: f64,
    pub y: f64,
    pub z: f64,
    /// rad, intrinsic z-y'-x'' (yaw, then pitch, then roll).
    pub roll: f64,
    pub pitch: f64,
    pub yaw: f64,
}
