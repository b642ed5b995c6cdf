//! Where a drive loop's observations go: each output time's observation is handed to every sink (the CSV
//! files, a recording, ...), which writes it its own way. Particle frames, at their own rate, are not
//! observations: they go to a [`crate::snapshot::SnapshotWriter`].

use crate::output::CsvOutputs;
use crate::record::{RecordError, Recorder};
use sph::motion::TankMotion;
use sph::observe::Observation;

/// Why a sink could not take an observation.
#[derive(Debug, thiserror::Error)]
pub enum SinkError {
    #[error(transparent)]
    Io(#[from] std::io::Error),
    #[error(transparent)]
    Record(#[from] RecordError),
}

/// A destination of observations.
pub trait Sink {
    /// Takes the observation made at an output time; `motion` drove the tank up to it.
    fn observed(&mut self, o: &Observation, motion: &dyn TankMotion) -> Result<(), SinkError>;

    /// Writes out what is buffered (a drive loop calls it every few seconds of wall-clock time, so that a
    /// process killed hard loses little).
    fn flush(&mut self) -> Result<(), SinkError> {
        Ok(())
    }
}

impl Sink for CsvOutputs {
    fn observed(&mut self, o: &Observation, _: &dyn TankMotion) -> Result<(), SinkError> {
        Ok(self.write(o)?)
    }

    fn flush(&mut self) -> Result<(), SinkError> {
        Ok(CsvOutputs::flush(self)?)
    }
}

/// How one observed state is recorded: the outputs, and the motion that drove the tank up to it (which the
/// closure knows: a run's motion, or a replay's recorded messages).
pub type RecordState<'a> = dyn FnMut(&mut Recorder, &Observation) -> Result<(), RecordError> + 'a;

/// A recording as a sink: the recorder and how a state is recorded.
pub struct Recording<'a, 'r> {
    pub recorder: &'a mut Recorder,
    pub record: &'a mut RecordState<'r>,
}

impl Sink for Recording<'_, '_> {
    fn observed(&mut self, o: &Observation, _: &dyn TankMotion) -> Result<(), SinkError> {
        Ok((self.record)(self.recorder, o)?)
    }
}
