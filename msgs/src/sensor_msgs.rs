//! `sensor_msgs`: [`Imu`], [`PointField`] and [`PointCloud2`].

use serde::{Deserialize, Serialize};

use crate::geometry_msgs::{Quaternion, Vector3};
use crate::message::ros_message;
use crate::std_msgs::Header;

/// `sensor_msgs/msg/Imu`: orientation, angular velocity and linear acceleration of an IMU.
///
/// A covariance of all zeros means "unknown"; element 0 = −1 means the estimate is absent.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Default)]
pub struct Imu {
    /// Time and sensor frame.
    pub header: Header,
    /// Orientation.
    pub orientation: Quaternion,
    /// Row-major 3×3 covariance about x, y, z.
    pub orientation_covariance: [f64; 9],
    /// Angular velocity, rad/s.
    pub angular_velocity: Vector3,
    /// Row-major 3×3 covariance about x, y, z.
    pub angular_velocity_covariance: [f64; 9],
    /// Linear acceleration, m/s² (not in g).
    pub linear_acceleration: Vector3,
    /// Row-major 3×3 covariance of x, y, z.
    pub linear_acceleration_covariance: [f64; 9],
}

/// `sensor_msgs/msg/PointField`: one field of the points of a [`PointCloud2`].
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct PointField {
    /// Field name, e.g. `x`, `y`, `z`, `intensity`, `rgb`.
    pub name: String,
    /// Offset of the field from the start of a point, bytes.
    pub offset: u32,
    /// Element type: one of [`PointField::INT8`] … [`PointField::FLOAT64`].
    pub datatype: u8,
    /// Number of elements in the field.
    pub count: u32,
}

impl PointField {
    /// `datatype` of `int8` elements.
    pub const INT8: u8 = 1;
    /// `datatype` of `uint8` elements.
    pub const UINT8: u8 = 2;
    /// `datatype` of `int16` elements.
    pub const INT16: u8 = 3;
    /// `datatype` of `uint16` elements.
    pub const UINT16: u8 = 4;
    /// `datatype` of `int32` elements.
    pub const INT32: u8 = 5;
    /// `datatype` of `uint32` elements.
    pub const UINT32: u8 = 6;
    /// `datatype` of `float32` elements.
    pub const FLOAT32: u8 = 7;
    /// `datatype` of `float64` elements.
    pub const FLOAT64: u8 = 8;

    /// A field `name` of `count` elements of type `datatype` at byte `offset`.
    pub fn new(name: impl Into<String>, offset: u32, datatype: u8, count: u32) -> Self {
        Self {
            name: name.into(),
            offset,
            datatype,
            count,
        }
    }

    /// Size of one element of `datatype`, bytes (`None` for an unknown datatype).
    pub fn datatype_size(datatype: u8) -> Option<u32> {
        match datatype {
            Self::INT8 | Self::UINT8 => Some(1),
            Self::INT16 | Self::UINT16 => Some(2),
            Self::INT32 | Self::UINT32 | Self::FLOAT32 => Some(4),
            Self::FLOAT64 => Some(8),
            _ => None,
        }
    }
}

/// `sensor_msgs/msg/PointCloud2`: a cloud of N-dimensional points in a binary blob laid out as
/// `fields` describe.
#[derive(Serialize, Deserialize, Clone, Debug, PartialEq, Eq, Hash, Default)]
pub struct PointCloud2 {
    /// Time of acquisition and frame of the points.
    pub header: Header,
    /// Rows; 1 for an unordered cloud.
    pub height: u32,
    /// Points per row; the number of points for an unordered cloud.
    pub width: u32,
    /// Layout of a point in `data`.
    pub fields: Vec<PointField>,
    /// Whether `data` is big endian.
    pub is_bigendian: bool,
    /// Length of a point, bytes.
    pub point_step: u32,
    /// Length of a row, bytes.
    pub row_step: u32,
    /// The points, `row_step · height` bytes (a CDR `sequence<uint8>`).
    #[serde(with = "crate::cdr::byte_seq")]
    pub data: Vec<u8>,
    /// True if there are no invalid points.
    pub is_dense: bool,
}

ros_message!(
    Imu,
    "sensor_msgs",
    "Imu",
    IMU_MSG,
    [Header, Quaternion, Vector3]
);
ros_message!(PointField, "sensor_msgs", "PointField", POINT_FIELD_MSG, []);
ros_message!(
    PointCloud2,
    "sensor_msgs",
    "PointCloud2",
    POINT_CLOUD2_MSG,
    [Header, PointField]
);

// The interface files of ROS 2 Jazzy, verbatim.

const IMU_MSG: &str = r#"# This is a message to hold data from an IMU (Inertial Measurement Unit)
#
# Accelerations should be in m/s^2 (not in g's), and rotational velocity should be in rad/sec
#
# If the covariance of the measurement is known, it should be filled in (if all you know is the
# variance of each measurement, e.g. from the datasheet, just put those along the diagonal)
# A covariance matrix of all zeros will be interpreted as "covariance unknown", and to use the
# data a covariance will have to be assumed or gotten from some other source
#
# If you have no estimate for one of the data elements (e.g. your IMU doesn't produce an
# orientation estimate), please set element 0 of the associated covariance matrix to -1
# If you are interpreting this message, please check for a value of -1 in the first element of each
# covariance matrix, and disregard the associated estimate.

std_msgs/Header header

geometry_msgs/Quaternion orientation
float64[9] orientation_covariance # Row major about x, y, z axes

geometry_msgs/Vector3 angular_velocity
float64[9] angular_velocity_covariance # Row major about x, y, z axes

geometry_msgs/Vector3 linear_acceleration
float64[9] linear_acceleration_covariance # Row major x, y z
"#;

const POINT_FIELD_MSG: &str = r#"# This message holds the description of one point entry in the
# PointCloud2 message format.
uint8 INT8    = 1
uint8 UINT8   = 2
uint8 INT16   = 3
uint8 UINT16  = 4
uint8 INT32   = 5
uint8 UINT32  = 6
uint8 FLOAT32 = 7
uint8 FLOAT64 = 8

# Common PointField names are x, y, z, intensity, rgb, rgba
string name      # Name of field
uint32 offset    # Offset from start of point struct
uint8  datatype  # Datatype enumeration, see above
uint32 count     # How many elements in the field
"#;

const POINT_CLOUD2_MSG: &str = r#"# This message holds a collection of N-dimensional points, which may
# contain additional information such as normals, intensity, etc. The
# point data is stored as a binary blob, its layout described by the
# contents of the "fields" array.
#
# The point cloud data may be organized 2d (image-like) or 1d (unordered).
# Point clouds organized as 2d images may be produced by camera depth sensors
# such as stereo or time-of-flight.

# Time of sensor data acquisition, and the coordinate frame ID (for 3d points).
std_msgs/Header header

# 2D structure of the point cloud. If the cloud is unordered, height is
# 1 and width is the length of the point cloud.
uint32 height
uint32 width

# Describes the channels and their layout in the binary data blob.
PointField[] fields

bool    is_bigendian # Is this data bigendian?
uint32  point_step   # Length of a point in bytes
uint32  row_step     # Length of a row in bytes
uint8[] data         # Actual point data, size is (row_step*height)

bool is_dense        # True if there are no invalid points
"#;
