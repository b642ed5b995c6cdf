//! Recording to a rosbag2 folder: one MCAP file (profile `ros2`, `ros2msg` schemas with their dependencies,
//! `cdr` payloads, chunked and zstd-compressed) plus the `metadata.yaml` that `ros2 bag` and rosbags read. The
//! run's parameters go in an MCAP metadata record named `slosh_parameters`, so a bag documents its own case.
//!
//! [`Recorder::finish`] writes the summary and `metadata.yaml`; dropping an unfinished recorder finishes it, so
//! a run that stops on an error still leaves a readable bag.

use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::RosMessage;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// What `record.*` configures.
#[derive(Debug, Clone, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct RecordCfg {
    /// rosbag2 folder to create (empty: no recording).
    pub path: String,
    /// `zstd` (default) or `none`.
    pub compression: String,
    /// Bytes of messages per chunk.
    pub chunk_size: u64,
}

impl Default for RecordCfg {
    fn default() -> Self {
        Self {
            path: String::new(),
            compression: "zstd".into(),
            chunk_size: 768 * 1024,
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    #[error("record.path {path}: {message}")]
    Path { path: String, message: String },
    #[error("record.compression: `{0}` is not one of `zstd`, `none`")]
    Compression(String),
    #[error("recording to {path}: {message}")]
    Write { path: String, message: String },
}

/// A failure while writing the bag in `dir`.
/// An error with its causes (the MCAP writer's own message hides the I/O error under it, e.g. a full disk).
fn with_causes(e: &dyn std::error::Error) -> String {
    let mut s = e.to_string();
    let mut cause = e.source();
    while let Some(c) = cause {
        s += &format!(": {c}");
        cause = c.source();
    }
    s
}

fn write_error(dir: &Path, e: impl std::fmt::Display) -> RecordError {
    RecordError::Write {
        path: dir.display().to_string(),
        message: e.to_string(),
    }
}

/// The QoS string written both in the channels' metadata and in `metadata.yaml` (they must be identical for
/// rosbags to read the messages); empty means the reader's defaults.
const OFFERED_QOS: &str = "";

struct Channel {
    id: u16,
    type_name: String,
    count: u64,
}

/// An open recording.
pub struct Recorder {
    dir: PathBuf,
    file_name: String,
    writer: Option<mcap::Writer<BufWriter<File>>>,
    channels: BTreeMap<String, Channel>,
    start_ns: Option<u64>,
    end_ns: u64,
    sequence: u32,
}

impl Recorder {
    /// Creates the rosbag2 folder `cfg.path` (which must not exist yet, or be empty) and its MCAP file.
    pub fn create(cfg: &RecordCfg, parameters: &serde_json::Value) -> Result<Self, RecordError> {
        let dir = PathBuf::from(&cfg.path);
        let err = |message: String| RecordError::Path {
            path: cfg.path.clone(),
            message,
        };
        let compression = match cfg.compression.as_str() {
            "zstd" => Some(mcap::Compression::Zstd),
            "none" | "" => None,
            other => return Err(RecordError::Compression(other.into())),
        };
        if dir.exists()
            && std::fs::read_dir(&dir)
                .map(|mut d| d.next().is_some())
                .unwrap_or(true)
        {
            return Err(err(
                "already exists and is not empty: choose a new folder (a bag is never overwritten)"
                    .into(),
            ));
        }
        std::fs::create_dir_all(&dir).map_err(|e| err(format!("cannot create the folder: {e}")))?;
        let stem = dir
            .file_name()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "recording".into());
        let file_name = format!("{stem}_0.mcap");
        let file = File::create(dir.join(&file_name))
            .map_err(|e| err(format!("cannot create {file_name}: {e}")))?;
        let mut writer = mcap::WriteOptions::new()
            .profile("ros2")
            .library(concat!("slosh ", env!("CARGO_PKG_VERSION")))
            .compression(compression)
            .chunk_size(Some(cfg.chunk_size.max(4096)))
            .create(BufWriter::new(file))
            .map_err(|e| err(format!("cannot start the MCAP file: {}", with_causes(&e))))?;
        let mut meta = BTreeMap::new();
        meta.insert("parameters".to_string(), parameters.to_string());
        writer
            .write_metadata(&mcap::records::Metadata {
                name: "slosh_parameters".into(),
                metadata: meta,
            })
            .map_err(|e| err(format!("cannot write the parameters: {}", with_causes(&e))))?;
        Ok(Self {
            dir,
            file_name,
            writer: Some(writer),
            channels: BTreeMap::new(),
            start_ns: None,
            end_ns: 0,
            sequence: 0,
        })
    }

    fn write_err(&self, e: impl std::fmt::Display) -> RecordError {
        write_error(&self.dir, e)
    }

    /// Records `msg` on `topic` at `log_time` (ROS time; negative times are written as 0).
    pub fn write<M: RosMessage>(
        &mut self,
        topic: &str,
        log_time: Time,
        msg: &M,
    ) -> Result<(), RecordError> {
        let ns = log_time.as_nanos().max(0) as u64;
        let schema = format!("{}/msg/{}", M::PACKAGE, M::NAME);
        let data = slosh_msgs::to_cdr(msg);
        self.write_raw(topic, &schema, &M::ros2msg_schema(), ns, &data)
    }

    /// Records an already serialized CDR message (with its encapsulation header) of ROS type `type_name`
    /// (`pkg/msg/Type`) whose `ros2msg` schema text is `schema`, at `log_time_ns`.
    pub fn write_raw(
        &mut self,
        topic: &str,
        type_name: &str,
        schema: &str,
        log_time_ns: u64,
        data: &[u8],
    ) -> Result<(), RecordError> {
        // A free function: `writer` below borrows `self` mutably.
        let dir = &self.dir;
        let err = |e: mcap::McapError| write_error(dir, with_causes(&e));
        let Some(writer) = self.writer.as_mut() else {
            return Err(write_error(dir, "the recording is already finished"));
        };
        let id = match self.channels.get(topic) {
            Some(c) => c.id,
            None => {
                let schema_id = writer
                    .add_schema(type_name, "ros2msg", schema.as_bytes())
                    .map_err(err)?;
                let mut meta = BTreeMap::new();
                meta.insert("offered_qos_profiles".to_string(), OFFERED_QOS.to_string());
                let id = writer
                    .add_channel(schema_id, topic, "cdr", &meta)
                    .map_err(err)?;
                self.channels.insert(
                    topic.to_string(),
                    Channel {
                        id,
                        type_name: type_name.to_string(),
                        count: 0,
                    },
                );
                id
            }
        };
        self.sequence += 1;
        let header = mcap::records::MessageHeader {
            channel_id: id,
            sequence: self.sequence,
            log_time: log_time_ns,
            publish_time: log_time_ns,
        };
        writer.write_to_known_channel(&header, data).map_err(err)?;
        if let Some(c) = self.channels.get_mut(topic) {
            c.count += 1;
        }
        self.start_ns = Some(self.start_ns.map_or(log_time_ns, |s| s.min(log_time_ns)));
        self.end_ns = self.end_ns.max(log_time_ns);
        Ok(())
    }

    /// Records the outputs of one state on `topics` (wrench, probes, pressures) at `log_time`, and each
    /// floating body's on `bodies/NAME/odom` and `bodies/NAME/wrench` beside the wrench topic.
    pub fn write_outputs(
        &mut self,
        topics: &[String; 3],
        log_time: Time,
        m: &crate::ros::node::OutputMessages,
    ) -> Result<(), RecordError> {
        self.write(&topics[0], log_time, &m.wrench)?;
        self.write(&topics[1], log_time, &m.probes)?;
        self.write(&topics[2], log_time, &m.pressures)?;
        let base = topics[0].rsplit_once('/').map_or("", |(ns, _)| ns);
        for b in &m.bodies {
            let topic = |what| format!("{base}/{}", crate::ros::node::body_topic(&b.name, what));
            self.write(&topic("odom"), log_time, &b.odom)?;
            self.write(&topic("wrench"), log_time, &b.wrench)?;
        }
        Ok(())
    }

    /// The folder of the bag.
    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Writes the MCAP summary and `metadata.yaml`. Safe to call twice.
    pub fn finish(&mut self) -> Result<(), RecordError> {
        let Some(mut writer) = self.writer.take() else {
            return Ok(());
        };
        writer
            .finish()
            .map_err(|e| self.write_err(with_causes(&e)))?;
        drop(writer);
        let yaml = self.metadata_yaml();
        std::fs::write(self.dir.join("metadata.yaml"), yaml).map_err(|e| self.write_err(e))
    }

    /// rosbag2's `metadata.yaml` (version 5 layout, which ros2 bag and rosbags read).
    fn metadata_yaml(&self) -> String {
        let start = self.start_ns.unwrap_or(0);
        let duration = self.end_ns.saturating_sub(start);
        let total: u64 = self.channels.values().map(|c| c.count).sum();
        let mut y = String::new();
        y += "rosbag2_bagfile_information:\n  version: 5\n  storage_identifier: mcap\n";
        y += &format!("  duration:\n    nanoseconds: {duration}\n");
        y += &format!("  starting_time:\n    nanoseconds_since_epoch: {start}\n");
        y += &format!("  message_count: {total}\n  topics_with_message_count:\n");
        for (topic, c) in &self.channels {
            y += &format!(
                "    - topic_metadata:\n        name: {topic}\n        type: {}\n        serialization_format: cdr\n        offered_qos_profiles: \"{OFFERED_QOS}\"\n      message_count: {}\n",
                c.type_name, c.count
            );
        }
        y += "  compression_format: \"\"\n  compression_mode: \"\"\n";
        y += &format!("  relative_file_paths:\n    - {}\n", self.file_name);
        y += &format!(
            "  files:\n    - path: {}\n      starting_time:\n        nanoseconds_since_epoch: {start}\n      duration:\n        nanoseconds: {duration}\n      message_count: {total}\n",
            self.file_name
        );
        y
    }
}

impl Drop for Recorder {
    fn drop(&mut self) {
        if let Err(e) = self.finish() {
            eprintln!("slosh: {e}");
        }
    }
}

/// Records one observed state of `slosh run`: the outputs on `/wrench`, `/probes`, `/pressures` and the
/// motion that drove the tank on `/motion/odom`, all at the simulation time `o.time`.
pub fn record_state(
    rec: &mut Recorder,
    params: &sph::params::SimParams,
    tank_frame: &str,
    o: &sph::observe::Observation,
    motion: &dyn sph::motion::TankMotion,
) -> Result<(), RecordError> {
    let stamp = slosh_msgs::builtin_interfaces::Time::from_secs_f64(o.time);
    let m = crate::ros::node::output_messages(params, tank_frame, stamp, o);
    let odom = crate::ros::motion_pub::odometry(&motion.state(o.time), stamp, "world", tank_frame);
    rec.write("/motion/odom", stamp, &odom)?;
    rec.write_outputs(&output_topics(), stamp, &m)
}

/// The topics `slosh run` and `slosh replay` record the outputs on: wrench, probes, pressures.
pub fn output_topics() -> [String; 3] {
    ["/wrench", "/probes", "/pressures"].map(String::from)
}

/// What [`repair`] recovered.
#[derive(Debug, Clone, PartialEq)]
pub struct Repaired {
    pub messages: u64,
    pub topics: usize,
    /// Why reading stopped before a proper end, if it did.
    pub stopped: Option<String>,
}

/// Makes a whole bag from a damaged or unfinished MCAP (a bag folder or the file): every message of the
/// complete chunks, up to the first damaged record, is written to a new bag folder `out`.
pub fn repair(input: &Path, out: &Path) -> Result<Repaired, RecordError> {
    let file = if input.is_dir() {
        std::fs::read_dir(input)
            .ok()
            .and_then(|d| {
                d.filter_map(|e| e.ok().map(|e| e.path()))
                    .find(|p| p.extension().is_some_and(|x| x == "mcap"))
            })
            .ok_or_else(|| RecordError::Path {
                path: input.display().to_string(),
                message: "no .mcap file in this folder".into(),
            })?
    } else {
        input.to_path_buf()
    };
    let bytes = std::fs::read(&file).map_err(|e| RecordError::Path {
        path: file.display().to_string(),
        message: format!("cannot read: {e}"),
    })?;
    let stream =
        mcap::MessageStream::new_with_options(&bytes, mcap::read::Options::IgnoreEndMagic.into())
            .map_err(|e| RecordError::Path {
            path: file.display().to_string(),
            message: format!("not an MCAP file: {e}"),
        })?;
    let cfg = RecordCfg {
        path: out.display().to_string(),
        ..Default::default()
    };
    let mut rec = Recorder::create(
        &cfg,
        &serde_json::json!({"repaired_from": file.display().to_string()}),
    )?;
    let mut n = 0;
    let mut stopped = None;
    for m in stream {
        match m {
            Ok(m) => {
                let (name, schema) = match &m.channel.schema {
                    Some(s) => (
                        s.name.clone(),
                        String::from_utf8_lossy(&s.data).into_owned(),
                    ),
                    None => (String::new(), String::new()),
                };
                rec.write_raw(&m.channel.topic, &name, &schema, m.log_time, &m.data)?;
                n += 1;
            }
            Err(e) => {
                stopped = Some(e.to_string());
                break;
            }
        }
    }
    let topics = rec.channels.len();
    rec.finish()?;
    Ok(Repaired {
        messages: n,
        topics,
        stopped,
    })
}
