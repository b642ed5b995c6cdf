//! Validation against experiments, from the data files in `../shared/validation/` (not shipped with the
//! project). Run with `cargo test --release -p slosh-tests --features validation`; the directory can be
//! moved with SLOSH_VALIDATION_DIR. A missing file is a failure, never a skip.
#![cfg(feature = "validation")]
// Component loops over the const-generic dimension read as the formulas do; `!(x >= 0.0)` is used on purpose
// to catch NaN along with negatives.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

use slosh_node::config;
use slosh_node::plot::figure::{self, Figure, Panel, Series};
use sph::motion::{SampledMotion, TankMotion};
use sph::observe::Observation;
use std::path::PathBuf;

fn data_dir() -> PathBuf {
    std::env::var("SLOSH_VALIDATION_DIR")
        .map(PathBuf::from)
        .unwrap_or_else(|_| {
            PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../shared/validation")
        })
}

fn read(rel: &str) -> String {
    let p = data_dir().join(rel);
    std::fs::read_to_string(&p).unwrap_or_else(|e| panic!("validation data {} is missing ({e}); set SLOSH_VALIDATION_DIR to the shared/validation folder", p.display()))
}

/// Draws a validation figure (`slosh plot`'s figures: PNG + SVG) into `target/validation/NAME.*` (or
/// `SLOSH_VALIDATION_OUT`), for a person to look at; returns the files, checked to be written.
fn figure(name: &str, title: &str, y_label: &str, series: Vec<Series>) -> Vec<PathBuf> {
    figure_panels(
        name,
        title,
        vec![Panel {
            title: String::new(),
            y_label: y_label.to_string(),
            series,
            ..Default::default()
        }],
    )
}

/// [`figure`] with several panels, one above the other.
fn figure_panels(name: &str, title: &str, panels: Vec<Panel>) -> Vec<PathBuf> {
    let dir = std::env::var("SLOSH_VALIDATION_OUT")
        .map(PathBuf::from)
        .unwrap_or_else(|_| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/validation"));
    std::fs::create_dir_all(&dir).unwrap();
    let height = 600 * panels.len() as u32;
    let f = Figure {
        title: title.to_string(),
        panels,
        columns: 1,
    };
    let files = figure::save(&f, &dir.join(name), (1400, height)).unwrap();
    for f in &files {
        assert!(
            std::fs::metadata(f).unwrap().len() > 1000,
            "{}",
            f.display()
        );
        eprintln!("validation figure: {}", f.display());
    }
    // The manual shows the figures of the run that last updated it (SLOSH_UPDATE_DOCS=1).
    if std::env::var_os("SLOSH_UPDATE_DOCS").is_some() {
        let docs = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../docs/src/images/validation");
        std::fs::create_dir_all(&docs).unwrap();
        for f in files
            .iter()
            .filter(|f| f.extension().is_some_and(|x| x == "png"))
        {
            std::fs::copy(f, docs.join(f.file_name().unwrap())).unwrap();
        }
    }
    files
}

/// One compared number of a validation case.
struct Row {
    quantity: String,
    simulated: String,
    reference: String,
    /// The bound, in words ("printed, not asserted" where there is none).
    bound: String,
    check: Check,
}

/// What a row's number is held to.
#[derive(Clone, Copy, PartialEq)]
enum Check {
    /// An asserted bound, and whether it holds.
    Bound(bool),
    /// A target that is not asserted (yet), and whether it is met (shown as inside or outside).
    Target(bool),
    /// Nothing: printed.
    Printed,
}

/// The numbers of one validation case (`name`, as its figure): each simulated quantity beside what it is
/// compared with and the bound it is held to. [`Results::publish_and_check`] writes them as a table into
/// `target/validation/NAME.md` and, with SLOSH_UPDATE_DOCS=1, into the manual's page `page` between the
/// case's markers (`<!-- results:NAME:begin -->`), then fails on every bound that does not hold.
struct Results {
    name: String,
    page: &'static str,
    run: String,
    rows: Vec<Row>,
    started: std::time::Instant,
}

/// One case at a time rewrites a page (the cases run in parallel, several to a page).
static DOCS: std::sync::Mutex<()> = std::sync::Mutex::new(());

impl Results {
    /// `run`: what was run, in words (scheme, spacing, span); `started`: when the case started.
    fn new(name: &str, page: &'static str, run: &str, started: std::time::Instant) -> Self {
        Self {
            name: name.into(),
            page,
            run: run.into(),
            rows: vec![],
            started,
        }
    }

    fn row(
        &mut self,
        quantity: &str,
        simulated: String,
        reference: String,
        bound: &str,
        ok: Option<bool>,
    ) {
        let check = ok.map_or(Check::Printed, Check::Bound);
        self.push(quantity, simulated, reference, bound, check);
    }

    /// A row held to a target that is not asserted (yet): the table says whether it is met.
    fn target(
        &mut self,
        quantity: &str,
        simulated: String,
        reference: String,
        bound: &str,
        met: bool,
    ) {
        self.push(quantity, simulated, reference, bound, Check::Target(met));
    }

    fn push(
        &mut self,
        quantity: &str,
        simulated: String,
        reference: String,
        bound: &str,
        check: Check,
    ) {
        self.rows.push(Row {
            quantity: quantity.into(),
            simulated,
            reference,
            bound: bound.into(),
            check,
        });
    }

    /// The table, with where and when it was measured.
    fn markdown(&self) -> String {
        let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
        let mut t = format!(
            "{}: measured by the validation command on {} ({threads} threads), {}, commit {}, in {:.0} s.\n\n",
            self.run,
            slosh_node::manual::machine(),
            slosh_node::manual::today(),
            slosh_node::manual::commit(),
            self.started.elapsed().as_secs_f64()
        );
        t.push_str("| quantity | simulated | reference | bound | |\n|---|---|---|---|---|\n");
        for r in &self.rows {
            let mark = match r.check {
                Check::Bound(true) => "pass",
                Check::Bound(false) => "**fails**",
                Check::Target(true) => "inside",
                Check::Target(false) => "outside",
                Check::Printed => "",
            };
            t.push_str(&format!(
                "| {} | {} | {} | {} | {mark} |\n",
                r.quantity, r.simulated, r.reference, r.bound
            ));
        }
        t
    }

    /// Writes the table (see [`Results`]), then asserts every bound.
    fn publish_and_check(self) {
        let table = self.markdown();
        let dir = std::env::var("SLOSH_VALIDATION_OUT")
            .map(PathBuf::from)
            .unwrap_or_else(|_| {
                PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../target/validation")
            });
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join(format!("{}.md", self.name)), &table).unwrap();
        eprintln!("{}\n{table}", self.name);
        if std::env::var_os("SLOSH_UPDATE_DOCS").is_some() {
            let _one = DOCS.lock().unwrap_or_else(|e| e.into_inner());
            let page = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
                .join("../docs/src/validation")
                .join(self.page);
            let text = std::fs::read_to_string(&page).unwrap();
            let text =
                slosh_node::manual::replace_block(&text, &format!("results:{}", self.name), &table)
                    .unwrap_or_else(|e| panic!("{}: {e}", page.display()));
            std::fs::write(&page, text).unwrap();
        }
        let failed: Vec<String> = self
            .rows
            .iter()
            .filter(|r| r.check == Check::Bound(false))
            .map(|r| {
                format!(
                    "{}: {} against {} ({})",
                    r.quantity, r.simulated, r.reference, r.bound
                )
            })
            .collect();
        assert!(failed.is_empty(), "{}: {}", self.name, failed.join("; "));
    }
}

fn series(label: &str, t: &[f64], y: &[f64], reference: bool) -> Series {
    Series {
        label: label.to_string(),
        t: t.to_vec(),
        y: y.to_vec(),
        reference,
    }
}

/// Numbers of a whitespace/comma/semicolon-separated table, skipping lines that do not parse.
fn table(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .filter_map(|l| {
            let v: Result<Vec<f64>, _> = l
                .split(|c: char| c == ',' || c == ';' || c.is_whitespace())
                .filter(|s| !s.is_empty())
                .map(str::parse)
                .collect();
            v.ok().filter(|v| !v.is_empty())
        })
        .collect()
}

fn interp(t: &[f64], y: &[f64], x: f64) -> f64 {
    let i = t.partition_point(|&v| v <= x).clamp(1, t.len() - 1);
    let w = (x - t[i - 1]) / (t[i] - t[i - 1]);
    y[i - 1] + w * (y[i] - y[i - 1])
}

/// A built-in case with overrides, built and ready to step.
fn simulation(case: &str, overrides: &[&str]) -> Box<dyn sph::Solver> {
    let o: Vec<String> = overrides.iter().map(|s| s.to_string()).collect();
    let cfg = config::load(case, &o).unwrap();
    sph::build(cfg.sim_params().unwrap()).unwrap()
}

/// Runs a built-in case with overrides under `motion`, observing it every `every` s up to `t_end`.
fn observe(
    case: &str,
    overrides: &[&str],
    motion: &dyn TankMotion,
    t_end: f64,
    every: f64,
) -> Vec<Observation> {
    let mut sim = simulation(case, overrides);
    let mut out = vec![];
    let mut k = 0;
    while sim.time() < t_end {
        sim.advance_to(motion, k as f64 * every).unwrap();
        out.push(sim.observe(motion).unwrap());
        k += 1;
    }
    out
}

/// [`observe`], keeping (time, probe 0, sensor 0).
fn run(
    case: &str,
    overrides: &[&str],
    motion: &dyn TankMotion,
    t_end: f64,
    every: f64,
) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let obs = observe(case, overrides, motion, t_end, every);
    (
        obs.iter().map(|o| o.time).collect(),
        obs.iter().map(|o| o.probes[0]).collect(),
        obs.iter().map(|o| o.pressures[0]).collect(),
    )
}

/// Linear potential-flow elevation at `x_wall` from the left wall of a 2D tank (length l, depth h) forced by
/// x_T = a cos(ωt) from rest: modal superposition of the odd modes, each β_n'' + ω_n² β_n = −(ω_n²/g) c_n ẍ_T
/// with c_n = −4l/(n²π²) the cosine coefficients of the horizontal coordinate (Faltinsen & Timokha 2009, ch. 5).
fn linear_forced_sway(t: f64, x_wall: f64, l: f64, h: f64, a: f64, period: f64) -> f64 {
    let (g, w) = (9.81, 2.0 * std::f64::consts::PI / period);
    (1..60)
        .step_by(2)
        .map(|n| {
            let n = n as f64;
            let k = n * std::f64::consts::PI / l;
            let wn2 = g * k * (k * h).tanh();
            let c = -4.0 * l / (n * n * std::f64::consts::PI.powi(2));
            let beta =
                wn2 / g * c * a * w * w * ((w * t).cos() - (wn2.sqrt() * t).cos()) / (wn2 - w * w);
            beta * (k * x_wall).cos()
        })
        .sum()
}

/// WCSPH reads an rms 1.30x the record's (its waves too high): it keeps the looser bound of 0.8-1.5, and
/// fails the 0.85-1.15 the incompressible scheme meets.
#[test]
fn faltinsen_2000_forced_sway_elevation_near_the_wall() {
    faltinsen_2000(&[], "faltinsen2000_sway", "WCSPH", 0.8..1.5);
}

/// The same comparison with the incompressible scheme, whose rms is within 15 % of the record's.
#[test]
fn faltinsen_2000_forced_sway_elevation_near_the_wall_dfsph() {
    faltinsen_2000(
        &["solver.scheme=dfsph"],
        "faltinsen2000_sway_dfsph",
        "DFSPH",
        0.85..1.15,
    );
}

/// Faltinsen et al. (2000), fig. 7: elevation 5 cm from the wall of a 1.73 m tank, 0.6 m deep, swayed
/// 32 mm at 1.3 s, against linear theory (first 1.5 s) and the record (0–7 s), with `overrides` on top of
/// dp 20 mm; draws the figure `name`. The simulated rms over the record's must lie in `rms_ratio`.
fn faltinsen_2000(overrides: &[&str], name: &str, scheme: &str, rms_ratio: std::ops::Range<f64>) {
    let started = std::time::Instant::now();
    let exp = table(&read(
        "faltinsen2000_sway/faltinsen_etal_2000_fig7_h0.6_T1.3.csv",
    ));
    assert!(exp.len() > 150, "expected the 170 digitised points");
    let cfg = config::load("faltinsen2000_sway", &[]).unwrap();
    let motion = slosh_node::motion_source::build(&cfg).unwrap();
    let t_end = 7.0;
    let mut o = vec!["particle_spacing=0.02"];
    o.extend_from_slice(overrides);
    let (t, probe, _) = run("faltinsen2000_sway", &o, motion.as_ref(), t_end, 0.02);
    let eta: Vec<f64> = probe.iter().map(|p| p - 0.6).collect();
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();

    // 1. Physics: while the waves are small (first 1.5 s) the simulation follows linear potential theory for
    //    the same forcing, started from rest.
    let early: Vec<usize> = (0..t.len()).filter(|&i| t[i] <= 1.5).collect();
    let lin: Vec<f64> = early
        .iter()
        .map(|&i| linear_forced_sway(t[i], 0.05, 1.73, 0.6, 0.032, 1.3))
        .collect();
    let diff: Vec<f64> = early.iter().zip(&lin).map(|(&i, l)| eta[i] - l).collect();
    let lin_err = rms(&diff) / rms(&lin);
    eprintln!(
        "Faltinsen 2000 ({scheme}), first 1.5 s against linear theory: rms {:.4} m, difference {:.0} %",
        rms(&lin),
        100.0 * lin_err
    );

    // 2. Experiment (0-7 s): the crests and troughs come at the measured times (correlation), and the
    //    elevation has the measured size within the bound documented in the manual's validation page: the simulation is about
    //    1.3x the record, mostly from its larger crests after 2 s (0.196 m against 0.157 m in linear theory and
    //    0.142 m measured; the figure this test draws shows all three).
    let pts: Vec<&Vec<f64>> = exp.iter().filter(|r| r[0] <= t_end).collect();
    let sim_at: Vec<f64> = pts.iter().map(|r| interp(&t, &eta, r[0])).collect();
    let meas: Vec<f64> = pts.iter().map(|r| r[1]).collect();
    let corr = correlation(&sim_at, &meas);
    let ratio = rms(&sim_at) / rms(&meas);
    let max_exp = meas.iter().map(|v| v.abs()).fold(0.0, f64::max);
    let max_sim = eta.iter().map(|v| v.abs()).fold(0.0, f64::max);
    eprintln!(
        "Faltinsen 2000 ({scheme}), 0-{t_end} s against the experiment: correlation {corr:.3}, rms ratio {ratio:.2}, peak {max_sim:.3} m vs {max_exp:.3} m"
    );
    let lin_all: Vec<f64> = t
        .iter()
        .map(|&x| linear_forced_sway(x, 0.05, 1.73, 0.6, 0.032, 1.3))
        .collect();
    let (te, ye): (Vec<f64>, Vec<f64>) = pts.iter().map(|r| (r[0], r[1])).unzip();
    let label = format!("slosh ({scheme}, dp 20 mm)");
    figure(
        name,
        "Faltinsen et al. (2000): elevation 5 cm from the wall, h = 0.6 m, T = 1.3 s",
        "elevation (m)",
        vec![
            series(&label, &t, &eta, false),
            series("measured (Faltinsen et al. 2000, fig. 7)", &te, &ye, true),
            series("linear potential theory", &t, &lin_all, true),
        ],
    );
    let mut r = Results::new(
        name,
        "faltinsen2000.md",
        &format!("{scheme}, dp 20 mm, 0-{t_end} s"),
        started,
    );
    r.row(
        "elevation over 0-1.5 s, rms difference from linear theory",
        format!("{:.0} %", 100.0 * lin_err),
        format!("linear theory, rms {:.1} mm", 1000.0 * rms(&lin)),
        "< 15 %",
        Some(lin_err < 0.15),
    );
    r.row(
        "correlation with the record, 0-7 s",
        format!("{corr:.3}"),
        "1".into(),
        "> 0.9",
        Some(corr > 0.9),
    );
    r.row(
        "rms over the record's rms, 0-7 s",
        format!("{ratio:.2}"),
        "1".into(),
        &format!("{:.2}-{:.2}", rms_ratio.start, rms_ratio.end),
        Some(rms_ratio.contains(&ratio)),
    );
    r.row(
        "highest elevation",
        format!("{max_sim:.3} m"),
        format!("{max_exp:.3} m"),
        "printed, not asserted",
        None,
    );
    r.publish_and_check();
}

#[test]
fn spheric10_sensor1_impacts_come_at_the_measured_times() {
    spheric10(
        &["solver.boundary.method=mirror"],
        0.008,
        "spheric10_sensor1",
        "WCSPH, dp 8 mm, mirror walls",
    );
}

/// The same impacts with the incompressible scheme (its walls: the dynamic boundary's particle layers).
#[test]
fn spheric10_sensor1_impacts_come_at_the_measured_times_dfsph() {
    spheric10(
        &["solver.scheme=dfsph"],
        0.008,
        "spheric10_sensor1_dfsph",
        "DFSPH, dp 8 mm",
    );
}

/// The incompressible scheme at 4 and 2 mm, and with corrected kernel gradients at 4 mm: the impact times and
/// the slow pressure around the first impact asserted (the latter within the target's 15 % at these
/// spacings), the rest against the targets. About five minutes.
#[test]
fn spheric10_sensor1_dfsph_at_finer_spacings() {
    for (overrides, dp, name, label) in [
        (
            &["solver.scheme=dfsph"][..],
            0.004,
            "spheric10_sensor1_dfsph_dp4mm",
            "DFSPH, dp 4 mm",
        ),
        (
            &["solver.scheme=dfsph"][..],
            0.002,
            "spheric10_sensor1_dfsph_dp2mm",
            "DFSPH, dp 2 mm",
        ),
        (
            &["solver.scheme=dfsph", "solver.dfsph.kernel_correction=true"][..],
            0.004,
            "spheric10_sensor1_dfsph_corrected_dp4mm",
            "DFSPH with corrected kernel gradients, dp 4 mm",
        ),
    ] {
        spheric10(overrides, dp, name, label);
    }
}

/// WCSPH (mirror walls) at 4 mm: the impact times and the slow pressure around the first impact (within the
/// target's 15 %) asserted, the rest against the targets. About seven minutes.
#[test]
fn spheric10_sensor1_at_4mm() {
    spheric10(
        &["solver.boundary.method=mirror"],
        0.004,
        "spheric10_sensor1_dp4mm",
        "WCSPH, dp 4 mm, mirror walls",
    );
}

/// The same at 2 mm, WCSPH's second resolution. Not in the validation command: it takes 30-60 minutes on two
/// cores. Run it by name with `--ignored` (see the manual's page).
#[test]
#[ignore = "30-60 minutes on two cores; run by name with --ignored"]
fn spheric10_sensor1_at_2mm() {
    spheric10(
        &["solver.boundary.method=mirror"],
        0.002,
        "spheric10_sensor1_dp2mm",
        "WCSPH, dp 2 mm, mirror walls",
    );
}

/// The first three impacts' peaks at sensor 1 over the experiment's ~100 repeats, mean and standard
/// deviation (Pa): Souto-Iglesias, Botia-Vera & Bulian (2011), as a public analysis of the repeatability
/// file gives them (see the manual's page).
const SPHERIC10_REPEATS: [(f64, f64); 3] = [(3710.0, 730.0), (4820.0, 1500.0), (4690.0, 1710.0)];

/// The experiment's sampling interval of its transducer (20 kHz).
const SPHERIC10_SAMPLING: f64 = 5e-5;

/// Sensor 1 of the built-in case `spheric10` with `overrides` under `motion` up to `t_end`: every 2 ms (the
/// series the figure and the slow pressure read), and, where `fine(t)`, sampled as the experiment samples
/// its transducer: after every step at least [`SPHERIC10_SAMPLING`] after the last sample, so every step
/// where the steps are longer. Each sample is the pressure of the step that ends there (the incompressible
/// scheme's: the wall's impulse over the step, divided by it). Returns (t, p) every 2 ms and the fine (t, p).
#[allow(clippy::type_complexity)]
fn spheric10_sensor(
    overrides: &[&str],
    motion: &dyn TankMotion,
    t_end: f64,
    fine: impl Fn(f64) -> bool,
) -> (Vec<f64>, Vec<f64>, (Vec<f64>, Vec<f64>)) {
    let mut sim = simulation("spheric10", overrides);
    let every = 0.002;
    let (mut t, mut p, mut tf, mut pf) = (vec![], vec![], vec![], vec![]);
    let mut k = 0;
    while sim.time() < t_end {
        let next = k as f64 * every;
        while sim.time() < next {
            sim.step(motion).unwrap();
            let now = sim.time();
            if fine(now)
                && tf
                    .last()
                    .is_none_or(|&l| now - l >= SPHERIC10_SAMPLING * (1.0 - 1e-9))
            {
                tf.push(now);
                pf.push(sim.observe(motion).unwrap().pressures[0]);
            }
        }
        let obs = sim.observe(motion).unwrap();
        t.push(obs.time);
        p.push(obs.pressures[0]);
        k += 1;
    }
    (t, p, (tf, pf))
}

/// SPHERIC Test 10 (water, low fill), pressure sensor 1 under the measured roll law at spacing `dp`, with
/// `overrides`; draws the figure `name`. The first three impacts come within 0.1 s of the measured ones and
/// the slow pressure before the first and after it within 15 % (25 % at 8 mm); the table also shows the
/// targets: impacts within 30 ms, their peaks inside the repeats' mean ± 2σ, the slow pressure between
/// impacts within 15 %; and prints each slow-pressure window against the record less the level the record
/// reads as the sensor dries after it ([`spheric10_level_as_it_dries`]).
/// The sensor is read on the wall's face (the case's sensor sits on it), as the flush transducer reads it.
fn spheric10(overrides: &[&str], dp: f64, name: &str, label: &str) {
    let started = std::time::Instant::now();
    let mut r = Results::new(name, "spheric10.md", &format!("{label}, 0-6 s"), started);
    let rows = table(&read("spheric10_dualsphysics/CaseSloshingMotionData.dat"));
    // The measured roll law (degrees) turns the tank about its y axis: pitch in the tank frame.
    // 20 kHz: keep every 20th sample (1 kHz) for the spline.
    // The file's positive angle turns the tank the other way round +y than our pitch does: with the angle
    // as given, the first impact is on the right wall; negated, it is on the left wall at 2.38 s as measured.
    let sign = -1.0;
    let (times, poses): (Vec<f64>, Vec<[f64; 6]>) = rows
        .iter()
        .step_by(20)
        .map(|r| (r[0], [0.0, 0.0, 0.0, 0.0, sign * r[1].to_radians(), 0.0]))
        .unzip();
    let motion = SampledMotion::new(times, &poses).unwrap();
    let mut exp = table(&read(
        "spheric10_dualsphysics/EXP_Pressure_SPHERIC_Benchmark10.txt",
    ));
    exp.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let t_end = 6.0;
    let spacing = format!("particle_spacing={dp}");
    let mut o = vec![spacing.as_str(), "motion.source=none"];
    o.extend_from_slice(overrides);
    let impacts = [2.375, 4.067, 5.672];
    let near_an_impact = |x: f64| impacts.iter().any(|&c| (x - c).abs() <= 0.3);
    let (t, p, (ts_fine, ps_fine)) = spheric10_sensor(&o, &motion, t_end, near_an_impact);
    eprintln!(
        "SPHERIC 10 ({label}) sensor sampled {} times within 0.3 s of the impacts, at least {:.0} us apart",
        ts_fine.len(),
        SPHERIC10_SAMPLING * 1e6
    );
    let (te, pe): (Vec<f64>, Vec<f64>) = exp
        .iter()
        .filter(|r| r[0] <= t_end)
        .map(|r| (r[0], r[1]))
        .unzip();
    let legend = format!("slosh ({label})");
    // Drawn: the 2 ms samples, and near the impacts the samples at the experiment's rate.
    let mut drawn: Vec<(f64, f64)> = (t.iter().zip(&p))
        .filter(|(x, _)| !near_an_impact(**x))
        .chain(ts_fine.iter().zip(&ps_fine))
        .map(|(x, y)| (*x, *y))
        .collect();
    drawn.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (td, pd): (Vec<f64>, Vec<f64>) = drawn.into_iter().unzip();
    figure(
        name,
        "SPHERIC Test 10 (water, low fill): pressure at sensor 1",
        "pressure (Pa)",
        vec![
            series(&legend, &td, &pd, false),
            series("measured", &te, &pe, true),
        ],
    );
    for (&t_peak, &(mean, sd)) in impacts.iter().zip(&SPHERIC10_REPEATS) {
        let window = |lo: f64, hi: f64| {
            ts_fine
                .iter()
                .zip(&ps_fine)
                .filter(|(x, _)| **x >= lo && **x <= hi)
                .map(|(x, y)| (*x, *y))
                .fold((0.0, f64::MIN), |a, b| if b.1 > a.1 { b } else { a })
        };
        let (ts, ps) = window(t_peak - 0.3, t_peak + 0.3);
        let pe = exp
            .iter()
            .filter(|r| (r[0] - t_peak).abs() < 0.3)
            .map(|r| r[1])
            .fold(f64::MIN, f64::max);
        eprintln!("SPHERIC 10 ({label}) impact near {t_peak} s: simulated peak {ps:.0} Pa at {ts:.3} s, measured {pe:.0} Pa");
        r.row(
            &format!("impact near {t_peak} s: time"),
            format!("{ts:.3} s"),
            format!("{t_peak:.3} s"),
            "± 0.1 s",
            Some((ts - t_peak).abs() < 0.1),
        );
        r.target(
            &format!("impact near {t_peak} s: time, against the target"),
            format!("{:+.0} ms", (ts - t_peak) * 1e3),
            format!("{t_peak:.3} s"),
            "± 30 ms",
            (ts - t_peak).abs() <= 0.03,
        );
        // Repetitions scatter by tens of percent: the target is the repeats' spread, not the one record.
        r.target(
            &format!("impact near {t_peak} s: peak"),
            format!("{:.1} kPa", ps / 1000.0),
            format!(
                "{:.1} ± {:.1} kPa over the repeats (record {:.1})",
                mean / 1000.0,
                sd / 1000.0,
                pe / 1000.0
            ),
            "mean ± 2σ",
            (ps - mean).abs() <= 2.0 * sd,
        );
    }
    // Between impacts the pressure is the slow part of the flow, which the record resolves well: the
    // sensor's mean over the rise before the first impact, over the run-up after it, and after the second
    // and third impacts.
    let mean_in = |ts: &[f64], ys: &[f64], lo: f64, hi: f64| {
        let v: Vec<f64> = ts
            .iter()
            .zip(ys)
            .filter(|(x, _)| **x >= lo && **x <= hi)
            .map(|(_, y)| *y)
            .collect();
        v.iter().sum::<f64>() / v.len().max(1) as f64
    };
    // Around the first impact the target's 15 % from 4 mm on; at 8 mm, where the sensor's reach along the
    // wall (2h, 21 mm) is most of the 30 mm of water above it in the first rise, 25 %.
    let bound = if dp <= 0.004 { 0.15 } else { 0.25 };
    for (lo, hi) in [(0.6, 1.2), (2.45, 2.85), (4.15, 4.45), (5.75, 6.0)] {
        let around_the_first_impact = hi < 3.0;
        let (ms, me) = (mean_in(&t, &p, lo, hi), mean_in(&te, &pe, lo, hi));
        eprintln!("SPHERIC 10 ({label}) mean pressure {lo}-{hi} s: simulated {ms:.0} Pa, measured {me:.0} Pa");
        let quantity = format!("mean pressure {lo}-{hi} s");
        if around_the_first_impact {
            r.row(
                &quantity,
                format!("{ms:.0} Pa ({:+.0} %)", (ms / me - 1.0) * 100.0),
                format!("{me:.0} Pa"),
                &format!("± {:.0} %", bound * 100.0),
                Some((ms - me).abs() < bound * me),
            );
        }
        if !around_the_first_impact || bound > 0.15 {
            r.target(
                &format!("{quantity}, against the target"),
                format!("{:+.0} %", (ms / me - 1.0) * 100.0),
                format!("{me:.0} Pa"),
                "± 15 %",
                (ms - me).abs() <= 0.15 * me,
            );
        }
        // The record's zero drifts by up to −250 Pa while the sensor is dry (see the manual's page): its
        // level as the water leaves the sensor, and the window's mean with that level taken as the zero.
        let (dry, level) = spheric10_level_as_it_dries(&exp, hi);
        let zeroed = me - level;
        r.row(
            &format!("{quantity}, against the record less its level as it dries"),
            format!("{:+.0} %", (ms / zeroed - 1.0) * 100.0),
            format!(
                "{zeroed:.0} Pa (level {level:.0} Pa at {dry:.2}-{:.2} s)",
                dry + 0.1
            ),
            "printed, not asserted",
            None,
        );
    }
    r.publish_and_check();
}

/// Where the record (`exp`: time, pressure rows sorted by time) turns dry from `after` on: the first sample
/// from which it stays below 100 Pa (under 1 cm of water, were its zero true) for 20 ms; and its median over
/// the 0.1 s from there, where the water has left the sensor (splashes aside) and a gauge sensor in air
/// reads 0: the record's level as the sensor dries.
fn spheric10_level_as_it_dries(exp: &[Vec<f64>], after: f64) -> (f64, f64) {
    let from = exp.partition_point(|r| r[0] < after);
    let dry = (from..exp.len())
        .find(|&i| {
            exp[i..]
                .iter()
                .take_while(|r| r[0] < exp[i][0] + 0.02)
                .all(|r| r[1] < 100.0)
        })
        .expect("the record dries after each impact");
    let t0 = exp[dry][0];
    let mut level: Vec<f64> = exp[dry..]
        .iter()
        .take_while(|r| r[0] <= t0 + 0.1)
        .map(|r| r[1])
        .collect();
    level.sort_by(f64::total_cmp);
    let n = level.len();
    let median = if n % 2 == 1 {
        level[n / 2]
    } else {
        0.5 * (level[n / 2 - 1] + level[n / 2])
    };
    (t0, median)
}

/// [`spheric10_level_as_it_dries`] on a made-up 1 kHz record: under water (600 Pa) until 1 s, then in air at
/// −200 Pa with a splash to 300 Pa over 1.012–1.016 s and one to 500 Pa at 1.05 s. The sensor dries after the
/// first splash (a 20 ms stretch below 100 Pa), and the second does not move the median.
#[test]
fn the_record_dries_after_a_splash_and_a_later_splash_does_not_move_its_level() {
    let exp: Vec<Vec<f64>> = (0..2000)
        .map(|i| {
            let p = match i {
                ..1000 => 600.0,
                1012..1017 => 300.0,
                1050 => 500.0,
                _ => -200.0,
            };
            vec![i as f64 * 1e-3, p]
        })
        .collect();
    let (dry, level) = spheric10_level_as_it_dries(&exp, 0.5);
    assert!((dry - 1.017).abs() < 1e-9, "dry from {dry} s");
    assert_eq!(level, -200.0);
}

/// Akyildiz & Unal (2006), fig. 5, with the incompressible scheme at the case's 20 mm spacing, 0-10 s.
#[test]
fn akyildiz_2006_pitch_wall_pressure_dfsph() {
    akyildiz_2006(
        &["solver.scheme=dfsph"],
        10.0,
        "akyildiz2006_pitch_dfsph",
        "DFSPH, dp 20 mm",
        0.9,
        0.25,
    );
}

/// The same with WCSPH at 40 mm over the first two periods (at 20 mm WCSPH takes ~40x longer than DFSPH).
/// Probe 8, 15 mm under the resting surface, is within one 40 mm spacing of it: its bounds are looser.
#[test]
fn akyildiz_2006_pitch_wall_pressure() {
    akyildiz_2006(
        &["particle_spacing=0.04"],
        6.5,
        "akyildiz2006_pitch",
        "WCSPH, dp 40 mm",
        0.8,
        0.5,
    );
}

fn correlation(a: &[f64], b: &[f64]) -> f64 {
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
    let (ma, mb) = (mean(a), mean(b));
    let cov: f64 = a.iter().zip(b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let var = |v: &[f64], m: f64| v.iter().map(|x| (x - m).powi(2)).sum::<f64>();
    cov / (var(a, ma) * var(b, mb)).sqrt()
}

/// Akyildiz & Unal (2006), fig. 5: a 3D tank 0.92 x 0.46 x 0.62 m, 75 % full, pitched 4 degrees at 2 rad/s;
/// wall pressure at probe 2 (+x wall, 0.17 m up) and probe 8 (-x wall, 0.45 m up) over 0-`t_end` s, with
/// `overrides`. The simulated pressure is averaged over 0.1 s (the digitised curve's detail) and compared at
/// the record's times: the oscillation in phase (correlation; probe 2 > 0.9, probe 8 > `corr8`) and of the
/// measured size (peak to peak within 20 % at probe 2, `p2p8` at probe 8). The record's mean at probe 2 sits
/// 0.3 kPa above the hydrostatic pressure of the stated depth (its dry-looking probe 8 reads 0.24 kPa too: an
/// offset of the digitised figure: it is where the simulated probe 8 is dry), so the simulated mean is checked
/// against hydrostatics instead (within 5 %).
fn akyildiz_2006(overrides: &[&str], t_end: f64, name: &str, label: &str, corr8: f64, p2p8: f64) {
    let started = std::time::Instant::now();
    let cfg = config::load("akyildiz2006_pitch", &[]).unwrap();
    let motion = slosh_node::motion_source::build(&cfg).unwrap();
    let obs = observe(
        "akyildiz2006_pitch",
        overrides,
        motion.as_ref(),
        t_end,
        0.02,
    );
    let t: Vec<f64> = obs.iter().map(|o| o.time).collect();
    let mut panels = vec![];
    for (k, probe, bounds) in [(0, "probe2", (0.9, 0.2)), (1, "probe8", (corr8, p2p8))] {
        let exp: Vec<Vec<f64>> = table(&read(&format!(
            "akyildiz2006_pitch/akyildiz_unal_2006_fig5_{probe}.csv"
        )))
        .into_iter()
        .filter(|r| r[0] <= t_end)
        .collect();
        assert!(exp.len() >= 15, "{probe}: {} digitised points", exp.len());
        let p: Vec<f64> = obs.iter().map(|o| o.pressures[k] / 1000.0).collect();
        let smooth: Vec<f64> = (0..p.len())
            .map(|i| {
                let w = &p[i.saturating_sub(2)..(i + 3).min(p.len())];
                w.iter().sum::<f64>() / w.len() as f64
            })
            .collect();
        let (te, pe): (Vec<f64>, Vec<f64>) = exp.iter().map(|r| (r[0], r[1])).unzip();
        let ps: Vec<f64> = te.iter().map(|&x| interp(&t, &smooth, x)).collect();
        let corr = correlation(&ps, &pe);
        let range = |v: &[f64]| {
            v.iter().cloned().fold(f64::MIN, f64::max) - v.iter().cloned().fold(f64::MAX, f64::min)
        };
        let (rs, re) = (range(&ps), range(&pe));
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        eprintln!(
            "Akyildiz 2006 ({label}) {probe}: correlation {corr:.3}, peak to peak {rs:.3} kPa against {re:.3} kPa measured, mean {:.3} kPa against {:.3} kPa",
            mean(&ps),
            mean(&pe)
        );
        panels.push((
            probe,
            t.clone(),
            smooth,
            te,
            pe,
            corr,
            rs / re,
            mean(&ps),
            bounds,
        ));
    }
    let where_ = ["+x wall, 0.17 m up", "-x wall, 0.45 m up"];
    let drawn = panels
        .iter()
        .zip(where_)
        .map(|((probe, t, p, te, pe, ..), at)| Panel {
            title: format!("{probe} ({at})"),
            y_label: "pressure (kPa)".into(),
            series: vec![
                series(&format!("slosh ({label}), 0.1 s mean"), t, p, false),
                series("measured (Akyildiz & Unal 2006, fig. 5)", te, pe, true),
            ],
            ..Default::default()
        })
        .collect();
    figure_panels(
        name,
        "Akyildiz & Unal (2006): wall pressure in a 3D tank pitched 4 degrees at 2 rad/s",
        drawn,
    );
    let mut r = Results::new(
        name,
        "akyildiz2006.md",
        &format!("{label}, 0-{t_end} s"),
        started,
    );
    for (probe, .., corr, ratio, m, (c_min, r_tol)) in &panels {
        r.row(
            &format!("{probe}: correlation with the record"),
            format!("{corr:.3}"),
            "1".into(),
            &format!("> {c_min}"),
            Some(*corr > *c_min),
        );
        r.row(
            &format!("{probe}: peak to peak over the record's"),
            format!("{ratio:.2}"),
            "1".into(),
            &format!("± {:.0} %", 100.0 * r_tol),
            Some((ratio - 1.0).abs() < *r_tol),
        );
        if *probe == "probe2" {
            let hydro = 1000.0 * 9.81 * (0.465 - 0.17) / 1000.0;
            r.row(
                "probe2: mean pressure",
                format!("{m:.3} kPa"),
                format!("{hydro:.3} kPa (hydrostatic)"),
                "± 5 %",
                Some((m - hydro).abs() < 0.05 * hydro),
            );
        }
    }
    r.publish_and_check();
}

/// Bouscasse et al. (2013), series 5, with the incompressible scheme at the case's 3 mm spacing.
#[test]
fn bouscasse_2013_shallow_water_bores_dfsph() {
    bouscasse_2013(
        &["solver.scheme=dfsph"],
        "bouscasse2013_shallow_dfsph",
        "DFSPH, dp 3 mm",
    );
}

/// Bouscasse et al. (2013), series 5 (fig. 19): water 0.03 m deep in a 1 m tank swayed 0.070 m at 1.231 times
/// the first natural frequency, so that bores run to and fro; elevation 0.05 m from the -x wall over the
/// record's t/T = 8.5-11 (the data file's `t_s` column is t/T, as PySPH plots it). Checked: the record's
/// shape (correlation > 0.9, rms within 25 %), and each of the three bores arriving (the rise through 2 cm)
/// within 0.05 T of the measured time with its crest within 25 % of the measured height.
fn bouscasse_2013(overrides: &[&str], name: &str, label: &str) {
    let started = std::time::Instant::now();
    let period = 2.99929;
    let exp = table(&read(
        "bouscasse2013_shallow/bouscasse_etal_2013_series5_fig19.csv",
    ));
    assert!(exp.len() > 80, "expected the 87 digitised points");
    let (te, ye): (Vec<f64>, Vec<f64>) = exp.iter().map(|r| (r[0], r[1])).unzip();
    let cfg = config::load("bouscasse2013_shallow", &[]).unwrap();
    let motion = slosh_node::motion_source::build(&cfg).unwrap();
    let t_end = 11.0 * period;
    let obs = observe(
        "bouscasse2013_shallow",
        overrides,
        motion.as_ref(),
        t_end,
        0.01,
    );
    // In periods, and as elevation above the resting 0.03 m.
    let tp: Vec<f64> = obs.iter().map(|o| o.time / period).collect();
    let eta: Vec<f64> = obs.iter().map(|o| o.probes[0] - 0.03).collect();
    let sim_at: Vec<f64> = te.iter().map(|&x| interp(&tp, &eta, x)).collect();
    let corr = correlation(&sim_at, &ye);
    let rms = |v: &[f64]| (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt();
    let ratio = rms(&sim_at) / rms(&ye);
    eprintln!(
        "Bouscasse 2013 ({label}), t/T = {:.2}-{:.2}: correlation {corr:.3}, rms {:.4} m against {:.4} m measured",
        te[0],
        te[te.len() - 1],
        rms(&sim_at),
        rms(&ye)
    );
    let from = te[0] - 0.05;
    let keep: Vec<usize> = (0..tp.len())
        .filter(|&i| tp[i] >= from && tp[i] <= 11.0)
        .collect();
    let (ts, ys): (Vec<f64>, Vec<f64>) = keep.iter().map(|&i| (tp[i], eta[i])).unzip();
    // Drawn in seconds (the record's t/T times T).
    let in_s = |v: &[f64]| v.iter().map(|x| x * period).collect::<Vec<f64>>();
    figure(
        name,
        "Bouscasse et al. (2013), series 5: elevation 0.05 m from the wall, h = 0.03 m, T = 3.0 s (bores)",
        "elevation above 0.03 m (m)",
        vec![
            series(&format!("slosh ({label})"), &in_s(&ts), &ys, false),
            series(
                "measured (Bouscasse et al. 2013, fig. 19)",
                &in_s(&te),
                &ye,
                true,
            ),
        ],
    );
    // The bores: upward crossings of 2 cm, and the crest within 0.1 T after each.
    let rises = |t: &[f64], y: &[f64]| -> Vec<(f64, f64)> {
        (1..t.len())
            .filter(|&i| y[i - 1] < 0.02 && y[i] >= 0.02)
            .map(|i| {
                let at = t[i - 1] + (0.02 - y[i - 1]) / (y[i] - y[i - 1]) * (t[i] - t[i - 1]);
                let crest = (0..t.len())
                    .filter(|&j| t[j] >= at && t[j] <= at + 0.1)
                    .map(|j| y[j])
                    .fold(f64::MIN, f64::max);
                (at, crest)
            })
            .collect()
    };
    let measured = rises(&te, &ye);
    let simulated = rises(&ts, &ys);
    eprintln!(
        "Bouscasse 2013 ({label}) bores (t/T, crest m): simulated {simulated:.3?}, measured {measured:.3?}"
    );
    assert_eq!(measured.len(), 3, "the record's three bores");
    let mut r = Results::new(
        name,
        "bouscasse2013.md",
        &format!("{label}, t/T = 0-11"),
        started,
    );
    for (tm, cm) in &measured {
        let (tsim, csim) = simulated
            .iter()
            .min_by(|a, b| (a.0 - tm).abs().total_cmp(&(b.0 - tm).abs()))
            .copied()
            .unwrap_or_else(|| panic!("no simulated bore"));
        r.row(
            &format!("bore near t/T = {tm:.2}: arrival (t/T)"),
            format!("{tsim:.3}"),
            format!("{tm:.3}"),
            "± 0.05",
            Some((tsim - tm).abs() < 0.05),
        );
        r.row(
            &format!("bore near t/T = {tm:.2}: crest"),
            format!("{:.1} mm", 1000.0 * csim),
            format!("{:.1} mm", 1000.0 * cm),
            "± 25 %",
            Some((csim - cm).abs() < 0.25 * cm),
        );
    }
    r.row(
        "correlation with the record",
        format!("{corr:.3}"),
        "1".into(),
        "> 0.9",
        Some(corr > 0.9),
    );
    r.row(
        "rms over the record's rms",
        format!("{ratio:.2}"),
        "1".into(),
        "0.75-1.25",
        Some((0.75..1.25).contains(&ratio)),
    );
    r.publish_and_check();
}

/// SPHERIC Test 2's front at water-height probe `k` (0-3, named `name`) sampled at times `t`: the first time
/// its height passes 5 cm; at H4 (k = 3), in the reservoir, the first time its level falls below 0.5 m.
fn kleefsman_arrival(k: usize, name: &str, t: &[f64], h: &[f64]) -> f64 {
    let i = h
        .iter()
        .position(|&v| if k == 3 { v < 0.5 } else { v > 0.05 })
        .unwrap_or_else(|| panic!("{name}: the front never arrives"));
    t[i]
}

/// SPHERIC Test 2's impact at a pressure sensor sampled at times `t`: the first time its pressure passes
/// 500 Pa (the last time if it never does).
fn kleefsman_impact(t: &[f64], p: &[f64]) -> f64 {
    t[p.iter().position(|&x| x > 500.0).unwrap_or(p.len() - 1)]
}

/// SPHERIC Test 2 (Kleefsman et al. 2005): the 3D dam break onto a box fixed to the floor (`obstacles`), with
/// the case's incompressible scheme at 40 mm, 0-6 s: the water heights H1-H4 against the record, each in
/// shape (correlation > 0.85) and size (rms within 25 %), and the front's arrival at H1, H2 (0.5 and 1.0 m
/// from the column) within 0.05 s and at H3 (1.5 m, beyond the box) within 0.15 s of the measured one; the
/// pressure on the box (P1-P4 on its face towards the column, P5-P8 on its top) in shape (correlation > 0.8)
/// and mean after the impact (1-6 s, within 20 %), and the impact on P1-P4 within 0.03 s.
#[test]
fn kleefsman_2005_dam_break_onto_a_box_water_heights_dfsph() {
    let started = std::time::Instant::now();
    let rows = table(&read("kleefsman_spheric2/test_case_2_exp_data.dat"));
    assert!(rows.len() > 7000, "expected the 7395 rows");
    let t_end = 6.0;
    let obs = observe(
        "kleefsman2005_dambreak",
        &[],
        &sph::motion::AtRest,
        t_end,
        0.01,
    );
    let t: Vec<f64> = obs.iter().map(|o| o.time).collect();
    let exp: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] <= t_end).collect();
    let te: Vec<f64> = exp.iter().map(|r| r[0]).collect();
    let mut panels = vec![];
    let mut checks = vec![];
    for (k, name) in ["H1", "H2", "H3", "H4"].iter().enumerate() {
        let he: Vec<f64> = exp.iter().map(|r| r[9 + k]).collect();
        let hs: Vec<f64> = obs.iter().map(|o| o.probes[k]).collect();
        let at: Vec<f64> = te.iter().map(|&x| interp(&t, &hs, x)).collect();
        let corr = correlation(&at, &he);
        let std = |v: &[f64]| {
            let m = v.iter().sum::<f64>() / v.len() as f64;
            (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / v.len() as f64).sqrt()
        };
        let ratio = std(&at) / std(&he);
        let (a_sim, a_exp) = (
            kleefsman_arrival(k, name, &t, &hs),
            kleefsman_arrival(k, name, &te, &he),
        );
        eprintln!(
            "Kleefsman 2005 (DFSPH, dp 40 mm) {name}: correlation {corr:.3}, rms {:.3} m against {:.3} m, peak {:.3} m against {:.3} m, front at {a_sim:.3} s against {a_exp:.3} s",
            std(&at),
            std(&he),
            hs.iter().cloned().fold(0.0, f64::max),
            he.iter().cloned().fold(0.0, f64::max)
        );
        panels.push(Panel {
            title: name.to_string(),
            y_label: "water height (m)".into(),
            series: vec![
                series("slosh (DFSPH, dp 40 mm)", &t, &hs, false),
                series("measured (MARIN, SPHERIC Test 2)", &te, &he, true),
            ],
            ..Default::default()
        });
        let tol = if k == 2 { 0.15 } else { 0.05 };
        checks.push((name.to_string(), corr, ratio, (a_sim, a_exp), tol));
    }
    figure_panels(
        "kleefsman2005_dambreak_dfsph",
        "SPHERIC Test 2 (Kleefsman et al. 2005): 3D dam break onto a box, water heights",
        panels,
    );
    let mut r = Results::new(
        "kleefsman2005_dambreak_dfsph",
        "kleefsman2005.md",
        "DFSPH, dp 40 mm, 0-6 s",
        started,
    );
    for (name, corr, ratio, (a_sim, a_exp), tol) in checks {
        r.row(
            &format!("{name}: correlation with the record"),
            format!("{corr:.3}"),
            "1".into(),
            "> 0.85",
            Some(corr > 0.85),
        );
        r.row(
            &format!("{name}: rms over the record's"),
            format!("{ratio:.2}"),
            "1".into(),
            "± 25 %",
            Some((ratio - 1.0).abs() < 0.25),
        );
        r.row(
            &format!("{name}: the front's arrival"),
            format!("{a_sim:.3} s"),
            format!("{a_exp:.3} s"),
            &format!("± {tol} s"),
            Some((a_sim - a_exp).abs() < tol),
        );
    }
    // The box's pressure sensors: P1-P4 on its face towards the column, P5-P8 on its top.
    let mut panels = vec![];
    let mut checks = vec![];
    for k in 0..8 {
        let name = format!("P{}", k + 1);
        let pe: Vec<f64> = exp.iter().map(|r| r[1 + k]).collect();
        let ps: Vec<f64> = obs.iter().map(|o| o.pressures[k]).collect();
        let at: Vec<f64> = te.iter().map(|&x| interp(&t, &ps, x)).collect();
        let corr = correlation(&at, &pe);
        let mean_after = |v: &[f64]| {
            let w: Vec<f64> = te
                .iter()
                .zip(v)
                .filter(|(t, _)| **t > 1.0)
                .map(|(_, p)| *p)
                .collect();
            w.iter().sum::<f64>() / w.len() as f64
        };
        let (ms, me) = (mean_after(&at), mean_after(&pe));
        let (ws, we) = (kleefsman_impact(&te, &at), kleefsman_impact(&te, &pe));
        eprintln!(
            "Kleefsman 2005 (DFSPH, dp 40 mm) {name}: correlation {corr:.3}, mean after 1 s {ms:.0} Pa against {me:.0} Pa, peak {:.0} Pa against {:.0} Pa, above 500 Pa from {ws:.3} s against {we:.3} s",
            at.iter().cloned().fold(0.0, f64::max),
            pe.iter().cloned().fold(0.0, f64::max)
        );
        panels.push(Panel {
            title: name.clone(),
            y_label: "pressure (Pa)".into(),
            series: vec![
                series("slosh (DFSPH, dp 40 mm)", &t, &ps, false),
                series("measured (MARIN, SPHERIC Test 2)", &te, &pe, true),
            ],
            ..Default::default()
        });
        let peaks = (
            at.iter().cloned().fold(0.0, f64::max),
            pe.iter().cloned().fold(0.0, f64::max),
        );
        checks.push((name, corr, (ms, me), (ws, we), peaks));
    }
    figure_panels(
        "kleefsman2005_dambreak_dfsph_pressure",
        "SPHERIC Test 2 (Kleefsman et al. 2005): pressure on the box, P1-P4 front, P5-P8 top",
        panels,
    );
    for (k, (name, corr, (ms, me), (ws, we), (peak_s, peak_e))) in checks.into_iter().enumerate() {
        r.row(
            &format!("{name}: correlation with the record"),
            format!("{corr:.3}"),
            "1".into(),
            "> 0.8",
            Some(corr > 0.8),
        );
        r.row(
            &format!("{name}: mean pressure after 1 s"),
            format!("{ms:.0} Pa"),
            format!("{me:.0} Pa"),
            "± 20 %",
            Some((ms / me - 1.0).abs() < 0.2),
        );
        // The front's impact on the face (P1-P4); the top gets wet in splashes first.
        let (bound, ok) = if k < 4 {
            ("± 0.03 s", Some((ws - we).abs() < 0.03))
        } else {
            ("printed, not asserted", None)
        };
        r.row(
            &format!("{name}: above 500 Pa from"),
            format!("{ws:.3} s"),
            format!("{we:.3} s"),
            bound,
            ok,
        );
        r.row(
            &format!("{name}: peak (at the record's times)"),
            format!("{:.1} kPa", peak_s / 1000.0),
            format!("{:.1} kPa", peak_e / 1000.0),
            "printed, not asserted",
            None,
        );
    }
    r.publish_and_check();
}

/// SPHERIC Test 2 (Kleefsman et al. 2005) at 20 mm, the impact on the box: the case's incompressible scheme
/// over 0-0.7 s (85,400 liquid particles; about 40 s on two cores), sampled every millisecond as the record
/// is. Asserted as at 40 mm: the front's arrival at H1 and H2 within 0.05 s and the impact on P1-P4 (the
/// pressure passing 500 Pa) within 0.03 s. Held to targets and shown inside or outside them, not asserted:
/// the reservoir's level (H4) falling below 0.5 m within 0.05 s (it lags by about that much at this spacing:
/// the liquid's start-up, the manual's page), each of P1-P4's peaks within 20 % of the record's (SPHERIC
/// Test 10's repeats scatter by 20-35 %: a single record's peak is a loose reference), and the mean pressure
/// over 0.5-0.7 s, the water running up the box's face, within 20 %. Printed: each sensor's correlation with the record over 0.35-0.7 s and its pressure
/// impulse over that span.
#[test]
fn kleefsman_2005_impact_on_the_box_at_20_mm_dfsph() {
    let started = std::time::Instant::now();
    let rows = table(&read("kleefsman_spheric2/test_case_2_exp_data.dat"));
    let t_end = 0.7;
    let obs = observe(
        "kleefsman2005_dambreak",
        &["particle_spacing=0.02"],
        &sph::motion::AtRest,
        t_end,
        0.001,
    );
    let t: Vec<f64> = obs.iter().map(|o| o.time).collect();
    let exp: Vec<&Vec<f64>> = rows.iter().filter(|r| r[0] <= t_end).collect();
    let te: Vec<f64> = exp.iter().map(|r| r[0]).collect();
    let mut r = Results::new(
        "kleefsman2005_impact_20mm_dfsph",
        "kleefsman2005.md",
        "DFSPH, dp 20 mm, 0-0.7 s, sampled every 1 ms",
        started,
    );
    for (k, name) in [(0, "H1"), (1, "H2"), (3, "H4")] {
        let he: Vec<f64> = exp.iter().map(|r| r[9 + k]).collect();
        let hs: Vec<f64> = obs.iter().map(|o| o.probes[k]).collect();
        let (a_sim, a_exp) = (
            kleefsman_arrival(k, name, &t, &hs),
            kleefsman_arrival(k, name, &te, &he),
        );
        let (quantity, ok) = (
            format!("{name}: the front's arrival"),
            (a_sim - a_exp).abs() < 0.05,
        );
        let (sim, rec) = (format!("{a_sim:.3} s"), format!("{a_exp:.3} s"));
        if k == 3 {
            r.target(&quantity, sim, rec, "± 0.05 s (target)", ok);
        } else {
            r.row(&quantity, sim, rec, "± 0.05 s", Some(ok));
        }
    }
    let span = |lo: f64| -> Vec<usize> { (0..te.len()).filter(|&i| te[i] >= lo).collect() };
    let (impact, run_up) = (span(0.35), span(0.5));
    let dt = (te[te.len() - 1] - te[0]) / (te.len() - 1) as f64;
    let mut panels = vec![];
    for k in 0..4 {
        let name = format!("P{}", k + 1);
        let pe: Vec<f64> = exp.iter().map(|r| r[1 + k]).collect();
        let ps: Vec<f64> = obs.iter().map(|o| o.pressures[k]).collect();
        let at: Vec<f64> = te.iter().map(|&x| interp(&t, &ps, x)).collect();
        let pick = |v: &[f64], idx: &[usize]| -> Vec<f64> { idx.iter().map(|&i| v[i]).collect() };
        let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
        let peak = |v: &[f64]| v.iter().cloned().fold(f64::MIN, f64::max);
        let (ws, we) = (kleefsman_impact(&te, &at), kleefsman_impact(&te, &pe));
        let (peak_s, peak_e) = (peak(&at), peak(&pe));
        let (mean_s, mean_e) = (mean(&pick(&at, &run_up)), mean(&pick(&pe, &run_up)));
        let (at_impact, pe_impact) = (pick(&at, &impact), pick(&pe, &impact));
        let corr = correlation(&at_impact, &pe_impact);
        let (imp_s, imp_e) = (
            at_impact.iter().sum::<f64>() * dt,
            pe_impact.iter().sum::<f64>() * dt,
        );
        r.row(
            &format!("{name}: above 500 Pa from"),
            format!("{ws:.3} s"),
            format!("{we:.3} s"),
            "± 0.03 s",
            Some((ws - we).abs() < 0.03),
        );
        r.target(
            &format!("{name}: peak"),
            format!("{:.1} kPa", peak_s / 1000.0),
            format!("{:.1} kPa", peak_e / 1000.0),
            "± 20 % (target)",
            (peak_s / peak_e - 1.0).abs() < 0.2,
        );
        r.target(
            &format!("{name}: mean pressure over 0.5-0.7 s"),
            format!("{mean_s:.0} Pa"),
            format!("{mean_e:.0} Pa"),
            "± 20 % (target)",
            (mean_s / mean_e - 1.0).abs() < 0.2,
        );
        r.row(
            &format!("{name}: correlation with the record over 0.35-0.7 s"),
            format!("{corr:.3}"),
            "1".into(),
            "printed, not asserted",
            None,
        );
        r.row(
            &format!("{name}: pressure impulse over 0.35-0.7 s"),
            format!("{imp_s:.0} Pa·s"),
            format!("{imp_e:.0} Pa·s"),
            "printed, not asserted",
            None,
        );
        let from = |ts: &[f64], v: &[f64]| -> (Vec<f64>, Vec<f64>) {
            ts.iter()
                .zip(v)
                .filter(|(x, _)| **x >= 0.3)
                .map(|(x, y)| (*x, *y))
                .unzip()
        };
        let (ts_s, ps_s) = from(&t, &ps);
        let (ts_e, ps_e) = from(&te, &pe);
        panels.push(Panel {
            title: name,
            y_label: "pressure (Pa)".into(),
            series: vec![
                series("slosh (DFSPH, dp 20 mm)", &ts_s, &ps_s, false),
                series("measured (MARIN, SPHERIC Test 2)", &ts_e, &ps_e, true),
            ],
            ..Default::default()
        });
    }
    figure_panels(
        "kleefsman2005_impact_20mm_dfsph",
        "SPHERIC Test 2 (Kleefsman et al. 2005) at 20 mm: the impact on the box's face, P1-P4",
        panels,
    );
    r.publish_and_check();
}

/// The paper's weakly-compressible scheme (the seed cases' settings otherwise) held tilted 5°, both seed
/// fills: the weight through the tilted liquid's centroid within 2 % (moment and both force components), as
/// `sph/tests/sloshing.rs` holds the incompressible scheme; here for its run time (about 4 min on two
/// cores). In 2D at 8 mm with the dynamic walls; in 3D at 40 mm with the mirror walls: in 3D the dynamic
/// walls leave the liquid's centroid short of the low side (the moment 13 % low at 40 mm and 7 % at 20 mm,
/// the forces right; the manual's sloshing page).
#[test]
fn wcsph_holds_a_tilted_tank_s_weight_through_the_centroid() {
    use sph::params::BoundaryMethod;
    use sph::sloshing::experiment::{seed_tank, tilted};
    let theta = 5f64.to_radians();
    for (dim, dp, walls) in [
        (2, 0.008, BoundaryMethod::Dynamic),
        (3, 0.04, BoundaryMethod::Mirror),
    ] {
        for fill in [0.19, 0.39] {
            let mut p = seed_tank(dim, fill, dp);
            p.solver.scheme = sph::params::Scheme::Wcsph;
            p.solver.boundary.method = walls;
            let r = tilted(p, theta, 1.5, 0.5, 3.0).unwrap();
            eprintln!(
                "WCSPH {dim}D {dp} m {walls:?} walls, fill {fill}, tilted 5°: moment {:.3} N·m against {:.3} ({:+.2} %), force {:?} N for a weight of {:.2} N",
                r.moment,
                r.theory_moment,
                100.0 * (r.moment / r.theory_moment - 1.0),
                r.force,
                r.weight
            );
            // Moment, force along x, force along z.
            assert!(
                r.errors().iter().all(|e| e.abs() < 0.02),
                "{dim}D, fill {fill}: {r:?}"
            );
        }
    }
}

/// The paper's flooding case A (`flooding_case_a`: a 2D damaged box 0.1 m square with 10 mm walls fills
/// through a 20 mm hole in its bottom and sinks onto the basin's floor; dp 2.5 mm, 1 s) with both schemes:
/// from 0.2 s on the flooded volumes within 10 % of each other (before, while the jet enters the dry box
/// through a hole that WCSPH's walls narrow, `dfsph`'s runs 10–15 % ahead: a target, not asserted); at the end
/// the box on the floor, its hollow full within 6 % (WCSPH's wall particles hold its liquid about 0.4 spacing
/// off the walls, which leaves (1 − 0.8 dp / 80 mm)² = 0.95 of the hollow to its particles). Not an
/// experiment: the seed paper's record of the case is lost; about three minutes, most of it WCSPH's.
#[test]
fn flooding_case_a_floods_alike_with_both_schemes() {
    let started = std::time::Instant::now();
    let params = config::load("flooding_case_a", &[])
        .unwrap()
        .sim_params()
        .unwrap();
    let (spec, dp) = (&params.bodies[0], params.particle_spacing);
    let hollow =
        (spec.size[0] - 2.0 * spec.wall_thickness) * (spec.size[2] - 2.0 * spec.wall_thickness);
    let every = 0.05;
    // Time, flooded volume (m² per metre), height of the centre of gravity.
    let run = |scheme: &str| -> Vec<(f64, f64, f64)> {
        let o = format!("solver.scheme={scheme}");
        observe("flooding_case_a", &[&o], &sph::motion::AtRest, 1.0, every)
            .iter()
            .map(|o| (o.time, o.bodies[0].flooded_volume, o.bodies[0].position[2]))
            .collect()
    };
    let (w, d) = (run("wcsph"), run("dfsph"));
    assert_eq!(w.len(), d.len());
    let mut r = Results::new(
        "flooding_case_a_schemes",
        "flooding.md",
        "WCSPH and DFSPH, flooding case A, dp 2.5 mm, 0-1 s",
        started,
    );
    let litres = |v: f64| format!("{:.2} l/m", 1000.0 * v);
    for (a, b) in w.iter().zip(&d) {
        let k = (a.0 / every).round() as usize;
        if k == 0 || (!k.is_multiple_of(2) && k != 3) {
            continue;
        }
        let ratio = b.1 / a.1 - 1.0;
        let quantity = format!("flooded volume at {:.2} s, `dfsph` against `wcsph`", a.0);
        let (sim, reference) = (litres(b.1), litres(a.1));
        let bound = "± 10 % from 0.2 s";
        if a.0 < 0.2 - 1e-9 {
            r.target(&quantity, sim, reference, bound, ratio.abs() <= 0.1);
        } else {
            r.row(&quantity, sim, reference, bound, Some(ratio.abs() <= 0.1));
        }
    }
    let worst = w
        .iter()
        .zip(&d)
        .filter(|(a, _)| a.0 >= 0.2 - 1e-9)
        .map(|(a, b)| b.1 / a.1 - 1.0)
        .fold(0.0f64, |m, x| if x.abs() > m.abs() { x } else { m });
    r.row(
        "largest difference from 0.2 s (every 0.05 s)",
        format!("{:+.1} %", 100.0 * worst),
        "0".into(),
        "± 10 %",
        Some(worst.abs() <= 0.1),
    );
    for (label, s) in [("wcsph", &w), ("dfsph", &d)] {
        let (_, v, z) = *s.last().unwrap();
        r.row(
            &format!("`{label}`: flooded volume at 1 s"),
            litres(v),
            format!("{} (the hollow)", litres(hollow)),
            "± 6 %",
            Some((v / hollow - 1.0).abs() <= 0.06),
        );
        // On the floor: the box's bottom within a spacing of it (contact holds it one spacing inside).
        let bottom = z - spec.centre_of_gravity[2];
        r.row(
            &format!("`{label}`: the box's bottom above the floor at 1 s"),
            format!("{:.1} mm", 1000.0 * bottom),
            "0 (resting on the floor)".into(),
            "below 1 spacing (2.5 mm)",
            Some(bottom < dp),
        );
    }
    let t: Vec<f64> = w.iter().map(|s| s.0).collect();
    let vol = |s: &[(f64, f64, f64)]| s.iter().map(|s| 1000.0 * s.1).collect::<Vec<_>>();
    figure(
        "flooding_case_a_schemes",
        "Flooding case A: the damaged box's flooded volume, both schemes (dp 2.5 mm)",
        "flooded volume (l per metre)",
        vec![
            series("wcsph", &t, &vol(&w), false),
            series("dfsph", &t, &vol(&d), false),
            series(
                "the hollow (full)",
                &t,
                &vec![1000.0 * hollow; t.len()],
                true,
            ),
        ],
    );
    r.publish_and_check();
}

/// The discharge coefficient of a slot against its width in particle spacings (4, 8, 12, 16), with both schemes
/// and both kinds of wall (`sph::flooding::slot_case`: the tank's obstacles, or a fixed body's side), dp 5 mm:
/// from 8 spacings on every 0.1 s window from 0.2 s within 0.61 ± 0.06 (a sharp-edged slot: π/(π+2) in
/// theory, 0.60–0.62 in experiment); 4 spacings printed. Draws the coefficient against the width. About
/// eight minutes on two cores, most of it WCSPH's.
#[test]
fn flooding_slot_discharge_against_the_width() {
    use sph::flooding::{slot_case, slot_discharge, SlotWall};
    use sph::params::Scheme;
    let started = std::time::Instant::now();
    let dp = 0.005;
    let widths = [4.0, 8.0, 12.0, 16.0];
    let mut r = Results::new(
        "flooding_slot_discharge",
        "flooding.md",
        "WCSPH and DFSPH, a slot in a tank's wall (obstacles) and in a body's side, 4-16 spacings, dp 5 mm, 0-0.6 s",
        started,
    );
    let mut series_list = Vec::new();
    for (wall, where_) in [
        (SlotWall::Obstacles, "the tank's wall"),
        (SlotWall::Body, "a body's side"),
    ] {
        for (scheme, name) in [(Scheme::Wcsph, "wcsph"), (Scheme::Dfsph, "dfsph")] {
            let mut means = Vec::new();
            for opening in widths {
                let d = slot_discharge(slot_case(scheme, wall, opening, dp), 0.6, 0.02, (0.2, 0.1))
                    .unwrap();
                let cds: Vec<f64> = d.windows.iter().map(|w| w.cd).collect();
                assert!(cds.len() >= 3, "{name}, {where_}, {opening}: {cds:?}");
                let (lo, hi) = cds
                    .iter()
                    .fold((f64::MAX, f64::MIN), |(a, b), c| (a.min(*c), b.max(*c)));
                let mean = cds.iter().sum::<f64>() / cds.len() as f64;
                means.push(mean);
                let quantity = format!(
                    "`{name}`, {where_}, {opening} spacings ({:.0} mm): C_d per 0.1 s window from 0.2 s",
                    1000.0 * d.width
                );
                let simulated = format!("{lo:.2}-{hi:.2} (mean {mean:.2})");
                let reference = "0.61 (sharp-edged slot)".to_string();
                if opening >= 8.0 {
                    let ok = cds.iter().all(|c| (c - 0.61).abs() <= 0.06);
                    r.row(&quantity, simulated, reference, "0.61 ± 0.06", Some(ok));
                } else {
                    r.row(&quantity, simulated, reference, "printed", None);
                }
            }
            series_list.push(series(&format!("{name}, {where_}"), &widths, &means, false));
        }
    }
    figure_panels(
        "flooding_slot_discharge",
        "Discharge coefficient of a slot against its width (dp 5 mm, mean over 0.2-0.6 s)",
        vec![Panel {
            title: String::new(),
            y_label: "discharge coefficient C_d".into(),
            x_label: "slot width (particle spacings)".into(),
            series: series_list,
            level: Some((0.61, "sharp-edged slot, 0.61".into())),
            markers: true,
        }],
    );
    r.publish_and_check();
}
