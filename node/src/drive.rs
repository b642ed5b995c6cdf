//! The drive loop's core, shared by the offline runs (`slosh run`, `slosh replay`: [`crate::runner`]) and
//! the live node (`slosh node`: [`crate::ros`]): the solver's steps land on the output times, a grid k / rate
//! from t = 0, and at each the observed state goes, stamped on the driver's time base, to every
//! [`Sink`]; particle frames go to every [`FrameSink`] on a grid of their own. The drivers differ only in
//! their motion (a configured law, a bag, the live input), their pacing (as fast as possible, at a rate,
//! as the input comes) and their sinks.

use crate::sinks::{FrameSink, Output, Sink, SinkError, TimeBase};
use slosh_msgs::builtin_interfaces::Time;
use sph::motion::TankMotion;
use sph::observe::Observation;
use sph::params::SimParams;
use sph::{SimError, Solver};

/// Times k / rate, k = 0, 1, ...: the next one due and the rate. A rate of 0 is off (never due).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Grid {
    rate: f64,
    next: u64,
}

impl Grid {
    /// The grid of `rate` per simulated second, t = 0 due first.
    pub fn new(rate: f64) -> Self {
        Self { rate, next: 0 }
    }

    /// The next time on the grid.
    pub fn time(&self) -> f64 {
        self.next as f64 / self.rate
    }

    /// Whether `t` has reached the next time on the grid.
    pub fn due(&self, t: f64) -> bool {
        self.rate > 0.0 && t >= self.time() - 1e-9
    }

    /// The next time is the first on the grid after `t`.
    pub fn pass(&mut self, t: f64) {
        self.next = (t * self.rate + 1e-9).floor() as u64 + 1;
    }

    /// Whether nothing was due yet (t = 0 is next).
    pub fn at_start(&self) -> bool {
        self.next == 0
    }

    /// From t = 0 again (a reset).
    pub fn restart(&mut self) {
        self.next = 0;
    }

    /// A new rate from `t` on: the next time is the new grid's first after `t` (0: off).
    pub fn set_rate(&mut self, rate: f64, t: f64) {
        self.rate = rate;
        if rate > 0.0 {
            self.pass(t);
        }
    }
}

/// Why an output time's state did not reach the sinks.
#[derive(Debug, thiserror::Error)]
pub enum DriveError {
    #[error(transparent)]
    Solver(#[from] SimError),
    #[error(transparent)]
    Sink(#[from] SinkError),
}

/// How observed states reach the sinks: what their messages name (the probes and sensors of the case, the
/// tank's frame) and the solver's step count at the last one.
pub struct Delivery {
    params: SimParams,
    tank_frame: String,
    steps_then: u64,
}

impl Delivery {
    pub fn new(params: &SimParams, tank_frame: &str) -> Self {
        Self {
            params: params.clone(),
            tank_frame: tank_frame.to_string(),
            steps_then: 0,
        }
    }

    /// Hands `observation`, reached under `motion` and stamped `(stamp, seconds)`, to every sink in order;
    /// `steps`: the solver's step count now (each output carries those since the previous one).
    pub fn hand_out(
        &mut self,
        observation: &Observation,
        motion: &dyn TankMotion,
        stamp: (Time, f64),
        steps: u64,
        sinks: &mut [&mut dyn Sink],
    ) -> Result<(), SinkError> {
        let names = (&self.params, self.tank_frame.as_str());
        let out = Output::new(observation, stamp, motion, steps - self.steps_then, names);
        for s in sinks.iter_mut() {
            s.observed(&out)?;
        }
        self.steps_then = steps;
        Ok(())
    }

    /// Steps counted from 0 again (a fresh solver).
    pub fn restart(&mut self) {
        self.steps_then = 0;
    }
}

/// A drive loop's outputs: their times, and how they reach the sinks.
pub struct Outputs {
    pub times: Grid,
    delivery: Delivery,
}

impl Outputs {
    pub fn new(rate: f64, params: &SimParams, tank_frame: &str) -> Self {
        Self {
            times: Grid::new(rate),
            delivery: Delivery::new(params, tank_frame),
        }
    }

    /// One step: to the next output time at most (so outputs come at exactly k / rate, whatever the step)
    /// and not past `end`.
    pub fn step(
        &self,
        sim: &mut dyn Solver,
        motion: &dyn TankMotion,
        end: f64,
    ) -> Result<(), SimError> {
        sim.step_to(motion, self.times.time().min(end)).map(|_| ())
    }

    /// At an output time: observes the state and hands it, stamped on `base`, to every sink, in order.
    /// Returns whether an output was due.
    pub fn deliver(
        &mut self,
        sim: &mut dyn Solver,
        motion: &dyn TankMotion,
        base: TimeBase,
        sinks: &mut [&mut dyn Sink],
    ) -> Result<bool, DriveError> {
        let t = sim.time();
        if !self.times.due(t) {
            return Ok(false);
        }
        let observation = sim.observe(motion)?;
        let stamp = (base.stamp(observation.time), base.seconds(observation.time));
        let steps = sim.stats().steps;
        self.delivery
            .hand_out(&observation, motion, stamp, steps, sinks)?;
        self.times.pass(t);
        Ok(true)
    }

    /// From t = 0 again, with a fresh solver (a reset).
    pub fn restart(&mut self) {
        self.times.restart();
        self.delivery.restart();
    }
}

/// At a frame time on `times`: hands the solver's state, stamped on `base`, to every frame sink. Returns
/// whether a frame was due.
pub fn deliver_frame(
    times: &mut Grid,
    sim: &dyn Solver,
    motion: &dyn TankMotion,
    base: TimeBase,
    sinks: &mut [&mut dyn FrameSink],
) -> Result<bool, SinkError> {
    let t = sim.time();
    if !times.due(t) {
        return Ok(false);
    }
    for s in sinks.iter_mut() {
        s.frame(sim, motion, base)?;
    }
    times.pass(t);
    Ok(true)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_grid_is_due_at_its_times_and_passes_to_the_next() {
        let mut g = Grid::new(50.0);
        assert!(g.at_start() && g.due(0.0));
        g.pass(0.0);
        assert!(!g.due(0.019) && g.due(0.02 - 1e-12));
        // A state past several grid times is due once; the next time is the first after it.
        g.pass(0.071);
        assert_eq!(g.time(), 0.08);
        g.set_rate(10.0, 0.071);
        assert_eq!(g.time(), 0.1);
        g.set_rate(0.0, 0.1);
        assert!(!g.due(1e9));
        g.restart();
        assert!(g.at_start());
    }

    /// Keeps the time, stamp and step count of each output it gets, in a log shared with other sinks.
    struct Log<'a>(
        &'a std::cell::RefCell<Vec<(&'static str, f64, Time, u64)>>,
        &'static str,
    );

    impl Sink for Log<'_> {
        fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
            let entry = (self.1, out.observation.time, out.stamp, out.steps);
            self.0.borrow_mut().push(entry);
            Ok(())
        }
    }

    #[test]
    fn outputs_land_on_their_grid_and_reach_every_sink_in_order() {
        let params = sph::sloshing::experiment::seed_tank(2, 0.1, 0.02);
        let motion = sph::motion::AtRest;
        let mut sim = sph::build(params.clone()).unwrap();
        let mut outputs = Outputs::new(50.0, &params, "tank");
        let log = std::cell::RefCell::new(Vec::new());
        let (mut a, mut b) = (Log(&log, "a"), Log(&log, "b"));
        let base = TimeBase::Seconds(100.0);
        let run = |sim: &mut dyn Solver, outputs: &mut Outputs, a: &mut Log, b: &mut Log| {
            while sim.time() < 0.06 - 1e-9 {
                assert!(!outputs.deliver(sim, &motion, base, &mut []).unwrap());
                outputs.step(sim, &motion, 0.06).unwrap();
                outputs.deliver(sim, &motion, base, &mut [a, b]).unwrap();
            }
        };
        assert!(outputs
            .deliver(sim.as_mut(), &motion, base, &mut [&mut a, &mut b])
            .unwrap());
        run(sim.as_mut(), &mut outputs, &mut a, &mut b);
        let got = log.take();
        let times: Vec<f64> = got.iter().step_by(2).map(|e| e.1).collect();
        assert_eq!(times, [0.0, 0.02, 0.04, 0.06]);
        for pair in got.chunks(2) {
            assert_eq!((pair[0].0, pair[1].0), ("a", "b"));
            assert_eq!(pair[0].2, Time::from_secs_f64(100.0 + pair[0].1));
        }
        // Each output's steps are those since the previous one; they add up to the solver's.
        let steps: u64 = got.iter().step_by(2).map(|e| e.3).sum();
        assert_eq!((got[0].3, steps), (0, sim.stats().steps));
        assert!(got[2..].iter().all(|e| e.3 > 0));
        // A reset: a fresh solver, outputs from t = 0 again, steps counted afresh.
        let mut sim = sph::build(params).unwrap();
        outputs.restart();
        assert!(outputs
            .deliver(sim.as_mut(), &motion, base, &mut [&mut a])
            .unwrap());
        loop {
            outputs.step(sim.as_mut(), &motion, 1.0).unwrap();
            if outputs
                .deliver(sim.as_mut(), &motion, base, &mut [&mut a])
                .unwrap()
            {
                break;
            }
        }
        let got = log.take();
        assert_eq!(
            got.iter().map(|e| (e.1, e.3)).collect::<Vec<_>>()[..1],
            [(0.0, 0)]
        );
        assert_eq!(got[1].3, sim.stats().steps);
    }

    #[test]
    fn time_bases_stamp_as_their_drivers_did() {
        let t = 0.123_456_789_4;
        assert_eq!(TimeBase::Seconds(0.0).stamp(t), Time::from_secs_f64(t));
        assert_eq!(
            TimeBase::Seconds(1.7e9).stamp(t),
            Time::from_secs_f64(1.7e9 + t)
        );
        let base = 1_700_000_000_000_000_123;
        assert_eq!(
            TimeBase::Nanos(base).stamp(t).as_nanos(),
            base + 123_456_789
        );
    }
}
