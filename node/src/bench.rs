//! `slosh bench`: particle-steps per second and real-time factor on the project's benchmark cases.

use crate::config;
use serde::Serialize;
use sph::motion::TankMotion;
use std::time::Instant;

/// A benchmark case: a built-in config with overrides and a default simulated time.
pub struct Case {
    pub name: &'static str,
    pub builtin: &'static str,
    pub overrides: &'static [&'static str],
    pub duration: f64,
}

pub const CASES: &[Case] = &[
    Case {
        name: "dambreak_2d",
        builtin: "dambreak_2d",
        overrides: &[],
        duration: 0.6,
    },
    Case {
        name: "seed_2d_dp8mm",
        builtin: "seed_tank_039",
        overrides: &[
            "dimension=2",
            "particle_spacing=0.008",
            "solver.scheme=wcsph",
        ],
        duration: 2.0,
    },
    Case {
        name: "seed_3d_dp20mm",
        builtin: "seed_tank_039",
        overrides: &[
            "dimension=3",
            "particle_spacing=0.02",
            "solver.scheme=wcsph",
        ],
        duration: 1.0,
    },
    Case {
        name: "seed_2d_dp8mm_dfsph",
        builtin: "seed_tank_039",
        overrides: &[
            "dimension=2",
            "particle_spacing=0.008",
            "solver.scheme=dfsph",
        ],
        duration: 10.0,
    },
    Case {
        name: "seed_3d_dp20mm_dfsph",
        builtin: "seed_tank_039",
        overrides: &[
            "dimension=3",
            "particle_spacing=0.02",
            "solver.scheme=dfsph",
        ],
        duration: 5.0,
    },
];

#[derive(Debug, Clone, Serialize)]
pub struct BenchResult {
    pub case: String,
    /// Threads per rank, and MPI ranks (1 without mpirun).
    pub threads: usize,
    pub ranks: usize,
    pub particles_fluid: usize,
    pub particles_boundary: usize,
    pub steps: u64,
    pub sim_time_s: f64,
    pub wall_time_s: f64,
    pub particle_steps_per_s: f64,
    pub realtime_factor: f64,
    pub wall_s_per_sim_s: f64,
    /// Pressure-solver iterations per step (incompressible scheme; 0 for WCSPH).
    pub iterations_per_step: f64,
    /// Steps that ended above the density tolerance, and steps solved again at half the step
    /// (incompressible scheme; `solver.dfsph.target_iterations`).
    pub unconverged_steps: u64,
    pub retried_steps: u64,
    /// Across ranks: particle-steps per second per rank, and the share of rank 0's time spent in MPI calls
    /// (communication and waiting for the other ranks).
    pub particle_steps_per_s_per_rank: f64,
    pub comm_share: f64,
    /// Runs of the case (`--repeat`): the figures above are the run of median wall time's, and these the
    /// fastest and the slowest run's wall times (equal to `wall_time_s` for one run).
    pub repeats: u32,
    pub wall_time_s_min: f64,
    pub wall_time_s_max: f64,
}

/// A case with the overrides `set` applied after its own: its solver parameters and motion, checked.
fn load_case(
    case: &Case,
    set: &[String],
) -> anyhow::Result<(sph::params::SimParams, Box<dyn TankMotion>)> {
    let overrides: Vec<String> = case
        .overrides
        .iter()
        .map(|s| s.to_string())
        .chain(set.iter().cloned())
        .collect();
    let cfg = config::load(case.builtin, &overrides)?;
    let params = cfg.sim_params()?;
    let motion = crate::motion_source::build(&cfg)?;
    Ok((params, motion))
}

/// Checks a case with the overrides `set` (its config, solver parameters and motion) without running it:
/// `slosh bench` refuses a bad `--set` before it prints anything.
pub fn check_case(case: &Case, set: &[String]) -> anyhow::Result<()> {
    load_case(case, set).map(|_| ())
}

/// Runs one case for `duration` simulated seconds (setup excluded from the timing), with `set` (KEY=VALUE)
/// applied after the case's own overrides.
pub fn run_case(case: &Case, duration: Option<f64>, set: &[String]) -> anyhow::Result<BenchResult> {
    let (params, motion) = load_case(case, set)?;
    let mut sim = sph::build(params)?;
    let duration = duration.unwrap_or(case.duration);
    let start = Instant::now();
    let comm0 = sph::domain::comm_seconds();
    sim.advance_to(motion.as_ref(), duration)?;
    let wall = start.elapsed().as_secs_f64();
    let comm = sph::domain::comm_seconds() - comm0;
    let pst = sim.stats().steps as f64 * sim.counts().fluid as f64 / wall;
    let (stats, counts) = (sim.stats(), sim.counts());
    Ok(BenchResult {
        case: case.name.to_string(),
        threads: rayon::current_num_threads(),
        ranks: sim.ranks(),
        particles_fluid: counts.fluid,
        particles_boundary: counts.boundary,
        steps: stats.steps,
        sim_time_s: sim.time(),
        wall_time_s: wall,
        particle_steps_per_s: stats.steps as f64 * counts.fluid as f64 / wall,
        realtime_factor: sim.time() / wall,
        wall_s_per_sim_s: wall / sim.time(),
        iterations_per_step: stats.solver_iterations as f64 / stats.steps.max(1) as f64,
        unconverged_steps: stats.unconverged_steps,
        retried_steps: stats.retried_steps,
        particle_steps_per_s_per_rank: pst / sim.ranks() as f64,
        comm_share: comm / wall,
        repeats: 1,
        wall_time_s_min: wall,
        wall_time_s_max: wall,
    })
}

/// Runs one case `repeats` times (a fresh simulation each time, the same work: the runs take the same steps)
/// and returns the run of median wall time (the slower of the two middle ones for an even count), with the
/// fastest and slowest runs' wall times: on a shared machine one run's speed can be tens of percent off.
pub fn run_repeated(
    case: &Case,
    duration: Option<f64>,
    set: &[String],
    repeats: u32,
) -> anyhow::Result<BenchResult> {
    let mut runs = (0..repeats.max(1))
        .map(|_| run_case(case, duration, set))
        .collect::<anyhow::Result<Vec<_>>>()?;
    if let Some(r) = runs.iter().find(|r| r.steps != runs[0].steps) {
        anyhow::bail!(
            "case {}: runs of the same case took {} and {} steps (they must do the same work)",
            case.name,
            runs[0].steps,
            r.steps
        );
    }
    runs.sort_by(|a, b| a.wall_time_s.total_cmp(&b.wall_time_s));
    let (min, max) = (runs[0].wall_time_s, runs[runs.len() - 1].wall_time_s);
    let n = runs.len();
    let mut median = runs.swap_remove(n / 2);
    median.repeats = n as u32;
    median.wall_time_s_min = min;
    median.wall_time_s_max = max;
    Ok(median)
}
