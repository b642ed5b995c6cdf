//! The ROS 2 parameters-file layout: node sections (`<node name>: {ros__parameters: {...}}`, node names
//! possibly nested under namespaces, `*` and `**` wildcards) and which of them apply to a node, as rclcpp
//! applies them: a section name without a leading `/` is absolute (`slosh` is `/slosh`), `*` stands for one
//! name and `**` for any number of them, none included (`/**` is every node), and every section that applies
//! is applied in file order, a later one overriding an earlier one parameter by parameter.

use serde_json::{Map, Value};

/// Where a node's parameters sit under its name.
pub const PARAMS_KEY: &str = "ros__parameters";

/// One `ros__parameters` map and the node name (or pattern) it is for, made absolute.
#[derive(Debug, Clone, PartialEq)]
pub struct Section {
    pub name: String,
    pub params: Value,
}

/// The node sections of a parsed parameters file, in file order.
pub fn sections(doc: Value) -> Result<Vec<Section>, String> {
    let Value::Object(top) = doc else {
        return Err(
            "expected a map `<node name>: {ros__parameters: {...}}` (the ROS 2 parameters layout)"
                .into(),
        );
    };
    if top.is_empty() {
        return Err("no node section (the ROS 2 parameters layout is `slosh: {ros__parameters: {...}}`, or `/**:` for every node)".into());
    }
    let mut out = Vec::new();
    for (key, value) in top {
        walk(&key, value, &mut out)?;
    }
    Ok(out)
}

/// A node name or namespace `path` and what is under it.
fn walk(path: &str, value: Value, out: &mut Vec<Section>) -> Result<(), String> {
    let missing = || {
        format!("{path}: missing `{PARAMS_KEY}:` (the ROS 2 parameters layout is `{path}: {{{PARAMS_KEY}: {{...}}}}`)")
    };
    let Value::Object(mut m) = value else {
        return Err(format!(
            "{path}: expected `{PARAMS_KEY}:` under the node name"
        ));
    };
    match m.remove(PARAMS_KEY) {
        Some(p @ Value::Object(_)) if m.is_empty() => {
            out.push(Section {
                name: absolute(path),
                params: p,
            });
            Ok(())
        }
        Some(Value::Object(_)) => Err(format!(
            "{path}: only `{PARAMS_KEY}` may sit under the node name, found {:?}",
            m.keys().collect::<Vec<_>>()
        )),
        Some(_) => Err(format!("{path}.{PARAMS_KEY}: expected a map of parameters")),
        // A namespace: the node names are under it.
        None if !m.is_empty() && m.values().all(Value::is_object) => {
            for (key, value) in m {
                walk(
                    &format!("{path}/{}", key.trim_start_matches('/')),
                    value,
                    out,
                )?;
            }
            Ok(())
        }
        // Parameters under a key that is not `ros__parameters` (`parameters:`, a typo) one level down.
        None => match path.rsplit_once('/') {
            Some((parent, last)) if !parent.is_empty() => Err(format!(
                "{path}: parameter values under `{last}:`, not `{PARAMS_KEY}:` (the layout is \
                 `{parent}: {{{PARAMS_KEY}: {{...}}}}`)"
            )),
            _ => Err(missing()),
        },
    }
}

/// `name` with a leading `/`.
fn absolute(name: &str) -> String {
    if name.starts_with('/') {
        name.to_string()
    } else {
        format!("/{name}")
    }
}

/// Whether the section name `pattern` applies to the node whose fully qualified name is `fqn` (`/ns/name`).
pub fn applies(pattern: &str, fqn: &str) -> bool {
    fn parts(s: &str) -> Vec<&str> {
        s.split('/').filter(|p| !p.is_empty()).collect()
    }
    fn glob(p: &[&str], n: &[&str]) -> bool {
        match p.split_first() {
            None => n.is_empty(),
            Some((&"**", rest)) => (0..=n.len()).any(|i| glob(rest, &n[i..])),
            Some((&"*", rest)) => !n.is_empty() && glob(rest, &n[1..]),
            Some((s, rest)) => n.first() == Some(s) && glob(rest, &n[1..]),
        }
    }
    glob(&parts(&absolute(pattern)), &parts(fqn))
}

/// `add` merged into `base` parameter by parameter (groups merged, values replaced).
pub fn merge(base: &mut Map<String, Value>, add: Map<String, Value>) {
    for (k, v) in add {
        match (base.get_mut(&k), v) {
            (Some(Value::Object(have)), Value::Object(more)) => merge(have, more),
            (_, v) => {
                base.insert(k, v);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn section_names_match_nodes_as_rclcpp_matches_them() {
        for (pattern, fqn, want) in [
            ("slosh", "/slosh", true),
            ("/slosh", "/slosh", true),
            ("slosh", "/ship1/slosh", false),
            ("/ship1/slosh", "/ship1/slosh", true),
            ("/ship1/slosh", "/ship2/slosh", false),
            ("/**", "/slosh", true),
            ("/**", "/a/b/slosh", true),
            ("/**/slosh", "/slosh", true),
            ("/**/slosh", "/a/b/slosh", true),
            ("/**/slosh", "/a/b/tank2", false),
            ("/*/slosh", "/ship1/slosh", true),
            ("/*/slosh", "/slosh", false),
            ("/ship1/*", "/ship1/tank2", true),
            ("/ship1/*", "/ship1/a/tank2", false),
            ("/ship1/**", "/ship1/a/tank2", true),
        ] {
            assert_eq!(applies(pattern, fqn), want, "{pattern} against {fqn}");
        }
    }

    #[test]
    fn sections_nest_under_namespaces_and_keep_file_order() {
        let doc = json!({
            "/**": {"ros__parameters": {"a": 1}},
            "ship1": {"tank2": {"ros__parameters": {"b": 2}}, "/tank3": {"ros__parameters": {"c": 3}}},
            "slosh": {"ros__parameters": {"d": 4}},
        });
        let s = sections(doc).unwrap();
        let names: Vec<&str> = s.iter().map(|s| s.name.as_str()).collect();
        assert_eq!(names, ["/**", "/ship1/tank2", "/ship1/tank3", "/slosh"]);
        assert_eq!(s[1].params, json!({"b": 2}));
    }

    #[test]
    fn malformed_layouts_are_named() {
        let e = |v: Value| sections(v).unwrap_err();
        assert!(e(json!({"slosh": {}})).contains("slosh: missing `ros__parameters:`"));
        assert!(e(json!({"slosh": {"dimension": 2}})).contains("slosh: missing `ros__parameters:`"));
        assert!(e(json!({"slosh": 3})).contains("expected `ros__parameters:` under the node name"));
        let m = e(json!({"/**": {"parameters": {"dimension": 2}}}));
        assert!(
            m.contains("/**/parameters: parameter values under `parameters:`, not `ros__parameters:` (the layout is `/**: {ros__parameters: {...}}`)"),
            "{m}"
        );
        assert!(
            e(json!({"slosh": {"ros__parameters": 3}})).contains("expected a map of parameters")
        );
        assert!(e(json!({"slosh": {"ros__parameters": {}, "x": {}}}))
            .contains("only `ros__parameters` may sit under the node name"));
        assert!(e(json!([1])).contains("expected a map"));
        assert!(e(json!({})).contains("no node section"));
    }

    #[test]
    fn later_sections_override_parameter_by_parameter() {
        let mut base = json!({"tank": {"length": 0.8, "breadth": 0.25}, "dimension": 2})
            .as_object()
            .unwrap()
            .clone();
        let add = json!({"tank": {"length": 1.0}, "dimension": 3})
            .as_object()
            .unwrap()
            .clone();
        merge(&mut base, add);
        assert_eq!(
            Value::Object(base),
            json!({"tank": {"length": 1.0, "breadth": 0.25}, "dimension": 3})
        );
    }
}
