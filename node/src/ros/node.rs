//! `slosh node`: the solver as a ROS 2 node. Vessel motion in (Odometry or PoseStamped), the liquid's wrench,
//! probe elevations, wall pressures and diagnostics out, stamped with the simulation time of the state they
//! describe (the input's time base: output stamp = first input stamp + simulation time).

use super::args::{Names, RosArgs};
use super::pacing::Pacing;
use super::parameters::{LiveSettings, ParameterServers, Parameters};
use super::publish;
use crate::config::{InputType, Loaded, RealtimeMode, StampSource, DEFAULT_NAME};
use crate::input::frames::Frames;
use crate::input::gravity_check::{GravityCheck, InputKind};
use crate::input::live::{Live, Reading};
use crate::input::live_motion::Limits;
use crate::messages::{body_topic, header, output_messages, static_transforms};
use crate::record::{RawMessage, Recorder};
use nalgebra::UnitQuaternion;
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{NodeName, NodeOptions, Publisher, QosProfile, ServiceMapping, ServiceTypeName};
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::diagnostic_msgs::{DiagnosticArray, DiagnosticStatus, KeyValue};
use slosh_msgs::geometry_msgs::{AccelStamped, PoseStamped, WrenchStamped};
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::rosgraph_msgs::Clock;
use slosh_msgs::sensor_msgs::{Imu, PointCloud2};
use slosh_msgs::slosh_msgs::{PressureArray, ProbeArray};
use slosh_msgs::std_srvs::{SetBoolRequest, SetBoolResponse, TriggerRequest, TriggerResponse};
use slosh_msgs::tf2_msgs::TFMessage;
use sph::motion::TankMotion as _;
use std::collections::VecDeque;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// Samples in a row on a new time base after which the node follows it (see the input loop).
const NEW_TIME_BASE: usize = 10;

/// A warning repeated while a condition lasts (silence would look like a hang): first `first` s after the
/// condition was first seen, then every 10 s.
#[derive(Debug, Default)]
struct Reminder {
    since: Option<f64>,
    last: Option<f64>,
}

impl Reminder {
    /// Whether to warn now (wall time `now`, s), the condition holding.
    fn due(&mut self, now: f64, first: f64) -> bool {
        let since = *self.since.get_or_insert(now);
        let due = match self.last {
            None => now - since >= first,
            Some(last) => now - last >= 10.0,
        };
        if due {
            self.last = Some(now);
        }
        due
    }
}

/// Options of `slosh node` besides the parameters.
#[derive(Debug, Clone, Default)]
pub struct NodeOptionsCli {
    /// Stop after this many simulated seconds (None: run until SIGINT/SIGTERM).
    pub duration: Option<f64>,
}

/// Loads the parameters the ROS way ([`crate::config::load_node`]): every `--params-file` in order, the
/// sections of each that apply to this node (after `-r __ns:=` / `__node:=`), then `-p name:=value`.
/// Without a parameters file, the `fallback` file or built-in case, read the same way.
pub fn load_parameters(ros: &RosArgs, fallback: Option<&str>) -> anyhow::Result<Loaded> {
    let files = match (ros.params_files.is_empty(), fallback) {
        (false, _) => ros.params_files.clone(),
        (true, Some(f)) => vec![f.to_string()],
        (true, None) => anyhow::bail!(
            "no parameters: pass --ros-args --params-file launch-configs/<case>.yaml (or a built-in case name)"
        ),
    };
    let fqn = Names::new(ros, DEFAULT_NAME)?.node_fqn();
    Ok(crate::config::load_node(&files, &fqn, &ros.params)?)
}

fn qos_outputs() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Wait(Duration::from_millis(50)))
        .durability(Durability::Volatile)
        .history(History::KeepLast { depth: 10 })
}

fn qos_input() -> QosProfile {
    QosProfile::subscription_default().history(History::KeepLast { depth: 5 })
}

fn qos_latched() -> QosProfile {
    QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Wait(Duration::from_millis(50)))
        .durability(Durability::TransientLocal)
        .history(History::KeepLast { depth: 1 })
}

/// Counters reported in diagnostics.
#[derive(Debug, Default, Clone)]
struct Counters {
    accepted: u64,
    rejected: u64,
    last_reject: String,
    /// Motion samples rejected since the last accepted one.
    rejected_in_a_row: u64,
    published: u64,
    timeouts: u64,
    /// How the particle spacing was chosen (`realtime.auto_resolution`).
    resolution: String,
    /// The frame conventions' plausibility check: empty until it has decided, `ok`, or its warning.
    input_check: String,
    /// Motion samples of the last [`RECENT_S`] (wall time taken, accepted).
    recent: std::collections::VecDeque<(f64, bool)>,
}

/// Why the node holds the last pose, `age` s after the last accepted motion sample: no input, or only
/// rejected samples (how many, and the last reason).
fn no_input(counters: &Counters, age: f64, timeout: f64) -> String {
    match counters.rejected_in_a_row {
        0 => format!("no motion input for {age:.2} s (motion_timeout_s = {timeout})"),
        n => format!(
            "no usable motion input for {age:.2} s (motion_timeout_s = {timeout}): the {n} samples since the last accepted one were rejected (last: {}); a newer sample that does not continue the held pose is then followed afresh",
            counters.last_reject
        ),
    }
}

/// While the simulation is still behind the last accepted sample (`last_real`, simulation time), it
/// runs on the motion received; the last pose is held only from there.
fn buffered(last_real: f64, sim_time: f64) -> String {
    if sim_time < last_real {
        format!(" from t = {last_real:.3} s (the simulation, at {sim_time:.3} s, still runs on the motion received up to then)")
    } else {
        String::new()
    }
}

/// The window over which a node that rejects most of its motion samples says so, s.
const RECENT_S: f64 = 2.0;

impl Counters {
    /// Notes a motion sample taken at wall time `w`, accepted or not.
    fn note_motion(&mut self, w: f64, accepted: bool) {
        self.recent.push_back((w, accepted));
        while self.recent.front().is_some_and(|(t, _)| *t < w - RECENT_S) {
            self.recent.pop_front();
        }
    }

    /// The diagnostics' state when most of the last [`RECENT_S`]' motion samples (at least five) were
    /// rejected: the tank then follows the few accepted ones, which a consumer must not take for running.
    fn mostly_rejected(&self, now: f64) -> Option<String> {
        let recent = self.recent.iter().filter(|(t, _)| *t >= now - RECENT_S);
        let (n, bad) = recent.fold((0, 0), |(n, b), (_, ok)| (n + 1, b + usize::from(!ok)));
        (n >= 5 && 2 * bad > n).then(|| {
            format!(
                "running, but {bad} of the last {n} motion samples were rejected (last: {})",
                self.last_reject
            )
        })
    }
}

enum Input {
    Odom(ros2_client::Subscription<Odometry>),
    Pose(ros2_client::Subscription<PoseStamped>),
    Imu(ros2_client::Subscription<Imu>),
    /// iceoryx2 `NAME/motion`, recorded as Odometry on `motion/odom` and AccelStamped on (the resolved)
    /// `.1`, with the vessel frame `.2`.
    Iox(
        iceoryx2::port::subscriber::Subscriber<
            iceoryx2::prelude::ipc::Service,
            crate::iox::MotionSample,
            (),
        >,
        String,
        String,
    ),
}

impl Input {
    /// The topic, before resolution.
    fn topic(kind: InputType) -> &'static str {
        match kind {
            InputType::Odom => "motion/odom",
            InputType::Pose => "motion/pose",
            InputType::Imu => "motion/imu",
            // Recorded there, as the Odometry it would be on DDS.
            InputType::Iceoryx2 => "motion/odom",
        }
    }

    /// The ROS type taken (iceoryx2: what it is recorded as).
    fn type_name(kind: InputType) -> &'static str {
        match kind {
            InputType::Odom | InputType::Iceoryx2 => "nav_msgs/msg/Odometry",
            InputType::Pose => "geometry_msgs/msg/PoseStamped",
            InputType::Imu => "sensor_msgs/msg/Imu",
        }
    }

    /// The next received sample: (header stamp, reading, the messages to record, serialized for the topic
    /// `rec` when given), or why a message received could not be decoded (DDS delivers a publisher of another
    /// type on the same topic name). The node records samples once it has taken or refused them.
    fn take(&self, rec: Option<&str>) -> anyhow::Result<Option<Result<Taken, String>>> {
        match self.take_decoded(rec) {
            Ok(t) => Ok(t.map(Ok)),
            Err(e) => match e.downcast::<ros2_client::ReadError>() {
                Ok(ros2_client::ReadError::Deserialization { reason }) => Ok(Some(Err(reason))),
                Ok(other) => Err(anyhow::anyhow!("reading the motion input: {other:?}")),
                Err(e) => Err(e),
            },
        }
    }

    fn take_decoded(&self, rec: Option<&str>) -> anyhow::Result<Option<Taken>> {
        let err = |_what: &str, e: ros2_client::ReadError| anyhow::Error::from(e);
        fn keep<M: slosh_msgs::RosMessage>(rec: Option<&str>, m: &M) -> Vec<RawMessage> {
            rec.map(|topic| vec![RawMessage::of(topic, m)])
                .unwrap_or_default()
        }
        Ok(match self {
            Input::Odom(s) => match s.take().map_err(|e| err("motion/odom", e))? {
                Some((m, _)) => Some((m.header.stamp, keep(rec, &m), Reading::Pose(m.pose.pose))),
                None => None,
            },
            Input::Pose(s) => match s.take().map_err(|e| err("motion/pose", e))? {
                Some((m, _)) => Some((m.header.stamp, keep(rec, &m), Reading::Pose(m.pose))),
                None => None,
            },
            Input::Imu(s) => match s.take().map_err(|e| err("motion/imu", e))? {
                Some((m, _)) => {
                    let raw = keep(rec, &m);
                    Some((m.header.stamp, raw, Reading::Imu(Box::new(m))))
                }
                None => None,
            },
            Input::Iox(sub, accel_topic, vessel) => match sub
                .receive()
                .map_err(|e| anyhow::anyhow!("reading the iceoryx2 motion: {e}"))?
            {
                Some(sample) => {
                    let m: crate::iox::MotionSample = *sample.payload();
                    let stamp = Time::from_secs_f64(m.time);
                    let mut raw = Vec::new();
                    if let Some(topic) = rec {
                        let identity = crate::iox::Mount {
                            offset: Default::default(),
                            rotation: UnitQuaternion::identity(),
                        };
                        let v = crate::iox::tank_state(&m, &identity);
                        raw.push(RawMessage::of(
                            topic,
                            &crate::messages::motion::odometry(&v, stamp, "odom", vessel),
                        ));
                        raw.push(RawMessage::of(
                            accel_topic,
                            &crate::messages::motion::accel(&v, stamp, vessel),
                        ));
                    }
                    Some((stamp, raw, Reading::State(m)))
                }
                None => None,
            },
        })
    }
}

/// (DDS topic name, DDS type name) of every publisher the graph shows.
fn writers_on_graph(context: &ros2_client::Context) -> Vec<(String, String)> {
    context
        .domain_participant()
        .discovered_writers()
        .into_iter()
        .map(|w| {
            (
                w.publication_topic_data.topic_name,
                w.publication_topic_data.type_name,
            )
        })
        .collect()
}

/// A received sample: its header stamp, its messages for the recording, the reading.
type Taken = (Time, Vec<RawMessage>, Reading);

/// A sample the input loop decides on.
struct Sample {
    /// Its time on the input's time base (s): the header stamp, or when it was taken (`input.stamp`).
    ts: f64,
    /// The same, as the log time it is recorded at once taken.
    log: Time,
    reading: Reading,
    /// When it was taken from the reader (the node's wall clock, s).
    received: f64,
    /// Its messages for the recording (none when not recording).
    raw: Vec<RawMessage>,
}

impl Sample {
    /// Records a refused sample at the recording's latest log time.
    fn record_refused(&self, r: &mut Recorder) -> Result<(), crate::record::RecordError> {
        for m in &self.raw {
            r.write_message_now(m, self.log)?;
        }
        Ok(())
    }
}

/// Runs the node until SIGINT/SIGTERM (or `duration` simulated seconds).
pub fn run(
    ros: &RosArgs,
    fallback_params: Option<&str>,
    opts: &NodeOptionsCli,
) -> anyhow::Result<()> {
    let cfg = load_parameters(ros, fallback_params)?;
    let mut params = cfg.sim_params()?;
    let names = Names::new(ros, DEFAULT_NAME)?;
    let c = &cfg.config;
    if !(c.motion_timeout_s.is_finite() && c.motion_timeout_s > 0.0) {
        anyhow::bail!(
            "{}: motion_timeout_s: must be a positive number of seconds, got {}",
            cfg.source_of("motion_timeout_s"),
            c.motion_timeout_s
        );
    }
    if !(c.input.max_gap_s.is_finite() && c.input.max_gap_s > 0.0) {
        anyhow::bail!(
            "{}: input.max_gap_s: must be a positive number of seconds, got {}",
            cfg.source_of("input.max_gap_s"),
            c.input.max_gap_s
        );
    }
    if !(c.diagnostics_rate_hz.is_finite() && c.diagnostics_rate_hz > 0.0) {
        anyhow::bail!(
            "{}: diagnostics_rate_hz: must be a positive number of messages per second, got {}",
            cfg.source_of("diagnostics_rate_hz"),
            c.diagnostics_rate_hz
        );
    }
    if !(c.particles.rate_hz.is_finite() && c.particles.rate_hz >= 0.0) {
        anyhow::bail!(
            "{}: particles.rate_hz: must be zero (off) or a positive number of clouds per simulated second, got {}",
            cfg.source_of("particles.rate_hz"),
            c.particles.rate_hz
        );
    }
    // Before the resolution trials, so that a signal during them stops the node cleanly too.
    let stop = crate::signals::shutdown_flag()?;
    let auto = &c.realtime.auto_resolution;
    let mut recorded_parameters = cfg.parameters.clone();
    let mut choice_record = None;
    let resolution = if auto.enabled && c.realtime.mode == RealtimeMode::Realtime {
        auto.check(&cfg)?;
        if c.solver.scheme == sph::params::Scheme::Wcsph {
            eprintln!(
                "[{}] realtime.auto_resolution with solver.scheme: wcsph: the weakly-compressible scheme's steps follow the speed of sound, so only very coarse spacings keep real time; solver.scheme: dfsph is the scheme for real time",
                names.node
            );
        }
        eprintln!(
            "[{}] realtime.auto_resolution: timing {} s trials of {} (target real-time factor {}) ...",
            names.node, auto.trial_s, cfg.source_name, auto.target_factor
        );
        let Some(choice) = crate::resolution::choose(&cfg, auto, &stop)? else {
            eprintln!(
                "[{}] interrupted during the resolution trials: stopping (nothing was published or recorded)",
                names.node
            );
            return Ok(());
        };
        if let Some((dp, why)) = choice.skipped.last() {
            eprintln!(
                "[{}] realtime.auto_resolution: spacings of {dp:.4} m and coarser left out: {why}",
                names.node
            );
        }
        if let Some(why) = &choice.held_by_accuracy {
            eprintln!("[{}] realtime.auto_resolution: {why}", names.node);
        }
        if let Some(w) = &choice.accuracy_warning {
            eprintln!("[{}] warning: realtime.auto_resolution: {w}", names.node);
        }
        params.particle_spacing = choice.particle_spacing;
        // The recording documents the spacing run, and how it was chosen.
        recorded_parameters["particle_spacing"] = serde_json::json!(choice.particle_spacing);
        choice_record = Some(serde_json::json!({
            "requested_particle_spacing": c.particle_spacing,
            "chosen": choice,
        }));
        choice.describe()
    } else if auto.enabled {
        "off (only in realtime mode)".to_string()
    } else {
        "off".to_string()
    };
    let context = super::context()?;
    let mut node = context
        .new_node(
            NodeName::new(&names.namespace, &names.node).map_err(|e| {
                anyhow::anyhow!("node name {}/{}: {e:?}", names.namespace, names.node)
            })?,
            NodeOptions::new().enable_rosout(true),
        )
        .map_err(|e| anyhow::anyhow!("cannot create the node: {e:?}"))?;

    let topic = Input::topic(c.input.kind);
    let iox = &c.iceoryx2;
    let iox_on = c.input.kind == InputType::Iceoryx2 || iox.outputs || iox.particles;
    if c.input.kind == InputType::Iceoryx2
        && (c.input.world_frame != crate::config::WorldFrame::Enu
            || c.input.body_frame != crate::config::BodyFrame::Flu)
    {
        anyhow::bail!(
            "{}: input.world_frame / input.body_frame: iceoryx2 motion samples are always in a z-up world and the FLU vessel frame; leave both at enu / flu",
            cfg.source_of("input.world_frame")
        );
    }
    if iox_on {
        crate::iox::check_sensors(
            &cfg.source_name,
            params.probes.len(),
            params.pressure_sensors.len(),
        )?;
    }
    if !(iox.dds_outputs || iox.outputs || iox.particles) {
        anyhow::bail!(
            "{}: iceoryx2.dds_outputs: false publishes nothing; set iceoryx2.outputs: true (and iceoryx2.particles) or leave dds_outputs true",
            cfg.source_of("iceoryx2.dds_outputs")
        );
    }
    let iox_node = if iox_on {
        Some(
            crate::iox::node(&format!("slosh_{}", names.node))
                .map_err(|e| anyhow::anyhow!("iceoryx2 (service {:?}): {e}", iox.service))?,
        )
    } else {
        None
    };
    let input = match c.input.kind {
        InputType::Iceoryx2 => Input::Iox(
            crate::iox::motion_subscriber(iox_node.as_ref().expect("created above"), &iox.service)?,
            names.resolve("motion/accel")?,
            c.frames.vessel.clone(),
        ),
        InputType::Imu => Input::Imu(super::subscription(&mut node, &names, topic, &qos_input())?),
        InputType::Odom => {
            Input::Odom(super::subscription(&mut node, &names, topic, &qos_input())?)
        }
        InputType::Pose => {
            Input::Pose(super::subscription(&mut node, &names, topic, &qos_input())?)
        }
    };
    let sub_accel: Option<ros2_client::Subscription<AccelStamped>> =
        if c.input.accel && c.input.kind != InputType::Imu {
            Some(super::subscription(
                &mut node,
                &names,
                "motion/accel",
                &qos_input(),
            )?)
        } else {
            None
        };
    let out_qos = qos_outputs();
    // (wrench, probes, pressures) over DDS unless iceoryx2 alone carries them.
    let pub_outputs: Option<(
        Publisher<WrenchStamped>,
        Publisher<ProbeArray>,
        Publisher<PressureArray>,
    )> = if iox.dds_outputs {
        Some((
            super::publisher(&mut node, &names, "wrench", &out_qos)?,
            super::publisher(&mut node, &names, "probes", &out_qos)?,
            super::publisher(&mut node, &names, "pressures", &out_qos)?,
        ))
    } else {
        None
    };
    // Each floating body's motion and the liquid's force on it.
    let mut pub_bodies: Vec<(Publisher<Odometry>, Publisher<WrenchStamped>)> = Vec::new();
    if iox.dds_outputs {
        for name in params.body_names() {
            pub_bodies.push((
                super::publisher(&mut node, &names, &body_topic(&name, "odom"), &out_qos)?,
                super::publisher(&mut node, &names, &body_topic(&name, "wrench"), &out_qos)?,
            ));
        }
    }
    let pub_diag: Publisher<DiagnosticArray> =
        super::publisher(&mut node, &names, "/diagnostics", &out_qos)?;
    let pub_tf: Publisher<TFMessage> =
        super::publisher(&mut node, &names, "/tf_static", &qos_latched())?;
    let pub_clock: Option<Publisher<Clock>> = match c.realtime.mode {
        RealtimeMode::Lockstep => Some(super::publisher(&mut node, &names, "/clock", &out_qos)?),
        _ => None,
    };
    if iox.particles && c.particles.rate_hz <= 0.0 {
        anyhow::bail!(
            "{}: iceoryx2.particles: set particles.rate_hz (frames per simulated second) above 0",
            cfg.source_of("iceoryx2.particles")
        );
    }
    let pub_cloud: Option<Publisher<PointCloud2>> = if c.particles.rate_hz > 0.0 && iox.dds_outputs
    {
        let qos = QosProfile::publisher_default()
            .reliability_reliable(WhenFull::Wait(Duration::from_millis(20)))
            .history(History::KeepLast { depth: 1 });
        Some(super::publisher(&mut node, &names, "particles", &qos)?)
    } else {
        None
    };
    let mut next_cloud = 0u64;
    // follow_clock: ROS time from /clock (best effort keep last 1, as rclcpp's ClockQoS; reliable
    // publishers connect too).
    let sub_clock: Option<ros2_client::Subscription<Clock>> = match c.realtime.mode {
        RealtimeMode::FollowClock => Some(super::subscription(
            &mut node,
            &names,
            "/clock",
            &QosProfile::subscription_default().history(History::KeepLast { depth: 1 }),
        )?),
        _ => None,
    };
    let mut ros_time: Option<f64> = None;

    let srv_qos = QosProfile::publisher_default().history(History::KeepLast { depth: 10 });
    let mapping = match c.service_mapping {
        crate::config::ServiceMappingCfg::Enhanced => ServiceMapping::Enhanced,
        crate::config::ServiceMappingCfg::Cyclone => ServiceMapping::Cyclone,
        crate::config::ServiceMappingCfg::Basic => ServiceMapping::Basic,
    };
    let srv_reset = node
        .create_server::<TriggerRequest, TriggerResponse>(
            mapping,
            &super::ros_name(&names, "~/reset")?,
            &ServiceTypeName::new("std_srvs", "Trigger"),
            srv_qos.clone(),
            srv_qos.clone(),
        )
        .map_err(|e| anyhow::anyhow!("service ~/reset: {e:?}"))?;
    let srv_pause = node
        .create_server::<SetBoolRequest, SetBoolResponse>(
            mapping,
            &super::ros_name(&names, "~/pause")?,
            &ServiceTypeName::new("std_srvs", "SetBool"),
            srv_qos.clone(),
            srv_qos.clone(),
        )
        .map_err(|e| anyhow::anyhow!("service ~/pause: {e:?}"))?;
    // Every parameter as the node runs with it: the parameter services' table and the recording's metadata.
    let effective = cfg.effective_parameters(&params);
    let mut param_srv = ParameterServers::new(&mut node, &names, mapping, &srv_qos)?;
    let mut param_table = Parameters::new(
        &effective,
        c.realtime.mode == RealtimeMode::FollowClock,
        c.particles.rate_hz > 0.0,
    );

    let frames = Frames::new(c.input.world_frame, c.input.body_frame, c.frames.tank_pose);
    let imu = c.input.kind == InputType::Imu;
    let limits = Limits {
        max_speed: c.input.max_speed,
        max_rotation_rate: c.input.max_rotation_rate,
    };
    let fresh_motion = || {
        if c.input.kind == InputType::Iceoryx2 {
            Live::states(limits, &frames)
        } else {
            Live::new(imu, limits, &frames, params.gravity)
        }
    };
    let mut motion = fresh_motion();
    let mut sim = sph::build(params.clone())?;
    let mut iox_ports = match &iox_node {
        Some(n) if iox.outputs || iox.particles => Some(crate::iox::OutputPorts::new(
            n,
            &iox.service,
            iox.particles
                .then_some(sim.counts().fluid + sim.counts().boundary),
        )?),
        _ => None,
    };
    let mut steps_at_output = 0u64;
    let in_topic = names.resolve(topic)?;
    let out_topics = [
        names.resolve("wrench")?,
        names.resolve("probes")?,
        names.resolve("pressures")?,
    ];
    let diag_topic = names.resolve("/diagnostics")?;
    let tf_topic = names.resolve("/tf_static")?;
    let cloud_topic = names.resolve("particles")?;
    let mut recorder = if c.record.path.is_empty() {
        None
    } else {
        let mut meta = crate::record::parameters_metadata(&recorded_parameters, &effective);
        if let Some(v) = &choice_record {
            meta.insert("auto_resolution".into(), v.to_string());
        }
        Some(Recorder::create_with_metadata(&c.record, meta)?)
    };
    let counts = sim.counts();
    let full_name = names.node_fqn();
    let log = |level: ros2_client::ros2::LogLevel, msg: &str| {
        eprintln!("[{full_name}] {msg}");
        ros2_client::rosout!(node, level, "{}", msg);
    };
    log(
        ros2_client::ros2::LogLevel::Info,
        &format!(
            "parameters {}: {}D tank {} x {} x {} m, {} liquid + {} wall particles (dp {} m, auto resolution: {}), {:?} mode; waiting for motion on {}",
            cfg.sections.join(", "),
            params.dimension,
            params.tank.length,
            params.tank.breadth,
            params.tank.height,
            counts.fluid,
            counts.boundary,
            params.particle_spacing,
            resolution,
            c.realtime.mode,
            if c.input.kind == InputType::Iceoryx2 {
                format!("iceoryx2 service {}/motion", iox.service)
            } else {
                in_topic.clone()
            }
        ),
    );

    let start = Instant::now();
    let wall = || start.elapsed().as_secs_f64();
    let mut pacing = Pacing::new(0.25);
    let mut counters = Counters {
        resolution,
        ..Default::default()
    };
    let mut t0: Option<f64> = None;
    // What a parameter set changes while the node runs.
    let mut live = LiveSettings {
        output_rate_hz: c.output_rate_hz,
        diagnostics_rate_hz: c.diagnostics_rate_hz,
        particles_rate_hz: c.particles.rate_hz,
        particles_decimation: c.particles.decimation,
        motion_timeout_s: c.motion_timeout_s,
    };
    // Outputs at k / rate (the steps land on them), the first the state at t = 0 before any step.
    let mut next_output = 0u64;
    let mut last_diag = DiagClock {
        wall: f64::NEG_INFINITY,
        level: None,
    };
    // Warnings are throttled to one a second each: rejected samples, and falling behind real time.
    let (mut last_reject_warn, mut last_behind_warn) = (f64::NEG_INFINITY, f64::NEG_INFINITY);
    // The stamp (s) of the newest accepted motion sample, and the samples rejected in a row since that look
    // like a motion on another time base.
    let mut newest_stamp: Option<f64> = None;
    let mut other_base: Vec<Sample> = Vec::new();
    // Warnings while no motion sample has come yet, and while follow_clock has motion but no /clock (first
    // after motion_timeout_s or 5 s).
    let (mut no_motion, mut no_clock) = (Reminder::default(), Reminder::default());
    let mut clock_behind = Reminder::default();
    let first_reminder = c.motion_timeout_s.max(5.0);
    let mut holding = false;
    let mut tf_sent = false;
    let mut gravity_check = GravityCheck::default();
    let mut last_clock: Option<Time> = None;
    let mut undecodable: Vec<String> = Vec::new();
    let mut last_undecodable = f64::NEG_INFINITY;
    let input_kind = match c.input.kind {
        InputType::Odom | InputType::Pose => InputKind::Pose,
        InputType::Imu => InputKind::Imu,
        InputType::Iceoryx2 => InputKind::State,
    };
    let dt_cap = params.solver.dt_max;
    let mut error: Option<String> = None;
    // Samples taken from the reader (also between steps), with when they were taken: the node's wall clock
    // (for the input's age) and the Unix time (the stamp of `input.stamp: receive`).
    let mut pending: Vec<(Taken, f64, f64)> = Vec::with_capacity(64);
    let rec_topic = recorder.is_some().then(|| in_topic.clone());
    let unix_now = || {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs_f64())
            .unwrap_or(0.0)
    };
    let mut last_real = 0.0;
    let mut paused = false;
    // After a reset or a resume the next sample is placed at the current simulation time.
    let mut rebase = false;

    let mut last_cleanup = Instant::now();
    while !stop.load(Ordering::Relaxed) {
        // iceoryx2 peers killed mid-run leave their resources behind: remove them now and then.
        if let Some(n) = &iox_node {
            if last_cleanup.elapsed() > Duration::from_secs(1) {
                let _ = n.try_cleanup_dead_nodes();
                last_cleanup = Instant::now();
            }
        }
        // 0. Services: ~/reset starts the liquid again at rest, ~/pause freezes the simulation.
        while let Ok(Some((id, _))) = srv_reset.receive_request() {
            sim = sph::build(params.clone())?;
            motion = fresh_motion();
            newest_stamp = None;
            next_output = 0;
            next_cloud = 0;
            rebase = t0.is_some();
            let message = "liquid reset to rest; the next motion sample is t = 0".to_string();
            log(
                ros2_client::ros2::LogLevel::Info,
                &format!("~/reset: {message}"),
            );
            let _ = srv_reset.send_response(
                id,
                TriggerResponse {
                    success: true,
                    message,
                },
            );
        }
        while let Ok(Some((id, req))) = srv_pause.receive_request() {
            let message = if req.data == paused {
                format!("already {}", if paused { "paused" } else { "running" })
            } else if req.data {
                paused = true;
                format!("paused at t = {:.4} s", sim.time())
            } else {
                paused = false;
                // Resume from the current input without catching up on the paused stretch.
                motion = fresh_motion();
                newest_stamp = None;
                rebase = t0.is_some();
                format!("resumed at t = {:.4} s", sim.time())
            };
            log(
                ros2_client::ros2::LogLevel::Info,
                &format!("~/pause: {message}"),
            );
            let _ = srv_pause.send_response(
                id,
                SetBoolResponse {
                    success: true,
                    message,
                },
            );
        }
        // The rcl_interfaces parameter services; a change applies at once (the next output and cloud are
        // placed on the new rates' grids).
        let before = live;
        param_srv.serve(&mut param_table, &mut live, &full_name, |m| {
            log(ros2_client::ros2::LogLevel::Info, m)
        })?;
        if live != before {
            let t = sim.time();
            next_output = (t * live.output_rate_hz + 1e-9).floor() as u64 + 1;
            if live.particles_rate_hz > 0.0 {
                next_cloud = (t * live.particles_rate_hz + 1e-9).floor() as u64 + 1;
            }
        }
        // 1. Drain the input (and what was fetched while stepping).
        let mut got = false;
        while let Some(taken) = input.take(rec_topic.as_deref())? {
            match taken {
                Ok(t) => pending.push((t, wall(), unix_now())),
                Err(reason) => {
                    undecodable.push(reason);
                    break;
                }
            }
        }
        // Messages that could not be decoded: refused and said, with what the graph shows (a publisher of
        // another type on the topic).
        if let Some(reason) = undecodable.last().cloned() {
            counters.rejected += undecodable.len() as u64;
            counters.last_reject = format!("undecodable message: {reason}");
            if wall() - last_undecodable > 10.0 {
                last_undecodable = wall();
                let hint = super::graph_hint::hint(
                    &in_topic,
                    Input::topic(c.input.kind),
                    Input::type_name(c.input.kind),
                    &writers_on_graph(&context),
                )
                .unwrap_or_else(|| {
                    format!(
                        "is every publisher on it sending {}?",
                        Input::type_name(c.input.kind)
                    )
                });
                log(
                    ros2_client::ros2::LogLevel::Warn,
                    &format!(
                        "refused {} message(s) on {in_topic} that cannot be decoded as {} ({reason}): {hint}",
                        undecodable.len(),
                        Input::type_name(c.input.kind)
                    ),
                );
            }
            undecodable.clear();
        }
        let mut incoming: VecDeque<Sample> = pending
            .drain(..)
            .map(|((stamp, raw, reading), received, unix)| {
                let log = match c.input.stamp {
                    StampSource::Header => stamp,
                    StampSource::Receive => Time::from_secs_f64(unix),
                };
                Sample {
                    ts: log.as_secs_f64(),
                    log,
                    reading,
                    received,
                    raw,
                }
            })
            .collect();
        while let Some(sample) = incoming.pop_front() {
            let ts = sample.ts;
            let w = wall();
            if rebase {
                rebase = false;
                let new_t0 = ts - sim.time();
                // Input on an earlier time base: the recording's log times go on from where they were.
                if let (Some(old), Some(r)) = (t0, recorder.as_mut()) {
                    if new_t0 < old {
                        r.continue_from(sample.log);
                    }
                }
                t0 = Some(new_t0);
            }
            let base = *t0.get_or_insert(ts);
            // A stamp far ahead of the newest sample (a garbled stamp, a clock set wrong) is rejected: the
            // solver would take the whole gap as one smooth move, and every later sample as out of order.
            // Not after a timeout (holding the last pose): then a later stamp is the input coming back.
            let gap = newest_stamp
                .map(|n| ts - n)
                .filter(|g| *g > c.input.max_gap_s && !holding);
            // Err: why, and whether it was for where the sample lies against the newest (maybe held) one.
            let pushed = match gap {
                Some(g) => Err((
                    format!(
                        "stamp {:.6} s is {g:.3} s after the newest sample's, more than input.max_gap_s = {}",
                        ts - base,
                        c.input.max_gap_s
                    ),
                    false,
                )),
                None => motion
                    .push(ts - base, &sample.reading, &frames)
                    .map_err(|e| (e.to_string(), e.against_newest())),
            };
            match pushed {
                Ok(()) => {
                    if let Some(r) = recorder.as_mut() {
                        for m in &sample.raw {
                            r.write_message(m, sample.log)?;
                        }
                        // Samples that looked like another time base, and were not.
                        for s in other_base.drain(..) {
                            s.record_refused(r)?;
                        }
                    }
                    newest_stamp = Some(ts);
                    other_base.clear();
                    last_real = ts - base;
                    counters.accepted += 1;
                    counters.rejected_in_a_row = 0;
                    counters.note_motion(w, true);
                    pacing.input(sample.received);
                    got = true;
                    if holding {
                        holding = false;
                        log(ros2_client::ros2::LogLevel::Info, "motion input is back");
                    }
                }
                // The input back after a timeout (a sample newer than its last accepted one) that does not
                // continue the held pose: its stamps behind the held ones (its clock stood still while it
                // was away, or runs behind the node's), or its pose too far from the held one for the time
                // between them (the vessel moved meanwhile; or every sample since the last accepted one was
                // refused for such a jump, which the timeout then ends). Held samples are the node's own, so
                // it follows the input at once, from the simulation's present, as after a pause.
                Err((e, true))
                    if holding && gap.is_none() && newest_stamp.is_none_or(|n| ts > n) =>
                {
                    let behind = motion.newest().unwrap_or(ts - base) - (ts - base);
                    log(
                        ros2_client::ros2::LogLevel::Warn,
                        &format!(
                            "motion input is back after {:.2} s without a usable sample, but it does not continue the held pose ({}): following it afresh from t = {:.4} s",
                            pacing.input_age(w).unwrap_or(0.0),
                            if behind >= 0.0 {
                                format!("its stamps are {behind:.3} s behind the held pose's")
                            } else {
                                e
                            },
                            sim.time()
                        ),
                    );
                    holding = false;
                    motion = fresh_motion();
                    rebase = true;
                    newest_stamp = None;
                    incoming.push_front(sample);
                }
                Err((e, _)) => {
                    counters.rejected += 1;
                    counters.rejected_in_a_row += 1;
                    counters.note_motion(w, false);
                    counters.last_reject = e.clone();
                    if w - last_reject_warn > 1.0 {
                        last_reject_warn = w;
                        log(
                            ros2_client::ros2::LogLevel::Warn,
                            &format!(
                                "rejected a motion sample: {e}{}{} ({} rejected so far)",
                                // (The stamps in the reasons count from the first sample.)
                                if e.starts_with("stamp ") {
                                    format!(
                                        " (times since the first sample; its stamp is {ts:.6} s)"
                                    )
                                } else {
                                    String::new()
                                },
                                if c.input.stamp == StampSource::Header && ts == 0.0 {
                                    ": the messages' header stamps are zero (never set?): stamp them, or set input.stamp: receive"
                                } else {
                                    ""
                                },
                                counters.rejected
                            ),
                        );
                    }
                    // Samples on another time base (a publisher restarted with other stamps, a clock
                    // reset): once NEW_TIME_BASE of them in a row follow each other as a motion would, the
                    // input follows them from the simulation's present, as after a pause.
                    let off = gap.is_some() || newest_stamp.is_some_and(|n| ts <= n);
                    let follows = other_base
                        .last()
                        .is_none_or(|p| ts > p.ts && ts - p.ts <= c.input.max_gap_s);
                    // Refused samples are recorded once refused for good, at the recording's latest log
                    // time (their own stamps may lie an hour ahead or on another time base).
                    if !off || !follows {
                        if let Some(r) = recorder.as_mut() {
                            for s in other_base.drain(..) {
                                s.record_refused(r)?;
                            }
                        }
                        other_base.clear();
                    }
                    if !off {
                        if let Some(r) = recorder.as_mut() {
                            sample.record_refused(r)?;
                        }
                    } else {
                        other_base.push(sample);
                        if other_base.len() >= NEW_TIME_BASE {
                            let jump = other_base[0].ts - newest_stamp.unwrap_or(other_base[0].ts);
                            log(
                                ros2_client::ros2::LogLevel::Warn,
                                &format!(
                                    "the motion input's stamps jumped by {jump:.3} s and {NEW_TIME_BASE} samples in a row follow the new stamps: following them from t = {:.4} s (a restarted publisher or a reset clock)",
                                    sim.time()
                                ),
                            );
                            motion = fresh_motion();
                            rebase = true;
                            newest_stamp = None;
                            // They were not refused after all: counted again as they are taken.
                            counters.rejected -= other_base.len() as u64;
                            for item in other_base.drain(..).rev() {
                                incoming.push_front(item);
                            }
                        }
                    }
                }
            }
        }
        if let (Some(sa), Some(base)) = (&sub_accel, t0) {
            while let Ok(Some((m, _))) = sa.take() {
                let stamp = m.header.stamp.as_secs_f64();
                let t = stamp - base;
                // Accelerations stamped on another clock than the motion would never cover the times the
                // solver asks for: they would be kept and silently never used.
                let off = motion
                    .newest()
                    .map(|n| t - n)
                    .filter(|d| d.abs() > c.input.max_gap_s);
                let pushed = match off {
                    Some(d) => Err(format!(
                        "stamp {stamp:.6} s is {d:.3} s from the newest motion sample's (more than input.max_gap_s = {}): AccelStamped must carry the motion's time stamps",
                        c.input.max_gap_s
                    )),
                    None => motion
                        .push_accel(t, &m.accel.linear, &m.accel.angular, &frames)
                        .map_err(|e| e.to_string()),
                };
                if let Err(e) = pushed {
                    counters.rejected += 1;
                    counters.last_reject = format!("motion/accel: {e}");
                    if wall() - last_reject_warn > 1.0 {
                        last_reject_warn = wall();
                        log(
                            ros2_client::ros2::LogLevel::Warn,
                            &format!(
                                "rejected an acceleration sample: {e} ({} rejected so far)",
                                counters.rejected
                            ),
                        );
                    }
                }
            }
        }
        let Some(base) = t0 else {
            std::thread::sleep(Duration::from_millis(2));
            let w = wall();
            if no_motion.due(w, first_reminder) {
                log(
                    ros2_client::ros2::LogLevel::Warn,
                    &format!(
                        "no motion sample yet after {w:.0} s on {}",
                        if c.input.kind == InputType::Iceoryx2 {
                            format!("iceoryx2 service {}/motion: is its publisher (e.g. `slosh motion CASE --iceoryx2 {}`) running?", iox.service, iox.service)
                        } else {
                            let writers = writers_on_graph(&context);
                            let name = Input::topic(c.input.kind);
                            match super::graph_hint::hint(&in_topic, name, Input::type_name(c.input.kind), &writers) {
                                Some(h) => format!("{in_topic}: {h}"),
                                None => format!("{in_topic}: is the publisher running, on this ROS_DOMAIN_ID, and is the topic remapped right (-r {name}:=NAME)?"),
                            }
                        }
                    ),
                );
            }
            maybe_diagnostics(
                &pub_diag,
                recorder.as_mut().map(|r| (r, diag_topic.as_str())),
                &full_name,
                wall(),
                &mut last_diag,
                live.diagnostics_rate_hz,
                level_of("waiting for motion input", false, &counters),
                || {
                    diagnostics(
                        &full_name,
                        None,
                        &pacing,
                        &counters,
                        sim.as_ref(),
                        "waiting for motion input",
                        wall(),
                    )
                },
            )?;
            continue;
        };
        if !tf_sent {
            let tf = static_transforms(&cfg, &params, Time::from_secs_f64(base));
            // Recorded too: a player of the bag (Foxglove, `ros2 bag play`) needs the frames.
            if let Some(r) = recorder.as_mut() {
                r.write(&tf_topic, Time::from_secs_f64(base), &tf)?;
            }
            pub_tf
                .publish(tf)
                .map_err(|e| anyhow::anyhow!("publishing /tf_static: {e:?}"))?;
            tf_sent = true;
        }
        // 2. No input for too long (real-time mode): hold the last pose, at rest, and say so.
        if c.realtime.mode == RealtimeMode::Realtime {
            if let (Some(age), Some(newest)) = (pacing.input_age(wall()), motion.newest()) {
                if age > live.motion_timeout_s {
                    if !holding {
                        holding = true;
                        counters.timeouts += 1;
                        log(
                            ros2_client::ros2::LogLevel::Error,
                            &format!(
                                "{}: holding the last pose{}",
                                no_input(&counters, age, live.motion_timeout_s),
                                buffered(last_real, sim.time())
                            ),
                        );
                    }
                    // Held samples follow the wall clock from the last real one, at most 100 per second.
                    let t_hold = last_real + age;
                    if t_hold > newest + 0.01 && motion.hold(t_hold) {
                        got = true;
                    }
                }
            }
        }
        // 3. Step up to what the input allows.
        motion.forget_before(sim.time());
        if let Some(sc) = &sub_clock {
            while let Ok(Some((m, _))) = sc.take() {
                ros_time = Some(m.clock.as_secs_f64());
            }
            // Motion but no /clock: the node waits for a ROS time that never comes.
            if ros_time.is_none() && counters.accepted > 0 && no_clock.due(wall(), first_reminder) {
                log(
                    ros2_client::ros2::LogLevel::Warn,
                    &format!(
                        "realtime.mode follow_clock: {} motion samples in but no message on /clock yet: the simulation waits for the ROS time (start the clock's publisher, e.g. `ros2 bag play --clock`, or use realtime.mode realtime)",
                        counters.accepted
                    ),
                );
            }
            // A /clock on another time base than the motion's stamps: the simulation waits for a ROS time
            // that is far behind it.
            if let Some(now) = ros_time {
                let behind = sim.time() - (now - base);
                if behind > c.input.max_gap_s && clock_behind.due(wall(), first_reminder) {
                    log(
                        ros2_client::ros2::LogLevel::Warn,
                        &format!(
                            "realtime.mode follow_clock: /clock reads {now:.3} s, {behind:.3} s behind the motion's stamps (the simulation is at stamp {:.3} s) and the simulation waits for it: /clock and the motion's header stamps must be on one time base (a bag played with --clock and its own stamps, or input.stamp: receive with a clock of the wall time)",
                            base + sim.time()
                        ),
                    );
                }
            }
        }
        let until = if paused {
            None
        } else {
            match (
                motion.safe_until(c.input.delay_samples),
                &sub_clock,
                ros_time,
            ) {
                (u, None, _) => u,
                // Following /clock: not past the ROS time (mapped to simulation time).
                (Some(u), Some(_), Some(now)) => Some(u.min(now - base)),
                (_, Some(_), None) => None,
                (None, _, _) => None,
            }
        };
        let mut stepped = false;
        if let Some(until) = until {
            let mut limit = until;
            if let Some(d) = opts.duration {
                limit = limit.min(d + dt_cap);
            }
            // The first pass at t = 0 takes no step: it only publishes the initial state (output 0).
            let mut initial = next_output == 0 && sim.time() == 0.0;
            while (initial || sim.time() + dt_cap < limit) && !stop.load(Ordering::Relaxed) {
                if !std::mem::take(&mut initial) {
                    // Each step lands on the next output time (when the input reaches that far), so
                    // outputs are stamped on the output rate's grid whatever the step.
                    if let Err(e) = sim.step_to(&motion, next_output as f64 / live.output_rate_hz) {
                        error = Some(e.to_string());
                        break;
                    }
                    stepped = true;
                    let g = motion.state(sim.time()).apparent_gravity(params.gravity);
                    match gravity_check.add(sim.time(), g, params.gravity, input_kind) {
                        Some(Ok(())) => counters.input_check = "ok".into(),
                        Some(Err(w)) => {
                            log(ros2_client::ros2::LogLevel::Warn, &w);
                            counters.input_check = w;
                        }
                        None => {}
                    }
                }
                // Fetch input between steps so that the reader's short history (keep last 5) never
                // overflows while a long stretch is stepped.
                while let Some(taken) = input.take(rec_topic.as_deref())? {
                    match taken {
                        Ok(t) => pending.push((t, wall(), unix_now())),
                        Err(reason) => {
                            undecodable.push(reason);
                            break;
                        }
                    }
                }
                let t = sim.time();
                if t >= next_output as f64 / live.output_rate_hz - 1e-9 {
                    let o = match sim.observe(&motion) {
                        Ok(o) => o,
                        Err(e) => {
                            error = Some(e.to_string());
                            break;
                        }
                    };
                    let stamp = Time::from_secs_f64(base + o.time);
                    let m = output_messages(&params, &c.frames.tank, stamp, &o);
                    if let Some(r) = recorder.as_mut() {
                        r.write_outputs(&out_topics, stamp, &m)?;
                    }
                    if let Some((pw, pp, ps)) = &pub_outputs {
                        publish(pw, m.wrench, "wrench")?;
                        publish(pp, m.probes, "probes")?;
                        publish(ps, m.pressures, "pressures")?;
                    }
                    for (b, (po, pw)) in m.bodies.into_iter().zip(&pub_bodies) {
                        publish(po, b.odom, "body odom")?;
                        publish(pw, b.wrench, "body wrench")?;
                    }
                    if let (Some(p), true) = (iox_ports.as_ref(), iox.outputs) {
                        let mut so = crate::iox::outputs_of(base + o.time, &o);
                        so.steps = (sim.stats().steps - steps_at_output) as u32;
                        p.publish(&so)?;
                    }
                    steps_at_output = sim.stats().steps;
                    if let Some(pc) = &pub_clock {
                        publish(pc, Clock { clock: stamp }, "/clock")?;
                        last_clock = Some(stamp);
                    }
                    counters.published += 1;
                    if live.particles_rate_hz > 0.0
                        && t >= next_cloud as f64 / live.particles_rate_hz - 1e-9
                    {
                        // The cloud is recorded even when only iceoryx2 publishes.
                        if pub_cloud.is_some() || recorder.is_some() {
                            let cloud = super::cloud::particle_cloud(
                                stamp,
                                &c.frames.tank,
                                &sim.fluid_positions(),
                                &sim.fluid_velocities(),
                                live.particles_decimation,
                            );
                            if let Some(r) = recorder.as_mut() {
                                r.write(&cloud_topic, stamp, &cloud)?;
                            }
                            if let Some(pc) = &pub_cloud {
                                publish(pc, cloud, "particles")?;
                            }
                        }
                        if let (Some(p), true) = (iox_ports.as_mut(), iox.particles) {
                            p.publish_particles(base + o.time, &sim.snapshot())?;
                        }
                        next_cloud = (t * live.particles_rate_hz + 1e-9).floor() as u64 + 1;
                    }
                    next_output = (t * live.output_rate_hz + 1e-9).floor() as u64 + 1;
                }
                // Keep reading input and reporting while a long stretch is stepped.
                if wall() - last_diag.wall > 1.0 / live.diagnostics_rate_hz {
                    break;
                }
            }
            if error.is_some() {
                break;
            }
            // Lockstep: /clock also says where the simulation stopped for want of input, so a publisher
            // pacing itself by /clock (`slosh motion --lockstep`) sends the next samples even when the
            // output period is longer than its lead.
            if let (Some(pc), true) = (&pub_clock, stepped) {
                let now = Time::from_secs_f64(base + sim.time());
                if last_clock != Some(now) {
                    publish(pc, Clock { clock: now }, "/clock")?;
                    last_clock = Some(now);
                }
            }
            // Held samples (no input) are no input to fall behind: they come in a stretch of
            // motion_timeout_s at once.
            let input_until = if holding { sim.time() } else { until };
            if pacing.record(wall(), sim.time(), input_until) && wall() - last_behind_warn > 1.0 {
                last_behind_warn = wall();
                log(
                    ros2_client::ros2::LogLevel::Warn,
                    &format!(
                        "falling behind real time: simulation at {:.3} s, input at {until:.3} s (real-time factor {:.2})",
                        sim.time(),
                        pacing.realtime_factor()
                    ),
                );
            }
        }
        let rejecting = counters.mostly_rejected(wall());
        let holding_state;
        let state = if paused {
            "paused (~/pause)"
        } else if holding {
            holding_state = format!(
                "no {}motion input: holding the last pose{}",
                if counters.rejected_in_a_row > 0 {
                    "usable "
                } else {
                    ""
                },
                buffered(last_real, sim.time())
            );
            &holding_state
        } else if pacing.behind() {
            "behind real time"
        } else if sub_clock.is_some() && ros_time.is_none() {
            "waiting for /clock (follow_clock)"
        } else {
            rejecting.as_deref().unwrap_or("running")
        };
        let w = wall();
        maybe_diagnostics(
            &pub_diag,
            recorder.as_mut().map(|r| (r, diag_topic.as_str())),
            &full_name,
            w,
            &mut last_diag,
            live.diagnostics_rate_hz,
            level_of(state, true, &counters),
            || {
                diagnostics(
                    &full_name,
                    Some(base + sim.time()),
                    &pacing,
                    &counters,
                    sim.as_ref(),
                    state,
                    w,
                )
            },
        )?;
        if let Some(d) = opts.duration {
            if sim.time() >= d {
                break;
            }
        }
        if !got && !stepped {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    // The recording is finished on every way out (errors included; Drop covers early returns).
    // A solver failure's diagnostics go into the recording too, before it is finished.
    let failure = error.as_ref().map(|e| {
        log(
            ros2_client::ros2::LogLevel::Fatal,
            &format!("solver stopped: {e}"),
        );
        diagnostics(
            &full_name,
            t0.map(|b| b + sim.time()),
            &pacing,
            &counters,
            sim.as_ref(),
            e,
            wall(),
        )
    });
    if let Some(mut r) = recorder.take() {
        if counters.accepted == 0 {
            eprintln!(
                "[{full_name}] no motion sample was accepted: the bag {} holds no simulation",
                c.record.path
            );
        }
        for s in other_base.drain(..) {
            s.record_refused(&mut r)?;
        }
        if let Some(d) = failure.as_ref().filter(|d| d.header.stamp.as_nanos() > 0) {
            let _ = r.write(&diag_topic, d.header.stamp, d);
        }
        r.finish()?;
    }
    if let (Some(e), Some(d)) = (&error, failure) {
        let _ = pub_diag.publish(d);
        anyhow::bail!("solver stopped at t = {:.4} s: {e}", sim.time());
    }
    log(
        ros2_client::ros2::LogLevel::Info,
        &format!(
            "stopping at t = {:.3} s: {} samples accepted, {} rejected, {} outputs published",
            sim.time(),
            counters.accepted,
            counters.rejected,
            counters.published
        ),
    );
    // Give reliable readers a moment to acknowledge the last messages before the participant goes away.
    std::thread::sleep(Duration::from_millis(300));
    Ok(())
}

/// When diagnostics were last published, and at what level.
struct DiagClock {
    wall: f64,
    level: Option<u8>,
}

impl DiagClock {
    /// Whether diagnostics at `level` are due at wall time `wall`: their period has passed, or the level
    /// changed since the last ones (an ERROR that lasts less than a period, e.g. a held pose the input
    /// soon takes over from, is still published, and so is the recovery from it).
    fn due(&self, wall: f64, rate: f64, level: u8) -> bool {
        wall - self.wall >= 1.0 / rate || self.level != Some(level)
    }
}

/// Publishes diagnostics at `level` if they are due (see [`DiagClock::due`]), and records them once they
/// carry a simulation time.
#[allow(clippy::too_many_arguments)]
fn maybe_diagnostics(
    p: &Publisher<DiagnosticArray>,
    rec: Option<(&mut Recorder, &str)>,
    name: &str,
    wall: f64,
    last: &mut DiagClock,
    rate: f64,
    level: u8,
    make: impl FnOnce() -> DiagnosticArray,
) -> Result<(), crate::record::RecordError> {
    if last.due(wall, rate, level) {
        *last = DiagClock {
            wall,
            level: Some(level),
        };
        let d = make();
        if let Some((r, topic)) = rec {
            if d.header.stamp.as_nanos() > 0 {
                r.write(topic, d.header.stamp, &d)?;
            }
        }
        if let Err(e) = p.publish(d) {
            eprintln!("[{name}] publishing /diagnostics: {e:?}");
        }
    }
    Ok(())
}

/// The diagnostics' level for the node's `state` (before the simulation has a time: `timed` false).
fn level_of(state: &str, timed: bool, c: &Counters) -> u8 {
    if state == "running" && !c.input_check.starts_with("input check") {
        DiagnosticStatus::OK
    } else if state.starts_with("running")
        || !timed
        || state.starts_with("behind")
        || state.starts_with("paused")
        || state.starts_with("waiting")
    {
        DiagnosticStatus::WARN
    } else {
        // No motion input (holding the last pose), or the solver stopped.
        DiagnosticStatus::ERROR
    }
}

#[allow(clippy::too_many_arguments)]
fn diagnostics(
    name: &str,
    stamp: Option<f64>,
    pacing: &Pacing,
    c: &Counters,
    sim: &dyn sph::Solver,
    state: &str,
    wall: f64,
) -> DiagnosticArray {
    let (counts, stats) = (sim.counts(), sim.stats());
    let level = level_of(state, stamp.is_some(), c);
    let kv = |k: &str, v: String| KeyValue {
        key: k.to_string(),
        value: v,
    };
    let age = pacing
        .input_age(wall)
        .map(|a| format!("{a:.3}"))
        .unwrap_or_else(|| "none yet".into());
    DiagnosticArray {
        header: header(Time::from_secs_f64(stamp.unwrap_or(0.0)), ""),
        status: vec![DiagnosticStatus {
            level,
            name: format!("{}: sloshing simulation", name.trim_start_matches('/')),
            message: state.to_string(),
            hardware_id: "slosh".into(),
            values: vec![
                kv(
                    "realtime_factor",
                    format!("{:.3}", pacing.realtime_factor()),
                ),
                kv("particles", counts.fluid.to_string()),
                kv("particles_lost", counts.lost.to_string()),
                kv(
                    "scheme",
                    format!("{:?}", sim.params().solver.scheme).to_lowercase(),
                ),
                kv(
                    "particle_spacing",
                    sim.params().particle_spacing.to_string(),
                ),
                kv("auto_resolution", c.resolution.clone()),
                kv("time_step_s", format!("{:.6}", stats.last_dt)),
                kv("pressure_iterations", stats.last_iterations.to_string()),
                kv("density_error", format!("{:.2e}", stats.last_density_error)),
                kv("unconverged_steps", stats.unconverged_steps.to_string()),
                kv("retried_steps", stats.retried_steps.to_string()),
                kv("input_age_s", age),
                kv("samples_accepted", c.accepted.to_string()),
                kv("samples_rejected", c.rejected.to_string()),
                kv("last_rejection", c.last_reject.clone()),
                kv("input_timeouts", c.timeouts.to_string()),
                kv(
                    "input_check",
                    if c.input_check.is_empty() {
                        "pending".into()
                    } else {
                        c.input_check.clone()
                    },
                ),
                kv("overruns", pacing.overruns.to_string()),
                kv("outputs_published", c.published.to_string()),
            ],
        }],
    }
}

#[cfg(test)]
mod tests {
    use super::{Counters, DiagClock, Reminder};
    use slosh_msgs::diagnostic_msgs::DiagnosticStatus;

    #[test]
    fn diagnostics_come_at_their_rate_and_at_once_when_the_level_changes() {
        let last = DiagClock {
            wall: 10.0,
            level: Some(DiagnosticStatus::OK),
        };
        // At 10 Hz: not within 0.1 s at the same level, due after it.
        assert!(!last.due(10.05, 10.0, DiagnosticStatus::OK));
        assert!(last.due(10.11, 10.0, DiagnosticStatus::OK));
        // A change of level is due at once (an ERROR shorter than the period is not missed).
        assert!(last.due(10.01, 10.0, DiagnosticStatus::ERROR));
        assert!(last.due(10.01, 10.0, DiagnosticStatus::WARN));
    }

    #[test]
    fn a_node_rejecting_most_of_its_motion_says_so() {
        let mut c = Counters::default();
        // A few samples, or mostly accepted ones: running.
        for k in 0..4 {
            c.note_motion(k as f64 * 0.02, false);
        }
        assert_eq!(c.mostly_rejected(0.1), None);
        for k in 4..10 {
            c.note_motion(k as f64 * 0.02, true);
        }
        assert_eq!(c.mostly_rejected(0.2), None);
        // 15 of the last 21 rejected.
        c.last_reject = "pitch jumps".into();
        for k in 10..21 {
            c.note_motion(k as f64 * 0.02, false);
        }
        let s = c.mostly_rejected(0.42).unwrap();
        assert!(
            s.starts_with("running, but 15 of the last 21 motion samples were rejected")
                && s.ends_with("(last: pitch jumps)"),
            "{s}"
        );
        // Samples older than the window no longer count.
        assert_eq!(c.mostly_rejected(3.0), None);
    }

    #[test]
    fn a_reminder_comes_first_after_its_delay_then_every_ten_seconds() {
        let mut r = Reminder::default();
        let times: Vec<f64> = (0..300).map(|k| 1.0 + k as f64 * 0.1).collect();
        let said: Vec<f64> = times.into_iter().filter(|&t| r.due(t, 5.0)).collect();
        assert_eq!(said.len(), 3, "{said:?}");
        assert!(
            (said[0] - 6.0).abs() < 1e-9 && (said[1] - 16.0).abs() < 1e-9,
            "{said:?}"
        );
    }
}
