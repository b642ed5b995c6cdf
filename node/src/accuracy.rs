//! How accurate a spacing is, from the manual's convergence table (`docs/src/validation/convergence.csv`,
//! made by `cargo run --release -p slosh-node --example sloshing_convergence`): the seed tank's first sloshing
//! mode in free decay, per scheme setting, dimension, fill and spacing, against linear theory. A spacing
//! passes when the period is within [`PERIOD_TOLERANCE`] of theory and the damping ratio at most
//! [`DAMPING_LIMIT`]. Spacings carry over between tanks as particles per liquid depth (fill height / spacing).

use sph::kernel::KernelKind;
use sph::params::{Scheme, SimParams};
use std::fmt::Write;

/// The convergence table, as the convergence command wrote it.
const TABLE: &str = include_str!("../convergence.csv");

/// The first mode's period within 1 % of linear theory for the fill simulated (ω² = g k tanh kh).
pub const PERIOD_TOLERANCE: f64 = 0.01;
/// Small model tanks measure damping ratios of 0.001–0.005 (laminar Stokes layers give less): more damps
/// every resonance a user studies.
pub const DAMPING_LIMIT: f64 = 0.005;

/// The table's columns.
pub const CSV_HEADER: &str = "setting,dimension,fill_m,dp_m,period_s,theory_period_s,period_error,damping_ratio,laminar_damping_ratio,wall_s,error";

/// A scheme setting of the table: its name and what it changes from the seed tank's defaults
/// (`sph::sloshing::experiment::seed_tank`).
pub struct Setting {
    pub name: &'static str,
    pub apply: fn(&mut SimParams),
}

const SHIPPED_DFSPH: &str = "dfsph (shipped)";
const CORRECTED_DFSPH: &str = "dfsph + kernel_correction, wendland, α 0";
const SHIPPED_WCSPH: &str = "wcsph (shipped)";

/// The settings the convergence command measures.
pub const SETTINGS: [Setting; 3] = [
    Setting {
        name: SHIPPED_DFSPH,
        apply: |p| p.solver.scheme = Scheme::Dfsph,
    },
    Setting {
        name: CORRECTED_DFSPH,
        apply: |p| {
            p.solver.scheme = Scheme::Dfsph;
            p.solver.kernel = KernelKind::Wendland;
            p.solver.dfsph.kernel_correction = true;
            p.solver.artificial_viscosity.alpha = 0.0;
        },
    },
    Setting {
        name: SHIPPED_WCSPH,
        apply: |p| p.solver.scheme = Scheme::Wcsph,
    },
];

/// One free decay of the table.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    pub setting: String,
    pub dimension: usize,
    pub fill: f64,
    pub spacing: f64,
    /// Period, theory period (s), damping ratio, laminar damping ratio, wall seconds; or why the run failed.
    pub result: Result<[f64; 5], String>,
}

impl Row {
    /// Particles per liquid depth.
    pub fn per_depth(&self) -> f64 {
        self.fill / self.spacing
    }

    pub fn passes(&self) -> bool {
        match &self.result {
            Ok([t, t0, z, ..]) => (t / t0 - 1.0).abs() <= PERIOD_TOLERANCE && *z <= DAMPING_LIMIT,
            Err(_) => false,
        }
    }

    /// "period 2.2 % short, damping ratio 0.027 (2D seed tank, fill 0.19 m, dp 0.008 m: 24 particles per depth)".
    pub fn describe(&self) -> String {
        let place = format!(
            "({}D seed tank, fill {} m, dp {} m: {:.0} particles per depth)",
            self.dimension,
            self.fill,
            self.spacing,
            self.per_depth()
        );
        match &self.result {
            Ok([t, t0, z, ..]) => format!(
                "period {:.1} % {}, damping ratio {z:.3} {place}",
                100.0 * (t / t0 - 1.0).abs(),
                if t < t0 { "short" } else { "long" }
            ),
            Err(why) => format!("no result ({why}) {place}"),
        }
    }
}

/// The convergence command's CSV: its first line names the machine (`# ...`), then [`CSV_HEADER`], then a row
/// per free decay (the setting quoted, its name has commas; a failed run's error quoted).
pub fn csv(heading: &str, rows: &[Row]) -> String {
    let mut out = format!("# {heading}\n{CSV_HEADER}\n");
    for r in rows {
        let head = format!("\"{}\",{},{},{}", r.setting, r.dimension, r.fill, r.spacing);
        match &r.result {
            Ok([t, t0, z, zl, w]) => writeln!(
                out,
                "{head},{t:.6},{t0:.6},{:.6},{z:.6},{zl:.6},{w:.1},",
                t / t0 - 1.0
            ),
            Err(e) => writeln!(out, "{head},,,,,,,\"{}\"", e.replace('"', "'")),
        }
        .expect("writing to a string");
    }
    out
}

/// `old` with `new` in place of its rows of the same setting, dimension, fill and spacing, in the order the
/// whole command writes them (by setting, dimension, spacing from coarse to fine, fill).
pub fn merge(old: Vec<Row>, new: Vec<Row>) -> Vec<Row> {
    let key = |r: &Row| (r.setting.clone(), r.dimension, r.fill, r.spacing);
    let mut rows: Vec<Row> = old
        .into_iter()
        .filter(|r| !new.iter().any(|n| key(n) == key(r)))
        .collect();
    rows.extend(new);
    let setting = |r: &Row| SETTINGS.iter().position(|s| s.name == r.setting);
    rows.sort_by(|a, b| {
        (setting(a), a.dimension)
            .cmp(&(setting(b), b.dimension))
            .then(b.spacing.total_cmp(&a.spacing))
            .then(a.fill.total_cmp(&b.fill))
    });
    rows
}

/// The rows of a CSV that [`csv`] wrote, and its first line's machine.
pub fn read_csv(text: &str) -> Result<(Vec<Row>, String), String> {
    let mut lines = text.lines();
    let heading = lines
        .next()
        .and_then(|l| l.strip_prefix("# "))
        .ok_or("the first line must name the machine (`# ...`)")?
        .to_string();
    if lines.next() != Some(CSV_HEADER) {
        return Err(format!("the second line must be the columns: {CSV_HEADER}"));
    }
    let rows = lines
        .enumerate()
        .map(|(i, l)| {
            let bad = |what: &str| format!("row {}: {what}: {l}", i + 1);
            let (setting, rest) = l
                .strip_prefix('"')
                .and_then(|l| l.split_once("\","))
                .ok_or_else(|| bad("the setting is not quoted"))?;
            let f: Vec<&str> = rest.splitn(10, ',').collect();
            if f.len() != 10 {
                return Err(bad("not 11 columns"));
            }
            let num = |k: usize| f[k].parse::<f64>().map_err(|_| bad("not a number"));
            let result = if f[9].is_empty() {
                Ok([num(3)?, num(4)?, num(6)?, num(7)?, num(8)?])
            } else {
                Err(f[9].trim_matches('"').to_string())
            };
            Ok(Row {
                setting: setting.to_string(),
                dimension: f[0].parse().map_err(|_| bad("not a dimension"))?,
                fill: num(1)?,
                spacing: num(2)?,
                result,
            })
        })
        .collect::<Result<_, String>>()?;
    Ok((rows, heading))
}

/// The table's setting that a case runs: the shipped scheme settings, or the incompressible scheme with
/// corrected kernel gradients, the Wendland kernel and no artificial viscosity. Other changes to a scheme's
/// settings are not told apart.
pub fn setting_of(p: &SimParams) -> &'static str {
    match p.solver.scheme {
        Scheme::Wcsph => SHIPPED_WCSPH,
        Scheme::Dfsph
            if p.solver.dfsph.kernel_correction
                && p.solver.kernel == KernelKind::Wendland
                && p.solver.artificial_viscosity.alpha == 0.0 =>
        {
            CORRECTED_DFSPH
        }
        Scheme::Dfsph => SHIPPED_DFSPH,
    }
}

/// What the table says about a case's setting and dimension.
#[derive(Debug, Clone, PartialEq)]
pub struct Accuracy {
    /// The rows of the case's setting and dimension.
    pub rows: Vec<Row>,
    /// The fewest particles per depth from which every measured spacing passes (None: none passes).
    pub per_depth: Option<f64>,
}

impl Accuracy {
    /// From the rows of `table` for the setting and dimension of `p`.
    pub fn of(table: &[Row], p: &SimParams) -> Self {
        let setting = setting_of(p);
        let rows = table
            .iter()
            .filter(|r| r.setting == setting && r.dimension == p.dimension)
            .cloned()
            .collect();
        Self::from_rows(rows)
    }

    /// From the rows of one setting and dimension (failed runs left out).
    pub fn from_rows(mut rows: Vec<Row>) -> Self {
        rows.retain(|r| r.result.is_ok());
        rows.sort_by(|a, b| a.per_depth().total_cmp(&b.per_depth()));
        // The coarsest row from which all finer rows pass.
        let mut per_depth = None;
        for r in rows.iter().rev() {
            if !r.passes() {
                break;
            }
            per_depth = Some(r.per_depth());
        }
        Self { rows, per_depth }
    }

    /// From the manual's table.
    pub fn for_case(p: &SimParams) -> Self {
        let (rows, _) = read_csv(TABLE).expect("the built-in convergence table reads");
        Self::of(&rows, p)
    }

    /// The coarsest spacing that passes for a case whose liquid is `fill` m deep (None: none measured passes).
    pub fn coarsest_spacing(&self, fill: f64) -> Option<f64> {
        self.per_depth.map(|n| fill / n)
    }

    /// The measured row nearest (in particles per depth) to a case `fill` m deep at spacing `dp`.
    pub fn nearest(&self, fill: f64, dp: f64) -> Option<&Row> {
        let n = fill / dp;
        self.rows.iter().min_by(|a, b| {
            (a.per_depth() - n)
                .abs()
                .total_cmp(&(b.per_depth() - n).abs())
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use sph::params::TankSpec;

    const SAMPLE: &str = "# a machine\nsetting,dimension,fill_m,dp_m,period_s,theory_period_s,period_error,damping_ratio,laminar_damping_ratio,wall_s,error\n\
\"a, b\",2,0.19,0.04,0.920000,1.000000,-0.080000,0.030000,0.000700,0.3,\n\
\"a, b\",2,0.19,0.02,1.015000,1.000000,0.015000,0.030000,0.000700,0.7,\n\
\"a, b\",2,0.39,0.02,1.012000,1.000000,0.012000,0.011000,0.000400,1.1,\n\
\"a, b\",2,0.19,0.01,1.004000,1.000000,0.004000,0.004000,0.000700,3.0,\n\
\"a, b\",2,0.19,0.005,1.001000,1.000000,0.001000,0.000600,0.000700,17.4,\n\
\"a, b\",2,0.39,0.005,,,,,,,\"the run failed\"\n\
\"a, b\",3,0.19,0.02,1.001000,1.000000,0.001000,0.020000,0.002000,22.6,\n";

    #[test]
    fn merged_rows_replace_their_namesakes_in_the_command_s_order() {
        let row = |setting: &str, dimension, fill, spacing, t: f64| Row {
            setting: setting.to_string(),
            dimension,
            fill,
            spacing,
            result: Ok([t, 1.0, 0.01, 0.001, 1.0]),
        };
        let old = vec![
            row(SHIPPED_WCSPH, 2, 0.19, 0.02, 0.9),
            row(SHIPPED_DFSPH, 3, 0.19, 0.02, 0.9),
            row(SHIPPED_DFSPH, 2, 0.19, 0.04, 0.9),
            row(SHIPPED_DFSPH, 2, 0.39, 0.04, 0.9),
        ];
        let new = vec![
            row(SHIPPED_DFSPH, 3, 0.39, 0.01, 1.1),
            row(SHIPPED_DFSPH, 3, 0.19, 0.02, 1.2),
            row(SHIPPED_DFSPH, 3, 0.19, 0.01, 1.1),
        ];
        let merged = merge(old, new);
        let keys: Vec<(&str, usize, f64, f64)> = merged
            .iter()
            .map(|r| (r.setting.as_str(), r.dimension, r.fill, r.spacing))
            .collect();
        assert_eq!(
            keys,
            [
                (SHIPPED_DFSPH, 2, 0.19, 0.04),
                (SHIPPED_DFSPH, 2, 0.39, 0.04),
                (SHIPPED_DFSPH, 3, 0.19, 0.02),
                (SHIPPED_DFSPH, 3, 0.19, 0.01),
                (SHIPPED_DFSPH, 3, 0.39, 0.01),
                (SHIPPED_WCSPH, 2, 0.19, 0.02),
            ]
        );
        // The new row replaced the old one of the same setting, dimension, fill and spacing.
        assert_eq!(merged[2].result.as_ref().unwrap()[0], 1.2);
        // The built-in table is in that order already.
        let (table, _) = read_csv(TABLE).unwrap();
        assert_eq!(merge(table.clone(), vec![]), table);
    }

    #[test]
    fn the_table_is_read_and_the_coarsest_passing_depth_found() {
        let (rows, machine) = read_csv(SAMPLE).unwrap();
        assert_eq!(machine, "a machine");
        assert_eq!(rows.len(), 7, "{rows:?}");
        assert_eq!(rows[0].setting, "a, b");
        assert_eq!(rows[5].result, Err("the run failed".to_string()));
        // What the convergence command writes, it reads back.
        assert_eq!(csv(&machine, &rows), SAMPLE);
        assert!(read_csv("# m\nsetting,dimension\n").is_err());
        assert!(read_csv(&SAMPLE.replace("0.004000,0.000700,3.0", "x,0.000700,3.0")).is_err());
        assert!(!rows[0].passes() && rows[3].passes());
        let two = Accuracy::from_rows(rows.iter().filter(|r| r.dimension == 2).cloned().collect());
        // 0.19 m at 10 mm (19 per depth) and finer pass, but 0.39 m at 20 mm (19.5 per depth) does not: every
        // measured spacing passes from 38 per depth.
        assert_eq!(two.per_depth, Some(0.19 / 0.005));
        assert_eq!(two.coarsest_spacing(0.38), Some(0.01));
        let three =
            Accuracy::from_rows(rows.iter().filter(|r| r.dimension == 3).cloned().collect());
        assert_eq!(three.per_depth, None);
    }

    #[test]
    fn the_manual_s_table_names_every_setting_a_case_can_run() {
        let (table, machine) = read_csv(TABLE).unwrap();
        assert!(table.len() >= 30, "{} rows", table.len());
        // (Written again from the values read, the period error column can differ in its last digit: it is
        // the ratio of the unrounded periods.)
        assert_eq!(
            read_csv(&csv(&machine, &table)).unwrap(),
            (table.clone(), machine)
        );
        let tank = TankSpec {
            length: 0.8,
            breadth: 0.25,
            height: 0.6,
        };
        let mut p = SimParams::filled_tank(2, tank, 0.19, 0.008);
        // (WCSPH is not measured in 3D: too slow on two cores. No row: no accurate spacing.)
        for (scheme, dimension) in [(Scheme::Wcsph, 2), (Scheme::Dfsph, 2), (Scheme::Dfsph, 3)] {
            p.solver.scheme = scheme;
            p.dimension = dimension;
            let a = Accuracy::of(&table, &p);
            assert!(a.rows.len() >= 4, "{scheme:?} {dimension}D: {a:?}");
        }
        p.solver.scheme = Scheme::Wcsph;
        p.dimension = 3;
        assert_eq!(Accuracy::of(&table, &p).per_depth, None);
        // The corrected incompressible scheme passes in 2D from about 24 particles per depth: at most 8 mm for
        // the seed tank's 0.19 m; the shipped settings pass nowhere.
        p.dimension = 2;
        p.solver.scheme = Scheme::Dfsph;
        p.solver.kernel = KernelKind::Wendland;
        p.solver.dfsph.kernel_correction = true;
        p.solver.artificial_viscosity.alpha = 0.0;
        let a = Accuracy::of(&table, &p);
        let dp = a.coarsest_spacing(0.19).expect("a passing spacing");
        assert!((0.005..=0.0105).contains(&dp), "{dp}");
        p.solver.dfsph.kernel_correction = false;
        assert_eq!(Accuracy::of(&table, &p).per_depth, None);
        let near = Accuracy::of(&table, &p)
            .nearest(0.19, 0.008)
            .unwrap()
            .clone();
        assert_eq!((near.fill, near.spacing), (0.19, 0.008));
        assert!(
            near.describe().contains("24 particles per depth"),
            "{}",
            near.describe()
        );
    }
}
