//! Pressure schemes: how a step finds the liquid's pressure and moves it. Each scheme implements
//! [`PressureScheme`] in a folder of its own, named for its method: [`wcsph`] (weakly-compressible SPH, the
//! seed paper's) and [`dfsph`] (divergence-free SPH, Bender & Koschier). Both advance the same [`State`]
//! (the liquid, the walls, the bodies, this rank's part of a decomposition) and share its stages (the frame
//! terms of the motion, sorting, the bodies); the simulation ([`crate::Simulation`]) holds one state and one
//! scheme and reads the observables of both alike.
//!
//! A new scheme (or a backend on other hardware) is a type that implements [`PressureScheme`], a
//! [`crate::params::Scheme`] variant, and its branch in [`crate::Simulation::new_in`].

pub mod coupling;
pub mod dfsph;
pub mod landing;
pub mod state;
pub mod wcsph;

pub use state::{State, Stats};

use crate::error::SimError;
use crate::kernel::Kernel;
use crate::motion::TankMotion;
use crate::observe::wall_pressure::FaceSpot;

/// A pressure scheme: one step of the liquid in a moving tank, and what the observables need of it.
pub trait PressureScheme<const D: usize, K: Kernel>: Send {
    /// Advances the state one time step, no further than the motion's end or the state's step limit;
    /// returns the step's length.
    fn step(&mut self, s: &mut State<D, K>, motion: &dyn TankMotion) -> Result<f64, SimError>;

    /// Makes the pressures and the walls' force belong to the current state (after the last step, or a
    /// change of state such as new velocities), and sorts the liquid for the observables' neighbour sums.
    fn prepare_observation(
        &mut self,
        s: &mut State<D, K>,
        motion: &dyn TankMotion,
    ) -> Result<(), SimError>;

    /// The tank walls' force and moment on the liquid to report now (per unit breadth in 2D); a scheme that
    /// reports a mean over the steps since the last observation starts a new mean.
    fn wall_wrench(&mut self, s: &State<D, K>) -> ([f64; 3], [f64; 3]);

    /// The pressure a sensor on a wall face reads when the scheme has a wall pressure of its own (the push of
    /// the liquid on the wall particles behind the sensor; across ranks, this rank's walls' part, those
    /// where `mine`); `None`: the liquid's pressure interpolated at the face.
    fn face_pressure(
        &self,
        s: &State<D, K>,
        spot: &FaceSpot<D>,
        mine: &dyn Fn(f64) -> bool,
    ) -> Option<f64>;

    /// Liquid particle a's pressure, for particle frames.
    fn liquid_pressure(&self, s: &State<D, K>, a: usize) -> f32;

    /// A wall particle's pressure and density for particle frames, from its density `rho`.
    fn wall_reading(&self, s: &State<D, K>, rho: f32) -> (f32, f32);
}

/// Particles per parallel work item of every scheme's passes (fixed, so reductions do not depend on the
/// number of threads).
pub const CHUNK: usize = 256;

/// What one force evaluation found, summed over the liquid.
#[derive(Clone, Copy, Debug, Default)]
pub struct PassTotals {
    /// Force of the boundary on the liquid (x, y, z), per unit breadth in 2D.
    pub force: [f64; 3],
    /// Its moment about the tank origin.
    pub moment: [f64; 3],
    /// Largest acceleration magnitude.
    pub max_acc: f32,
    /// Largest |h v·r / (r² + η²)| over interacting pairs.
    pub max_mu: f32,
    /// Any non-finite rate.
    pub non_finite: bool,
}

impl PassTotals {
    /// Sums force, moment and the non-finite flag with `reduce` (over ranks).
    pub fn reduce_with(&mut self, reduce: impl FnOnce(&mut [f64])) {
        let mut v = [0.0; 7];
        v[..3].copy_from_slice(&self.force);
        v[3..6].copy_from_slice(&self.moment);
        v[6] = f64::from(u8::from(self.non_finite));
        reduce(&mut v);
        self.force.copy_from_slice(&v[..3]);
        self.moment.copy_from_slice(&v[3..6]);
        self.non_finite = v[6] > 0.0;
    }

    pub fn merge(&mut self, o: &PassTotals) {
        for k in 0..3 {
            self.force[k] += o.force[k];
            self.moment[k] += o.moment[k];
        }
        self.max_acc = self.max_acc.max(o.max_acc);
        self.max_mu = self.max_mu.max(o.max_mu);
        self.non_finite |= o.non_finite;
    }
}
