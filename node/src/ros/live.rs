//! The node's motion input, whichever message carries it: poses (Odometry, PoseStamped) interpolated by a
//! spline, or IMU readings. Converts from the configured frame conventions and gives the solver a
//! [`TankMotion`] that never extends past what was received.

use super::frames::Frames;
use super::live_imu::{ImuSample, LiveImu};
use super::live_motion::{Limits, LiveMotion, Rejected};
use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use slosh_msgs::geometry_msgs::{Pose, Quaternion as QuatMsg, Vector3 as Vec3Msg};
use slosh_msgs::sensor_msgs::Imu;
use sph::motion::{RigidState, TankMotion};

/// One received sample, as it came.
#[derive(Debug, Clone)]
pub enum Reading {
    Pose(Pose),
    Imu(Box<Imu>),
}

/// Received motion of either kind.
#[derive(Debug)]
pub enum Live {
    Pose(LiveMotion),
    Imu(LiveImu),
}

fn unit(q: &QuatMsg) -> UnitQuaternion<f64> {
    let q = Quaternion::new(q.w, q.x, q.y, q.z);
    // A zero quaternion (orientation unset) normalises to NaN, which the sample checks reject by name.
    UnitQuaternion::new_unchecked(q / q.norm())
}

fn vector(v: &Vec3Msg) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

impl Live {
    /// Empty input of the kind `imu` says, for a tank mounted as `frames` says.
    pub fn new(imu: bool, limits: Limits, frames: &Frames, gravity: f64) -> Self {
        if imu {
            let (lever, mount) = frames.mount();
            Live::Imu(LiveImu::new(limits, gravity, lever, mount))
        } else {
            Live::Pose(LiveMotion::new(limits))
        }
    }

    /// Adds a sample at time `t`, converted by `frames`.
    pub fn push(&mut self, t: f64, r: &Reading, frames: &Frames) -> Result<(), Rejected> {
        match (self, r) {
            (Live::Pose(m), Reading::Pose(p)) => {
                let position = Vector3::new(p.position.x, p.position.y, p.position.z);
                m.push(t, frames.tank_coordinates(position, unit(&p.orientation)))
            }
            (Live::Imu(m), Reading::Imu(i)) => m.push(
                t,
                ImuSample {
                    orientation: frames.vessel_orientation(unit(&i.orientation)),
                    angular_velocity: frames.body_vector(vector(&i.angular_velocity)),
                    specific_force: frames.body_vector(vector(&i.linear_acceleration)),
                },
            ),
            _ => unreachable!("the input's kind is fixed at start-up"),
        }
    }

    /// Extends the motion to `t` holding the last pose at rest; false if there is nothing to hold.
    pub fn hold(&mut self, t: f64) -> bool {
        match self {
            Live::Pose(m) => m.last_pose().is_some_and(|p| m.push(t, p).is_ok()),
            Live::Imu(m) => m.held().is_some_and(|s| m.push(t, s).is_ok()),
        }
    }

    /// Drops samples older than the solver's time `t` needs.
    pub fn forget_before(&mut self, t: f64) {
        match self {
            Live::Pose(m) => m.forget_before(t),
            Live::Imu(m) => m.forget_before(t),
        }
    }

    pub fn newest(&self) -> Option<f64> {
        match self {
            Live::Pose(m) => m.newest(),
            Live::Imu(m) => m.newest(),
        }
    }

    pub fn safe_until(&self, delay_samples: usize) -> Option<f64> {
        match self {
            Live::Pose(m) => m.safe_until(delay_samples),
            Live::Imu(m) => m.safe_until(delay_samples),
        }
    }
}

impl TankMotion for Live {
    fn state(&self, t: f64) -> RigidState {
        match self {
            Live::Pose(m) => m.state(t),
            Live::Imu(m) => m.state(t),
        }
    }

    fn end_time(&self) -> f64 {
        self.newest().unwrap_or(0.0)
    }
}
