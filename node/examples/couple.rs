//! A ship-motion solver coupled to `slosh couple` step by step: a barge of mass M on a sway spring k, forced
//! by F sin(ωt), carrying the tank. Each step it sends its state (position, velocity, acceleration) at t and
//! blocks for the liquid's force at t, which enters its own equation of motion:
//!
//!     M x'' = -k x + F sin(ωt) + f_liquid,x(t)
//!
//! Run `slosh couple CASE` first (same SLOSH_IOX_PREFIX / SLOSH_IOX_ROOT if set), then
//!
//!     cargo run --release --example couple -- [--service slosh] [--steps 200] [--dt 0.01] [--start 0] [--bench]
//!
//! (`--start`: the clock of the first sample; a server that already served a client needs a later one).
//!
//! Prints one JSON line per step: t, x, the liquid's fx, probe elevations, solver steps. `--bench` (against
//! `slosh couple --dry`, which answers without simulating) times the round trips of the transport alone.

use slosh_node::iox::client::CouplingClient;
use slosh_node::iox::{MotionSample, STATUS_OK};
use std::time::{Duration, Instant};

fn arg(name: &str, default: &str) -> String {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1).cloned())
        .unwrap_or_else(|| default.to_string())
}

fn main() -> anyhow::Result<()> {
    let service = arg("--service", "slosh");
    let steps: usize = arg("--steps", "200").parse()?;
    let dt: f64 = arg("--dt", "0.01").parse()?;
    let bench = std::env::args().any(|a| a == "--bench");
    let client = CouplingClient::connect(&service, Duration::from_secs(30))?;
    client.wait_for_server(Duration::from_secs(30))?;
    let sample = |t: f64, x: f64, v: f64, a: f64| MotionSample {
        time: t,
        position: [x, 0.0, 0.0],
        orientation: [0.0, 0.0, 0.0, 1.0],
        velocity: [v, 0.0, 0.0],
        acceleration: [a, 0.0, 0.0],
        ..Default::default()
    };
    if bench {
        // Transport alone (against `slosh couple --dry`, which answers without simulating): one round trip
        // per sample.
        let start: f64 = arg("--start", "0").parse()?;
        let mut rtt: Vec<f64> = (0..steps)
            .map(|i| {
                let t = Instant::now();
                client
                    .step(&sample(start + i as f64 * dt, 0.0, 0.0, 0.0))
                    .map(|_| t.elapsed().as_secs_f64() * 1e6)
            })
            .collect::<anyhow::Result<_>>()?;
        rtt.sort_by(f64::total_cmp);
        let q = |p: f64| rtt[((rtt.len() - 1) as f64 * p) as usize];
        println!(
            "{{\"round_trips\":{},\"p50_us\":{:.1},\"p90_us\":{:.1},\"p99_us\":{:.1},\"max_us\":{:.1}}}",
            rtt.len(),
            q(0.5),
            q(0.9),
            q(0.99),
            q(1.0)
        );
        return Ok(());
    }
    // Barge: 2000 kg, sway natural period 1.5 s, forced at 1.2 s.
    let (m, w_n, f, w) = (
        2000.0,
        2.0 * std::f64::consts::PI / 1.5,
        400.0,
        2.0 * std::f64::consts::PI / 1.2,
    );
    let k = m * w_n * w_n;
    let (mut t, mut x, mut v) = (arg("--start", "0").parse::<f64>()?, 0.0f64, 0.0f64);
    let mut fx = 0.0;
    for _ in 0..=steps {
        let a = (-k * x + f * (w * t).sin() + fx) / m;
        let out = client.step(&sample(t, x, v, a))?;
        if out.status != STATUS_OK {
            anyhow::bail!("the server refused t = {t}: {}", out.message());
        }
        fx = out.force[0];
        println!(
            "{{\"t\":{t:.4},\"x\":{x:.6},\"fx\":{:.4},\"probes\":{:?},\"steps\":{}}}",
            out.force[0],
            out.probes(),
            out.steps
        );
        // Semi-implicit Euler with the liquid force of the state at t.
        v += dt * a;
        x += dt * v;
        t += dt;
    }
    Ok(())
}
