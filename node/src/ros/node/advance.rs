//! Stepping: the solver advances up to what the input allows (the newest sample less
//! `input.delay_samples`, and in `follow_clock` mode not past `/clock`), each step landing on the next
//! output time, where the outputs go to the node's sinks (`outputs.rs`); then the pacing is noted against
//! real time.

use super::LiveNode;
use crate::ros::publish;
use ros2_client::ros2::LogLevel;
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::rosgraph_msgs::Clock;
use sph::motion::TankMotion as _;
use std::sync::atomic::{AtomicBool, Ordering};

impl LiveNode<'_> {
    /// Steps up to what the input allows (at most to `duration`, or until a stop or a diagnostics period
    /// has passed, so that input and reporting go on while a long stretch is stepped). Returns whether a
    /// step was taken; a solver failure leaves its reason in `error`.
    pub(super) fn advance(
        &mut self,
        base: f64,
        stop: &AtomicBool,
        duration: Option<f64>,
    ) -> anyhow::Result<bool> {
        self.intake.motion.forget_before(self.sim.time());
        self.follow_clock(base);
        let Some(until) = self.until(base) else {
            return Ok(false);
        };
        let dt_cap = self.params.solver.dt_max;
        let limit = duration.map_or(until, |d| until.min(d + dt_cap));
        // The first pass at t = 0 takes no step: it only publishes the initial state (output 0).
        let mut initial = self.outputs.times.at_start() && self.sim.time() == 0.0;
        let mut stepped = false;
        while (initial || self.sim.time() + dt_cap < limit) && !stop.load(Ordering::Relaxed) {
            if !std::mem::take(&mut initial) {
                if !self.step() {
                    break;
                }
                stepped = true;
            }
            self.drain_reader()?;
            if !self.publish_outputs(base)? {
                break;
            }
            if self.wall() - self.report.last_diag.wall > 1.0 / self.live.diagnostics_rate_hz {
                break;
            }
        }
        if self.error.is_some() {
            return Ok(stepped);
        }
        if stepped {
            self.clock_where_stopped(base)?;
        }
        self.note_pacing(until);
        Ok(stepped)
    }

    /// How far the simulation may go: the motion's safe end, and not past the ROS time when following
    /// `/clock` (None: paused, no motion yet, or no `/clock` yet).
    fn until(&self, base: f64) -> Option<f64> {
        if self.paused {
            return None;
        }
        let u = self
            .intake
            .motion
            .safe_until(self.cfg.config.input.delay_samples)?;
        match (&self.ends.sub_clock, self.ros_time) {
            (None, _) => Some(u),
            (Some(_), Some(now)) => Some(u.min(now - base)),
            (Some(_), None) => None,
        }
    }

    /// One step, to the next output time at most (so outputs are stamped on the output rate's grid
    /// whatever the step), then the input conventions' check on the apparent gravity. False: the solver
    /// failed (`error`).
    fn step(&mut self) -> bool {
        let motion = &self.intake.motion;
        if let Err(e) = self.outputs.step(self.sim.as_mut(), motion, f64::INFINITY) {
            self.error = Some(e.to_string());
            return false;
        }
        let (t, g0) = (self.sim.time(), self.params.gravity);
        let g = self.intake.motion.state(t).apparent_gravity(g0);
        match self
            .report
            .gravity_check
            .add(t, g, g0, self.report.input_kind)
        {
            Some(Ok(())) => self.report.counters.input_check = "ok".into(),
            Some(Err(w)) => {
                self.log(LogLevel::Warn, &w);
                self.report.counters.input_check = w;
            }
            None => {}
        }
        true
    }

    /// `follow_clock`: the ROS time from `/clock`; warns while motion comes but no `/clock`, or while
    /// `/clock` is far behind the motion's stamps (the simulation waits for it).
    fn follow_clock(&mut self, base: f64) {
        let Some(sc) = &self.ends.sub_clock else {
            return;
        };
        while let Ok(Some((m, _))) = sc.take() {
            self.ros_time = Some(m.clock.as_secs_f64());
        }
        let (w, first) = (self.wall(), self.report.first_reminder);
        let accepted = self.report.counters.accepted;
        if self.ros_time.is_none() && accepted > 0 && self.report.no_clock.due(w, first) {
            self.log(
                LogLevel::Warn,
                &format!(
                    "realtime.mode follow_clock: {accepted} motion samples in but no message on /clock yet: the simulation waits for the ROS time (start the clock's publisher, e.g. `ros2 bag play --clock`, or use realtime.mode realtime)"
                ),
            );
        }
        let Some(now) = self.ros_time else {
            return;
        };
        let behind = self.sim.time() - (now - base);
        if behind > self.cfg.config.input.max_gap_s && self.report.clock_behind.due(w, first) {
            let at = base + self.sim.time();
            self.log(
                LogLevel::Warn,
                &format!(
                    "realtime.mode follow_clock: /clock reads {now:.3} s, {behind:.3} s behind the motion's stamps (the simulation is at stamp {at:.3} s) and the simulation waits for it: /clock and the motion's header stamps must be on one time base (a bag played with --clock and its own stamps, or input.stamp: receive with a clock of the wall time)"
                ),
            );
        }
    }

    /// Lockstep: `/clock` also says where the simulation stopped for want of input, so a publisher pacing
    /// itself by `/clock` (`slosh motion --lockstep`) sends the next samples even when the output period is
    /// longer than its lead.
    fn clock_where_stopped(&mut self, base: f64) -> anyhow::Result<()> {
        if let Some(pc) = &self.ends.out.clock {
            let now = Time::from_secs_f64(base + self.sim.time());
            if self.last_clock != Some(now) {
                publish(pc, Clock { clock: now }, "/clock")?;
                self.last_clock = Some(now);
            }
        }
        Ok(())
    }

    /// Notes how far the simulation got against the input (held samples are no input to fall behind: they
    /// come in a stretch of `motion_timeout_s` at once), and warns once a second while it falls behind.
    fn note_pacing(&mut self, until: f64) {
        let input_until = if self.intake.holding {
            self.sim.time()
        } else {
            until
        };
        let w = self.wall();
        let behind = self.report.pacing.record(w, self.sim.time(), input_until);
        if behind && w - self.report.last_behind_warn > 1.0 {
            self.report.last_behind_warn = w;
            self.log(
                LogLevel::Warn,
                &format!(
                    "falling behind real time: simulation at {:.3} s, input at {until:.3} s (real-time factor {:.2})",
                    self.sim.time(),
                    self.report.pacing.realtime_factor()
                ),
            );
        }
    }
}
