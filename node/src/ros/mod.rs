//! The ROS 2 side of `slosh`: the node (`slosh node`), the synthetic motion publisher (`slosh motion`), and
//! what they share — argument parsing and name resolution, frame conventions, live motion, pacing.

pub mod args;
pub mod cloud;
pub mod graph_hint;
pub mod motion_pub;
pub mod node;
pub mod pacing;
pub mod parameters;

use ros2_client::{Context, ContextOptions, MessageTypeName, Name, Node, QosProfile};
use slosh_msgs::RosMessage;

/// The DDS domain from `ROS_DOMAIN_ID` (0 when unset), as ROS 2 reads it.
pub fn domain_id() -> anyhow::Result<u16> {
    match std::env::var("ROS_DOMAIN_ID") {
        Err(_) => Ok(0),
        Ok(s) if s.trim().is_empty() => Ok(0),
        Ok(s) => match s.trim().parse::<u16>() {
            Ok(d) if d <= 232 => Ok(d),
            _ => anyhow::bail!("ROS_DOMAIN_ID={s}: expected an integer from 0 to 232"),
        },
    }
}

/// A DDS context on the domain of `ROS_DOMAIN_ID`.
pub fn context() -> anyhow::Result<Context> {
    let d = domain_id()?;
    Context::with_options(ContextOptions::new().domain_id(d))
        .map_err(|e| anyhow::anyhow!("cannot start DDS on domain {d}: {e:?}"))
}

/// The ros2-client name of a resolved topic name.
pub fn ros_name(names: &args::Names, name: &str) -> anyhow::Result<Name> {
    let (ns, base) = names.split(name)?;
    Name::new(&ns, &base).map_err(|e| anyhow::anyhow!("topic `{name}`: {e:?}"))
}

/// The DDS topic of message type `M` on `name` (resolved and remapped by `names`).
fn topic<M: RosMessage>(
    node: &mut Node,
    names: &args::Names,
    name: &str,
    qos: &QosProfile,
) -> anyhow::Result<ros2_client::dds::rustdds::Topic> {
    node.create_topic(
        &ros_name(names, name)?,
        MessageTypeName::new(M::PACKAGE, M::NAME),
        qos,
    )
    .map_err(|e| anyhow::anyhow!("topic `{name}`: {e:?}"))
}

/// A publisher of `M` on `name` (resolved and remapped by `names`).
pub fn publisher<M: RosMessage>(
    node: &mut Node,
    names: &args::Names,
    name: &str,
    qos: &QosProfile,
) -> anyhow::Result<ros2_client::Publisher<M>> {
    let topic = topic::<M>(node, names, name, qos)?;
    node.create_publisher::<M>(&topic, Some(qos.clone()))
        .map_err(|e| anyhow::anyhow!("publisher on `{name}`: {e:?}"))
}

/// A subscription to `M` on `name` (resolved and remapped by `names`).
pub fn subscription<M: RosMessage + 'static>(
    node: &mut Node,
    names: &args::Names,
    name: &str,
    qos: &QosProfile,
) -> anyhow::Result<ros2_client::Subscription<M>> {
    let topic = topic::<M>(node, names, name, qos)?;
    node.create_subscription::<M>(&topic, Some(qos.clone()))
        .map_err(|e| anyhow::anyhow!("subscription to `{name}`: {e:?}"))
}

/// Publishes `m`. A slow reliable reader must not stop the simulation or the motion: when its window is
/// full the sample is dropped for it (`WouldBlock`); other failures are errors naming `what`.
pub fn publish<M: serde::Serialize + std::fmt::Debug>(
    p: &ros2_client::Publisher<M>,
    m: M,
    what: &str,
) -> anyhow::Result<()> {
    match p.publish(m) {
        Ok(()) | Err(ros2_client::WriteError::WouldBlock { .. }) => Ok(()),
        Err(e) => Err(anyhow::anyhow!("publishing {what}: {e:?}")),
    }
}
