//! A vessel's full-state motion sample (the iceoryx2 input, [`MotionSample`]): its check, and the state of a
//! tank mounted on the vessel.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use slosh_msgs::iox::MotionSample;
use sph::motion::RigidState;

/// Where the tank is mounted on the vessel (the node's `frames.tank_pose`).
#[derive(Debug, Clone, Copy)]
pub struct Mount {
    /// Tank origin in the vessel frame, m.
    pub offset: Vector3<f64>,
    /// Vessel ← tank rotation.
    pub rotation: UnitQuaternion<f64>,
}

/// Why a sample cannot be used, naming the field.
pub fn check(s: &MotionSample) -> Result<(), String> {
    let fields: [(&str, &[f64]); 7] = [
        ("time", std::slice::from_ref(&s.time)),
        ("position", &s.position),
        ("orientation", &s.orientation),
        ("velocity", &s.velocity),
        ("angular_velocity", &s.angular_velocity),
        ("acceleration", &s.acceleration),
        ("angular_acceleration", &s.angular_acceleration),
    ];
    for (name, v) in fields {
        if let Some(x) = v.iter().find(|x| !x.is_finite()) {
            return Err(format!("{name}: {x} is not a finite number"));
        }
    }
    let norm = s.orientation.iter().map(|x| x * x).sum::<f64>().sqrt();
    if (norm - 1.0).abs() > 1e-3 {
        return Err(format!(
            "orientation: |q| = {norm:.6}, not a unit quaternion (x, y, z, w)"
        ));
    }
    Ok(())
}

/// The tank's rigid state from the vessel's (checked with [`check`]).
pub fn tank_state(s: &MotionSample, m: &Mount) -> RigidState {
    let [x, y, z, w] = s.orientation;
    let rv = UnitQuaternion::from_quaternion(Quaternion::new(w, x, y, z));
    let w_v = Vector3::from(s.angular_velocity);
    let a_v = Vector3::from(s.angular_acceleration);
    let r = m.offset;
    RigidState {
        position: Vector3::from(s.position) + rv * r,
        orientation: rv * m.rotation,
        velocity: Vector3::from(s.velocity) + rv * w_v.cross(&r),
        acceleration: Vector3::from(s.acceleration)
            + rv * (a_v.cross(&r) + w_v.cross(&w_v.cross(&r))),
        angular_velocity: m.rotation.inverse() * w_v,
        angular_acceleration: m.rotation.inverse() * a_v,
    }
}

/// The motion sample of a vessel whose tank is mounted with `m` = identity at the origin, from a tank state
/// (for clients that drive the tank directly, and tests).
pub fn sample_of(time: f64, s: &RigidState) -> MotionSample {
    let q = s.orientation.quaternion();
    MotionSample {
        time,
        position: s.position.into(),
        orientation: [q.i, q.j, q.k, q.w],
        velocity: s.velocity.into(),
        angular_velocity: s.angular_velocity.into(),
        acceleration: s.acceleration.into(),
        angular_acceleration: s.angular_acceleration.into(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_mounted_tank_moves_as_a_point_of_the_rigid_vessel() {
        let m = Mount {
            offset: Vector3::new(2.0, 0.0, 1.0),
            rotation: UnitQuaternion::from_euler_angles(0.0, 0.0, std::f64::consts::FRAC_PI_2),
        };
        let q = UnitQuaternion::from_euler_angles(0.1, 0.0, 0.0);
        let v = q.quaternion();
        let s = MotionSample {
            time: 1.0,
            position: [10.0, 0.0, 0.0],
            orientation: [v.i, v.j, v.k, v.w],
            velocity: [1.0, 0.0, 0.0],
            angular_velocity: [0.0, 0.0, 0.5],
            acceleration: [0.0; 3],
            angular_acceleration: [0.0; 3],
        };
        check(&s).unwrap();
        let t = tank_state(&s, &m);
        let r = q * m.offset;
        assert!((t.position - (Vector3::new(10.0, 0.0, 0.0) + r)).norm() < 1e-12);
        // Yawing at 0.5 rad/s: the tank 2 m ahead moves sideways at 1 m/s (rolled by 0.1 rad).
        let want_v = Vector3::new(1.0, 0.0, 0.0) + q * Vector3::new(0.0, 1.0, 0.0);
        assert!((t.velocity - want_v).norm() < 1e-12, "{}", t.velocity);
        // Centripetal: ω² r towards the axis, 0.25 · 2 m.
        let want_a = q * Vector3::new(-0.5, 0.0, 0.0);
        assert!((t.acceleration - want_a).norm() < 1e-12);
        // The tank is turned 90° about z on the vessel: the vessel's yaw rate is still about its z.
        assert!((t.angular_velocity - Vector3::new(0.0, 0.0, 0.5)).norm() < 1e-12);
        let mut bad = s;
        bad.velocity[1] = f64::NAN;
        assert!(check(&bad).unwrap_err().starts_with("velocity"));
        bad = s;
        bad.orientation = [0.0, 0.0, 0.0, 2.0];
        assert!(check(&bad).unwrap_err().contains("unit quaternion"));
    }
}
