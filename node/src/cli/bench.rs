//! `slosh bench`.

use super::*;
use anyhow::Context;

#[derive(clap::Args)]
pub struct Args {
    /// Only this case (dambreak_2d, seed_2d_dp8mm, seed_3d_dp20mm, seed_2d_dp8mm_dfsph,
    /// seed_3d_dp20mm_dfsph); default: all.
    #[arg(long)]
    pub case: Vec<String>,
    /// Simulated seconds per case (default: each case's own).
    #[arg(long, value_parser = positive_seconds)]
    pub duration: Option<f64>,
    /// Override a setting of every case after its own (`--set solver.dfsph.max_density_error=1e-3`).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// Print one JSON object per case instead of a table.
    #[arg(long)]
    pub json: bool,
    /// Run each case this many times and report the run of median wall time, with the fastest and
    /// slowest (a shared machine's speed can wander by tens of percent between runs).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
    pub repeat: u32,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args {
        case,
        duration,
        set,
        json,
        repeat,
    } = a;
    let cases: Vec<&crate::bench::Case> = if case.is_empty() {
        crate::bench::CASES.iter().collect()
    } else {
        case.iter()
            .map(|c| {
                crate::bench::CASES
                    .iter()
                    .find(|k| k.name == c)
                    .with_context(|| {
                        format!(
                            "unknown case {c}; cases: {}",
                            crate::bench::CASES
                                .iter()
                                .map(|k| k.name)
                                .collect::<Vec<_>>()
                                .join(", ")
                        )
                    })
            })
            .collect::<anyhow::Result<_>>()?
    };
    // Every case checked first: a bad --set leaves no half table on stdout.
    for c in &cases {
        crate::bench::check_case(c, &set).with_context(|| format!("case {}", c.name))?;
    }
    if !json {
        println!(
            "{:<22} {:>5} {:>7} {:>9} {:>8} {:>8} {:>10} {:>14} {:>10} {:>12} {:>7}",
            "case",
            "ranks",
            "threads",
            "particles",
            "steps",
            "sim s",
            "wall s",
            "particle-st/s",
            "RT factor",
            "wall s/sim s",
            "comm %"
        );
    }
    for c in cases {
        let r = crate::bench::run_repeated(c, duration, &set, repeat)?;
        if json {
            println!("{}", serde_json::to_string(&r)?);
        } else {
            // With --repeat: the median run, and the real-time factors of the slowest and fastest.
            let range = if r.repeats > 1 {
                format!(
                    "  ({} runs: RT factor {:.4}–{:.4})",
                    r.repeats,
                    r.sim_time_s / r.wall_time_s_max,
                    r.sim_time_s / r.wall_time_s_min
                )
            } else {
                String::new()
            };
            println!(
                "{:<22} {:>5} {:>7} {:>9} {:>8} {:>8.3} {:>10.2} {:>14.3e} {:>10.4} {:>12.1} {:>7.1}{range}",
                r.case,
                r.ranks,
                r.threads,
                r.particles_fluid,
                r.steps,
                r.sim_time_s,
                r.wall_time_s,
                r.particle_steps_per_s,
                r.realtime_factor,
                r.wall_s_per_sim_s,
                100.0 * r.comm_share
            );
        }
    }
    Ok(())
}
