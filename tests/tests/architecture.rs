//! The crates' modules import each other in layers: no module of `sph` or of `node` imports, directly or
//! through others, a module that imports it back (ARCHITECTURE.md lists the layers). A module here is a
//! top-level file or folder of `src/`; an import is a `crate::name` path in its code (comments and the
//! `#[cfg(test)]` module left out).

use slosh_tests::tree::{files, root};
use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// `text` without its comments and without what follows its `#[cfg(test)]` module.
fn code(text: &str) -> String {
    let text = text.split("#[cfg(test)]").next().unwrap_or("");
    let mut out = String::new();
    let mut rest = text;
    while let Some(i) = rest.find("/*") {
        out.push_str(&rest[..i]);
        rest = rest[i..].find("*/").map_or("", |j| &rest[i + j + 2..]);
    }
    out.push_str(rest);
    out.lines()
        .map(|l| l.find("//").map_or(l, |i| &l[..i]))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The first path segments after each `crate::` in `code` (for `crate::{a, b::c}`, a and b).
fn imported(code: &str) -> BTreeSet<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut out = BTreeSet::new();
    for (i, _) in code.match_indices("crate::") {
        let after = &code[i + "crate::".len()..];
        if let Some(group) = after.strip_prefix('{') {
            let group = &group[..group.find('}').unwrap_or(group.len())];
            out.extend(group.split(',').map(ident));
        } else {
            out.insert(ident(after));
        }
    }
    out.remove("");
    out
}

/// The import graph of a crate's top-level modules: module → the other modules its code names.
fn graph(src: &Path) -> BTreeMap<String, BTreeSet<String>> {
    let files = files(src, "rs");
    let module = |f: &Path| -> String {
        let rel = f.strip_prefix(src).unwrap();
        let first = rel
            .components()
            .next()
            .unwrap()
            .as_os_str()
            .to_string_lossy();
        first.trim_end_matches(".rs").to_string()
    };
    let modules: BTreeSet<String> = files
        .iter()
        .map(|f| module(f))
        .filter(|m| m != "lib" && m != "main")
        .collect();
    let mut g: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for f in &files {
        let m = module(f);
        if !modules.contains(&m) {
            continue;
        }
        let text = std::fs::read_to_string(f).unwrap();
        let uses = imported(&code(&text));
        let e = g.entry(m.clone()).or_default();
        e.extend(uses.into_iter().filter(|u| modules.contains(u) && *u != m));
    }
    g
}

/// The groups of two or more modules that import each other round in a circle (strongly connected
/// components, Tarjan), each sorted.
fn circles(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct Walk<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    impl<'a> Walk<'a> {
        fn visit(&mut self, v: &'a str) {
            let n = self.index.len();
            self.index.insert(v, n);
            self.low.insert(v, n);
            self.stack.push(v);
            self.on.insert(v);
            for w in self.g.get(v).into_iter().flatten() {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let l = self.low[v].min(self.low[w]);
                    self.low.insert(v, l);
                } else if self.on.contains(w) {
                    let l = self.low[v].min(self.index[w]);
                    self.low.insert(v, l);
                }
            }
            if self.low[v] == self.index[v] {
                let mut group = Vec::new();
                loop {
                    let w = self.stack.pop().unwrap();
                    self.on.remove(w);
                    group.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if group.len() > 1 {
                    group.sort();
                    self.out.push(group);
                }
            }
        }
    }
    let mut walk = Walk {
        g,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in g.keys() {
        if !walk.index.contains_key(v.as_str()) {
            walk.visit(v);
        }
    }
    walk.out
}

fn check(krate: &str) {
    let g = graph(&root().join(krate).join("src"));
    assert!(g.len() > 5, "{krate}: too few modules found: {g:?}");
    let found = circles(&g);
    let explain: Vec<String> = found
        .iter()
        .map(|c| {
            let edges: Vec<String> = c
                .iter()
                .map(|m| {
                    let inside: Vec<&str> = g[m]
                        .iter()
                        .filter(|t| c.contains(t))
                        .map(|t| t.as_str())
                        .collect();
                    format!("{m} → {}", inside.join(", "))
                })
                .collect();
            edges.join("; ")
        })
        .collect();
    assert!(
        found.is_empty(),
        "{krate}/src: modules that import each other round in a circle: {}",
        explain.join(" | ")
    );
}

#[test]
fn the_solver_s_modules_import_each_other_in_layers() {
    check("sph");
}

#[test]
fn the_node_s_modules_import_each_other_in_layers() {
    check("node");
}

#[test]
fn the_circle_finder_finds_circles_and_reads_imports() {
    let g: BTreeMap<String, BTreeSet<String>> = [
        ("a", vec!["b"]),
        ("b", vec!["c"]),
        ("c", vec!["a", "d"]),
        ("d", vec![]),
        ("e", vec!["d"]),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
    .collect();
    assert_eq!(circles(&g), vec![vec!["a", "b", "c"]]);
    let text = "use crate::a::X;\n// use crate::z;\nuse crate::{b, c::Y};\n/* crate::q */ fn f() { crate::d::g() }\n#[cfg(test)]\nmod tests { use crate::t; }";
    let found: Vec<String> = imported(&code(text)).into_iter().collect();
    assert_eq!(found, ["a", "b", "c", "d"]);
}
