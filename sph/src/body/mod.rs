//! Floating bodies: rigid hollow boxes of dynamic boundary particles that the liquid moves (the paper's
//! damaged box, its cases 2 and 3). Their particles sit among the tank's wall particles (tagged with their
//! body particle index) and act on the liquid as walls do; the liquid's reaction on them is summed into a
//! force and moment on each body ([`crate::scheme::coupling`]) and integrated with its mass and inertia ([`rigid`]).

pub mod piston;
pub mod rigid;
pub mod shell;

pub use rigid::RigidBody;

use crate::particles::{Boundary, NOT_BODY};
use nalgebra::Vector3;

/// What a body is doing, in the tank frame (2D: forces, moments and volumes for the tank's breadth).
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize)]
pub struct BodyState {
    pub name: String,
    /// Centre of gravity, m.
    pub position: [f64; 3],
    /// Orientation as a quaternion (x, y, z, w) and as roll, pitch, yaw (rad; rotation =
    /// Rz(yaw)·Ry(pitch)·Rx(roll), intrinsic z-y'-x'').
    pub quaternion: [f64; 4],
    pub roll_pitch_yaw: [f64; 3],
    /// m/s and rad/s.
    pub velocity: [f64; 3],
    pub angular_velocity: [f64; 3],
    /// The liquid's force on the body (N) and its moment about the centre of gravity (N·m).
    pub force: [f64; 3],
    pub moment: [f64; 3],
    /// Liquid inside the body's hollow, m³, and its rate of change since the last observation, m³/s.
    pub flooded_volume: f64,
    pub inflow_rate: f64,
}

/// The bodies of a simulation and where their particles are among the boundary particles.
#[derive(Clone, Debug, Default)]
pub struct Bodies {
    pub list: Vec<RigidBody>,
    /// Body particle index → (body, its particle).
    pub which: Vec<(u32, u32)>,
    /// Body particle index → index among the boundary particles (after each sort).
    pub slots: Vec<u32>,
    /// The liquid's force on each body particle (last evaluation).
    pub forces: Vec<[f64; 3]>,
    /// Force of the liquid on all bodies and its moment about the tank origin (last evaluation).
    pub total_force: [f64; 3],
    pub total_moment: [f64; 3],
    /// Flooded volume per body at the last observation, and its time.
    pub last_flooded: Option<(f64, Vec<f64>)>,
}

impl Bodies {
    pub fn is_empty(&self) -> bool {
        self.list.is_empty()
    }

    /// Moves the body particles among `bound` to where their bodies are now, with their velocities.
    pub fn place<const D: usize>(&self, bound: &mut Boundary<D>) {
        for (g, &(b, i)) in self.which.iter().enumerate() {
            let (x, v) = self.list[b as usize].particle(i as usize);
            let s = self.slots[g] as usize;
            let (x, v): ([f64; D], [f64; D]) = (
                crate::vector::from3([x.x, x.y, x.z]),
                crate::vector::from3([v.x, v.y, v.z]),
            );
            for d in 0..D {
                bound.x[d][s] = x[d] as f32;
                bound.v[d][s] = v[d] as f32;
            }
        }
    }

    /// Re-reads the slots from the boundary particles' tags (after a sort).
    pub fn reindex<const D: usize>(&mut self, bound: &Boundary<D>) {
        self.slots.resize(self.which.len(), 0);
        for (s, &t) in bound.tag.iter().enumerate() {
            if t != NOT_BODY {
                self.slots[t as usize] = s as u32;
            }
        }
    }

    /// Sums the per-particle forces into each body's force and moment and the totals about the tank origin;
    /// returns each body's (force, moment about its centre of gravity).
    pub fn sum_forces(&mut self) -> Vec<(Vector3<f64>, Vector3<f64>)> {
        let mut out = vec![(Vector3::zeros(), Vector3::zeros()); self.list.len()];
        let (mut tf, mut tm) = (Vector3::zeros(), Vector3::zeros());
        for (g, &(b, i)) in self.which.iter().enumerate() {
            let body = &self.list[b as usize];
            let f = Vector3::from(self.forces[g]);
            let (x, _) = body.particle(i as usize);
            out[b as usize].0 += f;
            out[b as usize].1 += (x - body.now.cog).cross(&f);
            tf += f;
            tm += x.cross(&f);
        }
        self.total_force = tf.into();
        self.total_moment = tm.into();
        out
    }
}
