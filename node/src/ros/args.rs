//! The ROS 2 command-line arguments a node accepts after `--ros-args` (as `rcl` parses them): parameter files,
//! `-p name:=value`, remapping rules `-r from:=to` (including `__ns` and `__node`), `--log-level` and the
//! log's outputs (applied by [`super::logging`]), and `--enclave` (accepted and ignored: the enclave is
//! `ROS_SECURITY_ENCLAVE_OVERRIDE`'s). Names are resolved and remapped here, since ros2-client does neither.

use std::fmt;

/// What came after `--ros-args`.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct RosArgs {
    /// `--params-file FILE`, in order (later files override earlier ones).
    pub params_files: Vec<String>,
    /// `-p name:=value`, as `name=value` overrides (the value is YAML, as in ROS).
    pub params: Vec<String>,
    /// `-r from:=to` topic and service remaps.
    pub remaps: Vec<(String, String)>,
    /// `-r __ns:=/ns`.
    pub namespace: Option<String>,
    /// `-r __node:=name`.
    pub node_name: Option<String>,
    /// `--log-level LEVEL` (None) and `--log-level NAME:=LEVEL` (the logger's name), in order.
    pub log_levels: Vec<(Option<String>, super::logging::LogLevel)>,
    /// `--disable-stdout-logs` (undone by a later `--enable-stdout-logs`).
    pub disable_stdout_logs: bool,
    /// `--disable-rosout-logs`.
    pub disable_rosout_logs: bool,
}

/// A malformed argument, with what was expected.
#[derive(Debug, Clone, PartialEq)]
pub struct ArgError(pub String);

impl fmt::Display for ArgError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "--ros-args: {}", self.0)
    }
}

impl std::error::Error for ArgError {}

/// Parses the arguments of a node. Plain arguments before `--ros-args` are returned apart; `--` or a second
/// `--ros-args` section works as in rcl.
pub fn parse(args: &[String]) -> Result<(Vec<String>, RosArgs), ArgError> {
    let mut plain = Vec::new();
    let mut out = RosArgs::default();
    let mut in_ros = false;
    let mut i = 0;
    let next = |i: &mut usize, flag: &str| -> Result<String, ArgError> {
        *i += 1;
        args.get(*i)
            .cloned()
            .ok_or_else(|| ArgError(format!("`{flag}` needs a value")))
    };
    while i < args.len() {
        let a = args[i].as_str();
        if a == "--ros-args" {
            in_ros = true;
        } else if a == "--" && in_ros {
            in_ros = false;
        } else if !in_ros {
            plain.push(a.to_string());
        } else {
            match a {
                "--params-file" => out.params_files.push(next(&mut i, a)?),
                "-p" | "--param" => {
                    let v = next(&mut i, a)?;
                    let (k, val) = split_assignment(&v, a)?;
                    out.params.push(format!("{k}={val}"));
                }
                "-r" | "--remap" => {
                    let v = next(&mut i, a)?;
                    let (from, to) = split_assignment(&v, a)?;
                    // A rule may be limited to one node: `node_name:from:=to`; we keep the node part to check
                    // once the node's name is known.
                    match from {
                        "__ns" => out.namespace = Some(to.to_string()),
                        "__node" | "__name" => out.node_name = Some(to.to_string()),
                        _ => out.remaps.push((from.to_string(), to.to_string())),
                    }
                }
                "--log-level" => {
                    let v = next(&mut i, a)?;
                    out.log_levels.push(super::logging::parse_level(&v)?);
                }
                "-e" | "--enclave" => {
                    next(&mut i, a)?;
                }
                "--disable-rosout-logs" => out.disable_rosout_logs = true,
                "--disable-stdout-logs" => out.disable_stdout_logs = true,
                "--enable-stdout-logs" => out.disable_stdout_logs = false,
                other => {
                    return Err(ArgError(format!(
                        "unknown argument `{other}` (accepted: --params-file FILE, -p name:=value, -r from:=to, -r __ns:=/ns, -r __node:=name, --log-level [LOGGER:=]LEVEL, --disable-stdout-logs, --disable-rosout-logs){}",
                        if other.starts_with("--") {
                            "; slosh's own options, such as --duration, go before --ros-args (or after a closing --)"
                        } else {
                            ""
                        }
                    )))
                }
            }
        }
        i += 1;
    }
    if let Some(ns) = &out.namespace {
        check_namespace(ns)?;
    }
    if let Some(n) = &out.node_name {
        check_base(n, "__node")?;
    }
    Ok((plain, out))
}

fn split_assignment<'a>(v: &'a str, flag: &str) -> Result<(&'a str, &'a str), ArgError> {
    v.split_once(":=")
        .filter(|(k, _)| !k.is_empty())
        .ok_or_else(|| ArgError(format!("`{flag} {v}`: expected name:=value")))
}

fn check_base(s: &str, what: &str) -> Result<(), ArgError> {
    let ok = !s.is_empty()
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !s.starts_with(|c: char| c.is_ascii_digit())
        && !s.contains("__");
    if ok {
        Ok(())
    } else {
        Err(ArgError(format!(
            "{what}: `{s}` is not a valid ROS name (letters, digits and single underscores, not starting with a digit)"
        )))
    }
}

fn check_namespace(ns: &str) -> Result<(), ArgError> {
    if !ns.starts_with('/') {
        return Err(ArgError(format!(
            "__ns: `{ns}` must be absolute (start with `/`)"
        )));
    }
    if ns == "/" {
        return Ok(());
    }
    for part in ns[1..].split('/') {
        check_base(part, "__ns")?;
    }
    Ok(())
}

/// Resolves topic and service names of one node the way rcl does, then applies the remaps.
#[derive(Debug, Clone)]
pub struct Names {
    pub namespace: String,
    pub node: String,
    remaps: Vec<(String, String)>,
}

impl Names {
    pub fn new(args: &RosArgs, default_node: &str) -> Result<Self, ArgError> {
        let namespace = args
            .namespace
            .clone()
            .unwrap_or_else(|| "/".into())
            .trim_end_matches('/')
            .to_string();
        let namespace = if namespace.is_empty() {
            "/".to_string()
        } else {
            namespace
        };
        let node = args
            .node_name
            .clone()
            .unwrap_or_else(|| default_node.into());
        let mut names = Self {
            namespace,
            node,
            remaps: Vec::new(),
        };
        for (from, to) in &args.remaps {
            // `node:from:=to` applies only to that node.
            let from = match from.split_once(':') {
                Some((n, f)) if n == names.node => f,
                Some(_) => continue,
                None => from.as_str(),
            };
            let r = (names.expand(from)?, names.expand(to)?);
            names.remaps.push(r);
        }
        Ok(names)
    }

    /// The node's fully qualified name, `/namespace/node` (`/node` in the root namespace).
    pub fn node_fqn(&self) -> String {
        if self.namespace == "/" {
            format!("/{}", self.node)
        } else {
            format!("{}/{}", self.namespace, self.node)
        }
    }

    /// The node's logger name as rcl names it: the namespace and the node joined by dots (`ship1.slosh`).
    pub fn logger_name(&self) -> String {
        self.node_fqn().trim_start_matches('/').replace('/', ".")
    }

    /// The fully qualified name without remapping: relative names go under the namespace, `~` is the node.
    fn expand(&self, name: &str) -> Result<String, ArgError> {
        let ns = if self.namespace == "/" {
            ""
        } else {
            &self.namespace
        };
        let full = if let Some(rest) = name.strip_prefix("~/") {
            format!("{ns}/{}/{rest}", self.node)
        } else if name == "~" {
            format!("{ns}/{}", self.node)
        } else if name.starts_with('/') {
            name.to_string()
        } else {
            format!("{ns}/{name}")
        };
        if full.len() < 2 || full.ends_with('/') || full.contains("//") {
            return Err(ArgError(format!("`{name}` is not a valid topic name")));
        }
        for part in full[1..].split('/') {
            check_base(part, "topic name")?;
        }
        Ok(full)
    }

    /// The name a topic or service `name` gets on the graph, after remapping (first matching rule wins).
    pub fn resolve(&self, name: &str) -> Result<String, ArgError> {
        let full = self.expand(name)?;
        Ok(self
            .remaps
            .iter()
            .find(|(from, _)| *from == full)
            .map(|(_, to)| to.clone())
            .unwrap_or(full))
    }

    /// The resolved name split into (namespace, base) as ros2-client's `Name::new` wants them.
    pub fn split(&self, name: &str) -> Result<(String, String), ArgError> {
        let full = self.resolve(name)?;
        let (ns, base) = full.rsplit_once('/').expect("resolved names are absolute");
        Ok((
            if ns.is_empty() { "/".into() } else { ns.into() },
            base.into(),
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn args(s: &str) -> Vec<String> {
        s.split_whitespace().map(String::from).collect()
    }

    #[test]
    fn parses_the_rcl_arguments() {
        let (plain, r) = parse(&args(
            "--ros-args --params-file a.yaml -p solver.cfl:=0.15 -r motion/odom:=/ship/odom -r __ns:=/ship1 -r __node:=tank2 --log-level debug",
        ))
        .unwrap();
        assert!(plain.is_empty());
        assert_eq!(r.params_files, ["a.yaml"]);
        assert_eq!(r.params, ["solver.cfl=0.15"]);
        assert_eq!(
            r.remaps,
            [("motion/odom".to_string(), "/ship/odom".to_string())]
        );
        assert_eq!(r.namespace.as_deref(), Some("/ship1"));
        assert_eq!(r.node_name.as_deref(), Some("tank2"));
        assert_eq!(
            r.log_levels,
            [(None, super::super::logging::LogLevel::Debug)]
        );
        let (plain, _) = parse(&args("--x 1 --ros-args -p a:=1 -- tail")).unwrap();
        assert_eq!(plain, ["--x", "1", "tail"]);
    }

    #[test]
    fn rejects_malformed_arguments_by_name() {
        assert!(parse(&args("--ros-args -p cfl=0.1"))
            .unwrap_err()
            .0
            .contains("name:=value"));
        assert!(parse(&args("--ros-args --params-file"))
            .unwrap_err()
            .0
            .contains("needs a value"));
        assert!(parse(&args("--ros-args --bogus"))
            .unwrap_err()
            .0
            .contains("unknown argument `--bogus`"));
        assert!(parse(&args("--ros-args --duration 2"))
            .unwrap_err()
            .0
            .contains("--duration, go before --ros-args"));
        assert!(parse(&args("--ros-args -r __ns:=ship"))
            .unwrap_err()
            .0
            .contains("absolute"));
        assert!(parse(&args("--ros-args -r __node:=a-b"))
            .unwrap_err()
            .0
            .contains("not a valid ROS name"));
    }

    #[test]
    fn resolves_and_remaps_like_rcl() {
        let (_, r) = parse(&args(
            "--ros-args -r __ns:=/ship1 -r __node:=tank2 -r motion/odom:=/nav/odom -r other:x:=y -r tank2:wrench:=loads/wrench",
        ))
        .unwrap();
        let n = Names::new(&r, "slosh").unwrap();
        assert_eq!(n.resolve("motion/odom").unwrap(), "/nav/odom");
        assert_eq!(n.resolve("probes").unwrap(), "/ship1/probes");
        assert_eq!(n.resolve("wrench").unwrap(), "/ship1/loads/wrench");
        assert_eq!(n.resolve("x").unwrap(), "/ship1/x");
        assert_eq!(n.resolve("~/reset").unwrap(), "/ship1/tank2/reset");
        assert_eq!(n.resolve("/diagnostics").unwrap(), "/diagnostics");
        assert_eq!(
            n.split("motion/imu").unwrap(),
            ("/ship1/motion".to_string(), "imu".to_string())
        );
        let root = Names::new(&RosArgs::default(), "slosh").unwrap();
        assert_eq!(root.resolve("wrench").unwrap(), "/wrench");
        assert_eq!(root.split("wrench").unwrap(), ("/".into(), "wrench".into()));
        assert!(root.resolve("a//b").is_err());
    }
}
