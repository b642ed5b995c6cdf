//! The seed tank's first sloshing mode as the solver gives it, against linear theory, by scheme setting,
//! dimension, fill and particle spacing: the free-decay period error and damping ratio beside the laminar
//! boundary-layer value (`sph::sloshing`). Writes what the manual shows:
//!
//! - the table between the `convergence` markers of `docs/src/validation/sloshing.md`,
//! - `docs/src/validation/convergence.csv`, the same rows as data,
//! - `docs/src/images/convergence.svg`, period error and damping ratio against the spacing.
//!
//! ```text
//! cargo run --release -p slosh-node --example sloshing_convergence              # about an hour on 2 cores
//! cargo run --release -p slosh-node --example sloshing_convergence -- --fine    # adds 3D at 10 mm, 2D wcsph at 5 mm
//! cargo run --release -p slosh-node --example sloshing_convergence -- --quick   # 2D at 40 and 20 mm, printed only
//! cargo run --release -p slosh-node --example sloshing_convergence -- --redraw  # table and figure from the CSV
//! cargo run --release -p slosh-node --example sloshing_convergence -- --only 3:0.01  # re-measure some rows
//! ```
//!
//! `--only DIM:DP` (repeatable) runs only the cases of that dimension and spacing (from the `--fine` list) and
//! merges their rows into the CSV, the table and the figure, replacing rows of the same setting, dimension,
//! fill and spacing.
//!
//! `--png FILE` also draws the figure as a PNG (to look at without an SVG viewer).
use plotters::prelude::*;
use slosh_node::accuracy::{csv, merge, read_csv, Row, SETTINGS};
use slosh_node::plot::figure::{self, Figure, Panel, Series};
use sph::sloshing::experiment::{free_decay, seed_tank};
use std::path::Path;

const FILLS: [f64; 2] = [0.19, 0.39];

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let only: Vec<(usize, f64)> = args
        .iter()
        .enumerate()
        .filter(|(_, a)| *a == "--only")
        .map(|(i, _)| {
            let v = args.get(i + 1).map(String::as_str).unwrap_or("");
            v.split_once(':')
                .and_then(|(d, dp)| Some((d.parse().ok()?, dp.parse().ok()?)))
                .unwrap_or_else(|| panic!("--only DIM:DP (e.g. 3:0.01), not `{v}`"))
        })
        .collect();
    let fine = args.iter().any(|a| a == "--fine") || !only.is_empty();
    let png = args
        .iter()
        .position(|a| a == "--png")
        .map(|i| args.get(i + 1).expect("--png FILE").clone());
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let data = root.join("docs/src/validation/convergence.csv");
    if args.iter().any(|a| a == "--redraw") {
        let text = std::fs::read_to_string(&data).expect("docs/src/validation/convergence.csv");
        let (rows, heading) = read_csv(&text).expect("the CSV this command writes");
        write(&root, &rows, &heading, png);
        return;
    }
    let mut rows = Vec::new();
    for (si, s) in SETTINGS.iter().enumerate() {
        let wcsph = si == 2;
        let mut cases: Vec<(usize, f64)> = vec![(2, 0.04), (2, 0.02)];
        if !quick {
            cases.extend([(2, 0.01), (2, 0.008)]);
            // WCSPH's steps follow the speed of sound: its 2D 5 mm decays take ten minutes each, its 3D ones
            // hours.
            if !wcsph || fine {
                cases.push((2, 0.005));
            }
            if !wcsph {
                cases.extend([(3, 0.04), (3, 0.02)]);
                if fine {
                    cases.push((3, 0.01));
                }
            }
        }
        if !only.is_empty() {
            cases.retain(|c| only.contains(c));
        }
        for &(dim, dp) in &cases {
            for fill in FILLS {
                let mut p = seed_tank(dim, fill, dp);
                (s.apply)(&mut p);
                let result = free_decay(p, 0.01, 8.0)
                    .map(|r| {
                        [
                            r.decay.period,
                            r.theory_period,
                            r.decay.damping_ratio,
                            r.laminar.ratio,
                            r.wall_time,
                        ]
                    })
                    .map_err(|e| e.to_string());
                let row = Row {
                    setting: s.name.to_string(),
                    dimension: dim,
                    fill,
                    spacing: dp,
                    result,
                };
                println!("{}", table_row(&row));
                rows.push(row);
            }
        }
    }
    if quick {
        return;
    }
    let machine = slosh_node::manual::machine();
    let threads = rayon::current_num_threads();
    let mut heading = format!("{machine} ({threads} threads)");
    if !only.is_empty() {
        let text = std::fs::read_to_string(&data).expect("docs/src/validation/convergence.csv");
        let (old, old_heading) = read_csv(&text).expect("the CSV this command writes");
        rows = merge(old, rows);
        if old_heading != heading {
            heading = format!("{old_heading}; the rows of `--only` on {heading}");
        }
    }
    std::fs::write(&data, csv(&heading, &rows)).unwrap();
    write(&root, &rows, &heading, png);
}

/// The manual's table and figure from `rows`.
fn write(root: &Path, rows: &[Row], heading: &str, png: Option<String>) {
    let mut table = format!(
        "Wall seconds measured on {heading}. Free decay of a 1 cm first-mode wave over eight periods; the \
         period and ζ fitted to the horizontal force after the first period.\n\n\
         | setting | dim | fill m | dp mm | period s | theory s | error | ζ | laminar ζ | wall s |\n\
         |---|---|---|---|---|---|---|---|---|---|\n"
    );
    for r in rows {
        table += &table_row(r);
        table.push('\n');
    }
    let page = root.join("docs/src/validation/sloshing.md");
    let text = std::fs::read_to_string(&page).expect("docs/src/validation/sloshing.md");
    let text = slosh_node::manual::replace_block(&text, "convergence", &table)
        .expect("the convergence markers");
    std::fs::write(&page, text).unwrap();
    let svg = root.join("docs/src/images/convergence.svg");
    let fig = convergence_figure(rows);
    figure::draw(
        SVGBackend::new(&svg, (1400, 1000)).into_drawing_area(),
        &fig,
    )
    .unwrap();
    if let Some(png) = png {
        figure::draw(
            BitMapBackend::new(&png, (1400, 1000)).into_drawing_area(),
            &fig,
        )
        .unwrap();
    }
    println!(
        "wrote {}, convergence.csv and {}",
        page.display(),
        svg.display()
    );
}

fn table_row(r: &Row) -> String {
    let head = format!(
        "| {} | {}D | {} | {:.0} |",
        r.setting,
        r.dimension,
        r.fill,
        r.spacing * 1000.0
    );
    match &r.result {
        Ok([t, t0, z, zl, w]) => format!(
            "{head} {t:.4} | {t0:.4} | {:+.2} % | {z:.4} | {zl:.5} | {w:.0} |",
            100.0 * (t / t0 - 1.0)
        ),
        Err(e) => format!("{head} failed: {e} | | | | | |"),
    }
}

/// Period error and damping ratio against the spacing, a panel each per dimension; a line per setting and
/// fill, the laminar damping dashed.
fn convergence_figure(rows: &[Row]) -> Figure {
    let mut panels = Vec::new();
    for dim in [2, 3] {
        let mut period = Panel {
            title: format!("{dim}D: first-mode period against linear theory"),
            y_label: "period error (%)".into(),
            x_label: "particle spacing dp (mm)".into(),
            markers: true,
            level: Some((0.0, "linear theory".into())),
            ..Default::default()
        };
        let mut damping = Panel {
            title: format!("{dim}D: damping ratio"),
            y_label: "ζ".into(),
            x_label: "particle spacing dp (mm)".into(),
            markers: true,
            ..Default::default()
        };
        for s in &SETTINGS {
            for fill in FILLS {
                let points: Vec<(f64, [f64; 5])> = rows
                    .iter()
                    .filter(|r| r.setting == s.name && r.dimension == dim && r.fill == fill)
                    .filter_map(|r| r.result.as_ref().ok().map(|v| (r.spacing * 1000.0, *v)))
                    .collect();
                if points.is_empty() {
                    continue;
                }
                let label = format!("{}, fill {fill} m", s.name);
                let x: Vec<f64> = points.iter().map(|p| p.0).collect();
                period.series.push(Series {
                    label: label.clone(),
                    t: x.clone(),
                    y: points
                        .iter()
                        .map(|p| 100.0 * (p.1[0] / p.1[1] - 1.0))
                        .collect(),
                    reference: false,
                });
                damping.series.push(Series {
                    label,
                    t: x,
                    y: points.iter().map(|p| p.1[2]).collect(),
                    reference: false,
                });
            }
        }
        for fill in FILLS {
            let laminar: Vec<(f64, f64)> = rows
                .iter()
                .filter(|r| r.dimension == dim && r.fill == fill)
                .filter_map(|r| r.result.as_ref().ok().map(|v| (r.spacing * 1000.0, v[3])))
                .collect();
            if let (Some(lo), Some(hi)) = (
                laminar.iter().map(|p| p.0).reduce(f64::min),
                laminar.iter().map(|p| p.0).reduce(f64::max),
            ) {
                damping.series.push(Series {
                    label: format!("laminar theory, fill {fill} m"),
                    t: vec![lo, hi],
                    y: vec![laminar[0].1; 2],
                    reference: true,
                });
            }
        }
        if !period.series.is_empty() {
            panels.push(period);
            panels.push(damping);
        }
    }
    Figure {
        title: "Seed tank, first sloshing mode: free decay against linear theory".into(),
        panels,
        columns: 2,
    }
}
