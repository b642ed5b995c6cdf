//! Fuzzes what `slosh` reads (`slosh_tests::fuzz`): a million generated inputs a target by default.
//!
//! ```text
//! cargo run --release -p slosh-tests --example fuzz -- [--inputs N] [--seed S] [--target parameters|ros-args|csv|iox|bags]
//! ```
//!
//! Prints, per target, the inputs tried, accepted and refused; exits non-zero if any input panicked, writing
//! each such input to `target/fuzz/`.

use slosh_tests::fuzz::{self, Rng, Tally};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let value = |flag: &str| {
        args.iter().position(|a| a == flag).map(|i| {
            args.get(i + 1)
                .unwrap_or_else(|| panic!("{flag} needs a value"))
                .clone()
        })
    };
    let n: usize = value("--inputs").map_or(1_000_000, |v| v.parse().expect("--inputs N"));
    let seed: u64 = value("--seed").map_or(1, |v| v.parse().expect("--seed S"));
    let only = value("--target");
    // Panics are expected to be caught and counted, not printed for each input.
    std::panic::set_hook(Box::new(|_| {}));
    let mut failed = false;
    let targets = ["parameters", "ros-args", "csv", "iox", "bags"];
    for name in targets
        .iter()
        .filter(|t| only.as_deref().is_none_or(|o| o == **t))
    {
        let mut rng = Rng::new(seed);
        let clock = std::time::Instant::now();
        let t: Tally = match *name {
            "parameters" => fuzz::parameters(n, &mut rng),
            "ros-args" => fuzz::ros_args(n, &mut rng),
            "csv" => fuzz::csv(n, &mut rng),
            "iox" => fuzz::iox_samples(n, &mut rng),
            _ => {
                let (bag, cfg) = fuzz::recorded_bag();
                fuzz::bags(n, &mut rng, &bag, &cfg)
            }
        };
        println!(
            "{name}: {} inputs in {:.0} s: {} accepted, {} refused ({} without a message), {} panicked",
            t.inputs,
            clock.elapsed().as_secs_f64(),
            t.accepted,
            t.refused,
            t.silent,
            t.panics.len()
        );
        for (i, (what, input)) in t.panics.iter().enumerate() {
            let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../target/fuzz");
            std::fs::create_dir_all(&dir).unwrap();
            let path = dir.join(format!("{name}-{i}"));
            std::fs::write(&path, input).unwrap();
            println!("  panic: {what} (input: {})", path.display());
            failed = true;
        }
        failed |= t.silent > 0;
    }
    if failed {
        std::process::exit(1);
    }
}
