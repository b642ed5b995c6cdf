//! Motion messages of a rigid state: nav_msgs/Odometry, geometry_msgs/AccelStamped and sensor_msgs/Imu.

use super::convert::{point_msg, quat_msg, vec3_msg};
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::geometry_msgs::{
    Accel, AccelStamped, Pose, PoseWithCovariance, Twist, TwistWithCovariance,
};
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::sensor_msgs::Imu;
use slosh_msgs::std_msgs::Header;
use sph::motion::RigidState;

/// The Odometry of a rigid state (pose in the world, twist in the body frame as REP 105 says).
pub fn odometry(s: &RigidState, stamp: Time, world: &str, body: &str) -> Odometry {
    let v_body = s.orientation.inverse_transform_vector(&s.velocity);
    Odometry {
        header: Header {
            stamp,
            frame_id: world.into(),
        },
        child_frame_id: body.into(),
        pose: PoseWithCovariance {
            pose: Pose {
                position: point_msg(s.position),
                orientation: quat_msg(s.orientation),
            },
            covariance: [0.0; 36],
        },
        twist: TwistWithCovariance {
            twist: Twist {
                linear: vec3_msg(v_body),
                angular: vec3_msg(s.angular_velocity),
            },
            covariance: [0.0; 36],
        },
    }
}

/// The accelerations of a rigid state in its body frame, as geometry_msgs/AccelStamped.
pub fn accel(s: &RigidState, stamp: Time, body: &str) -> AccelStamped {
    AccelStamped {
        header: Header {
            stamp,
            frame_id: body.into(),
        },
        accel: Accel {
            linear: vec3_msg(s.orientation.inverse_transform_vector(&s.acceleration)),
            angular: vec3_msg(s.angular_acceleration),
        },
    }
}

/// What an IMU at the origin of a rigid state reads: orientation, body angular velocity, and specific force
/// (acceleration minus gravity, in the body frame).
pub fn imu(s: &RigidState, stamp: Time, body: &str, gravity: f64) -> Imu {
    let q = s.orientation;
    let f =
        q.inverse_transform_vector(&(s.acceleration - nalgebra::Vector3::new(0.0, 0.0, -gravity)));
    Imu {
        header: Header {
            stamp,
            frame_id: body.into(),
        },
        orientation: quat_msg(q),
        orientation_covariance: [0.0; 9],
        angular_velocity: vec3_msg(s.angular_velocity),
        angular_velocity_covariance: [0.0; 9],
        linear_acceleration: vec3_msg(f),
        linear_acceleration_covariance: [0.0; 9],
    }
}
