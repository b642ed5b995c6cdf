//! ROS 2 message types for slosh, with ROS 2's exact CDR layout, their `.msg` definitions and
//! ROS type names; with the feature `iceoryx2`, the fixed-layout payloads of slosh's iceoryx2 services
//! ([`iox`]).
//!
//! One module per ROS package. Every message type implements [`RosMessage`] (package, name,
//! `.msg` text, dependencies, DDS type name, MCAP `ros2msg` schema); the services of
//! [`std_srvs`] implement [`RosService`]. [`to_cdr`] and [`from_cdr`] convert between values and
//! ROS 2 serialized messages (encapsulation header + little-endian plain CDR), byte for byte the
//! same as a DDS implementation (checked against Cyclone DDS by `tests/golden.rs`).
//!
//! ```
//! use slosh_msgs::geometry_msgs::{Vector3, Wrench, WrenchStamped};
//! use slosh_msgs::std_msgs::Header;
//! use slosh_msgs::builtin_interfaces::Time;
//! use slosh_msgs::{from_cdr, to_cdr, RosMessage};
//!
//! let msg = WrenchStamped {
//!     header: Header::new(Time::from_secs_f64(1.25), "tank"),
//!     wrench: Wrench { force: Vector3::new(0.0, 0.0, -153.0), torque: Vector3::default() },
//! };
//! let bytes = to_cdr(&msg);
//! assert_eq!(&bytes[..4], &[0, 1, 0, 0]);
//! assert_eq!(from_cdr::<WrenchStamped>(&bytes).unwrap(), msg);
//! assert_eq!(WrenchStamped::type_name(), "geometry_msgs/msg/WrenchStamped");
//! assert_eq!(WrenchStamped::dds_type_name(), "geometry_msgs::msg::dds_::WrenchStamped_");
//! ```

#![warn(missing_docs)]

pub mod builtin_interfaces;
pub mod cdr;
pub mod diagnostic_msgs;
pub mod geometry_msgs;
#[cfg(feature = "iceoryx2")]
pub mod iox;
pub mod message;
pub mod nav_msgs;
pub mod rosgraph_msgs;
pub mod sensor_msgs;
pub mod slosh_msgs;
pub mod std_msgs;
pub mod std_srvs;
pub mod tf2_msgs;

pub use cdr::{from_cdr, to_cdr, try_to_cdr, CdrError, CDR_LE_HEADER};
pub use message::{MessageDescription, RosMessage, RosService};

/// The descriptions of all message types of this crate.
pub const ALL_MESSAGES: &[&MessageDescription] = &[
    builtin_interfaces::Time::DESCRIPTION,
    builtin_interfaces::Duration::DESCRIPTION,
    std_msgs::Header::DESCRIPTION,
    geometry_msgs::Point::DESCRIPTION,
    geometry_msgs::Quaternion::DESCRIPTION,
    geometry_msgs::Pose::DESCRIPTION,
    geometry_msgs::PoseStamped::DESCRIPTION,
    geometry_msgs::Vector3::DESCRIPTION,
    geometry_msgs::Twist::DESCRIPTION,
    geometry_msgs::TwistStamped::DESCRIPTION,
    geometry_msgs::Accel::DESCRIPTION,
    geometry_msgs::AccelStamped::DESCRIPTION,
    geometry_msgs::Wrench::DESCRIPTION,
    geometry_msgs::WrenchStamped::DESCRIPTION,
    geometry_msgs::PoseWithCovariance::DESCRIPTION,
    geometry_msgs::TwistWithCovariance::DESCRIPTION,
    geometry_msgs::Transform::DESCRIPTION,
    geometry_msgs::TransformStamped::DESCRIPTION,
    nav_msgs::Odometry::DESCRIPTION,
    sensor_msgs::Imu::DESCRIPTION,
    sensor_msgs::PointField::DESCRIPTION,
    sensor_msgs::PointCloud2::DESCRIPTION,
    rosgraph_msgs::Clock::DESCRIPTION,
    diagnostic_msgs::KeyValue::DESCRIPTION,
    diagnostic_msgs::DiagnosticStatus::DESCRIPTION,
    diagnostic_msgs::DiagnosticArray::DESCRIPTION,
    tf2_msgs::TFMessage::DESCRIPTION,
    slosh_msgs::ProbeArray::DESCRIPTION,
    slosh_msgs::PressureArray::DESCRIPTION,
];

/// The description of the message type named `"pkg/msg/Type"` or `"pkg/Type"`, if this crate
/// has it.
pub fn find_message(name: &str) -> Option<&'static MessageDescription> {
    ALL_MESSAGES
        .iter()
        .copied()
        .find(|d| d.full_name == name || d.short_name == name)
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeSet;

    use super::builtin_interfaces::*;
    use super::diagnostic_msgs::*;
    use super::geometry_msgs::*;
    use super::nav_msgs::*;
    use super::rosgraph_msgs::*;
    use super::sensor_msgs::*;
    use super::slosh_msgs::*;
    use super::std_msgs::*;
    use super::std_srvs::*;
    use super::tf2_msgs::*;
    use super::*;

    fn round_trip<
        T: serde::Serialize + serde::de::DeserializeOwned + PartialEq + std::fmt::Debug,
    >(
        value: &T,
    ) {
        let bytes = to_cdr(value);
        assert_eq!(&bytes[..4], &CDR_LE_HEADER);
        let back: T = from_cdr(&bytes).unwrap_or_else(|e| panic!("{value:?}: {e}"));
        assert_eq!(&back, value);
        // Nothing is left over, and every strict prefix of the body fails to decode.
        for cut in 4..bytes.len() {
            assert!(
                from_cdr::<T>(&bytes[..cut]).is_err(),
                "{value:?} cut at {cut}"
            );
        }
    }

    fn header(frame: &str) -> Header {
        Header::new(
            Time {
                sec: -7,
                nanosec: 123,
            },
            frame,
        )
    }

    fn pose() -> Pose {
        Pose {
            position: Point::new(1.0, -2.0, 3.5),
            orientation: Quaternion::new(0.5, 0.5, -0.5, 0.5),
        }
    }

    fn twist() -> Twist {
        Twist {
            linear: Vector3::new(0.1, 0.2, 0.3),
            angular: Vector3::new(-0.1, -0.2, -0.3),
        }
    }

    fn transform_stamped(child: &str) -> TransformStamped {
        TransformStamped {
            header: header("world"),
            child_frame_id: child.into(),
            transform: Transform {
                translation: Vector3::new(4.0, 5.0, 6.0),
                rotation: Quaternion::identity(),
            },
        }
    }

    fn covariance() -> [f64; 36] {
        std::array::from_fn(|i| i as f64 * 0.5)
    }

    #[test]
    fn every_type_round_trips() {
        round_trip(&Time::from_secs_f64(-1.5));
        round_trip(&Duration::from_secs_f64(2.75));
        round_trip(&header("tank"));
        round_trip(&Point::new(1.0, 2.0, 3.0));
        round_trip(&Quaternion::identity());
        round_trip(&pose());
        round_trip(&PoseStamped {
            header: header("a"),
            pose: pose(),
        });
        round_trip(&Vector3::new(-1.0, 0.0, 9.81));
        round_trip(&twist());
        round_trip(&TwistStamped {
            header: header("ab"),
            twist: twist(),
        });
        round_trip(&Accel {
            linear: Vector3::new(1.0, 2.0, 3.0),
            angular: Vector3::new(4.0, 5.0, 6.0),
        });
        round_trip(&AccelStamped {
            header: header("abc"),
            accel: Accel::default(),
        });
        let wrench = Wrench {
            force: Vector3::new(0.0, 0.0, -153.0),
            torque: Vector3::new(0.0, 12.5, 0.0),
        };
        round_trip(&wrench);
        round_trip(&WrenchStamped {
            header: header("tank"),
            wrench,
        });
        round_trip(&PoseWithCovariance {
            pose: pose(),
            covariance: covariance(),
        });
        round_trip(&TwistWithCovariance {
            twist: twist(),
            covariance: covariance(),
        });
        round_trip(&transform_stamped("x").transform);
        round_trip(&transform_stamped("tank"));
        round_trip(&Odometry {
            header: header("world"),
            child_frame_id: "tank".into(),
            pose: PoseWithCovariance {
                pose: pose(),
                covariance: covariance(),
            },
            twist: TwistWithCovariance::default(),
        });
        round_trip(&Imu {
            header: header("imu"),
            orientation: Quaternion::identity(),
            orientation_covariance: [1.0; 9],
            angular_velocity: Vector3::new(0.0, 0.1, 0.0),
            angular_velocity_covariance: [2.0; 9],
            linear_acceleration: Vector3::new(0.0, 0.0, 9.81),
            linear_acceleration_covariance: [-1.0; 9],
        });
        let field = PointField::new("x", 0, PointField::FLOAT32, 1);
        round_trip(&field);
        round_trip(&PointCloud2 {
            header: header("tank"),
            height: 1,
            width: 2,
            fields: vec![field, PointField::new("i", 4, PointField::UINT8, 1)],
            is_bigendian: false,
            point_step: 5,
            row_step: 10,
            data: (0..10).collect(),
            is_dense: true,
        });
        round_trip(&Clock {
            clock: Time::from_secs_f64(12.5),
        });
        let kv = KeyValue::new("particles", "4900");
        round_trip(&kv);
        let status = DiagnosticStatus {
            level: DiagnosticStatus::WARN,
            name: "slosh".into(),
            message: "slow".into(),
            hardware_id: "cpu".into(),
            values: vec![kv.clone(), KeyValue::new("rtf", "0.05")],
        };
        round_trip(&status);
        round_trip(&DiagnosticArray {
            header: header(""),
            status: vec![status.clone(), DiagnosticStatus::default()],
        });
        round_trip(&TFMessage {
            transforms: vec![transform_stamped("tank"), transform_stamped("liquid")],
        });
        round_trip(&ProbeArray {
            header: header("tank"),
            names: vec!["p1".into(), "p2".into()],
            positions: vec![Point::new(-0.3, 0.0, 0.0), Point::new(0.3, 0.0, 0.0)],
            elevations: vec![0.38, 0.4],
        });
        round_trip(&PressureArray {
            header: header("tank"),
            names: vec!["s".into()],
            positions: vec![Point::new(-0.5, 0.0, 0.1)],
            pressures: vec![2900.0],
        });
        round_trip(&TriggerRequest::default());
        round_trip(&TriggerResponse {
            success: true,
            message: "reset".into(),
        });
        round_trip(&EmptyRequest::default());
        round_trip(&EmptyResponse::default());
    }

    #[test]
    fn nan_elevations_survive() {
        let msg = ProbeArray {
            header: header("tank"),
            names: vec!["dry".into()],
            positions: vec![Point::default()],
            elevations: vec![f64::NAN],
        };
        let back: ProbeArray = from_cdr(&to_cdr(&msg)).unwrap();
        assert!(back.elevations[0].is_nan());
    }

    #[test]
    fn names() {
        assert_eq!(Time::type_name(), "builtin_interfaces/msg/Time");
        assert_eq!(
            Time::dds_type_name(),
            "builtin_interfaces::msg::dds_::Time_"
        );
        assert_eq!(TFMessage::type_name(), "tf2_msgs/msg/TFMessage");
        assert_eq!(
            ProbeArray::dds_type_name(),
            "slosh_msgs::msg::dds_::ProbeArray_"
        );
        assert_eq!(Trigger::type_name(), "std_srvs/srv/Trigger");
        assert_eq!(Trigger::request_type_name(), "std_srvs/srv/Trigger_Request");
        assert_eq!(Empty::response_type_name(), "std_srvs/srv/Empty_Response");
        assert_eq!(
            Trigger::request_dds_type_name(),
            "std_srvs::srv::dds_::Trigger_Request_"
        );
        assert_eq!(
            Empty::response_dds_type_name(),
            "std_srvs::srv::dds_::Empty_Response_"
        );
        assert!(Trigger::DEFINITION.starts_with("---\n"));
        assert!(Trigger::DEFINITION.contains("\nbool success"));
        assert_eq!(Empty::DEFINITION, "---\n");
        for desc in ALL_MESSAGES {
            assert_eq!(
                desc.full_name,
                format!("{}/msg/{}", desc.package, desc.name)
            );
            assert_eq!(desc.short_name, format!("{}/{}", desc.package, desc.name));
            assert_eq!(
                find_message(desc.full_name).map(|d| d.full_name),
                Some(desc.full_name)
            );
            assert_eq!(
                find_message(desc.short_name).map(|d| d.full_name),
                Some(desc.full_name)
            );
        }
        let unique: BTreeSet<_> = ALL_MESSAGES.iter().map(|d| d.full_name).collect();
        assert_eq!(unique.len(), ALL_MESSAGES.len());
        assert!(find_message("std_msgs/msg/String").is_none());
    }

    /// The message types a `.msg` text names, found as rosbag2 finds them: the first word of
    /// each field or constant line, without its array suffix, unless primitive; a name without a
    /// package is in `package`.
    fn parse_dependencies(text: &str, package: &str) -> BTreeSet<String> {
        const PRIMITIVES: &[&str] = &[
            "bool", "byte", "char", "float32", "float64", "int8", "uint8", "int16", "uint16",
            "int32", "uint32", "int64", "uint64", "string",
        ];
        text.lines()
            .map(str::trim_start)
            .filter(|line| !line.is_empty() && !line.starts_with('#'))
            .filter_map(|line| line.split_whitespace().next())
            .map(|word| word.split('[').next().unwrap_or(word))
            .filter(|ty| !PRIMITIVES.contains(ty))
            .map(|ty| {
                if ty.contains('/') {
                    ty.to_string()
                } else {
                    format!("{package}/{ty}")
                }
            })
            .collect()
    }

    #[test]
    fn declared_dependencies_match_the_definitions() {
        for desc in ALL_MESSAGES {
            let declared: BTreeSet<String> = desc
                .direct_dependencies
                .iter()
                .map(|d| d.short_name.to_string())
                .collect();
            assert_eq!(
                declared.len(),
                desc.direct_dependencies.len(),
                "{} lists a dependency twice",
                desc.full_name
            );
            assert_eq!(
                declared,
                parse_dependencies(desc.definition, desc.package),
                "{}",
                desc.full_name
            );
            let all = desc.dependencies();
            let unique: BTreeSet<_> = all.iter().map(|(n, _)| *n).collect();
            assert_eq!(unique.len(), all.len(), "{}", desc.full_name);
            assert!(!unique.contains(desc.full_name), "{}", desc.full_name);
        }
    }

    #[test]
    fn dependencies_are_in_rosbag2_order() {
        let names: Vec<&str> = Odometry::dependencies().iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names,
            [
                "geometry_msgs/msg/PoseWithCovariance",
                "geometry_msgs/msg/Pose",
                "geometry_msgs/msg/Point",
                "geometry_msgs/msg/Quaternion",
                "geometry_msgs/msg/TwistWithCovariance",
                "geometry_msgs/msg/Twist",
                "geometry_msgs/msg/Vector3",
                "std_msgs/msg/Header",
                "builtin_interfaces/msg/Time",
            ]
        );
        let names: Vec<&str> = ProbeArray::dependencies().iter().map(|(n, _)| *n).collect();
        assert_eq!(
            names,
            [
                "geometry_msgs/msg/Point",
                "std_msgs/msg/Header",
                "builtin_interfaces/msg/Time",
            ]
        );
        assert!(Time::dependencies().is_empty());
    }

    #[test]
    fn ros2msg_schema_is_rosbag2s() {
        let sep = "=".repeat(80);
        assert_eq!(
            Clock::ros2msg_schema(),
            format!(
                "{}\n{sep}\nMSG: builtin_interfaces/Time\n{}",
                Clock::DEFINITION,
                Time::DEFINITION
            )
        );
        let schema = PoseStamped::ros2msg_schema();
        let tail = &schema[PoseStamped::DEFINITION.len()..];
        assert!(tail.starts_with(&format!("\n{sep}\nMSG: geometry_msgs/Pose\n")));
        assert_eq!(
            schema.lines().filter(|l| *l == sep).count(),
            PoseStamped::dependencies().len()
        );
        let msg_lines: Vec<&str> = schema.lines().filter(|l| l.starts_with("MSG: ")).collect();
        assert_eq!(
            msg_lines,
            [
                "MSG: geometry_msgs/Pose",
                "MSG: geometry_msgs/Point",
                "MSG: geometry_msgs/Quaternion",
                "MSG: std_msgs/Header",
                "MSG: builtin_interfaces/Time",
            ]
        );
    }

    #[test]
    fn slosh_msgs_definitions_are_the_package_files() {
        assert!(ProbeArray::DEFINITION.contains("\nfloat64[] elevations\n"));
        assert!(PressureArray::DEFINITION.contains("\nfloat64[] pressures\n"));
        let fields = |text: &str| -> Vec<String> {
            text.lines()
                .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
                .map(str::to_string)
                .collect()
        };
        assert_eq!(
            fields(ProbeArray::DEFINITION),
            [
                "std_msgs/Header header",
                "string[] names",
                "geometry_msgs/Point[] positions",
                "float64[] elevations"
            ]
        );
        assert_eq!(
            fields(PressureArray::DEFINITION),
            [
                "std_msgs/Header header",
                "string[] names",
                "geometry_msgs/Point[] positions",
                "float64[] pressures"
            ]
        );
    }
}
