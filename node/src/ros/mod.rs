//! The ROS 2 side of `slosh`: the node (`slosh node`), the synthetic motion publisher (`slosh motion`), and
//! what they share — argument parsing and name resolution, frame conventions, live motion, pacing.

pub mod args;
pub mod cloud;
pub mod graph_hint;
pub mod logging;
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

/// The files of an SROS2 enclave (`ros2 security create_enclave KEYSTORE ENCLAVE` makes them).
pub const ENCLAVE_FILES: [&str; 6] = [
    "identity_ca.cert.pem",
    "cert.pem",
    "key.pem",
    "permissions_ca.cert.pem",
    "governance.p7s",
    "permissions.p7s",
];

/// How a participant joins, from ROS 2's security variables.
#[derive(Debug, Clone, PartialEq)]
pub enum Security {
    /// `ROS_SECURITY_ENABLE` is not `true`.
    Off,
    /// Secured with the enclave's files in this folder.
    Enclave(std::path::PathBuf),
    /// Asked for, but the enclave is not there and the strategy is Permissive: unsecured, with this warning.
    Unsecured(String),
}

/// Reads ROS 2's security variables as rcl reads them: `ROS_SECURITY_ENABLE` must be exactly `true`;
/// the enclave is `ROS_SECURITY_ENCLAVE_OVERRIDE` (else `/`), its files in
/// `ROS_SECURITY_KEYSTORE/enclaves/<enclave>`; with `ROS_SECURITY_STRATEGY=Enforce` a missing keystore or
/// file is an error naming it and the fix, otherwise (Permissive) the participant joins unsecured and says
/// so. `env` reads a variable.
pub fn security(env: impl Fn(&str) -> Option<String>) -> anyhow::Result<Security> {
    if env("ROS_SECURITY_ENABLE").as_deref() != Some("true") {
        return Ok(Security::Off);
    }
    let enforce = env("ROS_SECURITY_STRATEGY").as_deref() == Some("Enforce");
    let enclave = env("ROS_SECURITY_ENCLAVE_OVERRIDE").unwrap_or_else(|| "/".into());
    let missing = match env("ROS_SECURITY_KEYSTORE").filter(|k| !k.is_empty()) {
        None => "ROS_SECURITY_KEYSTORE is not set".to_string(),
        Some(keystore) => {
            let dir = std::path::Path::new(&keystore)
                .join("enclaves")
                .join(enclave.trim_start_matches('/'));
            match ENCLAVE_FILES.iter().find(|f| !dir.join(f).is_file()) {
                None => return Ok(Security::Enclave(dir)),
                Some(f) => format!(
                    "{} is missing (enclave {enclave} of keystore {keystore})",
                    dir.join(f).display()
                ),
            }
        }
    };
    let fix = format!(
        "make the enclave with `ros2 security create_enclave KEYSTORE {enclave}` and set ROS_SECURITY_KEYSTORE \
         (ROS_SECURITY_ENCLAVE_OVERRIDE names another enclave)"
    );
    if enforce {
        anyhow::bail!("ROS_SECURITY_ENABLE=true, ROS_SECURITY_STRATEGY=Enforce: {missing}: {fix}");
    }
    Ok(Security::Unsecured(format!(
        "ROS_SECURITY_ENABLE=true (Permissive): {missing}: joining unsecured (unauthenticated and \
         unencrypted; secured participants will not talk to this one); to secure it, {fix}"
    )))
}

/// A DDS context on the domain of `ROS_DOMAIN_ID`, secured as [`security`] says (its warning goes to stderr).
pub fn context() -> anyhow::Result<Context> {
    let sec = security(|k| std::env::var(k).ok())?;
    let d = domain_id()?;
    let mut options = ContextOptions::new().domain_id(d);
    match &sec {
        Security::Off => {}
        Security::Unsecured(warning) => eprintln!("slosh: {warning}"),
        // SROS2's keys are not password-protected.
        Security::Enclave(dir) => options = options.enable_security(dir, String::new()),
    }
    Context::with_options(options).map_err(|e| match &sec {
        Security::Enclave(dir) => anyhow::anyhow!(
            "cannot start secured DDS on domain {d} with the enclave in {}: {e:?}",
            dir.display()
        ),
        _ => anyhow::anyhow!("cannot start DDS on domain {d}: {e:?}"),
    })
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
    use super::{security, Security, ENCLAVE_FILES};

    fn env(vars: Vec<(&'static str, String)>) -> impl Fn(&str) -> Option<String> {
        move |k| vars.iter().find(|(n, _)| *n == k).map(|(_, v)| v.clone())
    }

    #[test]
    fn security_variables_are_read_as_rcl_reads_them() {
        let on = |more: Vec<(&'static str, String)>| {
            let mut v = vec![("ROS_SECURITY_ENABLE", "true".to_string())];
            v.extend(more);
            v
        };
        // Not enabled (only the exact "true" enables it).
        assert_eq!(security(env(vec![])).unwrap(), Security::Off);
        let not = vec![
            ("ROS_SECURITY_ENABLE", "True".to_string()),
            ("ROS_SECURITY_STRATEGY", "Enforce".to_string()),
        ];
        assert_eq!(security(env(not)).unwrap(), Security::Off);
        // Enforce without a keystore, or with an enclave missing a file: refused, naming what and the fix.
        let e = security(env(on(vec![("ROS_SECURITY_STRATEGY", "Enforce".into())])))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("ROS_SECURITY_KEYSTORE is not set") && e.contains("create_enclave"),
            "{e}"
        );
        let keystore = std::env::temp_dir().join(format!("slosh-keystore-{}", std::process::id()));
        let dir = keystore.join("enclaves/ship/tank");
        std::fs::create_dir_all(&dir).unwrap();
        for f in &ENCLAVE_FILES[..5] {
            std::fs::write(dir.join(f), "x").unwrap();
        }
        let vars = |strategy: &str| {
            on(vec![
                ("ROS_SECURITY_STRATEGY", strategy.to_string()),
                ("ROS_SECURITY_KEYSTORE", keystore.display().to_string()),
                ("ROS_SECURITY_ENCLAVE_OVERRIDE", "/ship/tank".into()),
            ])
        };
        let e = security(env(vars("Enforce"))).unwrap_err().to_string();
        assert!(
            e.contains("permissions.p7s is missing") && e.contains("/ship/tank"),
            "{e}"
        );
        // Permissive (anything but Enforce): unsecured, with the warning.
        for strategy in ["Permissive", "enforce"] {
            match security(env(vars(strategy))).unwrap() {
                Security::Unsecured(w) => assert!(w.contains("joining unsecured"), "{w}"),
                other => panic!("{other:?}"),
            }
        }
        // Every file there: the enclave's folder.
        std::fs::write(dir.join(ENCLAVE_FILES[5]), "x").unwrap();
        assert_eq!(
            security(env(vars("Enforce"))).unwrap(),
            Security::Enclave(dir)
        );
        let _ = std::fs::remove_dir_all(&keystore);
    }
}
