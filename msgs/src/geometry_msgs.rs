//! `geometry_msgs`: points, vectors, poses, twists, accelerations, wrenches and transforms.

use serde::{Deserialize, Serialize};
use serde_big_array::BigArray;

use crate::message::ros_message;
use crate::std_msgs::Header;

/// `geometry_msgs/msg/Point`: a position in free space, m.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub struct Point {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl Point {
    /// The point (x, y, z).
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
}

/// `geometry_msgs/msg/Quaternion`: an orientation, `w + xi + yj + zk`.
///
/// `Default` gives all zeros (not a rotation); ROS's default is the identity, see
/// [`Quaternion::identity`].
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub struct Quaternion {
    /// x (i component).
    pub x: f64,
    /// y (j component).
    pub y: f64,
    /// z (k component).
    pub z: f64,
    /// w (real part).
    pub w: f64,
}

impl Quaternion {
    /// The quaternion (x, y, z, w).
    pub const fn new(x: f64, y: f64, z: f64, w: f64) -> Self {
        Self { x, y, z, w }
    }

    /// The identity rotation (0, 0, 0, 1), the default of the `.msg` file.
    pub const fn identity() -> Self {
        Self::new(0.0, 0.0, 0.0, 1.0)
    }
}

/// `geometry_msgs/msg/Pose`: a position and an orientation.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub struct Pose {
    /// Position, m.
    pub position: Point,
    /// Orientation.
    pub orientation: Quaternion,
}

/// `geometry_msgs/msg/PoseStamped`: a [`Pose`] with a frame and time stamp.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct PoseStamped {
    /// Time and frame.
    pub header: Header,
    /// The pose.
    pub pose: Pose,
}

/// `geometry_msgs/msg/Vector3`: a free vector (rotated, but not translated, by transforms).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub struct Vector3 {
    /// x.
    pub x: f64,
    /// y.
    pub y: f64,
    /// z.
    pub z: f64,
}

impl Vector3 {
    /// The vector (x, y, z).
    pub const fn new(x: f64, y: f64, z: f64) -> Self {
        Self { x, y, z }
    }
}

/// `geometry_msgs/msg/Twist`: linear (m/s) and angular (rad/s) velocity.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub struct Twist {
    /// Linear velocity, m/s.
    pub linear: Vector3,
    /// Angular velocity, rad/s.
    pub angular: Vector3,
}

/// `geometry_msgs/msg/TwistStamped`: a [`Twist`] with a frame and time stamp.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct TwistStamped {
    /// Time and frame.
    pub header: Header,
    /// The twist.
    pub twist: Twist,
}

/// `geometry_msgs/msg/Accel`: linear (m/s²) and angular (rad/s²) acceleration.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub struct Accel {
    /// Linear acceleration, m/s².
    pub linear: Vector3,
    /// Angular acceleration, rad/s².
    pub angular: Vector3,
}

/// `geometry_msgs/msg/AccelStamped`: an [`Accel`] with a frame and time stamp.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct AccelStamped {
    /// Time and frame.
    pub header: Header,
    /// The acceleration.
    pub accel: Accel,
}

/// `geometry_msgs/msg/Wrench`: a force (N) and a torque (N·m).
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub struct Wrench {
    /// Force, N.
    pub force: Vector3,
    /// Torque, N·m.
    pub torque: Vector3,
}

/// `geometry_msgs/msg/WrenchStamped`: a [`Wrench`] with a frame and time stamp.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct WrenchStamped {
    /// Time and frame.
    pub header: Header,
    /// The wrench.
    pub wrench: Wrench,
}

/// `geometry_msgs/msg/PoseWithCovariance`: a [`Pose`] and its uncertainty.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct PoseWithCovariance {
    /// The pose.
    pub pose: Pose,
    /// Row-major 6×6 covariance of (x, y, z, rotation about X, about Y, about Z), the rotations
    /// about fixed axes.
    #[serde(with = "BigArray")]
    pub covariance: [f64; 36],
}

impl Default for PoseWithCovariance {
    fn default() -> Self {
        Self {
            pose: Pose::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `geometry_msgs/msg/TwistWithCovariance`: a [`Twist`] and its uncertainty.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq)]
pub struct TwistWithCovariance {
    /// The twist.
    pub twist: Twist,
    /// Row-major 6×6 covariance of (x, y, z, rotation about X, about Y, about Z), the rotations
    /// about fixed axes.
    #[serde(with = "BigArray")]
    pub covariance: [f64; 36],
}

impl Default for TwistWithCovariance {
    fn default() -> Self {
        Self {
            twist: Twist::default(),
            covariance: [0.0; 36],
        }
    }
}

/// `geometry_msgs/msg/Transform`: the transform between two coordinate frames.
#[derive(Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Default)]
pub struct Transform {
    /// Translation, m.
    pub translation: Vector3,
    /// Rotation.
    pub rotation: Quaternion,
}

/// `geometry_msgs/msg/TransformStamped`: the transform from `header.frame_id` to
/// `child_frame_id` at `header.stamp` (the pose of the child frame in the parent frame).
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct TransformStamped {
    /// Time and parent frame.
    pub header: Header,
    /// The child frame.
    pub child_frame_id: String,
    /// Translation and rotation of the child frame in the parent frame.
    pub transform: Transform,
}

ros_message!(Point, "geometry_msgs", "Point", POINT_MSG, []);
ros_message!(
    Quaternion,
    "geometry_msgs",
    "Quaternion",
    QUATERNION_MSG,
    []
);
ros_message!(Pose, "geometry_msgs", "Pose", POSE_MSG, [Point, Quaternion]);
ros_message!(
    PoseStamped,
    "geometry_msgs",
    "PoseStamped",
    POSE_STAMPED_MSG,
    [Header, Pose]
);
ros_message!(Vector3, "geometry_msgs", "Vector3", VECTOR3_MSG, []);
ros_message!(Twist, "geometry_msgs", "Twist", TWIST_MSG, [Vector3]);
ros_message!(
    TwistStamped,
    "geometry_msgs",
    "TwistStamped",
    TWIST_STAMPED_MSG,
    [Header, Twist]
);
ros_message!(Accel, "geometry_msgs", "Accel", ACCEL_MSG, [Vector3]);
ros_message!(
    AccelStamped,
    "geometry_msgs",
    "AccelStamped",
    ACCEL_STAMPED_MSG,
    [Header, Accel]
);
ros_message!(Wrench, "geometry_msgs", "Wrench", WRENCH_MSG, [Vector3]);
ros_message!(
    WrenchStamped,
    "geometry_msgs",
    "WrenchStamped",
    WRENCH_STAMPED_MSG,
    [Header, Wrench]
);
ros_message!(
    PoseWithCovariance,
    "geometry_msgs",
    "PoseWithCovariance",
    POSE_WITH_COVARIANCE_MSG,
    [Pose]
);
ros_message!(
    TwistWithCovariance,
    "geometry_msgs",
    "TwistWithCovariance",
    TWIST_WITH_COVARIANCE_MSG,
    [Twist]
);
ros_message!(
    Transform,
    "geometry_msgs",
    "Transform",
    TRANSFORM_MSG,
    [Vector3, Quaternion]
);
ros_message!(
    TransformStamped,
    "geometry_msgs",
    "TransformStamped",
    TRANSFORM_STAMPED_MSG,
    [Header, Transform]
);

// The interface files of ROS 2 Jazzy, verbatim.

const POINT_MSG: &str = r#"# This contains the position of a point in free space
float64 x
float64 y
float64 z
"#;

const QUATERNION_MSG: &str = r#"# This represents an orientation in free space in quaternion form.

float64 x 0
float64 y 0
float64 z 0
float64 w 1
"#;

const POSE_MSG: &str = r#"# A representation of pose in free space, composed of position and orientation.

Point position
Quaternion orientation
"#;

const POSE_STAMPED_MSG: &str = r#"# A Pose with reference coordinate frame and timestamp

std_msgs/Header header
Pose pose
"#;

const VECTOR3_MSG: &str = r#"# This represents a vector in free space.

# This is semantically different than a point.
# A vector is always anchored at the origin.
# When a transform is applied to a vector, only the rotational component is applied.

float64 x
float64 y
float64 z
"#;

const TWIST_MSG: &str = r#"# This expresses velocity in free space broken into its linear and angular parts.

Vector3  linear
Vector3  angular
"#;

const TWIST_STAMPED_MSG: &str = r#"# A twist with reference coordinate frame and timestamp

std_msgs/Header header
Twist twist
"#;

const ACCEL_MSG: &str = r#"# This expresses acceleration in free space broken into its linear and angular parts.
Vector3  linear
Vector3  angular
"#;

const ACCEL_STAMPED_MSG: &str = r#"# An accel with reference coordinate frame and timestamp
std_msgs/Header header
Accel accel
"#;

const WRENCH_MSG: &str = r#"# This represents force in free space, separated into its linear and angular parts.

Vector3  force
Vector3  torque
"#;

const WRENCH_STAMPED_MSG: &str = r#"# A wrench with reference coordinate frame and timestamp

std_msgs/Header header
Wrench wrench
"#;

const POSE_WITH_COVARIANCE_MSG: &str = r#"# This represents a pose in free space with uncertainty.

Pose pose

# Row-major representation of the 6x6 covariance matrix
# The orientation parameters use a fixed-axis representation.
# In order, the parameters are:
# (x, y, z, rotation about X axis, rotation about Y axis, rotation about Z axis)
float64[36] covariance
"#;

const TWIST_WITH_COVARIANCE_MSG: &str = r#"# This expresses velocity in free space with uncertainty.

Twist twist

# Row-major representation of the 6x6 covariance matrix
# The orientation parameters use a fixed-axis representation.
# In order, the parameters are:
# (x, y, z, rotation about X axis, rotation about Y axis, rotation about Z axis)
float64[36] covariance
"#;

const TRANSFORM_MSG: &str = r#"# This represents the transform between two coordinate frames in free space.

Vector3 translation
Quaternion rotation
"#;

const TRANSFORM_STAMPED_MSG: &str = r#"# This expresses a transform from coordinate frame header.frame_id
# to the coordinate frame child_frame_id at the time of header.stamp
#
# This message is mostly used by the
# <a href="https://docs.ros.org/en/rolling/p/tf2/">tf2</a> package.
# See its documentation for more information.
#
# The child_frame_id is necessary in addition to the frame_id
# in the Header to communicate the full reference for the transform
# in a self contained message.

# The frame id in the header is used as the reference frame of this transform.
std_msgs/Header header

# The frame id of the child frame to which this transform points.
string child_frame_id

# Translation and rotation in 3-dimensions of child_frame_id from header.frame_id.
Transform transform
"#;
