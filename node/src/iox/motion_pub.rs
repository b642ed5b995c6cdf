//! `slosh motion CASE --iceoryx2 NAME`: the case's synthetic motion as [`MotionSample`]s on `NAME/motion`,
//! paced by the wall clock, for a node with `input.type: iceoryx2` (no DDS involved).

use super::*;
use crate::motion_source::{checked_motion, MotionOptions};
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
    let (_, motion) = checked_motion(config, params, opts)?;
    let node = node("slosh_motion")?;
    let svc = motion_service(&node, service)?;
    let publisher = svc.publisher_builder().create()?;
    let stop = crate::signals::shutdown_flag().map_err(std::io::Error::other)?;
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
    let start_stamp = opts.start_stamp();
    let n = (opts.duration * opts.rate_hz).round() as u64;
    eprintln!(
        "slosh motion: publishing {} samples (t = 0 to {} s) at {} Hz on iceoryx2 {service}/motion",
        n + 1,
        n as f64 / opts.rate_hz,
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
