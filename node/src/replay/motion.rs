//! The vessel motion recorded in a bag: finds the motion topic (nav_msgs/Odometry, geometry_msgs/PoseStamped
//! or sensor_msgs/Imu), checks its encodings and schema, decodes every message, takes each sample's time from
//! its header stamp or its log time, applies the bad-sample policy, and turns the samples into the tank's
//! motion through the same frame conventions as the live node.

use crate::bag::{for_each_message, BagError};
use crate::config::BadSamples;
use crate::config::StampSource;
use crate::input::frames::Frames;
use crate::input::live::{imu_sample, tank_coordinates};
use crate::input::live_imu::LiveImu;
use crate::input::live_motion::{check_pose, Limits, Rejected};
use slosh_msgs::geometry_msgs::PoseStamped;
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::sensor_msgs::Imu;
use slosh_msgs::RosMessage;
use sph::motion::{SampledMotion, TankMotion};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The message types that can carry the motion.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    Odometry,
    PoseStamped,
    Imu,
}

impl Kind {
    const ALL: [Kind; 3] = [Kind::Odometry, Kind::PoseStamped, Kind::Imu];

    /// `pkg/msg/Type`.
    pub fn type_name(self) -> String {
        match self {
            Kind::Odometry => Odometry::type_name(),
            Kind::PoseStamped => PoseStamped::type_name(),
            Kind::Imu => Imu::type_name(),
        }
    }

    fn definition(self) -> &'static str {
        match self {
            Kind::Odometry => Odometry::DEFINITION,
            Kind::PoseStamped => PoseStamped::DEFINITION,
            Kind::Imu => Imu::DEFINITION,
        }
    }

    /// The kind of a schema name, `pkg/msg/Type` (ROS 2) or `pkg/Type`.
    fn of(schema_name: &str) -> Option<Kind> {
        let plain = schema_name.replace("/msg/", "/");
        Kind::ALL
            .into_iter()
            .find(|k| k.type_name().replace("/msg/", "/") == plain)
    }
}

/// What the replay needs to know to read the motion.
#[derive(Debug, Clone)]
pub struct Reading<'a> {
    /// The topic to take (None: the only motion topic).
    pub topic: Option<&'a str>,
    pub stamp: StampSource,
    pub bad_samples: BadSamples,
    pub limits: Limits,
    /// `input.max_gap_s`: a sample stamped more than this after the newest accepted one is refused.
    pub max_gap_s: f64,
    pub frames: &'a Frames,
    pub gravity: f64,
}

impl<'a> Reading<'a> {
    /// As the case `c` says (its `input.*` and `replay.*`), through `frames`, for `topic`.
    pub fn of(
        c: &crate::config::RunConfig,
        frames: &'a Frames,
        topic: Option<&'a str>,
        gravity: f64,
    ) -> Self {
        Reading {
            topic,
            stamp: c.input.stamp,
            bad_samples: c.replay.bad_samples,
            limits: Limits {
                max_speed: c.input.max_speed,
                max_rotation_rate: c.input.max_rotation_rate,
            },
            max_gap_s: c.input.max_gap_s,
            frames,
            gravity,
        }
    }
}

/// The motion read from a bag.
pub struct BagMotion {
    pub motion: Box<dyn TankMotion>,
    pub topic: String,
    pub kind: Kind,
    /// The topic's schema text, to record its messages again.
    pub schema: String,
    /// Time of the first sample on the bag's axis (ns); the replay's t = 0.
    pub t0_ns: i64,
    /// The messages that drove the tank: (time on the bag's axis in ns, CDR bytes as stored).
    pub messages: Vec<(i64, Vec<u8>)>,
    /// `header` or `log`: where the sample times came from.
    pub time_source: &'static str,
    /// Why samples were skipped (with `replay.bad_samples: drop`).
    pub dropped: Vec<String>,
    /// Messages on the topic in the bag.
    pub total: usize,
}

/// One topic as found in the bag.
struct Found {
    type_name: String,
    schema_encoding: String,
    message_encoding: String,
    schema: String,
    count: usize,
    /// (log time ns, data) of motion topics.
    messages: Vec<(u64, Vec<u8>)>,
}

/// Reads the motion from the bag files `files` (of the bag `bag`).
pub fn read(bag: &Path, files: &[PathBuf], how: &Reading) -> Result<BagMotion, BagError> {
    let mut found: BTreeMap<String, Found> = BTreeMap::new();
    for_each_message(files, |m| {
        let ch = &m.channel;
        let (type_name, schema_encoding, schema) = match &ch.schema {
            Some(s) => (
                s.name.clone(),
                s.encoding.clone(),
                String::from_utf8_lossy(&s.data).into_owned(),
            ),
            None => Default::default(),
        };
        let f = found.entry(ch.topic.clone()).or_insert_with(|| Found {
            type_name: type_name.clone(),
            schema_encoding,
            message_encoding: ch.message_encoding.clone(),
            schema,
            count: 0,
            messages: Vec::new(),
        });
        if f.type_name != type_name {
            return Err(BagError::new(
                bag,
                format!(
                    "topic {} carries two types, {} and {type_name}",
                    ch.topic, f.type_name
                ),
            ));
        }
        f.count += 1;
        let wanted = match how.topic {
            Some(t) => t == ch.topic || names_relative(t, &ch.topic),
            None => Kind::of(&type_name).is_some(),
        };
        if wanted {
            f.messages.push((m.log_time, m.data.to_vec()));
        }
        Ok(())
    })?;
    let (topic, f) = choose(bag, &found, how.topic)?;
    let kind = Kind::of(&f.type_name).expect("chosen topics are motion topics");
    check_encodings(bag, topic, f, kind)?;
    let decoded = decode(bag, topic, f, kind)?;
    build(topic, f, kind, decoded, how).map_err(|m| BagError::new(bag, m))
}

fn listing(found: &BTreeMap<String, Found>, only_motion: bool) -> String {
    let list: Vec<String> = found
        .iter()
        .filter(|(_, f)| !only_motion || Kind::of(&f.type_name).is_some())
        .map(|(t, f)| format!("{t} ({}, {} messages)", f.type_name, f.count))
        .collect();
    if list.is_empty() {
        "none".into()
    } else {
        list.join(", ")
    }
}

/// Whether `t` is the relative form of the absolute topic name `name` (`motion/odom` of `/motion/odom`).
fn names_relative(t: &str, name: &str) -> bool {
    !t.starts_with('/') && name.strip_prefix('/') == Some(t)
}

fn choose<'f>(
    bag: &Path,
    found: &'f BTreeMap<String, Found>,
    topic: Option<&str>,
) -> Result<(&'f str, &'f Found), BagError> {
    let types = "nav_msgs/msg/Odometry, geometry_msgs/msg/PoseStamped or sensor_msgs/msg/Imu";
    if let Some(t) = topic {
        // The bag's name, or a relative one (`motion/odom`, as ROS 2 users and the manual's topic table
        // write it) resolved against the root namespace, as the bag's names are.
        let Some((name, f)) = found
            .get_key_value(t)
            .or_else(|| found.iter().find(|(n, _)| names_relative(t, n)))
        else {
            return Err(BagError::new(
                bag,
                format!(
                    "--topic {t}: no such topic in the bag (motion topics: {})",
                    listing(found, true)
                ),
            ));
        };
        if Kind::of(&f.type_name).is_none() {
            return Err(BagError::new(
                bag,
                format!(
                    "--topic {t} carries `{}`; the motion must be {types}",
                    f.type_name
                ),
            ));
        }
        return Ok((name.as_str(), f));
    }
    let motion: Vec<(&String, &Found)> = found
        .iter()
        .filter(|(_, f)| Kind::of(&f.type_name).is_some())
        .collect();
    match motion.as_slice() {
        [] => Err(BagError::new(
            bag,
            format!(
                "no motion topic: no topic carries {types} (topics in the bag: {})",
                listing(found, false)
            ),
        )),
        [(t, f)] => Ok((t.as_str(), f)),
        _ => Err(BagError::new(
            bag,
            format!(
                "several motion topics: {}; choose one with --topic",
                listing(found, true)
            ),
        )),
    }
}

fn check_encodings(bag: &Path, topic: &str, f: &Found, kind: Kind) -> Result<(), BagError> {
    let err = |m: String| Err(BagError::new(bag, format!("topic {topic}: {m}")));
    if f.message_encoding != "cdr" {
        return err(format!(
            "message encoding `{}`; ROS 2 messages are stored as `cdr`",
            f.message_encoding
        ));
    }
    match f.schema_encoding.as_str() {
        "ros2msg" => {
            if let Some(diff) = schema_difference(&f.schema, kind.definition()) {
                return err(format!(
                    "its {} schema is not ROS 2's ({diff}): a type we cannot decode",
                    kind.type_name()
                ));
            }
        }
        // The IDL form is not compared field by field; decoding checks the layout.
        "ros2idl" => {}
        other => {
            return err(format!(
                "unknown schema encoding `{other}` (expected `ros2msg` or `ros2idl`)"
            ))
        }
    }
    Ok(())
}

/// The fields (type without package, name) of a `.msg` text's own definition, constants left out.
fn fields(msg: &str) -> Vec<(String, String)> {
    msg.lines()
        .take_while(|l| !l.starts_with("====="))
        .filter_map(|l| {
            let l = l.split('#').next().unwrap_or("").trim();
            let mut it = l.split_whitespace();
            let (ty, name) = (it.next()?, it.next()?);
            if name.contains('=') || it.next().is_some_and(|v| v.starts_with('=')) {
                return None;
            }
            let ty = ty.rsplit('/').next().unwrap_or(ty);
            Some((ty.to_string(), name.to_string()))
        })
        .collect()
}

/// How `schema` differs from `ours` in its fields, if it does.
fn schema_difference(schema: &str, ours: &str) -> Option<String> {
    let (a, b) = (fields(schema), fields(ours));
    if a == b {
        return None;
    }
    let show = |f: Option<&(String, String)>| {
        f.map(|(t, n)| format!("`{t} {n}`"))
            .unwrap_or_else(|| "nothing".into())
    };
    let i = a.iter().zip(&b).take_while(|(x, y)| x == y).count();
    Some(format!(
        "field {} is {}, expected {}",
        i + 1,
        show(a.get(i)),
        show(b.get(i))
    ))
}

/// One decoded message: header stamp (ns), log time (ns), the reading.
struct Decoded {
    stamp_ns: i64,
    log_ns: u64,
    reading: crate::input::live::Reading,
}

fn decode(bag: &Path, topic: &str, f: &Found, kind: Kind) -> Result<Vec<Decoded>, BagError> {
    use crate::input::live::Reading as R;
    f.messages
        .iter()
        .enumerate()
        .map(|(i, (log_ns, data))| {
            let fail = |e: slosh_msgs::cdr::CdrError| {
                BagError::new(
                    bag,
                    format!(
                        "topic {topic}, message {} (log time {:.9} s): cannot be decoded as {}: {e}",
                        i + 1,
                        *log_ns as f64 * 1e-9,
                        kind.type_name()
                    ),
                )
            };
            let (stamp, reading) = match kind {
                Kind::Odometry => {
                    let m: Odometry = slosh_msgs::from_cdr(data).map_err(fail)?;
                    (m.header.stamp, R::Pose(m.pose.pose))
                }
                Kind::PoseStamped => {
                    let m: PoseStamped = slosh_msgs::from_cdr(data).map_err(fail)?;
                    (m.header.stamp, R::Pose(m.pose))
                }
                Kind::Imu => {
                    let m: Imu = slosh_msgs::from_cdr(data).map_err(fail)?;
                    (m.header.stamp, R::Imu(Box::new(m)))
                }
            };
            Ok(Decoded {
                stamp_ns: stamp.as_nanos(),
                log_ns: *log_ns,
                reading,
            })
        })
        .collect()
}

fn build(
    topic: &str,
    f: &Found,
    kind: Kind,
    decoded: Vec<Decoded>,
    how: &Reading,
) -> Result<BagMotion, String> {
    use crate::input::live::Reading as R;
    let header = how.stamp == StampSource::Header && decoded.iter().any(|d| d.stamp_ns != 0);
    let time_ns = |d: &Decoded| {
        if header {
            d.stamp_ns
        } else {
            d.log_ns as i64
        }
    };
    let Some(t0_ns) = decoded.first().map(time_ns) else {
        return Err(format!("topic {topic} has no messages"));
    };
    let mut dropped = Vec::new();
    let mut messages = Vec::new();
    let mut reject = |i: usize, r: Rejected| -> Result<(), String> {
        let what = format!("topic {topic}, message {}: {r}", i + 1);
        // Header stamps that go back by seconds: the publisher restarted on another time base while it was
        // recorded. The log times of a bag recorded by `slosh node` (or `ros2 bag record`) go on in order.
        let restarted = match r {
            Rejected::OutOfOrder { time, newest } if header && newest - time > 1.0 => format!(
                " (the header stamps go back by {:.3} s: a publisher restarted on another time base? the bag's log times stay in order: replay on them with `--set input.stamp=receive`)",
                newest - time
            ),
            _ => String::new(),
        };
        let what = what + &restarted;
        match how.bad_samples {
            BadSamples::Error => Err(format!(
                "{what}; replay.bad_samples is `error` (set `--set replay.bad_samples=drop` to skip such samples)"
            )),
            BadSamples::Drop => {
                dropped.push(what);
                Ok(())
            }
        }
    };
    let (mut times, mut poses) = (Vec::new(), Vec::<[f64; 6]>::new());
    let mut imu = LiveImu::new(
        how.limits,
        how.gravity,
        how.frames.mount().0,
        how.frames.mount().1,
    );
    let mut newest: Option<f64> = None;
    for (i, d) in decoded.iter().enumerate() {
        let t = (time_ns(d) - t0_ns) as f64 * 1e-9;
        // As the node: a stamp far ahead (garbled, a clock set wrong) would make the whole gap one move.
        if let Some(gap) = newest.map(|n| t - n).filter(|g| *g > how.max_gap_s) {
            reject(
                i,
                Rejected::Invalid(format!(
                    "stamp {t:.6} s is {gap:.3} s after the newest sample's, more than input.max_gap_s = {}",
                    how.max_gap_s
                )),
            )?;
            continue;
        }
        let accepted = match &d.reading {
            R::Pose(p) => tank_coordinates(p, how.frames).and_then(|c| {
                let prev = times.last().copied().zip(poses.last().copied());
                check_pose(prev, t, &c, &how.limits).map(|()| {
                    times.push(t);
                    poses.push(c);
                })
            }),
            R::Imu(m) => imu_sample(m, how.frames).and_then(|s| imu.push(t, s)),
            R::State(_) => unreachable!("bags are decoded to poses or IMU readings"),
        };
        match accepted {
            Ok(()) => {
                newest = Some(t);
                messages.push((time_ns(d), f.messages[i].1.clone()))
            }
            Err(r) => reject(i, r)?,
        }
    }
    let samples = messages.len();
    if samples < 2 {
        return Err(format!(
            "topic {topic} has {samples} usable samples; a motion needs at least 2"
        ));
    }
    let motion: Box<dyn TankMotion> = match kind {
        Kind::Imu => Box::new(imu),
        _ => {
            Box::new(SampledMotion::new(times, &poses).map_err(|e| format!("topic {topic}: {e}"))?)
        }
    };
    Ok(BagMotion {
        motion,
        topic: topic.to_string(),
        kind,
        schema: f.schema.clone(),
        t0_ns,
        messages,
        time_source: if header { "header" } else { "log" },
        dropped,
        total: f.count,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kinds_are_found_by_either_spelling_of_the_type() {
        assert_eq!(Kind::of("nav_msgs/msg/Odometry"), Some(Kind::Odometry));
        assert_eq!(Kind::of("nav_msgs/Odometry"), Some(Kind::Odometry));
        assert_eq!(Kind::of("sensor_msgs/msg/Imu"), Some(Kind::Imu));
        assert_eq!(Kind::of("std_msgs/msg/String"), None);
    }

    #[test]
    fn schemas_are_compared_by_their_fields() {
        let ours = Kind::PoseStamped.definition();
        // Comments, blank lines and package spellings do not matter.
        let same = "# a pose\nstd_msgs/msg/Header header  # stamp\n\nPose pose\n";
        assert_eq!(schema_difference(same, ours), None);
        let other = "Header header\ngeometry_msgs/Point position\n";
        let d = schema_difference(other, ours).unwrap();
        assert!(
            d.contains("field 2 is `Point position`, expected `Pose pose`"),
            "{d}"
        );
        // Constants are not fields.
        let imu = Kind::Imu.definition();
        assert_eq!(schema_difference(imu, imu), None);
        assert!(fields(&format!("int8 A=1\n{ours}")).len() == 2);
    }
}
