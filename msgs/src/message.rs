//! The [`RosMessage`] and [`RosService`] traits: ROS names, `.msg` texts and MCAP schemas.

use std::collections::HashSet;
use std::fmt::Debug;

use serde::de::DeserializeOwned;
use serde::Serialize;

/// The line of 80 `=` that separates definitions in a `ros2msg` schema.
pub const SCHEMA_SEPARATOR: &str =
    "================================================================================";

/// Static description of one message type: its names, its `.msg` text and the message types its
/// fields name directly.
///
/// The descriptions of all types form a graph; [`MessageDescription::dependencies`] walks it the
/// way rosbag2 does when it writes a bag's message definitions.
#[derive(Debug)]
pub struct MessageDescription {
    /// ROS package, e.g. `"geometry_msgs"`.
    pub package: &'static str,
    /// Type name, e.g. `"WrenchStamped"`.
    pub name: &'static str,
    /// `"pkg/msg/Type"`.
    pub full_name: &'static str,
    /// `"pkg/Type"`, the form `.msg` files use to name a field's type and the form of the
    /// `MSG:` lines of a `ros2msg` schema.
    pub short_name: &'static str,
    /// The `.msg` text, as in the package's interface file.
    pub definition: &'static str,
    /// The message types named by the fields of [`Self::definition`], each once.
    pub direct_dependencies: &'static [&'static MessageDescription],
}

impl MessageDescription {
    /// Direct and transitive dependencies as (`"pkg/msg/Type"`, `.msg` text), each once.
    ///
    /// The order is rosbag2's (`LocalMessageDefinitionSource::get_full_text` of ROS 2 Jazzy): a
    /// depth-first walk from this type that visits the dependencies of each type sorted by their
    /// `"pkg/Type"` names and lists each type when it is first reached, before its own
    /// dependencies.
    pub fn dependencies(&'static self) -> Vec<(&'static str, &'static str)> {
        fn walk(
            desc: &'static MessageDescription,
            seen: &mut HashSet<&'static str>,
            out: &mut Vec<(&'static str, &'static str)>,
        ) {
            let mut direct: Vec<&'static MessageDescription> = desc.direct_dependencies.to_vec();
            direct.sort_by_key(|d| d.short_name);
            for dep in direct {
                if seen.insert(dep.full_name) {
                    out.push((dep.full_name, dep.definition));
                    walk(dep, seen, out);
                }
            }
        }
        let mut seen = HashSet::new();
        let mut out = Vec::new();
        walk(self, &mut seen, &mut out);
        out
    }

    /// The MCAP `ros2msg` schema, exactly as rosbag2 writes it: this type's `.msg` text, then for
    /// each of [`Self::dependencies`] a newline, a line of 80 `=`, a line `MSG: pkg/Type` and the
    /// dependency's `.msg` text.
    pub fn ros2msg_schema(&'static self) -> String {
        let mut schema = String::from(self.definition);
        for (full_name, definition) in self.dependencies() {
            schema.push('\n');
            schema.push_str(SCHEMA_SEPARATOR);
            schema.push_str("\nMSG: ");
            schema.push_str(&full_name.replacen("/msg/", "/", 1));
            schema.push('\n');
            schema.push_str(definition);
        }
        schema
    }
}

/// A ROS 2 message type with ROS 2's exact CDR layout (see [`crate::cdr`]), its `.msg` text and
/// ROS type names.
pub trait RosMessage:
    Serialize + DeserializeOwned + Clone + Debug + PartialEq + Send + Sync + 'static
{
    /// ROS package, e.g. `"geometry_msgs"`.
    const PACKAGE: &'static str;
    /// Type name, e.g. `"WrenchStamped"`.
    const NAME: &'static str;
    /// The `.msg` text of this type, exactly as in ROS 2 Jazzy's interface file.
    const DEFINITION: &'static str;
    /// The description this type's names, definition and dependencies come from.
    const DESCRIPTION: &'static MessageDescription;

    /// Direct and transitive dependencies as (full name `"pkg/msg/Type"`, `.msg` text), each
    /// once, in the order rosbag2 writes them (see [`MessageDescription::dependencies`]).
    fn dependencies() -> Vec<(&'static str, &'static str)> {
        Self::DESCRIPTION.dependencies()
    }

    /// `"pkg/msg/Type"`, e.g. `"geometry_msgs/msg/WrenchStamped"`.
    fn type_name() -> String {
        format!("{}/msg/{}", Self::PACKAGE, Self::NAME)
    }

    /// DDS type name `"pkg::msg::dds_::Type_"`, e.g. `"geometry_msgs::msg::dds_::WrenchStamped_"`.
    fn dds_type_name() -> String {
        format!("{}::msg::dds_::{}_", Self::PACKAGE, Self::NAME)
    }

    /// The MCAP `ros2msg` schema: own definition, then for each dependency a line of 80 `=`, a
    /// line `MSG: pkg/Type` (no `/msg/`) and its `.msg` text, as rosbag2 writes it (see
    /// [`MessageDescription::ros2msg_schema`]).
    fn ros2msg_schema() -> String {
        Self::DESCRIPTION.ros2msg_schema()
    }
}

/// A ROS 2 service type: its `.srv` text, names and request and response types.
///
/// The request and response are plain CDR structs like messages; as in ROS 2, a request or
/// response with no fields has one `uint8 structure_needs_at_least_one_member`.
pub trait RosService {
    /// ROS package, e.g. `"std_srvs"`.
    const PACKAGE: &'static str;
    /// Service name, e.g. `"Trigger"`.
    const NAME: &'static str;
    /// The `.srv` text, exactly as in ROS 2 Jazzy's interface file.
    const DEFINITION: &'static str;
    /// The request message.
    type Request: Serialize + DeserializeOwned + Clone + Debug + PartialEq + Send + Sync + 'static;
    /// The response message.
    type Response: Serialize + DeserializeOwned + Clone + Debug + PartialEq + Send + Sync + 'static;

    /// `"pkg/srv/Name"`, e.g. `"std_srvs/srv/Trigger"`.
    fn type_name() -> String {
        format!("{}/srv/{}", Self::PACKAGE, Self::NAME)
    }

    /// `"pkg/srv/Name_Request"`.
    fn request_type_name() -> String {
        format!("{}/srv/{}_Request", Self::PACKAGE, Self::NAME)
    }

    /// `"pkg/srv/Name_Response"`.
    fn response_type_name() -> String {
        format!("{}/srv/{}_Response", Self::PACKAGE, Self::NAME)
    }

    /// DDS type name of the request, `"pkg::srv::dds_::Name_Request_"`.
    fn request_dds_type_name() -> String {
        format!("{}::srv::dds_::{}_Request_", Self::PACKAGE, Self::NAME)
    }

    /// DDS type name of the response, `"pkg::srv::dds_::Name_Response_"`.
    fn response_dds_type_name() -> String {
        format!("{}::srv::dds_::{}_Response_", Self::PACKAGE, Self::NAME)
    }
}

/// Implements [`RosMessage`] for a struct: `ros_message!(Type, "pkg", "Name", DEFINITION,
/// [DepType, ...])`, the dependency list naming the message types of the fields, each once.
/// With the `ros2-client` feature, also implements `ros2_client::Message`.
macro_rules! ros_message {
    ($ty:ty, $pkg:literal, $name:literal, $def:expr, [$($dep:ty),* $(,)?]) => {
        impl $crate::message::RosMessage for $ty {
            const PACKAGE: &'static str = $pkg;
            const NAME: &'static str = $name;
            const DEFINITION: &'static str = $def;
            const DESCRIPTION: &'static $crate::message::MessageDescription =
                &$crate::message::MessageDescription {
                    package: $pkg,
                    name: $name,
                    full_name: concat!($pkg, "/msg/", $name),
                    short_name: concat!($pkg, "/", $name),
                    definition: $def,
                    direct_dependencies: &[
                        $(<$dep as $crate::message::RosMessage>::DESCRIPTION),*
                    ],
                };
        }

        #[cfg(feature = "ros2-client")]
        impl ros2_client::Message for $ty {}
    };
}
pub(crate) use ros_message;
