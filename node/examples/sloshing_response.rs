//! The seed tank swayed and pitched below and above its first natural frequency, and held tilted, as the
//! solver gives it, against linear potential-flow theory (`sph::sloshing`), by scheme setting. Writes what
//! the manual shows between the `response` and `tilted` markers of `docs/src/validation/sloshing.md`:
//!
//! - forced sway (4 mm) and pitch (0.5°) at 0.5, 0.8, 1.25 and 1.5 ω₁, ramped in over three forcing
//!   periods: the force or moment per unit motion at the forcing frequency, fitted over the next eight,
//!   against theory (2D at 8 mm for every setting, 3D at 20 mm for the `dfsph` settings; fill 0.19 m);
//! - the tank tilted 5° over 1.5 s and held: the weight through the tilted liquid's centroid (moment, the
//!   force along and across the tank floor) and where the surface stands (both fills).
//!
//! ```text
//! cargo run --release -p slosh-node --example sloshing_response              # about half an hour on 2 cores
//! cargo run --release -p slosh-node --example sloshing_response -- --quick   # 2D dfsph only, printed only
//! ```
use slosh_node::accuracy::SETTINGS;
use slosh_node::manual;
use sph::params::{ProbeSpec, SimParams};
use sph::sloshing::experiment::{forced, seed_tank, tilted, Forcing};
use std::path::Path;

const RATIOS: [f64; 4] = [0.5, 0.8, 1.25, 1.5];
/// Sway 4 mm and pitch 0.5°: the elevation at the wall stays below a centimetre near resonance (linear).
const MOTIONS: [(Forcing, f64, &str); 2] = [
    (Forcing::Sway, 0.004, "sway 4 mm"),
    (
        Forcing::Pitch,
        0.5 * std::f64::consts::PI / 180.0,
        "pitch 0.5°",
    ),
];
const TILT_DEG: f64 = 5.0;
/// Probe positions along the tank (m from its centre) that read the tilted surface.
const PROBES: [f64; 3] = [-0.3, 0.0, 0.3];

fn main() {
    let quick = std::env::args().skip(1).any(|a| a == "--quick");
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let cases = |si: usize| -> Vec<(usize, f64)> {
        let wcsph = SETTINGS[si].name.starts_with("wcsph");
        match (quick, wcsph) {
            (true, true) => vec![],
            (true, false) => vec![(2, 0.008)],
            (false, true) => vec![(2, 0.008)],
            (false, false) => vec![(2, 0.008), (3, 0.02)],
        }
    };

    let mut response = String::from(
        "Fill 0.19 m. Force (sway, N per m of motion) or moment about the tank's y axis (pitch, N·m per rad) at \
         the forcing frequency, for the tank's whole breadth (0.25 m; a 2D run stands for that breadth). Phase \
         error: the simulated phase against the motion less theory's.\n\n\
         | motion | setting | dim | dp mm | ω/ω₁ | per unit motion | theory | error | phase error |\n\
         |---|---|---|---|---|---|---|---|---|\n",
    );
    for (si, s) in SETTINGS.iter().enumerate() {
        for (dim, dp) in cases(si) {
            for &(forcing, a, label) in &MOTIONS {
                for ratio in RATIOS {
                    let mut p = seed_tank(dim, 0.19, dp);
                    (s.apply)(&mut p);
                    let head = format!(
                        "| {label} | {} | {dim}D | {:.0} | {ratio} |",
                        s.name,
                        dp * 1000.0
                    );
                    let row = match forced(p, forcing, a, ratio, 3.0, 8.0) {
                        Ok(r) => format!(
                            "{head} {:.1} | {:.1} | {:+.1} % | {:+.1}° |",
                            r.amplitude,
                            r.theory_amplitude,
                            100.0 * r.amplitude_error(),
                            r.phase_error_deg()
                        ),
                        Err(e) => format!("{head} failed: {e} | | | |"),
                    };
                    println!("{row}");
                    response += &row;
                    response.push('\n');
                }
            }
        }
    }

    let mut held = format!(
        "Tilted {TILT_DEG}° over 1.5 s, averaged over three first-mode periods after 0.5 s more. Errors of the \
         weight carried through the tilted liquid's centroid: the moment about y, the force along the tank's \
         floor (m g sin θ) and across it (m g cos θ). Surface: the mean height of three probes (x = −0.3, 0, \
         0.3 m) above the level line through the fill, and their spread about that line, in spacings.\n\n\
         | setting | dim | fill m | dp mm | moment N·m | theory N·m | moment | force along | force across | surface dp | spread dp |\n\
         |---|---|---|---|---|---|---|---|---|---|---|\n"
    );
    let theta = TILT_DEG.to_radians();
    for (si, s) in SETTINGS.iter().enumerate() {
        for (dim, dp) in cases(si) {
            for fill in [0.19, 0.39] {
                let mut p: SimParams = seed_tank(dim, fill, dp);
                (s.apply)(&mut p);
                p.probes = PROBES
                    .iter()
                    .map(|&x| ProbeSpec {
                        name: format!("x{x}"),
                        x,
                        y: 0.0,
                    })
                    .collect();
                let head = format!("| {} | {dim}D | {fill} | {:.0} |", s.name, dp * 1000.0);
                let row = match tilted(p, theta, 1.5, 0.5, 3.0) {
                    Ok(r) => {
                        let off: Vec<f64> = PROBES
                            .iter()
                            .zip(&r.probes)
                            .map(|(x, z)| (z - (fill + x * theta.tan())) / dp)
                            .collect();
                        let mean = off.iter().sum::<f64>() / off.len() as f64;
                        let spread = off.iter().map(|o| (o - mean).abs()).fold(0.0, f64::max);
                        let [m, fx, fz] = r.errors().map(|e| 100.0 * e);
                        format!(
                            "{head} {:.3} | {:.3} | {m:+.2} % | {fx:+.2} % | {fz:+.2} % | {mean:+.2} | {spread:.2} |",
                            r.moment, r.theory_moment
                        )
                    }
                    Err(e) => format!("{head} failed: {e} | | | | | | |"),
                };
                println!("{row}");
                held += &row;
                held.push('\n');
            }
        }
    }
    if quick {
        return;
    }
    let stamp = measured();
    let response = format!("{stamp} {response}");
    let held = format!("{stamp} {held}");
    let page = root.join("docs/src/validation/sloshing.md");
    let mut text = std::fs::read_to_string(&page).expect("docs/src/validation/sloshing.md");
    for (name, table) in [("response", &response), ("tilted", &held)] {
        text = manual::replace_block(&text, name, table).expect("the sloshing page's markers");
    }
    std::fs::write(&page, text).unwrap();
    println!("wrote {}", page.display());
}

/// Where, when and at which commit the tables were measured.
fn measured() -> String {
    format!(
        "Measured on {} ({} threads), {}, commit {}.",
        manual::machine(),
        rayon::current_num_threads(),
        manual::today(),
        manual::commit()
    )
}
