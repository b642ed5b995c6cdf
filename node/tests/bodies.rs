//! Floating bodies through the command line: the paper's flooding cases reject a resolution their walls
//! cannot hold (or an integrator that cannot move them), a coarse damaged box floods and writes `bodies.csv`, and its recording carries each body's
//! Odometry and wrench, read by rosbags and mcap with the CSV's values.

mod common;

use common::slosh;

/// The paper's case A scaled ×2 for dp = 5 mm (walls of three particles), dry inside, floating free.
const COARSE: [&str; 16] = [
    "--set",
    "particle_spacing=0.005",
    "--set",
    "bodies.box.size=[0.2, 0.2, 0.2]",
    "--set",
    "bodies.box.wall_thickness=0.015",
    "--set",
    "bodies.box.position=[0.0, 0.0, 0.05]",
    "--set",
    "bodies.box.mass=30.0",
    "--set",
    "bodies.box.inertia=[0.3, 0.3, 0.3]",
    "--set",
    "bodies.box.centre_of_gravity=[0.0, 0.0, 0.05]",
    "--set",
    "bodies.box.openings.damage={centre: [0.0, 0.0, 0.0075], size: [0.02, 1.0, 0.03]}",
];

#[test]
fn walls_thinner_than_the_kernel_are_refused_by_name() {
    let out = slosh()
        .args(["run", "flooding_case_a", "--duration", "0.01", "--out"])
        .arg(common::tmp("bodies_thin").join("out"))
        .args(["--set", "particle_spacing=0.005"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bodies.box.wall_thickness") && err.contains("kernel support"),
        "{err}"
    );
    // The weakly-compressible scheme moves bodies with its symplectic steps only: said so, by name.
    let out = slosh()
        .args(["run", "flooding_case_a", "--duration", "0.01", "--out"])
        .arg(common::tmp("bodies_verlet").join("out"))
        .args(["--set", "solver.integrator=verlet"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("bodies.box") && err.contains("solver.integrator: symplectic"),
        "{err}"
    );
}

#[test]
fn an_opening_that_cuts_nothing_and_a_centre_of_gravity_outside_the_box_are_refused_by_name() {
    let refused = |name: &str, set: &str, expect: &[&str]| {
        let out = slosh()
            .args(["run", "flooding_case_a", "--duration", "0.01", "--out"])
            .arg(common::tmp(name).join("out"))
            .args(["--set", set])
            .output()
            .unwrap();
        assert!(!out.status.success(), "{set} accepted");
        let err = String::from_utf8_lossy(&out.stderr);
        for e in expect {
            assert!(err.contains(e), "{set}: `{e}` not in {err}");
        }
    };
    // Above the box (a frame or units mix-up): the box stayed intact and the case ran as if undamaged.
    refused(
        "bodies_opening_above",
        "bodies.box.openings.damage.centre=[0.0, 0.0, 0.5]",
        &[
            "bodies.box.openings.damage",
            "does not cut through a wall",
            "box: x -0.0500..0.0500",
        ],
    );
    // Inside the hollow, short of every wall.
    refused(
        "bodies_opening_inside",
        "bodies.box.openings.damage={centre: [0.0, 0.0, 0.05], size: [0.02, 1.0, 0.02]}",
        &["bodies.box.openings.damage", "does not cut through a wall"],
    );
    refused(
        "bodies_cog_outside",
        "bodies.box.centre_of_gravity=[0.0, 0.0, 0.5]",
        &["bodies.box.centre_of_gravity", "outside the box"],
    );
}

#[test]
fn a_damaged_box_floods_and_its_motion_is_recorded_as_odometry() {
    let dir = common::tmp("bodies_flood");
    let bag = dir.join("bag");
    let st = slosh()
        .args(["run", "flooding_case_a", "--duration", "0.25", "--out"])
        .arg(dir.join("out"))
        .args(COARSE)
        .args(["--set", "output_rate_hz=40"])
        .arg("--set")
        .arg(format!("record.path={}", bag.display()))
        .status()
        .unwrap();
    assert!(st.success());
    let (header, rows) = common::bodies_csv(&dir.join("out/bodies.csv"));
    assert_eq!(header.len(), 22);
    assert_eq!(&header[..5], ["time", "body", "x", "y", "z"]);
    assert_eq!(rows.len(), 11, "t = 0, 0.025, …, 0.25");
    assert!(rows.iter().all(|r| r.0 == "box"));
    let col = |name: &str| header.iter().position(|h| h == name).unwrap() - 1;
    let (z, volume, rate) = (col("z"), col("flooded_volume"), col("inflow_rate"));
    // Water comes in through the bottom, and the box, heavier by it, sinks.
    let last = &rows[rows.len() - 1].1;
    assert_eq!(rows[0].1[volume], 0.0);
    assert!(last[volume] > 1e-4, "flooded {} m²", last[volume]);
    assert!(rows.iter().all(|r| r.1[rate] >= -1e-3));
    assert!(
        last[z] < rows[0].1[z] - 1e-4,
        "sinks: {} → {}",
        rows[0].1[z],
        last[z]
    );

    let v = common::read_bag(&bag);
    for reader in ["rosbags", "mcap"] {
        let odom = &v[reader]["/bodies/box/odom"];
        let wrench = &v[reader]["/bodies/box/wrench"];
        assert_eq!(odom["type"], "nav_msgs/msg/Odometry", "{reader}");
        assert_eq!(wrench["type"], "geometry_msgs/msg/WrenchStamped");
        let (o, w) = (
            odom["items"].as_array().unwrap(),
            wrench["items"].as_array().unwrap(),
        );
        assert_eq!(o.len(), rows.len(), "{reader}: one message per CSV row");
        assert_eq!(w.len(), rows.len());
        for ((oi, wi), (_, row)) in o.iter().zip(w).zip(&rows) {
            let got = |item: &serde_json::Value, k: usize| item[1][k].as_f64().unwrap();
            let close = |a: f64, b: f64| (a - b).abs() <= 1e-6 * (1.0 + b.abs());
            assert!(close(oi[0].as_f64().unwrap(), row[0]), "{reader}: time");
            // Position of the centre of gravity; the 2D box turns about y only: q = (0, sin θ/2, 0, cos θ/2).
            assert!(close(got(oi, 0), row[col("x")]) && close(got(oi, 2), row[col("z")]));
            let pitch = row[col("pitch")];
            assert!(close(got(oi, 4), (0.5 * pitch).sin()), "{reader}: q.y");
            assert!(close(got(oi, 6), (0.5 * pitch).cos()), "{reader}: q.w");
            assert_eq!((got(oi, 3), got(oi, 5)), (0.0, 0.0));
            // Angular velocity about y is the same in the body's axes; the liquid's force as in the CSV.
            assert!(close(got(oi, 11), row[col("wy")]));
            assert!(close(got(wi, 0), row[col("fx")]) && close(got(wi, 2), row[col("fz")]));
            assert!(close(got(wi, 4), row[col("my")]));
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
