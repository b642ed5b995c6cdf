//! Shared by the solver's integration tests: the tank cases they start from.
#![allow(dead_code)]

use sph::params::*;

/// Standard gravity, m/s².
pub const G: f64 = 9.81;

/// A 2D tank (0.25 m broad) filled to `fill` at spacing `dp`, default solver, no probes, sensors or bodies.
pub fn tank2d(length: f64, height: f64, fill: f64, dp: f64) -> SimParams {
    let tank = TankSpec {
        length,
        breadth: 0.25,
        height,
    };
    SimParams::filled_tank(2, tank, fill, dp)
}

/// A probe at abscissa x on the centre line.
pub fn probe(name: &str, x: f64) -> ProbeSpec {
    ProbeSpec {
        name: name.into(),
        x,
        y: 0.0,
    }
}
