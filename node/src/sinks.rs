//! Where a drive loop's outputs go. Each output time's state ([`Output`]: the observation, its messages and
//! its stamp) is handed to every [`Sink`] (the CSV files, a recording, the node's DDS publishers, its
//! iceoryx2 port), which sends or writes it its own way; particle frames, at their own rate, go to every
//! [`FrameSink`] (ParaView files, the node's point clouds). The loop that produces them is
//! [`crate::drive`], which stamps them on its [`TimeBase`].

use crate::messages::{output_messages, OutputMessages};
use crate::output::CsvOutputs;
use crate::record::{RecordError, Recorder};
use slosh_msgs::builtin_interfaces::Time;
use sph::motion::TankMotion;
use sph::observe::Observation;
use sph::params::SimParams;
use sph::Solver;
use std::cell::OnceCell;

/// Why a sink could not take an output.
#[derive(Debug, thiserror::Error)]
pub enum SinkError {
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error(transparent)]
    Record(#[from] RecordError),
    /// A transport (DDS, iceoryx2) refused a message.
    #[error("{0}")]
    Send(String),
}

impl From<anyhow::Error> for SinkError {
    fn from(e: anyhow::Error) -> Self {
        SinkError::Send(format!("{e:#}"))
    }
}

/// How a state's simulation time t becomes its stamp: the time base's start plus t.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum TimeBase {
    /// In seconds (an offline run: 0; the live node: the first input sample's stamp).
    Seconds(f64),
    /// In nanoseconds (a replay: the bag's first motion stamp), t rounded to the nanosecond.
    Nanos(i64),
}

impl TimeBase {
    pub fn stamp(&self, t: f64) -> Time {
        match *self {
            TimeBase::Seconds(base) => Time::from_secs_f64(base + t),
            TimeBase::Nanos(base) => Time::from_nanos(base + (t * 1e9).round() as i64),
        }
    }

    /// The stamp in seconds (as the iceoryx2 outputs carry it).
    pub fn seconds(&self, t: f64) -> f64 {
        match *self {
            TimeBase::Seconds(base) => base + t,
            TimeBase::Nanos(_) => self.stamp(t).as_secs_f64(),
        }
    }
}

/// One output time's state, as every sink gets it.
pub struct Output<'a> {
    pub observation: &'a Observation,
    /// The state's time on the driver's time base, and the same in seconds.
    pub stamp: Time,
    pub seconds: f64,
    /// The motion that drove the tank up to the state.
    pub motion: &'a dyn TankMotion,
    /// Solver steps since the previous output.
    pub steps: u64,
    /// What the messages name: the case (its probes and sensors) and the tank's frame.
    names: (&'a SimParams, &'a str),
    /// The messages, built by the first sink that asks.
    messages: OnceCell<OutputMessages>,
}

impl<'a> Output<'a> {
    /// The state `observation`, stamped `stamp` (`seconds` in seconds), reached under `motion` in `steps`
    /// solver steps since the previous output; its messages name the sensors of `params` and `tank_frame`.
    pub fn new(
        observation: &'a Observation,
        (stamp, seconds): (Time, f64),
        motion: &'a dyn TankMotion,
        steps: u64,
        (params, tank_frame): (&'a SimParams, &'a str),
    ) -> Self {
        Self {
            observation,
            stamp,
            seconds,
            motion,
            steps,
            names: (params, tank_frame),
            messages: OnceCell::new(),
        }
    }

    /// The observation as messages (wrench, probes, pressures, the bodies'), stamped: built once, when
    /// a sink first asks (a driver whose sinks all take the observation builds none).
    pub fn messages(&self) -> &OutputMessages {
        self.messages.get_or_init(|| {
            output_messages(self.names.0, self.names.1, self.stamp, self.observation)
        })
    }
}

/// A destination of outputs.
pub trait Sink {
    /// Takes the state of an output time.
    fn observed(&mut self, out: &Output) -> Result<(), SinkError>;

    /// Writes out what is buffered (a drive loop calls it every few seconds of wall-clock time, so that a
    /// process killed hard loses little).
    fn flush(&mut self) -> Result<(), SinkError> {
        Ok(())
    }
}

/// A destination of particle frames.
pub trait FrameSink {
    /// Takes the solver's state at a frame time; `base` stamps it.
    fn frame(
        &mut self,
        sim: &dyn Solver,
        motion: &dyn TankMotion,
        base: TimeBase,
    ) -> Result<(), SinkError>;
}

/// A sink lent for one output.
impl<S: Sink + ?Sized> Sink for &mut S {
    fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
        (**self).observed(out)
    }

    fn flush(&mut self) -> Result<(), SinkError> {
        (**self).flush()
    }
}

/// A sink that may be absent (a file or transport not asked for): takes nothing when it is.
impl<S: Sink> Sink for Option<S> {
    fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
        self.as_mut().map_or(Ok(()), |s| s.observed(out))
    }

    fn flush(&mut self) -> Result<(), SinkError> {
        self.as_mut().map_or(Ok(()), |s| s.flush())
    }
}

impl Sink for CsvOutputs {
    fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
        Ok(self.write(out.observation)?)
    }

    fn flush(&mut self) -> Result<(), SinkError> {
        Ok(CsvOutputs::flush(self)?)
    }
}

impl FrameSink for crate::snapshot::SnapshotWriter {
    fn frame(
        &mut self,
        sim: &dyn Solver,
        motion: &dyn TankMotion,
        _: TimeBase,
    ) -> Result<(), SinkError> {
        Ok(self.send(sim.snapshot(), motion.state(sim.time()))?)
    }
}

/// How one output is recorded: its messages, and what else the recording keeps beside them (a run's
/// motion, a replay's recorded messages up to the output's stamp).
pub type RecordState<'a> = dyn FnMut(&mut Recorder, &Output) -> Result<(), RecordError> + 'a;

/// A recording as a sink: the recorder and how an output is recorded.
pub struct Recording<'a, 'r> {
    pub recorder: &'a mut Recorder,
    pub record: &'a mut RecordState<'r>,
}

impl Sink for Recording<'_, '_> {
    fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
        Ok((self.record)(self.recorder, out)?)
    }
}
