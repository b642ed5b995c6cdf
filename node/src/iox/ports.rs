//! The publish–subscribe services both servers offer (`slosh couple` and `slosh node` with `iceoryx2`
//! enabled): their settings, opened or created alike on every side, and the publishing half.

use super::*;
use iceoryx2::port::publisher::Publisher;
use iceoryx2::port::subscriber::Subscriber;
use sph::observe::snapshot::Snapshot;
use sph::observe::Observation;

/// Motion samples a subscriber keeps before the oldest is overwritten (at 1 kHz: one second).
pub const MOTION_BUFFER: usize = 1024;
/// Outputs a subscriber keeps before the oldest is overwritten.
pub const OUTPUTS_BUFFER: usize = 64;

type PubSub<T> =
    iceoryx2::service::port_factory::publish_subscribe::PortFactory<ipc::Service, T, ()>;
type ParticleService = iceoryx2::service::port_factory::publish_subscribe::PortFactory<
    ipc::Service,
    [Particle],
    ParticleHeader,
>;

/// `NAME/motion`: [`MotionSample`]s into `slosh node` (`input.type: iceoryx2`).
pub fn motion_service(
    node: &Node<ipc::Service>,
    prefix: &str,
) -> anyhow::Result<PubSub<MotionSample>> {
    Ok(node
        .service_builder(&service_name(&format!("{prefix}/motion"))?)
        .publish_subscribe::<MotionSample>()
        .history_size(0)
        .subscriber_max_buffer_size(MOTION_BUFFER)
        .open_or_create()?)
}

/// `NAME/outputs`: the [`StepOutputs`] of every output (node) or answered step (couple).
pub fn outputs_service(
    node: &Node<ipc::Service>,
    prefix: &str,
) -> anyhow::Result<PubSub<StepOutputs>> {
    Ok(node
        .service_builder(&service_name(&format!("{prefix}/outputs"))?)
        .publish_subscribe::<StepOutputs>()
        .history_size(1)
        .subscriber_max_buffer_size(OUTPUTS_BUFFER)
        .open_or_create()?)
}

/// `NAME/particles`: particle frames, a [`ParticleHeader`] and one [`Particle`] per particle.
pub fn particles_service(
    node: &Node<ipc::Service>,
    prefix: &str,
) -> anyhow::Result<ParticleService> {
    Ok(node
        .service_builder(&service_name(&format!("{prefix}/particles"))?)
        .publish_subscribe::<[Particle]>()
        .user_header::<ParticleHeader>()
        .subscriber_max_buffer_size(2)
        .open_or_create()?)
}

/// A subscriber of `NAME/motion`.
pub fn motion_subscriber(
    node: &Node<ipc::Service>,
    prefix: &str,
) -> anyhow::Result<Subscriber<ipc::Service, MotionSample, ()>> {
    Ok(motion_service(node, prefix)?
        .subscriber_builder()
        .create()?)
}

/// The outputs of an observation at the sender's `time`.
pub fn outputs_of(time: f64, o: &Observation) -> StepOutputs {
    let mut s = StepOutputs {
        time,
        force: o.wrench.force,
        moment: o.wrench.moment,
        probe_count: o.probes.len().min(MAX_SENSORS) as u32,
        pressure_count: o.pressures.len().min(MAX_SENSORS) as u32,
        ..Default::default()
    };
    s.probes[..s.probe_count as usize].copy_from_slice(&o.probes[..s.probe_count as usize]);
    s.pressures[..s.pressure_count as usize]
        .copy_from_slice(&o.pressures[..s.pressure_count as usize]);
    s
}

/// Refuses a case whose sensors do not fit [`StepOutputs`].
pub fn check_sensors(source: &str, probes: usize, pressures: usize) -> anyhow::Result<()> {
    for (what, n) in [("probes", probes), ("pressure_sensors", pressures)] {
        if n > MAX_SENSORS {
            anyhow::bail!(
                "{source}: {what}: {n} configured, the iceoryx2 outputs carry at most {MAX_SENSORS}"
            );
        }
    }
    Ok(())
}

/// The publishing half: outputs, and particle frames when asked for.
pub struct OutputPorts {
    outputs: Publisher<ipc::Service, StepOutputs, ()>,
    particles: Option<Publisher<ipc::Service, [Particle], ParticleHeader>>,
    /// Particle frames sent.
    pub frames: u64,
}

impl OutputPorts {
    /// Opens the services under `prefix`; `particles`: the particle count of a frame, None for no frames.
    pub fn new(
        node: &Node<ipc::Service>,
        prefix: &str,
        particles: Option<usize>,
    ) -> anyhow::Result<Self> {
        let outputs = outputs_service(node, prefix)?
            .publisher_builder()
            .create()?;
        let particles = match particles {
            Some(n) => Some(
                particles_service(node, prefix)?
                    .publisher_builder()
                    .initial_max_slice_len(n.max(1))
                    .allocation_strategy(AllocationStrategy::PowerOfTwo)
                    .create()?,
            ),
            None => None,
        };
        Ok(Self {
            outputs,
            particles,
            frames: 0,
        })
    }

    pub fn publish(&self, o: &StepOutputs) -> anyhow::Result<()> {
        self.outputs
            .send_copy(*o)
            .map_err(|e| anyhow::anyhow!("publishing the iceoryx2 outputs: {e}"))?;
        Ok(())
    }

    /// Publishes a particle frame (written straight into shared memory) at the sender's `time`; nothing
    /// without a particles publisher.
    pub fn publish_particles(&mut self, time: f64, snap: &Snapshot) -> anyhow::Result<()> {
        let Some(p) = &self.particles else {
            return Ok(());
        };
        let mut sample = p
            .loan_slice_uninit(snap.len())
            .map_err(|e| anyhow::anyhow!("loaning an iceoryx2 particle frame: {e}"))?;
        *sample.user_header_mut() = ParticleHeader {
            time,
            fluid: snap.fluid as u64,
            dimension: snap.dimension as u32,
            reserved: 0,
        };
        let sample = sample.write_from_fn(|i| Particle {
            position: snap.position[i],
            velocity: snap.velocity[i],
            pressure: snap.pressure[i],
            density: snap.density[i],
        });
        sample
            .send()
            .map_err(|e| anyhow::anyhow!("publishing an iceoryx2 particle frame: {e}"))?;
        self.frames += 1;
        Ok(())
    }
}

/// A drive loop's output as [`StepOutputs`]: at its stamp in seconds, with the solver steps since the
/// previous output.
pub fn outputs_at(out: &crate::sinks::Output) -> StepOutputs {
    let mut o = outputs_of(out.seconds, out.observation);
    o.steps = out.steps as u32;
    o
}

/// The outputs over iceoryx2.
impl crate::sinks::Sink for OutputPorts {
    fn observed(&mut self, out: &crate::sinks::Output) -> Result<(), crate::sinks::SinkError> {
        Ok(self.publish(&outputs_at(out))?)
    }
}

/// Particle frames over iceoryx2.
impl crate::sinks::FrameSink for OutputPorts {
    fn frame(
        &mut self,
        sim: &dyn sph::Solver,
        _: &dyn sph::motion::TankMotion,
        base: crate::sinks::TimeBase,
    ) -> Result<(), crate::sinks::SinkError> {
        Ok(self.publish_particles(base.seconds(sim.time()), &sim.snapshot())?)
    }
}
