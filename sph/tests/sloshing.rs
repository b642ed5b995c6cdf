//! Sloshing as a naval architect measures it, against linear potential-flow theory for the same tank and
//! fill (`sph::sloshing::theory`; Faltinsen & Timokha 2009): the first mode's free-decay period and damping,
//! the force and moment per unit motion of a swayed or pitched tank below and above resonance, and a tank
//! held tilted. The seed tank (0.8 m long) in 2D at 8 mm (24 and 49 particles deep), with the incompressible
//! scheme's corrected kernel gradients (`solver.dfsph.kernel_correction`), the Wendland kernel and no
//! artificial viscosity: the setting that reaches these bounds. Bounds from physics: the period within 1 % and ζ ≤ 0.005 (small model
//! tanks measure 0.001–0.005; laminar Stokes layers give 0.0004–0.0007 here), the steady force or moment
//! within 10 % and 10° of theory, a tilted tank's moment within 2 % of its weight through the centroid.
//! The shipped setting (the seed cases' `dfsph`) is held to the tilted tank's bounds too, in 2D and 3D; it
//! does not meet the period and damping bounds (the manual's sloshing page has its convergence table).

use sph::kernel::KernelKind;
use sph::params::*;
use sph::sloshing::experiment::{forced, free_decay, seed_tank, tilted, Forcing};

mod common;
use common::probe;

/// The 2D seed tank filled to `fill`, dp 8 mm, with the setting under test.
fn seed(fill: f64) -> SimParams {
    let mut p = seed_tank(2, fill, 0.008);
    p.solver.scheme = Scheme::Dfsph;
    p.solver.kernel = KernelKind::Wendland;
    p.solver.dfsph.kernel_correction = true;
    p.solver.artificial_viscosity.alpha = 0.0;
    p
}

#[test]
fn free_decay_has_the_linear_period_and_the_damping_of_a_model_tank() {
    for fill in [0.19, 0.39] {
        // A 1 cm wave (ka ≈ 0.04: linear), over seven periods; the first is left out of the fit.
        let r = free_decay(seed(fill), 0.01, 7.0).unwrap();
        eprintln!(
            "fill {fill}: period {:.4} s (theory {:.4} s, {:+.2} %), ζ {:.4} (laminar theory {:.5}) over {:.1} cycles",
            r.decay.period,
            r.theory_period,
            100.0 * r.period_error(),
            r.decay.damping_ratio,
            r.laminar.ratio,
            r.decay.cycles
        );
        assert!(r.decay.cycles >= 5.0);
        assert!(
            r.period_error().abs() < 0.01,
            "fill {fill}: period {} s against {} s",
            r.decay.period,
            r.theory_period
        );
        assert!(
            r.decay.damping_ratio >= 0.0 && r.decay.damping_ratio <= 0.005,
            "fill {fill}: damping ratio {}",
            r.decay.damping_ratio
        );
    }
}

#[test]
fn swayed_and_pitched_tanks_answer_as_linear_theory() {
    // Sway 4 mm (η at the wall ≤ 8 mm near resonance) and pitch 0.5°, ramped in over three forcing
    // periods, the force or moment fitted over the next eight with the free mode beside it.
    for (forcing, a) in [
        (Forcing::Sway, 0.004),
        (Forcing::Pitch, 0.5f64.to_radians()),
    ] {
        for ratio in [0.5, 0.8, 1.25, 1.5] {
            let r = forced(seed(0.19), forcing, a, ratio, 3.0, 8.0).unwrap();
            eprintln!(
                "{forcing:?} at {ratio} ω1: {:.1} per unit motion against {:.1} ({:+.1} %), phase {:+.1}°",
                r.amplitude,
                r.theory_amplitude,
                100.0 * r.amplitude_error(),
                r.phase_error_deg()
            );
            assert!(
                r.amplitude_error().abs() < 0.10,
                "{forcing:?} at {ratio} ω1: {} against {}",
                r.amplitude,
                r.theory_amplitude
            );
            assert!(
                r.phase_error_deg().abs() < 10.0,
                "{forcing:?} at {ratio} ω1: phase {}°",
                r.phase_error_deg()
            );
        }
    }
}

#[test]
fn a_tank_held_tilted_carries_the_weight_through_the_centroid() {
    let mut p = seed(0.19);
    let xs = [-0.3, 0.0, 0.3];
    p.probes = xs.iter().map(|&x| probe(&format!("x{x}"), x)).collect();
    let theta = 5f64.to_radians();
    let r = tilted(p, theta, 1.5, 0.5, 3.0).unwrap();
    eprintln!(
        "tilted 5°: moment {:.3} N·m against {:.3}, force {:?} N for a weight of {:.2} N, probes {:?}",
        r.moment, r.theory_moment, r.force, r.weight, r.probes
    );
    // Moment, force along x, force along z.
    assert!(r.errors().iter().all(|e| e.abs() < 0.02), "{r:?}");
    // Level in the world: z = h + x tan θ in the tank frame, within a quarter spacing.
    for (x, z) in xs.iter().zip(&r.probes) {
        let want = 0.19 + x * theta.tan();
        assert!(
            (z - want).abs() < 0.25 * 0.008,
            "probe at {x}: {z} against {want}"
        );
    }
}

/// The shipped incompressible setting (plain gradients, the cubic spline, α 0.02: the seed cases' `dfsph`)
/// held tilted 5°, 2D at 8 mm and 3D at 20 mm, both seed fills: the weight through the tilted liquid's
/// centroid within 2 % (moment and both force components) and the surface level in the world (the probes
/// on one horizontal line within a quarter spacing). Where the surface stands is not asserted here: this
/// setting's liquid settles 0.15–0.4 spacings below the fill (a known gap, in the manual's validation pages).
#[test]
fn the_shipped_setting_holds_a_tilted_tank_s_weight_through_the_centroid() {
    let theta = 5f64.to_radians();
    let xs = [-0.3, 0.0, 0.3];
    for (dim, dp) in [(2, 0.008), (3, 0.02)] {
        for fill in [0.19, 0.39] {
            let mut p = seed_tank(dim, fill, dp);
            p.solver.scheme = Scheme::Dfsph;
            p.probes = xs.iter().map(|&x| probe(&format!("x{x}"), x)).collect();
            let r = tilted(p, theta, 1.5, 0.5, 3.0).unwrap();
            // Each probe's height above the level line through the fill (z = h + x tan θ in the tank frame).
            let off: Vec<f64> = xs
                .iter()
                .zip(&r.probes)
                .map(|(x, z)| z - (fill + x * theta.tan()))
                .collect();
            let mean = off.iter().sum::<f64>() / off.len() as f64;
            eprintln!(
                "{dim}D {dp} m, fill {fill}: moment {:.3} N·m against {:.3}, force {:?} N for a weight of {:.2} N, surface {:.2} dp from the fill",
                r.moment, r.theory_moment, r.force, r.weight, mean / dp
            );
            let at = format!("{dim}D, fill {fill}");
            // Moment, force along x, force along z.
            assert!(r.errors().iter().all(|e| e.abs() < 0.02), "{at}: {r:?}");
            for (x, o) in xs.iter().zip(&off) {
                assert!(
                    (o - mean).abs() < 0.25 * dp,
                    "{at}: probe at {x} stands {o} m from the level line, the others {off:?}"
                );
            }
        }
    }
}
