//! Recordings read by third-party tools (Python rosbags and mcap + mcap-ros2-support), with the values the run
//! wrote to its CSVs; an interrupted run leaves a complete bag; a killed one is made whole by `slosh bag repair`.

mod common;

use common::slosh;

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const ARGS: [&str; 6] = [
    "--set",
    "dimension=2",
    "--set",
    "particle_spacing=0.02",
    "--set",
    "output_rate_hz=20",
];

#[test]
fn a_recording_is_read_by_rosbags_and_mcap_with_the_values_written() {
    let dir = common::tmp("record");
    let bag = dir.join("bag");
    let st = slosh()
        .args(["run", "seed_tank_019", "--out"])
        .arg(dir.join("out"))
        .args(["--duration", "0.5"])
        .args(ARGS)
        .arg("--set")
        .arg(format!("record.path={}", bag.display()))
        .status()
        .unwrap();
    assert!(st.success());
    let v = common::read_bag(&bag);
    assert_eq!(v["profile"], "ros2");
    let params: serde_json::Value = serde_json::from_str(
        v["metadata"]["slosh_parameters"]["parameters"]
            .as_str()
            .unwrap(),
    )
    .unwrap();
    assert_eq!(params["fill_height"], 0.19, "the bag documents its case");
    let wrench = common::csv(&dir.join("out/wrench.csv")).1;
    let probes = common::csv(&dir.join("out/probes.csv")).1;
    for reader in ["rosbags", "mcap"] {
        let topics = v[reader].as_object().unwrap();
        let mut names: Vec<&String> = topics.keys().collect();
        names.sort();
        assert_eq!(
            names,
            ["/motion/odom", "/pressures", "/probes", "/wrench"],
            "{reader}"
        );
        assert_eq!(
            v[reader]["/wrench"]["type"],
            "geometry_msgs/msg/WrenchStamped"
        );
        assert_eq!(v[reader]["/probes"]["type"], "slosh_msgs/msg/ProbeArray");
        let w = v[reader]["/wrench"]["items"].as_array().unwrap();
        let p = v[reader]["/probes"]["items"].as_array().unwrap();
        assert_eq!(w.len(), wrench.len(), "{reader}: one wrench per CSV row");
        assert_eq!(p.len(), probes.len());
        for (item, row) in w.iter().zip(&wrench) {
            let t = item[0].as_f64().unwrap();
            assert!(
                (t - row[0]).abs() < 1e-6,
                "{reader}: log time {t} vs {}",
                row[0]
            );
            for k in 0..6 {
                let got = item[1][k].as_f64().unwrap();
                assert!(
                    (got - row[k + 1]).abs() <= 1e-6 * (1.0 + row[k + 1].abs()),
                    "{reader}: {got} vs {}",
                    row[k + 1]
                );
            }
        }
        for (item, row) in p.iter().zip(&probes) {
            for k in 0..2 {
                let got = item[1][k].as_f64().unwrap();
                assert!(
                    (got - row[k + 1]).abs() < 1e-6,
                    "{reader}: probe {got} vs {}",
                    row[k + 1]
                );
            }
        }
    }
    // A bag is never overwritten: a second run into the same folder stops before it starts.
    let out = slosh()
        .args(["run", "seed_tank_019", "--out"])
        .arg(dir.join("out2"))
        .args(["--duration", "0.1"])
        .args(ARGS)
        .arg("--set")
        .arg(format!("record.path={}", bag.display()))
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("record.path"));
    let _ = std::fs::remove_dir_all(&dir);
}

/// Starts a long run that records with small chunks, waits until a few chunks are on disk, then sends `signal`.
fn interrupted_run(dir: &Path, signal: &str) -> std::process::ExitStatus {
    let bag = dir.join("bag");
    let mut child = slosh()
        .args(["run", "seed_tank_019", "--out"])
        .arg(dir.join("out"))
        .args(["--duration", "60"])
        .args(ARGS)
        .args(["--set", "record.chunk_size=4096", "--set"])
        .arg(format!("record.path={}", bag.display()))
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let file = bag.join("bag_0.mcap");
    let start = Instant::now();
    while std::fs::metadata(&file).map(|m| m.len()).unwrap_or(0) < 20_000 {
        assert!(
            start.elapsed() < Duration::from_secs(60),
            "the recording does not grow"
        );
        std::thread::sleep(Duration::from_millis(50));
    }
    let pid = child.id().to_string();
    assert!(Command::new("kill")
        .args([signal, &pid])
        .status()
        .unwrap()
        .success());
    child.wait().unwrap()
}

#[test]
fn sigint_leaves_a_complete_bag() {
    let dir = common::tmp("record-sigint");
    let status = interrupted_run(&dir, "-INT");
    assert!(!status.success(), "an interrupted run reports it");
    assert!(dir.join("bag/metadata.yaml").exists());
    let v = common::read_bag(&dir.join("bag"));
    let n = v["rosbags"]["/wrench"]["items"].as_array().unwrap().len();
    assert!(n > 5, "{n} wrench messages");
    assert_eq!(n, v["mcap"]["/wrench"]["items"].as_array().unwrap().len());
    let summary: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap())
            .unwrap();
    assert!(summary["error"].as_str().unwrap().contains("interrupted"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_hard_kill_loses_at_most_the_flush_interval() {
    // Default chunks (768 KiB, far more than this run writes): the recorder writes its chunk out after
    // each second of log time (`record.flush_interval_s`), so a kill loses about a second, not all of it.
    let dir = common::tmp("record-flush");
    let bag = dir.join("bag");
    let mut child = slosh()
        .args(["run", "seed_tank_019", "--out"])
        .arg(dir.join("out"))
        .args(["--duration", "60"])
        .args(ARGS)
        .arg("--set")
        .arg(format!("record.path={}", bag.display()))
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let last_row = |dir: &Path| {
        std::fs::read_to_string(dir.join("out/probes.csv"))
            .ok()
            .and_then(|t| {
                let line = t
                    .lines()
                    .rfind(|l| l.ends_with(|c: char| c.is_ascii_digit()))?;
                line.split(',').next()?.parse::<f64>().ok()
            })
            .unwrap_or(0.0)
    };
    let start = Instant::now();
    while last_row(&dir) < 3.2 {
        assert!(
            start.elapsed() < Duration::from_secs(120),
            "the run does not advance"
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(Command::new("kill")
        .args(["-KILL", &child.id().to_string()])
        .status()
        .unwrap()
        .success());
    child.wait().unwrap();
    let reached = last_row(&dir);
    let out = slosh().args(["bag", "repair"]).arg(&bag).output().unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v = common::read_bag(&dir.join("bag_repaired"));
    let w = v["rosbags"]["/wrench"]["items"].as_array().unwrap();
    let last = w.last().map_or(0.0, |i| i[0].as_f64().unwrap());
    assert!(
        last >= reached - 1.5,
        "recovered up to t = {last} s of a run that had reached {reached} s"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sigkill_then_repair_recovers_the_complete_chunks() {
    let dir = common::tmp("record-sigkill");
    let status = interrupted_run(&dir, "-KILL");
    assert!(!status.success());
    assert!(
        !dir.join("bag/metadata.yaml").exists(),
        "a killed recorder cannot finish"
    );
    let out = slosh()
        .args(["bag", "repair"])
        .arg(dir.join("bag"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let said = String::from_utf8_lossy(&out.stdout);
    assert!(said.contains("recovered"), "{said}");
    let v = common::read_bag(&dir.join("bag_repaired"));
    let w = v["rosbags"]["/wrench"]["items"].as_array().unwrap();
    assert!(w.len() > 5, "{} wrench messages recovered", w.len());
    // The recovered messages are the run's, in order, on its output grid.
    for (k, item) in w.iter().enumerate() {
        let t = item[0].as_f64().unwrap();
        assert!((t - k as f64 / 20.0).abs() < 0.01, "message {k} at {t}");
    }
    // The run's parameters record survived the kill (it is written first) and goes with the repair.
    let meta = &v["metadata"]["slosh_parameters"];
    let params: serde_json::Value =
        serde_json::from_str(meta["parameters"].as_str().unwrap_or("null")).unwrap();
    assert!(params["particle_spacing"].as_f64().is_some(), "{meta}");
    assert!(
        meta["repaired_from"].as_str().unwrap().ends_with("bag"),
        "{meta}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn a_full_disk_stops_the_run_with_a_clear_error_and_keeps_the_csv_outputs() {
    // The bag goes to a 64 KiB tmpfs in a private mount namespace (as root, or mapped to root in a user
    // namespace), which fills up after a fraction of a second of uncompressed recording.
    let dir = common::tmp("record-full");
    let full = dir.join("full");
    std::fs::create_dir_all(&full).unwrap();
    let mut cmd = Command::new("unshare");
    if common::euid() != 0 {
        cmd.arg("-r");
    }
    let out = cmd
        .args(["-m", "--", "sh", "-c"])
        .arg("mount -t tmpfs -o size=64k slosh-full \"$1\" && shift && exec \"$@\"")
        .arg("sh")
        .arg(&full)
        .arg(env!("CARGO_BIN_EXE_slosh"))
        .args(["run", "seed_tank_019", "--out"])
        .arg(dir.join("out"))
        .args(["--duration", "2"])
        .args(ARGS)
        .args([
            "--set",
            "output_rate_hz=200",
            "--set",
            "record.compression=none",
        ])
        .args(["--set", "record.chunk_size=4096", "--set"])
        .arg(format!("record.path={}", full.join("bag").display()))
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "the run went on: {err}");
    assert!(
        err.contains("recording to") && err.contains("No space left on device"),
        "{err}"
    );
    // The CSVs (on another disk) hold every state up to the failure, and the summary says why it stopped.
    let rows = common::csv(&dir.join("out/wrench.csv")).1;
    assert!(rows.len() > 5, "{} rows", rows.len());
    let s: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out/summary.json")).unwrap())
            .unwrap();
    assert!(s["error"]
        .as_str()
        .unwrap()
        .contains("No space left on device"));
    // A folder that cannot be created stops the run before it starts.
    let out = slosh()
        .args(["run", "seed_tank_019", "--out"])
        .arg(dir.join("out2"))
        .args(["--duration", "0.1"])
        .args(ARGS)
        .args(["--set", "record.path=/proc/slosh/bag"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        err.contains("record.path /proc/slosh/bag: cannot create the folder"),
        "{err}"
    );
    assert!(!dir.join("out2/wrench.csv").exists(), "nothing was run");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn an_empty_recording_is_read_by_rosbags_and_mcap() {
    // A node stopped before any motion arrived (a wrong remap) leaves a bag with no messages.
    let dir = common::tmp("record-empty");
    let cfg = slosh_node::config::RecordCfg {
        path: dir.join("bag").display().to_string(),
        ..Default::default()
    };
    let mut r = slosh_node::record::Recorder::create(
        &cfg,
        &serde_json::json!({"case": "empty"}),
        &serde_json::json!({"case": "empty", "gravity": 9.81}),
    )
    .unwrap();
    r.finish().unwrap();
    let v = common::read_bag(&dir.join("bag"));
    assert_eq!(v["rosbags"], serde_json::json!({}), "{v}");
    assert_eq!(v["mcap"], serde_json::json!({}), "{v}");
    assert!(v["metadata"]["slosh_parameters"]["parameters"]
        .as_str()
        .unwrap()
        .contains("empty"));
    assert!(v["metadata"]["slosh_parameters"]["effective_parameters"]
        .as_str()
        .unwrap()
        .contains("9.81"));
    let _ = std::fs::remove_dir_all(&dir);
}
