//! `slosh_msgs`: the simulator's own messages, [`ProbeArray`] and [`PressureArray`].
//!
//! The ROS 2 interface package is `msgs/ros2/slosh_msgs`; its `.msg` files are these types'
//! definitions (embedded with `include_str!`), so building it in a ROS 2 workspace gives other
//! ROS 2 nodes the same types.

use serde::{Deserialize, Serialize};

use crate::geometry_msgs::Point;
use crate::message::ros_message;
use crate::std_msgs::Header;

/// `slosh_msgs/msg/ProbeArray`: free-surface elevations at the wave probes of a tank.
///
/// `names`, `positions` and `elevations` have one element per probe, in the same order.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct ProbeArray {
    /// Simulation time of the liquid state, and the tank frame.
    pub header: Header,
    /// Probe names.
    pub names: Vec<String>,
    /// Probe positions in the tank frame, m: (x, y) of the probe line, z = 0.
    pub positions: Vec<Point>,
    /// Free-surface elevation above the tank bottom along the tank's z axis, m; NaN when the
    /// probe sees no liquid column.
    pub elevations: Vec<f64>,
}

/// `slosh_msgs/msg/PressureArray`: gauge pressures at the pressure sensors of a tank.
///
/// `names`, `positions` and `pressures` have one element per sensor, in the same order.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct PressureArray {
    /// Simulation time of the liquid state, and the tank frame.
    pub header: Header,
    /// Sensor names.
    pub names: Vec<String>,
    /// Sensor positions in the tank frame, m.
    pub positions: Vec<Point>,
    /// Gauge pressure, Pa; 0 when the sensor is dry.
    pub pressures: Vec<f64>,
}

ros_message!(
    ProbeArray,
    "slosh_msgs",
    "ProbeArray",
    include_str!("../ros2/slosh_msgs/msg/ProbeArray.msg"),
    [Header, Point]
);
ros_message!(
    PressureArray,
    "slosh_msgs",
    "PressureArray",
    include_str!("../ros2/slosh_msgs/msg/PressureArray.msg"),
    [Header, Point]
);
