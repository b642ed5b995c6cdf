//! Motion received sample by sample. Samples are checked (finite, in order, no duplicates, no jumps) and
//! interpolated by a cubic spline over a sliding window; the solver is never run past the newest sample it
//! has, less a small delay so that the spline's free end does not bias the accelerations it sees.

use sph::motion::{Dof6Motion, RigidState, SampledMotion, TankMotion};
use std::collections::VecDeque;
use std::f64::consts::PI;

/// Samples kept at least, and samples kept before the solver's time, for the spline's context.
const KEEP: usize = 24;
const KEEP_BEFORE: usize = 4;

/// Why a sample was dropped.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum Rejected {
    #[error("{what} is not a finite number")]
    NotFinite { what: &'static str },
    #[error("stamp {time:.6} s is older than the newest sample's {newest:.6} s (out of order)")]
    OutOfOrder { time: f64, newest: f64 },
    #[error("stamp {time:.6} s repeats the newest sample's (duplicate)")]
    Duplicate { time: f64 },
    #[error("{0}")]
    Invalid(String),
    #[error("{what} jumps by {size:.3} {unit} in {dt:.4} s ({rate:.2} {unit}/s), faster than {param} = {limit} {unit}/s (raise it if the motion is real)", rate = size / dt)]
    Jump {
        what: &'static str,
        size: f64,
        dt: f64,
        limit: f64,
        /// The parameter that sets `limit`.
        param: &'static str,
        /// m or rad.
        unit: &'static str,
    },
}

impl Rejected {
    /// Whether the sample was refused for where it lies against the newest sample (its time or its pose),
    /// not for what it holds: while the node holds the last pose, the newest sample is a held one.
    pub fn against_newest(&self) -> bool {
        matches!(
            self,
            Self::OutOfOrder { .. } | Self::Duplicate { .. } | Self::Jump { .. }
        )
    }
}

/// Plausibility limits of incoming samples.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// m/s between consecutive samples.
    pub max_speed: f64,
    /// rad/s between consecutive samples.
    pub max_rotation_rate: f64,
}

impl Limits {
    /// Refuses a move of `size` m in `dt` s faster than `max_speed` as a jump of `what`.
    pub fn moved(&self, what: &'static str, size: f64, dt: f64) -> Result<(), Rejected> {
        Self::jump(what, size, dt, self.max_speed, "input.max_speed", "m")
    }

    /// Refuses a turn of `size` rad in `dt` s faster than `max_rotation_rate` as a jump of `what`.
    pub fn turned(&self, what: &'static str, size: f64, dt: f64) -> Result<(), Rejected> {
        let limit = self.max_rotation_rate;
        Self::jump(what, size, dt, limit, "input.max_rotation_rate", "rad")
    }

    fn jump(
        what: &'static str,
        size: f64,
        dt: f64,
        limit: f64,
        param: &'static str,
        unit: &'static str,
    ) -> Result<(), Rejected> {
        if size > limit * dt {
            return Err(Rejected::Jump {
                what,
                size,
                dt,
                limit,
                param,
                unit,
            });
        }
        Ok(())
    }
}

/// Tank poses received so far (times relative to the first sample), as a [`TankMotion`].
#[derive(Debug)]
pub struct LiveMotion {
    limits: Limits,
    times: VecDeque<f64>,
    poses: VecDeque<[f64; 6]>,
    spline: Option<SampledMotion>,
}

const NAMES: [&str; 6] = ["x", "y", "z", "roll", "pitch", "yaw"];

impl LiveMotion {
    pub fn new(limits: Limits) -> Self {
        Self {
            limits,
            times: VecDeque::with_capacity(KEEP + 1),
            poses: VecDeque::with_capacity(KEEP + 1),
            spline: None,
        }
    }

    /// Adds a tank pose (x, y, z, roll, pitch, yaw) at time `t`, or says why not.
    pub fn push(&mut self, t: f64, pose: [f64; 6]) -> Result<(), Rejected> {
        let prev = self.times.back().copied().zip(self.poses.back().copied());
        check_pose(prev, t, &pose, &self.limits)?;
        self.times.push_back(t);
        self.poses.push_back(pose);
        self.refit();
        Ok(())
    }

    /// Drops samples the solver, now at time `t`, no longer needs (a few before `t` stay, and at least 24 in
    /// all): the window always covers the solver's time however far it lags behind the input.
    pub fn forget_before(&mut self, t: f64) {
        let mut dropped = false;
        while self.times.len() > KEEP && self.times[KEEP_BEFORE] < t {
            self.times.pop_front();
            self.poses.pop_front();
            dropped = true;
        }
        if dropped {
            self.refit();
        }
    }

    fn refit(&mut self) {
        self.spline = if self.times.len() >= 2 {
            let poses: Vec<[f64; 6]> = self.poses.iter().copied().collect();
            SampledMotion::new(self.times.iter().copied().collect(), &poses).ok()
        } else {
            None
        };
    }

    /// Time of the newest sample.
    pub fn newest(&self) -> Option<f64> {
        self.times.back().copied()
    }

    /// The newest pose.
    pub fn last_pose(&self) -> Option<[f64; 6]> {
        self.poses.back().copied()
    }

    /// How far the solver may go: the newest sample less `delay_samples` sample intervals (None until two
    /// samples are in).
    pub fn safe_until(&self, delay_samples: usize) -> Option<f64> {
        let n = self.times.len();
        if n < 2 {
            return None;
        }
        let k = delay_samples.min(n - 2);
        Some(self.times[n - 1 - k])
    }

    pub fn samples(&self) -> usize {
        self.times.len()
    }
}

/// Whether a tank pose (x, y, z, roll, pitch, yaw) at time `t` may follow the sample `prev`: finite, later than
/// it, and no faster a move than `limits` allow.
pub fn check_pose(
    prev: Option<(f64, [f64; 6])>,
    t: f64,
    pose: &[f64; 6],
    limits: &Limits,
) -> Result<(), Rejected> {
    if !t.is_finite() {
        return Err(Rejected::NotFinite { what: "time" });
    }
    if let Some(k) = pose.iter().position(|v| !v.is_finite()) {
        return Err(Rejected::NotFinite { what: NAMES[k] });
    }
    let Some((t0, p0)) = prev else {
        return Ok(());
    };
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
    let dist =
        ((pose[0] - p0[0]).powi(2) + (pose[1] - p0[1]).powi(2) + (pose[2] - p0[2]).powi(2)).sqrt();
    limits.moved("position", dist, dt)?;
    for k in 3..6 {
        let d = pose[k] - p0[k];
        let d = (d - (d / (2.0 * PI)).round() * 2.0 * PI).abs();
        limits.turned(NAMES[k], d, dt)?;
    }
    Ok(())
}

impl TankMotion for LiveMotion {
    fn state(&self, t: f64) -> RigidState {
        match &self.spline {
            Some(s) => s.dof(t).to_state(),
            None => match self.poses.back() {
                Some(p) => sph::motion::Dof6 {
                    q: *p,
                    ..Default::default()
                }
                .to_state(),
                None => RigidState::at_rest(),
            },
        }
    }

    fn end_time(&self) -> f64 {
        self.newest().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Limits {
        Limits {
            max_speed: 20.0,
            max_rotation_rate: 3.0,
        }
    }

    #[test]
    fn rejects_bad_samples_with_reasons_and_keeps_the_good_ones() {
        let mut m = LiveMotion::new(limits());
        m.push(0.0, [0.0; 6]).unwrap();
        assert_eq!(
            m.push(0.1, [f64::NAN, 0.0, 0.0, 0.0, 0.0, 0.0]),
            Err(Rejected::NotFinite { what: "x" })
        );
        m.push(0.1, [0.1, 0.0, 0.0, 0.0, 0.0, 0.0]).unwrap();
        assert!(matches!(
            m.push(0.1, [0.1; 6]),
            Err(Rejected::Duplicate { .. })
        ));
        assert!(matches!(
            m.push(0.05, [0.1; 6]),
            Err(Rejected::OutOfOrder { .. })
        ));
        assert!(matches!(
            m.push(0.2, [5.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            Err(Rejected::Jump {
                what: "position",
                param: "input.max_speed",
                ..
            })
        ));
        let msg = m
            .push(0.2, [0.2, 0.0, 0.0, 0.0, 0.0, 1.0])
            .unwrap_err()
            .to_string();
        assert!(
            msg.contains("yaw jumps by 1.000 rad in 0.1000 s (10.00 rad/s), faster than input.max_rotation_rate = 3 rad/s"),
            "{msg}"
        );
        assert!(matches!(
            m.push(0.2, [0.2, 0.0, 0.0, 0.0, 0.0, 1.0]),
            Err(Rejected::Jump { what: "yaw", .. })
        ));
        // Yaw wrapping through ±π is not a jump.
        let mut w = LiveMotion::new(limits());
        w.push(0.0, [0.0, 0.0, 0.0, 0.0, 0.0, PI - 0.01]).unwrap();
        w.push(0.1, [0.0, 0.0, 0.0, 0.0, 0.0, -PI + 0.01]).unwrap();
        assert_eq!(m.samples(), 2);
        assert_eq!(m.newest(), Some(0.1));
    }

    #[test]
    fn interpolates_a_sampled_sinusoid_with_its_acceleration() {
        let mut m = LiveMotion::new(limits());
        let (a, w) = (0.05, 2.0 * PI / 1.2);
        for i in 0..200 {
            let t = i as f64 * 0.01;
            m.push(t, [a * (w * t).sin(), 0.0, 0.0, 0.0, 0.0, 0.0])
                .unwrap();
        }
        // Nothing is forgotten before the solver has moved on; then the window keeps a few samples before
        // the solver's time, and at least KEEP.
        assert_eq!(m.samples(), 200);
        m.forget_before(1.5);
        assert_eq!(m.samples(), 200 - 150 + KEEP_BEFORE);
        m.forget_before(1.95);
        assert_eq!(m.samples(), KEEP);
        let until = m.safe_until(3).unwrap();
        assert!((until - 1.96).abs() < 1e-9);
        let t = until - 0.005;
        let s = m.state(t);
        let acc = -a * w * w * (w * t).sin();
        assert!(
            (s.acceleration.x - acc).abs() < 0.01 * a * w * w,
            "{} vs {acc}",
            s.acceleration.x
        );
        assert!((s.velocity.x - a * w * (w * t).cos()).abs() < 1e-3 * a * w);
    }
}
