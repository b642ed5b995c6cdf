//! `tf2_msgs`: [`TFMessage`].

use serde::{Deserialize, Serialize};

use crate::geometry_msgs::TransformStamped;
use crate::message::ros_message;

/// `tf2_msgs/msg/TFMessage`: transforms, as published on `/tf` and `/tf_static`.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct TFMessage {
    /// The transforms.
    pub transforms: Vec<TransformStamped>,
}

ros_message!(
    TFMessage,
    "tf2_msgs",
    "TFMessage",
    TF_MESSAGE_MSG,
    [TransformStamped]
);

// The interface files of ROS 2 Jazzy, verbatim.

const TF_MESSAGE_MSG: &str = r#"geometry_msgs/TransformStamped[] transforms
"#;
