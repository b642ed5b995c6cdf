//! The node's parameters as ROS 2 parameters: the six `rcl_interfaces` services every rclcpp node serves
//! (`~/list_parameters`, `~/get_parameters`, `~/get_parameter_types`, `~/describe_parameters`,
//! `~/set_parameters`, `~/set_parameters_atomically`) read and change a [`Parameters`] table made from the
//! effective parameters (every parameter the node runs with, defaults included, by its dotted name).
//!
//! The settings in [`LiveSettings`] change while the node runs (output and diagnostics rates, the particle cloud's
//! rate and decimation, the motion timeout); everything else shapes the simulation built at start-up and is
//! read-only: a set is refused with the reason, as rclcpp refuses a read-only parameter.

use ros2_client::parameters::raw::{
    FloatingPointRange, IntegerRange, Parameter, ParameterDescriptor, ParameterType,
    ParameterValue, SetParametersResult,
};
use ros2_client::rcl_interfaces::{
    DescribeParametersRequest, DescribeParametersResponse, GetParameterTypesRequest,
    GetParameterTypesResponse, GetParametersRequest, GetParametersResponse, ListParametersRequest,
    ListParametersResponse, ListParametersResult, SetParametersAtomicallyResponse,
    SetParametersRequest, SetParametersResponse,
};
use ros2_client::{
    MessageTypeName, Node, Publisher, QosProfile, Server, ServiceMapping, ServiceTypeName,
};
use serde::{Deserialize, Serialize};
use serde_json::Value;
use std::collections::BTreeMap;

/// The settings a running node takes from a parameter set at once.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LiveSettings {
    pub output_rate_hz: f64,
    pub diagnostics_rate_hz: f64,
    /// Particle clouds per simulated second (0: none) and every how many particles one is sent.
    pub particles_rate_hz: f64,
    pub particles_decimation: usize,
    pub motion_timeout_s: f64,
}

/// `rcl_interfaces/msg/ParameterEvent`, published on `/parameter_events` when parameters are declared (all
/// of them, at start-up) and when a set changes them.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct ParameterEvent {
    pub stamp: ros2_client::builtin_interfaces::Time,
    /// The node's fully qualified name.
    pub node: String,
    pub new_parameters: Vec<Parameter>,
    pub changed_parameters: Vec<Parameter>,
    pub deleted_parameters: Vec<Parameter>,
}

impl ros2_client::Message for ParameterEvent {}

/// A parameter that changes while the node runs: its name, what it means, its range.
struct Changeable {
    name: &'static str,
    description: &'static str,
    range: Range,
}

#[derive(Clone, Copy)]
enum Range {
    Double(f64, f64),
    Integer(i64, i64),
}

const CHANGEABLE: [Changeable; 5] = [
    Changeable {
        name: "output_rate_hz",
        description: "outputs (wrench, probes, pressures) per simulated second",
        range: Range::Double(0.01, 1000.0),
    },
    Changeable {
        name: "diagnostics_rate_hz",
        description: "diagnostics messages per wall-clock second",
        range: Range::Double(0.01, 100.0),
    },
    Changeable {
        name: "particles.rate_hz",
        description: "particle clouds per simulated second (0: none)",
        range: Range::Double(0.0, 1000.0),
    },
    Changeable {
        name: "particles.decimation",
        description: "every how many particles the cloud carries one",
        range: Range::Integer(1, 1_000_000),
    },
    Changeable {
        name: "motion_timeout_s",
        description:
            "seconds without motion input before the node holds the last pose and reports an error",
        range: Range::Double(0.01, 3600.0),
    },
];

/// Why a parameter is read-only while the node runs.
const READ_ONLY: &str = "read-only while the node runs (it shapes the simulation built at start-up): \
                         restart the node with the new value (--ros-args -p NAME:=VALUE or a parameters file)";

struct Entry {
    value: ParameterValue,
    descriptor: ParameterDescriptor,
}

/// The node's parameters by name.
pub struct Parameters {
    entries: BTreeMap<String, Entry>,
}

fn value(ptype: u8) -> ParameterValue {
    ParameterValue {
        ptype,
        boolean_value: false,
        int_value: 0,
        double_value: 0.0,
        string_value: String::new(),
        byte_array: vec![],
        bool_array: vec![],
        int_array: vec![],
        double_array: vec![],
        string_array: vec![],
    }
}

/// The ROS 2 value of a JSON value: booleans, integers, doubles, strings and arrays of one of them; null
/// (an optional parameter not given) is not set; anything else (an array of records, a mixed array) is its
/// JSON text as a string.
fn to_value(v: &Value) -> ParameterValue {
    match v {
        Value::Null => value(ParameterType::NOT_SET),
        Value::Bool(b) => ParameterValue {
            boolean_value: *b,
            ..value(ParameterType::BOOL)
        },
        Value::Number(n) if n.is_i64() => ParameterValue {
            int_value: n.as_i64().unwrap_or(0),
            ..value(ParameterType::INTEGER)
        },
        Value::Number(n) => ParameterValue {
            double_value: n.as_f64().unwrap_or(f64::NAN),
            ..value(ParameterType::DOUBLE)
        },
        Value::String(s) => ParameterValue {
            string_value: s.clone(),
            ..value(ParameterType::STRING)
        },
        Value::Array(a) if !a.is_empty() && a.iter().all(Value::is_boolean) => ParameterValue {
            bool_array: a.iter().filter_map(Value::as_bool).collect(),
            ..value(ParameterType::BOOL_ARRAY)
        },
        Value::Array(a) if !a.is_empty() && a.iter().all(|x| x.is_i64()) => ParameterValue {
            int_array: a.iter().filter_map(Value::as_i64).collect(),
            ..value(ParameterType::INTEGER_ARRAY)
        },
        // (An empty array is taken as one of doubles: the positions and amplitudes of the layout are.)
        Value::Array(a) if a.iter().all(Value::is_number) => ParameterValue {
            double_array: a.iter().filter_map(Value::as_f64).collect(),
            ..value(ParameterType::DOUBLE_ARRAY)
        },
        Value::Array(a) if a.iter().all(Value::is_string) => ParameterValue {
            string_array: a
                .iter()
                .filter_map(|s| s.as_str().map(String::from))
                .collect(),
            ..value(ParameterType::STRING_ARRAY)
        },
        other => ParameterValue {
            string_value: other.to_string(),
            ..value(ParameterType::STRING)
        },
    }
}

/// Every leaf of `v` by its dotted name.
fn flatten(prefix: &str, v: &Value, out: &mut Vec<(String, Value)>) {
    match v {
        Value::Object(m) if !m.is_empty() => {
            for (k, x) in m {
                let name = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                flatten(&name, x, out);
            }
        }
        _ => out.push((prefix.to_string(), v.clone())),
    }
}

fn type_name(t: u8) -> &'static str {
    match t {
        ParameterType::BOOL => "bool",
        ParameterType::INTEGER => "integer",
        ParameterType::DOUBLE => "double",
        ParameterType::STRING => "string",
        ParameterType::BYTE_ARRAY => "byte array",
        ParameterType::BOOL_ARRAY => "bool array",
        ParameterType::INTEGER_ARRAY => "integer array",
        ParameterType::DOUBLE_ARRAY => "double array",
        ParameterType::STRING_ARRAY => "string array",
        _ => "not set",
    }
}

impl Parameters {
    /// The table of `effective` (the effective parameters' JSON tree) and `use_sim_time` (true when the
    /// node follows `/clock`). `clouds`: whether the node started with particle clouds (a node started
    /// without keeps `particles.rate_hz` at 0: it made no cloud publisher).
    pub fn new(effective: &Value, use_sim_time: bool, clouds: bool) -> Self {
        let mut leaves = vec![];
        flatten("", effective, &mut leaves);
        leaves.push(("use_sim_time".into(), Value::Bool(use_sim_time)));
        let entries = leaves
            .into_iter()
            .filter(|(name, _)| !name.is_empty())
            .map(|(name, v)| {
                let value = to_value(&v);
                let changeable = CHANGEABLE
                    .iter()
                    .find(|c| c.name == name)
                    .filter(|c| clouds || !c.name.starts_with("particles."));
                let mut descriptor = ParameterDescriptor {
                    name: name.clone(),
                    r#type: value.ptype,
                    description: String::new(),
                    additional_constraints: String::new(),
                    read_only: changeable.is_none(),
                    dynamic_typing: false,
                    floating_point_range: vec![],
                    integer_range: vec![],
                };
                match changeable {
                    Some(c) => {
                        descriptor.description = c.description.to_string();
                        match c.range {
                            Range::Double(from_value, to_value) => {
                                descriptor.floating_point_range.push(FloatingPointRange {
                                    from_value,
                                    to_value,
                                    step: 0.0,
                                });
                                descriptor.additional_constraints =
                                    "applies at once; an integer is taken as a double".into();
                            }
                            Range::Integer(from_value, to_value) => {
                                descriptor.integer_range.push(IntegerRange {
                                    from_value,
                                    to_value,
                                    step: 1,
                                });
                                descriptor.additional_constraints = "applies at once".into();
                            }
                        }
                    }
                    None if name.starts_with("particles.") && !clouds => {
                        descriptor.additional_constraints =
                            "the node started without particle clouds (particles.rate_hz 0): restart it \
                             with particles.rate_hz above 0 to publish them"
                                .into();
                    }
                    None => descriptor.additional_constraints = READ_ONLY.into(),
                }
                (name, Entry { value, descriptor })
            })
            .collect();
        Self { entries }
    }

    /// The names, in order.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.entries.keys().map(String::as_str)
    }

    /// `list_parameters`: the names under `prefixes` (all when empty) at most `depth` levels below them
    /// (0: any), and the prefixes of the names listed, as rclcpp lists them.
    pub fn list(&self, prefixes: &[String], depth: u64) -> ListParametersResult {
        let mut names = vec![];
        let mut found_prefixes: Vec<String> = vec![];
        for name in self.entries.keys() {
            let within = |rest: &str| depth == 0 || (rest.matches('.').count() as u64) < depth;
            let listed = if prefixes.is_empty() {
                within(name)
            } else {
                prefixes.iter().any(|p| {
                    name == p
                        || name
                            .strip_prefix(p.as_str())
                            .and_then(|r| r.strip_prefix('.'))
                            .is_some_and(within)
                })
            };
            if !listed {
                continue;
            }
            names.push(name.clone());
            if let Some((prefix, _)) = name.rsplit_once('.') {
                if !found_prefixes.iter().any(|p| p == prefix) {
                    found_prefixes.push(prefix.to_string());
                }
            }
        }
        ListParametersResult {
            names,
            prefixes: found_prefixes,
        }
    }

    /// `get_parameters`: each name's value (not set for a name the node does not have).
    pub fn get(&self, names: &[String]) -> Vec<ParameterValue> {
        names
            .iter()
            .map(|n| {
                self.entries
                    .get(n)
                    .map_or_else(|| value(ParameterType::NOT_SET), |e| e.value.clone())
            })
            .collect()
    }

    /// `get_parameter_types`.
    pub fn types(&self, names: &[String]) -> Vec<u8> {
        self.get(names).iter().map(|v| v.ptype).collect()
    }

    /// `describe_parameters` (a name the node does not have: a read-only descriptor of no type, as rclcpp
    /// answers with allow_undeclared_parameters).
    pub fn describe(&self, names: &[String]) -> Vec<ParameterDescriptor> {
        names
            .iter()
            .map(|n| match self.entries.get(n) {
                Some(e) => e.descriptor.clone(),
                None => ParameterDescriptor {
                    name: n.clone(),
                    r#type: ParameterType::NOT_SET,
                    description: String::new(),
                    additional_constraints: "no such parameter".into(),
                    read_only: true,
                    dynamic_typing: false,
                    floating_point_range: vec![],
                    integer_range: vec![],
                },
            })
            .collect()
    }

    /// The value `p` would take, or why it cannot be set.
    fn check(&self, p: &Parameter) -> Result<ParameterValue, String> {
        let Some(e) = self.entries.get(&p.name) else {
            return Err(format!(
                "parameter '{}' is not a parameter of this node",
                p.name
            ));
        };
        let d = &e.descriptor;
        if d.read_only {
            return Err(format!(
                "parameter '{}' cannot be set because it is {}",
                p.name,
                if d.additional_constraints.is_empty() {
                    "read-only"
                } else {
                    d.additional_constraints.as_str()
                }
            ));
        }
        let v = &p.value;
        let wrong = || {
            format!(
                "parameter '{}' is of type {}, not {}",
                p.name,
                type_name(d.r#type),
                type_name(v.ptype)
            )
        };
        if let Some(r) = d.floating_point_range.first() {
            let x = match v.ptype {
                ParameterType::DOUBLE => v.double_value,
                ParameterType::INTEGER => v.int_value as f64,
                _ => return Err(wrong()),
            };
            if !(x >= r.from_value && x <= r.to_value) {
                return Err(format!(
                    "parameter '{}' = {x} is out of its range [{}, {}]",
                    p.name, r.from_value, r.to_value
                ));
            }
            return Ok(ParameterValue {
                double_value: x,
                ..value(ParameterType::DOUBLE)
            });
        }
        if let Some(r) = d.integer_range.first() {
            if v.ptype != ParameterType::INTEGER {
                return Err(wrong());
            }
            let x = v.int_value;
            if !(x >= r.from_value && x <= r.to_value) {
                return Err(format!(
                    "parameter '{}' = {x} is out of its range [{}, {}]",
                    p.name, r.from_value, r.to_value
                ));
            }
            return Ok(v.clone());
        }
        Err(wrong())
    }

    /// Applies checked values to `live`.
    fn apply(&mut self, values: &[(String, ParameterValue)], live: &mut LiveSettings) {
        for (name, v) in values {
            match name.as_str() {
                "output_rate_hz" => live.output_rate_hz = v.double_value,
                "diagnostics_rate_hz" => live.diagnostics_rate_hz = v.double_value,
                "particles.rate_hz" => live.particles_rate_hz = v.double_value,
                "particles.decimation" => live.particles_decimation = v.int_value as usize,
                "motion_timeout_s" => live.motion_timeout_s = v.double_value,
                _ => unreachable!("only changeable parameters pass the check"),
            }
            if let Some(e) = self.entries.get_mut(name) {
                e.value = v.clone();
            }
        }
    }

    /// `set_parameters`: each parameter on its own; returns a result per parameter and the parameters set
    /// (for `/parameter_events`).
    pub fn set(
        &mut self,
        params: &[Parameter],
        live: &mut LiveSettings,
    ) -> (Vec<SetParametersResult>, Vec<Parameter>) {
        let mut results = vec![];
        let mut changed = vec![];
        for p in params {
            match self.check(p) {
                Ok(v) => {
                    self.apply(&[(p.name.clone(), v.clone())], live);
                    changed.push(Parameter {
                        name: p.name.clone(),
                        value: v,
                    });
                    results.push(SetParametersResult {
                        successful: true,
                        reason: String::new(),
                    });
                }
                Err(reason) => results.push(SetParametersResult {
                    successful: false,
                    reason,
                }),
            }
        }
        (results, changed)
    }

    /// `set_parameters_atomically`: all or none.
    pub fn set_atomically(
        &mut self,
        params: &[Parameter],
        live: &mut LiveSettings,
    ) -> (SetParametersResult, Vec<Parameter>) {
        let mut values = vec![];
        for p in params {
            match self.check(p) {
                Ok(v) => values.push((p.name.clone(), v)),
                Err(reason) => {
                    return (
                        SetParametersResult {
                            successful: false,
                            reason,
                        },
                        vec![],
                    )
                }
            }
        }
        self.apply(&values, live);
        let changed = values
            .into_iter()
            .map(|(name, value)| Parameter { name, value })
            .collect();
        (
            SetParametersResult {
                successful: true,
                reason: String::new(),
            },
            changed,
        )
    }

    /// Every parameter with its value (the start-up `/parameter_events` message's new parameters).
    pub fn all(&self) -> Vec<Parameter> {
        self.entries
            .iter()
            .map(|(name, e)| Parameter {
                name: name.clone(),
                value: e.value.clone(),
            })
            .collect()
    }
}

/// The six parameter services and the `/parameter_events` publisher of a node.
pub struct ParameterServers {
    list: Server<ListParametersRequest, ListParametersResponse>,
    get: Server<GetParametersRequest, GetParametersResponse>,
    types: Server<GetParameterTypesRequest, GetParameterTypesResponse>,
    describe: Server<DescribeParametersRequest, DescribeParametersResponse>,
    set: Server<SetParametersRequest, SetParametersResponse>,
    set_atomically: Server<SetParametersRequest, SetParametersAtomicallyResponse>,
    events: Publisher<ParameterEvent>,
    announced: bool,
}

impl ParameterServers {
    /// Creates the services under the node's private namespace (`~/list_parameters`, ...) with the node's
    /// service mapping, and the publisher of `/parameter_events` (reliable, the last 1000 kept, as rclcpp's
    /// parameter events QoS).
    pub fn new(
        node: &mut Node,
        names: &super::args::Names,
        mapping: ServiceMapping,
        qos: &QosProfile,
    ) -> anyhow::Result<Self> {
        macro_rules! server {
            ($name:literal, $type:literal) => {
                node.create_server(
                    mapping,
                    &super::ros_name(names, concat!("~/", $name))?,
                    &ServiceTypeName::new("rcl_interfaces", $type),
                    qos.clone(),
                    qos.clone(),
                )
                .map_err(|e| anyhow::anyhow!(concat!("service ~/", $name, ": {:?}"), e))?
            };
        }
        let events_qos = QosProfile::publisher_default()
            .history(ros2_client::qos::History::KeepLast { depth: 1000 });
        let topic = node
            .create_topic(
                &super::ros_name(names, "/parameter_events")?,
                MessageTypeName::new("rcl_interfaces", "ParameterEvent"),
                &events_qos,
            )
            .map_err(|e| anyhow::anyhow!("topic /parameter_events: {e:?}"))?;
        let events = node
            .create_publisher(&topic, Some(events_qos))
            .map_err(|e| anyhow::anyhow!("publisher on /parameter_events: {e:?}"))?;
        Ok(Self {
            list: server!("list_parameters", "ListParameters"),
            get: server!("get_parameters", "GetParameters"),
            types: server!("get_parameter_types", "GetParameterTypes"),
            describe: server!("describe_parameters", "DescribeParameters"),
            set: server!("set_parameters", "SetParameters"),
            set_atomically: server!("set_parameters_atomically", "SetParametersAtomically"),
            events,
            announced: false,
        })
    }

    fn publish(
        &self,
        node: &str,
        new: Vec<Parameter>,
        changed: Vec<Parameter>,
    ) -> anyhow::Result<()> {
        super::publish(
            &self.events,
            ParameterEvent {
                stamp: ros2_client::builtin_interfaces::Time::now(),
                node: node.to_string(),
                new_parameters: new,
                changed_parameters: changed,
                deleted_parameters: vec![],
            },
            "/parameter_events",
        )
    }

    /// Answers the requests that have come, applying sets to `table` and `live`; the first call announces
    /// every parameter on `/parameter_events`. `log` is told of every change and refusal.
    pub fn serve(
        &mut self,
        table: &mut Parameters,
        live: &mut LiveSettings,
        node: &str,
        log: impl Fn(&str),
    ) -> anyhow::Result<()> {
        if !self.announced {
            self.announced = true;
            self.publish(node, table.all(), vec![])?;
        }
        while let Ok(Some((id, req))) = self.list.receive_request() {
            let result = table.list(&req.prefixes, req.depth);
            let _ = self
                .list
                .send_response(id, ListParametersResponse { result });
        }
        while let Ok(Some((id, req))) = self.get.receive_request() {
            let values = table.get(&req.names);
            let _ = self.get.send_response(id, GetParametersResponse { values });
        }
        while let Ok(Some((id, req))) = self.types.receive_request() {
            let values = table.types(&req.names);
            let _ = self
                .types
                .send_response(id, GetParameterTypesResponse { values });
        }
        while let Ok(Some((id, req))) = self.describe.receive_request() {
            let values = table.describe(&req.names);
            let _ = self
                .describe
                .send_response(id, DescribeParametersResponse { values });
        }
        let tell = |asked: &[Parameter], results: &[SetParametersResult]| {
            for (p, r) in asked.iter().zip(results) {
                if r.successful {
                    log(&format!("parameter {} set", p.name));
                } else {
                    log(&format!("parameter {} not set: {}", p.name, r.reason));
                }
            }
        };
        while let Ok(Some((id, req))) = self.set.receive_request() {
            let (results, changed) = table.set(&req.parameter, live);
            tell(&req.parameter, &results);
            let _ = self
                .set
                .send_response(id, SetParametersResponse { results });
            if !changed.is_empty() {
                self.publish(node, vec![], changed)?;
            }
        }
        while let Ok(Some((id, req))) = self.set_atomically.receive_request() {
            let (result, changed) = table.set_atomically(&req.parameter, live);
            if !result.successful {
                log(&format!("parameters not set: {}", result.reason));
            }
            for p in &changed {
                log(&format!("parameter {} set", p.name));
            }
            let _ = self
                .set_atomically
                .send_response(id, SetParametersAtomicallyResponse { result });
            if !changed.is_empty() {
                self.publish(node, vec![], changed)?;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    fn live() -> LiveSettings {
        LiveSettings {
            output_rate_hz: 50.0,
            diagnostics_rate_hz: 1.0,
            particles_rate_hz: 5.0,
            particles_decimation: 1,
            motion_timeout_s: 1.0,
        }
    }

    fn table(clouds: bool) -> Parameters {
        let effective = json!({
            "dimension": 3,
            "particle_spacing": 0.02,
            "output_rate_hz": 50.0,
            "diagnostics_rate_hz": 1.0,
            "motion_timeout_s": 1.0,
            "solver": {"scheme": "dfsph", "dfsph": {"max_iterations": 100, "relaxation": 0.7}},
            "particles": {"rate_hz": 5.0, "decimation": 1},
            "probes": {"names": ["a", "b"], "x": [0.1, -0.2], "y": []},
            "record": {"path": ""},
            "tank_pose": null,
            "flags": [true, false],
            "bodies": [{"name": "box"}],
        });
        Parameters::new(&effective, false, clouds)
    }

    fn param(name: &str, v: ParameterValue) -> Parameter {
        Parameter {
            name: name.into(),
            value: v,
        }
    }

    fn double(x: f64) -> ParameterValue {
        ParameterValue {
            double_value: x,
            ..value(ParameterType::DOUBLE)
        }
    }

    #[test]
    fn every_leaf_is_a_parameter_of_its_type() {
        let t = table(true);
        let names: Vec<&str> = t.names().collect();
        for n in [
            "dimension",
            "solver.dfsph.max_iterations",
            "probes.names",
            "probes.y",
            "record.path",
            "tank_pose",
            "use_sim_time",
        ] {
            assert!(names.contains(&n), "{n} in {names:?}");
        }
        let ask = |n: &str| t.types(&[n.to_string()])[0];
        assert_eq!(ask("dimension"), ParameterType::INTEGER);
        assert_eq!(ask("particle_spacing"), ParameterType::DOUBLE);
        assert_eq!(ask("solver.scheme"), ParameterType::STRING);
        assert_eq!(ask("probes.names"), ParameterType::STRING_ARRAY);
        assert_eq!(ask("probes.x"), ParameterType::DOUBLE_ARRAY);
        assert_eq!(ask("probes.y"), ParameterType::DOUBLE_ARRAY);
        assert_eq!(ask("flags"), ParameterType::BOOL_ARRAY);
        assert_eq!(ask("use_sim_time"), ParameterType::BOOL);
        assert_eq!(ask("tank_pose"), ParameterType::NOT_SET);
        assert_eq!(ask("no.such"), ParameterType::NOT_SET);
        // A list of records is its JSON text.
        let v = &t.get(&["bodies".into()])[0];
        assert_eq!(v.ptype, ParameterType::STRING);
        assert_eq!(v.string_value, r#"[{"name":"box"}]"#);
        assert_eq!(t.get(&["probes.x".into()])[0].double_array, [0.1, -0.2]);
    }

    #[test]
    fn listing_follows_prefixes_and_depth_as_rclcpp() {
        let t = table(true);
        let all = t.list(&[], 0);
        assert_eq!(all.names.len(), t.names().count());
        assert!(all.prefixes.contains(&"solver.dfsph".to_string()));
        // Depth 1: only names without a dot.
        let top = t.list(&[], 1);
        assert!(
            top.names.iter().all(|n| !n.contains('.')),
            "{:?}",
            top.names
        );
        assert!(top.names.contains(&"dimension".to_string()));
        // Under a prefix, one level down.
        let solver = t.list(&["solver".into()], 1);
        assert_eq!(solver.names, ["solver.scheme"]);
        let solver = t.list(&["solver".into()], 0);
        assert_eq!(
            solver.names,
            [
                "solver.dfsph.max_iterations",
                "solver.dfsph.relaxation",
                "solver.scheme"
            ]
        );
        assert_eq!(solver.prefixes, ["solver.dfsph", "solver"]);
        // A prefix is a whole name part: "solve" lists nothing.
        assert!(t.list(&["solve".into()], 0).names.is_empty());
    }

    #[test]
    fn descriptors_say_what_changes_and_what_is_read_only() {
        let t = table(true);
        let d = &t.describe(&["output_rate_hz".into()])[0];
        assert!(!d.read_only);
        assert_eq!(d.r#type, ParameterType::DOUBLE);
        assert_eq!(d.floating_point_range[0].from_value, 0.01);
        let d = &t.describe(&["particles.decimation".into()])[0];
        assert!(!d.read_only && d.integer_range[0].from_value == 1);
        let d = &t.describe(&["particle_spacing".into()])[0];
        assert!(d.read_only && d.additional_constraints.contains("restart"));
        // Without clouds at start-up the cloud's settings are read-only, with the reason.
        let d = &table(false).describe(&["particles.rate_hz".into()])[0];
        assert!(
            d.read_only
                && d.additional_constraints
                    .contains("particles.rate_hz above 0")
        );
        let d = &t.describe(&["nope".into()])[0];
        assert!(d.read_only && d.r#type == ParameterType::NOT_SET);
    }

    #[test]
    fn sets_apply_at_once_or_are_refused_with_the_reason() {
        let mut t = table(true);
        let mut l = live();
        let int = |x| ParameterValue {
            int_value: x,
            ..value(ParameterType::INTEGER)
        };
        let (r, changed) = t.set(
            &[
                param("output_rate_hz", double(20.0)),
                param("particles.decimation", int(4)),
                // ros2 param set sends "10" as an integer: taken as a double.
                param("motion_timeout_s", int(10)),
                param("particle_spacing", double(0.01)),
                param("diagnostics_rate_hz", double(0.0)),
                param("particles.decimation", double(2.0)),
                param("no_such", double(1.0)),
            ],
            &mut l,
        );
        let ok: Vec<bool> = r.iter().map(|r| r.successful).collect();
        assert_eq!(ok, [true, true, true, false, false, false, false]);
        assert_eq!(
            l,
            LiveSettings {
                output_rate_hz: 20.0,
                particles_decimation: 4,
                motion_timeout_s: 10.0,
                ..live()
            }
        );
        assert!(r[3].reason.contains("read-only") && r[3].reason.contains("restart"));
        assert!(r[4].reason.contains("out of its range"), "{}", r[4].reason);
        assert!(
            r[5].reason.contains("of type integer, not double"),
            "{}",
            r[5].reason
        );
        assert!(r[6].reason.contains("not a parameter"), "{}", r[6].reason);
        assert_eq!(changed.len(), 3);
        assert_eq!(changed[2].value.ptype, ParameterType::DOUBLE);
        assert_eq!(t.get(&["output_rate_hz".into()])[0].double_value, 20.0);
        assert_eq!(
            t.types(&["motion_timeout_s".into()])[0],
            ParameterType::DOUBLE
        );
        // Atomically: one refusal leaves everything as it was.
        let before = l;
        let (r, changed) = t.set_atomically(
            &[
                param("output_rate_hz", double(10.0)),
                param("dimension", int(2)),
            ],
            &mut l,
        );
        assert!(!r.successful && r.reason.contains("'dimension'") && changed.is_empty());
        assert_eq!(l, before);
        assert_eq!(t.get(&["output_rate_hz".into()])[0].double_value, 20.0);
        let (r, changed) = t.set_atomically(
            &[
                param("output_rate_hz", double(10.0)),
                param("diagnostics_rate_hz", double(2.0)),
            ],
            &mut l,
        );
        assert!(r.successful && changed.len() == 2);
        assert_eq!((l.output_rate_hz, l.diagnostics_rate_hz), (10.0, 2.0));
    }
}
