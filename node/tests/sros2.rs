//! SROS2: `slosh node` on a secured domain (DDS-Security: authentication, access control, encryption), with a
//! keystore laid out as `ros2 security` makes it, generated here with `openssl`: a secured motion publisher
//! and the secured node exchange data, an unsecured participant gets nothing from the node and cannot feed
//! it. Runs in a loopback-only network namespace.

mod common;

use common::{rest_odometry, ros_topic, slosh};
use ros2_client::qos::{History, WhenFull};
use ros2_client::{
    Context, ContextOptions, MessageTypeName, Name, NodeName, NodeOptions, QosProfile,
};
use slosh_msgs::geometry_msgs::WrenchStamped;
use slosh_msgs::nav_msgs::Odometry;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const DOMAIN: u16 = 62;

fn openssl(dir: &Path, args: &[&str]) {
    let o = Command::new("openssl")
        .args(args)
        .current_dir(dir)
        .output()
        .expect("openssl (apt install openssl)");
    assert!(
        o.status.success(),
        "openssl {args:?}: {}",
        String::from_utf8_lossy(&o.stderr)
    );
}

const GOVERNANCE: &str = r#"<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-SECURITY/20170901/omg_shared_ca_governance.xsd">
  <domain_access_rules>
    <domain_rule>
      <domains><id_range><min>0</min><max>232</max></id_range></domains>
      <allow_unauthenticated_participants>false</allow_unauthenticated_participants>
      <enable_join_access_control>true</enable_join_access_control>
      <discovery_protection_kind>ENCRYPT</discovery_protection_kind>
      <liveliness_protection_kind>ENCRYPT</liveliness_protection_kind>
      <rtps_protection_kind>SIGN</rtps_protection_kind>
      <topic_access_rules>
        <topic_rule>
          <topic_expression>*</topic_expression>
          <enable_discovery_protection>true</enable_discovery_protection>
          <enable_liveliness_protection>true</enable_liveliness_protection>
          <enable_read_access_control>true</enable_read_access_control>
          <enable_write_access_control>true</enable_write_access_control>
          <metadata_protection_kind>ENCRYPT</metadata_protection_kind>
          <data_protection_kind>ENCRYPT</data_protection_kind>
        </topic_rule>
      </topic_access_rules>
    </domain_rule>
  </domain_access_rules>
</dds>
"#;

/// The permissions of enclave `name` (certificate subject CN=`name`): every topic on the test's domain, or
/// for `limited` only ROS 2's own (discovery, rosout, parameter events) and `rt/elsewhere`.
fn permissions(name: &str) -> String {
    let topics = if name == "limited" {
        [
            "ros_discovery_info",
            "rt/rosout",
            "rt/parameter_events",
            "rt/elsewhere",
        ]
        .map(|t| format!("<topic>{t}</topic>"))
        .concat()
    } else {
        "<topic>*</topic>".to_string()
    };
    format!(
        r#"<?xml version="1.0" encoding="UTF-8"?>
<dds xmlns:xsi="http://www.w3.org/2001/XMLSchema-instance" xsi:noNamespaceSchemaLocation="http://www.omg.org/spec/DDS-Security/20170901/omg_shared_ca_permissions.xsd">
  <permissions>
    <grant name="{name}">
      <subject_name>CN={name}</subject_name>
      <validity><not_before>2020-01-01T00:00:00</not_before><not_after>2100-01-01T00:00:00</not_after></validity>
      <allow_rule>
        <domains><id>{DOMAIN}</id></domains>
        <publish><topics>{topics}</topics></publish>
        <subscribe><topics>{topics}</topics></subscribe>
      </allow_rule>
      <default>DENY</default>
    </grant>
  </permissions>
</dds>
"#
    )
}

/// A keystore in `root` as `ros2 security create_keystore` / `create_enclave` lay it out (one CA for
/// identities and permissions), with the enclaves `names`: `root/enclaves/<name>/` holding the six files.
fn keystore(root: &Path, names: &[&str]) {
    let ca = root.join("public");
    std::fs::create_dir_all(&ca).unwrap();
    openssl(&ca, &["ecparam", "-name", "prime256v1", "-out", "ec.pem"]);
    openssl(
        &ca,
        &[
            "req",
            "-x509",
            "-newkey",
            "param:ec.pem",
            "-nodes",
            "-keyout",
            "ca.key.pem",
            "-out",
            "ca.cert.pem",
            "-days",
            "3650",
            "-subj",
            "/CN=sros2testCA",
        ],
    );
    std::fs::write(ca.join("governance.xml"), GOVERNANCE).unwrap();
    openssl(
        &ca,
        &[
            "smime",
            "-sign",
            "-text",
            "-in",
            "governance.xml",
            "-out",
            "governance.p7s",
            "-signer",
            "ca.cert.pem",
            "-inkey",
            "ca.key.pem",
        ],
    );
    for name in names {
        let dir = root.join("enclaves").join(name);
        std::fs::create_dir_all(&dir).unwrap();
        for f in ["ca.cert.pem", "ec.pem", "governance.p7s"] {
            std::fs::copy(ca.join(f), dir.join(f)).unwrap();
        }
        std::fs::copy(ca.join("ca.cert.pem"), dir.join("identity_ca.cert.pem")).unwrap();
        std::fs::copy(ca.join("ca.cert.pem"), dir.join("permissions_ca.cert.pem")).unwrap();
        openssl(
            &dir,
            &[
                "req",
                "-newkey",
                "param:ec.pem",
                "-nodes",
                "-keyout",
                "key.pem",
                "-out",
                "req.pem",
                "-subj",
                &format!("/CN={name}"),
            ],
        );
        openssl(
            &dir,
            &[
                "x509",
                "-req",
                "-days",
                "3650",
                "-in",
                "req.pem",
                "-CA",
                "ca.cert.pem",
                "-CAkey",
                "../../public/ca.key.pem",
                "-out",
                "cert.pem",
                "-set_serial",
                "1",
            ],
        );
        std::fs::write(dir.join("permissions.xml"), permissions(name)).unwrap();
        openssl(
            &dir,
            &[
                "smime",
                "-sign",
                "-text",
                "-in",
                "permissions.xml",
                "-out",
                "permissions.p7s",
                "-signer",
                "ca.cert.pem",
                "-inkey",
                "../../public/ca.key.pem",
            ],
        );
    }
}

/// A ROS 2 node of the test on the test's domain, secured with the enclave in `dir` (None: unsecured).
fn participant(dir: Option<&PathBuf>, name: &str) -> (Context, ros2_client::Node) {
    let mut options = ContextOptions::new().domain_id(DOMAIN);
    if let Some(d) = dir {
        options = options.enable_security(d, String::new());
    }
    let ctx = Context::with_options(options).unwrap();
    let node = ctx
        .new_node(
            NodeName::new("/", name).unwrap(),
            NodeOptions::new().enable_rosout(false),
        )
        .unwrap();
    (ctx, node)
}

#[test]
fn a_secured_node_talks_to_secured_peers_only() {
    if !common::in_private_netns("a_secured_node_talks_to_secured_peers_only") {
        return;
    }
    let dir = common::tmp("sros2");
    let ks = dir.join("keystore");
    keystore(&ks, &["node", "driver", "limited"]);
    let case = dir.join("case.yaml");
    std::fs::write(&case, common::small_case_at(0.04, "")).unwrap();
    let mut proc = slosh()
        .args(["node", "--duration", "3", "--ros-args", "--params-file"])
        .arg(&case)
        .args(["-r", "__ns:=/sec", "-p", "realtime.mode:=lockstep"])
        .env("ROS_DOMAIN_ID", DOMAIN.to_string())
        .env("ROS_SECURITY_ENABLE", "true")
        .env("ROS_SECURITY_STRATEGY", "Enforce")
        .env("ROS_SECURITY_KEYSTORE", &ks)
        .env("ROS_SECURITY_ENCLAVE_OVERRIDE", "/node")
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();

    let qos = QosProfile::publisher_default()
        .reliability_reliable(WhenFull::Wait(Duration::from_millis(100)))
        .history(History::KeepLast { depth: 100 });
    let driver_dir = ks.join("enclaves/driver");
    let (_sctx, mut secured) = participant(Some(&driver_dir), "driver");
    let (_uctx, mut open) = participant(None, "intruder");
    // Authenticated, but its permissions grant only ROS 2's own topics and rt/elsewhere: DDS-Security
    // refuses it the node's topics (at their creation: it can neither feed the node nor read it).
    let limited_dir = ks.join("enclaves/limited");
    let (_lctx, limited) = participant(Some(&limited_dir), "limited");
    for (ns, name, type_name) in [
        (
            "/sec/motion",
            "odom",
            MessageTypeName::new("nav_msgs", "Odometry"),
        ),
        (
            "/sec",
            "wrench",
            MessageTypeName::new("geometry_msgs", "WrenchStamped"),
        ),
    ] {
        let refused = limited
            .create_topic(&Name::new(ns, name).unwrap(), type_name, &qos)
            .map(|_| ())
            .unwrap_err();
        assert!(
            format!("{refused:?}").contains("not allowed by security"),
            "{name}: {refused:?}"
        );
    }
    limited
        .create_topic(
            &Name::new("/", "elsewhere").unwrap(),
            MessageTypeName::new("nav_msgs", "Odometry"),
            &qos,
        )
        .expect("the topic its permissions grant");
    let motion_topic = ros_topic::<Odometry>(&mut secured, "/sec/motion/odom", &qos);
    let motion = secured
        .create_publisher::<Odometry>(&motion_topic, Some(qos.clone()))
        .unwrap();
    let wrench_topic = ros_topic::<WrenchStamped>(&mut secured, "/sec/wrench", &qos);
    let wrench = secured
        .create_subscription::<WrenchStamped>(&wrench_topic, Some(qos.clone()))
        .unwrap();
    let forged_topic = ros_topic::<Odometry>(&mut open, "/sec/motion/odom", &qos);
    let forged = open
        .create_publisher::<Odometry>(&forged_topic, Some(qos.clone()))
        .unwrap();
    let eavesdrop_topic = ros_topic::<WrenchStamped>(&mut open, "/sec/wrench", &qos);
    let eavesdrop = open
        .create_subscription::<WrenchStamped>(&eavesdrop_topic, Some(qos.clone()))
        .unwrap();

    // Motion at 50 Hz from the secured publisher (from stamp 1000 s) and forged samples from the unsecured
    // one (stamps 5000 s on: the node would refuse them as a jump, and count them).
    let (mut got, mut stolen) = (0usize, 0usize);
    let start = Instant::now();
    let mut k = 0u64;
    while start.elapsed() < Duration::from_secs(40) && got < 40 {
        let t = k as f64 / 50.0;
        motion.publish(rest_odometry(1000.0 + t)).unwrap();
        let _ = forged.publish(rest_odometry(5000.0 + t));
        k += 1;
        std::thread::sleep(Duration::from_millis(20));
        while let Ok(Some(_)) = wrench.take() {
            got += 1;
        }
        while let Ok(Some(_)) = eavesdrop.take() {
            stolen += 1;
        }
    }
    std::thread::sleep(Duration::from_millis(500));
    while let Ok(Some(_)) = eavesdrop.take() {
        stolen += 1;
    }
    let _ = Command::new("kill")
        .args(["-INT", &proc.id().to_string()])
        .status();
    let mut log = String::new();
    if let Some(mut e) = proc.stderr.take() {
        std::io::Read::read_to_string(&mut e, &mut log).unwrap();
    }
    let status = proc.wait().unwrap();
    println!("sros2: {k} samples sent, {got} wrenches to the secured peer, {stolen} to the unsecured one");
    assert!(status.success(), "{status}: {log}");
    assert!(got >= 40, "the secured peer got {got} wrenches: {log}");
    assert_eq!(
        stolen, 0,
        "the unsecured participant read the node's wrench"
    );
    // The forged samples never reached the node: it refused none (they would have been 4000 s ahead).
    assert_eq!(common::stop_count(&log, "rejected"), 0, "{log}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A keystore whose files are there but do not make a participant (the certificate is not one): both commands
/// stop at start-up with the enclave's folder.
#[test]
fn a_broken_keystore_stops_the_node_at_start_up() {
    if !common::in_private_netns("a_broken_keystore_stops_the_node_at_start_up") {
        return;
    }
    let dir = common::tmp("sros2-broken");
    let ks = dir.join("keystore");
    keystore(&ks, &["node"]);
    std::fs::write(ks.join("enclaves/node/cert.pem"), "not a certificate\n").unwrap();
    for args in [
        vec!["node", "--duration", "1", "seed_tank_039"],
        vec!["motion", "seed_tank_039", "--duration", "1"],
    ] {
        let o = slosh()
            .args(&args)
            .env("ROS_DOMAIN_ID", DOMAIN.to_string())
            .env("ROS_SECURITY_ENABLE", "true")
            .env("ROS_SECURITY_STRATEGY", "Enforce")
            .env("ROS_SECURITY_KEYSTORE", &ks)
            .env("ROS_SECURITY_ENCLAVE_OVERRIDE", "/node")
            .output()
            .unwrap();
        assert!(!o.status.success(), "{args:?} started");
        let e = String::from_utf8_lossy(&o.stderr);
        assert!(
            e.contains("cannot start secured DDS") && e.contains("enclaves/node"),
            "{args:?}: {e}"
        );
    }
    let _ = std::fs::remove_dir_all(&dir);
}
