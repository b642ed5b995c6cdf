//! The fixed-layout (`#[repr(C)]`, no heap) payloads of slosh's iceoryx2 services (feature `iceoryx2`). Their `type_name`s are what a
//! peer in another language declares to open the same services. Units are SI; frames as named per field.

use iceoryx2::prelude::ZeroCopySend;

/// Probes and pressure sensors a fixed-layout output carries at most.
pub const MAX_SENSORS: usize = 32;

/// Length of the text of a [`StepOutputs::message`].
pub const MESSAGE_LEN: usize = 160;

/// One motion sample of the vessel: its full rigid state at `time`, at the vessel's reference point (the
/// node's `frames.tank_pose` places the tank on it). World frame: z up.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("slosh::MotionSample")]
pub struct MotionSample {
    /// The sender's time, s; strictly increasing from sample to sample.
    pub time: f64,
    /// Position in the world frame, m.
    pub position: [f64; 3],
    /// Orientation (world ← vessel) as a unit quaternion x, y, z, w.
    pub orientation: [f64; 4],
    /// Velocity in the world frame, m/s.
    pub velocity: [f64; 3],
    /// Angular velocity in the vessel frame, rad/s.
    pub angular_velocity: [f64; 3],
    /// Acceleration in the world frame (without gravity), m/s².
    pub acceleration: [f64; 3],
    /// Angular acceleration in the vessel frame, rad/s².
    pub angular_acceleration: [f64; 3],
}

/// [`StepOutputs::status`]: the state was simulated up to the sample's time.
pub const STATUS_OK: u32 = 0;
/// The sample was refused (not finite, not after the last one, not a unit quaternion): nothing was
/// simulated; `message` says which field and why.
pub const STATUS_REJECTED: u32 = 1;
/// The solver failed; `message` says why. The server stops.
pub const STATUS_FAILED: u32 = 2;

/// What the liquid does at a time: the answer to a coupling step and what the outputs service publishes.
#[derive(Debug, Clone, Copy, PartialEq, ZeroCopySend)]
#[repr(C)]
#[type_name("slosh::StepOutputs")]
pub struct StepOutputs {
    /// The sample time this state belongs to (the sender's time base), s.
    pub time: f64,
    /// Force of the liquid on the tank, tank frame, N.
    pub force: [f64; 3],
    /// Moment of the liquid on the tank about the tank origin, tank frame, N·m.
    pub moment: [f64; 3],
    /// Free-surface elevation above the tank bottom at each probe, m (NaN: dry); `probe_count` used.
    pub probes: [f64; MAX_SENSORS],
    /// Gauge pressure at each sensor, Pa; `pressure_count` used.
    pub pressures: [f64; MAX_SENSORS],
    /// Probes in `probes`.
    pub probe_count: u32,
    /// Sensors in `pressures`.
    pub pressure_count: u32,
    /// [`STATUS_OK`], [`STATUS_REJECTED`] or [`STATUS_FAILED`].
    pub status: u32,
    /// Solver steps taken for this sample.
    pub steps: u32,
    /// Why a sample was refused or the solver failed: UTF-8, zero-padded.
    pub message: [u8; MESSAGE_LEN],
}

impl Default for StepOutputs {
    fn default() -> Self {
        Self {
            time: 0.0,
            force: [0.0; 3],
            moment: [0.0; 3],
            probes: [0.0; MAX_SENSORS],
            pressures: [0.0; MAX_SENSORS],
            probe_count: 0,
            pressure_count: 0,
            status: STATUS_OK,
            steps: 0,
            message: [0; MESSAGE_LEN],
        }
    }
}

impl StepOutputs {
    /// The message as text.
    pub fn message(&self) -> String {
        let end = self
            .message
            .iter()
            .position(|&b| b == 0)
            .unwrap_or(MESSAGE_LEN);
        String::from_utf8_lossy(&self.message[..end]).into_owned()
    }

    /// Sets the message (cut to fit, at a character boundary).
    pub fn set_message(&mut self, text: &str) {
        self.message = [0; MESSAGE_LEN];
        let mut end = text.len().min(MESSAGE_LEN);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        self.message[..end].copy_from_slice(&text.as_bytes()[..end]);
    }

    /// The probes' elevations carried.
    pub fn probes(&self) -> &[f64] {
        &self.probes[..self.probe_count as usize]
    }

    /// The sensors' pressures carried.
    pub fn pressures(&self) -> &[f64] {
        &self.pressures[..self.pressure_count as usize]
    }
}

/// Header of a particle frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("slosh::ParticleHeader")]
pub struct ParticleHeader {
    /// The sample time of the state, s.
    pub time: f64,
    /// Liquid particles: the first `fluid` entries of the slice; the rest are boundary particles.
    pub fluid: u64,
    /// 2 or 3 (a 2D run has y = 0).
    pub dimension: u32,
    /// Padding to eight bytes (0).
    pub reserved: u32,
}

/// One particle, tank frame.
#[derive(Debug, Clone, Copy, PartialEq, Default, ZeroCopySend)]
#[repr(C)]
#[type_name("slosh::Particle")]
pub struct Particle {
    /// Position, m.
    pub position: [f32; 3],
    /// Velocity relative to the tank, m/s.
    pub velocity: [f32; 3],
    /// Gauge pressure, Pa.
    pub pressure: f32,
    /// Density, kg/m³.
    pub density: f32,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layouts_are_fixed_and_messages_round_trip() {
        assert_eq!(std::mem::size_of::<MotionSample>(), 8 * (1 + 3 + 4 + 3 * 4));
        assert_eq!(std::mem::size_of::<Particle>(), 32);
        assert_eq!(std::mem::size_of::<ParticleHeader>(), 24);
        assert_eq!(
            std::mem::size_of::<StepOutputs>(),
            8 * (1 + 6 + 2 * MAX_SENSORS) + 16 + MESSAGE_LEN
        );
        let mut o = StepOutputs::default();
        o.set_message("time: 0.5 s is not after the last sample's 0.6 s");
        assert_eq!(
            o.message(),
            "time: 0.5 s is not after the last sample's 0.6 s"
        );
        o.set_message(&"é".repeat(100));
        assert_eq!(o.message(), "é".repeat(80));
    }
}
