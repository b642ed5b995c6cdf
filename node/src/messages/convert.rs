//! Conversions between nalgebra values and the geometry message fields they travel in.

use nalgebra::{Quaternion, UnitQuaternion, Vector3};
use slosh_msgs::geometry_msgs::{Point, Quaternion as QuatMsg, Vector3 as Vec3Msg};

pub fn vec3_msg(v: Vector3<f64>) -> Vec3Msg {
    Vec3Msg {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

pub fn point_msg(v: Vector3<f64>) -> Point {
    Point {
        x: v.x,
        y: v.y,
        z: v.z,
    }
}

pub fn quat_msg(q: UnitQuaternion<f64>) -> QuatMsg {
    QuatMsg {
        x: q.i,
        y: q.j,
        z: q.k,
        w: q.w,
    }
}

pub fn vector(v: &Vec3Msg) -> Vector3<f64> {
    Vector3::new(v.x, v.y, v.z)
}

pub fn position(p: &Point) -> Vector3<f64> {
    Vector3::new(p.x, p.y, p.z)
}

/// The rotation a message's quaternion stands for. A zero quaternion (orientation unset) normalises to NaN;
/// received samples are checked for it first (`live::tank_coordinates`, `live::imu_sample`).
pub fn unit(q: &QuatMsg) -> UnitQuaternion<f64> {
    let q = Quaternion::new(q.w, q.x, q.y, q.z);
    UnitQuaternion::new_unchecked(q / q.norm())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips() {
        let q = UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3);
        assert!((unit(&quat_msg(q)).angle_to(&q)) < 1e-12);
        let v = Vector3::new(1.0, -2.0, 3.5);
        assert_eq!(vector(&vec3_msg(v)), v);
        assert_eq!(position(&point_msg(v)), v);
        assert!(unit(&QuatMsg::default()).w.is_nan());
    }
}
