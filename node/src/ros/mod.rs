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

/// What ROS 2's security variables ask of a participant, read as rcl reads them: `ROS_SECURITY_ENABLE` must be
/// exactly `true` to ask for DDS-Security (SROS2), and `ROS_SECURITY_STRATEGY` `Enforce` makes a participant that
/// cannot be secured fail instead of joining unsecured (anything else is Permissive). This build of `slosh` has
/// no DDS-Security: asked to enforce it, it refuses to start (it would otherwise join the graph
/// unauthenticated and unencrypted); asked permissively, it starts unsecured with a warning, as a Permissive
/// rcl participant without its keystore files does. `env` reads a variable.
pub fn security(env: impl Fn(&str) -> Option<String>) -> anyhow::Result<Option<String>> {
    if env("ROS_SECURITY_ENABLE").as_deref() != Some("true") {
        return Ok(None);
    }
    let keystore = env("ROS_SECURITY_KEYSTORE").unwrap_or_else(|| "(unset)".into());
    if env("ROS_SECURITY_STRATEGY").as_deref() == Some("Enforce") {
        anyhow::bail!(
            "ROS_SECURITY_ENABLE=true with ROS_SECURITY_STRATEGY=Enforce (keystore {keystore}): this slosh has no \
             DDS-Security (SROS2) support, so it cannot join a secured ROS 2 graph; run it on an unsecured \
             domain (unset ROS_SECURITY_ENABLE) or set ROS_SECURITY_STRATEGY=Permissive to join unsecured"
        );
    }
    Ok(Some(format!(
        "ROS_SECURITY_ENABLE=true (Permissive; keystore {keystore}): this slosh has no DDS-Security (SROS2) \
         support: it joins the graph unauthenticated and unencrypted, and secured participants will not talk to it"
    )))
}

/// A DDS context on the domain of `ROS_DOMAIN_ID` (after [`security`]: its warning goes to stderr).
pub fn context() -> anyhow::Result<Context> {
    if let Some(warning) = security(|k| std::env::var(k).ok())? {
        eprintln!("slosh: {warning}");
    }
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

#[cfg(test)]
mod tests {
    use super::security;

    fn env(vars: &'static [(&'static str, &'static str)]) -> impl Fn(&str) -> Option<String> {
        move |k| {
            vars.iter()
                .find(|(n, _)| *n == k)
                .map(|(_, v)| v.to_string())
        }
    }

    #[test]
    fn security_variables_are_read_as_rcl_reads_them() {
        // Not enabled: nothing to say (only the exact "true" enables it).
        assert!(security(env(&[])).unwrap().is_none());
        assert!(security(env(&[("ROS_SECURITY_ENABLE", "1")]))
            .unwrap()
            .is_none());
        assert!(security(env(&[
            ("ROS_SECURITY_ENABLE", "True"),
            ("ROS_SECURITY_STRATEGY", "Enforce")
        ]))
        .unwrap()
        .is_none());
        // Enforce: refused, naming the variables, the keystore and the ways out.
        let e = security(env(&[
            ("ROS_SECURITY_ENABLE", "true"),
            ("ROS_SECURITY_STRATEGY", "Enforce"),
            ("ROS_SECURITY_KEYSTORE", "/ks"),
        ]))
        .unwrap_err()
        .to_string();
        assert!(
            e.contains("ROS_SECURITY_STRATEGY=Enforce")
                && e.contains("/ks")
                && e.contains("unset ROS_SECURITY_ENABLE")
                && e.contains("Permissive"),
            "{e}"
        );
        // Permissive (or anything but Enforce): a warning.
        for strategy in ["Permissive", "enforce", ""] {
            let w = security(env(match strategy {
                "Permissive" => &[
                    ("ROS_SECURITY_ENABLE", "true"),
                    ("ROS_SECURITY_STRATEGY", "Permissive"),
                ],
                "enforce" => &[
                    ("ROS_SECURITY_ENABLE", "true"),
                    ("ROS_SECURITY_STRATEGY", "enforce"),
                ],
                _ => &[("ROS_SECURITY_ENABLE", "true")],
            }))
            .unwrap()
            .unwrap();
            assert!(w.contains("unauthenticated and unencrypted"), "{w}");
        }
    }
}
