//! `diagnostic_msgs`: [`KeyValue`], [`DiagnosticStatus`] and [`DiagnosticArray`].

use serde::{Deserialize, Serialize};

use crate::message::ros_message;
use crate::std_msgs::Header;

/// `diagnostic_msgs/msg/KeyValue`: a labelled value.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct KeyValue {
    /// Label of the value.
    pub key: String,
    /// The value.
    pub value: String,
}

impl KeyValue {
    /// The pair (`key`, `value`).
    pub fn new(key: impl Into<String>, value: impl Into<String>) -> Self {
        Self {
            key: key.into(),
            value: value.into(),
        }
    }
}

/// `diagnostic_msgs/msg/DiagnosticStatus`: the status of one component.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct DiagnosticStatus {
    /// Level of operation: [`DiagnosticStatus::OK`], [`DiagnosticStatus::WARN`],
    /// [`DiagnosticStatus::ERROR`] or [`DiagnosticStatus::STALE`] (a `byte`).
    pub level: u8,
    /// Component or test.
    pub name: String,
    /// Description of the status.
    pub message: String,
    /// Hardware unique string.
    pub hardware_id: String,
    /// Values associated with the status.
    pub values: Vec<KeyValue>,
}

impl DiagnosticStatus {
    /// `level`: all well.
    pub const OK: u8 = 0;
    /// `level`: a warning.
    pub const WARN: u8 = 1;
    /// `level`: an error.
    pub const ERROR: u8 = 2;
    /// `level`: no recent data.
    pub const STALE: u8 = 3;
}

/// `diagnostic_msgs/msg/DiagnosticArray`: the statuses of a set of components.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct DiagnosticArray {
    /// Time stamp.
    pub header: Header,
    /// The components' statuses.
    pub status: Vec<DiagnosticStatus>,
}

ros_message!(KeyValue, "diagnostic_msgs", "KeyValue", KEY_VALUE_MSG, []);
ros_message!(
    DiagnosticStatus,
    "diagnostic_msgs",
    "DiagnosticStatus",
    DIAGNOSTIC_STATUS_MSG,
    [KeyValue]
);
ros_message!(
    DiagnosticArray,
    "diagnostic_msgs",
    "DiagnosticArray",
    DIAGNOSTIC_ARRAY_MSG,
    [Header, DiagnosticStatus]
);

// The interface files of ROS 2 Jazzy, verbatim.

const KEY_VALUE_MSG: &str = r#"# What to label this value when viewing.
string key
# A value to track over time.
string value
"#;

const DIAGNOSTIC_STATUS_MSG: &str = r#"# This message holds the status of an individual component of the robot.

# Possible levels of operations.
byte OK=0
byte WARN=1
byte ERROR=2
byte STALE=3

# Level of operation enumerated above.
byte level
# A description of the test/component reporting.
string name
# A description of the status.
string message
# A hardware unique string.
string hardware_id
# An array of values associated with the status.
KeyValue[] values

"#;

const DIAGNOSTIC_ARRAY_MSG: &str = r#"# This message is used to send diagnostic information about the state of the robot.
std_msgs/Header header # for timestamp
DiagnosticStatus[] status # an array of components being reported on
"#;
