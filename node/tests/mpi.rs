//! `mpirun -n N slosh ...` (OpenMPI; built with `--features mpi`): the liquid decomposed over ranks gives
//! the serial run's outputs, conserves the particles, reports its world size, and fails as one program.

mod common;

use common::{csv, mpirun, slosh};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const CASE: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../launch-configs/seed_tank_019.yaml"
);

/// `slosh run CASE --out OUT args...` by `cmd` (plain or under mpirun).
fn run_by(mut cmd: Command, out: &Path, args: &[&str]) -> Output {
    cmd.args(["run", CASE, "--out"])
        .arg(out)
        .args(args)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap()
}

/// [`run_by`], which must succeed.
fn run(cmd: Command, out: &Path, args: &[&str]) -> Output {
    let o = run_by(cmd, out, args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    o
}

fn summary(out: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

/// Asserts that two runs' CSV files agree: the same times and columns, values within `tol` times the
/// column's largest magnitude (CSV values carry 7 significant digits).
fn same_csv(a: &Path, b: &Path, tol: f64) {
    let (ha, ra) = csv(a);
    let (hb, rb) = csv(b);
    assert_eq!(ha, hb);
    assert_eq!(ra.len(), rb.len(), "{} rows", b.display());
    for c in 0..ha.len() {
        let scale = ra.iter().map(|r| r[c].abs()).fold(1e-12, f64::max);
        for (x, y) in ra.iter().zip(&rb) {
            assert!(
                (x[c] - y[c]).abs() <= tol * scale,
                "{} column {} at t = {}: {} serial, {} across ranks",
                b.display(),
                ha[c],
                x[0],
                x[c],
                y[c]
            );
        }
    }
}

/// The 2D seed tank at dp = 20 mm for 1.5 s, its motion ramped up in 0.2 s.
const SLOSH_2D: [&str; 8] = [
    "--duration",
    "1.5",
    "--set",
    "dimension=2",
    "--set",
    "particle_spacing=0.02",
    "--set",
    "motion.ramp_time=0.2",
];

fn tmp(name: &str) -> PathBuf {
    common::tmp(&format!("mpi-{name}"))
}

/// Sloshing in the seed tank (2D, the irregular motion of the case, ramped up in 0.2 s) on 1, 2 and 3
/// ranks: the decomposition reproduces the serial run (probes and sensors exactly, the wrench up to the
/// order of its sums), keeps every particle and its mass, rebalances the slabs as the liquid moves, and
/// says on how many ranks it ran.
#[test]
fn sloshing_on_one_two_and_three_ranks_equals_the_serial_run() {
    let dir = tmp("2d");
    let args = SLOSH_2D;
    let serial = dir.join("serial");
    run(slosh(), &serial, &args);
    let s = summary(&serial);
    assert_eq!(s["mpi_ranks"], 1);
    // The motion must move the liquid for the comparison to mean something.
    let (_, probes) = csv(&serial.join("probes.csv"));
    let swing = probes.iter().map(|r| r[1]).fold(f64::MIN, f64::max)
        - probes.iter().map(|r| r[1]).fold(f64::MAX, f64::min);
    assert!(swing > 0.02, "the probe near the wall moved {swing} m");
    for ranks in 1..=3 {
        let out = dir.join(format!("ranks{ranks}"));
        let o = run(mpirun(ranks), &out, &args);
        let m = summary(&out);
        // The world size: a binary started by another launcher would be `ranks` serial runs of 1.
        assert_eq!(
            m["mpi_ranks"],
            ranks,
            "{}",
            String::from_utf8_lossy(&o.stderr)
        );
        for k in [
            "particles_fluid",
            "particles_boundary",
            "particles_lost",
            "liquid_mass_kg",
            "steps",
            "sim_time_s",
        ] {
            assert_eq!(m[k], s[k], "{k} on {ranks} ranks");
        }
        same_csv(&serial.join("probes.csv"), &out.join("probes.csv"), 0.0);
        same_csv(&serial.join("pressure.csv"), &out.join("pressure.csv"), 0.0);
        same_csv(&serial.join("wrench.csv"), &out.join("wrench.csv"), 1e-6);
        if ranks == 3 {
            assert!(
                m["rebalances"].as_u64().unwrap() > 0,
                "the liquid moved from wall to wall but the slabs never followed: {m}"
            );
        }
        // Only rank 0 wrote (one progress line per run, not one per rank).
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(err.matches("slosh: running").count(), 1, "{err}");
    }
    // The Verlet integrator (one evaluation a step, the previous step's densities carried along) too.
    let verlet: Vec<&str> = args
        .iter()
        .copied()
        .chain(["--set", "solver.integrator=verlet"])
        .collect();
    let serial = dir.join("verlet_serial");
    run(slosh(), &serial, &verlet);
    let out = dir.join("verlet_ranks3");
    run(mpirun(3), &out, &verlet);
    assert!(summary(&out)["rebalances"].as_u64().unwrap() > 0);
    same_csv(&serial.join("probes.csv"), &out.join("probes.csv"), 0.0);
    same_csv(&serial.join("wrench.csv"), &out.join("wrench.csv"), 1e-6);
}

/// 3D: the seed tank on 2 ranks against the serial run, with each scheme.
#[test]
fn three_dimensional_tank_on_two_ranks_equals_the_serial_run() {
    // Both schemes: the incompressible one keeps 3D velocities in four lanes too, refreshed after each
    // halo exchange.
    for scheme in ["wcsph", "dfsph"] {
        let dir = tmp(&format!("3d_{scheme}"));
        let set_scheme = format!("solver.scheme={scheme}");
        let args = [
            "--duration",
            "0.4",
            "--set",
            "particle_spacing=0.04",
            "--set",
            "motion.ramp_time=0.1",
            "--set",
            &set_scheme,
        ];
        let serial = dir.join("serial");
        run(slosh(), &serial, &args);
        let out = dir.join("ranks2");
        run(mpirun(2), &out, &args);
        let (s, m) = (summary(&serial), summary(&out));
        assert_eq!(s["dimension"], 3);
        assert_eq!(m["mpi_ranks"], 2);
        for k in [
            "particles_fluid",
            "particles_lost",
            "steps",
            "liquid_mass_kg",
            "pressure_solver",
        ] {
            assert_eq!(m[k], s[k], "{k} ({scheme})");
        }
        same_csv(&serial.join("probes.csv"), &out.join("probes.csv"), 0.0);
        same_csv(&serial.join("wrench.csv"), &out.join("wrench.csv"), 1e-6);
    }
}

/// The incompressible scheme on 2 and 3 ranks: its pressure iterations exchange the halos' pressures and
/// velocities and stop on the error over all ranks, so again the serial run's outputs.
#[test]
fn incompressible_scheme_on_two_and_three_ranks_equals_the_serial_run() {
    let dir = tmp("dfsph");
    let args: Vec<&str> = SLOSH_2D
        .iter()
        .copied()
        .chain([
            "--set",
            "solver.scheme=dfsph",
            // A floor sensor mid-tank, where the cut between two ranks falls: it reads wall particles
            // on both sides of the cut.
            "--set",
            "pressure_sensors={names: [left, floor], x: [-0.4, 0.0], y: [0.0, 0.0], z: [0.1, 0.0]}",
        ])
        .collect();
    let serial = dir.join("serial");
    run(slosh(), &serial, &args);
    let s = summary(&serial);
    assert!(
        s["pressure_solver"]["iterations"].as_u64().unwrap() > 0,
        "{s}"
    );
    for ranks in [2, 3] {
        let out = dir.join(format!("ranks{ranks}"));
        run(mpirun(ranks), &out, &args);
        let m = summary(&out);
        assert_eq!(m["mpi_ranks"], ranks);
        for k in [
            "particles_fluid",
            "particles_lost",
            "steps",
            "liquid_mass_kg",
        ] {
            assert_eq!(m[k], s[k], "{k} on {ranks} ranks");
        }
        // The same iterations: the solver's error is summed in integers, independent of the order.
        assert_eq!(m["pressure_solver"], s["pressure_solver"], "{ranks} ranks");
        same_csv(&serial.join("probes.csv"), &out.join("probes.csv"), 0.0);
        // Wall sensors sum over the ranks' wall particles: equal up to the order of the sums.
        same_csv(
            &serial.join("pressure.csv"),
            &out.join("pressure.csv"),
            1e-6,
        );
        same_csv(&serial.join("wrench.csv"), &out.join("wrench.csv"), 1e-6);
    }
}

/// A failure on the ranks (here the time step collapsing at once) stops every rank; rank 0 reports it
/// once and finishes the outputs. Too many ranks for the tank is refused with the most it takes, and the
/// mDBC walls, which run in one process, by name.
#[test]
fn a_failure_stops_all_ranks_and_is_reported_once() {
    let dir = tmp("fail");
    let out = dir.join("collapse");
    let o = run_by(
        mpirun(2),
        &out,
        &[
            "--duration",
            "0.2",
            "--set",
            "dimension=2",
            "--set",
            "particle_spacing=0.02",
            "--set",
            "solver.dt_min=1.0",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success(), "{err}");
    assert_eq!(err.matches("time step collapsed").count(), 1, "{err}");
    let s = summary(&out);
    assert!(
        s["error"].as_str().unwrap().contains("time step collapsed"),
        "{s}"
    );
    assert_eq!(s["mpi_ranks"], 2);
    // The first output row (t = 0) was written before the failure and the files were finished.
    assert_eq!(csv(&out.join("probes.csv")).1.len(), 1);

    // A 0.12 m tank is 14 neighbour-grid columns long with its walls: at most 7 slabs of 2 columns.
    let o = run_by(
        mpirun(8),
        &dir.join("narrow"),
        &[
            "--duration",
            "0.1",
            "--set",
            "dimension=2",
            "--set",
            "tank.length=0.12",
            "--set",
            "particle_spacing=0.02",
            "--set",
            "probes.x=[0.0,0.01]",
            "--set",
            "pressure_sensors.x=[-0.06,0.06]",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("run on at most 7 ranks"), "{err}");

    // The mDBC walls read the liquid at their images, which a rank's halo does not hold: refused by name.
    let o = run_by(
        mpirun(2),
        &dir.join("mdbc"),
        &[
            "--duration",
            "0.1",
            "--set",
            "dimension=2",
            "--set",
            "particle_spacing=0.02",
            "--set",
            "solver.scheme=wcsph",
            "--set",
            "solver.boundary.method=mdbc",
        ],
    );
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("solver.boundary.method: mdbc") && err.contains("`dynamic` or `mirror`"),
        "{err}"
    );
}

/// A damaged box (the paper's case A at twice the size, dp = 5 mm) floating across the cut between two
/// ranks: each rank sums its own liquid's force on the box, so the box moves as in one process, up to the
/// order of those sums; with both schemes (the incompressible one's warm start reads columns of liquid that
/// the cut divides).
#[test]
fn a_floating_box_across_ranks_moves_as_in_one_process() {
    for scheme in ["wcsph", "dfsph"] {
        floating_box_across_ranks(scheme);
    }
}

fn floating_box_across_ranks(scheme: &str) {
    let solver = format!("solver.scheme={scheme}");
    let args = [
        "--duration",
        "0.25",
        "--set",
        "particle_spacing=0.005",
        "--set",
        "bodies.box={size: [0.2, 0.2, 0.2], wall_thickness: 0.015, position: [0.0, 0.0, 0.05], mass: 30.0, inertia: [0.3, 0.3, 0.3], centre_of_gravity: [0.0, 0.0, 0.05], angular_velocity: [0.0, 0.3, 0.0], openings: {damage: {centre: [0.0, 0.0, 0.0075], size: [0.02, 1.0, 0.03]}}}",
        "--set",
        "output_rate_hz=40",
        "--set",
        &solver,
    ];
    let case = |mut cmd: Command, out: &Path| {
        let o = cmd
            .args(["run", "flooding_case_a", "--out"])
            .arg(out)
            .args(args)
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let (serial, two) = (
        tmp(&format!("bodies-1-{scheme}")),
        tmp(&format!("bodies-2-{scheme}")),
    );
    case(slosh(), &serial);
    case(mpirun(2), &two);
    assert_eq!(summary(&two)["mpi_ranks"], 2);
    assert_eq!(
        summary(&two)["particles_fluid"],
        summary(&serial)["particles_fluid"]
    );
    let (h, a) = common::bodies_csv(&serial.join("bodies.csv"));
    let (_, b) = common::bodies_csv(&two.join("bodies.csv"));
    assert_eq!(a.len(), b.len());
    let col = |name: &str| h.iter().position(|c| c == name).unwrap() - 1;
    let mut worst = [0.0f64; 3];
    for ((_, x), (_, y)) in a.iter().zip(&b) {
        for (w, c) in worst.iter_mut().zip(["z", "pitch", "flooded_volume"]) {
            *w = w.max((x[col(c)] - y[col(c)]).abs());
        }
    }
    println!(
        "{scheme}, serial vs 2 ranks: z {:.2e} m, pitch {:.2e} rad, flooded {:.2e} m²",
        worst[0], worst[1], worst[2]
    );
    let last = &a[a.len() - 1].1;
    assert!(last[col("flooded_volume")] > 1e-4 && last[col("pitch")].abs() > 1e-3);
    assert!(worst[0] < 1e-5 && worst[1] < 1e-4 && worst[2] < 1e-3 * last[col("flooded_volume")]);
}
