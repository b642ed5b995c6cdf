//! A short run of the fuzzing in `slosh_tests::fuzz` (the command `cargo run --release -p slosh-tests
//! --example fuzz` runs a million inputs a target): no input panics, every refusal says something, and the
//! generated inputs reach both outcomes (so they are neither all garbage nor all unchanged).

use slosh_tests::fuzz::{self, Rng, Tally};

fn check(name: &str, t: &Tally) {
    eprintln!(
        "{name}: {} inputs, {} accepted, {} refused, {} panics",
        t.inputs,
        t.accepted,
        t.refused,
        t.panics.len()
    );
    for (what, input) in &t.panics {
        eprintln!(
            "  panic: {what}\n  input ({} bytes): {:?}",
            input.len(),
            String::from_utf8_lossy(&input[..input.len().min(400)])
        );
    }
    assert!(t.panics.is_empty(), "{name}: inputs panicked (above)");
    assert_eq!(t.silent, 0, "{name}: refusals without a message");
    assert!(
        t.accepted > 0 && t.refused > 0,
        "{name}: the inputs reached one outcome only"
    );
}

#[test]
fn parameters_and_overrides() {
    check("parameters", &fuzz::parameters(3000, &mut Rng::new(1)));
}

#[test]
fn ros_arguments() {
    check("ros-args", &fuzz::ros_args(20000, &mut Rng::new(2)));
}

#[test]
fn motion_csv_files() {
    check("csv", &fuzz::csv(5000, &mut Rng::new(3)));
}

#[test]
fn iceoryx2_motion_samples() {
    check("iox", &fuzz::iox_samples(20000, &mut Rng::new(4)));
}

#[test]
fn recorded_bags() {
    let (seed, cfg) = fuzz::recorded_bag();
    check("bags", &fuzz::bags(1500, &mut Rng::new(5), &seed, &cfg));
}
