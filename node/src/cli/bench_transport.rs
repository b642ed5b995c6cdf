//! `slosh bench-transport`.

#[derive(clap::Args)]
pub struct Args {
    /// Coupling round trips timed per transport.
    #[arg(long, default_value_t = 2000)]
    pub round_trips: usize,
    /// Particles per frame (repeatable).
    #[arg(long, default_values_t = vec![10_000usize, 100_000])]
    pub particles: Vec<usize>,
    /// Frames timed per particle count.
    #[arg(long, default_value_t = 30)]
    pub frames: usize,
    /// Transports (repeatable): iceoryx2, dds.
    #[arg(long, default_values_t = vec!["iceoryx2".to_string(), "dds".to_string()])]
    pub transport: Vec<String>,
    /// Print one JSON object per result instead of tables.
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args {
        round_trips,
        particles,
        frames,
        transport,
        json,
    } = a;
    let (lat, thr) = crate::transport_bench::run(&crate::transport_bench::Options {
        round_trips,
        particles,
        frames,
        transports: transport,
    })?;
    if json {
        for l in &lat {
            println!("{}", serde_json::to_string(l)?);
        }
        for t in &thr {
            println!("{}", serde_json::to_string(t)?);
        }
    } else {
        println!("coupling round trip (motion sample out, outputs back), µs");
        println!(
            "{:<10} {:>8} {:>9} {:>9} {:>9} {:>9}",
            "transport", "trips", "p50", "p90", "p99", "max"
        );
        for l in &lat {
            println!(
                "{:<10} {:>8} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
                l.transport, l.round_trips, l.p50_us, l.p90_us, l.p99_us, l.max_us
            );
        }
        println!("particle frames (32 B per particle, one frame in flight)");
        println!(
            "{:<10} {:>10} {:>10} {:>8} {:>10} {:>10} {:>10}",
            "transport", "particles", "MB/frame", "frames", "frames/s", "MB/s", "ms/frame"
        );
        for t in &thr {
            println!(
                "{:<10} {:>10} {:>10.2} {:>8} {:>10.1} {:>10.1} {:>10.3}",
                t.transport,
                t.particles,
                t.bytes_per_frame as f64 / 1e6,
                t.frames,
                t.frames_per_s,
                t.mb_per_s,
                t.ms_per_frame
            );
        }
    }
    Ok(())
}
