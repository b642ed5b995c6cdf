//! End to end: the `slosh` binary as a user runs it.

mod common;

use common::{csv, slosh};
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("slosh-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

#[test]
fn run_writes_the_documented_outputs() {
    let out = tmp("run");
    let st = slosh()
        .args(["run", "../launch-configs/seed_tank_019.yaml", "--out"])
        .arg(&out)
        .args([
            "--duration",
            "0.2",
            "--set",
            "dimension=2",
            "--set",
            "particle_spacing=0.02",
            "--set",
            "output_rate_hz=20",
        ])
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    assert!(String::from_utf8_lossy(&st.stdout).contains(&out.display().to_string()));
    let (h, rows) = csv(&out.join("probes.csv"));
    assert_eq!(h, ["time", "p25", "p180"]);
    assert_eq!(rows.len(), 5, "rows at 0, 0.05, ..., 0.2 s");
    assert!(
        rows.iter()
            .all(|r| (r[1] - 0.19).abs() < 0.02 && (r[2] - 0.19).abs() < 0.02),
        "{rows:?}"
    );
    let (h, rows) = csv(&out.join("wrench.csv"));
    assert_eq!(h, ["time", "fx", "fy", "fz", "mx", "my", "mz"]);
    // A 2D run has no fy, mx, mz: written as plain zeros, not negative ones.
    let text = std::fs::read_to_string(out.join("wrench.csv")).unwrap();
    assert!(!text.contains("-0.000000e0"), "{text}");
    // Liquid weight 0.8 x 0.25 x 0.19 x 1000 x 9.81 = 372.8 N, downwards (the first row is the initial state).
    let fz = rows.last().unwrap()[3];
    assert!((fz + 372.8).abs() < 0.05 * 372.8, "fz {fz}");
    let (h, _) = csv(&out.join("pressure.csv"));
    assert_eq!(h, ["time", "wall_left_0.10", "wall_right_0.10"]);
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    for k in [
        "dimension",
        "particles_fluid",
        "particles_boundary",
        "steps",
        "sim_time_s",
        "wall_time_s",
        "realtime_factor",
        "particle_steps_per_s",
    ] {
        assert!(s.get(k).is_some(), "summary lacks {k}");
    }
    assert_eq!(s["dimension"], 2);
    assert!(s["sim_time_s"].as_f64().unwrap() >= 0.2);
    // The case as run: --duration in place of the file's 20 s.
    assert_eq!(s["parameters"]["duration"], 0.2);
    assert_eq!(s["parameters"]["particle_spacing"], 0.02);
    // Every parameter as run, the ones not given included: the defaults, the scheme's kernel gradient and
    // the speed of sound the solver derived (not given: 0 in the file's terms).
    let e = &s["effective_parameters"];
    assert_eq!(e["duration"], 0.2);
    assert_eq!(e["particle_spacing"], 0.02);
    assert!(s["parameters"]["solver"]["dfsph"].is_null(), "{s}");
    assert_eq!(e["solver"]["dfsph"]["max_density_error"], 1e-4, "{e}");
    assert!(s["parameters"]["motion_timeout_s"].is_null(), "{s}");
    assert!(e["motion_timeout_s"].as_f64().unwrap() > 0.0, "{e}");
    assert_eq!(e["motion"]["irregular"]["seed"], 2);
    // (The case's incompressible scheme takes the cubic spline's gradient with Thomas & Couchman's
    // correction; the paper's scheme the exact one.)
    assert_eq!(e["solver"]["scheme"], "dfsph", "{e}");
    assert_eq!(e["solver"]["kernel_gradient"], "thomas_couchman", "{e}");
    let c0 = e["solver"]["sound_speed"].as_f64().unwrap();
    assert!(c0 > 10.0 && c0 < 100.0, "{c0}");
    assert!(e["output_rate_hz"].as_f64().unwrap() > 0.0);
    assert!(s["error"].is_null());
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn bad_parameters_fail_with_the_key_named() {
    let out = tmp("bad");
    let o = slosh()
        .args(["run", "../launch-configs/seed_tank_039.yaml", "--out"])
        .arg(&out)
        .args(["--set", "solver.kernel=gaussian"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("solver.kernel") && e.contains("cubic_spline") && e.contains("wendland"),
        "{e}"
    );
    let o = slosh()
        .args(["run", "no_such_case", "--out"])
        .arg(&out)
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("built-in cases"));
}

/// A pressure sensor beside a wall but off it runs, and the run says what it reads and where on the wall it
/// would read the wall; on the wall, nothing is said.
#[test]
fn a_sensor_beside_a_wall_but_off_it_is_warned_about() {
    let run = |x: &str| {
        let out = tmp(&format!("beside_{x}"));
        let o = slosh()
            .args(["run", "spheric10", "--duration", "0.01", "--out"])
            .arg(&out)
            .args(["--set", "particle_spacing=0.008"])
            .args(["--set", &format!("pressure_sensors.x=[{x}]")])
            .args(["--set", "solver.scheme=dfsph"])
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        assert!(out.join("pressure.csv").exists());
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let e = run("-0.44");
    assert!(
        e.contains(
            "warning: pressure_sensors: sensor 0 (sensor1) is 10.0 mm from the tank's -x wall"
        ) && e.contains("pressure_sensors.x to -0.45"),
        "{e}"
    );
    let e = run("-0.45");
    assert!(!e.contains("warning"), "{e}");
}

#[test]
fn csv_motion_drives_the_tank_and_bad_rows_are_reported_by_line() {
    let dir = tmp("csv");
    std::fs::create_dir_all(&dir).unwrap();
    // Sway at 1 Hz, 1 cm, sampled at 100 Hz, far from the world origin.
    let mut text = String::from("time,x,y,z,roll,pitch,yaw\n");
    for i in 0..=100 {
        let t = i as f64 * 0.01;
        text += &format!(
            "{t},{},2000.0,0.0,0.0,0.0,0.0\n",
            1000.0 + 0.01 * (2.0 * std::f64::consts::PI * t).sin()
        );
    }
    std::fs::write(dir.join("motion.csv"), &text).unwrap();
    let cfg = "slosh:\n  ros__parameters:\n    dimension: 2\n    tank: {length: 0.4, breadth: 0.1, height: 0.3}\n    fill_height: 0.1\n    particle_spacing: 0.02\n    motion: {source: csv, file: motion.csv}\n";
    std::fs::write(dir.join("case.yaml"), cfg).unwrap();
    let o = slosh()
        .arg("run")
        .arg(dir.join("case.yaml"))
        .arg("--out")
        .arg(dir.join("out"))
        .args(["--duration", "0.5"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let (_, rows) = csv(&dir.join("out/wrench.csv"));
    // The sway accelerates the liquid: a horizontal force appears.
    assert!(rows.iter().any(|r| r[1].abs() > 0.5), "no horizontal force");
    // Asking for more than the motion covers is refused up front.
    let o = slosh()
        .arg("run")
        .arg(dir.join("case.yaml"))
        .arg("--out")
        .arg(dir.join("out2"))
        .args(["--duration", "2"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    assert!(String::from_utf8_lossy(&o.stderr).contains("motion ends at t = 1.000 s"));
    // A duplicated time stamp is reported with its line.
    std::fs::write(dir.join("motion.csv"), text.replace("0.05,", "0.04,")).unwrap();
    let o = slosh()
        .arg("run")
        .arg(dir.join("case.yaml"))
        .arg("--out")
        .arg(dir.join("out3"))
        .args(["--duration", "0.5"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("motion.csv: line 7") && e.contains("times must increase"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_solver_failure_keeps_the_outputs_written_so_far() {
    let out = tmp("fail");
    // A violent shake with a far too large Courant number for the weakly-compressible scheme's acoustic
    // step: the run blows up, and says so.
    let o = slosh()
        .args(["run", "../launch-configs/seed_tank_019.yaml", "--out"])
        .arg(&out)
        .args([
            "--duration",
            "3",
            "--set",
            "solver.scheme=wcsph",
            "--set",
            "dimension=2",
            "--set",
            "particle_spacing=0.02",
            "--set",
            "solver.cfl=1.0",
            "--set",
            "solver.dt_max=0.01",
        ])
        .args([
            "--set",
            "motion.source=regular",
            "--set",
            "motion.regular.amplitude=[0.3,0,0,0,0.3,0]",
            "--set",
            "motion.regular.period=[0.3,0,0,0,0.3,0]",
        ])
        .output()
        .unwrap();
    assert!(!o.status.success(), "expected a failure");
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("solver stopped") && e.contains("outputs up to t ="),
        "{e}"
    );
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    assert!(s["error"].is_string());
    let (_, rows) = csv(&out.join("probes.csv"));
    assert!(!rows.is_empty());
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn node_rejects_a_bad_parameter_at_startup_naming_it() {
    let out = slosh()
        .args([
            "node",
            "--ros-args",
            "--params-file",
            "../launch-configs/seed_tank_039.yaml",
            "-p",
            "solver.kernal:=wendland",
        ])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("solver.kernal") && err.contains("kernel"),
        "{err}"
    );
    let out = slosh()
        .args(["node", "--ros-args", "-r", "__ns:=ship1"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("__ns"));
    let out = slosh()
        .args([
            "node",
            "seed_tank_039",
            "--ros-args",
            "-p",
            "motion_timeout_s:=-1",
        ])
        .env("ROS_DOMAIN_ID", "999")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("motion_timeout_s"), "{err}");
    for (p, key) in [
        (
            "diagnostics_rate_hz:=-1",
            "diagnostics_rate_hz: must be a positive",
        ),
        (
            "diagnostics_rate_hz:=0",
            "diagnostics_rate_hz: must be a positive",
        ),
        (
            "particles.rate_hz:=-5",
            "particles.rate_hz: must be zero (off) or",
        ),
    ] {
        let out = slosh()
            .args(["node", "seed_tank_039", "--ros-args", "-p", p])
            .env("ROS_DOMAIN_ID", "999")
            .output()
            .unwrap();
        assert!(!out.status.success(), "{p} accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(key), "{p}: {err}");
    }
}

#[test]
fn the_incompressible_scheme_runs_and_reports_its_pressure_solver() {
    let out = tmp("dfsph");
    let o = slosh()
        .args(["run", "seed_tank_019", "--out"])
        .arg(&out)
        .args(["--duration", "1.0"])
        .args(["--set", "dimension=2", "--set", "particle_spacing=0.02"])
        .args(["--set", "solver.scheme=dfsph"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap();
    let ps = &s["pressure_solver"];
    assert_eq!(ps["unconverged_steps"], 0, "{ps}");
    assert!(ps["max_density_error"].as_f64().unwrap() <= ps["tolerance"].as_f64().unwrap());
    assert!(ps["iterations_per_step"].as_f64().unwrap() >= 2.0);
    // Steps follow the flow speed: far fewer than the weakly-compressible scheme's ~4,000 a second here.
    assert!(s["steps"].as_u64().unwrap() < 1000, "{s}");
    // ... and land on the output times (50 Hz, steps of up to 5 ms): rows at exactly k / 50 s.
    let rows = csv(&out.join("wrench.csv")).1;
    assert_eq!(rows.len(), 51);
    for (k, r) in rows.iter().enumerate() {
        assert!(
            (r[0] - k as f64 / 50.0).abs() < 1e-9,
            "row {k} at {} s",
            r[0]
        );
    }
    // The scheme's walls are particle layers: the mirror boundary is refused by name.
    let o = slosh()
        .args(["run", "seed_tank_019", "--out"])
        .arg(tmp("dfsph-mirror"))
        .args(["--set", "solver.scheme=dfsph"])
        .args(["--set", "solver.boundary.method=mirror"])
        .output()
        .unwrap();
    assert!(!o.status.success());
    let e = String::from_utf8_lossy(&o.stderr);
    assert!(
        e.contains("solver.boundary.method") && e.contains("dfsph"),
        "{e}"
    );
}

/// `slosh bench --json` on the 2D incompressible case, 0.05 s at 20 mm, with `extra` arguments.
fn small_bench(extra: &[&str]) -> std::process::Output {
    slosh()
        .args([
            "bench",
            "--case",
            "seed_2d_dp8mm_dfsph",
            "--duration",
            "0.05",
            "--set",
            "particle_spacing=0.02",
            "--json",
        ])
        .args(extra)
        .output()
        .unwrap()
}

/// `bench/scaling/run` with a built `slosh`: a row per thread count with its speed-up over the first, and a
/// row per finer spacing with its particle count.
#[test]
fn the_scaling_script_prints_a_row_per_thread_count_and_per_spacing() {
    let script = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../bench/scaling/run");
    let st = std::process::Command::new(script)
        .args(["--slosh", env!("CARGO_BIN_EXE_slosh")])
        .args(["--case", "seed_2d_dp8mm_dfsph", "--duration", "0.02"])
        .args(["--threads", "1,2", "--spacings", "0.02,0.016"])
        .output()
        .unwrap();
    let out = String::from_utf8_lossy(&st.stdout);
    assert!(
        st.status.success(),
        "{out}{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let rows: Vec<Vec<&str>> = out
        .lines()
        .filter(|l| {
            l.starts_with("| ") && !l.starts_with("| threads") && !l.starts_with("| spacing")
        })
        .map(|l| l.trim_matches('|').split('|').map(str::trim).collect())
        .collect();
    assert_eq!(rows.len(), 4, "{out}");
    assert_eq!(
        (rows[0][0], rows[0][5], rows[0][6]),
        ("1", "1.00", "100 %"),
        "{out}"
    );
    assert_eq!(rows[1][0], "2", "{out}");
    // Both coarser than the case's own 8 mm: fewer liquid particles at 20 mm than at 16 mm.
    let liquid = |r: &Vec<&str>| r[1].parse::<usize>().unwrap();
    assert!(liquid(&rows[2]) < liquid(&rows[3]), "{out}");
}

#[test]
fn bench_repeats_a_case_and_reports_the_median_run_with_the_fastest_and_slowest() {
    let st = small_bench(&["--repeat", "3"]);
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let r: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
    assert_eq!(r["repeats"], 3, "{r}");
    let w = |k: &str| r[k].as_f64().unwrap();
    assert!(
        w("wall_time_s_min") <= w("wall_time_s") && w("wall_time_s") <= w("wall_time_s_max"),
        "{r}"
    );
    assert!(w("wall_time_s_min") > 0.0);
    // The figures are the median run's own: its real-time factor goes with its wall time.
    assert!(
        (w("realtime_factor") * w("wall_time_s") - w("sim_time_s")).abs() < 1e-9 * w("sim_time_s")
    );
    // The same work as one run.
    let one: serde_json::Value = serde_json::from_slice(&small_bench(&[]).stdout).unwrap();
    assert_eq!(one["steps"], r["steps"], "the same work every run");
    // No runs at all is refused by name.
    let st = small_bench(&["--repeat", "0"]);
    assert!(!st.status.success());
    let e = String::from_utf8_lossy(&st.stderr);
    assert!(e.contains("--repeat"), "{e}");
}

#[test]
fn bench_reports_json_and_applies_overrides() {
    let st = small_bench(&[]);
    assert!(
        st.status.success(),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    let r: serde_json::Value = serde_json::from_slice(&st.stdout).unwrap();
    assert_eq!(r["case"], "seed_2d_dp8mm_dfsph");
    // 0.8 m × 0.39 m at 20 mm instead of 8 mm: 40 × 19 or so liquid particles, not 4,900.
    let n = r["particles_fluid"].as_u64().unwrap();
    assert!((500..1000).contains(&n), "{n} liquid particles");
    assert!(r["steps"].as_u64().unwrap() > 0);
    assert!(r["sim_time_s"].as_f64().unwrap() >= 0.05 - 1e-9);
    for k in [
        "particle_steps_per_s",
        "realtime_factor",
        "iterations_per_step",
    ] {
        assert!(r[k].as_f64().unwrap() > 0.0, "{k}: {r}");
    }
    for k in ["unconverged_steps", "retried_steps"] {
        assert!(r[k].as_u64().is_some(), "{k}: {r}");
    }
    // One run (no --repeat): the range of wall times is that run.
    assert_eq!(r["repeats"], 1);
    assert_eq!(r["wall_time_s_min"], r["wall_time_s"]);
    assert_eq!(r["wall_time_s_max"], r["wall_time_s"]);
    // A misspelt setting is refused by name, not ignored.
    let st = slosh()
        .args([
            "bench",
            "--case",
            "seed_2d_dp8mm_dfsph",
            "--duration",
            "0.01",
            "--set",
            "solver.dfsph.dt_maxx=0.003",
        ])
        .output()
        .unwrap();
    assert!(!st.status.success());
    assert!(
        String::from_utf8_lossy(&st.stderr).contains("dt_maxx"),
        "{}",
        String::from_utf8_lossy(&st.stderr)
    );
    // A value out of range, in table mode: refused before the table's header, so stdout stays empty.
    let st = slosh()
        .args(["bench", "--case", "seed_2d_dp8mm", "--set", "solver.cfl=5"])
        .output()
        .unwrap();
    assert!(!st.status.success());
    assert!(
        st.stdout.is_empty(),
        "{}",
        String::from_utf8_lossy(&st.stdout)
    );
    assert!(String::from_utf8_lossy(&st.stderr).contains("solver.cfl: must be within (0, 1]"));
    // And a run refused for its values does not announce itself first.
    let st = slosh()
        .args([
            "run",
            "seed_tank_039",
            "--duration",
            "0.1",
            "--set",
            "solver.cfl=5",
            "--out",
        ])
        .arg(common::tmp("refused_run").join("out"))
        .output()
        .unwrap();
    assert!(!st.status.success());
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(
        err.contains("solver.cfl") && !err.contains("slosh: running"),
        "{err}"
    );
}

#[test]
fn motion_publisher_rejects_a_start_stamp_that_cannot_be_a_ros_time() {
    for s in ["nan", "-5", "1e30"] {
        let out = slosh()
            .args([
                "motion",
                "seed_tank_039",
                "--iceoryx2",
                "slosh_test_start_stamp",
                "--duration",
                "1",
                "--start-stamp",
                s,
            ])
            .output()
            .unwrap();
        assert!(!out.status.success(), "--start-stamp {s} accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains("--start-stamp: must be seconds since the epoch"),
            "{s}: {err}"
        );
    }
}

#[test]
fn a_run_into_an_earlier_run_s_folder_leaves_nothing_of_it_to_be_taken_for_its_own() {
    let out = tmp("rerun");
    // What an earlier run with a floating body, particle frames, figures and pictures left, and a user's file.
    let earlier = [
        "bodies.csv",
        "summary.json",
        "snapshots/frame_000000.vtu",
        "snapshots/run.pvd",
        "plots/probes.png",
        "plots/probes.svg",
        "render/frame_000003.png",
        "render/run.gif",
    ];
    for f in earlier.iter().chain(&["notes.txt", "plots/mine.png"]) {
        let p = out.join(f);
        std::fs::create_dir_all(p.parent().unwrap()).unwrap();
        std::fs::write(&p, "earlier\n").unwrap();
    }
    let st = slosh()
        .args(["run", "seed_tank_039", "--out"])
        .arg(&out)
        .args(["--duration", "0.05", "--set", "dimension=2"])
        .args(["--set", "particle_spacing=0.04"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&st.stderr);
    assert!(st.status.success(), "{err}");
    assert!(
        err.contains("removed what an earlier run there left")
            && err.contains("bodies.csv")
            && err.contains("snapshots/ (2 particle frame files)"),
        "{err}"
    );
    for f in &earlier[2..] {
        assert!(!out.join(f).exists(), "{f} is still there");
    }
    assert!(!out.join("bodies.csv").exists());
    assert!(std::fs::read_to_string(out.join("summary.json"))
        .unwrap()
        .contains("\"steps\""));
    // Not the run's: left alone.
    assert!(out.join("notes.txt").exists() && out.join("plots/mine.png").exists());
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_full_disk_stops_the_run_naming_the_file_and_leaves_whole_rows() {
    // A 16 KiB file system of its own (a private mount namespace; as a user, in a user namespace too).
    let out = tmp("diskfull");
    std::fs::create_dir_all(&out).unwrap();
    let bin = env!("CARGO_BIN_EXE_slosh");
    let script = format!(
        "mount -t tmpfs -o size=16k tmpfs {d} && {bin} run seed_tank_039 --out {d}/o --duration 5 \
         --set dimension=2 --set particle_spacing=0.02; echo \"exit $?\"; \
         cp {d}/o/*.csv {d}/.. 2>/dev/null; true",
        d = out.join("fs").display()
    );
    std::fs::create_dir_all(out.join("fs")).unwrap();
    let flags = if is_root() { "-m" } else { "-rm" };
    let st = std::process::Command::new("unshare")
        .args([flags, "sh", "-c", &script])
        .output()
        .unwrap();
    let (so, se) = (
        String::from_utf8_lossy(&st.stdout),
        String::from_utf8_lossy(&st.stderr),
    );
    assert!(so.contains("exit 1"), "{so}\n{se}");
    assert!(
        se.contains("writing the outputs at t = ")
            && se.contains("No space left on device")
            && se.contains(".csv: "),
        "{se}"
    );
    // Every CSV ends in a whole row and reads as a table.
    for f in ["probes.csv", "wrench.csv", "pressure.csv"] {
        let text = std::fs::read_to_string(out.join(f)).unwrap();
        assert!(text.ends_with('\n'), "{f} ends mid-row");
        let (h, rows) = csv(&out.join(f));
        assert!(rows.len() > 10, "{f}: {} rows", rows.len());
        assert!(rows.iter().all(|r| r.len() == h.len()), "{f}: a short row");
    }
    let _ = std::fs::remove_dir_all(&out);
}

/// Whether this process runs as root (then `unshare -m` needs no user namespace).
fn is_root() -> bool {
    std::process::Command::new("id")
        .arg("-u")
        .output()
        .map(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
        .unwrap_or(false)
}

/// The README's commands as a reader copies them: the quick start's run (at a short duration), the minimal
/// config, and every command of its commands table (`--help`), so a renamed flag or command fails here.
#[test]
fn the_readme_s_commands_run() {
    let readme = std::fs::read_to_string("../README.md").unwrap();
    let out = tmp("readme");
    // The quick start's run.
    let quick = readme
        .lines()
        .find_map(|l| {
            l.trim()
                .strip_prefix("cargo run --release --bin slosh -- run ")
        })
        .expect("the README's quick start runs a case");
    let mut args: Vec<String> = quick.split_whitespace().map(str::to_string).collect();
    for (flag, value) in [
        ("--duration", "0.1".to_string()),
        ("--out", out.join("quick").display().to_string()),
    ] {
        let i = args
            .iter()
            .position(|a| a == flag)
            .unwrap_or_else(|| panic!("the quick start has no {flag}"));
        args[i + 1] = value;
    }
    let st = slosh()
        .arg("run")
        .args(&args)
        .current_dir("..")
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "{quick}: {}",
        String::from_utf8_lossy(&st.stderr)
    );
    for f in ["probes.csv", "wrench.csv", "pressure.csv", "summary.json"] {
        assert!(out.join("quick").join(f).exists(), "{quick}: no {f}");
    }
    // The minimal config.
    let section = &readme[readme
        .find("## A minimal config")
        .expect("a minimal config section")..];
    let yaml = section
        .split("```yaml\n")
        .nth(1)
        .and_then(|s| s.split("```").next())
        .expect("a yaml block in the minimal config section");
    std::fs::create_dir_all(&out).unwrap();
    let case = out.join("minimal.yaml");
    std::fs::write(&case, yaml).unwrap();
    let st = slosh()
        .arg("run")
        .arg(&case)
        .arg("--out")
        .arg(out.join("minimal"))
        .args(["--duration", "0.1", "--set", "solver.kernel=wendland"])
        .output()
        .unwrap();
    assert!(
        st.status.success(),
        "the minimal config: {}",
        String::from_utf8_lossy(&st.stderr)
    );
    let (h, rows) = csv(&out.join("minimal/probes.csv"));
    assert_eq!(h, ["time", "wall", "mid"]);
    assert!(rows.iter().all(|r| (r[2] - 0.19).abs() < 0.02), "{rows:?}");
    // Every command of the table.
    let mut commands = 0;
    for row in readme.lines().filter(|l| l.starts_with("| `slosh ")) {
        let words: Vec<&str> = row["| `slosh ".len()..]
            .split(['`', ' '])
            .take_while(|w| {
                !w.is_empty()
                    && !w.starts_with('-')
                    && w.chars().all(|c| c.is_ascii_lowercase() || c == '-')
            })
            .collect();
        let st = slosh().args(&words).arg("--help").output().unwrap();
        assert!(
            st.status.success(),
            "`slosh {}` from the README: {}",
            words.join(" "),
            String::from_utf8_lossy(&st.stderr)
        );
        commands += 1;
    }
    assert!(commands >= 10, "{commands} commands in the README's table");
    let _ = std::fs::remove_dir_all(&out);
}

/// SROS2 enforced without its keystore: the node and the motion publisher stop at start-up (before joining
/// any DDS domain), naming the missing file and the fix.
#[test]
fn enforced_ros_security_without_its_keystore_stops_at_start_up() {
    // (In a loopback-only namespace all the same: were the refusal to fail, the node would join a domain.)
    if !common::in_private_netns("enforced_ros_security_without_its_keystore_stops_at_start_up") {
        return;
    }
    for args in [
        vec!["node", "--duration", "1", "seed_tank_039"],
        vec!["motion", "seed_tank_039", "--duration", "1"],
    ] {
        let o = slosh()
            .args(&args)
            .env("ROS_SECURITY_ENABLE", "true")
            .env("ROS_SECURITY_STRATEGY", "Enforce")
            .env("ROS_SECURITY_KEYSTORE", "/nonexistent/keystore")
            .env("ROS_SECURITY_ENCLAVE_OVERRIDE", "/ship/tank")
            .output()
            .unwrap();
        assert!(!o.status.success(), "{args:?} started");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(
            e.contains("ROS_SECURITY_STRATEGY=Enforce")
                && e.contains(
                    "/nonexistent/keystore/enclaves/ship/tank/identity_ca.cert.pem is missing"
                )
                && e.contains("ros2 security create_enclave"),
            "{args:?}: {e}"
        );
    }
}
