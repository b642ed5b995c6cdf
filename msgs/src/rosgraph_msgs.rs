//! `rosgraph_msgs`: [`Clock`].

use serde::{Deserialize, Serialize};

use crate::builtin_interfaces::Time;
use crate::message::ros_message;

/// `rosgraph_msgs/msg/Clock`: the current time, as published on `/clock` for simulated time.
#[derive(
    Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default,
)]
pub struct Clock {
    /// The current time.
    pub clock: Time,
}

ros_message!(Clock, "rosgraph_msgs", "Clock", CLOCK_MSG, [Time]);

// The interface files of ROS 2 Jazzy, verbatim.

const CLOCK_MSG: &str = r#"# This message communicates the current time.
#
# For more information, see https://design.ros2.org/articles/clock_and_time.html.
builtin_interfaces/Time clock
"#;
