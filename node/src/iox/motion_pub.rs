//! `slosh motion CASE --iceoryx2 NAME`: the case's synthetic motion as [`MotionSample`]s on `NAME/motion`,
//! paced by the wall clock, for a node with `input.type: iceoryx2` (no DDS involved).

use super::*;
use crate::motion_source;
use crate::ros::motion_pub::MotionOptions;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

pub fn run(
    config: &str,
    params: &[String],
    service: &str,
    opts: &MotionOptions,
) -> anyhow::Result<()> {
    if opts.lockstep || opts.pose || opts.imu || opts.accel {
        anyhow::bail!(
            "--iceoryx2: --lockstep, --pose, --imu and --accel are DDS options; an iceoryx2 sample carries the full state"
        );
    }
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
    let cfg = crate::config::load(config, params)?;
    let motion = motion_source::build(&cfg)?;
    if opts.duration > motion.end_time() {
        anyhow::bail!(
            "--duration {} s: the motion ends at t = {} s",
            opts.duration,
            motion.end_time()
        );
    }
    let node = node("slosh_motion")?;
    let svc = motion_service(&node, service)?;
    let publisher = svc.publisher_builder().create()?;
    let stop = crate::ros::shutdown_flag().map_err(std::io::Error::other)?;
    if opts.wait_for_subscribers > 0 {
        eprintln!(
            "slosh motion: waiting for {} subscriber(s) on iceoryx2 {service}/motion",
            opts.wait_for_subscribers
        );
        while svc.dynamic_config().number_of_subscribers() < opts.wait_for_subscribers {
            if stop.load(Ordering::Relaxed) {
                return Ok(());
            }
            std::thread::sleep(Duration::from_millis(10));
        }
    }
    let start_stamp = opts.start_stamp.unwrap_or_else(|| {
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map(|d| d.as_secs_f64())
            .unwrap_or(0.0)
    });
    let n = (opts.duration * opts.rate_hz).round() as u64;
    eprintln!(
        "slosh motion: publishing {n} samples at {} Hz on iceoryx2 {service}/motion",
        opts.rate_hz
    );
    let start = Instant::now();
    for k in 0..=n {
        let t = k as f64 / opts.rate_hz;
        let due = Duration::from_secs_f64(t);
        let now = start.elapsed();
        if due > now {
            std::thread::sleep(due - now);
        }
        if stop.load(Ordering::Relaxed) {
            break;
        }
        publisher
            .send_copy(sample_of(start_stamp + t, &motion.state(t)))
            .map_err(|e| anyhow::anyhow!("publishing on {service}/motion: {e}"))?;
    }
    Ok(())
}
