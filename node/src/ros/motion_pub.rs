//! `slosh motion`: publishes synthetic vessel motion (the config's `motion.*`: regular, irregular JONSWAP or a
//! CSV file) as nav_msgs/Odometry on `motion/odom`, and optionally geometry_msgs/PoseStamped on `motion/pose`,
//! for headless CI and demos. Paced by the wall clock, or in lockstep with a simulation's `/clock`.

use super::args::{Names, RosArgs};
use super::logging::{LogLevel, Logger};
use super::publish;
use crate::messages::motion::{accel, imu, odometry};
use crate::motion_source::{checked_motion, MotionOptions};
use ros2_client::qos::{History, WhenFull};
use ros2_client::{NodeName, NodeOptions, QosProfile};
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::geometry_msgs::{AccelStamped, PoseStamped};
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::rosgraph_msgs::Clock;
use slosh_msgs::sensor_msgs::Imu;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

/// Publishes until the duration is reached or SIGINT/SIGTERM.
pub fn run(ros: &RosArgs, config: &str, opts: &MotionOptions) -> anyhow::Result<()> {
    let (cfg, motion) = checked_motion(config, &ros.params, opts)?;
    let names = Names::new(ros, "slosh_motion")?;
    let log = Logger::new(ros, &names);
    let stop = crate::signals::shutdown_flag()?;
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
        log.say(
            LogLevel::Info,
            &format!(
                "waiting for {} subscriber(s) on {odom_topic}",
                opts.wait_for_subscribers
            ),
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
    log.say(
        LogLevel::Info,
        &format!(
            "publishing {} samples (t = 0 to {} s) at {} Hz on {odom_topic}{}",
            n + 1,
            n as f64 / opts.rate_hz,
            opts.rate_hz,
            if opts.lockstep {
                " in lockstep with /clock"
            } else {
                ""
            }
        ),
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
                        log.say(LogLevel::Info, &format!(
                            "{odom_topic} has no subscriber any more (the simulation ended?): stopping at t = {t:.3} s after {k} of {} samples",
                            n + 1
                        ));
                        return Ok(());
                    }
                    if reminded.elapsed() > Duration::from_secs(10) {
                        reminded = Instant::now();
                        log.say(LogLevel::Warn, &format!(
                            "--lockstep: waiting for /clock to pass t = {:.3} s (it reads {}): is the simulation running, in realtime.mode lockstep, on this ROS_DOMAIN_ID?",
                            t - lead as f64 / opts.rate_hz,
                            if clock_t.is_finite() { format!("{clock_t:.3} s") } else { "nothing yet".into() }
                        ));
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
