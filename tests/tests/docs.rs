//! The manual (`docs/`, an mdBook), the README, the changelog and ARCHITECTURE.md hold together: every page
//! is listed in the summary and every listed page exists, every relative link resolves to a file and every
//! `#anchor` to a heading of the page it names (as mdBook and GitHub derive heading ids), and the tables
//! made from data are the ones their data make. External links are not followed.

use slosh_tests::tree::{files, root};
use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// The lines of `text` outside fenced and indented code blocks.
fn prose(text: &str) -> Vec<&str> {
    let mut fenced = false;
    let mut out = Vec::new();
    for l in text.lines() {
        if l.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        if !fenced && !l.starts_with("    ") && !l.starts_with('\t') {
            out.push(l);
        }
    }
    out
}

/// The id mdBook (and GitHub) give a heading: lower case, spaces to `-`, other punctuation dropped.
fn heading_id(title: &str) -> String {
    title
        .trim()
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// Heading ids of a page.
fn anchors(text: &str) -> BTreeSet<String> {
    prose(text)
        .iter()
        .filter_map(|l| {
            let t = l.trim_start_matches('#');
            (t.len() < l.len() && t.starts_with(' ')).then(|| heading_id(t))
        })
        .collect()
}

/// Targets of the inline links `[text](target)` of a page (code spans removed first).
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    for l in prose(text) {
        let mut line = String::new();
        let mut code = false;
        for c in l.chars() {
            if c == '`' {
                code = !code;
            } else if !code {
                line.push(c);
            }
        }
        let mut rest = line.as_str();
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let Some(end) = after.find(')') else { break };
            out.push(after[..end].to_string());
            rest = &after[end..];
        }
    }
    out
}

/// Checks every relative link of `page`; returns the broken ones.
fn broken(page: &Path, texts: &mut HashMap<PathBuf, String>) -> Vec<String> {
    let text = texts
        .entry(page.to_path_buf())
        .or_insert_with(|| std::fs::read_to_string(page).unwrap())
        .clone();
    let mut bad = Vec::new();
    for target in links(&text) {
        if target.contains("://") || target.starts_with("mailto:") {
            continue;
        }
        let (file, anchor) = match target.split_once('#') {
            Some((f, a)) => (f, Some(a)),
            None => (target.as_str(), None),
        };
        let dest = if file.is_empty() {
            page.to_path_buf()
        } else {
            page.parent().unwrap().join(file)
        };
        if !dest.exists() {
            bad.push(format!("{}: {target}: no such file", page.display()));
            continue;
        }
        if let Some(a) = anchor {
            let t = texts
                .entry(dest.clone())
                .or_insert_with(|| std::fs::read_to_string(&dest).unwrap_or_default());
            if !anchors(t).contains(a) {
                bad.push(format!(
                    "{}: {target}: no heading with that id",
                    page.display()
                ));
            }
        }
    }
    bad
}

#[test]
fn the_manual_and_the_readme_link_only_to_what_exists() {
    let src = root().join("docs/src");
    let mut all = files(&src, "md");
    all.push(root().join("README.md"));
    all.push(root().join("CHANGELOG.md"));
    all.push(root().join("ARCHITECTURE.md"));
    let mut texts = HashMap::new();
    let bad: Vec<String> = all.iter().flat_map(|p| broken(p, &mut texts)).collect();
    assert!(bad.is_empty(), "broken links:\n{}", bad.join("\n"));
}

#[test]
fn every_page_of_the_manual_is_in_its_summary() {
    let src = root().join("docs/src");
    let summary = std::fs::read_to_string(src.join("SUMMARY.md")).unwrap();
    let listed: BTreeSet<PathBuf> = links(&summary).iter().map(|l| src.join(l)).collect();
    let all = files(&src, "md");
    let missing: Vec<_> = all
        .iter()
        .filter(|p| p.file_name().unwrap() != "SUMMARY.md" && !listed.contains(*p))
        .collect();
    assert!(missing.is_empty(), "pages not in SUMMARY.md: {missing:?}");
    let absent: Vec<_> = listed.iter().filter(|p| !p.exists()).collect();
    assert!(
        absent.is_empty(),
        "SUMMARY.md lists missing pages: {absent:?}"
    );
}

#[test]
fn heading_ids_are_derived_as_mdbook_does() {
    assert_eq!(heading_id("`slosh run`"), "slosh-run");
    assert_eq!(
        heading_id("The incompressible scheme (`solver.scheme: dfsph`)"),
        "the-incompressible-scheme-solverscheme-dfsph"
    );
    assert_eq!(
        links("see [a](x.md#b) and `[c](d)`"),
        vec!["x.md#b".to_string()]
    );
}

/// The performance table made from the benchmark records `docs/bench/*.json` (`docs/bench/record`).
fn bench_table() -> String {
    let dir = root().join("docs/bench");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == "json"))
        .collect();
    files.sort();
    assert!(
        !files.is_empty(),
        "no benchmark records in {}",
        dir.display()
    );
    let mut rows = String::from(
        "| case | particles (liquid + wall) | steps | particle-steps/s | RTF (slowest–fastest) | pressure iterations a step |\n|---|---|---|---|---|---|\n",
    );
    let mut timed = BTreeSet::new();
    for f in &files {
        let r: serde_json::Value =
            serde_json::from_str(&std::fs::read_to_string(f).unwrap()).unwrap();
        let num = |k: &str| {
            r[k].as_f64()
                .unwrap_or_else(|| panic!("{}: no number {k}", f.display()))
        };
        let text = |k: &str| {
            r[k].as_str()
                .unwrap_or_else(|| panic!("{}: no {k}", f.display()))
                .to_string()
        };
        let sim = num("sim_time_s");
        let rtf = |wall: f64| sim / wall;
        let iterations = if num("iterations_per_step") > 0.0 {
            format!("{:.1}", num("iterations_per_step"))
        } else {
            "—".into()
        };
        rows += &format!(
            "| `{}`, {:.1} s | {} + {} | {} | {:.2e} | {:.3} ({:.3}–{:.3}) | {} |\n",
            text("case"),
            sim,
            num("particles_fluid"),
            num("particles_boundary"),
            num("steps"),
            num("particle_steps_per_s"),
            num("realtime_factor"),
            rtf(num("wall_time_s_max")),
            rtf(num("wall_time_s_min")),
            iterations
        );
        timed.insert(format!(
            "{} ({} threads, {} process(es)), {}, commit {}",
            text("machine"),
            num("threads"),
            num("ranks"),
            text("date"),
            text("commit")
        ));
    }
    let timed: Vec<String> = timed.into_iter().collect();
    format!("{rows}\nTimed on {}.\n", timed.join("; "))
}

/// Replaces what stands between `<!-- NAME:begin -->` and `<!-- NAME:end -->` in `file` with `body`, or (unless
/// SLOSH_UPDATE_DOCS is set) fails when it differs.
fn generated(file: &str, name: &str, body: &str) {
    let path = root().join(file);
    let text = std::fs::read_to_string(&path).unwrap();
    let made = slosh_node::manual::replace_block(&text, name, body)
        .unwrap_or_else(|e| panic!("{file}: {e}"));
    if made == text {
        return;
    }
    if std::env::var_os("SLOSH_UPDATE_DOCS").is_some() {
        std::fs::write(&path, made).unwrap();
        return;
    }
    panic!(
        "{file}: the {name} table is not the one its data make; run with SLOSH_UPDATE_DOCS=1 to rewrite it. Expected:\n{body}"
    );
}

#[test]
fn the_performance_tables_are_made_from_the_benchmark_records() {
    let table = bench_table();
    generated("README.md", "bench", &table);
    generated("docs/src/performance/benchmarks.md", "bench", &table);
}

/// A row of a parameter table of the user guide: the keys its first column names, and its default column
/// ("" where the table has none).
struct ParamRow {
    keys: Vec<String>,
    default: String,
}

/// The parameter tables of the user guide: tables whose head's first cell says `key` or `parameter`. The
/// first column names keys as `a.b`, `.c` (a sibling of the item before it), `a.{x,y}` (each of x, y),
/// `a.<name>.b` (any name); a table whose head names a group (`key (under `wave_maker.`)`) names its members
/// relative to it, and the group itself. Returns the rows, and the groups whose members a default
/// configuration does not have (named members, or an optional group).
fn parameter_tables() -> (Vec<ParamRow>, BTreeSet<String>) {
    let (mut rows, mut groups) = (Vec::new(), BTreeSet::new());
    for f in files(&root().join("docs/src/guide"), "md") {
        let text = std::fs::read_to_string(&f).unwrap();
        let (mut under, mut in_table, mut read, mut with_default) =
            (String::new(), false, false, false);
        for line in prose(&text) {
            let Some(cells) = line
                .strip_prefix('|')
                .map(|l| l.split('|').collect::<Vec<_>>())
            else {
                (under, in_table, read) = (String::new(), false, false);
                continue;
            };
            let cell = cells[0];
            if !in_table {
                // The table's head.
                in_table = true;
                let head = cell.trim_start();
                read = head.starts_with("key") || head.starts_with("parameter");
                with_default = cells.get(1).is_some_and(|c| c.trim() == "default");
                if let Some(group) = cell.split('`').nth(1).filter(|g| read && g.ends_with('.')) {
                    under = group.to_string();
                    let group = group.trim_end_matches('.');
                    rows.push(ParamRow {
                        keys: vec![group.to_string()],
                        default: String::new(),
                    });
                    if !group.contains(".<") {
                        groups.insert(group.to_string());
                    }
                }
                continue;
            }
            if !read || cell.starts_with("---") {
                continue;
            }
            let mut keys = Vec::new();
            let mut parent = String::new();
            for (i, item) in cell.split('`').enumerate() {
                if i % 2 == 0 || item.is_empty() {
                    continue;
                }
                let full = match item.strip_prefix('.') {
                    Some(rest) if !parent.is_empty() => format!("{parent}.{rest}"),
                    _ => format!("{under}{item}"),
                };
                if let Some(p) = full.rfind('.') {
                    parent = full[..p].to_string();
                }
                if let Some(i) = full.find(".<") {
                    groups.insert(full[..i].to_string());
                }
                match (full.find(".{"), full.strip_suffix('}')) {
                    (Some(b), Some(body)) => {
                        for member in body[b + 2..].split(',') {
                            keys.push(format!("{}.{}", &full[..b], member.trim()));
                        }
                    }
                    _ => keys.push(full),
                }
            }
            let default = if with_default {
                cells.get(1).map_or("", |c| c.trim()).to_string()
            } else {
                String::new()
            };
            rows.push(ParamRow { keys, default });
        }
    }
    (rows, groups)
}

/// The value a default cell gives, where it is a plain value: a number (what leads the cell: "0 (off)" is
/// 0), `a name`, true/false, [] (anything else, e.g. "by scheme", gives None).
fn default_value(cell: &str) -> Option<serde_json::Value> {
    let cell = cell.trim();
    if let Some(name) = cell.strip_prefix('`').and_then(|c| c.strip_suffix('`')) {
        return Some(serde_json::json!(name));
    }
    match cell {
        "true" | "false" => return Some(serde_json::json!(cell == "true")),
        "[]" => return Some(serde_json::json!([])),
        _ => {}
    }
    let lead = cell.split([' ', '(']).next()?;
    lead.parse::<f64>().ok().map(|x| serde_json::json!(x))
}

/// Dotted paths of the leaves of `v` (an array, or an object with no members, is a leaf).
fn leaves(v: &serde_json::Value, at: &str, out: &mut BTreeSet<String>) {
    match v {
        serde_json::Value::Object(m) if !m.is_empty() => {
            for (k, v) in m {
                let path = if at.is_empty() {
                    k.clone()
                } else {
                    format!("{at}.{k}")
                };
                leaves(v, &path, out);
            }
        }
        _ => {
            out.insert(at.to_string());
        }
    }
}

#[test]
fn the_parameter_reference_names_every_parameter_and_only_those() {
    let case = "/**:\n  ros__parameters:\n    dimension: 2\n    tank: {length: 0.8, breadth: 0.25, height: 0.6}\n    fill_height: 0.19\n    particle_spacing: 0.02\n";
    let loaded = slosh_node::config::from_str(case, "case.yaml", None, &[]).unwrap();
    let params = loaded.sim_params().unwrap();
    let mut every = BTreeSet::new();
    leaves(&loaded.effective_parameters(&params), "", &mut every);
    // Groups of named members (`obstacles.<name>.centre`) and optional groups document the group's key.
    let (rows, named_groups) = parameter_tables();
    let documented: BTreeSet<String> = rows.iter().flat_map(|r| r.keys.iter().cloned()).collect();
    let undocumented: Vec<&String> = every
        .iter()
        .filter(|k| !documented.contains(*k) && !named_groups.contains(*k))
        .collect();
    assert!(
        undocumented.is_empty(),
        "parameters the user guide's tables do not name: {undocumented:?}"
    );
    // What the tables name under a parameter group must be a parameter.
    let tops: BTreeSet<&str> = every.iter().map(|k| k.split('.').next().unwrap()).collect();
    let unknown: Vec<&String> = documented
        .iter()
        .filter(|k| {
            k.chars()
                .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || "_.".contains(c))
                && k.contains('.')
                && tops.contains(k.split('.').next().unwrap())
                && !every.contains(*k)
                && !named_groups.iter().any(|g| k.starts_with(&format!("{g}.")))
        })
        .collect();
    assert!(
        unknown.is_empty(),
        "the user guide's tables name parameters that do not exist: {unknown:?}"
    );
    // And give their defaults: a cell of one value for every key of its row, or one per key.
    let effective = loaded.effective_parameters(&params);
    let given = ["dimension", "tank", "fill_height", "particle_spacing"];
    let (mut checked, mut wrong) = (0, Vec::new());
    for r in rows.iter().filter(|r| !r.default.is_empty()) {
        let cells: Vec<&str> = r.default.split(", ").collect();
        for (i, key) in r.keys.iter().enumerate() {
            let cell = if cells.len() == r.keys.len() {
                cells[i]
            } else {
                r.default.as_str()
            };
            let (Some(want), Some(got)) = (
                default_value(cell),
                key.split('.')
                    .try_fold(&effective, |v, k| v.get(k))
                    .filter(|_| !given.contains(&key.split('.').next().unwrap())),
            ) else {
                continue;
            };
            checked += 1;
            let same = match (want.as_f64(), got.as_f64()) {
                (Some(a), Some(b)) => (a - b).abs() <= 1e-9 * b.abs().max(1e-12),
                _ => &want == got,
            };
            if !same {
                wrong.push(format!(
                    "{key}: the table says {cell}, the default is {got}"
                ));
            }
        }
    }
    assert!(
        wrong.is_empty(),
        "defaults the tables get wrong:\n{}",
        wrong.join("\n")
    );
    assert!(
        checked >= 60,
        "only {checked} defaults read from the tables"
    );
}

/// Every validation page shows the numbers of each case it draws as the validation command wrote them: a
/// `<!-- results:NAME:begin -->` block with a table (a header and at least one row) for every figure of
/// `docs/src/images/validation` (a case's second figure, `*_pressure`, shares its case's block), and no block
/// without its figure.
#[test]
fn each_validation_figure_has_its_generated_numbers() {
    let dir = root().join("docs/src/validation");
    let mut blocks = std::collections::BTreeSet::new();
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let text = std::fs::read_to_string(&path).unwrap();
        let results: Vec<(&str, &str)> = generated_blocks(&text)
            .into_iter()
            .filter_map(|(name, body)| name.strip_prefix("results:").map(|n| (n, body)))
            .collect();
        assert_eq!(
            text.matches("<!-- results:").count(),
            2 * results.len(),
            "{}: a results marker without its pair",
            path.display()
        );
        for (name, body) in results {
            let table: Vec<&str> = body.lines().filter(|l| l.starts_with('|')).collect();
            assert!(
                table.len() >= 3 && table[1].starts_with("|---"),
                "{}: the results of {name} hold no table: run the validation command with SLOSH_UPDATE_DOCS=1",
                path.display()
            );
            assert!(
                blocks.insert(name.to_string()),
                "{name}: two results blocks"
            );
        }
    }
    let figures: std::collections::BTreeSet<String> =
        std::fs::read_dir(root().join("docs/src/images/validation"))
            .unwrap()
            .map(|e| e.unwrap().path())
            .filter(|p| p.extension().is_some_and(|x| x == "png"))
            .map(|p| p.file_stem().unwrap().to_string_lossy().to_string())
            .filter(|n| !n.ends_with("_pressure"))
            .collect();
    assert_eq!(blocks, figures, "results blocks against validation figures");
}

/// The numbers written in `text`, each with its decimals and whether it carries a sign: a run of digits with
/// an optional fraction, not part of a word (`P8`, `2D`), with a sign (`+`, `-`, `−`) directly before it
/// where that sign starts a word.
fn numbers(text: &str) -> Vec<(f64, usize, bool)> {
    let c: Vec<char> = text.chars().collect();
    let word = |ch: char| ch.is_alphanumeric() || ch == '.' || ch == '_';
    let mut out = Vec::new();
    let mut i = 0;
    while i < c.len() {
        if !c[i].is_ascii_digit() || (i > 0 && word(c[i - 1])) {
            i += 1;
            continue;
        }
        let start = i;
        while i < c.len() && c[i].is_ascii_digit() {
            i += 1;
        }
        let mut decimals = 0;
        if i + 1 < c.len() && c[i] == '.' && c[i + 1].is_ascii_digit() {
            i += 1;
            while i < c.len() && c[i].is_ascii_digit() {
                i += 1;
                decimals += 1;
            }
        }
        if i < c.len() && c[i].is_ascii_alphabetic() {
            continue;
        }
        let digits: String = c[start..i].iter().collect();
        let mut value: f64 = digits.parse().unwrap();
        let signed = start > 0
            && matches!(c[start - 1], '+' | '-' | '−')
            && (start == 1 || !word(c[start - 2]));
        if signed && c[start - 1] != '+' {
            value = -value;
        }
        out.push((value, decimals, signed));
    }
    out
}

/// The generated blocks of a page, `<!-- NAME:begin -->` … `<!-- NAME:end -->`: each name and what stands
/// between its markers.
fn generated_blocks(text: &str) -> Vec<(&str, &str)> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(a) = rest.find(":begin -->") {
        let name = &rest[rest[..a].rfind("<!-- ").expect("a begin marker") + "<!-- ".len()..a];
        let end = format!("<!-- {name}:end -->");
        let body = &rest[a + ":begin -->".len()..];
        let b = body.find(&end).unwrap_or_else(|| panic!("no {end}"));
        out.push((name, &body[..b]));
        rest = &body[b..];
    }
    out
}

/// The README's validation table is a summary of the manual's generated numbers: each row links to the
/// validation page(s) it summarises, and every number in its result column is, as rounded there, a number
/// of those pages' generated blocks (the validation command's results, the convergence and response
/// tables), so that a rerun that moves a number fails here until the README says what the manual does.
#[test]
fn the_readme_validation_numbers_are_the_generated_ones() {
    let readme = std::fs::read_to_string(root().join("README.md")).unwrap();
    let section = readme
        .split("\n## Validation\n")
        .nth(1)
        .expect("README.md: a ## Validation section");
    let rows: Vec<&str> = section
        .lines()
        .skip_while(|l| !l.starts_with('|'))
        .take_while(|l| l.starts_with('|'))
        .skip(2)
        .collect();
    assert!(rows.len() >= 5, "README.md: the validation table: {rows:?}");
    for row in rows {
        let cells: Vec<&str> = row.trim_matches('|').split(" | ").collect();
        assert!(cells.len() >= 3, "README.md validation row {row}");
        let pages: BTreeSet<String> = links(cells[0])
            .into_iter()
            .filter_map(|l| {
                l.split('#')
                    .next()
                    .filter(|p| p.starts_with("docs/src/validation/"))
                    .map(str::to_string)
            })
            .collect();
        assert!(
            !pages.is_empty(),
            "README.md validation row without a link to its validation page: {row}"
        );
        let mut known = Vec::new();
        for p in &pages {
            let text = std::fs::read_to_string(root().join(p)).unwrap();
            for (_, body) in generated_blocks(&text) {
                known.extend(numbers(body));
            }
        }
        for (x, decimals, signed) in numbers(cells[1]) {
            let half = 0.5 * 10f64.powi(-(decimals as i32)) + 1e-9;
            let found = known.iter().any(|&(y, _, _)| {
                if signed {
                    (y - x).abs() <= half
                } else {
                    (y.abs() - x.abs()).abs() <= half
                }
            });
            assert!(
                found,
                "README.md validation row: {x} is not a number of the generated tables of {pages:?} \
                 (rerun the command that makes them, or say in the README what they say): {row}"
            );
        }
    }
}

#[test]
fn numbers_are_read_as_written() {
    let n = numbers("P8 0.94–0.97, +3 % / −11 %, 2D 1.30× (at 20 mm) x-1");
    assert_eq!(
        n,
        vec![
            (0.94, 2, false),
            (0.97, 2, false),
            (3.0, 0, true),
            (-11.0, 0, true),
            (1.30, 2, false),
            (20.0, 0, false),
            (1.0, 0, false),
        ]
    );
}
