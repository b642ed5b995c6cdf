//! The seed tank's first sloshing mode as the solver gives it, beside linear theory: free-decay period and
//! damping ratio, by scheme setting, fill and particle spacing, as a Markdown table (the manual's accuracy
//! table is this command's output).
//!
//!     cargo run --release -p sph --example sloshing_accuracy            # 2D, 16/8/4 mm
//!     cargo run --release -p sph --example sloshing_accuracy -- --3d    # adds 3D at 20 mm
//!     cargo run --release -p sph --example sloshing_accuracy -- --quick # 2D at 16 mm only
use sph::kernel::KernelKind;
use sph::params::*;
use sph::sloshing::experiment::{free_decay, seed_tank as seed};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let quick = args.iter().any(|a| a == "--quick");
    let three = args.iter().any(|a| a == "--3d");
    type Setup = (&'static str, fn(&mut SimParams));
    let setups: [Setup; 3] = [
        ("dfsph (default)", |p| p.solver.scheme = Scheme::Dfsph),
        ("dfsph, kernel_correction, wendland, α 0", |p| {
            p.solver.scheme = Scheme::Dfsph;
            p.solver.kernel = KernelKind::Wendland;
            p.solver.dfsph.kernel_correction = true;
            p.solver.artificial_viscosity.alpha = 0.0;
        }),
        ("wcsph (default)", |_| {}),
    ];
    let mut cases: Vec<(usize, f64)> = if quick {
        vec![(2, 0.016)]
    } else {
        vec![(2, 0.016), (2, 0.008), (2, 0.004)]
    };
    if three {
        cases.push((3, 0.02));
    }
    println!(
        "| setting | dim | fill m | dp mm | period s | theory s | error | ζ | laminar ζ | wall s |"
    );
    println!("|---|---|---|---|---|---|---|---|---|---|");
    for (name, setup) in setups {
        for &(dim, dp) in &cases {
            // WCSPH's steps follow the speed of sound: its finer cases take minutes each.
            if name.starts_with("wcsph") && (dp < 0.008 || dim == 3) {
                continue;
            }
            for fill in [0.19, 0.39] {
                let mut p = seed(dim, fill, dp);
                setup(&mut p);
                match free_decay(p, 0.01, 8.0) {
                    Ok(r) => println!(
                        "| {name} | {dim}D | {fill} | {:.0} | {:.4} | {:.4} | {:+.2} % | {:.4} | {:.5} | {:.0} |",
                        dp * 1000.0,
                        r.decay.period,
                        r.theory_period,
                        100.0 * r.period_error(),
                        r.decay.damping_ratio,
                        r.laminar.ratio,
                        r.wall_time
                    ),
                    Err(e) => println!("| {name} | {dim}D | {fill} | {:.0} | failed: {e} |", dp * 1000.0),
                }
            }
        }
    }
}
