//! # sph — a liquid in a moving tank, by smoothed particle hydrodynamics
//!
//! The solver of the paper in the project's seed (Shen & Vassalos, "Applications of 3D parallel SPH for
//! sloshing and flooding"): weakly-compressible SPH with the cubic B-spline (or Wendland) kernel, Tait
//! equation of state, Monaghan's artificial viscosity, δ-SPH density diffusion, dynamic boundary particles or
//! mirror particles, symplectic or Verlet time stepping under the CFL condition. No I/O: a
//! [`motion::TankMotion`] goes in, [`observe::Observation`]s come out.
//!
//! ```
//! use sph::{params::*, motion::AtRest, simulation::build};
//! let params = SimParams {
//!     dimension: 2,
//!     tank: TankSpec { length: 0.4, breadth: 0.1, height: 0.3 },
//!     fill: FillSpec { height: 0.1, length: 0.0 },
//!     particle_spacing: 0.02,
//!     fluid: FluidSpec::default(),
//!     gravity: 9.81,
//!     solver: SolverSpec::default(),
//!     probes: vec![ProbeSpec { name: "mid".into(), x: 0.0, y: 0.0 }],
//!     pressure_sensors: vec![],
//!     bodies: vec![],
//!     wave_maker: None,
//!     obstacles: vec![],
//! };
//! let mut sim = build(params).unwrap();
//! sim.advance_to(&AtRest, 0.01).unwrap();
//! let obs = sim.observe(&AtRest).unwrap();
//! assert!((obs.probes[0] - 0.1).abs() < 0.02);
//! ```
// Component loops over the const-generic dimension read as the formulas do; `!(x >= 0.0)` is used on purpose
// to catch NaN along with negatives.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod body;
pub mod boundary;
pub mod domain;
pub mod eos;
pub mod error;
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

pub use error::SimError;
pub use simulation::{build, Counts, Simulation, Solver, Stats};
