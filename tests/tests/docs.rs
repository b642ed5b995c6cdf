//! The manual (`docs/`, an mdBook), the README, the changelog and ARCHITECTURE.md hold together: every page
//! is listed in the summary and every listed page exists, every relative link resolves to a file and every
//! `#anchor` to a heading of the page it names (as mdBook and GitHub derive heading ids), and the tables
//! made from data are the ones their data make. External links are not followed.

use std::collections::{BTreeSet, HashMap};
use std::path::{Path, PathBuf};

/// The repository root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .unwrap()
        .to_path_buf()
}

/// Markdown files under `dir`, recursively.
fn pages(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            pages(&p, out);
        } else if p.extension().is_some_and(|x| x == "md") {
            out.push(p);
        }
    }
}

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
    let mut all = Vec::new();
    pages(&src, &mut all);
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
    let mut all = Vec::new();
    pages(&src, &mut all);
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
    let (begin, end) = (
        format!("<!-- {name}:begin -->\n"),
        format!("<!-- {name}:end -->"),
    );
    let a = text
        .find(&begin)
        .unwrap_or_else(|| panic!("{file}: no {begin}"))
        + begin.len();
    let b = text[a..]
        .find(&end)
        .unwrap_or_else(|| panic!("{file}: no {end}"))
        + a;
    if &text[a..b] == body {
        return;
    }
    if std::env::var_os("SLOSH_UPDATE_DOCS").is_some() {
        std::fs::write(&path, format!("{}{body}{}", &text[..a], &text[b..])).unwrap();
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
