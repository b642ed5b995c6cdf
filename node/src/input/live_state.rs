//! Motion received as full rigid states (pose, velocities, accelerations: the iceoryx2 [`MotionSample`]),
//! sample by sample. Between two samples the tank follows the quintic Hermite curve through both
//! ([`CoupledMotion`]), so the solver may go right up to the newest sample: nothing is estimated from
//! later ones.
//!
//! [`MotionSample`]: slosh_msgs::iox::MotionSample

use super::live_motion::{Limits, Rejected};
use sph::motion::{CoupledMotion, RigidState, TankMotion};
use std::collections::VecDeque;

/// Samples kept before the solver's time.
const KEEP_BEFORE: usize = 2;

/// Whether the tank can have moved from state `from` to `to` in `dt` s: no faster a move or turn than
/// `limits` allow (a garbled sample would otherwise collapse the solver's step).
pub fn check_jump(
    limits: &Limits,
    dt: f64,
    from: &RigidState,
    to: &RigidState,
) -> Result<(), Rejected> {
    let moved = (to.position - from.position).norm();
    limits.moved("position", moved, dt)?;
    let turned = from.orientation.angle_to(&to.orientation);
    limits.turned("orientation", turned, dt)?;
    Ok(())
}

#[derive(Debug)]
pub struct LiveState {
    limits: Limits,
    samples: VecDeque<(f64, RigidState)>,
}

impl LiveState {
    pub fn new(limits: Limits) -> Self {
        Self {
            limits,
            samples: VecDeque::with_capacity(64),
        }
    }

    /// Adds the tank's state at `t` (already checked finite): refused when not after the newest, or a
    /// faster move than the limits from it.
    pub fn push(&mut self, t: f64, s: RigidState) -> Result<(), Rejected> {
        if let Some(&(t0, s0)) = self.samples.back() {
            if t == t0 {
                return Err(Rejected::Duplicate { time: t });
            }
            if t < t0 {
                return Err(Rejected::OutOfOrder {
                    time: t,
                    newest: t0,
                });
            }
            check_jump(&self.limits, t - t0, &s0, &s)?;
        }
        self.samples.push_back((t, s));
        Ok(())
    }

    /// The newest state at rest (velocities and accelerations zero), for holding the last pose.
    pub fn held(&self) -> Option<RigidState> {
        self.samples.back().map(|&(_, s)| RigidState {
            velocity: Default::default(),
            acceleration: Default::default(),
            angular_velocity: Default::default(),
            angular_acceleration: Default::default(),
            ..s
        })
    }

    pub fn forget_before(&mut self, t: f64) {
        while self.samples.len() > KEEP_BEFORE && self.samples[1].0 < t {
            self.samples.pop_front();
        }
    }

    pub fn newest(&self) -> Option<f64> {
        self.samples.back().map(|s| s.0)
    }

    /// The newest sample's time (None until two are in): every state carries its derivatives, so there is
    /// nothing to wait for.
    pub fn safe_until(&self) -> Option<f64> {
        (self.samples.len() >= 2).then(|| self.samples.back().expect("two").0)
    }
}

impl TankMotion for LiveState {
    fn state(&self, t: f64) -> RigidState {
        let n = self.samples.len();
        if n == 0 {
            return RigidState::at_rest();
        }
        let i = self.samples.partition_point(|s| s.0 <= t);
        if i == 0 {
            return self.samples[0].1;
        }
        if i == n {
            return self.samples[n - 1].1;
        }
        let (ta, sa) = self.samples[i - 1];
        let (tb, sb) = self.samples[i];
        let mut m = CoupledMotion::new(ta, sa);
        m.push(tb, sb);
        m.state(t)
    }

    fn end_time(&self) -> f64 {
        self.newest().unwrap_or(0.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph::motion::{RegularDof, RegularMotion};

    #[test]
    fn follows_sampled_states_between_samples_and_refuses_bad_ones() {
        let dof = |amplitude, period| RegularDof {
            amplitude,
            period,
            phase: 0.3,
        };
        let zero = dof(0.0, 0.0);
        let m = RegularMotion {
            dofs: [
                dof(0.2, 2.0),
                zero,
                dof(0.1, 3.0),
                dof(0.05, 4.0),
                zero,
                zero,
            ],
            ramp: 0.0,
        };
        let limits = Limits {
            max_speed: 5.0,
            max_rotation_rate: 2.0,
        };
        let mut live = LiveState::new(limits);
        assert_eq!(live.safe_until(), None);
        // 20 Hz states: between them the quintic follows the motion closely.
        for k in 0..=40 {
            let t = k as f64 * 0.05;
            live.push(t, m.state(t)).unwrap();
        }
        assert_eq!(live.safe_until(), Some(2.0));
        let mut worst = 0.0f64;
        for k in 0..200 {
            let t = k as f64 * 0.01 + 0.003;
            let (a, b) = (live.state(t), m.state(t));
            worst = worst.max((a.acceleration - b.acceleration).norm());
            assert!((a.position - b.position).norm() < 1e-5, "t = {t}");
        }
        assert!(worst < 0.02, "acceleration off by {worst} m/s²");
        live.forget_before(1.0);
        assert!((live.state(1.52).position - m.state(1.52).position).norm() < 1e-5);
        // Out of order, duplicate, jump.
        let s = m.state(2.1);
        assert!(matches!(
            live.push(1.9, s),
            Err(Rejected::OutOfOrder { .. })
        ));
        assert!(matches!(live.push(2.0, s), Err(Rejected::Duplicate { .. })));
        let mut far = s;
        far.position.x += 1.0;
        assert!(matches!(
            live.push(2.1, far),
            Err(Rejected::Jump {
                what: "position",
                ..
            })
        ));
        live.push(2.1, s).unwrap();
        let held = live.held().unwrap();
        assert_eq!(held.position, s.position);
        assert_eq!(held.velocity.norm(), 0.0);
    }
}
