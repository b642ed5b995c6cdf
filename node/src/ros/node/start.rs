//! Start-up: the settings checked before anything is joined, the particle spacing (`realtime.auto_resolution`),
//! then the participant, its endpoints and the node's first state.

use super::input::Input;
use super::report::{Counters, DiagClock, Reminder, Report};
use super::{Endpoints, Intake, LiveNode, Publishers, Services};
use crate::config::{InputType, Loaded, RealtimeMode, RunConfig};
use crate::input::frames::Frames;
use crate::input::gravity_check::{GravityCheck, InputKind};
use crate::input::live_motion::Limits;
use crate::messages::body_topic;
use crate::record::Recorder;
use crate::ros::args::Names;
use crate::ros::logging::{LogLevel, Logger};
use crate::ros::pacing::Pacing;
use crate::ros::parameters::{LiveSettings, ParameterServers, Parameters};
use crate::ros::{publisher, subscription};
use ros2_client::qos::{Durability, History, WhenFull};
use ros2_client::{NodeName, NodeOptions, QosProfile, ServiceMapping, ServiceTypeName};
use slosh_msgs::geometry_msgs::AccelStamped;
use std::sync::atomic::AtomicBool;
use std::time::{Duration, Instant};

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

/// The node's own settings that the case's checks do not cover, with the file and key that set them.
pub(super) fn check_settings(cfg: &Loaded) -> anyhow::Result<()> {
    let c = &cfg.config;
    let positive = |key: &str, v: f64, what: &str| {
        if v.is_finite() && v > 0.0 {
            Ok(())
        } else {
            Err(anyhow::anyhow!(
                "{}: {key}: must be a positive number of {what}, got {v}",
                cfg.source_of(key)
            ))
        }
    };
    positive("motion_timeout_s", c.motion_timeout_s, "seconds")?;
    positive("input.max_gap_s", c.input.max_gap_s, "seconds")?;
    positive(
        "diagnostics_rate_hz",
        c.diagnostics_rate_hz,
        "messages per second",
    )?;
    if !(c.particles.rate_hz.is_finite() && c.particles.rate_hz >= 0.0) {
        anyhow::bail!(
            "{}: particles.rate_hz: must be zero (off) or a positive number of clouds per simulated second, got {}",
            cfg.source_of("particles.rate_hz"),
            c.particles.rate_hz
        );
    }
    let iox = &c.iceoryx2;
    if c.input.kind == InputType::Iceoryx2
        && (c.input.world_frame != crate::config::WorldFrame::Enu
            || c.input.body_frame != crate::config::BodyFrame::Flu)
    {
        anyhow::bail!(
            "{}: input.world_frame / input.body_frame: iceoryx2 motion samples are always in a z-up world and the FLU vessel frame; leave both at enu / flu",
            cfg.source_of("input.world_frame")
        );
    }
    if !(iox.dds_outputs || iox.outputs || iox.particles) {
        anyhow::bail!(
            "{}: iceoryx2.dds_outputs: false publishes nothing; set iceoryx2.outputs: true (and iceoryx2.particles) or leave dds_outputs true",
            cfg.source_of("iceoryx2.dds_outputs")
        );
    }
    if iox.particles && c.particles.rate_hz <= 0.0 {
        anyhow::bail!(
            "{}: iceoryx2.particles: set particles.rate_hz (frames per simulated second) above 0",
            cfg.source_of("iceoryx2.particles")
        );
    }
    Ok(())
}

/// How the particle spacing was chosen.
pub(super) struct Resolution {
    /// The spacing chosen by `realtime.auto_resolution` (None: the case's).
    particle_spacing: Option<f64>,
    /// The choice as the recording's metadata documents it.
    record: Option<serde_json::Value>,
    /// In words, for the log and the diagnostics.
    described: String,
}

/// The particle spacing: the case's, or in real-time mode with `realtime.auto_resolution` the one its
/// trials choose (None: a signal stopped them).
pub(super) fn resolution(
    cfg: &Loaded,
    log: &Logger,
    stop: &AtomicBool,
) -> anyhow::Result<Option<Resolution>> {
    let c = &cfg.config;
    let auto = &c.realtime.auto_resolution;
    let off = |described: &str| {
        Ok(Some(Resolution {
            particle_spacing: None,
            record: None,
            described: described.into(),
        }))
    };
    if !auto.enabled {
        return off("off");
    }
    if c.realtime.mode != RealtimeMode::Realtime {
        return off("off (only in realtime mode)");
    }
    auto.check(cfg)?;
    let say = |m: &str| log.say(LogLevel::Info, m);
    let warn = |m: &str| log.say(LogLevel::Warn, m);
    if c.solver.scheme == sph::params::Scheme::Wcsph {
        warn("realtime.auto_resolution with solver.scheme: wcsph: the weakly-compressible scheme's steps follow the speed of sound, so only very coarse spacings keep real time; solver.scheme: dfsph is the scheme for real time");
    }
    say(&format!(
        "realtime.auto_resolution: timing {} s trials of {} (target real-time factor {}) ...",
        auto.trial_s, cfg.source_name, auto.target_factor
    ));
    let Some(choice) = crate::resolution::choose(cfg, auto, stop)? else {
        say("interrupted during the resolution trials: stopping (nothing was published or recorded)");
        return Ok(None);
    };
    if let Some((dp, why)) = choice.skipped.last() {
        say(&format!(
            "realtime.auto_resolution: spacings of {dp:.4} m and coarser left out: {why}"
        ));
    }
    if let Some(why) = &choice.held_by_accuracy {
        say(&format!("realtime.auto_resolution: {why}"));
    }
    if let Some(w) = &choice.accuracy_warning {
        warn(&format!("realtime.auto_resolution: {w}"));
    }
    Ok(Some(Resolution {
        particle_spacing: Some(choice.particle_spacing),
        record: Some(serde_json::json!({
            "requested_particle_spacing": c.particle_spacing,
            "chosen": choice,
        })),
        described: choice.describe(),
    }))
}

impl Endpoints {
    /// Joins the domain as the node and opens every endpoint the settings ask for.
    fn open(
        cfg: &Loaded,
        names: &Names,
        params: &sph::params::SimParams,
        particles: usize,
        rosout: bool,
    ) -> anyhow::Result<Self> {
        let c = &cfg.config;
        let iox = &c.iceoryx2;
        let context = crate::ros::context()?;
        let mut node = context
            .new_node(
                NodeName::new(&names.namespace, &names.node).map_err(|e| {
                    anyhow::anyhow!("node name {}/{}: {e:?}", names.namespace, names.node)
                })?,
                NodeOptions::new().enable_rosout(rosout),
            )
            .map_err(|e| anyhow::anyhow!("cannot create the node: {e:?}"))?;
        let iox_node = open_iceoryx2(cfg, names, params)?;
        let (input, sub_accel) = open_input(&mut node, names, cfg, iox_node.as_ref())?;
        let out = Publishers::open(&mut node, names, cfg, params)?;
        // follow_clock: ROS time from /clock (best effort keep last 1, as rclcpp's ClockQoS; reliable
        // publishers connect too).
        let sub_clock = match c.realtime.mode {
            RealtimeMode::FollowClock => Some(subscription(
                &mut node,
                names,
                "/clock",
                &QosProfile::subscription_default().history(History::KeepLast { depth: 1 }),
            )?),
            _ => None,
        };
        let srv = Services::open(&mut node, names, cfg)?;
        let iox_ports = match &iox_node {
            Some(n) if iox.outputs || iox.particles => Some(crate::iox::OutputPorts::new(
                n,
                &iox.service,
                iox.particles.then_some(particles),
            )?),
            _ => None,
        };
        Ok(Self {
            input,
            sub_accel,
            sub_clock,
            out,
            srv,
            iox_node,
            iox_ports,
            in_topic: names.resolve(Input::topic(c.input.kind))?,
            out_topics: [
                names.resolve("wrench")?,
                names.resolve("probes")?,
                names.resolve("pressures")?,
            ],
            diag_topic: names.resolve("/diagnostics")?,
            tf_topic: names.resolve("/tf_static")?,
            cloud_topic: names.resolve("particles")?,
            context,
            node,
        })
    }
}

/// The iceoryx2 node, where iceoryx2 carries the input or outputs (the probes and sensors checked against
/// its fixed-size payloads).
fn open_iceoryx2(
    cfg: &Loaded,
    names: &Names,
    params: &sph::params::SimParams,
) -> anyhow::Result<Option<iceoryx2::node::Node<iceoryx2::prelude::ipc::Service>>> {
    let (c, iox) = (&cfg.config, &cfg.config.iceoryx2);
    if !(c.input.kind == InputType::Iceoryx2 || iox.outputs || iox.particles) {
        return Ok(None);
    }
    crate::iox::check_sensors(
        &cfg.source_name,
        params.probes.len(),
        params.pressure_sensors.len(),
    )?;
    let node = crate::iox::node(&format!("slosh_{}", names.node))
        .map_err(|e| anyhow::anyhow!("iceoryx2 (service {:?}): {e}", iox.service))?;
    Ok(Some(node))
}

/// The motion input (`input.type`) and, where asked for, the accelerations beside a pose input.
fn open_input(
    node: &mut ros2_client::Node,
    names: &Names,
    cfg: &Loaded,
    iox_node: Option<&iceoryx2::node::Node<iceoryx2::prelude::ipc::Service>>,
) -> anyhow::Result<(Input, Option<ros2_client::Subscription<AccelStamped>>)> {
    let c = &cfg.config;
    let topic = Input::topic(c.input.kind);
    let input = match c.input.kind {
        InputType::Iceoryx2 => Input::Iox(
            crate::iox::motion_subscriber(
                iox_node.expect("an iceoryx2 input has its node"),
                &c.iceoryx2.service,
            )?,
            names.resolve("motion/accel")?,
            c.frames.vessel.clone(),
        ),
        InputType::Imu => Input::Imu(subscription(node, names, topic, &qos_input())?),
        InputType::Odom => Input::Odom(subscription(node, names, topic, &qos_input())?),
        InputType::Pose => Input::Pose(subscription(node, names, topic, &qos_input())?),
    };
    let accel = if c.input.accel && c.input.kind != InputType::Imu {
        Some(subscription(node, names, "motion/accel", &qos_input())?)
    } else {
        None
    };
    Ok((input, accel))
}

impl Publishers {
    fn open(
        node: &mut ros2_client::Node,
        names: &Names,
        cfg: &Loaded,
        params: &sph::params::SimParams,
    ) -> anyhow::Result<Self> {
        let c = &cfg.config;
        let dds = c.iceoryx2.dds_outputs;
        let qos = qos_outputs();
        let liquid = if dds {
            Some((
                publisher(node, names, "wrench", &qos)?,
                publisher(node, names, "probes", &qos)?,
                publisher(node, names, "pressures", &qos)?,
            ))
        } else {
            None
        };
        let mut bodies = Vec::new();
        if dds {
            for name in params.body_names() {
                bodies.push((
                    publisher(node, names, &body_topic(&name, "odom"), &qos)?,
                    publisher(node, names, &body_topic(&name, "wrench"), &qos)?,
                ));
            }
        }
        let cloud = if c.particles.rate_hz > 0.0 && dds {
            let qos = QosProfile::publisher_default()
                .reliability_reliable(WhenFull::Wait(Duration::from_millis(20)))
                .history(History::KeepLast { depth: 1 });
            Some(publisher(node, names, "particles", &qos)?)
        } else {
            None
        };
        Ok(Self {
            liquid,
            bodies,
            diag: publisher(node, names, "/diagnostics", &qos)?,
            tf: publisher(node, names, "/tf_static", &qos_latched())?,
            clock: match c.realtime.mode {
                RealtimeMode::Lockstep => Some(publisher(node, names, "/clock", &qos)?),
                _ => None,
            },
            cloud,
        })
    }
}

impl Services {
    fn open(node: &mut ros2_client::Node, names: &Names, cfg: &Loaded) -> anyhow::Result<Self> {
        let qos = QosProfile::publisher_default().history(History::KeepLast { depth: 10 });
        let mapping = match cfg.config.service_mapping {
            crate::config::ServiceMappingCfg::Enhanced => ServiceMapping::Enhanced,
            crate::config::ServiceMappingCfg::Cyclone => ServiceMapping::Cyclone,
            crate::config::ServiceMappingCfg::Basic => ServiceMapping::Basic,
        };
        let named = |name: &str, kind: &str| {
            anyhow::Ok((
                crate::ros::ros_name(names, name)?,
                ServiceTypeName::new("std_srvs", kind),
            ))
        };
        let (name, kind) = named("~/reset", "Trigger")?;
        let reset = node
            .create_server(mapping, &name, &kind, qos.clone(), qos.clone())
            .map_err(|e| anyhow::anyhow!("service ~/reset: {e:?}"))?;
        let (name, kind) = named("~/pause", "SetBool")?;
        let pause = node
            .create_server(mapping, &name, &kind, qos.clone(), qos.clone())
            .map_err(|e| anyhow::anyhow!("service ~/pause: {e:?}"))?;
        Ok(Self {
            reset,
            pause,
            parameters: ParameterServers::new(node, names, mapping, &qos)?,
        })
    }
}

impl Intake {
    /// No motion yet, in the input's conventions; `rec_topic`: where the input is recorded.
    fn new(c: &RunConfig, gravity: f64, rec_topic: Option<String>) -> Self {
        let frames = Frames::new(c.input.world_frame, c.input.body_frame, c.frames.tank_pose);
        let limits = Limits {
            max_speed: c.input.max_speed,
            max_rotation_rate: c.input.max_rotation_rate,
        };
        let motion = super::fresh_motion(c, limits, &frames, gravity);
        Self {
            motion,
            frames,
            limits,
            t0: None,
            newest_stamp: None,
            other_base: Vec::new(),
            last_real: 0.0,
            holding: false,
            rebase: false,
            pending: Vec::with_capacity(64),
            undecodable: Vec::new(),
            last_undecodable: f64::NEG_INFINITY,
            rec_topic,
        }
    }
}

impl Report {
    /// Nothing counted yet; `resolution`: how the spacing was chosen.
    fn new(c: &RunConfig, resolution: String) -> Self {
        Self {
            start: Instant::now(),
            pacing: Pacing::new(0.25),
            counters: Counters {
                resolution,
                ..Default::default()
            },
            last_diag: DiagClock {
                wall: f64::NEG_INFINITY,
                level: None,
            },
            last_reject_warn: f64::NEG_INFINITY,
            last_behind_warn: f64::NEG_INFINITY,
            no_motion: Reminder::default(),
            no_clock: Reminder::default(),
            clock_behind: Reminder::default(),
            first_reminder: c.motion_timeout_s.max(5.0),
            gravity_check: GravityCheck::default(),
            input_kind: match c.input.kind {
                InputType::Odom | InputType::Pose => InputKind::Pose,
                InputType::Imu => InputKind::Imu,
                InputType::Iceoryx2 => InputKind::State,
            },
        }
    }
}

impl<'c> LiveNode<'c> {
    /// The node as it starts with the case's `params` (its spacing as `resolution` chose it): the solver at
    /// rest, no motion yet, the recording (if any) opened.
    pub(super) fn start(
        cfg: &'c Loaded,
        names: &Names,
        logger: Logger,
        mut params: sph::params::SimParams,
        resolution: Resolution,
    ) -> anyhow::Result<Self> {
        let c = &cfg.config;
        // The recording documents the spacing run, and how it was chosen.
        let mut recorded_parameters = cfg.parameters.clone();
        if let Some(dp) = resolution.particle_spacing {
            params.particle_spacing = dp;
            recorded_parameters["particle_spacing"] = serde_json::json!(dp);
        }
        let sim = sph::build(params.clone())?;
        let counts = sim.counts();
        let ends = Endpoints::open(
            cfg,
            names,
            &params,
            counts.fluid + counts.boundary,
            logger.rosout(),
        )?;
        // Every parameter as the node runs with it: the parameter services' table and the recording's
        // metadata.
        let effective = cfg.effective_parameters(&params);
        let table = Parameters::new(
            &effective,
            c.realtime.mode == RealtimeMode::FollowClock,
            c.particles.rate_hz > 0.0,
        );
        let recorder = if c.record.path.is_empty() {
            None
        } else {
            let mut meta = crate::record::parameters_metadata(&recorded_parameters, &effective);
            if let Some(v) = &resolution.record {
                meta.insert("auto_resolution".into(), v.to_string());
            }
            Some(Recorder::create_with_metadata(&c.record, meta)?)
        };
        let rec_topic = recorder.is_some().then(|| ends.in_topic.clone());
        let intake = Intake::new(c, params.gravity, rec_topic);
        let report = Report::new(c, resolution.described);
        let node = Self {
            cfg,
            full_name: names.node_fqn(),
            logger,
            table,
            live: LiveSettings {
                output_rate_hz: c.output_rate_hz,
                diagnostics_rate_hz: c.diagnostics_rate_hz,
                particles_rate_hz: c.particles.rate_hz,
                particles_decimation: c.particles.decimation,
                motion_timeout_s: c.motion_timeout_s,
            },
            sim,
            intake,
            recorder,
            report,
            outputs: crate::drive::Outputs::new(c.output_rate_hz, &params, &c.frames.tank),
            clouds: crate::drive::Grid::new(c.particles.rate_hz),
            ros_time: None,
            last_clock: None,
            tf_sent: false,
            paused: false,
            error: None,
            last_cleanup: Instant::now(),
            ends,
            params,
        };
        node.say_started();
        Ok(node)
    }

    /// The first log line: the case, the particles, the mode and where the node waits for motion.
    fn say_started(&self) {
        let (c, p) = (&self.cfg.config, &self.params);
        let counts = self.sim.counts();
        self.log(
            ros2_client::ros2::LogLevel::Info,
            &format!(
                "parameters {}: {}D tank {} x {} x {} m, {} liquid + {} wall particles (dp {} m, auto resolution: {}), {:?} mode; waiting for motion on {}",
                self.cfg.sections.join(", "),
                p.dimension,
                p.tank.length,
                p.tank.breadth,
                p.tank.height,
                counts.fluid,
                counts.boundary,
                p.particle_spacing,
                self.report.counters.resolution,
                c.realtime.mode,
                if c.input.kind == InputType::Iceoryx2 {
                    format!("iceoryx2 service {}/motion", c.iceoryx2.service)
                } else {
                    self.ends.in_topic.clone()
                }
            ),
        );
        for w in p.sensors_beside_walls() {
            self.log(
                ros2_client::ros2::LogLevel::Warn,
                &format!("pressure_sensors: {w}"),
            );
        }
    }
}
