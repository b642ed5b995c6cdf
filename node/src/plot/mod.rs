//! `slosh plot DIR`: figures of a run's outputs, as PNG and SVG in `DIR/plots`: the probe elevations with
//! the fill level marked (`probes`), the six wrench components (`wrench`) and the pressure sensors
//! (`pressure`). Reference tables (`--reference FILE.csv`: a time column and columns named like the run's,
//! e.g. a probe name, `fx`, a sensor name) are overlaid on the panels of the same name.

pub mod figure;
pub mod table;

use figure::{Figure, Panel, Series};
use std::path::{Path, PathBuf};
use table::Table;

/// What to draw and where.
#[derive(Clone, Debug)]
pub struct PlotOptions {
    /// Image size in pixels (width, height).
    pub size: (u32, u32),
    /// Tables of measured or analytic data to overlay.
    pub references: Vec<PathBuf>,
    /// Output folder (None: `DIR/plots`).
    pub out: Option<PathBuf>,
}

impl Default for PlotOptions {
    fn default() -> Self {
        Self {
            size: (1200, 800),
            references: Vec::new(),
            out: None,
        }
    }
}

/// What [`plot`] wrote and what it could not match.
#[derive(Clone, Debug, Default)]
pub struct Plotted {
    pub files: Vec<PathBuf>,
    /// Reference columns that name nothing in the run (left out of the figures).
    pub unmatched: Vec<String>,
}

/// Parses `WIDTHxHEIGHT`.
pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("--size {s:?}: expected WIDTHxHEIGHT in pixels, e.g. 1200x800");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let (w, h): (u32, u32) = (
        w.trim().parse().map_err(|_| bad())?,
        h.trim().parse().map_err(|_| bad())?,
    );
    if !(200..=10_000).contains(&w) || !(150..=10_000).contains(&h) {
        return Err(format!(
            "--size {s:?}: between 200x150 and 10000x10000 pixels, please"
        ));
    }
    Ok((w, h))
}

/// The fill level and a title from the run's `summary.json` (if it is there).
fn run_facts(dir: &Path) -> (Option<f64>, String) {
    let name = dir
        .canonicalize()
        .ok()
        .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
        .unwrap_or_else(|| dir.display().to_string());
    let summary: Option<serde_json::Value> = std::fs::read_to_string(dir.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    let fill = summary
        .as_ref()
        .and_then(|s| s["parameters"]["fill_height"].as_f64());
    (fill, name)
}

fn run_series(label: &str, t: &Table, col: usize) -> Series {
    Series {
        label: label.to_string(),
        t: t.time.clone(),
        y: t.data[col].clone(),
        reference: false,
    }
}

/// Draws the figures of the run in `dir`.
pub fn plot(dir: &Path, opts: &PlotOptions) -> Result<Plotted, String> {
    let read = |name: &str| -> Result<Table, String> {
        let path = dir.join(name);
        if !path.exists() {
            return Err(format!(
                "{}: not found; `slosh plot` reads the folder a `slosh run` or `slosh replay` wrote (probes.csv, wrench.csv, pressure.csv, summary.json)",
                path.display()
            ));
        }
        table::read(&path)
    };
    let probes = read("probes.csv")?;
    let wrench = read("wrench.csv")?;
    let pressure = read("pressure.csv")?;
    let references = opts
        .references
        .iter()
        .map(|p| table::read(p))
        .collect::<Result<Vec<_>, _>>()?;
    let (fill, name) = run_facts(dir);
    let mut out = Plotted::default();

    // A panel per run column, with the reference columns of the same name.
    let mut matched = vec![vec![false; 0]; references.len()];
    for (m, r) in matched.iter_mut().zip(&references) {
        *m = vec![false; r.columns.len()];
    }
    let mut panel = |t: &Table, col: usize, title: String, y_label: &str| -> Panel {
        let name = &t.columns[col];
        let mut series = vec![run_series("this run", t, col)];
        for (k, r) in references.iter().enumerate() {
            if let Some(i) = r.columns.iter().position(|c| c == name) {
                matched[k][i] = true;
                let label = Path::new(&r.path)
                    .file_stem()
                    .map(|s| s.to_string_lossy().into_owned())
                    .unwrap_or_else(|| r.path.clone());
                series.push(Series {
                    label,
                    t: r.time.clone(),
                    y: r.data[i].clone(),
                    reference: true,
                });
            }
        }
        Panel {
            title,
            y_label: y_label.to_string(),
            series,
            ..Default::default()
        }
    };

    let mut figures: Vec<(&str, Figure)> = Vec::new();
    let probe_panels: Vec<Panel> = (0..probes.columns.len())
        .map(|c| {
            let mut p = panel(
                &probes,
                c,
                format!("probe {}: free-surface elevation", probes.columns[c]),
                "elevation above the tank bottom (m)",
            );
            p.level = fill.map(|f| (f, format!("fill level {f} m")));
            p
        })
        .collect();
    if !probe_panels.is_empty() {
        figures.push((
            "probes",
            Figure {
                title: format!("{name}: wave probes"),
                panels: probe_panels,
                columns: 1,
            },
        ));
    }
    let names = [
        ("fx", "force x", "N"),
        ("mx", "moment x", "N·m"),
        ("fy", "force y", "N"),
        ("my", "moment y", "N·m"),
        ("fz", "force z", "N"),
        ("mz", "moment z", "N·m"),
    ];
    let mut wrench_panels = Vec::new();
    for (col, what, unit) in names {
        let c = wrench
            .columns
            .iter()
            .position(|n| n == col)
            .ok_or_else(|| format!("{}: no column {col}", wrench.path))?;
        wrench_panels.push(panel(
            &wrench,
            c,
            format!("{what} ({col}) of the liquid on the tank"),
            &format!("{col} ({unit})"),
        ));
    }
    figures.push((
        "wrench",
        Figure {
            title: format!("{name}: sloshing force and moment (tank frame, about the tank origin)"),
            panels: wrench_panels,
            columns: 2,
        },
    ));
    let pressure_panels: Vec<Panel> = (0..pressure.columns.len())
        .map(|c| {
            panel(
                &pressure,
                c,
                format!("pressure sensor {}", pressure.columns[c]),
                "gauge pressure (Pa)",
            )
        })
        .collect();
    if !pressure_panels.is_empty() {
        let columns = if pressure_panels.len() > 3 { 2 } else { 1 };
        figures.push((
            "pressure",
            Figure {
                title: format!("{name}: pressure sensors"),
                panels: pressure_panels,
                columns,
            },
        ));
    }

    for (k, r) in references.iter().enumerate() {
        let unmatched: Vec<&String> = r
            .columns
            .iter()
            .zip(&matched[k])
            .filter(|(_, m)| !**m)
            .map(|(c, _)| c)
            .collect();
        if unmatched.len() == r.columns.len() {
            return Err(format!(
                "{}: none of its columns ({}) is named like a column of the run: probes {}, wrench fx..mz, pressure sensors {}",
                r.path,
                r.columns.join(", "),
                probes.columns.join(", "),
                if pressure.columns.is_empty() { "(none)".to_string() } else { pressure.columns.join(", ") }
            ));
        }
        out.unmatched
            .extend(unmatched.into_iter().map(|c| format!("{}: {c}", r.path)));
    }

    let folder = opts.out.clone().unwrap_or_else(|| dir.join("plots"));
    std::fs::create_dir_all(&folder).map_err(|e| format!("{}: {e}", folder.display()))?;
    for (stem, f) in &figures {
        out.files
            .extend(figure::save(f, &folder.join(stem), opts.size)?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_parse_and_bad_ones_say_the_form() {
        assert_eq!(parse_size("800x600"), Ok((800, 600)));
        assert!(parse_size("800").unwrap_err().contains("WIDTHxHEIGHT"));
        assert!(parse_size("10x10").unwrap_err().contains("between"));
    }
}
