//! Whether a case's particles fit in this machine's memory, checked before anything is allocated: a
//! mistyped `particle_spacing` (1e-5 for 1e-2) must be refused with the key and a spacing that fits, not
//! end in an allocation failure (or the machine swapping) minutes later.

use sph::params::{Scheme, SimParams};

/// Bytes a particle needs at least (measured with `slosh run`'s peak resident memory, less the ~8 MB of a
/// run of a few particles: the 3D seed tank at dp 10 mm, 78,000 liquid and 55,956 wall particles, took 48 MB
/// with `wcsph` and 134 MB with `dfsph`, whose neighbour lists hold ~80 neighbours' gradients per liquid
/// particle in 3D (184 MB with the gradients in single precision); the 2D tank at
/// dp 2 mm, 78,000 and 4,236, 25 and 52 MB): kept below the measured figures, so that a refused case would
/// not have fitted.
fn bytes_per_particle(p: &SimParams) -> (f64, f64) {
    let liquid = match (p.solver.scheme, p.dimension) {
        (Scheme::Dfsph, 3) => 1400.0,
        (Scheme::Dfsph, _) => 450.0,
        (Scheme::Wcsph, 3) => 250.0,
        (Scheme::Wcsph, _) => 180.0,
    };
    (liquid, 100.0)
}

/// The case's estimated memory, bytes.
pub fn estimated_bytes(p: &SimParams) -> f64 {
    let (liquid, walls) = p.estimated_particles();
    let (per_liquid, per_wall) = bytes_per_particle(p);
    liquid * per_liquid + walls * per_wall
}

/// Refuses the case if this machine's share of it (`share`: the fraction of all MPI ranks that run here)
/// needs more than `available` bytes; the message names the estimate and the finest spacing that fits.
pub fn check_with(p: &SimParams, available: f64, share: f64) -> Result<(), String> {
    let need = estimated_bytes(p) * share;
    if need <= available {
        return Ok(());
    }
    let (liquid, walls) = p.estimated_particles();
    let fits = p.particle_spacing * (need / available).powf(1.0 / p.dimension as f64);
    Err(format!(
        "{} m makes about {:.2e} particles ({:.2e} liquid, {:.2e} wall), which need about {:.1} GB{} but this machine has {:.1} GB available: use a particle_spacing of at least {:.2e} m{}",
        p.particle_spacing,
        liquid + walls,
        liquid,
        walls,
        need / 1e9,
        if share < 1.0 { " on this machine (its share of the MPI ranks)" } else { "" },
        available / 1e9,
        fits,
        if share < 1.0 { "" } else { ", or spread the run over machines with MPI" },
    ))
}

/// [`check_with`] against this machine's available memory (`MemAvailable` of /proc/meminfo) and, under
/// `mpirun`, its share of the ranks (Open MPI's and MPICH's environment); no check where the memory cannot
/// be read.
pub fn check(p: &SimParams) -> Result<(), String> {
    match available_bytes() {
        Some(available) => check_with(p, available, rank_share()),
        None => Ok(()),
    }
}

fn available_bytes() -> Option<f64> {
    let info = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = info.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The first of the environment variables `names` that holds a count of at least 1.
fn count_in(names: &[&str]) -> Option<u32> {
    names
        .iter()
        .find_map(|n| std::env::var(n).ok()?.parse::<u32>().ok())
        .filter(|v| *v >= 1)
}

/// How many ranks `mpirun` started, read from its environment (Open MPI's or MPICH's); None outside it.
pub fn mpi_world_size() -> Option<u32> {
    count_in(&["OMPI_COMM_WORLD_SIZE", "PMI_SIZE"])
}

/// The fraction of all ranks that run on this machine (1 outside MPI).
fn rank_share() -> f64 {
    match (
        count_in(&["OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS"]),
        mpi_world_size(),
    ) {
        (Some(local), Some(world)) if local <= world => local as f64 / world as f64,
        _ => 1.0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn case(dimension: usize, dp: f64, scheme: Scheme) -> SimParams {
        let l = crate::config::load("seed_tank_039", &[]).unwrap();
        let mut p = l.sim_params().unwrap();
        p.dimension = dimension;
        p.particle_spacing = dp;
        p.solver.scheme = scheme;
        p
    }

    #[test]
    fn estimate_is_near_the_built_counts() {
        // The 3D seed tank at dp 20 mm builds 10,400 liquid and 15,864 wall particles.
        let (liquid, walls) = case(3, 0.02, Scheme::Dfsph).estimated_particles();
        assert!((liquid / 10_400.0 - 1.0).abs() < 0.05, "{liquid}");
        assert!((walls / 15_864.0 - 1.0).abs() < 0.2, "{walls}");
    }

    #[test]
    fn a_case_that_does_not_fit_names_a_spacing_that_does() {
        let p = case(3, 0.001, Scheme::Dfsph);
        let e = check_with(&p, 24e9, 1.0).unwrap_err();
        assert!(e.contains("0.001 m makes about"), "{e}");
        assert!(e.contains("24.0 GB available"), "{e}");
        let fits: f64 = e
            .rsplit("at least ")
            .next()
            .and_then(|s| s.split(' ').next())
            .unwrap()
            .parse()
            .unwrap();
        let q = case(3, fits * 1.01, Scheme::Dfsph);
        assert!(check_with(&q, 24e9, 1.0).is_ok(), "{fits}");
        // Half the ranks elsewhere: half the memory here.
        assert!(check_with(&p, 24e9, 0.5).is_err());
        assert!(check_with(&case(3, 0.02, Scheme::Dfsph), 24e9, 1.0).is_ok());
    }
}
