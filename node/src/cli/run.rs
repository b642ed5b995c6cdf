//! `slosh run`.

use super::*;

#[derive(clap::Args)]
pub struct Args {
    /// Config file (ROS 2 parameters layout) or the name of a built-in case (seed_tank_039, dambreak_2d, ...).
    pub config: String,
    /// Output folder.
    #[arg(long)]
    pub out: PathBuf,
    /// Simulated seconds (default: the config's `duration`).
    #[arg(long, value_parser = positive_seconds)]
    pub duration: Option<f64>,
    /// Override a parameter by its dotted name, value as YAML: --set solver.cfl=0.15 --set probes.x=[-0.3,0.0]
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    #[command(flatten)]
    pub visuals: Visuals,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args {
        config: cfg,
        out,
        duration,
        set,
        visuals,
    } = a;
    let loaded = config::load(&cfg, &set)?;
    let opts = runner::RunOptions {
        duration,
        progress: true,
        rate: None,
        snapshots: visuals.snapshots(&out),
    };
    // Said once the case and options have passed their checks and the outputs exist.
    let announce = || {
        eprintln!(
            "slosh: running {} for {} s, writing to {}",
            loaded.source_name,
            duration.unwrap_or(loaded.config.duration),
            out.display()
        )
    };
    let s = visuals.plot_after(
        &out,
        runner::run(&loaded, &out, &opts, announce).map_err(Into::into),
    )?;
    println!(
        "done: {:.3} s simulated in {:.1} s (real-time factor {:.3}, {:.2e} particle-steps/s, {} liquid + {} boundary particles, {} lost)",
        s.sim_time_s, s.wall_time_s, s.realtime_factor, s.particle_steps_per_s, s.particles_fluid, s.particles_boundary, s.particles_lost
    );
    println!("outputs: {}", outputs(&out));
    Ok(())
}
