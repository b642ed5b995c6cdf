//! Run configuration: a YAML file in the ROS 2 parameters layout (`<node name>: ros__parameters: ...`),
//! parsed once into typed structs. `--set key.sub=value` overrides any parameter by its dotted name, the value
//! parsed as YAML. Every error names the file, the parameter and what is accepted.

mod features;

pub use features::{
    AutoResolutionCfg, BadSamples, BodyFrame, ChosenBy, RecordCfg, ReplayCfg, TankPose, WorldFrame,
    DEFAULT_NAME,
};

use serde::Deserialize;
use serde_json::{Map, Value};
use sph::motion::{JonswapDof, RegularDof};
use sph::params::{
    BodySpec, FillSpec, FluidSpec, ProbeSpec, RegionSpec, SensorSpec, SimParams, SolverSpec,
    TankSpec,
};
use std::path::{Path, PathBuf};

/// The cases shipped in `launch-configs/`, built into the binary so `slosh run NAME` and `slosh bench` work
/// anywhere.
pub const BUILTIN: &[(&str, &str)] = &[
    (
        "seed_tank_039",
        include_str!("../../launch-configs/seed_tank_039.yaml"),
    ),
    (
        "seed_tank_019",
        include_str!("../../launch-configs/seed_tank_019.yaml"),
    ),
    (
        "dambreak_2d",
        include_str!("../../launch-configs/dambreak_2d.yaml"),
    ),
    (
        "faltinsen2000_sway",
        include_str!("../../launch-configs/faltinsen2000_sway.yaml"),
    ),
    (
        "spheric10",
        include_str!("../../launch-configs/spheric10.yaml"),
    ),
    (
        "akyildiz2006_pitch",
        include_str!("../../launch-configs/akyildiz2006_pitch.yaml"),
    ),
    (
        "bouscasse2013_shallow",
        include_str!("../../launch-configs/bouscasse2013_shallow.yaml"),
    ),
    (
        "kleefsman2005_dambreak",
        include_str!("../../launch-configs/kleefsman2005_dambreak.yaml"),
    ),
    (
        "flooding_case_a",
        include_str!("../../launch-configs/flooding_case_a.yaml"),
    ),
    (
        "flooding_case_b",
        include_str!("../../launch-configs/flooding_case_b.yaml"),
    ),
    (
        "flooding_case_c",
        include_str!("../../launch-configs/flooding_case_c.yaml"),
    ),
    (
        "flooding_3d_compartment",
        include_str!("../../launch-configs/flooding_3d_compartment.yaml"),
    ),
];

#[derive(Debug, thiserror::Error)]
pub enum ConfigError {
    #[error("{source_name}: cannot read: {message}")]
    Read {
        source_name: String,
        message: String,
    },
    #[error("{source_name}: not valid YAML: {message}")]
    Yaml {
        source_name: String,
        message: String,
    },
    #[error("{source_name}: {message}")]
    Layout {
        source_name: String,
        message: String,
    },
    #[error("{source_name}: {key}: {message}")]
    Key {
        source_name: String,
        key: String,
        message: String,
    },
}

const DOF_NAMES: &str = "x, y, z, roll, pitch, yaw";

#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum MotionSource {
    #[default]
    None,
    Regular,
    Irregular,
    Csv,
}

/// Per-DOF sinusoids, arrays in the order x, y, z, roll, pitch, yaw (m, rad, s).
#[derive(Debug, Clone, Default, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RegularCfg {
    pub amplitude: Vec<f64>,
    pub period: Vec<f64>,
    pub phase: Vec<f64>,
}

/// Per-DOF JONSWAP sums of sines, arrays in the order x, y, z, roll, pitch, yaw.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct IrregularCfg {
    /// 2·sqrt(m0) per DOF (m or rad).
    pub significant_amplitude: Vec<f64>,
    /// s, per DOF.
    pub peak_period: Vec<f64>,
    pub gamma: f64,
    pub components: usize,
    pub seed: u64,
}

impl Default for IrregularCfg {
    fn default() -> Self {
        Self {
            significant_amplitude: vec![],
            peak_period: vec![],
            gamma: 3.3,
            components: 128,
            seed: 1,
        }
    }
}

#[derive(Debug, Clone, Default, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct MotionCfg {
    pub source: MotionSource,
    /// CSV with header `time,x,y,z,roll,pitch,yaw` (relative paths: from the config file's folder).
    pub file: String,
    /// s, smooth start of synthetic motion.
    pub ramp_time: f64,
    pub regular: RegularCfg,
    pub irregular: IrregularCfg,
}

fn default_gravity() -> f64 {
    9.81
}
fn default_rate() -> f64 {
    50.0
}
fn default_duration() -> f64 {
    10.0
}

/// Everything under `ros__parameters`.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields)]
pub struct RunConfig {
    pub dimension: usize,
    pub tank: TankSpec,
    /// m: depth of the liquid at rest.
    pub fill_height: f64,
    /// m: length of the liquid block against the −x wall (0: the whole tank).
    #[serde(default)]
    pub fill_length: f64,
    /// m.
    pub particle_spacing: f64,
    #[serde(default)]
    pub fluid: FluidSpec,
    #[serde(default = "default_gravity")]
    pub gravity: f64,
    #[serde(default)]
    pub solver: SolverSpec,
    /// Wave probes, as columns (`names`, `x`, `y`).
    #[serde(default, with = "sph::params::records::probes")]
    pub probes: Vec<ProbeSpec>,
    /// Pressure sensors, as columns (`names`, `x`, `y`, `z`).
    #[serde(default, with = "sph::params::records::sensors")]
    pub pressure_sensors: Vec<SensorSpec>,
    /// Floating bodies by name (the tank is then the basin around them).
    #[serde(default, with = "sph::params::records::by_name")]
    pub bodies: Vec<BodySpec>,
    /// A piston wave maker at the tank's −x end.
    #[serde(default)]
    pub wave_maker: Option<sph::params::PistonSpec>,
    /// Fixed obstacles by name: solid boxes of wall particles fixed to the tank, centre and size in the tank
    /// frame (origin at the centre of the tank bottom).
    #[serde(default, with = "sph::params::records::by_name")]
    pub obstacles: Vec<RegionSpec>,
    /// Rows per simulated second in the outputs.
    #[serde(default = "default_rate")]
    pub output_rate_hz: f64,
    /// Simulated seconds of `slosh run` (overridden by --duration).
    #[serde(default = "default_duration")]
    pub duration: f64,
    #[serde(default)]
    pub motion: MotionCfg,
    /// The ROS 2 node's motion input (`slosh node`).
    #[serde(default)]
    pub input: InputCfg,
    /// Frame names and the tank's pose on the vessel (`slosh node`).
    #[serde(default)]
    pub frames: FramesCfg,
    /// Pacing of `slosh node`.
    #[serde(default)]
    pub realtime: RealtimeCfg,
    /// s without motion input before the node holds the last pose and reports an error (`slosh node`).
    #[serde(default = "default_timeout")]
    pub motion_timeout_s: f64,
    /// Request/reply mapping of the node's services: `enhanced` (rmw_fastrtps, ROS 2's default), `cyclone`
    /// (rmw_cyclonedds) or `basic`.
    #[serde(default)]
    pub service_mapping: ServiceMappingCfg,
    /// Recording to a rosbag2 MCAP folder (`record.path`; empty: off).
    #[serde(default)]
    pub record: RecordCfg,
    /// How `slosh replay` treats bad samples in a bag.
    #[serde(default)]
    pub replay: ReplayCfg,
    /// The `particles` PointCloud2 output of `slosh node` (off by default).
    #[serde(default)]
    pub particles: ParticlesCfg,
    /// Diagnostics messages per wall-clock second (`slosh node`).
    #[serde(default = "default_diag_rate")]
    pub diagnostics_rate_hz: f64,
    /// ROS 2's standard parameter (launch files set it on every node): `true` takes the time from `/clock`,
    /// i.e. `realtime.mode` `follow_clock` unless it is `lockstep` (which publishes `/clock` itself).
    #[serde(default)]
    pub use_sim_time: bool,
    /// iceoryx2 services of `slosh node` beside (or instead of) DDS.
    #[serde(default)]
    pub iceoryx2: Iceoryx2Cfg,
}

/// The node's zero-copy services (see `crate::iox`): motion in with `input.type: iceoryx2`, outputs and
/// particle frames out.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct Iceoryx2Cfg {
    /// Service prefix: `NAME/motion`, `NAME/outputs`, `NAME/particles`.
    pub service: String,
    /// Publish every output (wrench, probes, pressures) on `NAME/outputs`.
    pub outputs: bool,
    /// Publish every particle (liquid and walls) on `NAME/particles` at `particles.rate_hz`.
    pub particles: bool,
    /// Also publish the outputs and particle clouds over DDS (false: over iceoryx2 only; diagnostics,
    /// `/tf_static`, `/clock`, services and the recording stay).
    pub dds_outputs: bool,
}

impl Default for Iceoryx2Cfg {
    fn default() -> Self {
        Self {
            service: "slosh".into(),
            outputs: false,
            particles: false,
            dds_outputs: true,
        }
    }
}

fn default_timeout() -> f64 {
    1.0
}
fn default_diag_rate() -> f64 {
    1.0
}

/// The node's particle cloud output.
#[derive(Debug, Clone, Copy, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct ParticlesCfg {
    /// Clouds per simulated second (0: off).
    pub rate_hz: f64,
    /// Publish every n-th liquid particle.
    pub decimation: usize,
}

impl Default for ParticlesCfg {
    fn default() -> Self {
        Self {
            rate_hz: 0.0,
            decimation: 1,
        }
    }
}

/// How requests and replies of services are matched on DDS (it differs between ROS 2 middlewares).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum ServiceMappingCfg {
    #[default]
    Enhanced,
    Cyclone,
    Basic,
}

/// Which message drives the tank in `slosh node`.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum InputType {
    /// nav_msgs/Odometry on `motion/odom`.
    #[default]
    Odom,
    /// geometry_msgs/PoseStamped on `motion/pose`.
    Pose,
    /// sensor_msgs/Imu on `motion/imu`: orientation, angular velocity and specific force of the vessel at
    /// its frame origin (the tank's offset adds the lever-arm terms).
    Imu,
    /// `slosh::MotionSample` on the iceoryx2 service `<iceoryx2.service>/motion`: the vessel's full state
    /// (z-up world, FLU vessel frame), recorded as Odometry + AccelStamped.
    Iceoryx2,
}

/// Motion input of the ROS 2 node.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct InputCfg {
    #[serde(rename = "type")]
    pub kind: InputType,
    pub world_frame: WorldFrame,
    pub body_frame: BodyFrame,
    /// The solver stays this many sample intervals behind the newest sample (0 = right up to it).
    pub delay_samples: usize,
    /// m/s: a sample implying a faster move than this from the previous one is rejected as a jump.
    pub max_speed: f64,
    /// rad/s: likewise for each angle.
    pub max_rotation_rate: f64,
    /// s: a sample stamped more than this after the newest one is rejected (a garbled stamp would otherwise
    /// stretch one move over the whole gap and make every later sample out of order); ten samples in a row
    /// that follow each other on another time base are followed from then on.
    pub max_gap_s: f64,
    /// Take sample times from the header stamp (`header`) or from the arrival time (`receive`).
    pub stamp: StampSource,
    /// Also subscribe `motion/accel` (geometry_msgs/AccelStamped, vessel body frame) and use its measured
    /// accelerations instead of the pose spline's (with `odom` or `pose` input).
    pub accel: bool,
}

impl Default for InputCfg {
    fn default() -> Self {
        Self {
            kind: InputType::Odom,
            world_frame: Default::default(),
            body_frame: Default::default(),
            delay_samples: 2,
            max_speed: 50.0,
            max_rotation_rate: 5.0,
            max_gap_s: 5.0,
            stamp: StampSource::Header,
            accel: false,
        }
    }
}

/// Where a sample's time comes from.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum StampSource {
    #[default]
    Header,
    Receive,
}

/// Frame names in the node's messages, and where the tank sits on the vessel.
#[derive(Debug, Clone, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct FramesCfg {
    pub vessel: String,
    pub tank: String,
    pub tank_pose: TankPose,
}

impl Default for FramesCfg {
    fn default() -> Self {
        Self {
            vessel: "base_link".into(),
            tank: "tank".into(),
            tank_pose: Default::default(),
        }
    }
}

/// How `slosh node` paces the simulation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Deserialize, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum RealtimeMode {
    /// Keep up with the incoming motion in wall-clock time; hold the last pose when input stops.
    #[default]
    Realtime,
    /// As fast as the input allows, publishing `/clock` (CI, replay).
    Lockstep,
    /// Never ahead of the ROS time on `/clock` (rosgraph_msgs/Clock, e.g. `ros2 bag play --clock`), as
    /// nodes with `use_sim_time` do.
    FollowClock,
}

#[derive(Debug, Clone, Copy, Default, Deserialize, serde::Serialize)]
#[serde(deny_unknown_fields, default)]
pub struct RealtimeCfg {
    pub mode: RealtimeMode,
    /// Choose `particle_spacing` at start-up from a timed trial so that `realtime` mode keeps up.
    pub auto_resolution: AutoResolutionCfg,
}

/// A loaded configuration: the typed parameters, where they came from, and the merged parameter tree.
#[derive(Debug, Clone)]
pub struct Loaded {
    pub config: RunConfig,
    pub source_name: String,
    /// Folder relative paths in the config refer to (None for built-in cases: the working directory).
    pub base_dir: Option<PathBuf>,
    /// The parameters after overrides, as JSON (recorded in summary.json).
    pub parameters: Value,
    /// The node sections that were applied, in order: `NAME (FILE)`.
    pub sections: Vec<String>,
    /// The parameters overrides set, and the flag they were given with (`--set`, `-p`).
    pub overridden: Vec<String>,
    pub flag: &'static str,
}

/// serde's type errors in a user's words: "expected struct AutoResolutionCfg" (a value given where a group of
/// parameters belongs) and Rust's integer type names.
fn plain_type_error(message: &str, key: &str) -> String {
    if let Some((head, _)) = message.split_once(", expected struct ") {
        let got = head.strip_prefix("invalid type: ").unwrap_or(head);
        return format!(
            "a group of parameters, not one value (got {got}): set its members by name (`{key}.MEMBER`, e.g. with -p {key}.MEMBER:=VALUE, or nested under `{key}` in the file; see the parameter reference, docs/src/guide/parameters.md)"
        );
    }
    for (rust, plain) in [
        ("expected usize", "expected a whole number of zero or more"),
        ("expected u64", "expected a whole number of zero or more"),
        ("expected u32", "expected a whole number of zero or more"),
        ("expected u16", "expected a whole number of zero or more"),
        ("expected f64", "expected a number"),
    ] {
        if let Some(head) = message.strip_suffix(rust) {
            return format!("{head}{plain}");
        }
    }
    message.to_string()
}

/// Reads a config file, or a built-in case by name, and applies `--set` overrides. A file with several node
/// sections is read as the node `slosh` would read it (see [`load_node`]); a single section is read whatever
/// node it names.
pub fn load(path_or_name: &str, overrides: &[String]) -> Result<Loaded, ConfigError> {
    let (text, source_name, base_dir) = read(path_or_name)?;
    from_str(&text, &source_name, base_dir, overrides)
}

/// Reads the parameters of the ROS 2 node whose fully qualified name is `fqn` (`/ns/name`) the way rclcpp
/// does: from every parameters file in order, each section that applies to the node (its name, `/**`, ...;
/// [`crate::param_file`]), a later one overriding an earlier one parameter by parameter; sections for other
/// nodes are left alone. Then the `-p name:=value` overrides. A relative `motion.file` is relative to the
/// folder of the file that gave it.
pub fn load_node(files: &[String], fqn: &str, overrides: &[String]) -> Result<Loaded, ConfigError> {
    let mut params = Map::new();
    let mut base_dir = None;
    let mut others = Vec::new();
    let mut applied = Vec::new();
    for f in files {
        let (text, source_name, dir) = read(f)?;
        for s in sections_of(&text, &source_name)? {
            if !crate::param_file::applies(&s.name, fqn) {
                others.push(format!("{} ({source_name})", s.name));
                continue;
            }
            let p = group_names(s.params, &source_name)?;
            if p.get("motion").and_then(|m| m.get("file")).is_some() {
                base_dir = dir.clone();
            }
            crate::param_file::merge(&mut params, p);
            applied.push(format!("{} ({source_name})", s.name));
        }
    }
    let source_name = files.join(", ");
    if applied.is_empty() {
        return Err(ConfigError::Layout {
            source_name,
            message: format!(
                "no parameters for this node: it is {fqn}, the file's sections are for {}. A section applies \
                 to the node it names (`slosh:` is /slosh, in no namespace): name it `{fqn}:`, or `/**:` for \
                 every node",
                others.join(", ")
            ),
        });
    }
    let mut l = finish(
        Value::Object(params),
        &source_name,
        base_dir,
        overrides,
        "-p",
    )?;
    l.sections = applied;
    Ok(l)
}

/// A config file's text, its name for messages, and the folder its relative paths start from (None for a
/// built-in case).
fn read(path_or_name: &str) -> Result<(String, String, Option<PathBuf>), ConfigError> {
    let path = Path::new(path_or_name);
    if path.exists() {
        let text = std::fs::read_to_string(path).map_err(|e| ConfigError::Read {
            source_name: path_or_name.into(),
            message: e.to_string(),
        })?;
        return Ok((
            text,
            path_or_name.to_string(),
            Some(path.parent().map(Path::to_path_buf).unwrap_or_default()),
        ));
    }
    let name = path_or_name.trim_end_matches(".yaml");
    let name = name.rsplit('/').next().unwrap_or(name);
    match BUILTIN.iter().find(|(n, _)| *n == name) {
        Some((n, t)) if !path_or_name.contains('/') || !path_or_name.ends_with(".yaml") => {
            Ok((t.to_string(), format!("built-in case {n}"), None))
        }
        _ => {
            let names: Vec<&str> = BUILTIN.iter().map(|(n, _)| *n).collect();
            Err(ConfigError::Read {
                source_name: path_or_name.into(),
                message: format!("no such file (built-in cases: {})", names.join(", ")),
            })
        }
    }
}

/// The node sections of a parameters file's text.
fn sections_of(
    text: &str,
    source_name: &str,
) -> Result<Vec<crate::param_file::Section>, ConfigError> {
    let doc: Value = serde_saphyr::from_str(text).map_err(|e| ConfigError::Yaml {
        source_name: source_name.into(),
        message: for_the_user(&e),
    })?;
    crate::param_file::sections(doc).map_err(|message| ConfigError::Layout {
        source_name: source_name.into(),
        message,
    })
}

/// A section's parameters with dotted names made groups ([`nested`]).
fn group_names(params: Value, source_name: &str) -> Result<Map<String, Value>, ConfigError> {
    match nested(params, "") {
        Ok(Value::Object(m)) => Ok(m),
        Ok(_) => unreachable!("a section's parameters are a map"),
        Err(message) => Err(ConfigError::Layout {
            source_name: source_name.into(),
            message,
        }),
    }
}

/// Parses configuration text (see [`load`]).
pub fn from_str(
    text: &str,
    source_name: &str,
    base_dir: Option<PathBuf>,
    overrides: &[String],
) -> Result<Loaded, ConfigError> {
    let sections = sections_of(text, source_name)?;
    let chosen = if sections.len() == 1 {
        sections
    } else {
        let fqn = format!("/{}", DEFAULT_NAME);
        let (mine, others): (Vec<_>, Vec<_>) = sections
            .into_iter()
            .partition(|s| crate::param_file::applies(&s.name, &fqn));
        if mine.is_empty() {
            let names: Vec<&str> = others.iter().map(|s| s.name.as_str()).collect();
            return Err(ConfigError::Layout {
                source_name: source_name.into(),
                message: format!(
                    "several node sections ({}) and none for {fqn}: a file with several is read as the node \
                     {fqn} reads it (its sections `{}:`, `/**:`, ...); `slosh node` reads those for its own name",
                    names.join(", "),
                    DEFAULT_NAME,
                ),
            });
        }
        mine
    };
    let mut params = Map::new();
    let mut applied = Vec::new();
    for s in chosen {
        crate::param_file::merge(&mut params, group_names(s.params, source_name)?);
        applied.push(format!("{} ({source_name})", s.name));
    }
    let mut l = finish(
        Value::Object(params),
        source_name,
        base_dir,
        overrides,
        "--set",
    )?;
    l.sections = applied;
    Ok(l)
}

/// Applies the overrides (given with `flag`) and reads the parameters into a [`RunConfig`].
fn finish(
    mut params: Value,
    source_name: &str,
    base_dir: Option<PathBuf>,
    overrides: &[String],
    flag: &'static str,
) -> Result<Loaded, ConfigError> {
    let mut keys = Vec::new();
    for o in overrides {
        let o = &from_current_dir(o);
        apply_override(&mut params, o).map_err(|(key, message)| ConfigError::Key {
            source_name: flag.into(),
            key,
            message,
        })?;
        keys.push(
            o.split_once('=')
                .map_or(o.as_str(), |(k, _)| k)
                .trim()
                .to_string(),
        );
    }
    let mut config: RunConfig = serde_path_to_error::deserialize(params.clone()).map_err(|e| {
        let key = e.path().to_string();
        let message = plain_type_error(&e.into_inner().to_string(), &key);
        // An error in a parameter an override set (or in a group it set) is the override's.
        let given = keys.iter().any(|k| {
            *k == key || key.starts_with(&format!("{k}.")) || k.starts_with(&format!("{key}."))
        });
        ConfigError::Key {
            source_name: if given { flag } else { source_name }.into(),
            key: if key == "." {
                "(top level)".into()
            } else {
                key
            },
            message,
        }
    })?;
    if config.use_sim_time && config.realtime.mode == RealtimeMode::Realtime {
        config.realtime.mode = RealtimeMode::FollowClock;
    }
    Ok(Loaded {
        config,
        source_name: source_name.to_string(),
        base_dir,
        parameters: params,
        sections: Vec::new(),
        overridden: keys,
        flag,
    })
}

/// A `motion.file=PATH` override with a relative PATH made absolute from the current folder (where the user
/// typed it; a config file's own `motion.file` is relative to the file's folder); other overrides as they are.
fn from_current_dir(o: &str) -> String {
    if let Some((key, value)) = o.split_once('=') {
        let v = value.trim();
        if key.trim() == "motion.file" && !v.is_empty() && Path::new(v).is_relative() {
            if let Ok(here) = std::env::current_dir() {
                // Quoted as YAML, so that the path stays one string whatever its characters.
                let abs = here.join(v).display().to_string();
                return format!("{key}={}", serde_json::Value::String(abs));
            }
        }
    }
    o.to_string()
}

/// The YAML parser's message with its hints for programs using it (which parser options would accept the
/// text) turned into what the author of the parameters can do.
fn for_the_user(e: &dyn std::fmt::Display) -> String {
    e.to_string()
        .replace(
            ", set DuplicateKeyPolicy in Options if acceptable",
            " (each parameter may be given once: remove one)",
        )
        .replace(
            "rejected by the configured policy",
            "(parameters must be finite numbers)",
        )
}

/// The parameter tree with dotted names (`tank.length: 0.8`, as ROS 2 parameter files may write them) nested
/// as groups (`tank: {length: 0.8}`); a parameter given both ways is an error naming it.
fn nested(v: Value, prefix: &str) -> Result<Value, String> {
    let Value::Object(m) = v else {
        return Ok(v);
    };
    let mut out = Map::new();
    for (key, value) in m {
        let full = if prefix.is_empty() {
            key.clone()
        } else {
            format!("{prefix}.{key}")
        };
        let value = nested(value, &full)?;
        let mut parts = key.split('.').peekable();
        let mut node = &mut out;
        let mut path = prefix.to_string();
        while let Some(part) = parts.next() {
            if part.is_empty() {
                return Err(format!("{full}: empty parameter name"));
            }
            path = if path.is_empty() {
                part.to_string()
            } else {
                format!("{path}.{part}")
            };
            if parts.peek().is_none() {
                match (node.get_mut(part), value) {
                    (Some(Value::Object(have)), Value::Object(add)) => {
                        for (k, v) in add {
                            if have.insert(k.clone(), v).is_some() {
                                return Err(format!(
                                    "{path}.{k}: given twice (as a dotted name and in its group)"
                                ));
                            }
                        }
                    }
                    (Some(_), _) => {
                        return Err(format!(
                            "{path}: given twice (as a dotted name and in its group)"
                        ))
                    }
                    (None, value) => {
                        node.insert(part.to_string(), value);
                    }
                }
                break;
            }
            let next = node
                .entry(part.to_string())
                .or_insert_with(|| Value::Object(Map::new()));
            let Value::Object(next) = next else {
                return Err(format!("{path}: is a value, not a group of parameters"));
            };
            node = next;
        }
    }
    Ok(Value::Object(out))
}

/// Applies `a.b.c=value` (value parsed as YAML) to the parameter tree.
pub fn apply_override(params: &mut Value, o: &str) -> Result<(), (String, String)> {
    let Some((key, raw)) = o.split_once('=') else {
        return Err((
            o.to_string(),
            "an override must look like key.sub=value (e.g. --set solver.cfl=0.15)".into(),
        ));
    };
    let key = key.trim();
    if key.is_empty() || key.split('.').any(str::is_empty) {
        return Err((key.to_string(), "empty parameter name".into()));
    }
    let value: Value = if raw.trim().is_empty() {
        Value::String(String::new())
    } else {
        serde_saphyr::from_str(raw).map_err(|e| {
            (key.to_string(), {
                let why = for_the_user(&e);
                if why.contains("(parameters must be finite numbers)") {
                    format!("value `{raw}`: parameters must be finite numbers")
                } else {
                    format!("value `{raw}` is not valid YAML: {why}")
                }
            })
        })?
    };
    let mut node = params;
    let parts: Vec<&str> = key.split('.').collect();
    for (i, part) in parts.iter().enumerate() {
        let Value::Object(map) = node else {
            return Err((
                key.to_string(),
                format!("`{}` is not a group of parameters", parts[..i].join(".")),
            ));
        };
        if i + 1 == parts.len() {
            map.insert(part.to_string(), value);
            return Ok(());
        }
        node = map
            .entry(part.to_string())
            .or_insert_with(|| Value::Object(Map::new()));
    }
    unreachable!()
}

fn key_err(src: &str, key: &str, message: impl Into<String>) -> ConfigError {
    ConfigError::Key {
        source_name: src.into(),
        key: key.into(),
        message: message.into(),
    }
}

/// Rejects a non-positive period (`key` names the periods) for any DOF whose amplitude is not zero.
fn periods_where_moving(
    src: &str,
    key: &str,
    amplitude: &[f64; 6],
    period: &[f64; 6],
) -> Result<(), ConfigError> {
    match (0..6).find(|&i| amplitude[i] != 0.0 && period[i] <= 0.0) {
        Some(i) => Err(key_err(
            src,
            key,
            format!("element {i} must be positive where the amplitude is not zero"),
        )),
        None => Ok(()),
    }
}

/// Six values per DOF, or none (all zero).
fn six(src: &str, key: &str, v: &[f64]) -> Result<[f64; 6], ConfigError> {
    match v.len() {
        0 => Ok([0.0; 6]),
        6 => {
            if let Some(i) = v.iter().position(|x| !x.is_finite()) {
                return Err(key_err(
                    src,
                    key,
                    format!("element {i} is not a finite number"),
                ));
            }
            Ok([v[0], v[1], v[2], v[3], v[4], v[5]])
        }
        n => Err(key_err(
            src,
            key,
            format!("expected 6 values ({DOF_NAMES}), got {n}"),
        )),
    }
}

impl Loaded {
    /// Where the value of parameter `key` came from, for messages: the override flag (`--set` / `-p`) when
    /// an override set it (or the group it is in, or a parameter inside it), else the file.
    pub fn source_of(&self, key: &str) -> &str {
        let covers = |k: &String| {
            k == key || key.starts_with(&format!("{k}.")) || k.starts_with(&format!("{key}."))
        };
        if self.overridden.iter().any(covers) {
            self.flag
        } else {
            &self.source_name
        }
    }

    /// `e` attributed to the override that set its parameter, if one did ([`Self::source_of`]).
    fn attribute(&self, e: ConfigError) -> ConfigError {
        match e {
            ConfigError::Key {
                source_name,
                key,
                message,
            } if source_name == self.source_name => ConfigError::Key {
                source_name: self.source_of(&key).to_string(),
                key,
                message,
            },
            e => e,
        }
    }

    /// Every parameter as the run uses it, defaults included (`summary.json`'s and the recording's
    /// `effective_parameters`; `parameters` holds only those given): the configuration with `params`'
    /// particle spacing (a node's automatic resolution may have chosen it), the kernel gradient the scheme
    /// takes when none is set, the speed of sound the solver derived when none is set, and the incompressible
    /// solver's relaxation when none is set.
    pub fn effective_parameters(&self, params: &SimParams) -> Value {
        let mut v = serde_json::to_value(&self.config).expect("the configuration serialises");
        v["particle_spacing"] = serde_json::json!(params.particle_spacing);
        v["solver"]["kernel_gradient"] =
            serde_json::to_value(params.solver.kernel_gradient()).expect("serialises");
        v["solver"]["sound_speed"] = serde_json::json!(params.sound_speed());
        v["solver"]["dfsph"]["relaxation"] =
            serde_json::json!(params.solver.dfsph.relaxation(params.gradients_corrected()));
        v
    }

    /// The solver's parameters, checked.
    pub fn sim_params(&self) -> Result<SimParams, ConfigError> {
        self.sim_params_here().map_err(|e| self.attribute(e))
    }

    /// The regular motion's six degrees of freedom, checked.
    pub fn regular(&self) -> Result<[RegularDof; 6], ConfigError> {
        self.regular_here().map_err(|e| self.attribute(e))
    }

    /// The irregular motion's six degrees of freedom, checked.
    pub fn irregular(&self) -> Result<[JonswapDof; 6], ConfigError> {
        self.irregular_here().map_err(|e| self.attribute(e))
    }

    /// The solver's parameters.
    fn sim_params_here(&self) -> Result<SimParams, ConfigError> {
        let c = &self.config;
        let src = self.source_name.as_str();
        let probes: Vec<&str> = c.probes.iter().map(|p| p.name.as_str()).collect();
        let sensors: Vec<&str> = c.pressure_sensors.iter().map(|p| p.name.as_str()).collect();
        for (what, names) in [
            ("probes.names", probes),
            ("pressure_sensors.names", sensors),
        ] {
            for (i, &name) in names.iter().enumerate() {
                if name.is_empty()
                    || name.contains(',')
                    || name.contains('"')
                    || names[..i].contains(&name)
                {
                    return Err(key_err(src, what, format!("`{name}` must be non-empty, unique and free of commas and quotes (it becomes a CSV column)")));
                }
            }
        }
        let p = SimParams {
            dimension: c.dimension,
            tank: c.tank.clone(),
            fill: FillSpec {
                height: c.fill_height,
                length: c.fill_length,
            },
            particle_spacing: c.particle_spacing,
            fluid: c.fluid.clone(),
            gravity: c.gravity,
            solver: c.solver.clone(),
            probes: c.probes.clone(),
            pressure_sensors: c.pressure_sensors.clone(),
            bodies: c.bodies.clone(),
            wave_maker: c.wave_maker.clone(),
            obstacles: c.obstacles.clone(),
        };
        p.validate()
            .map_err(|e| key_err(src, &e.field, e.message))?;
        crate::memory::check(&p).map_err(|m| {
            let auto = if c.realtime.auto_resolution.enabled {
                " (realtime.auto_resolution tries particle_spacing as its finest spacing: it must fit too)"
            } else {
                ""
            };
            key_err(src, "particle_spacing", format!("{m}{auto}"))
        })?;
        if !(c.output_rate_hz.is_finite() && c.output_rate_hz > 0.0) {
            return Err(key_err(
                src,
                "output_rate_hz",
                format!("must be a positive number, got {}", c.output_rate_hz),
            ));
        }
        if !matches!(c.record.compression.as_str(), "zstd" | "none" | "") {
            return Err(key_err(
                src,
                "record.compression",
                format!("`{}` is not one of `zstd`, `none`", c.record.compression),
            ));
        }
        if !(c.duration.is_finite() && c.duration > 0.0) {
            return Err(key_err(
                src,
                "duration",
                format!("must be a positive number of seconds, got {}", c.duration),
            ));
        }
        // The input's plausibility limits: at 0 or below every sample would be refused as a jump.
        for (key, v, unit) in [
            ("input.max_speed", c.input.max_speed, "m/s"),
            (
                "input.max_rotation_rate",
                c.input.max_rotation_rate,
                "rad/s",
            ),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(key_err(
                    src,
                    key,
                    format!("must be a positive speed in {unit} (samples that move faster are refused), got {v}"),
                ));
            }
        }
        if c.particles.decimation == 0 {
            return Err(key_err(
                src,
                "particles.decimation",
                "must be 1 (every particle) or more (every n-th), got 0",
            ));
        }
        if c.record.chunk_size < 4096 {
            return Err(key_err(
                src,
                "record.chunk_size",
                format!(
                    "must be at least 4096 bytes (the MCAP writer's smallest chunk; default 786432), got {}",
                    c.record.chunk_size
                ),
            ));
        }
        if !(c.record.flush_interval_s.is_finite() && c.record.flush_interval_s >= 0.0) {
            return Err(key_err(
                src,
                "record.flush_interval_s",
                format!(
                    "must be zero (write out only full chunks) or a positive number of seconds of log time, got {}",
                    c.record.flush_interval_s
                ),
            ));
        }
        for (key, name) in [
            ("frames.tank", &c.frames.tank),
            ("frames.vessel", &c.frames.vessel),
        ] {
            if name.trim().is_empty() {
                return Err(key_err(
                    src,
                    key,
                    "the frame's name may not be empty (it is the messages' frame_id and a tf frame)",
                ));
            }
        }
        Ok(p)
    }

    /// Regular motion per DOF.
    fn regular_here(&self) -> Result<[RegularDof; 6], ConfigError> {
        let r = &self.config.motion.regular;
        let src = &self.source_name;
        self.synthetic_motion_checks("regular", "amplitude", &r.amplitude)?;
        let a = six(src, "motion.regular.amplitude", &r.amplitude)?;
        let t = six(src, "motion.regular.period", &r.period)?;
        let ph = six(src, "motion.regular.phase", &r.phase)?;
        periods_where_moving(src, "motion.regular.period", &a, &t)?;
        Ok(std::array::from_fn(|i| RegularDof {
            amplitude: a[i],
            period: t[i],
            phase: ph[i],
        }))
    }

    /// Irregular motion per DOF.
    fn irregular_here(&self) -> Result<[JonswapDof; 6], ConfigError> {
        let r = &self.config.motion.irregular;
        let src = &self.source_name;
        self.synthetic_motion_checks(
            "irregular",
            "significant_amplitude",
            &r.significant_amplitude,
        )?;
        let a = six(
            src,
            "motion.irregular.significant_amplitude",
            &r.significant_amplitude,
        )?;
        let t = six(src, "motion.irregular.peak_period", &r.peak_period)?;
        periods_where_moving(src, "motion.irregular.peak_period", &a, &t)?;
        let out = std::array::from_fn(|i| JonswapDof {
            significant_amplitude: a[i],
            peak_period: t[i],
        });
        if !(r.gamma >= 1.0) {
            return Err(key_err(
                src,
                "motion.irregular.gamma",
                format!("must be at least 1, got {}", r.gamma),
            ));
        }
        if r.components == 0 {
            return Err(key_err(
                src,
                "motion.irregular.components",
                "must be at least 1",
            ));
        }
        Ok(out)
    }

    /// What regular and irregular motion share: a ramp of zero or more seconds, and some amplitude (a
    /// synthetic source whose amplitudes are all missing or zero would run a tank at rest, silently).
    fn synthetic_motion_checks(
        &self,
        source: &str,
        amplitude: &str,
        values: &[f64],
    ) -> Result<(), ConfigError> {
        let ramp = self.config.motion.ramp_time;
        if !(ramp.is_finite() && ramp >= 0.0) {
            return Err(key_err(
                self.source_of("motion.ramp_time"),
                "motion.ramp_time",
                format!("must be zero or more seconds, got {ramp}"),
            ));
        }
        if values.iter().all(|v| *v == 0.0) {
            let key = format!("motion.{source}.{amplitude}");
            return Err(key_err(
                self.source_of("motion.source"),
                &key,
                format!(
                    "motion.source is {source}, but every {amplitude} is {}: give six values ({DOF_NAMES}), \
                     or set motion.source: none for a tank at rest",
                    if values.is_empty() { "missing" } else { "0" }
                ),
            ));
        }
        Ok(())
    }

    /// The motion file's path.
    pub fn motion_file(&self) -> Result<PathBuf, ConfigError> {
        let f = &self.config.motion.file;
        if f.is_empty() {
            return Err(key_err(
                self.source_of("motion.file"),
                "motion.file",
                "motion.source is csv: name a CSV file with header time,x,y,z,roll,pitch,yaw",
            ));
        }
        let p = PathBuf::from(f);
        Ok(match (&self.base_dir, p.is_relative()) {
            (Some(b), true) => b.join(p),
            _ => p,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const MIN: &str = "slosh:\n  ros__parameters:\n    dimension: 2\n    tank: {length: 0.8, breadth: 0.25, height: 0.6}\n    fill_height: 0.39\n    particle_spacing: 0.02\n";

    fn err(text: &str, overrides: &[&str]) -> String {
        let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
        match from_str(text, "case.yaml", None, &o).and_then(|l| l.sim_params().map(|_| l)) {
            Ok(_) => panic!("accepted"),
            Err(e) => e.to_string(),
        }
    }

    #[test]
    fn minimal_config_loads_with_defaults() {
        let l = from_str(MIN, "case.yaml", None, &[]).unwrap();
        let p = l.sim_params().unwrap();
        assert_eq!(p.dimension, 2);
        assert_eq!(p.gravity, 9.81);
        assert_eq!(l.config.output_rate_hz, 50.0);
        assert_eq!(l.config.motion.source, MotionSource::None);
    }

    #[test]
    fn wildcard_node_name_is_accepted() {
        let text = MIN.replace("slosh:", "/**:");
        assert!(from_str(&text, "case.yaml", None, &[]).is_ok());
    }

    #[test]
    fn unknown_key_is_named_with_accepted_ones() {
        let e = err(&format!("{MIN}    solver: {{kernal: wendland}}\n"), &[]);
        assert!(
            e.contains("case.yaml: solver.kernal: unknown field `kernal`, expected one of"),
            "{e}"
        );
        assert!(e.contains("`kernel`"), "{e}");
        let e = err(MIN, &["tank.lenght=1.0"]);
        assert!(e.contains("tank.lenght: unknown field `lenght`"), "{e}");
    }

    #[test]
    fn bad_enum_value_lists_the_choices() {
        let e = err(MIN, &["solver.kernel=gauss"]);
        assert!(
            e.contains(
                "solver.kernel: unknown variant `gauss`, expected `cubic_spline` or `wendland`"
            ),
            "{e}"
        );
        let e = err(MIN, &["motion.source=bag"]);
        assert!(e.contains("motion.source") && e.contains("`csv`"), "{e}");
    }

    #[test]
    fn the_kernel_gradient_follows_the_scheme_unless_set() {
        use sph::kernel::KernelGradient::{Exact, ThomasCouchman};
        let gradient = |o: &[&str]| {
            let o: Vec<String> = o.iter().map(|s| s.to_string()).collect();
            let p = from_str(MIN, "case.yaml", None, &o)
                .unwrap()
                .sim_params()
                .unwrap();
            p.solver.kernel_gradient()
        };
        assert_eq!(gradient(&[]), Exact);
        assert_eq!(gradient(&["solver.scheme=dfsph"]), ThomasCouchman);
        assert_eq!(
            gradient(&["solver.scheme=dfsph", "solver.kernel_gradient=exact"]),
            Exact
        );
        assert_eq!(
            gradient(&["solver.kernel_gradient=thomas_couchman"]),
            ThomasCouchman
        );
        let e = err(
            MIN,
            &[
                "solver.kernel=wendland",
                "solver.kernel_gradient=thomas_couchman",
            ],
        );
        assert!(
            e.contains("solver.kernel_gradient: thomas_couchman is for the cubic spline"),
            "{e}"
        );
        let e = err(MIN, &["solver.kernel_gradient=tc"]);
        assert!(e.contains("`exact` or `thomas_couchman`"), "{e}");
    }

    #[test]
    fn overrides_are_parsed_as_yaml() {
        let o = vec![
            "probes.names=[a, b]".to_string(),
            "probes.x=[-0.375,0.0]".to_string(),
            "solver.cfl=0.1".to_string(),
            "dimension=3".into(),
        ];
        let l = from_str(MIN, "case.yaml", None, &o).unwrap();
        let p = l.sim_params().unwrap();
        assert_eq!(p.probes.len(), 2);
        assert_eq!(p.probes[0].x, -0.375);
        assert_eq!(p.solver.cfl, 0.1);
        assert_eq!(p.dimension, 3);
    }

    #[test]
    fn wrong_types_and_values_name_the_key() {
        assert!(err(MIN, &["particle_spacing=fine"]).contains("particle_spacing: invalid type"));
        // serde's type names in a user's words.
        let e = err(MIN, &["realtime.auto_resolution=true"]);
        assert!(
            e.contains("realtime.auto_resolution: a group of parameters, not one value (got boolean `true`)")
                && e.contains("realtime.auto_resolution.MEMBER")
                && !e.contains("AutoResolutionCfg"),
            "{e}"
        );
        let e = err(MIN, &["dimension=3D"]);
        assert!(
            e.contains("expected a whole number") && !e.contains("usize"),
            "{e}"
        );
        let e = err(MIN, &["solver.boundary.layers=-1"]);
        assert!(
            e.contains("solver.boundary.layers") && e.contains("a whole number of zero or more"),
            "{e}"
        );
        // Synthetic motion: a negative ramp, and a source switched on without amplitudes (it ran a tank at
        // rest, silently), named with the option that chose the source.
        let motion_err = |o: &[&str]| {
            let o: Vec<String> = o.iter().map(|s| s.to_string()).collect();
            let l = from_str(MIN, "case.yaml", None, &o).unwrap();
            crate::motion_source::build(&l).err().unwrap().to_string()
        };
        let e = motion_err(&["motion.source=irregular"]);
        assert!(
            e.starts_with("--set: motion.irregular.significant_amplitude: motion.source is irregular, but every significant_amplitude is missing")
                && e.contains("motion.source: none"),
            "{e}"
        );
        let e = motion_err(&[
            "motion.source=regular",
            "motion.regular.amplitude=[0,0,0,0,0,0]",
        ]);
        assert!(e.contains("every amplitude is 0"), "{e}");
        let e = motion_err(&[
            "motion.source=regular",
            "motion.regular={amplitude: [0.01, 0, 0, 0, 0, 0], period: [1, 1, 1, 1, 1, 1], phase: [0, 0, 0, 0, 0, 0]}",
            "motion.ramp_time=-1",
        ]);
        assert!(
            e.starts_with("--set: motion.ramp_time: must be zero or more seconds, got -1"),
            "{e}"
        );
        assert!(
            err(MIN, &["fill_height=0.7"]).contains("fill_height: 0.7 m is above the tank height")
        );
        assert!(err(MIN, &["probes.names=[a]"])
            .contains("probes: probes.names, probes.x and probes.y must have the same length"));
        assert!(
            err(MIN, &["output_rate_hz=0"]).contains("output_rate_hz: must be a positive number")
        );
        assert!(err(MIN, &["tank.length=-1"]).contains("tank.length: must be a positive number"));
        assert!(err(MIN, &["input.max_speed=-1"])
            .contains("--set: input.max_speed: must be a positive speed in m/s"));
        assert!(
            err(MIN, &["input.max_rotation_rate=0"]).contains("input.max_rotation_rate: must be")
        );
        assert!(err(MIN, &["particles.decimation=0"]).contains("particles.decimation: must be 1"));
        assert!(
            err(MIN, &["record.chunk_size=0"]).contains("record.chunk_size: must be at least 4096")
        );
        assert!(err(MIN, &["record.flush_interval_s=-1"]).contains(
            "record.flush_interval_s: must be zero (write out only full chunks) or a positive"
        ));
        assert!(err(MIN, &["record.flush_interval_s=.nan"]).contains("record.flush_interval_s"));
        assert!(err(MIN, &["frames.tank=''"])
            .contains("frames.tank: the frame's name may not be empty"));
        assert!(err(MIN, &["record.compression=lz4"])
            .contains("--set: record.compression: `lz4` is not one of `zstd`, `none`"));
        // A spacing typed 1000× too fine: refused before anything is allocated.
        let e = err(MIN, &["particle_spacing=1e-5"]);
        assert!(
            e.contains("--set: particle_spacing: 0.00001 m makes about")
                && e.contains("use a spacing of at least"),
            "{e}"
        );
        // With auto resolution the requested spacing is the finest tried: said so.
        let e = err(
            MIN,
            &[
                "particle_spacing=2e-5",
                "realtime.auto_resolution.enabled=true",
            ],
        );
        assert!(
            e.contains("makes about")
                && e.contains("realtime.auto_resolution tries particle_spacing"),
            "{e}"
        );
        assert!(err(MIN, &["solver"]).contains("an override must look like key.sub=value"));
        assert!(err("slosh: {}\n", &[]).contains("missing `ros__parameters:`"));
        assert!(
            err("a: {ros__parameters: {}}\nb: {ros__parameters: {}}\n", &[])
                .contains("several node sections (/a, /b) and none for /slosh")
        );
        assert!(
            err("slosh:\n  ros__parameters:\n    dimension: [\n", &[]).contains("not valid YAML")
        );
        let e = err(MIN, &["solver.cfl=.nan"]);
        assert!(
            e.contains("solver.cfl: value `.nan`: parameters must be finite numbers")
                && !e.contains("policy")
                && !e.contains("not valid YAML"),
            "{e}"
        );
        let e = err(&format!("{MIN}    dimension: 3\n"), &[]);
        assert!(
            e.contains("duplicate mapping key: dimension (each parameter may be given once")
                && !e.contains("DuplicateKeyPolicy"),
            "{e}"
        );
    }

    #[test]
    fn a_motion_file_given_on_the_command_line_is_relative_to_the_current_folder() {
        let dir = std::env::temp_dir().join(format!("slosh-config-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = dir.join("case.yaml");
        std::fs::write(
            &file,
            format!("{MIN}    motion: {{source: csv, file: m.csv}}\n"),
        )
        .unwrap();
        let cfg = file.display().to_string();
        let l = load(&cfg, &[]).unwrap();
        assert_eq!(l.motion_file().unwrap(), dir.join("m.csv"));
        let l = load(&cfg, &["motion.file=data/my motion.csv".into()]).unwrap();
        let here = std::env::current_dir().unwrap();
        assert_eq!(l.motion_file().unwrap(), here.join("data/my motion.csv"));
        let l = load(&cfg, &["motion.file=/abs/m.csv".into()]).unwrap();
        assert_eq!(l.motion_file().unwrap(), PathBuf::from("/abs/m.csv"));
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn a_node_reads_the_sections_for_its_name_from_every_file_in_order() {
        let dir = std::env::temp_dir().join(format!("slosh-config-node-{}", std::process::id()));
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        let every = MIN.replace("slosh:", "/**:");
        let a = dir.join("a.yaml");
        std::fs::write(
            &a,
            format!(
                "{every}    motion: {{source: csv, file: m.csv}}\n\
                 other_node:\n  ros__parameters:\n    dimension: 3\n\
                 /ship1/tank2:\n  ros__parameters:\n    fill_height: 0.2\n    solver: {{cfl: 0.1}}\n"
            ),
        )
        .unwrap();
        let b = dir.join("sub/b.yaml");
        std::fs::write(
            &b,
            "ship1:\n  '*':\n    ros__parameters:\n      solver.cfl: 0.15\n      motion: {source: csv, file: n.csv}\n",
        )
        .unwrap();
        let files = [a.display().to_string(), b.display().to_string()];
        let l = load_node(&files, "/ship1/tank2", &[]).unwrap();
        let p = l.sim_params().unwrap();
        // The other node's 3D is not applied; this node's fill height is; the second file's cfl overrides the
        // first's, and the first file's section's other parameters stay.
        assert_eq!(
            (p.dimension, l.config.fill_height, p.solver.cfl),
            (2, 0.2, 0.15)
        );
        assert_eq!(l.motion_file().unwrap(), dir.join("sub/n.csv"));
        assert_eq!(l.sections.len(), 3, "{:?}", l.sections);
        // Another node in the same launch gets the common section only.
        let l = load_node(&files, "/ship2/tank2", &[]).unwrap();
        let p = l.sim_params().unwrap();
        assert_eq!((p.dimension, l.config.fill_height), (2, 0.39));
        assert_eq!(l.motion_file().unwrap(), dir.join("m.csv"));
        // No section for the node: named, with the fix.
        let only = dir.join("c.yaml");
        std::fs::write(&only, MIN.replace("slosh:", "controller:")).unwrap();
        let e = load_node(&[only.display().to_string()], "/slosh", &[])
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("no parameters for this node: it is /slosh, the file's sections are for /controller")
                && e.contains("name it `/slosh:`, or `/**:`"),
            "{e}"
        );
        // `slosh run` reads a single section whatever its name.
        assert!(load(&only.display().to_string(), &[]).is_ok());
        let _ = std::fs::remove_dir_all(&dir);
    }

    #[test]
    fn an_override_s_errors_name_the_override_not_the_file() {
        let files = [String::from("seed_tank_039")];
        let e = |o: &str| {
            load_node(&files, "/slosh", &[o.to_string()])
                .unwrap_err()
                .to_string()
        };
        let m = e("solver.cfll=0.1");
        assert!(m.starts_with("-p: solver.cfll: unknown field"), "{m}");
        let m = e("solver.cfl=[1");
        assert!(
            m.starts_with("-p: solver.cfl: value `[1` is not valid YAML"),
            "{m}"
        );
        let m = e("solver=3");
        assert!(m.starts_with("-p: solver: "), "{m}");
        // Range checks too.
        let checked = |o: &str| {
            load_node(&files, "/slosh", &[o.to_string()])
                .unwrap()
                .sim_params()
                .unwrap_err()
                .to_string()
        };
        let m = checked("solver.cfl=5");
        assert!(
            m.starts_with("-p: solver.cfl: must be within (0, 1]"),
            "{m}"
        );
        let m = checked("solver={cfl: 5}");
        assert!(
            m.starts_with("-p: solver.cfl: must be within (0, 1]"),
            "{m}"
        );
        // The dfsph settings are checked with wcsph too (the default scheme here).
        let m = checked("solver.dfsph.relaxation=1.5");
        assert!(
            m.starts_with("-p: solver.dfsph.relaxation: must be in (0, 1]"),
            "{m}"
        );
        // A parameter the override did not set stays the file's.
        let m = err(MIN, &["output_rate_hz=20", "fill_height=0.7"]);
        assert!(m.starts_with("--set: fill_height"), "{m}");
        let m = err(&MIN.replace("0.39", "0.7"), &["output_rate_hz=20"]);
        assert!(m.starts_with("case.yaml: fill_height"), "{m}");
        let m = load("seed_tank_039", &["dimension=two".into()])
            .unwrap_err()
            .to_string();
        assert!(m.starts_with("--set: dimension: "), "{m}");
    }

    #[test]
    fn dotted_names_in_a_parameter_file_are_groups() {
        let text = "slosh:\n  ros__parameters:\n    dimension: 2\n    tank.length: 0.8\n    tank: {breadth: 0.25, height: 0.6}\n    fill_height: 0.39\n    particle_spacing: 0.02\n    solver.dfsph.cfl: 0.3\n";
        let l = from_str(text, "case.yaml", None, &[]).unwrap();
        let p = l.sim_params().unwrap();
        assert_eq!((p.tank.length, p.tank.breadth), (0.8, 0.25));
        assert_eq!(p.solver.dfsph.cfl, 0.3);
        let twice = text.replace("{breadth: 0.25", "{length: 0.7, breadth: 0.25");
        let e = err(&twice, &[]);
        assert!(e.contains("tank.length: given twice"), "{e}");
        let e = err(&text.replace("solver.dfsph.cfl", "solver.dfsph.cfll"), &[]);
        assert!(e.contains("solver.dfsph.cfll: unknown field"), "{e}");
    }

    #[test]
    fn use_sim_time_follows_the_clock() {
        let mode = |o: &[&str]| {
            let o: Vec<String> = o.iter().map(|s| s.to_string()).collect();
            from_str(MIN, "case.yaml", None, &o)
                .unwrap()
                .config
                .realtime
                .mode
        };
        assert_eq!(mode(&[]), RealtimeMode::Realtime);
        assert_eq!(mode(&["use_sim_time=true"]), RealtimeMode::FollowClock);
        assert_eq!(mode(&["use_sim_time=false"]), RealtimeMode::Realtime);
        let lockstep = ["use_sim_time=true", "realtime.mode=lockstep"];
        assert_eq!(mode(&lockstep), RealtimeMode::Lockstep);
    }

    #[test]
    fn motion_arrays_need_six_values() {
        let l = from_str(
            MIN,
            "case.yaml",
            None,
            &["motion.regular.amplitude=[0.1, 0.2]".into()],
        )
        .unwrap();
        let e = l.regular().unwrap_err().to_string();
        assert!(
            e.contains(
                "motion.regular.amplitude: expected 6 values (x, y, z, roll, pitch, yaw), got 2"
            ),
            "{e}"
        );
    }

    #[test]
    fn obstacles_are_read_by_name_and_a_bad_one_is_named() {
        let l = load("kleefsman2005_dambreak", &[]).unwrap();
        let p = l.sim_params().unwrap();
        assert_eq!(p.obstacles.len(), 1);
        assert_eq!(p.obstacles[0].name, "box");
        assert_eq!(p.obstacles[0].size, [0.161, 0.403, 0.161]);
        let l = load(
            "kleefsman2005_dambreak",
            &["obstacles.box.size=[0.01, 0.403, 0.161]".into()],
        )
        .unwrap();
        let e = l.sim_params().unwrap_err().to_string();
        assert!(
            e.contains("obstacles.box.size") && e.contains("thinner than the kernel support"),
            "{e}"
        );
    }

    #[test]
    fn builtin_cases_all_load() {
        for (name, _) in BUILTIN {
            let l = load(name, &[]).unwrap_or_else(|e| panic!("{name}: {e}"));
            l.sim_params().unwrap_or_else(|e| panic!("{name}: {e}"));
        }
    }
}
