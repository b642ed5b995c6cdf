//! `nav_msgs`: [`Odometry`].

use serde::{Deserialize, Serialize};

use crate::geometry_msgs::{PoseWithCovariance, TwistWithCovariance};
use crate::message::ros_message;
use crate::std_msgs::Header;

/// `nav_msgs/msg/Odometry`: an estimate of a pose (in `header.frame_id`) and a velocity (in
/// `child_frame_id`).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct Odometry {
    /// Time, and the frame of the pose.
    pub header: Header,
    /// The frame the pose points to; the twist is expressed in it.
    pub child_frame_id: String,
    /// Pose of `child_frame_id` in `header.frame_id`.
    pub pose: PoseWithCovariance,
    /// Linear and angular velocity, in `child_frame_id`.
    pub twist: TwistWithCovariance,
}

ros_message!(
    Odometry,
    "nav_msgs",
    "Odometry",
    ODOMETRY_MSG,
    [Header, PoseWithCovariance, TwistWithCovariance]
);

// The interface files of ROS 2 Jazzy, verbatim.

const ODOMETRY_MSG: &str = r#"# This represents an estimate of a position and velocity in free space.
# The pose in this message should be specified in the coordinate frame given by header.frame_id
# The twist in this message should be specified in the coordinate frame given by the child_frame_id

# Includes the frame id of the pose parent.
std_msgs/Header header

# Frame id the pose points to. The twist is in this coordinate frame.
string child_frame_id

# Estimated pose that is typically relative to a fixed world frame.
geometry_msgs/PoseWithCovariance pose

# Estimated linear and angular velocity relative to child_frame_id.
geometry_msgs/TwistWithCovariance twist
"#;
