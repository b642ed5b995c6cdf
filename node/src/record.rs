//! Recording to a rosbag2 folder: one MCAP file (profile `ros2`, `ros2msg` schemas with their dependencies,
//! `cdr` payloads, chunked and zstd-compressed) plus the `metadata.yaml` that `ros2 bag` and rosbags read. The
//! run's parameters go in an MCAP metadata record named `slosh_parameters`, so a bag documents its own case.
//!
//! [`Recorder::finish`] writes the summary and `metadata.yaml`; dropping an unfinished recorder finishes it, so
//! a run that stops on an error still leaves a readable bag.

use crate::config::{ChosenBy, RecordCfg};
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::RosMessage;
use std::collections::BTreeMap;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

#[derive(Debug, thiserror::Error)]
pub enum RecordError {
    /// The bag folder (or, for `bag repair`, the damaged input) cannot be used; `what` names where it was
    /// given.
    #[error("{what} {path}: {message}")]
    Path {
        what: &'static str,
        path: String,
        message: String,
    },
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
    /// Added to every log time given (see [`Recorder::continue_from`]).
    shift_ns: i64,
    /// `flush_interval_s` in ns (0: off), and the log time of the last chunk written out.
    flush_ns: u64,
    flushed_ns: Option<u64>,
}

/// A message serialized for the recording, to be written once its log time is known.
#[derive(Debug, Clone)]
pub struct RawMessage {
    pub topic: String,
    /// `pkg/msg/Type`.
    pub type_name: String,
    /// Its `ros2msg` schema text.
    pub schema: String,
    /// CDR, with the encapsulation header.
    pub data: Vec<u8>,
}

impl RawMessage {
    pub fn of<M: RosMessage>(topic: &str, msg: &M) -> Self {
        Self {
            topic: topic.to_string(),
            type_name: format!("{}/msg/{}", M::PACKAGE, M::NAME),
            schema: M::ros2msg_schema(),
            data: slosh_msgs::to_cdr(msg),
        }
    }
}

/// The name of the MCAP metadata record that documents a recording's run.
pub const PARAMETERS_RECORD: &str = "slosh_parameters";

/// The entries of the [`PARAMETERS_RECORD`] for a run's parameters, as JSON: those given under
/// `parameters`, every parameter as run (defaults included) under `effective_parameters`.
pub fn parameters_metadata(
    parameters: &serde_json::Value,
    effective: &serde_json::Value,
) -> BTreeMap<String, String> {
    BTreeMap::from([
        ("parameters".to_string(), parameters.to_string()),
        ("effective_parameters".to_string(), effective.to_string()),
    ])
}

impl Recorder {
    /// Creates the rosbag2 folder `cfg.path` (which must not exist yet, or be empty) and its MCAP file.
    /// `parameters` and `effective` go in the [`PARAMETERS_RECORD`] ([`parameters_metadata`]).
    pub fn create(
        cfg: &RecordCfg,
        parameters: &serde_json::Value,
        effective: &serde_json::Value,
    ) -> Result<Self, RecordError> {
        Self::create_with_metadata(cfg, parameters_metadata(parameters, effective))
    }

    /// [`Recorder::create`] with the [`PARAMETERS_RECORD`]'s entries given whole.
    pub fn create_with_metadata(
        cfg: &RecordCfg,
        meta: BTreeMap<String, String>,
    ) -> Result<Self, RecordError> {
        let dir = PathBuf::from(&cfg.path);
        let err = |message: String| RecordError::Path {
            what: cfg.chosen_by.label(),
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
            return Err(err(format!(
                "already exists and is not empty: {} (a bag is never overwritten)",
                cfg.chosen_by.choose_another()
            )));
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
            .chunk_size(Some(cfg.chunk_size))
            .create(BufWriter::new(file))
            .map_err(|e| err(format!("cannot start the MCAP file: {}", with_causes(&e))))?;
        writer
            .write_metadata(&mcap::records::Metadata {
                name: PARAMETERS_RECORD.into(),
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
            shift_ns: 0,
            flush_ns: (cfg.flush_interval_s.max(0.0) * 1e9) as u64,
            flushed_ns: None,
        })
    }

    fn write_err(&self, e: impl std::fmt::Display) -> RecordError {
        write_error(&self.dir, e)
    }

    /// Records `msg` on `topic` at `log_time` (ROS time, shifted as [`Recorder::continue_from`] says;
    /// negative times are written as 0).
    pub fn write<M: RosMessage>(
        &mut self,
        topic: &str,
        log_time: Time,
        msg: &M,
    ) -> Result<(), RecordError> {
        let raw = RawMessage::of(topic, msg);
        self.write_message(&raw, log_time)
    }

    /// Records a serialized message at `log_time` (shifted as [`Recorder::continue_from`] says).
    pub fn write_message(&mut self, m: &RawMessage, log_time: Time) -> Result<(), RecordError> {
        let ns = log_time.as_nanos().saturating_add(self.shift_ns).max(0) as u64;
        self.write_raw(&m.topic, &m.type_name, &m.schema, ns, &m.data)
    }

    /// Records a serialized message at the latest log time written so far (`log_time`, shifted, when nothing
    /// has been written yet): for input the node refused, whose own stamp (an hour ahead, or on another time
    /// base) would put it out of the recording's order and stretch its duration.
    pub fn write_message_now(&mut self, m: &RawMessage, log_time: Time) -> Result<(), RecordError> {
        if self.start_ns.is_none() {
            return self.write_message(m, log_time);
        }
        self.write_raw(&m.topic, &m.type_name, &m.schema, self.end_ns, &m.data)
    }

    /// From now on every log time given is shifted so that `log_time` comes right after the latest log time
    /// written so far: a node whose input restarted on an earlier time base (whose outputs' stamps follow it
    /// back) keeps its recording's log times going forward, so players and `slosh replay` read the
    /// recording in the order it happened. The messages' header stamps are left as they are.
    pub fn continue_from(&mut self, log_time: Time) {
        if self.start_ns.is_some() {
            self.shift_ns = (self.end_ns as i64 + 1).saturating_sub(log_time.as_nanos());
        }
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
        // A chunk open for `flush_interval_s` of log time is written out (a hard kill loses only it).
        let since = *self.flushed_ns.get_or_insert(log_time_ns);
        if self.flush_ns > 0 && log_time_ns >= since.saturating_add(self.flush_ns) {
            writer.flush().map_err(err)?;
            self.flushed_ns = Some(log_time_ns);
        }
        Ok(())
    }

    /// Records the outputs of one state on `topics` (wrench, probes, pressures) at `log_time`, and each
    /// floating body's on `bodies/NAME/odom` and `bodies/NAME/wrench` beside the wrench topic.
    pub fn write_outputs(
        &mut self,
        topics: &[String; 3],
        log_time: Time,
        m: &crate::messages::OutputMessages,
    ) -> Result<(), RecordError> {
        self.write(&topics[0], log_time, &m.wrench)?;
        self.write(&topics[1], log_time, &m.probes)?;
        self.write(&topics[2], log_time, &m.pressures)?;
        let base = topics[0].rsplit_once('/').map_or("", |(ns, _)| ns);
        for b in &m.bodies {
            let topic = |what| format!("{base}/{}", crate::messages::body_topic(&b.name, what));
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
        // An empty list is written `[]`: a bare key would read as null, which rosbags refuses.
        y += &format!(
            "  message_count: {total}\n  topics_with_message_count:{}\n",
            if self.channels.is_empty() { " []" } else { "" }
        );
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

/// Records one output of `slosh run`: its messages on `/wrench`, `/probes`, `/pressures` and the tank's
/// `motion` up to it on `/motion/odom`, all at `stamp` (the simulation time).
pub fn record_state(
    rec: &mut Recorder,
    tank_frame: &str,
    stamp: Time,
    m: &crate::messages::OutputMessages,
    motion: &sph::motion::RigidState,
) -> Result<(), RecordError> {
    let odom = crate::messages::motion::odometry(motion, stamp, "world", tank_frame);
    rec.write("/motion/odom", stamp, &odom)?;
    rec.write_outputs(&output_topics(), stamp, m)
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
    /// MCAP files read.
    pub files: usize,
    /// Why reading stopped before a proper end, if it did.
    pub stopped: Option<String>,
}

/// Makes a whole bag from a damaged or unfinished MCAP bag (a bag folder, split or not, or one `.mcap`
/// file): every message of the complete chunks of each file, up to its first damaged record, is written in
/// order to a new bag folder `out`. A file that is not MCAP at all is an error (nothing is written).
pub fn repair(input: &Path, out: &Path) -> Result<Repaired, RecordError> {
    let bad = |path: &Path, message: String| RecordError::Path {
        what: "bag",
        path: path.display().to_string(),
        message,
    };
    let files = repair_inputs(input).map_err(|m| bad(input, m))?;
    // Every file is checked before the new bag is made: nothing is written for a file that is not MCAP.
    for file in &files {
        let mut head = Vec::with_capacity(mcap::MAGIC.len());
        std::fs::File::open(file)
            .and_then(|f| {
                use std::io::Read;
                f.take(mcap::MAGIC.len() as u64).read_to_end(&mut head)
            })
            .map_err(|e| bad(file, format!("cannot read: {e}")))?;
        if head != mcap::MAGIC {
            return Err(bad(
                file,
                "not an MCAP file (it does not start with the MCAP magic bytes)".into(),
            ));
        }
    }
    let cfg = RecordCfg {
        path: out.display().to_string(),
        chosen_by: ChosenBy::RepairOut,
        ..Default::default()
    };
    // The damaged bag's own parameters record, where it survived (it is written first), goes with it.
    let mut meta = files
        .first()
        .and_then(|f| surviving_parameters(f))
        .unwrap_or_default();
    meta.insert("repaired_from".into(), input.display().to_string());
    let mut rec = Recorder::create_with_metadata(&cfg, meta)?;
    let mut n = 0;
    let mut stops = Vec::new();
    for file in &files {
        // One file mapped at a time (split bags may be large).
        let f = std::fs::File::open(file).map_err(|e| bad(file, format!("cannot open: {e}")))?;
        // SAFETY: the map is only read, while this loop runs; a file changed underneath by another process
        // reads as damaged to the MCAP reader's checks, not as valid messages.
        let bytes =
            unsafe { memmap2::Mmap::map(&f) }.map_err(|e| bad(file, format!("cannot map: {e}")))?;
        // A damaged chunk (an impossible size, records that do not fit) ends what is recovered (the reader would try to allocate what it claims).
        let (readable, damaged) = crate::mcap_bounds::readable(&bytes);
        let stream = mcap::MessageStream::new_with_options(
            readable,
            mcap::read::Options::IgnoreEndMagic.into(),
        )
        .map_err(|e| bad(file, format!("not an MCAP file: {e}")))?;
        let mut stopped = false;
        let where_ = |file: &Path, why: String| {
            if files.len() > 1 {
                format!("{}: {why}", file.display())
            } else {
                why
            }
        };
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
                    // (Where a chunk was damaged the read part ends there: that is why.)
                    let why = damaged.map_or_else(|| e.to_string(), |o| o.to_string());
                    stops.push(where_(file, why));
                    stopped = true;
                    break;
                }
            }
        }
        if let (false, Some(o)) = (stopped, damaged) {
            stops.push(where_(file, o.to_string()));
        }
    }
    let topics = rec.channels.len();
    rec.finish()?;
    if n == 0 {
        // An empty bag would pass for a repaired one.
        let _ = std::fs::remove_dir_all(out);
        return Err(bad(
            input,
            format!(
                "no whole message to recover{}; no bag written",
                if stops.is_empty() {
                    String::new()
                } else {
                    format!(" ({})", stops.join("; "))
                }
            ),
        ));
    }
    Ok(Repaired {
        messages: n,
        topics,
        files: files.len(),
        stopped: (!stops.is_empty()).then(|| stops.join("; ")),
    })
}

/// The entries of `file`'s [`PARAMETERS_RECORD`], read record by record up to the first damaged one (an
/// unfinished file has no summary to find it by).
fn surviving_parameters(file: &Path) -> Option<BTreeMap<String, String>> {
    let f = std::fs::File::open(file).ok()?;
    // SAFETY: only read while this function runs (as in `repair`).
    let bytes = unsafe { memmap2::Mmap::map(&f) }.ok()?;
    let (readable, _) = crate::mcap_bounds::readable(&bytes);
    let reader = mcap::read::LinearReader::new_with_options(
        readable,
        mcap::read::Options::IgnoreEndMagic.into(),
    )
    .ok()?;
    for record in reader {
        match record {
            Ok(mcap::records::Record::Metadata(m)) if m.name == PARAMETERS_RECORD => {
                return Some(m.metadata)
            }
            Ok(_) => {}
            Err(_) => return None,
        }
    }
    None
}

/// The MCAP files to repair, in order: the one file given; a bag folder's files in the order its
/// `metadata.yaml` lists them; without a readable `metadata.yaml` (a recording killed before it wrote one),
/// the folder's `.mcap` files in the order rosbag2 numbers them (`NAME_0.mcap`, `NAME_1.mcap`, ...).
fn repair_inputs(input: &Path) -> Result<Vec<PathBuf>, String> {
    if !input.exists() {
        return Err("no such file or folder (give a bag folder or an .mcap file)".into());
    }
    if input.is_file() {
        return Ok(vec![input.to_path_buf()]);
    }
    if let Ok(files) = crate::bag::files(input) {
        return Ok(files);
    }
    let mut mcaps: Vec<PathBuf> = std::fs::read_dir(input)
        .map_err(|e| format!("cannot list: {e}"))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "mcap"))
        .collect();
    if mcaps.is_empty() {
        return Err("no .mcap file in this folder".into());
    }
    // rosbag2's split files end in _<index>: order by that number, then by name.
    let index = |p: &PathBuf| {
        p.file_stem()
            .and_then(|s| s.to_str())
            .and_then(|s| s.rsplit_once('_'))
            .and_then(|(_, i)| i.parse::<u64>().ok())
            .unwrap_or(u64::MAX)
    };
    mcaps.sort_by(|a, b| index(a).cmp(&index(b)).then_with(|| a.cmp(b)));
    Ok(mcaps)
}

#[cfg(test)]
mod tests {
    use super::*;
    use slosh_msgs::geometry_msgs::Vector3;

    fn tmp(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("slosh-record-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A finished bag in `dir` with one /v message per time in `times` (x = the time).
    fn bag(dir: &Path, times: &[i32]) -> PathBuf {
        let cfg = RecordCfg {
            path: dir.display().to_string(),
            ..Default::default()
        };
        let mut r = Recorder::create(&cfg, &serde_json::json!({}), &serde_json::json!({})).unwrap();
        for &t in times {
            let v = Vector3 {
                x: t as f64,
                y: 0.0,
                z: 0.0,
            };
            r.write("/v", Time { sec: t, nanosec: 0 }, &v).unwrap();
        }
        r.finish().unwrap();
        dir.join(format!(
            "{}_0.mcap",
            dir.file_name().unwrap().to_string_lossy()
        ))
    }

    /// The log times (s) of the messages of the MCAP files of the bag folder `dir`, read by the `mcap` crate.
    fn times(dir: &Path) -> Vec<u64> {
        let mut out = Vec::new();
        for f in crate::bag::files(dir).unwrap() {
            let bytes = std::fs::read(f).unwrap();
            for m in mcap::MessageStream::new(&bytes).unwrap() {
                out.push(m.unwrap().log_time / 1_000_000_000);
            }
        }
        out
    }

    #[test]
    fn repair_refuses_a_file_that_is_not_mcap() {
        let d = tmp("not-mcap");
        for (name, content) in [("text.mcap", &b"hello, not a bag"[..]), ("empty.mcap", b"")] {
            let f = d.join(name);
            std::fs::write(&f, content).unwrap();
            let out = d.join(format!("{name}_repaired"));
            let e = repair(&f, &out).unwrap_err().to_string();
            assert!(
                e.starts_with("bag ") && e.contains("not an MCAP file"),
                "{e}"
            );
            assert!(!out.exists(), "nothing written for {name}");
        }
        let e = repair(&d.join("missing.mcap"), &d.join("x"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("missing.mcap: no such file or folder"), "{e}");
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn a_damaged_file_of_a_split_bag_is_repaired_with_its_folder() {
        let d = tmp("split-hint");
        let split = d.join("split");
        std::fs::create_dir_all(&split).unwrap();
        for (i, ts) in [(0, &[1, 2][..]), (1, &[3, 4, 5])] {
            let f = bag(&d.join(format!("part{i}")), ts);
            std::fs::rename(f, split.join(format!("split_{i}.mcap"))).unwrap();
        }
        let first = split.join("split_0.mcap");
        let bytes = std::fs::read(&first).unwrap();
        std::fs::write(&first, &bytes[..bytes.len() * 2 / 3]).unwrap();
        let files = [first.clone(), split.join("split_1.mcap")];
        let e = crate::bag::for_each_message(&files, |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("`slosh bag repair {}`", split.display())),
            "{e}"
        );
        // One file alone: that file.
        let e = crate::bag::for_each_message(&files[..1], |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("`slosh bag repair {}`", first.display())),
            "{e}"
        );
        // One file of a rosbag2 folder (with its metadata.yaml): the folder, which repair copies beside it
        // (repairing the file would write the new bag inside the damaged one's folder).
        std::fs::write(
            split.join("metadata.yaml"),
            "rosbag2_bagfile_information: {}\n",
        )
        .unwrap();
        let e = crate::bag::for_each_message(&files[..1], |_| Ok(()))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains(&format!("`slosh bag repair {}`", split.display())),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn repair_that_recovers_nothing_fails_and_writes_nothing() {
        let d = tmp("nothing");
        let f = bag(&d.join("whole"), &[1, 2, 3]);
        let cut = d.join("cut.mcap");
        std::fs::write(&cut, &std::fs::read(&f).unwrap()[..100]).unwrap();
        let out = d.join("cut_repaired");
        let e = repair(&cut, &out).unwrap_err().to_string();
        assert!(
            e.contains("cut.mcap: no whole message to recover") && e.contains("no bag written"),
            "{e}"
        );
        assert!(!out.exists());
        let _ = std::fs::remove_dir_all(&d);
    }

    #[test]
    fn repair_reads_every_file_of_a_split_bag_in_order() {
        let d = tmp("split");
        // Three files of a killed split recording (no metadata.yaml), numbered as rosbag2 does: _10 after _2.
        let split = d.join("split");
        std::fs::create_dir_all(&split).unwrap();
        for (i, ts) in [(0, &[1, 2][..]), (2, &[3, 4, 5]), (10, &[6])] {
            let f = bag(&d.join(format!("part{i}")), ts);
            std::fs::rename(f, split.join(format!("split_{i}.mcap"))).unwrap();
        }
        // The last file cut short inside its summary: its messages are still whole.
        let last = split.join("split_10.mcap");
        let len = std::fs::metadata(&last).unwrap().len();
        let bytes = std::fs::read(&last).unwrap();
        std::fs::write(&last, &bytes[..len as usize - 20]).unwrap();
        let out = d.join("repaired");
        let r = repair(&split, &out).unwrap();
        assert_eq!((r.messages, r.topics, r.files), (6, 1, 3), "{r:?}");
        assert_eq!(times(&out), vec![1, 2, 3, 4, 5, 6]);
        // A second repair into the same folder is refused, naming the option to change.
        let e = repair(&split, &out).unwrap_err().to_string();
        assert!(
            e.contains("the repaired bag (--out)") && e.contains("choose another --out"),
            "{e}"
        );
        let _ = std::fs::remove_dir_all(&d);
    }
}
