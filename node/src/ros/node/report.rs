//! What the node tells of itself: its state, the diagnostics (at their rate, and at once when the level
//! changes), the counters behind them, and the reminders of a condition that lasts.

use super::input::{writers_on_graph, Input};
use super::LiveNode;
use crate::config::InputType;
use crate::input::gravity_check::{GravityCheck, InputKind};
use crate::messages::header;
use crate::ros::pacing::Pacing;
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::diagnostic_msgs::{DiagnosticArray, DiagnosticStatus, KeyValue};
use std::time::Instant;

/// What the node tells of itself: counters, warnings' throttles, diagnostics' clock, pacing.
pub(super) struct Report {
    pub(super) start: Instant,
    pub(super) pacing: Pacing,
    pub(super) counters: Counters,
    pub(super) last_diag: DiagClock,
    /// Warnings are throttled to one a second each: rejected samples, and falling behind real time.
    pub(super) last_reject_warn: f64,
    pub(super) last_behind_warn: f64,
    /// Warnings while no motion sample has come yet, while `follow_clock` has motion but no `/clock`, and
    /// while `/clock` is far behind the motion (first after `motion_timeout_s` or 5 s).
    pub(super) no_motion: Reminder,
    pub(super) no_clock: Reminder,
    pub(super) clock_behind: Reminder,
    pub(super) first_reminder: f64,
    /// The frame conventions' plausibility check on the apparent gravity.
    pub(super) gravity_check: GravityCheck,
    pub(super) input_kind: InputKind,
}

/// A warning repeated while a condition lasts (silence would look like a hang): first `first` s after the
/// condition was first seen, then every 10 s.
#[derive(Debug, Default)]
pub(super) struct Reminder {
    since: Option<f64>,
    last: Option<f64>,
}

impl Reminder {
    /// Whether to warn now (wall time `now`, s), the condition holding.
    pub(super) fn due(&mut self, now: f64, first: f64) -> bool {
        let since = *self.since.get_or_insert(now);
        let due = match self.last {
            None => now - since >= first,
            Some(last) => now - last >= 10.0,
        };
        if due {
            self.last = Some(now);
        }
        due
    }
}

/// Counters reported in diagnostics.
#[derive(Debug, Default, Clone)]
pub(super) struct Counters {
    pub(super) accepted: u64,
    pub(super) rejected: u64,
    pub(super) last_reject: String,
    /// Motion samples rejected since the last accepted one.
    pub(super) rejected_in_a_row: u64,
    pub(super) published: u64,
    pub(super) timeouts: u64,
    /// How the particle spacing was chosen (`realtime.auto_resolution`).
    pub(super) resolution: String,
    /// The frame conventions' plausibility check: empty until it has decided, `ok`, or its warning.
    pub(super) input_check: String,
    /// Motion samples of the last [`RECENT_S`] (wall time taken, accepted).
    pub(super) recent: std::collections::VecDeque<(f64, bool)>,
}

/// Why the node holds the last pose, `age` s after the last accepted motion sample: no input, or only
/// rejected samples (how many, and the last reason).
pub(super) fn no_input(counters: &Counters, age: f64, timeout: f64) -> String {
    match counters.rejected_in_a_row {
        0 => format!("no motion input for {age:.2} s (motion_timeout_s = {timeout})"),
        n => format!(
            "no usable motion input for {age:.2} s (motion_timeout_s = {timeout}): the {n} samples since the last accepted one were rejected (last: {}); a newer sample that does not continue the held pose is then followed afresh",
            counters.last_reject
        ),
    }
}

/// While the simulation is still behind the last accepted sample (`last_real`, simulation time), it
/// runs on the motion received; the last pose is held only from there.
pub(super) fn buffered(last_real: f64, sim_time: f64) -> String {
    if sim_time < last_real {
        format!(" from t = {last_real:.3} s (the simulation, at {sim_time:.3} s, still runs on the motion received up to then)")
    } else {
        String::new()
    }
}

/// The window over which a node that rejects most of its motion samples says so, s.
const RECENT_S: f64 = 2.0;

impl Counters {
    /// Notes a motion sample taken at wall time `w`, accepted or not.
    pub(super) fn note_motion(&mut self, w: f64, accepted: bool) {
        self.recent.push_back((w, accepted));
        while self.recent.front().is_some_and(|(t, _)| *t < w - RECENT_S) {
            self.recent.pop_front();
        }
    }

    /// The diagnostics' state when most of the last [`RECENT_S`]' motion samples (at least five) were
    /// rejected: the tank then follows the few accepted ones, which a consumer must not take for running.
    fn mostly_rejected(&self, now: f64) -> Option<String> {
        let recent = self.recent.iter().filter(|(t, _)| *t >= now - RECENT_S);
        let (n, bad) = recent.fold((0, 0), |(n, b), (_, ok)| (n + 1, b + usize::from(!ok)));
        (n >= 5 && 2 * bad > n).then(|| {
            format!(
                "running, but {bad} of the last {n} motion samples were rejected (last: {})",
                self.last_reject
            )
        })
    }
}

/// When diagnostics were last published, and at what level.
pub(super) struct DiagClock {
    pub(super) wall: f64,
    pub(super) level: Option<u8>,
}

impl DiagClock {
    /// Whether diagnostics at `level` are due at wall time `wall`: their period has passed, or the level
    /// changed since the last ones (an ERROR that lasts less than a period, e.g. a held pose the input
    /// soon takes over from, is still published, and so is the recovery from it).
    fn due(&self, wall: f64, rate: f64, level: u8) -> bool {
        wall - self.wall >= 1.0 / rate || self.level != Some(level)
    }
}

impl LiveNode<'_> {
    /// No motion sample accepted yet: waits a moment, says so now and then with what the graph shows, and
    /// publishes diagnostics without a simulation time.
    pub(super) fn wait_for_motion(&mut self) -> Result<(), crate::record::RecordError> {
        std::thread::sleep(std::time::Duration::from_millis(2));
        let w = self.wall();
        if self.report.no_motion.due(w, self.report.first_reminder) {
            let msg = format!(
                "no motion sample yet after {w:.0} s on {}",
                self.where_motion_comes_from()
            );
            self.log(ros2_client::ros2::LogLevel::Warn, &msg);
        }
        self.maybe_diagnostics(None, "waiting for motion input")
    }

    /// Where the node waits for motion, and what may keep it from coming.
    fn where_motion_comes_from(&self) -> String {
        let c = &self.cfg.config;
        let in_topic = &self.ends.in_topic;
        if c.input.kind == InputType::Iceoryx2 {
            let s = &c.iceoryx2.service;
            return format!("iceoryx2 service {s}/motion: is its publisher (e.g. `slosh motion CASE --iceoryx2 {s}`) running?");
        }
        let writers = writers_on_graph(&self.ends.context);
        let name = Input::topic(c.input.kind);
        match crate::ros::graph_hint::hint(in_topic, name, Input::type_name(c.input.kind), &writers) {
            Some(h) => format!("{in_topic}: {h}"),
            None => format!("{in_topic}: is the publisher running, on this ROS_DOMAIN_ID, and is the topic remapped right (-r {name}:=NAME)?"),
        }
    }

    /// The node's state in words, for the diagnostics (their level follows from it: [`level_of`]).
    fn state(&self) -> String {
        let (i, c) = (&self.intake, &self.report.counters);
        if self.paused {
            "paused (~/pause)".into()
        } else if i.holding {
            format!(
                "no {}motion input: holding the last pose{}",
                if c.rejected_in_a_row > 0 {
                    "usable "
                } else {
                    ""
                },
                buffered(i.last_real, self.sim.time())
            )
        } else if self.report.pacing.behind() {
            "behind real time".into()
        } else if self.ends.sub_clock.is_some() && self.ros_time.is_none() {
            "waiting for /clock (follow_clock)".into()
        } else {
            c.mostly_rejected(self.wall())
                .unwrap_or_else(|| "running".into())
        }
    }

    /// Diagnostics with the node's state, when due.
    pub(super) fn report_state(&mut self, base: f64) -> Result<(), crate::record::RecordError> {
        let state = self.state();
        self.maybe_diagnostics(Some(base + self.sim.time()), &state)
    }

    /// The diagnostics of the node in `state`, at simulation stamp `stamp` (None before the first sample).
    pub(super) fn diagnostics(&self, stamp: Option<f64>, state: &str) -> DiagnosticArray {
        let r = &self.report;
        diagnostics(
            &self.full_name,
            stamp,
            &r.pacing,
            &r.counters,
            self.sim.as_ref(),
            state,
            self.wall(),
        )
    }

    /// Publishes diagnostics if they are due (see [`DiagClock::due`]), and records them once they carry a
    /// simulation time.
    fn maybe_diagnostics(
        &mut self,
        stamp: Option<f64>,
        state: &str,
    ) -> Result<(), crate::record::RecordError> {
        let w = self.wall();
        let level = level_of(state, stamp.is_some(), &self.report.counters);
        if !self
            .report
            .last_diag
            .due(w, self.live.diagnostics_rate_hz, level)
        {
            return Ok(());
        }
        self.report.last_diag = DiagClock {
            wall: w,
            level: Some(level),
        };
        let d = self.diagnostics(stamp, state);
        if let Some(r) = self.recorder.as_mut() {
            if d.header.stamp.as_nanos() > 0 {
                r.write(&self.ends.diag_topic, d.header.stamp, &d)?;
            }
        }
        if let Err(e) = self.ends.out.diag.publish(d) {
            self.log(
                ros2_client::ros2::LogLevel::Error,
                &format!("publishing /diagnostics: {e:?}"),
            );
        }
        Ok(())
    }
}

/// The diagnostics' level for the node's `state` (before the simulation has a time: `timed` false).
fn level_of(state: &str, timed: bool, c: &Counters) -> u8 {
    if state == "running" && !c.input_check.starts_with("input check") {
        DiagnosticStatus::OK
    } else if state.starts_with("running")
        || !timed
        || state.starts_with("behind")
        || state.starts_with("paused")
        || state.starts_with("waiting")
    {
        DiagnosticStatus::WARN
    } else {
        // No motion input (holding the last pose), or the solver stopped.
        DiagnosticStatus::ERROR
    }
}

#[allow(clippy::too_many_arguments)]
fn diagnostics(
    name: &str,
    stamp: Option<f64>,
    pacing: &Pacing,
    c: &Counters,
    sim: &dyn sph::Solver,
    state: &str,
    wall: f64,
) -> DiagnosticArray {
    let (counts, stats) = (sim.counts(), sim.stats());
    let level = level_of(state, stamp.is_some(), c);
    let kv = |k: &str, v: String| KeyValue {
        key: k.to_string(),
        value: v,
    };
    let age = pacing
        .input_age(wall)
        .map(|a| format!("{a:.3}"))
        .unwrap_or_else(|| "none yet".into());
    DiagnosticArray {
        header: header(Time::from_secs_f64(stamp.unwrap_or(0.0)), ""),
        status: vec![DiagnosticStatus {
            level,
            name: format!("{}: sloshing simulation", name.trim_start_matches('/')),
            message: state.to_string(),
            hardware_id: "slosh".into(),
            values: vec![
                kv(
                    "realtime_factor",
                    format!("{:.3}", pacing.realtime_factor()),
                ),
                kv("particles", counts.fluid.to_string()),
                kv("particles_lost", counts.lost.to_string()),
                kv(
                    "scheme",
                    format!("{:?}", sim.params().solver.scheme).to_lowercase(),
                ),
                kv(
                    "particle_spacing",
                    sim.params().particle_spacing.to_string(),
                ),
                kv("auto_resolution", c.resolution.clone()),
                kv("time_step_s", format!("{:.6}", stats.last_dt)),
                kv("pressure_iterations", stats.last_iterations.to_string()),
                kv("density_error", format!("{:.2e}", stats.last_density_error)),
                kv("unconverged_steps", stats.unconverged_steps.to_string()),
                kv("retried_steps", stats.retried_steps.to_string()),
                kv("input_age_s", age),
                kv("samples_accepted", c.accepted.to_string()),
                kv("samples_rejected", c.rejected.to_string()),
                kv("last_rejection", c.last_reject.clone()),
                kv("input_timeouts", c.timeouts.to_string()),
                kv(
                    "input_check",
                    if c.input_check.is_empty() {
                        "pending".into()
                    } else {
                        c.input_check.clone()
                    },
                ),
                kv("overruns", pacing.overruns.to_string()),
                kv("outputs_published", c.published.to_string()),
            ],
        }],
    }
}

#[cfg(test)]
mod tests {
    use super::{Counters, DiagClock, Reminder};
    use slosh_msgs::diagnostic_msgs::DiagnosticStatus;

    #[test]
    fn diagnostics_come_at_their_rate_and_at_once_when_the_level_changes() {
        let last = DiagClock {
            wall: 10.0,
            level: Some(DiagnosticStatus::OK),
        };
        // At 10 Hz: not within 0.1 s at the same level, due after it.
        assert!(!last.due(10.05, 10.0, DiagnosticStatus::OK));
        assert!(last.due(10.11, 10.0, DiagnosticStatus::OK));
        // A change of level is due at once (an ERROR shorter than the period is not missed).
        assert!(last.due(10.01, 10.0, DiagnosticStatus::ERROR));
        assert!(last.due(10.01, 10.0, DiagnosticStatus::WARN));
    }

    #[test]
    fn a_node_rejecting_most_of_its_motion_says_so() {
        let mut c = Counters::default();
        // A few samples, or mostly accepted ones: running.
        for k in 0..4 {
            c.note_motion(k as f64 * 0.02, false);
        }
        assert_eq!(c.mostly_rejected(0.1), None);
        for k in 4..10 {
            c.note_motion(k as f64 * 0.02, true);
        }
        assert_eq!(c.mostly_rejected(0.2), None);
        // 15 of the last 21 rejected.
        c.last_reject = "pitch jumps".into();
        for k in 10..21 {
            c.note_motion(k as f64 * 0.02, false);
        }
        let s = c.mostly_rejected(0.42).unwrap();
        assert!(
            s.starts_with("running, but 15 of the last 21 motion samples were rejected")
                && s.ends_with("(last: pitch jumps)"),
            "{s}"
        );
        // Samples older than the window no longer count.
        assert_eq!(c.mostly_rejected(3.0), None);
    }

    #[test]
    fn a_reminder_comes_first_after_its_delay_then_every_ten_seconds() {
        let mut r = Reminder::default();
        let times: Vec<f64> = (0..300).map(|k| 1.0 + k as f64 * 0.1).collect();
        let said: Vec<f64> = times.into_iter().filter(|&t| r.due(t, 5.0)).collect();
        assert_eq!(said.len(), 3, "{said:?}");
        assert!(
            (said[0] - 6.0).abs() < 1e-9 && (said[1] - 16.0).abs() < 1e-9,
            "{said:?}"
        );
    }
}
