//! Shared by the tests that start DDS participants: they run inside a private network namespace that has only
//! loopback (`unshare -n`), so no discovery traffic leaves the machine, on a laptop or in CI.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

/// Marks a process that already runs inside the private namespace.
const INSIDE: &str = "SLOSH_TEST_NETNS";

/// Call first in a test. Outside the namespace it re-runs this one test (by its full name, e.g.
/// `motion_to_node_to_subscriber`) in a new loopback-only network namespace, asserts that it passed and
/// returns false; inside, it returns true and the test does its work.
pub fn in_private_netns(test: &str) -> bool {
    if std::env::var_os(INSIDE).is_some() {
        return true;
    }
    // One at a time: each starts several processes of its own, and the real-time checks need the cores.
    static ONE_AT_A_TIME: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner());
    let exe = std::env::current_exe().expect("test binary path");
    let root = euid() == 0;
    let setup = "ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo && exec \"$@\"";
    let mut cmd = Command::new("unshare");
    if !root {
        // Unprivileged: a user namespace maps us to root inside, enough to configure loopback.
        cmd.arg("-r");
    }
    cmd.args(["-n", "--", "sh", "-c", setup, "sh"])
        .arg(&exe)
        .args([test, "--exact", "--nocapture", "--test-threads", "1"])
        .env(INSIDE, "1");
    let status = cmd.status().unwrap_or_else(|e| {
        panic!("cannot run `unshare` ({e}): install util-linux and iproute2 (apt-get install util-linux iproute2)")
    });
    assert!(
        status.success(),
        "{test} failed inside its loopback-only network namespace ({status}); its output is above"
    );
    false
}

/// The effective user id (0: root).
pub fn euid() -> u32 {
    // `id -u` keeps this free of libc bindings.
    Command::new("id")
        .arg("-u")
        .output()
        .ok()
        .and_then(|o| String::from_utf8(o.stdout).ok())
        .and_then(|s| s.trim().parse().ok())
        .unwrap_or(1)
}

/// The Python interpreter of the test peers: `SLOSH_PYTHON`, else the workspace's `.venv`.
pub fn python() -> PathBuf {
    if let Some(p) = std::env::var_os("SLOSH_PYTHON") {
        return PathBuf::from(p);
    }
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../.venv/bin/python3");
    assert!(
        p.exists(),
        "the Python test peers are missing: run `python3 -m venv .venv && .venv/bin/pip install -r tests/py/requirements.txt` in the workspace (or set SLOSH_PYTHON)"
    );
    p
}

/// A fresh temporary folder for one test.
pub fn tmp(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("slosh-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A small 2D case (the seed tank's 0.19 m fill at dp = 20 mm) for the ROS 2 tests, for every node (`/**`);
/// `extra` is appended to its parameters (indented by four spaces).
pub fn small_case(extra: &str) -> String {
    small_case_at(0.02, extra)
}

/// [`small_case`] at particle spacing `dp` (0.04: 100 liquid particles, several times faster than real
/// time on a slow 2-core machine, for tests that follow the node in real time).
pub fn small_case_at(dp: f64, extra: &str) -> String {
    format!(
        "/**:
  ros__parameters:
    dimension: 2
    tank: {{length: 0.8, breadth: 0.25, height: 0.6}}
    fill_height: 0.19
    particle_spacing: {dp}
    probes: {{names: [left, mid], x: [-0.375, 0.0], y: [0.0, 0.0]}}
    output_rate_hz: 20.0
{extra}"
    )
}

/// A fresh folder for one test with `case.yaml` holding [`small_case`]`(extra)`: (folder, case file).
pub fn case_dir(name: &str, extra: &str) -> (PathBuf, PathBuf) {
    let dir = tmp(name);
    let case = dir.join("case.yaml");
    std::fs::write(&case, small_case(extra)).unwrap();
    (dir, case)
}

/// Runs the Python peer `tests/py/<script>` with `args` and returns what it printed, as JSON; a failure is
/// reported as `failure` followed by its stderr.
pub fn py_json(script: &str, args: &[&std::ffi::OsStr], failure: &str) -> serde_json::Value {
    let path = format!("{}/../tests/py/{script}", env!("CARGO_MANIFEST_DIR"));
    let out = Command::new(python())
        .arg(path)
        .args(args)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{failure}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

/// What the third-party bag readers decoded (tests/py/read_bag.py: rosbags and mcap + mcap-ros2-support).
pub fn read_bag(bag: &std::path::Path) -> serde_json::Value {
    py_json(
        "read_bag.py",
        &[bag.as_os_str()],
        &format!("the readers failed on {}", bag.display()),
    )
}

/// The shipped Foxglove layout checked against a recorded bag (tests/py/check_layout.py, decoding with
/// rosbags); `namespace` is where the node's relative topic names went (e.g. "/ship1", or "").
pub fn check_layout(bag: &std::path::Path, namespace: &str) -> serde_json::Value {
    let layout = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../launch-configs/foxglove_layout.json"
    );
    py_json(
        "check_layout.py",
        &[layout.as_ref(), bag.as_os_str(), namespace.as_ref()],
        &format!("the layout does not fit the recording {}", bag.display()),
    )
}

/// The `slosh` binary under test.
pub fn slosh() -> Command {
    Command::new(env!("CARGO_BIN_EXE_slosh"))
}

/// A CSV written by `slosh run`: (header, rows of numbers).
pub fn csv(path: &std::path::Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}

/// `bodies.csv` written by `slosh run`: its header and rows (the body's name, then the row's numbers with
/// the time first: column `c` of the header is value `c - 1`).
pub fn bodies_csv(path: &std::path::Path) -> (Vec<String>, Vec<(String, Vec<f64>)>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            let mut f = l.split(',');
            let t: f64 = f.next().unwrap().parse().unwrap();
            let name = f.next().unwrap().to_string();
            let mut v = vec![t];
            v.extend(f.map(|x| x.parse::<f64>().unwrap()));
            (name, v)
        })
        .collect();
    (header, rows)
}

/// `mpirun -n RANKS slosh` (OpenMPI), kept on this machine: shared memory between ranks, loopback for the
/// launcher, more ranks than cores allowed, and allowed as root (CI runs as root).
pub fn mpirun(ranks: usize) -> Command {
    let mut c = Command::new("mpirun");
    c.args(["-n", &ranks.to_string()])
        .env("OMPI_ALLOW_RUN_AS_ROOT", "1")
        .env("OMPI_ALLOW_RUN_AS_ROOT_CONFIRM", "1")
        .env("OMPI_MCA_rmaps_base_oversubscribe", "1")
        .env("OMPI_MCA_btl", "self,vader")
        .env("OMPI_MCA_btl_tcp_if_include", "lo")
        .env("OMPI_MCA_oob_tcp_if_include", "lo")
        .arg(env!("CARGO_BIN_EXE_slosh"));
    c
}

/// A child process killed and reaped when dropped: a test that fails leaves no node running.
pub struct Kill(pub std::process::Child);

impl Drop for Kill {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The DDS topic of `M` on the absolute ROS name `name` (e.g. `/ns/motion/odom`) for a test's participant.
pub fn ros_topic<M: slosh_msgs::RosMessage>(
    node: &mut ros2_client::Node,
    name: &str,
    qos: &ros2_client::QosProfile,
) -> ros2_client::dds::rustdds::Topic {
    let (ns, base) = name.rsplit_once('/').expect("an absolute name");
    node.create_topic(
        &ros2_client::Name::new(if ns.is_empty() { "/" } else { ns }, base).unwrap(),
        ros2_client::MessageTypeName::new(M::PACKAGE, M::NAME),
        qos,
    )
    .unwrap()
}

/// Odometry of a vessel at rest at the origin, stamped `t` s.
pub fn rest_odometry(t: f64) -> slosh_msgs::nav_msgs::Odometry {
    use slosh_msgs::geometry_msgs::{Pose, PoseWithCovariance, Quaternion, TwistWithCovariance};
    slosh_msgs::nav_msgs::Odometry {
        header: slosh_msgs::std_msgs::Header {
            stamp: slosh_msgs::builtin_interfaces::Time::from_secs_f64(t),
            frame_id: "odom".into(),
        },
        child_frame_id: "base_link".into(),
        pose: PoseWithCovariance {
            pose: Pose {
                orientation: Quaternion::identity(),
                ..Default::default()
            },
            covariance: [0.0; 36],
        },
        twist: TwistWithCovariance::default(),
    }
}

/// The number before `what` in `slosh node`'s stop line (`stopping at t = ... s: N samples accepted, M
/// rejected, K outputs published`) in its log.
pub fn stop_count(log: &str, what: &str) -> u64 {
    let line = log
        .lines()
        .find(|l| l.contains("stopping at t ="))
        .unwrap_or_else(|| panic!("no stop line in the log:\n{log}"));
    let at = line
        .find(what)
        .unwrap_or_else(|| panic!("{what} in {line}"));
    line[..at]
        .split_whitespace()
        .last()
        .unwrap()
        .trim_start_matches([',', ':'])
        .parse()
        .unwrap_or_else(|e| panic!("{e}: {line}"))
}

/// Reads `child`'s piped stderr as it comes (a child whose stderr pipe fills up blocks on its next log line),
/// and gives it whole once the child has closed it.
pub fn drain_stderr(child: &mut std::process::Child) -> std::thread::JoinHandle<String> {
    let mut err = child.stderr.take().expect("stderr piped");
    std::thread::spawn(move || {
        let mut log = String::new();
        let _ = std::io::Read::read_to_string(&mut err, &mut log);
        log
    })
}

/// A DDS context on `domain` and a node of the test in it named `name` (keep the context alive with the node).
pub fn participant(domain: u16, name: &str) -> (ros2_client::Context, ros2_client::Node) {
    let ctx =
        ros2_client::Context::with_options(ros2_client::ContextOptions::new().domain_id(domain))
            .unwrap();
    let node = ctx
        .new_node(
            ros2_client::NodeName::new("/", name).unwrap(),
            ros2_client::NodeOptions::new().enable_rosout(false),
        )
        .unwrap();
    (ctx, node)
}

/// Waits until the node under test, as `node` (the test's participant) sees it, subscribes to every topic of
/// `subscribed` and publishes on every topic of `published` (failing after 30 s), then `settle` more for the
/// readers and writers to match.
pub fn wait_for_node(
    node: &ros2_client::Node,
    subscribed: &[&str],
    published: &[&str],
    settle: std::time::Duration,
) {
    let seen = std::time::Instant::now();
    while subscribed.iter().any(|t| node.subscription_count(t) == 0)
        || published.iter().any(|t| node.publisher_count(t) == 0)
    {
        assert!(
            seen.elapsed() < std::time::Duration::from_secs(30),
            "the node never subscribed to {subscribed:?} and published {published:?}"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    std::thread::sleep(settle);
}
