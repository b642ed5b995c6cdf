//! Frame conventions of incoming motion. The solver's world is z up (ENU) and bodies are x forward, y left,
//! z up (FLU, REP 103); vessels from marine pipelines often come in NED / FRD (x forward, y right, z down).
//! The tank's pose in the vessel frame turns the vessel's pose into the tank's.

use crate::config::{BodyFrame, TankPose, WorldFrame};
use nalgebra::{Matrix3, Rotation3, UnitQuaternion, Vector3};

/// Turns vessel poses in the configured conventions into tank poses in the z-up world.
#[derive(Debug, Clone, Copy)]
pub struct Frames {
    world: Rotation3<f64>,
    body: Rotation3<f64>,
    offset: Vector3<f64>,
    mount: UnitQuaternion<f64>,
}

fn rot(m: Matrix3<f64>) -> Rotation3<f64> {
    Rotation3::from_matrix_unchecked(m)
}

impl Frames {
    pub fn new(world: WorldFrame, body: BodyFrame, tank: TankPose) -> Self {
        // NED → ENU swaps x and y and flips z (a proper rotation: det = +1).
        let world = match world {
            WorldFrame::Enu => Rotation3::identity(),
            WorldFrame::Ned => rot(Matrix3::new(0.0, 1.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0)),
        };
        // FLU ← FRD flips y and z.
        let body = match body {
            BodyFrame::Flu => Rotation3::identity(),
            BodyFrame::Frd => rot(Matrix3::new(1.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0, 0.0, -1.0)),
        };
        Self {
            world,
            body,
            offset: Vector3::new(tank.x, tank.y, tank.z),
            mount: UnitQuaternion::from_euler_angles(tank.roll, tank.pitch, tank.yaw),
        }
    }

    /// The tank's pose in the z-up world from the vessel's position and orientation (body → world) as received.
    pub fn tank_pose(
        &self,
        position: Vector3<f64>,
        orientation: UnitQuaternion<f64>,
    ) -> (Vector3<f64>, UnitQuaternion<f64>) {
        let p = self.world * position;
        // Vessel FLU body → ENU world: world conversion · received (FRD/FLU body → world) · FLU → body.
        let r = self.vessel_orientation(orientation);
        (p + r * self.offset, r * self.mount)
    }

    /// The vessel's orientation (FLU body → ENU world) from one received in the configured conventions.
    pub fn vessel_orientation(&self, orientation: UnitQuaternion<f64>) -> UnitQuaternion<f64> {
        UnitQuaternion::from_rotation_matrix(&self.world)
            * orientation
            * UnitQuaternion::from_rotation_matrix(&self.body.inverse())
    }

    /// A vector in the vessel's received body frame, in FLU.
    pub fn body_vector(&self, v: Vector3<f64>) -> Vector3<f64> {
        self.body * v
    }

    /// Where the tank origin sits in the vessel's FLU frame, and how the tank is turned on it.
    pub fn mount(&self) -> (Vector3<f64>, UnitQuaternion<f64>) {
        (self.offset, self.mount)
    }

    /// The six coordinates the solver's motion uses: x, y, z, then roll, pitch, yaw (z-y'-x'').
    pub fn tank_coordinates(
        &self,
        position: Vector3<f64>,
        orientation: UnitQuaternion<f64>,
    ) -> [f64; 6] {
        let (p, q) = self.tank_pose(position, orientation);
        let (roll, pitch, yaw) = q.euler_angles();
        [p.x, p.y, p.z, roll, pitch, yaw]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    fn close(a: [f64; 6], b: [f64; 6]) -> bool {
        a.iter().zip(&b).all(|(x, y)| (x - y).abs() < 1e-12)
    }

    #[test]
    fn enu_flu_is_the_identity_and_the_mount_offset_rotates_with_the_vessel() {
        let f = Frames::new(WorldFrame::Enu, BodyFrame::Flu, TankPose::default());
        let q = UnitQuaternion::from_euler_angles(0.1, -0.2, 0.3);
        let c = f.tank_coordinates(Vector3::new(1.0, 2.0, 3.0), q);
        assert!(close(c, [1.0, 2.0, 3.0, 0.1, -0.2, 0.3]));
        // A tank 10 m forward on a vessel heading north (yaw +90° in ENU) sits 10 m north of it.
        let f = Frames::new(
            WorldFrame::Enu,
            BodyFrame::Flu,
            TankPose {
                x: 10.0,
                ..Default::default()
            },
        );
        let c = f.tank_coordinates(
            Vector3::zeros(),
            UnitQuaternion::from_euler_angles(0.0, 0.0, FRAC_PI_2),
        );
        assert!(close(c, [0.0, 10.0, 0.0, 0.0, 0.0, FRAC_PI_2]), "{c:?}");
    }

    #[test]
    fn ned_frd_poses_map_to_the_same_tank_pose_as_enu_flu() {
        // A vessel heading east, 2 m above the datum, rolled 0.1 rad to starboard (starboard side down).
        // ENU/FLU: yaw 0 (x east), roll about x forward with starboard (−y) down: positive roll.
        let enu = Frames::new(WorldFrame::Enu, BodyFrame::Flu, TankPose::default());
        let a = enu.tank_coordinates(
            Vector3::new(5.0, 7.0, 2.0),
            UnitQuaternion::from_euler_angles(0.1, 0.0, 0.0),
        );
        // NED/FRD: north 7, east 5, down −2; heading east is yaw +90° about down; roll starboard-down is +0.1.
        let ned = Frames::new(WorldFrame::Ned, BodyFrame::Frd, TankPose::default());
        let b = ned.tank_coordinates(
            Vector3::new(7.0, 5.0, -2.0),
            UnitQuaternion::from_euler_angles(0.1, 0.0, FRAC_PI_2),
        );
        assert!(close(a, b), "{a:?} vs {b:?}");
        // Pitch bow-up is positive about FRD's y (starboard) and negative about FLU's y (port).
        let b = ned.tank_coordinates(
            Vector3::zeros(),
            UnitQuaternion::from_euler_angles(0.0, 0.05, FRAC_PI_2),
        );
        let a = enu.tank_coordinates(
            Vector3::zeros(),
            UnitQuaternion::from_euler_angles(0.0, -0.05, 0.0),
        );
        assert!(close(a, b), "{a:?} vs {b:?}");
    }
}
