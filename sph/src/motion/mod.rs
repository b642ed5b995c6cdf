//! Prescribed rigid motion of the tank. The solver integrates the liquid in the tank frame, so what it needs
//! from the motion is the frame's acceleration relative to free fall and its rotation rate: positions in the
//! world never enter the particle arithmetic (a tank kilometres from the origin behaves like one at it).

mod coupled;
mod frame;
mod irregular;
mod regular;
mod sampled;

pub use coupled::CoupledMotion;
pub use frame::FrameTerms;
pub use irregular::{IrregularMotion, JonswapDof};
pub use regular::{RegularDof, RegularMotion};
pub use sampled::{SampleError, SampledMotion};

use nalgebra::{Rotation3, UnitQuaternion, Vector3};

/// Pose and its derivatives of the tank frame in the world (world z up).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RigidState {
    /// Tank origin in the world, m.
    pub position: Vector3<f64>,
    /// Rotation from tank frame to world.
    pub orientation: UnitQuaternion<f64>,
    /// Velocity of the tank origin, world frame, m/s.
    pub velocity: Vector3<f64>,
    /// Acceleration of the tank origin, world frame, m/s².
    pub acceleration: Vector3<f64>,
    /// Angular velocity, tank frame, rad/s.
    pub angular_velocity: Vector3<f64>,
    /// Angular acceleration, tank frame, rad/s².
    pub angular_acceleration: Vector3<f64>,
}

impl RigidState {
    pub fn at_rest() -> Self {
        Self {
            position: Vector3::zeros(),
            orientation: UnitQuaternion::identity(),
            velocity: Vector3::zeros(),
            acceleration: Vector3::zeros(),
            angular_velocity: Vector3::zeros(),
            angular_acceleration: Vector3::zeros(),
        }
    }

    /// The apparent gravity in the tank frame, R^T (g − a), with g = (0, 0, −gravity) in the world.
    pub fn apparent_gravity(&self, gravity: f64) -> Vector3<f64> {
        let g = Vector3::new(0.0, 0.0, -gravity);
        self.orientation
            .inverse_transform_vector(&(g - self.acceleration))
    }

    /// Velocity in the world of a point fixed to the tank at `r` (tank frame): v + R (ω × r).
    pub fn point_velocity(&self, r: &Vector3<f64>) -> Vector3<f64> {
        self.velocity + self.orientation * self.angular_velocity.cross(r)
    }
}

/// Six degrees of freedom with first and second time derivatives: x, y, z (m) of the tank origin in the world
/// and roll, pitch, yaw (rad), intrinsic z-y'-x'' (yaw, then pitch, then roll) from world to tank.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Dof6 {
    pub q: [f64; 6],
    pub dq: [f64; 6],
    pub ddq: [f64; 6],
}

impl Dof6 {
    /// Rigid state from the six coordinates and their derivatives (angular rates mapped through the
    /// Euler-angle kinematics, exactly).
    pub fn to_state(&self) -> RigidState {
        let [x, y, z, phi, theta, psi] = self.q;
        let [dx, dy, dz, dphi, dtheta, dpsi] = self.dq;
        let [ax, ay, az, ddphi, ddtheta, ddpsi] = self.ddq;
        let (sf, cf) = phi.sin_cos();
        let (st, ct) = theta.sin_cos();
        let rot = Rotation3::from_euler_angles(phi, theta, psi);
        let w = Vector3::new(
            dphi - dpsi * st,
            dtheta * cf + dpsi * sf * ct,
            -dtheta * sf + dpsi * cf * ct,
        );
        let dw = Vector3::new(
            ddphi - ddpsi * st - dpsi * dtheta * ct,
            ddtheta * cf - dtheta * dphi * sf + ddpsi * sf * ct + dpsi * dphi * cf * ct
                - dpsi * dtheta * sf * st,
            -ddtheta * sf - dtheta * dphi * cf + ddpsi * cf * ct
                - dpsi * dphi * sf * ct
                - dpsi * dtheta * cf * st,
        );
        RigidState {
            position: Vector3::new(x, y, z),
            orientation: UnitQuaternion::from_rotation_matrix(&rot),
            velocity: Vector3::new(dx, dy, dz),
            acceleration: Vector3::new(ax, ay, az),
            angular_velocity: w,
            angular_acceleration: dw,
        }
    }
}

/// Anything that can say where the tank is at time t. This is the solver's only input from outside.
pub trait TankMotion: Send + Sync {
    fn state(&self, t: f64) -> RigidState;
    /// The last time for which the motion is known (infinite for synthetic motion).
    fn end_time(&self) -> f64 {
        f64::INFINITY
    }
}

/// A tank that does not move.
#[derive(Clone, Copy, Debug, Default)]
pub struct AtRest;

impl TankMotion for AtRest {
    fn state(&self, _t: f64) -> RigidState {
        RigidState::at_rest()
    }
}

/// Motion given by its six coordinates as functions of time.
pub trait Dof6Motion: Send + Sync {
    fn dof(&self, t: f64) -> Dof6;
    fn end_time(&self) -> f64 {
        f64::INFINITY
    }
}

impl<T: Dof6Motion> TankMotion for T {
    fn state(&self, t: f64) -> RigidState {
        self.dof(t).to_state()
    }
    fn end_time(&self) -> f64 {
        Dof6Motion::end_time(self)
    }
}

/// Constant velocity from an offset (for tests and sailing vessels).
#[derive(Clone, Copy, Debug)]
pub struct Uniform {
    pub start: [f64; 6],
    pub velocity: [f64; 6],
    pub acceleration: [f64; 6],
}

impl Dof6Motion for Uniform {
    fn dof(&self, t: f64) -> Dof6 {
        let mut d = Dof6::default();
        for i in 0..6 {
            d.q[i] = self.start[i] + self.velocity[i] * t + 0.5 * self.acceleration[i] * t * t;
            d.dq[i] = self.velocity[i] + self.acceleration[i] * t;
            d.ddq[i] = self.acceleration[i];
        }
        d
    }
}

/// Smooth start: 0 before t = 0, 1 after `ramp`, half a cosine between. Returns (r, r', r'').
pub(crate) fn ramp(t: f64, ramp: f64) -> (f64, f64, f64) {
    if ramp <= 0.0 || t >= ramp {
        return (1.0, 0.0, 0.0);
    }
    if t <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    let a = std::f64::consts::PI / ramp;
    (
        0.5 * (1.0 - (a * t).cos()),
        0.5 * a * (a * t).sin(),
        0.5 * a * a * (a * t).cos(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check_derivatives(m: &dyn Dof6Motion, t: f64) {
        let e = 1e-5;
        let (a, b, c) = (m.dof(t - e), m.dof(t), m.dof(t + e));
        for i in 0..6 {
            let fd1 = (c.q[i] - a.q[i]) / (2.0 * e);
            let fd2 = (c.dq[i] - a.dq[i]) / (2.0 * e);
            assert!(
                (fd1 - b.dq[i]).abs() < 1e-6 * (1.0 + b.dq[i].abs()),
                "dof {i}: {fd1} vs {}",
                b.dq[i]
            );
            assert!(
                (fd2 - b.ddq[i]).abs() < 1e-5 * (1.0 + b.ddq[i].abs()),
                "dof {i}: {fd2} vs {}",
                b.ddq[i]
            );
        }
        // Angular velocity and acceleration against differences of the orientation.
        let (sa, sb, sc) = (a.to_state(), b.to_state(), c.to_state());
        let dr = sb.orientation.inverse() * sc.orientation;
        let dl = sa.orientation.inverse() * sb.orientation;
        let w_fd = (dr.scaled_axis() + dl.scaled_axis()) / (2.0 * e);
        assert!(
            (w_fd - sb.angular_velocity).norm() < 1e-6 * (1.0 + sb.angular_velocity.norm()),
            "{w_fd} vs {}",
            sb.angular_velocity
        );
        let dw_fd = (sc.angular_velocity - sa.angular_velocity) / (2.0 * e);
        assert!((dw_fd - sb.angular_acceleration).norm() < 1e-5 * (1.0 + dw_fd.norm()));
    }

    #[test]
    fn regular_motion_derivatives_are_consistent() {
        let m = RegularMotion {
            dofs: [
                RegularDof {
                    amplitude: 0.1,
                    period: 2.0,
                    phase: 0.3,
                },
                RegularDof {
                    amplitude: 0.05,
                    period: 3.0,
                    phase: 0.0,
                },
                RegularDof {
                    amplitude: 0.2,
                    period: 7.0,
                    phase: 1.0,
                },
                RegularDof {
                    amplitude: 0.2,
                    period: 5.0,
                    phase: 0.0,
                },
                RegularDof {
                    amplitude: 0.1,
                    period: 4.0,
                    phase: 2.0,
                },
                RegularDof {
                    amplitude: 0.3,
                    period: 9.0,
                    phase: 0.5,
                },
            ],
            ramp: 3.0,
        };
        for t in [0.5, 1.7, 2.9, 4.0, 11.3] {
            check_derivatives(&m, t);
        }
    }

    #[test]
    fn apparent_gravity_of_a_tilted_accelerating_tank() {
        // Pitched by 0.1 rad (nose down about +y) and accelerating forward: the apparent gravity in the tank
        // frame has the rotated and the inertial part.
        let d = Dof6 {
            q: [0.0, 0.0, 0.0, 0.0, 0.1, 0.0],
            dq: [0.0; 6],
            ddq: [2.0, 0.0, 0.0, 0.0, 0.0, 0.0],
        };
        let s = d.to_state();
        let g = s.apparent_gravity(9.81);
        assert!((g.norm() - (9.81f64.powi(2) + 4.0).sqrt()).abs() < 1e-12);
        let expect =
            Rotation3::from_euler_angles(0.0, 0.1, 0.0).inverse() * Vector3::new(-2.0, 0.0, -9.81);
        assert!((g - expect).norm() < 1e-12);
    }
}
