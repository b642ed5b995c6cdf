//! Interoperability with a third-party ROS 2 peer: Python `cyclonedds` (the DDS under rmw_cyclonedds), acting
//! as a ROS 2 node with ROS type names and `rt/` topics, drives `slosh node` with Odometry and receives its
//! WrenchStamped, ProbeArray, PressureArray and DiagnosticArray. Runs in a loopback-only network namespace.

mod common;

use std::process::{Command, Stdio};

#[test]
fn cyclonedds_peer_drives_the_node_and_reads_its_outputs() {
    if !common::in_private_netns("cyclonedds_peer_drives_the_node_and_reads_its_outputs") {
        return;
    }
    let (dir, case) = common::case_dir(
        "ros-peer",
        "    pressure_sensors: {names: [bottom], x: [0.0], y: [0.0], z: [0.0]}\n",
    );
    let domain = "23";
    let mut node = common::slosh()
        .args(["node", "--duration", "2.0", "--ros-args", "--params-file"])
        .arg(&case)
        .args(["-r", "__ns:=/peer", "-p", "realtime.mode:=lockstep"])
        .args(["-p", "particles:={rate_hz: 5.0, decimation: 4}"])
        .env("ROS_DOMAIN_ID", domain)
        .spawn()
        .unwrap();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/py/peer_cyclonedds.py"
    );
    let out = Command::new(common::python())
        .arg(script)
        .args([
            "--domain",
            domain,
            "--ns",
            "/peer",
            "--seconds",
            "3",
            "--t0",
            "2000",
        ])
        .stderr(Stdio::inherit())
        .output()
        .unwrap();
    let _ = node.kill();
    let node_status = node.wait().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "the cyclonedds peer failed: {text}");
    let v: serde_json::Value =
        serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("{e}: {text}"));
    println!("peer saw: {}", v["counts"]);
    assert!(v.get("error").is_none(), "{}", v["error"]);
    assert!(
        node_status.success() || node_status.code().is_none(),
        "slosh node failed: {node_status}"
    );

    // Counts: 2 s at 20 Hz of each output, all received by the reliable peer.
    for k in ["wrench", "probes", "pressures"] {
        let n = v["counts"][k].as_u64().unwrap();
        assert!((38..=42).contains(&n), "{k}: {n} messages, expected 41");
    }
    assert!(v["counts"]["diagnostics"].as_u64().unwrap() >= 2);
    // Stamps are the simulation time of the state on the input's time base, in order, at 20 Hz.
    let times: Vec<f64> = v["wrench_times"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect();
    assert!(times.windows(2).all(|w| w[1] > w[0]));
    assert!(
        times[0].abs() < 1e-3 && (times[times.len() - 1] - 2.0).abs() < 0.03,
        "{times:?}"
    );

    // Physics: the tank is at rest (5 km from the origin, heading 0.3 rad): the liquid presses down with
    // its weight, the surface stays at the fill height, the bottom sensor reads rho g h.
    let w = &v["wrench_last"];
    assert_eq!(w["frame_id"], "tank");
    let weight = 1000.0 * 9.81 * 0.8 * 0.19 * 0.25;
    let f: Vec<f64> = w["force"]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_f64().unwrap())
        .collect();
    assert!(
        (f[2] + weight).abs() < 0.02 * weight,
        "fz {} vs -{weight}",
        f[2]
    );
    assert!(f[0].abs() < 0.02 * weight, "fx {}", f[0]);
    let p = &v["probes_last"];
    assert_eq!(p["names"], serde_json::json!(["left", "mid"]));
    for e in p["elevations"].as_array().unwrap() {
        assert!((e.as_f64().unwrap() - 0.19).abs() < 0.01, "elevation {e}");
    }
    assert_eq!(p["positions"][0], serde_json::json!([-0.375, 0.0, 0.0]));
    let pb = v["pressures_last"]["pressures"][0].as_f64().unwrap();
    assert!(
        (pb - 1000.0 * 9.81 * 0.19).abs() < 0.1 * 1000.0 * 9.81 * 0.19,
        "bottom pressure {pb}"
    );
    // The particle cloud: 5 Hz, every 4th of the 400 particles, x y z speed as float32, inside the tank.
    let n = v["counts"]["particles"].as_u64().unwrap();
    assert!((10..=12).contains(&n), "{n} clouds, expected 11");
    let c = &v["particles_last"];
    assert_eq!(c["width"], 100);
    assert_eq!(c["frame_id"], "tank");
    assert_eq!(c["fields"], serde_json::json!(["x", "y", "z", "speed"]));
    for pt in c["points"].as_array().unwrap() {
        let (x, z) = (pt["x"].as_f64().unwrap(), pt["z"].as_f64().unwrap());
        assert!(x.abs() < 0.4 && (0.0..0.25).contains(&z), "point {pt}");
        assert!(pt["speed"].as_f64().unwrap() < 0.2, "a tank at rest: {pt}");
    }
    let d = &v["diagnostics_last"];
    assert!(
        d["name"].as_str().unwrap().contains("peer/slosh"),
        "{}",
        d["name"]
    );
    for k in [
        "realtime_factor",
        "particles",
        "input_age_s",
        "overruns",
        "samples_rejected",
    ] {
        assert!(
            d["values"].get(k).is_some(),
            "diagnostics lack {k}: {}",
            d["values"]
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
