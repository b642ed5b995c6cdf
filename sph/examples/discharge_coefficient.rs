//! The discharge coefficient of a slot against its width in particle spacings, with both schemes and both
//! kinds of wall (`sph::flooding::slot_case`: a reservoir emptying through a slot in its wall into a dry
//! compartment; the wall fixed obstacles, or a fixed body's side): prints the manual's table
//! (validation/flooding.md).
//!
//!     cargo run --release -p slosh-sph --example discharge_coefficient [-- --dp 0.005]

use sph::flooding::{slot_case, slot_discharge, SlotWall};
use sph::params::Scheme;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let dp = args
        .iter()
        .position(|a| a == "--dp")
        .and_then(|i| args.get(i + 1))
        .map_or(Ok(0.005), |s| s.parse::<f64>())?;
    println!(
        "| scheme | wall | slot, spacings | slot, mm | C_d per window (0.1 s from 0.2 s) | mean | head, m |"
    );
    println!("|---|---|---|---|---|---|---|");
    let runs = [SlotWall::Obstacles, SlotWall::Body]
        .into_iter()
        .flat_map(|wall| [Scheme::Wcsph, Scheme::Dfsph].map(|scheme| (wall, scheme)));
    for (wall, scheme) in runs {
        for opening in [4.0, 8.0, 12.0, 16.0] {
            let p = slot_case(scheme, wall, opening, dp);
            let d = slot_discharge(p, 0.6, 0.02, (0.2, 0.1))?;
            let cds: Vec<f64> = d.windows.iter().map(|w| w.cd).collect();
            let mean = cds.iter().sum::<f64>() / cds.len().max(1) as f64;
            let list: Vec<String> = cds.iter().map(|c| format!("{c:.2}")).collect();
            let heads = (d.windows.first(), d.windows.last());
            let (Some(first), Some(last)) = heads else {
                return Err("no window: the run is shorter than its settling time".into());
            };
            println!(
                "| {} | {} | {opening} | {:.0} | {} | {mean:.2} | {:.3}–{:.3} |",
                match scheme {
                    Scheme::Wcsph => "wcsph",
                    Scheme::Dfsph => "dfsph",
                },
                match wall {
                    SlotWall::Obstacles => "obstacles",
                    SlotWall::Body => "body",
                },
                d.width * 1000.0,
                list.join(", "),
                first.head,
                last.head
            );
        }
    }
    println!(
        "\n2D, dp {} mm; sharp-edged slot in theory and experiment: 0.61.",
        dp * 1000.0
    );
    Ok(())
}
