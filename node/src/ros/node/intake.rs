//! The motion intake: every sample received is accepted into the motion the solver follows, or refused
//! with its reason; both are recorded. The first accepted sample sets the time base (its stamp is
//! simulation time 0). A stamp far ahead of the newest (`input.max_gap_s`), one out of order, or a pose that
//! jumps is refused; ten samples in a row that follow each other on another time base (a restarted
//! publisher, a reset clock) are followed from the simulation's present, as after a pause; after a timeout
//! the input coming back is followed afresh when it does not continue the held pose.

use super::input::{writers_on_graph, Input, Sample};
use super::report::{buffered, no_input};
use super::LiveNode;
use crate::config::{RealtimeMode, StampSource};
use ros2_client::ros2::LogLevel;
use slosh_msgs::builtin_interfaces::Time;
use std::collections::VecDeque;

/// Samples in a row on a new time base after which the node follows it.
const NEW_TIME_BASE: usize = 10;

impl LiveNode<'_> {
    /// Takes what the reader holds into the pending samples (also between steps, so that the reader's short
    /// history never overflows while a long stretch is stepped).
    pub(super) fn drain_reader(&mut self) -> anyhow::Result<()> {
        let i = &mut self.intake;
        while let Some(taken) = self.ends.input.take(i.rec_topic.as_deref())? {
            match taken {
                Ok(t) => i
                    .pending
                    .push((t, self.report.start.elapsed().as_secs_f64(), unix_now())),
                Err(reason) => {
                    i.undecodable.push(reason);
                    break;
                }
            }
        }
        Ok(())
    }

    /// Takes the samples received: each accepted or refused, and the accelerations that go with them.
    /// Returns whether one was accepted.
    pub(super) fn take_input(&mut self) -> anyhow::Result<bool> {
        self.drain_reader()?;
        self.say_undecodable();
        let stamp = self.cfg.config.input.stamp;
        let mut incoming: VecDeque<Sample> = self
            .intake
            .pending
            .drain(..)
            .map(|((header, raw, reading), received, unix)| {
                let log = match stamp {
                    StampSource::Header => header,
                    StampSource::Receive => Time::from_secs_f64(unix),
                };
                Sample {
                    ts: log.as_secs_f64(),
                    log,
                    reading,
                    received,
                    raw,
                }
            })
            .collect();
        let mut got = false;
        while let Some(sample) = incoming.pop_front() {
            got |= self.take_sample(sample, &mut incoming)?;
        }
        self.take_accels();
        Ok(got)
    }

    /// Messages that could not be decoded: refused and said (once in 10 s), with what the graph shows (a
    /// publisher of another type on the topic).
    fn say_undecodable(&mut self) {
        let Some(reason) = self.intake.undecodable.last().cloned() else {
            return;
        };
        let n = self.intake.undecodable.len();
        self.intake.undecodable.clear();
        let c = &mut self.report.counters;
        c.rejected += n as u64;
        c.last_reject = format!("undecodable message: {reason}");
        if self.wall() - self.intake.last_undecodable <= 10.0 {
            return;
        }
        self.intake.last_undecodable = self.wall();
        let kind = self.cfg.config.input.kind;
        let in_topic = &self.ends.in_topic;
        let hint = crate::ros::graph_hint::hint(
            in_topic,
            Input::topic(kind),
            Input::type_name(kind),
            &writers_on_graph(&self.ends.context),
        )
        .unwrap_or_else(|| {
            format!(
                "is every publisher on it sending {}?",
                Input::type_name(kind)
            )
        });
        self.log(
            LogLevel::Warn,
            &format!(
                "refused {n} message(s) on {in_topic} that cannot be decoded as {} ({reason}): {hint}",
                Input::type_name(kind)
            ),
        );
    }

    /// Accepts or refuses one sample; samples to be taken again (a new time base) go back to `incoming`.
    /// Returns whether it was accepted.
    fn take_sample(
        &mut self,
        sample: Sample,
        incoming: &mut VecDeque<Sample>,
    ) -> anyhow::Result<bool> {
        let (ts, w) = (sample.ts, self.wall());
        let base = self.place(&sample);
        let max_gap = self.cfg.config.input.max_gap_s;
        let i = &mut self.intake;
        // A stamp far ahead of the newest sample (a garbled stamp, a clock set wrong) is refused: the solver
        // would take the whole gap as one smooth move, and every later sample as out of order. Not after a
        // timeout (holding the last pose): then a later stamp is the input coming back.
        let gap = i
            .newest_stamp
            .map(|n| ts - n)
            .filter(|g| *g > max_gap && !i.holding);
        let pushed = match gap {
            Some(g) => Err((
                format!(
                    "stamp {:.6} s is {g:.3} s after the newest sample's, more than input.max_gap_s = {max_gap}",
                    ts - base
                ),
                false,
            )),
            None => i
                .motion
                .push(ts - base, &sample.reading, &i.frames)
                .map_err(|e| (e.to_string(), e.against_newest())),
        };
        match pushed {
            Ok(()) => {
                self.accept(sample, base, w)?;
                return Ok(true);
            }
            // The input back after a timeout (a sample newer than its last accepted one) that does not
            // continue the held pose: its stamps behind the held ones (its clock stood still while it was
            // away, or runs behind the node's), or its pose too far from the held one for the time between
            // them (the vessel moved meanwhile; or every sample since the last accepted one was refused for
            // such a jump, which the timeout then ends). Held samples are the node's own, so it follows the
            // input at once, from the simulation's present, as after a pause.
            Err((e, true))
                if i.holding && gap.is_none() && i.newest_stamp.is_none_or(|n| ts > n) =>
            {
                self.follow_afresh(&e, ts - base, w);
                incoming.push_front(sample);
            }
            Err((e, _)) => self.refuse(sample, e, gap.is_some(), w, incoming)?,
        }
        Ok(false)
    }

    /// The time base of `sample`: the first sample's stamp, or after a rebase the stamp that places it at
    /// the current simulation time.
    fn place(&mut self, sample: &Sample) -> f64 {
        let i = &mut self.intake;
        if std::mem::take(&mut i.rebase) {
            let new_t0 = sample.ts - self.sim.time();
            // Input on an earlier time base: the recording's log times go on from where they were.
            if let (Some(old), Some(r)) = (i.t0, self.recorder.as_mut()) {
                if new_t0 < old {
                    r.continue_from(sample.log);
                }
            }
            i.t0 = Some(new_t0);
        }
        *i.t0.get_or_insert(sample.ts)
    }

    /// A sample taken into the motion: recorded (with the samples set aside as another time base, which it
    /// was not), counted, and the input's age reset.
    fn accept(&mut self, sample: Sample, base: f64, w: f64) -> anyhow::Result<()> {
        let i = &mut self.intake;
        if let Some(r) = self.recorder.as_mut() {
            for m in &sample.raw {
                r.write_message(m, sample.log)?;
            }
            for s in i.other_base.drain(..) {
                s.record_refused(r)?;
            }
        }
        i.other_base.clear();
        i.newest_stamp = Some(sample.ts);
        i.last_real = sample.ts - base;
        let c = &mut self.report.counters;
        c.accepted += 1;
        c.rejected_in_a_row = 0;
        c.note_motion(w, true);
        self.report.pacing.input(sample.received);
        if std::mem::take(&mut self.intake.holding) {
            self.log(LogLevel::Info, "motion input is back");
        }
        Ok(())
    }

    /// The input back after a timeout but not continuing the held pose (`why`; the sample at `t` on the
    /// old time base): the motion starts afresh from the simulation's present.
    fn follow_afresh(&mut self, why: &str, t: f64, w: f64) {
        let behind = self.intake.motion.newest().unwrap_or(t) - t;
        self.log(
            LogLevel::Warn,
            &format!(
                "motion input is back after {:.2} s without a usable sample, but it does not continue the held pose ({}): following it afresh from t = {:.4} s",
                self.report.pacing.input_age(w).unwrap_or(0.0),
                if behind >= 0.0 {
                    format!("its stamps are {behind:.3} s behind the held pose's")
                } else {
                    why.to_string()
                },
                self.sim.time()
            ),
        );
        self.intake.motion = self.fresh_motion();
        let i = &mut self.intake;
        i.holding = false;
        i.rebase = true;
        i.newest_stamp = None;
    }

    /// A refused sample: counted, said (once a second), and recorded, unless it may start a new time base
    /// (`off`: its stamp is past the gap or not after the newest), where it is set aside with the samples
    /// that follow it.
    fn refuse(
        &mut self,
        sample: Sample,
        e: String,
        gapped: bool,
        w: f64,
        incoming: &mut VecDeque<Sample>,
    ) -> anyhow::Result<()> {
        let c = &mut self.report.counters;
        c.rejected += 1;
        c.rejected_in_a_row += 1;
        c.note_motion(w, false);
        c.last_reject = e.clone();
        if w - self.report.last_reject_warn > 1.0 {
            self.report.last_reject_warn = w;
            self.warn_refused(&e, sample.ts);
        }
        let max_gap = self.cfg.config.input.max_gap_s;
        let i = &mut self.intake;
        let off = gapped || i.newest_stamp.is_some_and(|n| sample.ts <= n);
        let follows = i
            .other_base
            .last()
            .is_none_or(|p| sample.ts > p.ts && sample.ts - p.ts <= max_gap);
        // Refused samples are recorded once refused for good, at the recording's latest log time (their
        // own stamps may lie an hour ahead or on another time base).
        if !off || !follows {
            if let Some(r) = self.recorder.as_mut() {
                for s in i.other_base.drain(..) {
                    s.record_refused(r)?;
                }
            }
            i.other_base.clear();
        }
        if !off {
            if let Some(r) = self.recorder.as_mut() {
                sample.record_refused(r)?;
            }
            return Ok(());
        }
        i.other_base.push(sample);
        if i.other_base.len() >= NEW_TIME_BASE {
            self.follow_new_time_base(incoming);
        }
        Ok(())
    }

    /// The warning for a refused sample (`e`, its stamp `ts`).
    fn warn_refused(&self, e: &str, ts: f64) {
        let zero = self.cfg.config.input.stamp == StampSource::Header && ts == 0.0;
        self.log(
            LogLevel::Warn,
            &format!(
                "rejected a motion sample: {e}{}{} ({} rejected so far)",
                // (The stamps in the reasons count from the first sample.)
                if e.starts_with("stamp ") {
                    format!(" (times since the first sample; its stamp is {ts:.6} s)")
                } else {
                    String::new()
                },
                if zero {
                    ": the messages' header stamps are zero (never set?): stamp them, or set input.stamp: receive"
                } else {
                    ""
                },
                self.report.counters.rejected
            ),
        );
    }

    /// [`NEW_TIME_BASE`] samples in a row follow each other as a motion would on another time base: the
    /// input follows them from the simulation's present, and they are taken again (not refused after all).
    fn follow_new_time_base(&mut self, incoming: &mut VecDeque<Sample>) {
        let i = &self.intake;
        let jump = i.other_base[0].ts - i.newest_stamp.unwrap_or(i.other_base[0].ts);
        self.log(
            LogLevel::Warn,
            &format!(
                "the motion input's stamps jumped by {jump:.3} s and {NEW_TIME_BASE} samples in a row follow the new stamps: following them from t = {:.4} s (a restarted publisher or a reset clock)",
                self.sim.time()
            ),
        );
        self.intake.motion = self.fresh_motion();
        let i = &mut self.intake;
        i.rebase = true;
        i.newest_stamp = None;
        // Counted again as they are taken.
        self.report.counters.rejected -= i.other_base.len() as u64;
        for item in i.other_base.drain(..).rev() {
            incoming.push_front(item);
        }
    }

    /// The accelerations (`motion/accel`) received, once the time base is known.
    fn take_accels(&mut self) {
        let (Some(sa), Some(base)) = (&self.ends.sub_accel, self.intake.t0) else {
            return;
        };
        let max_gap = self.cfg.config.input.max_gap_s;
        while let Ok(Some((m, _))) = sa.take() {
            let stamp = m.header.stamp.as_secs_f64();
            let t = stamp - base;
            // Accelerations stamped on another clock than the motion would never cover the times the
            // solver asks for: they would be kept and silently never used.
            let i = &mut self.intake;
            let off = i
                .motion
                .newest()
                .map(|n| t - n)
                .filter(|d| d.abs() > max_gap);
            let pushed = match off {
                Some(d) => Err(format!(
                    "stamp {stamp:.6} s is {d:.3} s from the newest motion sample's (more than input.max_gap_s = {max_gap}): AccelStamped must carry the motion's time stamps"
                )),
                None => i
                    .motion
                    .push_accel(t, &m.accel.linear, &m.accel.angular, &i.frames)
                    .map_err(|e| e.to_string()),
            };
            if let Err(e) = pushed {
                let c = &mut self.report.counters;
                c.rejected += 1;
                c.last_reject = format!("motion/accel: {e}");
                let w = self.wall();
                if w - self.report.last_reject_warn > 1.0 {
                    self.report.last_reject_warn = w;
                    let msg = format!(
                        "rejected an acceleration sample: {e} ({} rejected so far)",
                        self.report.counters.rejected
                    );
                    self.log(LogLevel::Warn, &msg);
                }
            }
        }
    }

    /// No input for `motion_timeout_s` in real-time mode: holds the last pose, at rest, and says so. Held
    /// samples follow the wall clock from the last real one, at most 100 per second. Returns whether one
    /// was added.
    pub(super) fn hold_if_silent(&mut self) -> bool {
        if self.cfg.config.realtime.mode != RealtimeMode::Realtime {
            return false;
        }
        let timeout = self.live.motion_timeout_s;
        let (Some(age), Some(newest)) = (
            self.report.pacing.input_age(self.wall()),
            self.intake.motion.newest(),
        ) else {
            return false;
        };
        if age <= timeout {
            return false;
        }
        if !self.intake.holding {
            self.intake.holding = true;
            self.report.counters.timeouts += 1;
            let msg = format!(
                "{}: holding the last pose{}",
                no_input(&self.report.counters, age, timeout),
                buffered(self.intake.last_real, self.sim.time())
            );
            self.log(LogLevel::Error, &msg);
        }
        let t_hold = self.intake.last_real + age;
        t_hold > newest + 0.01 && self.intake.motion.hold(t_hold)
    }
}

/// The Unix time (the stamp of `input.stamp: receive`).
fn unix_now() -> f64 {
    std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map(|d| d.as_secs_f64())
        .unwrap_or(0.0)
}
