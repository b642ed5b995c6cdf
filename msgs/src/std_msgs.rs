//! `std_msgs`: [`Header`].

use serde::{Deserialize, Serialize};

use crate::builtin_interfaces::Time;
use crate::message::ros_message;

/// `std_msgs/msg/Header`: the time stamp and coordinate frame of stamped data.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct Header {
    /// Time of the data.
    pub stamp: Time,
    /// Coordinate frame the data is expressed in.
    pub frame_id: String,
}

impl Header {
    /// A header with the given stamp and frame.
    pub fn new(stamp: Time, frame_id: impl Into<String>) -> Self {
        Self {
            stamp,
            frame_id: frame_id.into(),
        }
    }
}

ros_message!(Header, "std_msgs", "Header", HEADER_MSG, [Time]);

// The interface files of ROS 2 Jazzy, verbatim.

const HEADER_MSG: &str = r#"# Standard metadata for higher-level stamped data types.
# This is generally used to communicate timestamped data
# in a particular coordinate frame.

# Two-integer timestamp that is expressed as seconds and nanoseconds.
builtin_interfaces/Time stamp

# Transform frame with which this data is associated.
string frame_id
"#;
