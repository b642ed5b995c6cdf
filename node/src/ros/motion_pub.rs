//! `slosh motion`: publishes synthetic vessel motion (the config's `motion.*`: regular, irregular JONSWAP or a
//! CSV file) as nav_msgs/Odometry on `motion/odom`, and optionally geometry_msgs/PoseStamped on `motion/pose`,
//! for headless CI and demos. Paced by the wall clock, or in lockstep with a simulation's `/clock`.

use super::args::{Names, RosArgs};
use super::convert::{point_msg, quat_msg, vec3_msg};
use super::publish;
use crate::motion_source;
use ros2_client::qos::{History, WhenFull};
use ros2_client::{NodeName, NodeOptions, QosProfile};
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::geometry_msgs::{
    Accel, AccelStamped, Pose, PoseStamped, PoseWithCovariance, Twist, TwistWithCovariance,
};
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::rosgraph_msgs::Clock;
use slosh_msgs::sensor_msgs::Imu;
use slosh_msgs::std_msgs::Header;
use sph::motion::RigidState;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

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

/// The Odometry of a rigid state (pose in the world, twist in the body frame as REP 105 says).
pub fn odometry(s: &RigidState, stamp: Time, world: &str, body: &str) -> Odometry {
    let v_body = s.orientation.inverse_transform_vector(&s.velocity);
    Odometry {
        header: Header {
            stamp,
            frame_id: world.into(),
        },
        child_frame_id: body.into(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: point_msg(s.position),
                orientation: quat_msg(s.orientation),
            },
            covariance: [0.0; 36],
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: vec3_msg(v_body),
                angular: vec3_msg(s.angular_velocity),
            },
            covariance: [0.0; 36],
        },
    }
}

/// The accelerations of a rigid state in its body frame, as geometry_msgs/AccelStamped.
pub fn accel(s: &RigidState, stamp: Time, body: &str) -> AccelStamped {
    AccelStamped {
        header: Header {
            stamp,
            frame_id: body.into(),
        },
        accel: Accel {
            linear: vec3_msg(s.orientation.inverse_transform_vector(&s.acceleration)),
            angular: vec3_msg(s.angular_acceleration),
        },
    }
}

/// What an IMU at the origin of a rigid state reads: orientation, body angular velocity, and specific force
/// (acceleration minus gravity, in the body frame).
pub fn imu(s: &RigidState, stamp: Time, body: &str, gravity: f64) -> Imu {
    let q = s.orientation;
    let f =
        q.inverse_transform_vector(&(s.acceleration - nalgebra::Vector3::new(0.0, 0.0, -gravity)));
    Imu {
        header: Header {
            stamp,
            frame_id: body.into(),
        },
        orientation: quat_msg(q),
        orientation_covariance: [0.0; 9],
        angular_velocity: vec3_msg(s.angular_velocity),
        angular_velocity_covariance: [0.0; 9],
        linear_acceleration: vec3_msg(f),
        linear_acceleration_covariance: [0.0; 9],
    }
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
    let motion = motion_source::build(&cfg)?;
    if opts.duration > motion.end_time() {
        anyhow::bail!(
            "--duration {} s: the motion ends at t = {} s",
            opts.duration,
            motion.end_time()
        );
    }
    Ok((cfg, motion))
}

/// Publishes until the duration is reached or SIGINT/SIGTERM.
pub fn run(ros: &RosArgs, config: &str, opts: &MotionOptions) -> anyhow::Result<()> {
    let (cfg, motion) = checked_motion(config, &ros.params, opts)?;
    let names = Names::new(ros, "slosh_motion")?;
    let stop = super::shutdown_flag()?;
    let context = super::context()?;
    let mut node = context
        .new_node(
            NodeName::new(&names.namespace, &names.node)
                .map_err(|e| anyhow::anyhow!("node name: {e:?}"))?,
            NodeOptions::new().enable_rosout(false),
        )
        .map_err(|e| anyhow::anyhow!("cannot create the node: {e:?}"))?;
    let qos = QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Wait(Duration::from_millis(20)))
        .history(History::KeepLast { depth: 5 });
    let pub_odom = super::publisher::<Odometry>(&mut node, &names, "motion/odom", &qos)?;
    let pub_pose = if opts.pose {
        Some(super::publisher::<PoseStamped>(
            &mut node,
            &names,
            "motion/pose",
            &qos,
        )?)
    } else {
        None
    };
    let pub_imu = if opts.imu {
        Some(super::publisher::<Imu>(
            &mut node,
            &names,
            "motion/imu",
            &qos,
        )?)
    } else {
        None
    };
    let pub_accel = if opts.accel {
        Some(super::publisher::<AccelStamped>(
            &mut node,
            &names,
            "motion/accel",
            &qos,
        )?)
    } else {
        None
    };
    let clock = if opts.lockstep {
        Some(super::subscription::<Clock>(
            &mut node,
            &names,
            "/clock",
            &QosProfile::subscription_default().history(History::KeepLast { depth: 5 }),
        )?)
    } else {
        None
    };
    // The topic whose subscribers are waited for: the first one published.
    let odom_topic = names.resolve(if opts.imu && !opts.pose {
        "motion/imu"
    } else {
        "motion/odom"
    })?;
    if opts.wait_for_subscribers > 0 {
        eprintln!(
            "slosh motion: waiting for {} subscriber(s) on {odom_topic}",
            opts.wait_for_subscribers
        );
        while node.subscription_count(&odom_topic) < opts.wait_for_subscribers {
            if stop.load(Ordering::Relaxed) {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(20));
        }
        // Let the matching finish on both sides before the first sample.
        std::thread::sleep(Duration::from_millis(500));
    }
    let start_stamp = opts.start_stamp();
    let n = (opts.duration * opts.rate_hz).round() as u64;
    let lead = 4u64;
    let mut clock_t = f64::NEG_INFINITY;
    let start = Instant::now();
    eprintln!(
        "slosh motion: publishing {} samples (t = 0 to {} s) at {} Hz on {odom_topic}{}",
        n + 1,
        n as f64 / opts.rate_hz,
        opts.rate_hz,
        if opts.lockstep {
            " in lockstep with /clock"
        } else {
            ""
        }
    );
    // Lockstep: whether the simulation has been seen subscribed (once it has gone, nothing will move /clock).
    let mut subscribed = false;
    for k in 0..=n {
        let t = k as f64 / opts.rate_hz;
        if let Some(sub) = &clock {
            // Stay `lead` samples ahead of the simulation.
            let waiting = Instant::now();
            let (mut checked, mut reminded) = (waiting, waiting);
            while k >= lead && clock_t < t - lead as f64 / opts.rate_hz - 1e-9 {
                if stop.load(Ordering::Relaxed) {
                    return Ok(());
                }
                match sub.take() {
                    Ok(Some((c, _))) => clock_t = c.clock.as_secs_f64() - start_stamp,
                    _ => std::thread::sleep(Duration::from_millis(1)),
                }
                if checked.elapsed() > Duration::from_millis(100) {
                    checked = Instant::now();
                    let count = node.subscription_count(&odom_topic);
                    subscribed |= count > 0;
                    if subscribed && count == 0 {
                        eprintln!(
                            "slosh motion: {odom_topic} has no subscriber any more (the simulation ended?): stopping at t = {t:.3} s after {k} of {} samples",
                            n + 1
                        );
                        return Ok(());
                    }
                    if reminded.elapsed() > Duration::from_secs(10) {
                        reminded = Instant::now();
                        eprintln!(
                            "slosh motion: --lockstep: waiting for /clock to pass t = {:.3} s (it reads {}): is the simulation running, in realtime.mode lockstep, on this ROS_DOMAIN_ID?",
                            t - lead as f64 / opts.rate_hz,
                            if clock_t.is_finite() { format!("{clock_t:.3} s") } else { "nothing yet".into() }
                        );
                    }
                }
            }
        } else {
            let due = Duration::from_secs_f64(t);
            let now = start.elapsed();
            if due > now {
                std::thread::sleep(due - now);
            }
        }
        if stop.load(Ordering::Relaxed) {
            break;
        }
        let stamp = Time::from_secs_f64(start_stamp + t);
        let state = motion.state(t);
        let odom = odometry(&state, stamp, "odom", "base_link");
        if let Some(p) = &pub_accel {
            publish(p, accel(&state, stamp, "base_link"), "motion/accel")?;
        }
        if let Some(p) = &pub_imu {
            let m = imu(&state, stamp, "base_link", cfg.config.gravity);
            publish(p, m, "motion/imu")?;
        }
        if let Some(p) = &pub_pose {
            let ps = PoseStamped {
                header: odom.header.clone(),
                pose: odom.pose.pose,
            };
            publish(p, ps, "motion/pose")?;
        }
        publish(&pub_odom, odom, "motion/odom")?;
    }
    // Let reliable readers fetch the last samples.
    std::thread::sleep(Duration::from_millis(300));
    Ok(())
}
