//! `slosh replay`.

use super::*;

#[derive(clap::Args)]
pub struct Args {
    /// The bag: a rosbag2 folder (metadata.yaml + .mcap files) or a bare .mcap file.
    pub bag: PathBuf,
    /// Config file or built-in case: the tank, liquid, probes, frames (its `motion.*` is not used).
    #[arg(long)]
    pub config: String,
    /// The motion topic (default: the bag's only nav_msgs/Odometry, geometry_msgs/PoseStamped or
    /// sensor_msgs/Imu topic).
    #[arg(long)]
    pub topic: Option<String>,
    /// At most this many simulated seconds per wall-clock second (1 = real time).
    #[arg(long, conflicts_with = "as_fast_as_possible")]
    pub rate: Option<f64>,
    /// As fast as the solver can (the default).
    #[arg(long)]
    pub as_fast_as_possible: bool,
    /// Output folder (default: BAG_replay beside the bag); the new bag goes to OUT/bag unless
    /// `record.path` is set.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Simulated seconds (default: the whole recorded motion).
    #[arg(long, value_parser = positive_seconds)]
    pub duration: Option<f64>,
    /// Override a parameter by its dotted name, value as YAML: --set replay.bad_samples=drop
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    #[command(flatten)]
    pub visuals: Visuals,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args {
        bag,
        config: cfg,
        topic,
        rate,
        as_fast_as_possible: _,
        out,
        duration,
        set,
        visuals,
    } = a;
    let loaded = config::load(&cfg, &set)?;
    let out = out.unwrap_or_else(|| beside(&bag, "_replay"));
    let opts = crate::replay::ReplayOptions {
        topic,
        duration,
        rate,
        progress: true,
        snapshots: visuals.snapshots(&out),
    };
    let s = visuals.plot_after(&out, crate::replay::replay(&bag, &loaded, &out, &opts, |f| {
        eprintln!(
            "slosh: replaying {} ({}, {} of {} messages, {:.3} s, times from {}) through {}, writing to {} and the bag {}",
            f.topic, f.type_name, f.samples, f.messages, f.span_s,
            if f.time_source == "header" { "the header stamps" } else { "the log times" },
            loaded.source_name, out.display(), f.recording
        );
        for d in &f.dropped {
            eprintln!("slosh: dropped {d}");
        }
        if f.input_check.starts_with("input check") {
            eprintln!("slosh: warning: {}", f.input_check);
        }
    }).map_err(Into::into))?;
    println!(
        "done: {:.3} s replayed in {:.1} s (real-time factor {:.3}, {:.2e} particle-steps/s)",
        s.sim_time_s, s.wall_time_s, s.realtime_factor, s.particle_steps_per_s
    );
    println!("outputs: {}", outputs(&out));
    Ok(())
}
