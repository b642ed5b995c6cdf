//! A consumer of the iceoryx2 outputs of `slosh node` (with `iceoryx2.outputs` / `iceoryx2.particles`) or
//! `slosh couple`: prints one JSON line per output (time, force, probe elevations) and per particle frame
//! (time, particle counts, the fastest liquid particle), read zero-copy from shared memory.
//!
//!     cargo run --release --example consumer -- [--service slosh] [--outputs 100]
//!
//! Stops after `--outputs` outputs (default: on Ctrl-C). Killing it never disturbs the publisher.

use slosh_node::iox::{node, outputs_service, particles_service};
use std::time::Duration;

fn arg(name: &str, default: &str) -> String {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
        .unwrap_or_else(|| default.to_string())
}

fn main() -> anyhow::Result<()> {
    let service = arg("--service", "slosh");
    let limit: u64 = arg("--outputs", "0").parse()?;
    let node = node("slosh_consumer")?;
    let outputs = outputs_service(&node, &service)?
        .subscriber_builder()
        .create()?;
    let particles = particles_service(&node, &service)?
        .subscriber_builder()
        .create()?;
    let stop = slosh_node::signals::shutdown_flag()?;
    let mut seen = 0u64;
    eprintln!("consumer: reading {service}/outputs and {service}/particles");
    while !stop.load(std::sync::atomic::Ordering::Relaxed) && (limit == 0 || seen < limit) {
        let mut idle = true;
        while let Some(o) = outputs.receive()? {
            idle = false;
            seen += 1;
            println!(
                "{{\"t\":{:.6},\"force\":{:?},\"probes\":{:?},\"steps\":{}}}",
                o.time,
                o.force,
                o.probes(),
                o.steps
            );
        }
        while let Some(f) = particles.receive()? {
            idle = false;
            let h = *f.user_header();
            let fastest = f.payload()[..h.fluid as usize]
                .iter()
                .map(|p| p.velocity.iter().map(|v| v * v).sum::<f32>().sqrt())
                .fold(0.0f32, f32::max);
            println!(
                "{{\"frame_t\":{:.6},\"particles\":{},\"fluid\":{},\"max_speed\":{fastest:.4}}}",
                h.time,
                f.payload().len(),
                h.fluid
            );
        }
        if idle {
            std::thread::sleep(Duration::from_millis(1));
        }
    }
    Ok(())
}
