//! The log of `slosh node` and `slosh motion` as rcl's arguments set it: `--log-level LEVEL` (every logger)
//! or `--log-level NAME:=LEVEL` (the logger of that name: a node's is its namespace and name joined by dots,
//! `ship1.slosh`), `--disable-stdout-logs` (nothing on stderr) and `--disable-rosout-logs` (nothing on
//! `/rosout`). A message below the level goes nowhere. On stderr a message reads as rcutils' default console
//! format has it: `[WARN] [1733500000.123456789] [ship1.slosh]: message`; on `/rosout` it carries the same
//! logger name (so nodes of one name in different namespaces stay apart) and the file and line it was said
//! at.

use super::args::{ArgError, Names, RosArgs};
pub use ros2_client::ros2::LogLevel;

/// Parses `--log-level`'s value, `LEVEL` or `LOGGER:=LEVEL`, the level as rcutils reads one: any case,
/// `warning` for `warn`.
pub fn parse_level(v: &str) -> Result<(Option<String>, LogLevel), ArgError> {
    let (name, level) = match v.split_once(":=") {
        Some((name, level)) => (Some(name), level),
        None => (None, v),
    };
    let level = match level.to_ascii_lowercase().as_str() {
        "debug" => Some(LogLevel::Debug),
        "info" => Some(LogLevel::Info),
        "warn" | "warning" => Some(LogLevel::Warn),
        "error" => Some(LogLevel::Error),
        "fatal" => Some(LogLevel::Fatal),
        _ => None,
    };
    match (name, level) {
        (Some(""), _) | (_, None) => Err(ArgError(format!(
            "`--log-level {v}`: expected LEVEL or LOGGER:=LEVEL, the level debug, info, warn, error or fatal (any case)"
        ))),
        (name, Some(level)) => Ok((name.map(String::from), level)),
    }
}

/// Where a process's messages go, and from which level.
#[derive(Debug, Clone, PartialEq)]
pub struct Logger {
    /// The logger's name, as rcl names a node's: `ship1.slosh`.
    name: String,
    /// The least severe level said.
    level: LogLevel,
    stderr: bool,
    rosout: bool,
}

impl Logger {
    /// The logger of the node `names` names, set by `args`: its own `NAME:=LEVEL` wins over a plain level;
    /// info when neither is given.
    pub fn new(args: &RosArgs, names: &Names) -> Self {
        let own = names.logger_name();
        let named = args
            .log_levels
            .iter()
            .rev()
            .find(|(n, _)| n.as_deref() == Some(own.as_str()));
        let plain = args.log_levels.iter().rev().find(|(n, _)| n.is_none());
        Self {
            name: own,
            level: named.or(plain).map_or(LogLevel::Info, |(_, l)| *l),
            stderr: !args.disable_stdout_logs,
            rosout: !args.disable_rosout_logs,
        }
    }

    /// Whether a message of `level` is said at all.
    pub fn enabled(&self, level: LogLevel) -> bool {
        level >= self.level
    }

    /// Whether a message of `level` goes to `/rosout`.
    pub fn to_rosout(&self, level: LogLevel) -> bool {
        self.rosout && self.enabled(level)
    }

    /// Whether the node publishes on `/rosout` at all.
    pub fn rosout(&self) -> bool {
        self.rosout
    }

    /// Says `msg` on stderr and on `/rosout` from `node`, where `level` is said.
    #[track_caller]
    pub fn log(&self, node: &ros2_client::Node, level: LogLevel, msg: &str) {
        self.say(level, msg);
        if self.to_rosout(level) {
            let at = std::panic::Location::caller();
            ros2_client::rosout::RosoutRaw::rosout_raw(
                node,
                ros2_client::builtin_interfaces::Time::now(),
                level,
                &self.name,
                msg,
                at.file(),
                "",
                at.line(),
            );
        }
    }

    /// Writes `msg` on stderr if `level` is said there.
    pub fn say(&self, level: LogLevel, msg: &str) {
        if self.stderr && self.enabled(level) {
            eprintln!("{}", self.line(level, msg, std::time::SystemTime::now()));
        }
    }

    /// `msg` as a console line, stamped `at`.
    fn line(&self, level: LogLevel, msg: &str, at: std::time::SystemTime) -> String {
        let since = at.duration_since(std::time::UNIX_EPOCH).unwrap_or_default();
        let severity = match level {
            LogLevel::Debug => "DEBUG",
            LogLevel::Info => "INFO",
            LogLevel::Warn => "WARN",
            LogLevel::Error => "ERROR",
            LogLevel::Fatal => "FATAL",
        };
        format!(
            "[{severity}] [{}.{:09}] [{}]: {msg}",
            since.as_secs(),
            since.subsec_nanos(),
            self.name
        )
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ros::args::parse;

    fn logger(a: &str) -> Logger {
        let args: Vec<String> = a.split_whitespace().map(String::from).collect();
        let (_, r) = parse(&args).unwrap();
        let names = Names::new(&r, "slosh").unwrap();
        Logger::new(&r, &names)
    }

    #[test]
    fn the_level_and_the_outputs_follow_the_arguments() {
        let l = logger("--ros-args");
        assert!(l.enabled(LogLevel::Info) && !l.enabled(LogLevel::Debug));
        assert!(l.rosout() && l.to_rosout(LogLevel::Info));
        let l = logger("--ros-args --log-level WARNING");
        assert!(!l.enabled(LogLevel::Info) && l.enabled(LogLevel::Warn));
        assert!(l.enabled(LogLevel::Fatal) && !l.to_rosout(LogLevel::Info));
        let l = logger("--ros-args --log-level debug --disable-rosout-logs");
        assert!(l.enabled(LogLevel::Debug) && !l.rosout() && !l.to_rosout(LogLevel::Fatal));
        // The node's own logger (namespace and name joined by dots) wins over a plain level, in any order;
        // another logger's level changes nothing here.
        let l =
            logger("--ros-args -r __ns:=/ship1 --log-level ship1.slosh:=error --log-level debug");
        assert!(!l.enabled(LogLevel::Warn) && l.enabled(LogLevel::Error));
        let l = logger("--ros-args -r __ns:=/ship1 --log-level other:=debug");
        assert!(!l.enabled(LogLevel::Debug) && l.enabled(LogLevel::Info));
        let l = logger("--ros-args --log-level slosh:=fatal");
        assert!(!l.enabled(LogLevel::Error));
        // The last of two plain levels counts, as in rcl.
        assert!(logger("--ros-args --log-level error --log-level info").enabled(LogLevel::Info));
    }

    #[test]
    fn a_line_reads_as_rcutils_writes_it() {
        let at = std::time::UNIX_EPOCH + std::time::Duration::new(1_733_500_000, 1_234);
        let l = logger("--ros-args -r __ns:=/ship1");
        assert_eq!(
            l.line(LogLevel::Warn, "holding the last pose", at),
            "[WARN] [1733500000.000001234] [ship1.slosh]: holding the last pose"
        );
        assert!(logger("--ros-args")
            .line(LogLevel::Info, "x", at)
            .starts_with("[INFO] [1733500000.000001234] [slosh]: "));
    }

    #[test]
    fn a_bad_level_is_refused_naming_the_levels() {
        for a in [
            "--ros-args --log-level verbose",
            "--ros-args --log-level slosh:=loud",
        ] {
            let args: Vec<String> = a.split_whitespace().map(String::from).collect();
            let e = parse(&args).unwrap_err().to_string();
            // The whole value named, with what it may be.
            assert!(e.contains("debug, info, warn, error or fatal"), "{e}");
            assert!(e.contains(a.trim_start_matches("--ros-args ")), "{e}");
        }
        let args: Vec<String> = ["--ros-args", "--log-level", ":=info"]
            .map(String::from)
            .into();
        assert!(parse(&args)
            .unwrap_err()
            .to_string()
            .contains("LOGGER:=LEVEL"));
    }
}
