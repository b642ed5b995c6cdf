//! A rigid body's state and its equations of motion in the tank frame, advanced with the liquid's
//! symplectic predictor–corrector (the same half steps, the same force evaluations).
//!
//! Translation: m dV/dt = F_liquid + F_springs + m a_frame(cog, V), with a_frame the apparent gravity and the
//! frame's inertial terms at the centre of gravity. Rotation (ω relative to the tank, Ω = ω_frame + ω the
//! absolute angular velocity): I dΩ/dt + Ω × I Ω = M about the centre of gravity, so
//! dω/dt = I⁻¹ (M − Ω × I Ω) − ω̇_frame − ω_frame × ω. Fixed degrees of freedom get no acceleration.

use crate::motion::FrameTerms;
use crate::params::{BodySpec, Dof, PistonSpec};
use nalgebra::{Matrix3, Rotation3, Vector3};

type V3 = Vector3<f64>;

/// A spring, with its attachment relative to the centre of gravity in body axes.
#[derive(Clone, Debug)]
struct Spring {
    attach: V3,
    anchor: V3,
    stiffness: f64,
    rest_length: f64,
}

/// Position, orientation and velocities of a body in the tank frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Pose {
    /// Centre of gravity, m.
    pub cog: V3,
    /// Body axes in the tank frame.
    pub rot: Rotation3<f64>,
    /// Velocity of the centre of gravity, m/s.
    pub vel: V3,
    /// Angular velocity relative to the tank, rad/s.
    pub omega: V3,
}

#[derive(Clone, Debug)]
pub struct RigidBody {
    pub name: String,
    pub mass: f64,
    /// About the centre of gravity, body axes.
    inertia: Matrix3<f64>,
    /// Degrees of freedom that move (x, y, z, rx, ry, rz).
    free: [bool; 6],
    springs: Vec<Spring>,
    /// Centre of gravity in box coordinates.
    pub cog_box: V3,
    /// The hollow inside in box coordinates: lower and upper corners.
    pub inner: (V3, V3),
    /// Outer size of its box (x, y, z), m (0 for a wave maker's plate).
    pub size: V3,
    /// Its particles relative to the centre of gravity, body axes.
    pub local: Vec<V3>,
    pub now: Pose,
    start: Pose,
    /// Accelerations of the last evaluation (tank frame): linear, angular.
    pub acc: V3,
    pub alpha: V3,
    /// The liquid's force on the body and its moment about the centre of gravity (last evaluation).
    pub liquid_force: V3,
    pub liquid_moment: V3,
    /// A wave maker's plate: moved along x by its piston from the rest position of its centre, not by forces.
    drive: Option<(PistonSpec, f64)>,
}

/// The 3-vector of a D-dimensional point (y = 0 in 2D), and back.
pub fn v3(p: [f64; 3]) -> V3 {
    V3::new(p[0], p[1], p[2])
}

impl RigidBody {
    /// The body of `spec` at rest where it starts, with particles at `points` (box coordinates).
    pub fn new(spec: &BodySpec, dimension: usize, points: &[[f64; 3]]) -> Self {
        let cog_box = v3(spec.centre_of_gravity);
        let mut free = [true; 6];
        for d in &spec.fixed {
            free[d.index()] = false;
        }
        if dimension == 2 {
            for d in [Dof::Sway, Dof::Roll, Dof::Yaw] {
                free[d.index()] = false;
            }
        }
        let t = spec.wall_thickness;
        let half = |k: usize| 0.5 * spec.size[k];
        let inner = (
            V3::new(-half(0) + t, -half(1) + t, t),
            V3::new(half(0) - t, half(1) - t, spec.size[2] - t),
        );
        let origin = v3(spec.position);
        let keep = |v: [f64; 3], first: usize| {
            V3::from_fn(|k, _| if free[first + k] { v[k] } else { 0.0 })
        };
        let pose = Pose {
            cog: origin + cog_box,
            rot: Rotation3::identity(),
            vel: keep(spec.velocity, 0),
            omega: keep(spec.angular_velocity, 3),
        };
        Self {
            name: spec.name.clone(),
            mass: spec.mass,
            inertia: Matrix3::from_diagonal(&v3(spec.inertia)),
            free,
            springs: spec
                .springs
                .iter()
                .map(|s| Spring {
                    attach: v3(s.attach) - cog_box,
                    anchor: v3(s.anchor),
                    stiffness: s.stiffness,
                    rest_length: s.rest_length,
                })
                .collect(),
            cog_box,
            inner,
            size: v3(spec.size),
            local: points.iter().map(|p| v3(*p) - cog_box).collect(),
            now: pose,
            start: pose,
            acc: V3::zeros(),
            alpha: V3::zeros(),
            liquid_force: V3::zeros(),
            liquid_moment: V3::zeros(),
            drive: None,
        }
    }

    /// A wave maker's plate of `points` (tank frame) driven by `piston`.
    pub fn driven(name: &str, piston: &PistonSpec, points: &[[f64; 3]]) -> Self {
        let n = points.len().max(1) as f64;
        let centre = points.iter().fold(V3::zeros(), |c, p| c + v3(*p)) / n;
        let pose = Pose {
            cog: centre,
            rot: Rotation3::identity(),
            vel: V3::zeros(),
            omega: V3::zeros(),
        };
        Self {
            name: name.to_string(),
            mass: 1.0,
            inertia: Matrix3::identity(),
            free: [false; 6],
            springs: Vec::new(),
            cog_box: V3::zeros(),
            // No hollow: nothing floods it.
            inner: (V3::repeat(1.0), V3::repeat(-1.0)),
            size: V3::zeros(),
            local: points.iter().map(|p| v3(*p) - centre).collect(),
            now: pose,
            start: pose,
            acc: V3::zeros(),
            alpha: V3::zeros(),
            liquid_force: V3::zeros(),
            liquid_moment: V3::zeros(),
            drive: Some((piston.clone(), centre.x)),
        }
    }

    /// The artificial added mass of [`Self::accelerate_relaxed`]: the liquid that fills the box's outer
    /// volume (density `rho`; 2D: per metre), and its moments of inertia about the centre of the box.
    pub fn liquid_of_box(&self, rho: f64, dimension: usize) -> (f64, V3) {
        let s = self.size;
        let ma = rho * s.x * s.z * if dimension == 3 { s.y } else { 1.0 };
        let ia = V3::new(
            ma * (s.y * s.y + s.z * s.z) / 12.0,
            ma * (s.x * s.x + s.z * s.z) / 12.0,
            ma * (s.x * s.x + s.y * s.y) / 12.0,
        );
        (ma, ia)
    }

    /// A driven body's pose at time t.
    fn drive_to(&mut self, t: f64) -> bool {
        let Some((piston, x0)) = &self.drive else {
            return false;
        };
        let (x, v) = piston.displacement(t);
        self.now.cog.x = x0 + x;
        self.now.vel.x = v;
        true
    }

    /// Position and velocity of particle i in the tank frame.
    #[inline]
    pub fn particle(&self, i: usize) -> (V3, V3) {
        let r = self.now.rot * self.local[i];
        (self.now.cog + r, self.now.vel + self.now.omega.cross(&r))
    }

    /// A tank-frame point in box coordinates.
    pub fn to_box(&self, x: V3) -> V3 {
        self.now.rot.inverse() * (x - self.now.cog) + self.cog_box
    }

    /// Whether a tank-frame point is in the body's hollow inside.
    pub fn inside(&self, x: V3, dimension: usize) -> bool {
        let b = self.to_box(x);
        let (lo, hi) = &self.inner;
        (0..3)
            .filter(|&k| dimension == 3 || k != 1)
            .all(|k| b[k] > lo[k] && b[k] < hi[k])
    }

    /// The springs' force and moment about the centre of gravity.
    fn spring_wrench(&self) -> (V3, V3) {
        let (mut f, mut m) = (V3::zeros(), V3::zeros());
        for s in &self.springs {
            let arm = self.now.rot * s.attach;
            let d = self.now.cog + arm - s.anchor;
            let len = d.norm();
            if len > 0.0 {
                let fs = -s.stiffness * (len - s.rest_length) * d / len;
                f += fs;
                m += arm.cross(&fs);
            }
        }
        (f, m)
    }

    /// Accelerations from the liquid's force and moment (about the centre of gravity), the springs and the
    /// tank frame's motion.
    pub fn accelerate(&mut self, force: V3, moment: V3, frame: &FrameTerms) {
        self.liquid_force = force;
        self.liquid_moment = moment;
        let p = &self.now;
        let f32v = |v: V3| [v.x as f32, v.y as f32, v.z as f32];
        let a_frame = frame.acceleration(f32v(p.cog), f32v(p.vel));
        let a_frame = V3::new(a_frame[0] as f64, a_frame[1] as f64, a_frame[2] as f64);
        let (fs, ms) = self.spring_wrench();
        let mut acc = (force + fs) / self.mass + a_frame;
        let w_frame = V3::new(frame.w[0] as f64, frame.w[1] as f64, frame.w[2] as f64);
        let dw_frame = V3::new(frame.dw[0] as f64, frame.dw[1] as f64, frame.dw[2] as f64);
        let rot = p.rot.matrix();
        let inertia = rot * self.inertia * rot.transpose();
        let big_omega = w_frame + p.omega;
        let torque = moment + ms - big_omega.cross(&(inertia * big_omega));
        // Only the free rotations respond: solve the inertia's free block.
        let mut alpha = V3::zeros();
        let free_rot: Vec<usize> = (0..3).filter(|&k| self.free[3 + k]).collect();
        if !free_rot.is_empty() {
            let n = free_rot.len();
            let sub = nalgebra::DMatrix::from_fn(n, n, |i, j| inertia[(free_rot[i], free_rot[j])]);
            let rhs = nalgebra::DVector::from_fn(n, |i, _| torque[free_rot[i]]);
            if let Some(sol) = sub.lu().solve(&rhs) {
                for (i, &k) in free_rot.iter().enumerate() {
                    alpha[k] = sol[i];
                }
            }
            alpha -= dw_frame + w_frame.cross(&p.omega);
        }
        for k in 0..3 {
            if !self.free[k] {
                acc[k] = 0.0;
            }
            if !self.free[3 + k] {
                alpha[k] = 0.0;
            }
        }
        self.acc = acc;
        self.alpha = alpha;
    }

    /// [`Self::accelerate`] for a partitioned coupling (the divergence-free scheme's step computes the
    /// liquid's force with the body's velocity held): with an artificial added mass `ma` (and moments of
    /// inertia `ia`, tank axes), (m + ma)·a = m·a_new + ma·a_last, so a body lighter than the liquid it
    /// drags along does not overshoot step after step (the added-mass instability); in a steady motion
    /// a_new = a_last and nothing changes.
    pub fn accelerate_relaxed(
        &mut self,
        force: V3,
        moment: V3,
        frame: &FrameTerms,
        ma: f64,
        ia: V3,
    ) {
        let (acc0, alpha0) = (self.acc, self.alpha);
        self.accelerate(force, moment, frame);
        let w = self.mass / (self.mass + ma);
        self.acc = w * self.acc + (1.0 - w) * acc0;
        let inertia = self.now.rot.matrix() * self.inertia * self.now.rot.matrix().transpose();
        for k in 0..3 {
            let i = inertia[(k, k)];
            let w = i / (i + ia[k]);
            self.alpha[k] = w * self.alpha[k] + (1.0 - w) * alpha0[k];
        }
    }

    /// Saves the state (at time t) and advances it half a step with the accelerations of the state.
    pub fn predict(&mut self, t: f64, dt: f64) {
        self.start = self.now;
        if self.drive_to(t + 0.5 * dt) {
            return;
        }
        let h = 0.5 * dt;
        let p = &mut self.now;
        p.cog += h * p.vel;
        p.rot = Rotation3::new(h * p.omega) * p.rot;
        p.vel += h * self.acc;
        p.omega += h * self.alpha;
    }

    /// One step of the divergence-free scheme (from t): symplectic Euler with the accelerations of the
    /// step's solve, as the liquid is moved (its new velocity, then the position from it).
    pub fn advance(&mut self, t: f64, dt: f64) {
        self.start = self.now;
        if self.drive_to(t + dt) {
            return;
        }
        let p = &mut self.now;
        p.vel += dt * self.acc;
        p.omega += dt * self.alpha;
        p.cog += dt * p.vel;
        p.rot = Rotation3::new(dt * p.omega) * p.rot;
    }

    /// Completes the step (from t) from the accelerations at the half step.
    pub fn correct(&mut self, t: f64, dt: f64) {
        if self.drive_to(t + dt) {
            return;
        }
        let s = self.start;
        let vel = s.vel + dt * self.acc;
        let omega = s.omega + dt * self.alpha;
        self.now = Pose {
            cog: s.cog + 0.5 * dt * (s.vel + vel),
            rot: Rotation3::new(0.5 * dt * (s.omega + omega)) * s.rot,
            vel,
            omega,
        };
    }
}

impl RigidBody {
    /// Keeps the body's particles at least `gap` inside the tank's box (`lo`, `hi`, tank frame) along the
    /// axes it may move along (none for a fixed or driven body): a body that reaches a wall is moved back
    /// onto it and loses its velocity into the wall (an inelastic contact, without friction or the
    /// contact's moment). Returns whether it touched.
    pub fn contain(&mut self, lo: V3, hi: V3, gap: f64) -> bool {
        if !self.free[..3].contains(&true) {
            return false;
        }
        let (mut min, mut max) = (V3::repeat(f64::INFINITY), V3::repeat(f64::NEG_INFINITY));
        for r in &self.local {
            let x = self.now.cog + self.now.rot * r;
            min = min.inf(&x);
            max = max.sup(&x);
        }
        let mut touched = false;
        for k in (0..3).filter(|&k| self.free[k]) {
            if min[k] < lo[k] + gap {
                self.now.cog[k] += lo[k] + gap - min[k];
                self.now.vel[k] = self.now.vel[k].max(0.0);
                touched = true;
            } else if max[k] > hi[k] - gap {
                self.now.cog[k] -= max[k] - (hi[k] - gap);
                self.now.vel[k] = self.now.vel[k].min(0.0);
                touched = true;
            }
        }
        touched
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> BodySpec {
        BodySpec {
            name: "b".into(),
            size: [0.1, 0.1, 0.1],
            wall_thickness: 0.01,
            position: [0.0, 0.0, 0.1],
            mass: 2.0,
            inertia: [0.1, 0.2, 0.3],
            centre_of_gravity: [0.0, 0.0, 0.05],
            velocity: [0.0; 3],
            angular_velocity: [0.0; 3],
            fixed: vec![],
            openings: vec![],
            bulkheads: vec![],
            springs: vec![],
        }
    }

    #[test]
    fn falls_freely_under_gravity_to_second_order() {
        let mut b = RigidBody::new(&spec(), 3, &[[0.05, 0.0, 0.0]]);
        let frame = FrameTerms {
            g: [0.0, 0.0, -9.81],
            ..Default::default()
        };
        let dt = 0.01;
        for _ in 0..100 {
            b.accelerate(V3::zeros(), V3::zeros(), &frame);
            b.predict(0.0, dt);
            b.accelerate(V3::zeros(), V3::zeros(), &frame);
            b.correct(0.0, dt);
        }
        // z = z0 − g t²/2 exactly for a constant acceleration.
        let g = 9.81f32 as f64;
        assert!((b.now.cog.z - (0.15 - 0.5 * g)).abs() < 1e-9);
        assert!((b.now.vel.z + g).abs() < 1e-9);
        assert_eq!(b.now.rot, Rotation3::identity());
    }

    #[test]
    fn spring_oscillates_at_its_natural_period() {
        let mut s = spec();
        s.springs.push(crate::params::SpringSpec {
            name: "k".into(),
            attach: [0.0, 0.0, 0.05],
            anchor: [0.0, 0.0, 0.15],
            stiffness: 50.0,
            rest_length: 0.0,
        });
        let mut b = RigidBody::new(&s, 2, &[]);
        b.now.vel.x = 0.1;
        let frame = FrameTerms::default();
        let dt = 1e-3;
        let period = 2.0 * std::f64::consts::PI * (2.0f64 / 50.0).sqrt();
        let mut t = 0.0;
        let mut crossings = vec![];
        let mut prev = b.now.cog.x;
        while t < 3.0 * period {
            b.accelerate(V3::zeros(), V3::zeros(), &frame);
            b.predict(0.0, dt);
            b.accelerate(V3::zeros(), V3::zeros(), &frame);
            b.correct(0.0, dt);
            t += dt;
            let x = b.now.cog.x;
            if prev > 0.0 && x <= 0.0 {
                crossings.push(t - dt * x / (x - prev));
            }
            prev = x;
        }
        let measured = crossings[1] - crossings[0];
        assert!(
            (measured / period - 1.0).abs() < 1e-3,
            "{measured} vs {period}"
        );
    }

    #[test]
    fn a_falling_body_stops_on_the_floor() {
        let mut b = RigidBody::new(&spec(), 2, &[[0.0, 0.0, 0.0], [0.05, 0.0, 0.1]]);
        let frame = FrameTerms {
            g: [0.0, 0.0, -9.81],
            ..Default::default()
        };
        let (lo, hi) = (V3::new(-1.0, 0.0, 0.0), V3::new(1.0, 0.0, 1.0));
        let mut touched = false;
        for _ in 0..1000 {
            b.accelerate(V3::zeros(), V3::zeros(), &frame);
            b.predict(0.0, 1e-3);
            b.accelerate(V3::zeros(), V3::zeros(), &frame);
            b.correct(0.0, 1e-3);
            touched |= b.contain(lo, hi, 0.01);
        }
        assert!(touched);
        // Its lowest particle (the bottom face, 0.05 below the centre of gravity) rests 0.01 above the floor.
        assert!((b.now.cog.z - 0.06).abs() < 1e-12);
        assert!(b.now.vel.z.abs() < 0.01);
    }

    #[test]
    fn a_torque_turns_a_2d_body_about_y_only() {
        let mut b = RigidBody::new(&spec(), 2, &[[0.05, 0.0, 0.05]]);
        let frame = FrameTerms::default();
        let dt = 1e-3;
        for _ in 0..100 {
            b.accelerate(V3::zeros(), V3::new(0.3, 0.02, 0.5), &frame);
            b.predict(0.0, dt);
            b.accelerate(V3::zeros(), V3::new(0.3, 0.02, 0.5), &frame);
            b.correct(0.0, dt);
        }
        // ω = M t / I about y; no turn about x or z in 2D.
        assert!((b.now.omega.y - 0.02 * 0.1 / 0.2).abs() < 1e-12);
        assert_eq!((b.now.omega.x, b.now.omega.z), (0.0, 0.0));
        let angle: f64 = 0.5 * 0.02 / 0.2 * 0.1 * 0.1;
        let (x, _) = b.particle(0);
        // The particle 0.05 m along x of the centre of gravity turns by `angle` about y (z goes down).
        assert!((x.z - (0.15 - 0.05 * angle.sin())).abs() < 1e-9);
    }
}
