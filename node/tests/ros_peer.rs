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
    let v = node_and_peer(
        &case,
        "23",
        &["-p", "particles:={rate_hz: 5.0, decimation: 4}"],
        &[],
    );
    println!("peer saw: {}", v["counts"]);

    // Counts: 2 s at 20 Hz of each output, all received by the reliable peer.
    for k in ["wrench", "probes", "pressures"] {
        let n = v["counts"][k].as_u64().unwrap();
        assert!((38..=42).contains(&n), "{k}: {n} messages, expected 41");
    }
    assert!(v["counts"]["diagnostics"].as_u64().unwrap() >= 2);
    // Stamps are the simulation time of the state on the input's time base, in order, at 20 Hz.
    let times = wrench_times(&v);
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

/// The rcl_interfaces parameter services, called by the same third-party peer: every parameter listed
/// with its type, described (read-only or changeable, with a range), a rate changed while the node runs
/// (the outputs follow at once), a read-only parameter and an atomic set with one refused with the reason,
/// and the change on `/parameter_events`.
#[test]
fn cyclonedds_peer_lists_gets_and_sets_the_node_parameters() {
    if !common::in_private_netns("cyclonedds_peer_lists_gets_and_sets_the_node_parameters") {
        return;
    }
    let (dir, case) = common::case_dir("ros-peer-params", "");
    let v = node_and_peer(&case, "24", &[], &["--parameters", "slosh"]);
    let p = &v["parameters"];
    let listed: Vec<&str> = p["list"]
        .as_array()
        .unwrap()
        .iter()
        .map(|n| n.as_str().unwrap())
        .collect();
    for n in [
        "output_rate_hz",
        "particle_spacing",
        "solver.scheme",
        "solver.dfsph.max_iterations",
        "particles.decimation",
        "probes.names",
        "use_sim_time",
    ] {
        assert!(listed.contains(&n), "{n} not listed: {listed:?}");
    }
    assert!(listed.len() > 50, "{} parameters", listed.len());
    assert!(p["prefixes"]
        .as_array()
        .unwrap()
        .contains(&serde_json::json!("solver.dfsph")));
    for n in p["solver_depth1"].as_array().unwrap() {
        let n = n.as_str().unwrap();
        assert!(
            n.starts_with("solver.") && n.matches('.').count() == 1,
            "{n}"
        );
    }
    // Values and types as ROS 2 types them (double 3, string 4, string array 9, not set 0).
    let g = &p["get"];
    assert_eq!(
        g["output_rate_hz"],
        serde_json::json!({"type": 3, "value": 20.0})
    );
    assert_eq!(
        g["particle_spacing"],
        serde_json::json!({"type": 3, "value": 0.02})
    );
    assert_eq!(g["solver.scheme"]["type"], 4);
    assert_eq!(
        g["probes.names"],
        serde_json::json!({"type": 9, "value": ["left", "mid"]})
    );
    assert_eq!(g["no_such"]["type"], 0);
    assert_eq!(p["types"], serde_json::json!([3, 3, 4, 9, 0]));
    let d = &p["describe"];
    assert_eq!(d[0]["read_only"], false);
    assert_eq!(d[0]["range"], serde_json::json!([[0.01, 1000.0]]));
    assert_eq!(d[1]["read_only"], true);
    assert!(d[1]["constraints"].as_str().unwrap().contains("restart"));
    // The set: the rate applies, the spacing is refused with the reason.
    assert_eq!(p["set"][0]["ok"], true, "{}", p["set"]);
    assert_eq!(p["set"][1]["ok"], false);
    assert!(p["set"][1]["reason"]
        .as_str()
        .unwrap()
        .contains("read-only"));
    assert_eq!(p["atomic"]["ok"], false);
    assert!(p["atomic"]["reason"]
        .as_str()
        .unwrap()
        .contains("'dimension'"));
    // The outputs: 20 Hz before the set, 10 Hz after it (stamps on the input's time base, t0 removed).
    let times = wrench_times(&v);
    let set_at = p["set_at"].as_f64().unwrap();
    let gaps = |from: f64, to: f64| -> Vec<f64> {
        times
            .windows(2)
            .filter(|w| w[0] >= from && w[1] <= to)
            .map(|w| w[1] - w[0])
            .collect()
    };
    let before = gaps(0.0, set_at - 0.1);
    let after = gaps(set_at + 0.2, 10.0);
    assert!(
        !before.is_empty() && before.iter().all(|g| (g - 0.05).abs() < 1e-3),
        "before the set: {before:?}"
    );
    assert!(
        !after.is_empty() && after.iter().all(|g| (g - 0.1).abs() < 1e-3),
        "after the set: {after:?}"
    );
    // /parameter_events carries the change. (The start-up event that declares every parameter is
    // volatile, as rclcpp's: a peer that joins later does not see it.)
    let events = p["events"].as_array().unwrap();
    assert!(
        events.iter().any(
            |e| e["changed"]["output_rate_hz"] == serde_json::json!({"type": 3, "value": 10.0})
        ),
        "{events:?}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Runs `slosh node` on `case` (namespace /peer, lockstep, 2 simulated seconds, `node_args` added to its ROS
/// arguments) in DDS domain `domain` and the Python peer beside it (3 s of motion from stamp 2000, `peer_args`
/// added); what the peer printed, once both have ended well.
fn node_and_peer(
    case: &std::path::Path,
    domain: &str,
    node_args: &[&str],
    peer_args: &[&str],
) -> serde_json::Value {
    let mut node = common::slosh()
        .args(["node", "--duration", "2.0", "--ros-args", "--params-file"])
        .arg(case)
        .args(["-r", "__ns:=/peer", "-p", "realtime.mode:=lockstep"])
        .args(node_args)
        .env("ROS_DOMAIN_ID", domain)
        .spawn()
        .unwrap();
    let script = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../tests/py/peer_cyclonedds.py"
    );
    let out = Command::new(common::python())
        .arg(script)
        .args(["--domain", domain, "--ns", "/peer", "--seconds", "3"])
        .args(["--t0", "2000"])
        .args(peer_args)
        .stderr(Stdio::inherit())
        .output()
        .unwrap();
    let _ = node.kill();
    let node_status = node.wait().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "the cyclonedds peer failed: {text}");
    let v: serde_json::Value =
        serde_json::from_str(text.trim()).unwrap_or_else(|e| panic!("{e}: {text}"));
    assert!(v.get("error").is_none(), "{}", v["error"]);
    assert!(
        node_status.success() || node_status.code().is_none(),
        "slosh node failed: {node_status}"
    );
    v
}

/// The stamps of the wrenches the peer received (s on the input's time base, its t0 removed).
fn wrench_times(v: &serde_json::Value) -> Vec<f64> {
    v["wrench_times"]
        .as_array()
        .unwrap()
        .iter()
        .map(|t| t.as_f64().unwrap())
        .collect()
}
