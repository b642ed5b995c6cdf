//! The node's motion input, whichever message carries it: poses (Odometry, PoseStamped) interpolated by a
//! spline, or IMU readings. Converts from the configured frame conventions and gives the solver a
//! [`TankMotion`] that never extends past what was received.

use super::frames::Frames;
use super::live_imu::{ImuSample, LiveImu};
use super::live_motion::{Limits, LiveMotion, Rejected};
use super::live_state::LiveState;
use crate::messages::convert::{position, unit, vector};
use nalgebra::{UnitQuaternion, Vector3};
use slosh_msgs::geometry_msgs::{Pose, Quaternion as QuatMsg, Vector3 as Vec3Msg};
use slosh_msgs::sensor_msgs::Imu;
use sph::motion::{RigidState, TankMotion};

/// One received sample, as it came.
#[derive(Debug, Clone)]
pub enum Reading {
    Pose(Pose),
    Imu(Box<Imu>),
    /// The vessel's full state from iceoryx2 (z-up world, FLU vessel frame).
    State(slosh_msgs::iox::MotionSample),
}

/// The tank's six coordinates (x, y, z, roll, pitch, yaw) from a received vessel pose.
pub fn tank_coordinates(p: &Pose, frames: &Frames) -> Result<[f64; 6], Rejected> {
    orientation(&p.orientation)?;
    Ok(frames.tank_coordinates(position(&p.position), unit(&p.orientation)))
}

/// An IMU reading in the vessel's FLU frame and the ENU world, from one received.
pub fn imu_sample(i: &Imu, frames: &Frames) -> Result<ImuSample, Rejected> {
    if i.orientation_covariance[0] == -1.0 {
        return Err(Rejected::Invalid(
            "orientation: this IMU gives none (orientation_covariance[0] = -1); the IMU input needs the \
             vessel's orientation (an AHRS or a filter's output), or use input.type: odom"
                .into(),
        ));
    }
    orientation(&i.orientation)?;
    Ok(ImuSample {
        orientation: frames.vessel_orientation(unit(&i.orientation)),
        angular_velocity: frames.body_vector(vector(&i.angular_velocity)),
        specific_force: frames.body_vector(vector(&i.linear_acceleration)),
    })
}

/// A received orientation that is a rotation: finite, and not the zero quaternion of an orientation left
/// unset (any other length is normalised, as ROS tools do).
fn orientation(q: &QuatMsg) -> Result<(), Rejected> {
    let c = [q.x, q.y, q.z, q.w];
    if !c.iter().all(|v| v.is_finite()) {
        return Err(Rejected::NotFinite {
            what: "orientation (quaternion)",
        });
    }
    let n = c.iter().map(|v| v * v).sum::<f64>().sqrt();
    if n < 1e-6 {
        return Err(Rejected::Invalid(format!(
            "orientation: the quaternion (x, y, z, w) = ({}, {}, {}, {}) has no length: an orientation left \
             unset? (the identity is (0, 0, 0, 1))",
            q.x, q.y, q.z, q.w
        )));
    }
    Ok(())
}

/// Received motion of either kind.
#[derive(Debug)]
pub enum Live {
    Pose(LiveMotion, Accel),
    Imu(LiveImu),
    State(LiveState, super::sample::Mount),
}

/// Measured accelerations of the vessel (geometry_msgs/AccelStamped on `motion/accel`, body frame), used
/// instead of the pose spline's second derivatives where they cover the time asked for.
#[derive(Debug, Default)]
pub struct Accel {
    /// (t, linear m/s², angular rad/s²), vessel FLU frame.
    samples: std::collections::VecDeque<(f64, Vector3<f64>, Vector3<f64>)>,
    lever: Vector3<f64>,
    mount: UnitQuaternion<f64>,
}

impl Accel {
    /// (linear, angular) acceleration at t, linearly interpolated, if samples bracket t.
    fn at(&self, t: f64) -> Option<(Vector3<f64>, Vector3<f64>)> {
        let i = self.samples.partition_point(|s| s.0 <= t);
        if i == 0 || i == self.samples.len() {
            return None;
        }
        let ((ta, la, aa), (tb, lb, ab)) = (self.samples[i - 1], self.samples[i]);
        let u = (t - ta) / (tb - ta);
        Some((la.lerp(&lb, u), aa.lerp(&ab, u)))
    }

    /// The tank's state with the measured accelerations: a_tank = R_v (a + α × r + ω × (ω × r)).
    fn apply(&self, t: f64, mut s: RigidState) -> RigidState {
        let Some((a, alpha)) = self.at(t) else {
            return s;
        };
        let r = self.lever;
        let w_v = self.mount * s.angular_velocity;
        let r_v = s.orientation * self.mount.inverse();
        s.acceleration = r_v * (a + alpha.cross(&r) + w_v.cross(&w_v.cross(&r)));
        s.angular_acceleration = self.mount.inverse() * alpha;
        s
    }
}

impl Live {
    /// Empty input of full states (iceoryx2 [`slosh_msgs::iox::MotionSample`]s) for a tank mounted as `frames`
    /// says.
    pub fn states(limits: Limits, frames: &Frames) -> Self {
        let (offset, rotation) = frames.mount();
        Live::State(
            LiveState::new(limits),
            super::sample::Mount { offset, rotation },
        )
    }

    /// Empty input of the kind `imu` says, for a tank mounted as `frames` says.
    pub fn new(imu: bool, limits: Limits, frames: &Frames, gravity: f64) -> Self {
        let (lever, mount) = frames.mount();
        if imu {
            Live::Imu(LiveImu::new(limits, gravity, lever, mount))
        } else {
            Live::Pose(
                LiveMotion::new(limits),
                Accel {
                    samples: Default::default(),
                    lever,
                    mount,
                },
            )
        }
    }

    /// Adds a measured acceleration (linear, angular; received body frame) at time `t` (pose input only).
    pub fn push_accel(
        &mut self,
        t: f64,
        linear: &Vec3Msg,
        angular: &Vec3Msg,
        frames: &Frames,
    ) -> Result<(), Rejected> {
        let Live::Pose(_, acc) = self else {
            return Ok(());
        };
        let (l, a) = (vector(linear), vector(angular));
        if !(l.iter().chain(a.iter()).all(|v| v.is_finite())) {
            return Err(Rejected::NotFinite {
                what: "acceleration",
            });
        }
        if let Some(&(t0, _, _)) = acc.samples.back() {
            if t <= t0 {
                return Err(Rejected::OutOfOrder {
                    time: t,
                    newest: t0,
                });
            }
        }
        acc.samples
            .push_back((t, frames.body_vector(l), frames.body_vector(a)));
        Ok(())
    }

    /// Adds a sample at time `t`, converted by `frames`.
    pub fn push(&mut self, t: f64, r: &Reading, frames: &Frames) -> Result<(), Rejected> {
        match (self, r) {
            (Live::Pose(m, _), Reading::Pose(p)) => m.push(t, tank_coordinates(p, frames)?),
            (Live::Imu(m), Reading::Imu(i)) => m.push(t, imu_sample(i, frames)?),
            (Live::State(m, mount), Reading::State(s)) => {
                super::sample::check(s).map_err(Rejected::Invalid)?;
                m.push(t, super::sample::tank_state(s, mount))
            }
            _ => unreachable!("the input's kind is fixed at start-up"),
        }
    }

    /// Extends the motion to `t` holding the last pose at rest; false if there is nothing to hold.
    pub fn hold(&mut self, t: f64) -> bool {
        match self {
            Live::Pose(m, _) => m.last_pose().is_some_and(|p| m.push(t, p).is_ok()),
            Live::Imu(m) => m.held().is_some_and(|s| m.push(t, s).is_ok()),
            Live::State(m, _) => m.held().is_some_and(|s| m.push(t, s).is_ok()),
        }
    }

    /// Drops samples older than the solver's time `t` needs.
    pub fn forget_before(&mut self, t: f64) {
        match self {
            Live::Pose(m, acc) => {
                m.forget_before(t);
                while acc.samples.len() > 2 && acc.samples[1].0 < t {
                    acc.samples.pop_front();
                }
            }
            Live::Imu(m) => m.forget_before(t),
            Live::State(m, _) => m.forget_before(t),
        }
    }

    pub fn newest(&self) -> Option<f64> {
        match self {
            Live::Pose(m, _) => m.newest(),
            Live::Imu(m) => m.newest(),
            Live::State(m, _) => m.newest(),
        }
    }

    pub fn safe_until(&self, delay_samples: usize) -> Option<f64> {
        match self {
            Live::Pose(m, _) => m.safe_until(delay_samples),
            Live::Imu(m) => m.safe_until(delay_samples),
            Live::State(m, _) => m.safe_until(),
        }
    }
}

impl TankMotion for Live {
    fn state(&self, t: f64) -> RigidState {
        match self {
            Live::Pose(m, acc) => acc.apply(t, m.state(t)),
            Live::Imu(m) => m.state(t),
            Live::State(m, _) => m.state(t),
        }
    }

    fn end_time(&self) -> f64 {
        self.newest().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{BodyFrame, TankPose, WorldFrame};
    use crate::messages::convert::{point_msg, quat_msg, vec3_msg};
    use sph::motion::{Dof6Motion, RegularDof, RegularMotion};

    #[test]
    fn an_unset_or_non_finite_orientation_is_named() {
        let frames = Frames::new(WorldFrame::Enu, BodyFrame::Flu, TankPose::default());
        let mut p = Pose::default();
        let e = tank_coordinates(&p, &frames).unwrap_err().to_string();
        assert!(
            e.starts_with("orientation: the quaternion") && e.contains("has no length"),
            "{e}"
        );
        p.orientation.w = f64::NAN;
        let e = tank_coordinates(&p, &frames).unwrap_err().to_string();
        assert_eq!(e, "orientation (quaternion) is not a finite number");
        // Not of unit length: normalised.
        p.orientation.w = 2.0;
        assert_eq!(tank_coordinates(&p, &frames).unwrap(), [0.0; 6]);
        let mut i = Imu::default();
        assert!(imu_sample(&i, &frames).is_err());
        i.orientation_covariance[0] = -1.0;
        let e = imu_sample(&i, &frames).unwrap_err().to_string();
        assert!(
            e.contains("this IMU gives none (orientation_covariance[0] = -1)"),
            "{e}"
        );
    }

    #[test]
    fn measured_accelerations_replace_the_splines_and_carry_the_lever_arm() {
        let dof = |amplitude, period| RegularDof {
            amplitude,
            period,
            phase: 0.2,
        };
        let zero = dof(0.0, 0.0);
        let m = RegularMotion {
            dofs: [
                dof(0.3, 3.0),
                zero,
                dof(0.2, 4.0),
                dof(0.1, 5.0),
                dof(0.05, 7.0),
                zero,
            ],
            ramp: 0.0,
        };
        let tank = TankPose {
            x: 3.0,
            z: 2.0,
            ..Default::default()
        };
        let frames = Frames::new(WorldFrame::Enu, BodyFrame::Flu, tank);
        let limits = Limits {
            max_speed: 50.0,
            max_rotation_rate: 5.0,
        };
        let mut live = Live::new(false, limits, &frames, 9.81);
        // Poses only at 5 Hz (a coarse spline); accelerations at 50 Hz.
        for k in 0..=100 {
            let t = k as f64 * 0.02;
            let s = m.dof(t).to_state();
            if k % 10 == 0 {
                let pose = Pose {
                    position: point_msg(s.position),
                    orientation: quat_msg(s.orientation),
                };
                live.push(t, &Reading::Pose(pose), &frames).unwrap();
            }
            let a_body = s.orientation.inverse_transform_vector(&s.acceleration);
            live.push_accel(
                t,
                &vec3_msg(a_body),
                &vec3_msg(s.angular_acceleration),
                &frames,
            )
            .unwrap();
        }
        let t = 1.01;
        let s = m.dof(t).to_state();
        let r = Vector3::new(3.0, 0.0, 2.0);
        let w = s.angular_velocity;
        let exact = s.acceleration
            + s.orientation * (s.angular_acceleration.cross(&r) + w.cross(&w.cross(&r)));
        let got = live.state(t);
        // The spline of 5 Hz poses alone is far off; with the measured accelerations it is close.
        let Live::Pose(spline, _) = &live else {
            unreachable!()
        };
        let coarse = spline.state(t).acceleration;
        assert!(
            (got.acceleration - exact).norm() < 0.02 * exact.norm(),
            "{} vs {exact}",
            got.acceleration
        );
        assert!((coarse - exact).norm() > 5.0 * (got.acceleration - exact).norm());
        assert!(
            (got.angular_acceleration - s.angular_acceleration).norm()
                < 0.02 * s.angular_acceleration.norm()
        );
    }
}
