//! Motion from an IMU on the vessel (sensor_msgs/Imu): orientation, angular velocity and specific force
//! (what an accelerometer reads: acceleration minus gravity, so 9.81 m/s² up at rest). The solver works in the
//! tank frame and needs only the apparent gravity and the rotation, so no position is integrated: the tank's
//! acceleration is R f + g plus the lever-arm terms of the tank's offset from the IMU, gravity counted once.
//! Samples are interpolated linearly (orientation by slerp); the angular acceleration is the slope of the
//! angular velocity between samples.

use super::live_motion::{Limits, Rejected};
use nalgebra::{UnitQuaternion, Vector3};
use sph::motion::{RigidState, TankMotion};
use std::collections::VecDeque;

/// Samples kept at least, and samples kept before the solver's time.
const KEEP: usize = 24;
const KEEP_BEFORE: usize = 2;

/// One IMU reading, in the vessel's FLU frame and the ENU world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ImuSample {
    /// Vessel body → world.
    pub orientation: UnitQuaternion<f64>,
    /// rad/s, vessel frame.
    pub angular_velocity: Vector3<f64>,
    /// m/s², vessel frame: acceleration minus gravity.
    pub specific_force: Vector3<f64>,
}

/// IMU samples received so far (times relative to the first), as a [`TankMotion`] of a tank at `lever` (m,
/// vessel frame, from the IMU) turned by `mount` relative to the vessel.
#[derive(Debug)]
pub struct LiveImu {
    limits: Limits,
    gravity: f64,
    lever: Vector3<f64>,
    mount: UnitQuaternion<f64>,
    samples: VecDeque<(f64, ImuSample)>,
}

impl LiveImu {
    pub fn new(
        limits: Limits,
        gravity: f64,
        lever: Vector3<f64>,
        mount: UnitQuaternion<f64>,
    ) -> Self {
        Self {
            limits,
            gravity,
            lever,
            mount,
            samples: VecDeque::with_capacity(KEEP + 1),
        }
    }

    /// Adds a reading at time `t`, or says why not.
    pub fn push(&mut self, t: f64, s: ImuSample) -> Result<(), Rejected> {
        if !t.is_finite() {
            return Err(Rejected::NotFinite { what: "time" });
        }
        let q = s.orientation.quaternion();
        if !(q.coords.iter().all(|v| v.is_finite())) {
            return Err(Rejected::NotFinite {
                what: "orientation",
            });
        }
        if !s.angular_velocity.iter().all(|v| v.is_finite()) {
            return Err(Rejected::NotFinite {
                what: "angular_velocity",
            });
        }
        if !s.specific_force.iter().all(|v| v.is_finite()) {
            return Err(Rejected::NotFinite {
                what: "linear_acceleration",
            });
        }
        if let Some(&(t0, p)) = self.samples.back() {
            if t == t0 {
                return Err(Rejected::Duplicate { time: t });
            }
            if t < t0 {
                return Err(Rejected::OutOfOrder {
                    time: t,
                    newest: t0,
                });
            }
            let dt = t - t0;
            let turn = p.orientation.angle_to(&s.orientation);
            self.limits.turned("orientation", turn, dt)?;
        }
        self.samples.push_back((t, s));
        Ok(())
    }

    /// Drops samples the solver, now at time `t`, no longer needs (see `LiveMotion::forget_before`).
    pub fn forget_before(&mut self, t: f64) {
        while self.samples.len() > KEEP && self.samples[KEEP_BEFORE].0 < t {
            self.samples.pop_front();
        }
    }

    pub fn newest(&self) -> Option<f64> {
        self.samples.back().map(|s| s.0)
    }

    /// The newest reading with the vessel at rest in its current attitude (for holding when input stops).
    pub fn held(&self) -> Option<ImuSample> {
        self.samples.back().map(|&(_, s)| ImuSample {
            orientation: s.orientation,
            angular_velocity: Vector3::zeros(),
            specific_force: s.orientation.inverse_transform_vector(&Vector3::new(
                0.0,
                0.0,
                self.gravity,
            )),
        })
    }

    /// How far the solver may go (as [`super::live_motion::LiveMotion::safe_until`]).
    pub fn safe_until(&self, delay_samples: usize) -> Option<f64> {
        let n = self.samples.len();
        if n < 2 {
            return None;
        }
        Some(self.samples[n - 1 - delay_samples.min(n - 2)].0)
    }
}

impl TankMotion for LiveImu {
    fn state(&self, t: f64) -> RigidState {
        let n = self.samples.len();
        let Some(&(t_last, last)) = self.samples.back() else {
            return RigidState::at_rest();
        };
        // The reading at t and the slope of the angular velocity.
        let (s, dw) = if n < 2 || t >= t_last {
            (last, Vector3::zeros())
        } else if t <= self.samples[0].0 {
            (self.samples[0].1, Vector3::zeros())
        } else {
            let i = self
                .samples
                .partition_point(|&(ti, _)| ti <= t)
                .clamp(1, n - 1)
                - 1;
            let ((ta, a), (tb, b)) = (self.samples[i], self.samples[i + 1]);
            let u = (t - ta) / (tb - ta);
            (
                ImuSample {
                    orientation: a.orientation.slerp(&b.orientation, u),
                    angular_velocity: a.angular_velocity.lerp(&b.angular_velocity, u),
                    specific_force: a.specific_force.lerp(&b.specific_force, u),
                },
                (b.angular_velocity - a.angular_velocity) / (tb - ta),
            )
        };
        let q = s.orientation;
        let w = s.angular_velocity;
        let r = self.lever;
        let g = Vector3::new(0.0, 0.0, -self.gravity);
        // Vessel (IMU) acceleration, then the tank's: lever-arm terms ω̇ × r + ω × (ω × r).
        let a_imu = q * s.specific_force + g;
        let a_tank = a_imu + q * (dw.cross(&r) + w.cross(&w.cross(&r)));
        let inv_mount = self.mount.inverse();
        RigidState {
            position: q * r,
            orientation: q * self.mount,
            velocity: q * w.cross(&r),
            acceleration: a_tank,
            angular_velocity: inv_mount * w,
            angular_acceleration: inv_mount * dw,
        }
    }

    fn end_time(&self) -> f64 {
        self.newest().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph::motion::{Dof6Motion, RegularDof, RegularMotion};

    fn limits() -> Limits {
        Limits {
            max_speed: 50.0,
            max_rotation_rate: 5.0,
        }
    }

    /// What an IMU at the vessel origin reads for a prescribed motion.
    fn reading(m: &RegularMotion, t: f64) -> ImuSample {
        let s = m.dof(t).to_state();
        let g = Vector3::new(0.0, 0.0, -9.81);
        ImuSample {
            orientation: s.orientation,
            angular_velocity: s.angular_velocity,
            specific_force: s
                .orientation
                .inverse_transform_vector(&(s.acceleration - g)),
        }
    }

    #[test]
    fn at_rest_the_tank_feels_gravity_once() {
        let mut m = LiveImu::new(limits(), 9.81, Vector3::zeros(), UnitQuaternion::identity());
        let rest = ImuSample {
            orientation: UnitQuaternion::identity(),
            angular_velocity: Vector3::zeros(),
            specific_force: Vector3::new(0.0, 0.0, 9.81),
        };
        m.push(0.0, rest).unwrap();
        m.push(0.02, rest).unwrap();
        let g = m.state(0.01).apparent_gravity(9.81);
        assert!((g - Vector3::new(0.0, 0.0, -9.81)).norm() < 1e-12, "{g}");
        assert!(matches!(
            m.push(0.02, rest),
            Err(Rejected::Duplicate { .. })
        ));
        let mut bad = rest;
        bad.specific_force.x = f64::NAN;
        assert_eq!(
            m.push(0.04, bad),
            Err(Rejected::NotFinite {
                what: "linear_acceleration"
            })
        );
    }

    #[test]
    fn reproduces_the_apparent_gravity_and_rotation_of_a_rolling_swaying_tank_on_a_lever() {
        let dof = |amplitude, period| RegularDof {
            amplitude,
            period,
            phase: 0.3,
        };
        let zero = dof(0.0, 0.0);
        let m = RegularMotion {
            dofs: [
                dof(0.2, 4.0),
                zero,
                dof(0.1, 5.0),
                dof(0.1, 6.0),
                zero,
                zero,
            ],
            ramp: 0.0,
        };
        let lever = Vector3::new(2.0, 1.0, 3.0);
        let mut imu = LiveImu::new(limits(), 9.81, lever, UnitQuaternion::identity());
        for k in 0..400 {
            let t = k as f64 * 0.02;
            imu.push(t, reading(&m, t)).unwrap();
        }
        // Exact: the tank origin sits at the lever in the vessel frame.
        let t = 7.5 + 0.011;
        imu.forget_before(t);
        let v = m.dof(t).to_state();
        let exact_a = v.acceleration
            + v.orientation
                * (v.angular_acceleration.cross(&lever)
                    + v.angular_velocity.cross(&v.angular_velocity.cross(&lever)));
        let exact_g = v
            .orientation
            .inverse_transform_vector(&(Vector3::new(0.0, 0.0, -9.81) - exact_a));
        let s = imu.state(t);
        let g = s.apparent_gravity(9.81);
        assert!((g - exact_g).norm() < 2e-3 * 9.81, "{g} vs {exact_g}");
        assert!((s.angular_velocity - v.angular_velocity).norm() < 1e-3);
        assert!((s.angular_acceleration - v.angular_acceleration).norm() < 5e-3);
    }
}
