//! The node's sinks: what each output time's state and each particle frame become on the node's
//! transports (DDS, the recording; iceoryx2's are `crate::iox`'s), in the order the node sends them.

use super::{LiveNode, Publishers};
use crate::drive::deliver_frame;
use crate::record::Recorder;
use crate::ros::publish;
use crate::sinks::{FrameSink, Output, Sink, SinkError, TimeBase};
use ros2_client::Publisher;
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::rosgraph_msgs::Clock;
use slosh_msgs::sensor_msgs::PointCloud2;
use sph::motion::TankMotion;
use sph::Solver;

/// The outputs recorded on the node's (resolved) output topics.
struct Recorded<'a> {
    recorder: &'a mut Recorder,
    topics: &'a [String; 3],
}

impl Sink for Recorded<'_> {
    fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
        Ok(self
            .recorder
            .write_outputs(self.topics, out.stamp, out.messages())?)
    }
}

/// The outputs over DDS: the liquid's (unless iceoryx2 alone carries them) and each floating body's.
impl Sink for &Publishers {
    fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
        let m = out.messages();
        if let Some((pw, pp, ps)) = &self.liquid {
            publish(pw, m.wrench.clone(), "wrench")?;
            publish(pp, m.probes.clone(), "probes")?;
            publish(ps, m.pressures.clone(), "pressures")?;
        }
        for (b, (po, pw)) in m.bodies.iter().zip(&self.bodies) {
            publish(po, b.odom.clone(), "body odom")?;
            publish(pw, b.wrench.clone(), "body wrench")?;
        }
        Ok(())
    }
}

/// `/clock` in lockstep mode: each output's stamp.
struct Lockstep<'a> {
    publisher: &'a Publisher<Clock>,
    /// The stamp last published.
    last: &'a mut Option<Time>,
}

impl Sink for Lockstep<'_> {
    fn observed(&mut self, out: &Output) -> Result<(), SinkError> {
        publish(self.publisher, Clock { clock: out.stamp }, "/clock")?;
        *self.last = Some(out.stamp);
        Ok(())
    }
}

/// The liquid as a point cloud, published and recorded.
struct Clouds<'a> {
    publisher: Option<&'a Publisher<PointCloud2>>,
    recorder: Option<(&'a mut Recorder, &'a str)>,
    frame: &'a str,
    decimation: usize,
}

impl FrameSink for Clouds<'_> {
    fn frame(
        &mut self,
        sim: &dyn Solver,
        _: &dyn TankMotion,
        base: TimeBase,
    ) -> Result<(), SinkError> {
        if self.publisher.is_none() && self.recorder.is_none() {
            return Ok(());
        }
        let stamp = base.stamp(sim.time());
        let cloud = crate::ros::cloud::particle_cloud(
            stamp,
            self.frame,
            &sim.fluid_positions(),
            &sim.fluid_velocities(),
            self.decimation,
        );
        if let Some((r, topic)) = self.recorder.as_mut() {
            r.write(topic, stamp, &cloud)?;
        }
        if let Some(p) = self.publisher {
            publish(p, cloud, "particles")?;
        }
        Ok(())
    }
}

impl LiveNode<'_> {
    /// At an output time: observes the state and sends it to every sink (recorded, then over DDS, iceoryx2
    /// and, in lockstep mode, as `/clock`), then a particle frame when one is due (recorded even when only
    /// iceoryx2 publishes). False: the observation failed (`error`).
    pub(super) fn publish_outputs(&mut self, base: f64) -> anyhow::Result<bool> {
        // (Asked between every two steps: the sinks are gathered only when an output is due.)
        if !self.outputs.times.due(self.sim.time()) {
            return Ok(true);
        }
        let base = TimeBase::Seconds(base);
        let c = &self.cfg.config;
        let ends = &mut self.ends;
        let mut recorded = self.recorder.as_mut().map(|recorder| Recorded {
            recorder,
            topics: &ends.out_topics,
        });
        let mut dds = &ends.out;
        let mut lockstep = ends.out.clock.as_ref().map(|publisher| Lockstep {
            publisher,
            last: &mut self.last_clock,
        });
        let mut iox = ends.iox_ports.as_mut().filter(|_| c.iceoryx2.outputs);
        let mut sinks: [&mut dyn Sink; 4] = [&mut recorded, &mut dds, &mut iox, &mut lockstep];
        let motion = &self.intake.motion;
        match self
            .outputs
            .deliver(self.sim.as_mut(), motion, base, &mut sinks)
        {
            Ok(_) => {}
            Err(crate::drive::DriveError::Solver(e)) => {
                self.error = Some(e.to_string());
                return Ok(false);
            }
            Err(crate::drive::DriveError::Sink(e)) => return Err(e.into()),
        }
        self.report.counters.published += 1;
        if !self.clouds.due(self.sim.time()) {
            return Ok(true);
        }
        let mut clouds = Clouds {
            publisher: ends.out.cloud.as_ref(),
            recorder: self
                .recorder
                .as_mut()
                .map(|r| (r, ends.cloud_topic.as_str())),
            frame: &c.frames.tank,
            decimation: self.live.particles_decimation,
        };
        let mut frames: Vec<&mut dyn FrameSink> = vec![&mut clouds];
        let iox = ends.iox_ports.as_mut().filter(|_| c.iceoryx2.particles);
        frames.extend(iox.map(|s| s as &mut dyn FrameSink));
        deliver_frame(
            &mut self.clouds,
            self.sim.as_ref(),
            motion,
            base,
            &mut frames,
        )?;
        Ok(true)
    }
}
