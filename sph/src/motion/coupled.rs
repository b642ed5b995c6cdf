//! Motion given one state at a time, as a co-simulation sends it: the full rigid state (pose, velocities,
//! accelerations) at the end of each coupling step. Between the last two states the position follows the
//! quintic Hermite curve that matches position, velocity and acceleration at both ends; the orientation is
//! slerped and the body rates are interpolated linearly.

use super::{RigidState, TankMotion};

#[derive(Clone, Copy, Debug)]
pub struct CoupledMotion {
    t0: f64,
    s0: RigidState,
    t1: f64,
    s1: RigidState,
}

impl CoupledMotion {
    /// The motion known only at `t`: the state `s` there.
    pub fn new(t: f64, s: RigidState) -> Self {
        Self {
            t0: t,
            s0: s,
            t1: t,
            s1: s,
        }
    }

    /// Adds the state at a later time `t` (the previous newest state starts the new interval).
    pub fn push(&mut self, t: f64, s: RigidState) {
        debug_assert!(t > self.t1);
        self.t0 = self.t1;
        self.s0 = self.s1;
        self.t1 = t;
        self.s1 = s;
    }

    /// The newest time.
    pub fn newest(&self) -> f64 {
        self.t1
    }
}

impl TankMotion for CoupledMotion {
    fn state(&self, t: f64) -> RigidState {
        let h = self.t1 - self.t0;
        if h <= 0.0 || t >= self.t1 {
            return self.s1;
        }
        if t <= self.t0 {
            return self.s0;
        }
        let u = (t - self.t0) / h;
        let (u2, u3, u4, u5) = (u * u, u * u * u, u.powi(4), u.powi(5));
        let b = [
            1.0 - 10.0 * u3 + 15.0 * u4 - 6.0 * u5,
            u - 6.0 * u3 + 8.0 * u4 - 3.0 * u5,
            0.5 * u2 - 1.5 * u3 + 1.5 * u4 - 0.5 * u5,
            0.5 * u3 - u4 + 0.5 * u5,
            -4.0 * u3 + 7.0 * u4 - 3.0 * u5,
            10.0 * u3 - 15.0 * u4 + 6.0 * u5,
        ];
        let d = [
            -30.0 * u2 + 60.0 * u3 - 30.0 * u4,
            1.0 - 18.0 * u2 + 32.0 * u3 - 15.0 * u4,
            u - 4.5 * u2 + 6.0 * u3 - 2.5 * u4,
            1.5 * u2 - 4.0 * u3 + 2.5 * u4,
            -12.0 * u2 + 28.0 * u3 - 15.0 * u4,
            30.0 * u2 - 60.0 * u3 + 30.0 * u4,
        ];
        let dd = [
            -60.0 * u + 180.0 * u2 - 120.0 * u3,
            -36.0 * u + 96.0 * u2 - 60.0 * u3,
            1.0 - 9.0 * u + 18.0 * u2 - 10.0 * u3,
            3.0 * u - 12.0 * u2 + 10.0 * u3,
            -24.0 * u + 84.0 * u2 - 60.0 * u3,
            60.0 * u - 180.0 * u2 + 120.0 * u3,
        ];
        let (a, c) = (&self.s0, &self.s1);
        let terms = [
            a.position,
            a.velocity * h,
            a.acceleration * h * h,
            c.acceleration * h * h,
            c.velocity * h,
            c.position,
        ];
        let sum = |w: &[f64; 6]| {
            terms
                .iter()
                .zip(w)
                .fold(nalgebra::Vector3::zeros(), |acc, (v, w)| acc + v * *w)
        };
        RigidState {
            position: sum(&b),
            orientation: a.orientation.slerp(&c.orientation, u),
            velocity: sum(&d) / h,
            acceleration: sum(&dd) / (h * h),
            angular_velocity: a.angular_velocity.lerp(&c.angular_velocity, u),
            angular_acceleration: a.angular_acceleration.lerp(&c.angular_acceleration, u),
        }
    }

    fn end_time(&self) -> f64 {
        self.t1
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use nalgebra::{UnitQuaternion, Vector3};

    fn state(t: f64) -> RigidState {
        // A quintic in each coordinate: reproduced exactly.
        let p = |k: f64| {
            k * (0.3 + t - 2.0 * t * t + 0.5 * t.powi(3) - 0.25 * t.powi(4) + 0.1 * t.powi(5))
        };
        let v = |k: f64| k * (1.0 - 4.0 * t + 1.5 * t * t - t.powi(3) + 0.5 * t.powi(4));
        let a = |k: f64| k * (-4.0 + 3.0 * t - 3.0 * t * t + 2.0 * t.powi(3));
        RigidState {
            position: Vector3::new(p(1.0), p(-0.5), p(0.2)),
            orientation: UnitQuaternion::from_euler_angles(0.0, 0.1 * t, 0.0),
            velocity: Vector3::new(v(1.0), v(-0.5), v(0.2)),
            acceleration: Vector3::new(a(1.0), a(-0.5), a(0.2)),
            angular_velocity: Vector3::new(0.0, 0.1, 0.0),
            angular_acceleration: Vector3::zeros(),
        }
    }

    #[test]
    fn a_quintic_path_is_reproduced_between_two_states() {
        let mut m = CoupledMotion::new(0.5, state(0.5));
        assert_eq!(m.state(0.7), state(0.5), "only one state: held");
        m.push(0.8, state(0.8));
        for t in [0.5, 0.55, 0.6813, 0.8] {
            let (got, want) = (m.state(t), state(t));
            assert!((got.position - want.position).norm() < 1e-12, "{t}");
            assert!((got.velocity - want.velocity).norm() < 1e-10, "{t}");
            assert!((got.acceleration - want.acceleration).norm() < 1e-8, "{t}");
            assert!(got.orientation.angle_to(&want.orientation) < 1e-12, "{t}");
        }
        assert_eq!(m.end_time(), 0.8);
    }
}
