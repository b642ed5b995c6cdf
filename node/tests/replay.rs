//! `slosh replay` on bags written by a third-party tool (Python rosbags, tests/py/write_bag.py): the outputs
//! equal `slosh run` driven by the same motion as CSV, the new recording is read by rosbags and mcap, and
//! damaged bags get errors that name the problem.

mod common;

use common::{csv, slosh};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// Stamp of the first motion sample in the test bags (ns since the epoch).
const START_NS: i64 = 1_700_000_000_000_000_000;

/// A barge-like motion, 50 samples per second for `seconds`: sway, heave and pitch of incommensurate
/// periods, on a heading of 0.1 rad.
fn motion_csv(path: &Path, seconds: f64) {
    use std::f64::consts::TAU;
    let mut s = String::from("time,x,y,z,roll,pitch,yaw\n");
    let n = (seconds * 50.0).round() as usize;
    for i in 0..=n {
        let t = i as f64 * 0.02;
        s += &format!(
            "{t},{},0.0,{},0.0,{},0.1\n",
            0.03 * (TAU * t / 1.2).sin(),
            0.01 * (TAU * t / 1.5).sin(),
            0.04 * (TAU * t / 1.3 + 0.3).sin()
        );
    }
    std::fs::write(path, s).unwrap();
}

/// A folder with the motion CSV and the small case driven by it.
fn setup(name: &str, seconds: f64) -> (PathBuf, PathBuf) {
    let (dir, case) = common::case_dir(name, "    motion: {source: csv, file: motion.csv}\n");
    motion_csv(&dir.join("motion.csv"), seconds);
    (dir, case)
}

/// Writes a bag from the folder's motion.csv with tests/py/write_bag.py.
fn write_bag(dir: &Path, bag: &str, args: &[&str]) -> PathBuf {
    let script = concat!(env!("CARGO_MANIFEST_DIR"), "/../tests/py/write_bag.py");
    let path = dir.join(bag);
    let out = Command::new(common::python())
        .arg(script)
        .arg(dir.join("motion.csv"))
        .arg(&path)
        .arg("--start-ns")
        .arg(START_NS.to_string())
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "write_bag.py failed: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    path
}

/// `slosh replay BAG --config CASE --out OUT extra...`: (success, stderr).
fn replay(bag: &Path, case: &Path, out: &Path, extra: &[&str]) -> (bool, String) {
    let o = replay_by(slosh(), bag, case, out)
        .args(extra)
        .env("RUST_BACKTRACE", "0")
        .output()
        .unwrap();
    (
        o.status.success(),
        String::from_utf8_lossy(&o.stderr).into(),
    )
}

/// `cmd replay BAG --config CASE --out OUT` (`cmd`: the binary, or mpirun starting it).
fn replay_by(mut cmd: Command, bag: &Path, case: &Path, out: &Path) -> Command {
    cmd.arg("replay")
        .arg(bag)
        .arg("--config")
        .arg(case)
        .arg("--out")
        .arg(out);
    cmd
}

fn summary(out: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(out.join("summary.json")).unwrap()).unwrap()
}

#[test]
fn rosbags_odometry_and_pose_bags_replay_exactly_like_run_from_the_same_csv() {
    let (dir, case) = setup("replay-equal", 1.2);
    let st = slosh()
        .arg("run")
        .arg(&case)
        .arg("--out")
        .arg(dir.join("run"))
        .args(["--duration", "1.0"])
        .status()
        .unwrap();
    assert!(st.success());
    let run_w = csv(&dir.join("run/wrench.csv")).1;
    let run_p = csv(&dir.join("run/probes.csv")).1;
    // A rosbag2 folder of Odometry, and the bare .mcap of a PoseStamped bag.
    let odom = write_bag(&dir, "odom_bag", &["--type", "odom"]);
    let pose = write_bag(&dir, "pose_bag", &["--type", "pose"]).join("pose_bag.mcap");
    for (bag, topic, ty) in [
        (odom, "/motion/odom", "nav_msgs/msg/Odometry"),
        (pose, "/motion/pose", "geometry_msgs/msg/PoseStamped"),
    ] {
        let out = dir.join(format!("replay_{}", &topic[8..]));
        let (ok, err) = replay(&bag, &case, &out, &["--duration", "1.0"]);
        assert!(ok, "{err}");
        let s = summary(&out);
        assert_eq!(s["input"]["topic"], topic);
        assert_eq!(s["input"]["type"], ty);
        assert_eq!(s["input"]["samples"], 61);
        assert_eq!(s["input"]["time_source"], "header");
        assert_eq!(s["input"]["start_stamp_s"], 1.7e9);
        // The same motion gives the same liquid: the CSVs agree to rounding.
        let (w, p) = (
            csv(&out.join("wrench.csv")).1,
            csv(&out.join("probes.csv")).1,
        );
        assert_eq!(w.len(), run_w.len());
        assert_eq!(p.len(), run_p.len());
        for (a, b) in w.iter().zip(&run_w).chain(p.iter().zip(&run_p)) {
            for (x, y) in a.iter().zip(b) {
                assert!(
                    (x - y).abs() <= 1e-6 * (1.0 + y.abs()),
                    "{ty}: replay {a:?} vs run {b:?}"
                );
            }
        }
        // The new recording, read by rosbags and mcap: the motion as recorded and every output on the
        // source bag's time axis.
        let v = common::read_bag(&out.join("bag"));
        for reader in ["rosbags", "mcap"] {
            let mut topics: Vec<&str> = v[reader]
                .as_object()
                .unwrap()
                .keys()
                .map(String::as_str)
                .collect();
            let mut want = [topic, "/pressures", "/probes", "/wrench"];
            topics.sort();
            want.sort();
            assert_eq!(topics, want, "{reader}");
            assert_eq!(v[reader][topic]["type"], ty);
            let motion = v[reader][topic]["items"].as_array().unwrap();
            assert_eq!(motion.len(), 51, "{reader}: samples up to t = 1.0 s");
            let items = v[reader]["/wrench"]["items"].as_array().unwrap();
            assert_eq!(items.len(), w.len());
            for (item, row) in items.iter().zip(&w) {
                let t = item[0].as_f64().unwrap() - 1.7e9;
                assert!((t - row[0]).abs() < 1e-6, "{reader}: log time {t}");
                for k in 0..6 {
                    let got = item[1][k].as_f64().unwrap();
                    assert!((got - row[k + 1]).abs() <= 1e-6 * (1.0 + row[k + 1].abs()));
                }
            }
        }
    }
}

#[test]
fn an_imu_bag_replays_close_to_run_from_the_same_motion() {
    // The IMU carries orientation, body rates and specific force (by finite differences in write_bag.py), not
    // the pose: the tank feels the same apparent gravity and rotation, so the liquid agrees closely until the
    // first wall impacts (t ≈ 1.5 s) make WCSPH's pressure noise diverge.
    let (dir, case) = setup("replay-imu", 1.6);
    let st = slosh()
        .arg("run")
        .arg(&case)
        .arg("--out")
        .arg(dir.join("run"))
        .args(["--duration", "1.4"])
        .status()
        .unwrap();
    assert!(st.success());
    let bag = write_bag(&dir, "imu_bag", &["--type", "imu"]);
    let out = dir.join("replay");
    let (ok, err) = replay(&bag, &case, &out, &["--duration", "1.4"]);
    assert!(ok, "{err}");
    assert_eq!(summary(&out)["input"]["type"], "sensor_msgs/msg/Imu");
    assert_eq!(summary(&out)["input"]["input_check"], "ok");
    let (w, run_w) = (
        csv(&out.join("wrench.csv")).1,
        csv(&dir.join("run/wrench.csv")).1,
    );
    let rms = |f: &dyn Fn(usize) -> f64| {
        ((0..w.len()).map(|i| f(i).powi(2)).sum::<f64>() / w.len() as f64).sqrt()
    };
    for k in [1, 3] {
        let rel = rms(&|i| w[i][k] - run_w[i][k]) / rms(&|i| run_w[i][k]);
        assert!(
            rel < 0.05,
            "wrench column {k}: {:.1} % rms from slosh run",
            rel * 100.0
        );
    }
    let (p, run_p) = (
        csv(&out.join("probes.csv")).1,
        csv(&dir.join("run/probes.csv")).1,
    );
    let worst = p
        .iter()
        .zip(&run_p)
        .flat_map(|(a, b)| a[1..].iter().zip(&b[1..]).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max);
    assert!(worst < 0.006, "probes differ by up to {worst} m");

    // The same motion as poses read as if their world were NED: the tank is upside down, and the replay
    // says so.
    let odom = write_bag(&dir, "odom_bag", &["--type", "odom"]);
    let flipped = dir.join("flipped");
    let (ok, err) = replay(
        &odom,
        &case,
        &flipped,
        &["--duration", "0.6", "--set", "input.world_frame=ned"],
    );
    assert!(ok, "{err}");
    let check = summary(&flipped)["input"]["input_check"].clone();
    assert!(
        check.as_str().unwrap().contains("pointing up")
            && err.contains("slosh: warning: input check")
            && err.contains("input.world_frame and input.body_frame"),
        "{check}\n{err}"
    );
}

#[test]
fn damaged_and_ambiguous_bags_get_errors_naming_the_problem() {
    let (dir, case) = setup("replay-bad", 1.2);
    let out = |n: &str| dir.join(format!("out_{n}"));
    let fails = |bag: &Path, extra: &[&str], expect: &[&str]| {
        let name = bag.file_name().unwrap().to_string_lossy().into_owned();
        let (ok, err) = replay(bag, &case, &out(&name), extra);
        assert!(!ok, "{name} replayed");
        for e in expect {
            assert!(err.contains(e), "{name}: `{e}` not in: {err}");
        }
        // A refused replay does not announce outputs it never writes.
        assert!(!err.contains("writing to"), "{name}: {err}");
    };
    fails(&dir.join("missing"), &[], &["no such file or folder"]);
    let good = write_bag(&dir, "good", &[]);
    fails(
        &good,
        &["--duration", "100"],
        &["before the requested duration of 100 s", "ask for at most"],
    );
    assert!(
        !out("good").exists(),
        "a refused replay left its output folder"
    );
    let truncated = dir.join("truncated.mcap");
    let bytes = std::fs::read(good.join("good.mcap")).unwrap();
    std::fs::write(&truncated, &bytes[..bytes.len() * 2 / 3]).unwrap();
    fails(
        &truncated,
        &[],
        &["truncated or corrupt", "slosh bag repair"],
    );
    // A flipped bit in a chunk's stated uncompressed size (bit 57: 2^57 bytes, which the MCAP reader
    // allocated and aborted the process on) is refused with an error, not an abort.
    let flipped = dir.join("flipped.mcap");
    let mut bytes = bytes.clone();
    let (mut at, mut chunk) = (8usize, None);
    while at + 9 <= bytes.len() && bytes[at] != 0x0F {
        if bytes[at] == 0x06 {
            chunk = Some(at);
            break;
        }
        at += 9 + u64::from_le_bytes(bytes[at + 1..at + 9].try_into().unwrap()) as usize;
    }
    let chunk = chunk.expect("the bag is chunked");
    bytes[chunk + 9 + 16 + 7] ^= 0x02;
    std::fs::write(&flipped, &bytes).unwrap();
    fails(
        &flipped,
        &[],
        &[
            "truncated or corrupt",
            &format!("the chunk at byte {chunk} claims"),
            "slosh bag repair",
        ],
    );
    let text = dir.join("text.mcap");
    std::fs::write(&text, "time,x\n0,0\n").unwrap();
    fails(&text, &[], &["not an MCAP file"]);
    let sqlite = write_bag(&dir, "sqlite", &["--storage", "sqlite3"]);
    fails(&sqlite, &[], &["storage `sqlite3`", "convert"]);
    let none = write_bag(&dir, "none", &["--no-motion"]);
    fails(
        &none,
        &[],
        &["no motion topic", "/chatter (std_msgs/msg/String"],
    );
    let two = write_bag(&dir, "two", &["--second-topic", "/gps/odom"]);
    fails(
        &two,
        &[],
        &[
            "several motion topics",
            "/gps/odom",
            "/motion/odom",
            "--topic",
        ],
    );
    fails(
        &two,
        &["--topic", "/nope"],
        &["--topic /nope: no such topic"],
    );
    let chat = write_bag(&dir, "chat", &["--chatter"]);
    fails(
        &chat,
        &["--topic", "/chatter"],
        &["carries `std_msgs/msg/String`"],
    );
    let schema = write_bag(&dir, "schema", &["--bad-schema"]);
    fails(
        &schema,
        &[],
        &[
            "schema is not ROS 2's",
            "cannot decode",
            "float64[3] position",
        ],
    );
    let idl = write_bag(&dir, "idl.mcap", &["--schema-encoding", "omgidl"]);
    fails(&idl, &[], &["unknown schema encoding `omgidl`"]);
    let dup = write_bag(&dir, "dup", &["--duplicate", "5"]);
    fails(
        &dup,
        &[],
        &["message 7", "duplicate", "replay.bad_samples=drop"],
    );
    let swap = write_bag(&dir, "swap", &["--swap", "7"]);
    fails(&swap, &[], &["message 9", "out of order"]);

    // Chosen by --topic; bad samples skipped by policy and listed; zero header stamps fall back to the log
    // times, which `input.stamp: receive` asks for directly.
    let short = ["--duration", "0.1"];
    let (ok, err) = replay(
        &two,
        &case,
        &out("two_chosen"),
        &[&short[..], &["--topic", "/gps/odom"]].concat(),
    );
    assert!(ok, "{err}");
    assert_eq!(summary(&out("two_chosen"))["input"]["topic"], "/gps/odom");
    // A relative name resolves against the root namespace, as in ROS 2.
    let (ok, err) = replay(
        &two,
        &case,
        &out("two_relative"),
        &[&short[..], &["--topic", "gps/odom"]].concat(),
    );
    assert!(ok, "{err}");
    assert_eq!(summary(&out("two_relative"))["input"]["topic"], "/gps/odom");
    let (ok, err) = replay(
        &dup,
        &case,
        &out("dup_dropped"),
        &[&short[..], &["--set", "replay.bad_samples=drop"]].concat(),
    );
    assert!(ok, "{err}");
    let s = summary(&out("dup_dropped"));
    assert_eq!(s["input"]["samples"], 61);
    assert_eq!(s["input"]["messages"], 62);
    let dropped = s["input"]["dropped"].as_array().unwrap();
    assert_eq!(dropped.len(), 1);
    assert!(dropped[0].as_str().unwrap().contains("message 7"));
    let zero = write_bag(&dir, "zero", &["--zero-stamps"]);
    let (ok, err) = replay(&zero, &case, &out("zero"), &short);
    assert!(ok, "{err}");
    let s = summary(&out("zero"));
    assert_eq!(s["input"]["time_source"], "log");
    // The log times are the stamps 3 ms later.
    assert!((s["input"]["start_stamp_s"].as_f64().unwrap() - 1.700000000003e9).abs() < 1e-6);
    let (ok, err) = replay(
        &good,
        &case,
        &out("receive"),
        &[&short[..], &["--set", "input.stamp=receive"]].concat(),
    );
    assert!(ok, "{err}");
    assert_eq!(summary(&out("receive"))["input"]["time_source"], "log");
}

#[test]
fn rate_caps_the_replay_speed_and_the_motion_bounds_the_duration() {
    let (dir, case) = setup("replay-rate", 0.4);
    let bag = write_bag(&dir, "bag", &[]);
    // Pacing only ever waits, so this holds on any machine. Without --duration the whole motion is replayed.
    let (ok, err) = replay(&bag, &case, &dir.join("paced"), &["--rate", "0.5"]);
    assert!(ok, "{err}");
    let s = summary(&dir.join("paced"));
    assert!((s["sim_time_s"].as_f64().unwrap() - 0.4).abs() < 1e-9);
    let rtf = s["realtime_factor"].as_f64().unwrap();
    assert!(rtf <= 0.5 * 1.02, "real-time factor {rtf} above --rate 0.5");
    assert!(
        (rtf - s["sim_time_s"].as_f64().unwrap() / s["wall_time_s"].as_f64().unwrap()).abs() < 1e-9
    );
    let (ok, err) = replay(&bag, &case, &dir.join("long"), &["--duration", "5"]);
    assert!(!ok);
    assert!(
        err.contains("the motion ends at t = 0.400 s") && err.contains("--duration"),
        "{err}"
    );
    // Refused before anything is written: no empty bag is left to block the next try.
    assert!(!dir.join("long/bag").exists());
    let (ok, err) = replay(
        &bag,
        &case,
        &dir.join("both"),
        &["--rate", "2", "--as-fast-as-possible"],
    );
    assert!(!ok && err.contains("cannot be used with"), "{err}");
}

/// `mpirun -n 2 slosh replay`: rank 0 alone reads the bag and writes the outputs and the new recording;
/// they equal the serial replay's, and third-party readers read the recording.
#[cfg(feature = "mpi")]
#[test]
fn replay_on_two_mpi_ranks_equals_the_serial_replay() {
    let (dir, case) = setup("replay-mpi", 1.2);
    let bag = write_bag(&dir, "odom_bag", &["--type", "odom"]);
    let serial = dir.join("serial");
    let (ok, err) = replay(&bag, &case, &serial, &["--duration", "1.0"]);
    assert!(ok, "{err}");
    let out = dir.join("ranks2");
    let o = replay_by(common::mpirun(2), &bag, &case, &out)
        .args(["--duration", "1.0"])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(summary(&out)["mpi_ranks"], 2);
    for f in ["probes.csv", "pressure.csv"] {
        assert_eq!(csv(&out.join(f)), csv(&serial.join(f)), "{f}");
    }
    let (w, sw) = (
        csv(&out.join("wrench.csv")).1,
        csv(&serial.join("wrench.csv")).1,
    );
    assert_eq!(w.len(), sw.len());
    for (a, b) in w.iter().zip(&sw) {
        for (x, y) in a.iter().zip(b) {
            assert!((x - y).abs() <= 1e-6 * (1.0 + y.abs()), "{a:?} vs {b:?}");
        }
    }
    let v = common::read_bag(&out.join("bag"));
    for reader in ["rosbags", "mcap"] {
        let items = v[reader]["/probes"]["items"].as_array().unwrap();
        assert_eq!(items.len(), w.len(), "{reader}");
    }
}

/// Ctrl-C on `mpirun` (which sends SIGINT/SIGTERM to every rank, then kills them): rank 0 stops, finishes
/// the CSVs, summary.json and the recording, and releases the other ranks, which wait for it.
#[cfg(feature = "mpi")]
#[test]
fn interrupting_mpirun_leaves_finished_outputs_and_a_readable_recording() {
    let (dir, case) = setup("replay-mpi-int", 30.0);
    let bag = write_bag(&dir, "odom_bag", &["--type", "odom"]);
    let out = dir.join("ranks2");
    let mut child = replay_by(common::mpirun(2), &bag, &case, &out)
        .args(["--rate", "1"])
        .spawn()
        .unwrap();
    // Until the run is well under way.
    let start = std::time::Instant::now();
    while csv_rows(&out.join("probes.csv")) < 20 {
        assert!(start.elapsed().as_secs() < 60, "the replay did not start");
        std::thread::sleep(std::time::Duration::from_millis(100));
    }
    let st = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(st.success());
    let _ = child.wait().unwrap();
    let s = summary(&out);
    assert!(
        s["error"]
            .as_str()
            .unwrap_or_default()
            .contains("interrupted"),
        "{s}"
    );
    assert_eq!(s["mpi_ranks"], 2);
    let rows = csv(&out.join("probes.csv")).1.len();
    let v = common::read_bag(&out.join("bag"));
    for reader in ["rosbags", "mcap"] {
        let items = v[reader]["/probes"]["items"].as_array().unwrap();
        assert_eq!(items.len(), rows, "{reader}");
    }
}

/// Rows written so far to a CSV (0 before it exists).
#[cfg(feature = "mpi")]
fn csv_rows(path: &Path) -> usize {
    std::fs::read_to_string(path).map_or(0, |t| t.lines().count().saturating_sub(1))
}
