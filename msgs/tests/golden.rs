//! Golden bytes: every message type's CDR encoding against Cyclone DDS's.
//!
//! `tests/py/golden_cdr.py` builds one fixed value of every type with Cyclone DDS's Python IDL
//! support (`cyclonedds==11.0.1`) and prints their serialized forms; the `value_*` functions
//! below build the same values in Rust (keep the two files in step). For every type, the test
//! checks that `to_cdr` gives Cyclone's bytes exactly, that `from_cdr` reads Cyclone's bytes back
//! to the Rust value, and that both sides cover the same set of types, which includes every
//! message type of the crate.
//!
//! The Python interpreter is `$SLOSH_PYTHON`, or else `<workspace>/.venv/bin/python3`; create it
//! with `python3 -m venv .venv && .venv/bin/pip install -r tests/py/requirements.txt` in the
//! workspace root.

use std::collections::{BTreeMap, BTreeSet};
use std::fmt::Debug;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;

use serde::de::DeserializeOwned;
use serde::Serialize;

use slosh_msgs::builtin_interfaces::{Duration, Time};
use slosh_msgs::diagnostic_msgs::{DiagnosticArray, DiagnosticStatus, KeyValue};
use slosh_msgs::geometry_msgs::{
    Accel, AccelStamped, Point, Pose, PoseStamped, PoseWithCovariance, Quaternion, Transform,
    TransformStamped, Twist, TwistStamped, TwistWithCovariance, Vector3, Wrench, WrenchStamped,
};
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::rosgraph_msgs::Clock;
use slosh_msgs::sensor_msgs::{Imu, PointCloud2, PointField};
use slosh_msgs::slosh_msgs::{PressureArray, ProbeArray};
use slosh_msgs::std_msgs::Header;
use slosh_msgs::std_srvs::{
    EmptyRequest, EmptyResponse, SetBoolRequest, SetBoolResponse, TriggerRequest, TriggerResponse,
};
use slosh_msgs::tf2_msgs::TFMessage;
use slosh_msgs::{from_cdr, to_cdr, ALL_MESSAGES};

// ---------------------------------------------------------------------------------------------
// The values: one per type, mirroring the value_* functions of tests/py/golden_cdr.py.

fn value_time() -> Time {
    Time {
        sec: 1712345678,
        nanosec: 987654321,
    }
}

fn value_duration() -> Duration {
    Duration {
        sec: -5,
        nanosec: 250000000,
    }
}

fn value_header() -> Header {
    // "tank" + NUL = 5 bytes: a following float64 needs 7 bytes of padding.
    Header::new(value_time(), "tank")
}

fn value_point() -> Point {
    Point::new(1.5, -2.25, 3.125)
}

fn value_quaternion() -> Quaternion {
    Quaternion::new(0.125, -0.25, 0.5, 0.8)
}

fn value_pose() -> Pose {
    Pose {
        position: value_point(),
        orientation: value_quaternion(),
    }
}

fn value_pose_stamped() -> PoseStamped {
    PoseStamped {
        header: value_header(),
        pose: value_pose(),
    }
}

fn value_vector3() -> Vector3 {
    Vector3::new(0.5, -1.5, 9.81)
}

fn value_twist() -> Twist {
    Twist {
        linear: Vector3::new(1.0, 2.0, 3.0),
        angular: Vector3::new(-0.1, -0.2, -0.3),
    }
}

fn value_twist_stamped() -> TwistStamped {
    TwistStamped {
        header: Header::new(Time { sec: 3, nanosec: 7 }, "base_link"),
        twist: value_twist(),
    }
}

fn value_accel() -> Accel {
    Accel {
        linear: Vector3::new(0.25, -9.81, 4.0),
        angular: Vector3::new(0.01, 0.02, -0.03),
    }
}

fn value_accel_stamped() -> AccelStamped {
    AccelStamped {
        header: Header::new(
            Time {
                sec: -2,
                nanosec: 999999999,
            },
            "imu_link",
        ),
        accel: value_accel(),
    }
}

fn value_wrench() -> Wrench {
    Wrench {
        force: Vector3::new(12.5, -3.0, -1530.0),
        torque: Vector3::new(0.75, -221.5, 1.0),
    }
}

fn value_wrench_stamped() -> WrenchStamped {
    WrenchStamped {
        header: value_header(),
        wrench: value_wrench(),
    }
}

fn value_pose_with_covariance() -> PoseWithCovariance {
    PoseWithCovariance {
        pose: value_pose(),
        covariance: std::array::from_fn(|i| i as f64),
    }
}

fn value_twist_with_covariance() -> TwistWithCovariance {
    TwistWithCovariance {
        twist: value_twist(),
        covariance: std::array::from_fn(|i| i as f64 + 100.0),
    }
}

fn value_transform() -> Transform {
    Transform {
        translation: Vector3::new(10.0, -20.0, 0.5),
        rotation: value_quaternion(),
    }
}

fn value_transform_stamped() -> TransformStamped {
    TransformStamped {
        header: Header::new(value_time(), "world"),
        child_frame_id: "tank".into(),
        transform: value_transform(),
    }
}

fn value_odometry() -> Odometry {
    Odometry {
        header: Header::new(value_time(), "odom"),
        child_frame_id: "base_link".into(),
        pose: value_pose_with_covariance(),
        twist: value_twist_with_covariance(),
    }
}

fn value_imu() -> Imu {
    Imu {
        header: Header::new(value_time(), "imu"),
        orientation: value_quaternion(),
        orientation_covariance: std::array::from_fn(|i| i as f64),
        angular_velocity: Vector3::new(0.01, -0.02, 0.03),
        angular_velocity_covariance: std::array::from_fn(|i| i as f64 + 10.0),
        linear_acceleration: Vector3::new(0.1, 0.2, 9.81),
        linear_acceleration_covariance: std::array::from_fn(|i| i as f64 + 20.0),
    }
}

fn value_point_field() -> PointField {
    PointField::new("intensity", 12, PointField::UINT8, 1)
}

fn value_point_cloud2() -> PointCloud2 {
    // Three points of x, y, z (float32) and intensity (uint8): point_step 13, so data (39
    // bytes) leaves the final bool unaligned.
    PointCloud2 {
        header: Header::new(value_time(), "lidar"),
        height: 1,
        width: 3,
        fields: vec![
            PointField::new("x", 0, PointField::FLOAT32, 1),
            PointField::new("y", 4, PointField::FLOAT32, 1),
            PointField::new("z", 8, PointField::FLOAT32, 1),
            value_point_field(),
        ],
        is_bigendian: false,
        point_step: 13,
        row_step: 39,
        data: (0..39u32).map(|i| ((7 * i + 3) % 256) as u8).collect(),
        is_dense: true,
    }
}

fn value_clock() -> Clock {
    Clock {
        clock: Time {
            sec: 42,
            nanosec: 500000000,
        },
    }
}

fn value_key_value() -> KeyValue {
    KeyValue::new("particles", "20000")
}

fn value_diagnostic_status() -> DiagnosticStatus {
    DiagnosticStatus {
        level: DiagnosticStatus::WARN,
        name: "slosh: solver".into(),
        message: "real-time factor low".into(),
        hardware_id: "cpu0".into(),
        values: vec![value_key_value(), KeyValue::new("rtf", "0.056")],
    }
}

fn value_diagnostic_array() -> DiagnosticArray {
    DiagnosticArray {
        header: Header::new(value_time(), ""),
        status: vec![
            value_diagnostic_status(),
            DiagnosticStatus {
                level: DiagnosticStatus::STALE,
                name: "slosh: ros".into(),
                message: "stale".into(),
                hardware_id: String::new(),
                values: vec![],
            },
        ],
    }
}

fn value_tf_message() -> TFMessage {
    let second = TransformStamped {
        header: Header::new(Time { sec: 1, nanosec: 2 }, "tank"),
        child_frame_id: "liquid_centroid".into(),
        transform: Transform {
            translation: Vector3::new(0.0, 0.1, 0.2),
            rotation: Quaternion::identity(),
        },
    };
    TFMessage {
        transforms: vec![value_transform_stamped(), second],
    }
}

fn value_probe_array() -> ProbeArray {
    ProbeArray {
        header: value_header(),
        names: vec!["p1".into(), "centre".into(), "wall_left".into()],
        positions: vec![
            Point::new(-0.375, 0.0, 0.0),
            Point::new(0.0, 0.0, 0.0),
            Point::new(0.4, 0.05, 0.0),
        ],
        elevations: vec![0.391, f64::NAN, 0.402],
    }
}

fn value_pressure_array() -> PressureArray {
    PressureArray {
        header: value_header(),
        names: vec!["s1".into(), "bottom".into()],
        positions: vec![Point::new(-0.5, 0.0, 0.1), Point::new(0.0, 0.0, 0.0)],
        pressures: vec![3826.125, 1250.5],
    }
}

fn value_trigger_request() -> TriggerRequest {
    TriggerRequest {
        structure_needs_at_least_one_member: 0,
    }
}

fn value_trigger_response() -> TriggerResponse {
    TriggerResponse {
        success: true,
        message: "reset done".into(),
    }
}

fn value_set_bool_request() -> SetBoolRequest {
    SetBoolRequest { data: true }
}

fn value_set_bool_response() -> SetBoolResponse {
    SetBoolResponse {
        success: true,
        message: "paused at t = 1.25 s".into(),
    }
}

fn value_empty_request() -> EmptyRequest {
    EmptyRequest {
        structure_needs_at_least_one_member: 0,
    }
}

fn value_empty_response() -> EmptyResponse {
    EmptyResponse {
        structure_needs_at_least_one_member: 0,
    }
}

// ---------------------------------------------------------------------------------------------
// The Python side.

fn workspace_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("msgs/ has a parent directory")
        .to_path_buf()
}

/// Runs `tests/py/golden_cdr.py` once and returns its bytes by type name.
fn python_golden() -> &'static BTreeMap<String, Vec<u8>> {
    static GOLDEN: OnceLock<BTreeMap<String, Vec<u8>>> = OnceLock::new();
    GOLDEN.get_or_init(|| {
        let root = workspace_root();
        let python = match std::env::var_os("SLOSH_PYTHON") {
            Some(p) => PathBuf::from(p),
            None => root.join(".venv/bin/python3"),
        };
        if !python.exists() {
            panic!(
                "the golden CDR test needs a Python with cyclonedds; {} does not exist.\n\
                 Create it in the workspace root ({}):\n    \
                 python3 -m venv .venv && .venv/bin/pip install -r tests/py/requirements.txt\n\
                 or point SLOSH_PYTHON at a python3 that has the packages of \
                 tests/py/requirements.txt.",
                python.display(),
                root.display()
            );
        }
        let script = root.join("tests/py/golden_cdr.py");
        let output = Command::new(&python)
            .arg(&script)
            .output()
            .unwrap_or_else(|e| panic!("cannot run {}: {e}", python.display()));
        assert!(
            output.status.success(),
            "{} {} failed ({}):\n{}\n(install the packages with: {} -m pip install -r \
             tests/py/requirements.txt)",
            python.display(),
            script.display(),
            output.status,
            String::from_utf8_lossy(&output.stderr),
            python.display()
        );
        let hex: BTreeMap<String, String> =
            serde_json::from_slice(&output.stdout).unwrap_or_else(|e| {
                panic!(
                    "golden_cdr.py printed no JSON object of hex strings ({e}):\n{}",
                    String::from_utf8_lossy(&output.stdout)
                )
            });
        hex.into_iter()
            .map(|(name, h)| {
                let bytes = from_hex(&h).unwrap_or_else(|| panic!("{name}: bad hex {h:?}"));
                (name, bytes)
            })
            .collect()
    })
}

fn from_hex(s: &str) -> Option<Vec<u8>> {
    if !s.len().is_multiple_of(2) {
        return None;
    }
    (0..s.len())
        .step_by(2)
        .map(|i| u8::from_str_radix(s.get(i..i + 2)?, 16).ok())
        .collect()
}

fn to_hex(bytes: &[u8]) -> String {
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

/// Checks `value` against Cyclone DDS's bytes for type `name`.
fn check<T: Serialize + DeserializeOwned + Debug + PartialEq>(name: &str, value: T) {
    let expected = python_golden()
        .get(name)
        .unwrap_or_else(|| panic!("golden_cdr.py has no value for {name}"));
    let ours = to_cdr(&value);
    if &ours != expected {
        let first_difference = ours
            .iter()
            .zip(expected.iter())
            .position(|(a, b)| a != b)
            .unwrap_or(ours.len().min(expected.len()));
        panic!(
            "{name}: to_cdr differs from Cyclone DDS at byte {first_difference} \
             (lengths {} and {}; the values in msgs/tests/golden.rs and \
             tests/py/golden_cdr.py must be the same)\n  rust:    {}\n  cyclone: {}",
            ours.len(),
            expected.len(),
            to_hex(&ours),
            to_hex(expected)
        );
    }
    let decoded: T =
        from_cdr(expected).unwrap_or_else(|e| panic!("{name}: from_cdr of Cyclone's bytes: {e}"));
    // Debug text is compared, not `==`, so that NaN elevations compare equal to themselves
    // (it is otherwise stricter than `==`: it tells -0.0 from 0.0).
    assert_eq!(
        format!("{decoded:?}"),
        format!("{value:?}"),
        "{name}: from_cdr of Cyclone's bytes"
    );
}

macro_rules! golden_tests {
    ($($test:ident: $name:literal => $value:expr;)*) => {
        /// The type names the Rust side checks.
        const RUST_TYPES: &[&str] = &[$($name),*];
        $(
            #[test]
            fn $test() {
                check($name, $value);
            }
        )*
    };
}

golden_tests! {
    time: "builtin_interfaces/msg/Time" => value_time();
    duration: "builtin_interfaces/msg/Duration" => value_duration();
    header: "std_msgs/msg/Header" => value_header();
    point: "geometry_msgs/msg/Point" => value_point();
    quaternion: "geometry_msgs/msg/Quaternion" => value_quaternion();
    pose: "geometry_msgs/msg/Pose" => value_pose();
    pose_stamped: "geometry_msgs/msg/PoseStamped" => value_pose_stamped();
    vector3: "geometry_msgs/msg/Vector3" => value_vector3();
    twist: "geometry_msgs/msg/Twist" => value_twist();
    twist_stamped: "geometry_msgs/msg/TwistStamped" => value_twist_stamped();
    accel: "geometry_msgs/msg/Accel" => value_accel();
    accel_stamped: "geometry_msgs/msg/AccelStamped" => value_accel_stamped();
    wrench: "geometry_msgs/msg/Wrench" => value_wrench();
    wrench_stamped: "geometry_msgs/msg/WrenchStamped" => value_wrench_stamped();
    pose_with_covariance: "geometry_msgs/msg/PoseWithCovariance" => value_pose_with_covariance();
    twist_with_covariance: "geometry_msgs/msg/TwistWithCovariance" => value_twist_with_covariance();
    transform: "geometry_msgs/msg/Transform" => value_transform();
    transform_stamped: "geometry_msgs/msg/TransformStamped" => value_transform_stamped();
    odometry: "nav_msgs/msg/Odometry" => value_odometry();
    imu: "sensor_msgs/msg/Imu" => value_imu();
    point_field: "sensor_msgs/msg/PointField" => value_point_field();
    point_cloud2: "sensor_msgs/msg/PointCloud2" => value_point_cloud2();
    clock: "rosgraph_msgs/msg/Clock" => value_clock();
    key_value: "diagnostic_msgs/msg/KeyValue" => value_key_value();
    diagnostic_status: "diagnostic_msgs/msg/DiagnosticStatus" => value_diagnostic_status();
    diagnostic_array: "diagnostic_msgs/msg/DiagnosticArray" => value_diagnostic_array();
    tf_message: "tf2_msgs/msg/TFMessage" => value_tf_message();
    probe_array: "slosh_msgs/msg/ProbeArray" => value_probe_array();
    pressure_array: "slosh_msgs/msg/PressureArray" => value_pressure_array();
    trigger_request: "std_srvs/srv/Trigger_Request" => value_trigger_request();
    trigger_response: "std_srvs/srv/Trigger_Response" => value_trigger_response();
    set_bool_request: "std_srvs/srv/SetBool_Request" => value_set_bool_request();
    set_bool_response: "std_srvs/srv/SetBool_Response" => value_set_bool_response();
    empty_request: "std_srvs/srv/Empty_Request" => value_empty_request();
    empty_response: "std_srvs/srv/Empty_Response" => value_empty_response();
}

#[test]
fn both_sides_cover_every_type() {
    let rust: BTreeSet<&str> = RUST_TYPES.iter().copied().collect();
    assert_eq!(rust.len(), RUST_TYPES.len(), "a type is listed twice");
    let python: BTreeSet<&str> = python_golden().keys().map(String::as_str).collect();
    let only_python: Vec<&&str> = python.difference(&rust).collect();
    let only_rust: Vec<&&str> = rust.difference(&python).collect();
    assert!(
        only_python.is_empty() && only_rust.is_empty(),
        "golden_cdr.py and golden.rs cover different types: only in Python {only_python:?}, \
         only in Rust {only_rust:?}"
    );
    let crate_messages: BTreeSet<&str> = ALL_MESSAGES.iter().map(|d| d.full_name).collect();
    let missing: Vec<&&str> = crate_messages.difference(&rust).collect();
    assert!(missing.is_empty(), "no golden value for {missing:?}");
}
