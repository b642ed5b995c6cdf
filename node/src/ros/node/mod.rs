//! `slosh node`: the solver as a ROS 2 node. Vessel motion in (Odometry, PoseStamped, Imu or iceoryx2
//! states), the liquid's wrench, probe elevations, wall pressures and diagnostics out, stamped with the
//! simulation time of the state they describe (the input's time base: output stamp = first input stamp +
//! simulation time).
//!
//! The node is a loop of passes over one `LiveNode`; each pass, in order:
//!
//! 0. answers the services (`~/reset`, `~/pause`, the parameter services: `services.rs`);
//! 1. takes the motion samples received, accepts or refuses each against the time base and the motion so
//!    far, records them (`intake.rs`);
//! 2. until a first sample is accepted, waits for motion and says why it has none (`LiveNode::wait_for_motion`);
//!    in real-time mode, holds the last pose once the input has been silent for `motion_timeout_s`;
//! 3. steps the solver up to what the input (and `/clock` when following it) allows, landing on each output
//!    time and publishing there (`advance.rs`; the outputs' sinks: `outputs.rs`);
//! 4. publishes diagnostics with the node's state: waiting, running, behind real time, holding, paused
//!    (`report.rs`).
//!
//! Start-up (the settings' checks, the automatic resolution, the participant and its endpoints) is
//! `start.rs`; the way out (the recording finished on every exit) is `LiveNode::finish`.

mod advance;
mod input;
mod intake;
mod outputs;
mod report;
mod services;
mod start;

use super::args::{Names, RosArgs};
use super::logging::Logger;
use super::parameters::{LiveSettings, ParameterServers, Parameters};
use crate::config::{Loaded, DEFAULT_NAME};
use crate::input::frames::Frames;
use crate::input::live::Live;
use crate::input::live_motion::Limits;
use crate::record::Recorder;
use input::{Input, Sample, Taken};
use report::Report;
use ros2_client::{Publisher, Server};
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::diagnostic_msgs::DiagnosticArray;
use slosh_msgs::geometry_msgs::{AccelStamped, WrenchStamped};
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::rosgraph_msgs::Clock;
use slosh_msgs::sensor_msgs::PointCloud2;
use slosh_msgs::slosh_msgs::{PressureArray, ProbeArray};
use slosh_msgs::std_srvs::{SetBoolRequest, SetBoolResponse, TriggerRequest, TriggerResponse};
use slosh_msgs::tf2_msgs::TFMessage;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

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

/// Runs the node until SIGINT/SIGTERM (or `duration` simulated seconds).
pub fn run(
    ros: &RosArgs,
    fallback_params: Option<&str>,
    opts: &NodeOptionsCli,
) -> anyhow::Result<()> {
    let cfg = load_parameters(ros, fallback_params)?;
    let names = Names::new(ros, DEFAULT_NAME)?;
    let params = cfg.sim_params()?;
    start::check_settings(&cfg)?;
    // Before the resolution trials, so that a signal during them stops the node cleanly too.
    let stop = crate::signals::shutdown_flag()?;
    let logger = Logger::new(ros, &names);
    let Some(resolution) = start::resolution(&cfg, &logger, &stop)? else {
        return Ok(());
    };
    let mut node = LiveNode::start(&cfg, &names, logger, params, resolution)?;
    while !stop.load(Ordering::Relaxed) {
        if node.pass(&stop, opts.duration)? == Flow::Stop {
            break;
        }
    }
    node.finish()
}

/// The motion of a start: none yet, in the input's conventions.
fn fresh_motion(
    c: &crate::config::RunConfig,
    limits: Limits,
    frames: &Frames,
    gravity: f64,
) -> Live {
    if c.input.kind == crate::config::InputType::Iceoryx2 {
        Live::states(limits, frames)
    } else {
        let imu = c.input.kind == crate::config::InputType::Imu;
        Live::new(imu, limits, frames, gravity)
    }
}

/// Whether the node goes on after a pass.
#[derive(Debug, PartialEq)]
enum Flow {
    Go,
    Stop,
}

/// The node's ROS 2 participant and its endpoints, and the iceoryx2 node when iceoryx2 is used.
///
/// (Fields drop in their order: the endpoints before the node and its participant, the iceoryx2 ports
/// before their node.)
struct Endpoints {
    input: Input,
    sub_accel: Option<ros2_client::Subscription<AccelStamped>>,
    /// `/clock`, in `follow_clock` mode.
    sub_clock: Option<ros2_client::Subscription<Clock>>,
    out: Publishers,
    srv: Services,
    iox_ports: Option<crate::iox::OutputPorts>,
    iox_node: Option<iceoryx2::node::Node<iceoryx2::prelude::ipc::Service>>,
    /// Resolved names: the motion input, (wrench, probes, pressures), diagnostics, static frames, clouds.
    in_topic: String,
    out_topics: [String; 3],
    diag_topic: String,
    tf_topic: String,
    cloud_topic: String,
    node: ros2_client::Node,
    context: ros2_client::Context,
}

/// The node's publishers.
struct Publishers {
    /// (wrench, probes, pressures) over DDS unless iceoryx2 alone carries them.
    liquid: Option<(
        Publisher<WrenchStamped>,
        Publisher<ProbeArray>,
        Publisher<PressureArray>,
    )>,
    /// Each floating body's motion and the liquid's force on it.
    bodies: Vec<(Publisher<Odometry>, Publisher<WrenchStamped>)>,
    diag: Publisher<DiagnosticArray>,
    tf: Publisher<TFMessage>,
    /// `/clock`, in `lockstep` mode.
    clock: Option<Publisher<Clock>>,
    cloud: Option<Publisher<PointCloud2>>,
}

/// The node's services.
struct Services {
    reset: Server<TriggerRequest, TriggerResponse>,
    pause: Server<SetBoolRequest, SetBoolResponse>,
    parameters: ParameterServers,
}

/// The motion taken so far and the time base it is on.
struct Intake {
    motion: Live,
    frames: Frames,
    limits: Limits,
    /// The input's stamp at simulation time 0 (None until the first sample is accepted).
    t0: Option<f64>,
    /// The stamp (s) of the newest accepted motion sample.
    newest_stamp: Option<f64>,
    /// The samples refused in a row since the newest accepted one that look like a motion on another time
    /// base.
    other_base: Vec<Sample>,
    /// The simulation time of the newest accepted (not held) sample.
    last_real: f64,
    /// No input for `motion_timeout_s`: the last pose is held.
    holding: bool,
    /// After a reset, a resume or a new time base the next sample is placed at the current simulation time.
    rebase: bool,
    /// Samples taken from the reader (also between steps), with when they were taken: the node's wall clock
    /// (for the input's age) and the Unix time (the stamp of `input.stamp: receive`).
    pending: Vec<(Taken, f64, f64)>,
    /// Why the messages received since the last pass could not be decoded.
    undecodable: Vec<String>,
    last_undecodable: f64,
    /// The topic the input is recorded on (None when not recording).
    rec_topic: Option<String>,
}

/// A running node: its endpoints, the solver, the motion and the outputs' schedule.
struct LiveNode<'c> {
    cfg: &'c Loaded,
    params: sph::params::SimParams,
    full_name: String,
    /// Where [`Self::log`] says what, from which level (`--log-level`).
    logger: Logger,
    /// (Before the endpoints: on an early way out its `Drop` finishes the recording while the node is up.)
    recorder: Option<Recorder>,
    ends: Endpoints,
    table: Parameters,
    /// What a parameter set changes while the node runs.
    live: LiveSettings,
    sim: Box<dyn sph::Solver>,
    intake: Intake,
    report: Report,
    /// Outputs at k / rate (the steps land on them), the first the state at t = 0 before any step.
    outputs: crate::drive::Outputs,
    /// Particle clouds' times (at an output time when one is due).
    clouds: crate::drive::Grid,
    /// The ROS time of the newest `/clock` message (`follow_clock`).
    ros_time: Option<f64>,
    /// The stamp of the last `/clock` published (`lockstep`).
    last_clock: Option<Time>,
    tf_sent: bool,
    paused: bool,
    /// Why the solver stopped.
    error: Option<String>,
    last_cleanup: Instant,
}

impl LiveNode<'_> {
    /// One pass of the loop (see the module's description).
    fn pass(&mut self, stop: &AtomicBool, duration: Option<f64>) -> anyhow::Result<Flow> {
        self.clean_up_iceoryx2();
        self.serve()?;
        let got = self.take_input()?;
        let Some(base) = self.intake.t0 else {
            self.wait_for_motion()?;
            return Ok(Flow::Go);
        };
        self.send_frames(base)?;
        let held = self.hold_if_silent();
        let stepped = self.advance(base, stop, duration)?;
        if self.error.is_some() {
            return Ok(Flow::Stop);
        }
        self.report_state(base)?;
        if duration.is_some_and(|d| self.sim.time() >= d) {
            return Ok(Flow::Stop);
        }
        if !(got || held || stepped) {
            std::thread::sleep(Duration::from_millis(1));
        }
        Ok(Flow::Go)
    }

    /// Seconds since the node started.
    fn wall(&self) -> f64 {
        self.report.start.elapsed().as_secs_f64()
    }

    /// Says `msg` on stderr and on `/rosout`, as far as `--log-level` and the log's outputs let it.
    #[track_caller]
    fn log(&self, level: ros2_client::ros2::LogLevel, msg: &str) {
        self.logger.log(&self.ends.node, level, msg);
    }

    /// The motion of a fresh start (after a reset, a resume or a new time base).
    fn fresh_motion(&self) -> Live {
        let i = &self.intake;
        fresh_motion(&self.cfg.config, i.limits, &i.frames, self.params.gravity)
    }

    /// iceoryx2 peers killed mid-run leave their resources behind: removes them now and then.
    fn clean_up_iceoryx2(&mut self) {
        if let Some(n) = &self.ends.iox_node {
            if self.last_cleanup.elapsed() > Duration::from_secs(1) {
                let _ = n.try_cleanup_dead_nodes();
                self.last_cleanup = Instant::now();
            }
        }
    }

    /// The static frames, once the time base is known; recorded too (a player of the bag, Foxglove or
    /// `ros2 bag play`, needs them).
    fn send_frames(&mut self, base: f64) -> anyhow::Result<()> {
        if self.tf_sent {
            return Ok(());
        }
        let tf =
            crate::messages::static_transforms(self.cfg, &self.params, Time::from_secs_f64(base));
        if let Some(r) = self.recorder.as_mut() {
            r.write(&self.ends.tf_topic, Time::from_secs_f64(base), &tf)?;
        }
        self.ends
            .out
            .tf
            .publish(tf)
            .map_err(|e| anyhow::anyhow!("publishing /tf_static: {e:?}"))?;
        self.tf_sent = true;
        Ok(())
    }

    /// Stops: the recording is finished on every way out (a solver failure's diagnostics go into it first),
    /// a solver failure is the error returned, the reliable readers get a moment to acknowledge the last
    /// messages.
    fn finish(mut self) -> anyhow::Result<()> {
        let failure = self.error.clone().map(|e| {
            self.log(
                ros2_client::ros2::LogLevel::Fatal,
                &format!("solver stopped: {e}"),
            );
            let stamp = self.intake.t0.map(|b| b + self.sim.time());
            self.diagnostics(stamp, &e)
        });
        if let Some(mut r) = self.recorder.take() {
            if self.report.counters.accepted == 0 {
                self.log(
                    ros2_client::ros2::LogLevel::Warn,
                    &format!(
                        "no motion sample was accepted: the bag {} holds no simulation",
                        self.cfg.config.record.path
                    ),
                );
            }
            for s in self.intake.other_base.drain(..) {
                s.record_refused(&mut r)?;
            }
            if let Some(d) = failure.as_ref().filter(|d| d.header.stamp.as_nanos() > 0) {
                let _ = r.write(&self.ends.diag_topic, d.header.stamp, d);
            }
            r.finish()?;
        }
        if let (Some(e), Some(d)) = (&self.error, failure) {
            let _ = self.ends.out.diag.publish(d);
            anyhow::bail!("solver stopped at t = {:.4} s: {e}", self.sim.time());
        }
        let c = &self.report.counters;
        self.log(
            ros2_client::ros2::LogLevel::Info,
            &format!(
                "stopping at t = {:.3} s: {} samples accepted, {} rejected, {} outputs published",
                self.sim.time(),
                c.accepted,
                c.rejected,
                c.published
            ),
        );
        // Give reliable readers a moment to acknowledge the last messages before the participant goes away.
        std::thread::sleep(Duration::from_millis(300));
        Ok(())
    }
}
