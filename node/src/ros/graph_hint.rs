//! Why no motion sample comes, from what the DDS graph shows: a publisher of another type on the node's
//! motion topic (a PoseStamped publisher while the node takes Odometry), or motion published on another topic
//! only (to be remapped). Pure functions over the discovered writers' (DDS topic name, DDS type name).

/// The ROS type name (`pkg/msg/Type`) of a DDS type name (`pkg::msg::dds_::Type_`), or the name as it is.
pub fn ros_type(dds_type: &str) -> String {
    let parts: Vec<&str> = dds_type.split("::").collect();
    match parts.as_slice() {
        [pkg, kind, "dds_", name] => {
            format!("{pkg}/{kind}/{}", name.strip_suffix('_').unwrap_or(name))
        }
        _ => dds_type.to_string(),
    }
}

/// The ROS topic name of a DDS topic name (`rt/a/b` → `/a/b`); None for non-topics (services, ...).
pub fn ros_topic(dds_topic: &str) -> Option<String> {
    dds_topic.strip_prefix("rt/").map(|t| format!("/{t}"))
}

/// The `input.type` that takes the ROS type `ros_type`.
fn input_type_of(ros_type: &str) -> Option<&'static str> {
    match ros_type {
        "nav_msgs/msg/Odometry" => Some("odom"),
        "geometry_msgs/msg/PoseStamped" => Some("pose"),
        "sensor_msgs/msg/Imu" => Some("imu"),
        _ => None,
    }
}

/// What the graph says about a motion topic `topic` (resolved; `name` before resolution, for the remap
/// hint) of ROS type `expected` that has given no sample, from `writers`: (DDS topic name, DDS type name) of
/// every publisher discovered. None when it shows nothing to point at.
pub fn hint(
    topic: &str,
    name: &str,
    expected: &str,
    writers: &[(String, String)],
) -> Option<String> {
    let mut on_topic: Vec<String> = writers
        .iter()
        .filter(|(t, _)| ros_topic(t).as_deref() == Some(topic))
        .map(|(_, ty)| ros_type(ty))
        .collect();
    on_topic.sort();
    on_topic.dedup();
    let wrong: Vec<&String> = on_topic.iter().filter(|t| *t != expected).collect();
    if let Some(other) = wrong.first() {
        let fix = match input_type_of(other) {
            // The other input type listens on its own topic (motion/pose, ...): remapped to this one.
            Some(kind) => format!(
                "set input.type: {kind} and remap its topic to this one (-r motion/{kind}:={topic}) to take \
                 it, or publish {expected}"
            ),
            None => format!("publish {expected} there (or remap the input to a topic that has it)"),
        };
        return Some(format!(
            "the graph has a publisher on {topic} of type {other}, not {expected}, so its messages never \
             reach the node: {fix}"
        ));
    }
    if !on_topic.is_empty() {
        return None;
    }
    let mut elsewhere: Vec<String> = writers
        .iter()
        .filter_map(|(t, ty)| {
            let ty = ros_type(ty);
            input_type_of(&ty)?;
            Some(format!("{} ({ty})", ros_topic(t)?))
        })
        .collect();
    elsewhere.sort();
    elsewhere.dedup();
    if elsewhere.is_empty() {
        return None;
    }
    Some(format!(
        "nothing publishes on {topic}, but the graph has motion on {}: remap the input to it (-r {name}:=TOPIC) \
         and set input.type to its type",
        elsewhere.join(", ")
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn w(t: &str, ty: &str) -> (String, String) {
        (t.to_string(), ty.to_string())
    }

    #[test]
    fn names_are_read_the_ros_way() {
        assert_eq!(
            ros_type("geometry_msgs::msg::dds_::PoseStamped_"),
            "geometry_msgs/msg/PoseStamped"
        );
        assert_eq!(ros_type("odd"), "odd");
        assert_eq!(
            ros_topic("rt/ship1/motion/odom").unwrap(),
            "/ship1/motion/odom"
        );
        assert_eq!(ros_topic("rq/slosh/resetRequest"), None);
    }

    #[test]
    fn a_publisher_of_another_type_and_motion_elsewhere_are_named() {
        let odom = "nav_msgs/msg/Odometry";
        let pose = w("rt/motion/odom", "geometry_msgs::msg::dds_::PoseStamped_");
        let h = hint("/motion/odom", "motion/odom", odom, &[pose]).unwrap();
        assert!(
            h.contains("of type geometry_msgs/msg/PoseStamped, not nav_msgs/msg/Odometry")
                && h.contains("input.type: pose and remap its topic to this one (-r motion/pose:=/motion/odom)"),
            "{h}"
        );
        let s = w("rt/motion/odom", "std_msgs::msg::dds_::String_");
        let h = hint("/motion/odom", "motion/odom", odom, &[s]).unwrap();
        assert!(h.contains("publish nav_msgs/msg/Odometry there"), "{h}");
        // The right type there: nothing to point at (QoS, or it has not sent yet).
        let right = w("rt/motion/odom", "nav_msgs::msg::dds_::Odometry_");
        assert_eq!(hint("/motion/odom", "motion/odom", odom, &[right]), None);
        // Motion on another topic only.
        let gps = w("rt/ship1/gps/odom", "nav_msgs::msg::dds_::Odometry_");
        let other = w("rt/rosout", "rcl_interfaces::msg::dds_::Log_");
        let h = hint("/motion/odom", "motion/odom", odom, &[gps, other.clone()]).unwrap();
        assert!(
            h.contains("motion on /ship1/gps/odom (nav_msgs/msg/Odometry)")
                && h.contains("-r motion/odom:=TOPIC"),
            "{h}"
        );
        assert_eq!(hint("/motion/odom", "motion/odom", odom, &[other]), None);
    }
}
