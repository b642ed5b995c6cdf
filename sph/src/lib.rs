//! # sph — a liquid in a moving tank, by smoothed particle hydrodynamics
//!
//! The liquid in a closed rectangular tank that moves with a vessel: a [`motion::TankMotion`] (the tank's
//! pose, velocity and acceleration in time) goes in, [`observe::Observation`]s (free-surface probes, wall
//! pressures, the liquid's force and moment on the tank) come out. No I/O.
//!
//! Two schemes ([`params::Scheme`]): the weakly-compressible SPH of the project's seed paper (Shen &
//! Vassalos, "Applications of 3D parallel SPH for sloshing and flooding": cubic B-spline or Wendland kernel,
//! Tait equation of state, Monaghan's artificial viscosity, δ-SPH, dynamic or mirror boundary particles,
//! symplectic or Verlet time stepping under the CFL condition), in [`scheme::wcsph`], and divergence-free
//! incompressible SPH (Bender & Koschier), in [`scheme::dfsph`]. [`sloshing`] holds the linear theory the
//! solver is checked against and the experiments that check it.
//!
//! A complete program: a 2D tank 0.8 m long, 0.19 m of water, swayed 5 mm at 1.3 s, two probes, stepped to
//! each output time:
//!
//! ```
//! use sph::motion::{RegularDof, RegularMotion};
//! use sph::params::{ProbeSpec, Scheme, SimParams, TankSpec};
//!
//! let tank = TankSpec { length: 0.8, breadth: 0.25, height: 0.6 };
//! let mut params = SimParams::filled_tank(2, tank, 0.19, 0.02);
//! params.solver.scheme = Scheme::Dfsph;
//! for (name, x) in [("wall", -0.376), ("mid", 0.0)] {
//!     params.probes.push(ProbeSpec { name: name.into(), x, y: 0.0 });
//! }
//! let mut sway = RegularMotion { dofs: Default::default(), ramp: 1.0 };
//! sway.dofs[0] = RegularDof { amplitude: 0.005, period: 1.3, phase: 0.0 };
//!
//! let mut sim = sph::build(params).unwrap();
//! for k in 1..=10 {
//!     let t = 0.05 * k as f64;
//!     sim.advance_to(&sway, t).unwrap();
//!     let o = sim.observe(&sway).unwrap();
//!     println!("t {:.2} s: probes {:?} m, fx {:.1} N", o.time, o.probes, o.wrench.force[0]);
//!     // Both probes see the liquid near its resting depth; the liquid weighs 0.8 × 0.25 × 0.19 m³ of water.
//!     assert!(o.probes.iter().all(|h| (h - 0.19).abs() < 0.03));
//!     assert!((o.wrench.force[2] + 372.8).abs() < 0.1 * 372.8);
//! }
//! ```
// Component loops over the const-generic dimension read as the formulas do; `!(x >= 0.0)` is used on purpose
// to catch NaN along with negatives.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod body;
pub mod boundary;
pub mod distributed;
pub mod domain;
pub mod eos;
pub mod error;
pub mod fast;
pub mod flooding;
pub mod integrate;
pub mod kernel;
pub mod motion;
pub mod neighbours;
pub mod observe;
pub mod params;
pub mod particles;
pub mod scheme;
pub mod simulation;
pub mod sloshing;
pub mod tank;
pub mod vector;

pub use error::SimError;
pub use simulation::{Counts, Simulation, Solver, Stats};

/// Builds the simulation the parameters ask for: in one process, or spread over the ranks of an MPI
/// program ([`crate::domain::install`]; called on rank 0, the others follow in [`crate::distributed::serve`]).
pub fn build(params: params::SimParams) -> Result<Box<dyn Solver>, SimError> {
    params.validate()?;
    match domain::world() {
        Some(comm) => Ok(Box::new(distributed::Distributed::build(
            comm.clone(),
            params,
        )?)),
        None => simulation::build_local(params, None),
    }
}
