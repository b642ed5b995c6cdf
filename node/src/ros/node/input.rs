//! The motion input as the node reads it: a DDS subscription of one of the accepted types or the iceoryx2
//! motion service, each sample with its stamp, its reading and the messages it is recorded as.

use crate::config::InputType;
use crate::input::live::Reading;
use crate::record::{RawMessage, Recorder};
use nalgebra::UnitQuaternion;
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::geometry_msgs::PoseStamped;
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::sensor_msgs::Imu;

pub(super) enum Input {
    Odom(ros2_client::Subscription<Odometry>),
    Pose(ros2_client::Subscription<PoseStamped>),
    Imu(ros2_client::Subscription<Imu>),
    /// iceoryx2 `NAME/motion`, recorded as Odometry on `motion/odom` and AccelStamped on (the resolved)
    /// `.1`, with the vessel frame `.2`.
    Iox(
        iceoryx2::port::subscriber::Subscriber<
            iceoryx2::prelude::ipc::Service,
            crate::iox::MotionSample,
            (),
        >,
        String,
        String,
    ),
}

impl Input {
    /// The topic, before resolution.
    pub(super) fn topic(kind: InputType) -> &'static str {
        match kind {
            InputType::Odom => "motion/odom",
            InputType::Pose => "motion/pose",
            InputType::Imu => "motion/imu",
            // Recorded there, as the Odometry it would be on DDS.
            InputType::Iceoryx2 => "motion/odom",
        }
    }

    /// The ROS type taken (iceoryx2: what it is recorded as).
    pub(super) fn type_name(kind: InputType) -> &'static str {
        match kind {
            InputType::Odom | InputType::Iceoryx2 => "nav_msgs/msg/Odometry",
            InputType::Pose => "geometry_msgs/msg/PoseStamped",
            InputType::Imu => "sensor_msgs/msg/Imu",
        }
    }

    /// The next received sample: (header stamp, reading, the messages to record, serialized for the topic
    /// `rec` when given), or why a message received could not be decoded (DDS delivers a publisher of another
    /// type on the same topic name). The node records samples once it has taken or refused them.
    pub(super) fn take(&self, rec: Option<&str>) -> anyhow::Result<Option<Result<Taken, String>>> {
        match self.take_decoded(rec) {
            Ok(t) => Ok(t.map(Ok)),
            Err(e) => match e.downcast::<ros2_client::ReadError>() {
                Ok(ros2_client::ReadError::Deserialization { reason }) => Ok(Some(Err(reason))),
                Ok(other) => Err(anyhow::anyhow!("reading the motion input: {other:?}")),
                Err(e) => Err(e),
            },
        }
    }

    fn take_decoded(&self, rec: Option<&str>) -> anyhow::Result<Option<Taken>> {
        let err = |_what: &str, e: ros2_client::ReadError| anyhow::Error::from(e);
        fn keep<M: slosh_msgs::RosMessage>(rec: Option<&str>, m: &M) -> Vec<RawMessage> {
            rec.map(|topic| vec![RawMessage::of(topic, m)])
                .unwrap_or_default()
        }
        Ok(match self {
            Input::Odom(s) => match s.take().map_err(|e| err("motion/odom", e))? {
                Some((m, _)) => Some((m.header.stamp, keep(rec, &m), Reading::Pose(m.pose.pose))),
                None => None,
            },
            Input::Pose(s) => match s.take().map_err(|e| err("motion/pose", e))? {
                Some((m, _)) => Some((m.header.stamp, keep(rec, &m), Reading::Pose(m.pose))),
                None => None,
            },
            Input::Imu(s) => match s.take().map_err(|e| err("motion/imu", e))? {
                Some((m, _)) => {
                    let raw = keep(rec, &m);
                    Some((m.header.stamp, raw, Reading::Imu(Box::new(m))))
                }
                None => None,
            },
            Input::Iox(sub, accel_topic, vessel) => match sub
                .receive()
                .map_err(|e| anyhow::anyhow!("reading the iceoryx2 motion: {e}"))?
            {
                Some(sample) => {
                    let m: crate::iox::MotionSample = *sample.payload();
                    let stamp = Time::from_secs_f64(m.time);
                    let mut raw = Vec::new();
                    if let Some(topic) = rec {
                        let identity = crate::iox::Mount {
                            offset: Default::default(),
                            rotation: UnitQuaternion::identity(),
                        };
                        let v = crate::iox::tank_state(&m, &identity);
                        raw.push(RawMessage::of(
                            topic,
                            &crate::messages::motion::odometry(&v, stamp, "odom", vessel),
                        ));
                        raw.push(RawMessage::of(
                            accel_topic,
                            &crate::messages::motion::accel(&v, stamp, vessel),
                        ));
                    }
                    Some((stamp, raw, Reading::State(m)))
                }
                None => None,
            },
        })
    }
}

/// (DDS topic name, DDS type name) of every publisher the graph shows.
pub(super) fn writers_on_graph(context: &ros2_client::Context) -> Vec<(String, String)> {
    context
        .domain_participant()
        .discovered_writers()
        .into_iter()
        .map(|w| {
            (
                w.publication_topic_data.topic_name,
                w.publication_topic_data.type_name,
            )
        })
        .collect()
}

/// A received sample: its header stamp, its messages for the recording, the reading.
pub(super) type Taken = (Time, Vec<RawMessage>, Reading);

/// A sample the input loop decides on.
pub(super) struct Sample {
    /// Its time on the input's time base (s): the header stamp, or when it was taken (`input.stamp`).
    pub(super) ts: f64,
    /// The same, as the log time it is recorded at once taken.
    pub(super) log: Time,
    pub(super) reading: Reading,
    /// When it was taken from the reader (the node's wall clock, s).
    pub(super) received: f64,
    /// Its messages for the recording (none when not recording).
    pub(super) raw: Vec<RawMessage>,
}

impl Sample {
    /// Records a refused sample at the recording's latest log time.
    pub(super) fn record_refused(
        &self,
        r: &mut Recorder,
    ) -> Result<(), crate::record::RecordError> {
        for m in &self.raw {
            r.write_message_now(m, self.log)?;
        }
        Ok(())
    }
}
