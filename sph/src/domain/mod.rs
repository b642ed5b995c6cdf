//! Domain decomposition across processes (the paper's MPI parallelisation, §2).
//!
//! The tank is cut across its length into slabs of whole neighbour-grid columns, one per rank ([`Slabs`]).
//! A rank integrates the liquid particles in its slab. Where a serial run sorts its cells (the start of a
//! step) it exchanges, in one all-to-all, the particles that crossed into another slab (with their whole
//! state) and copies of its particles within two columns (one kernel support) of a neighbour's slab, the
//! neighbour's halo; between sorts (the weakly-compressible half step, the incompressible pressure
//! iterations) only the halo copies' values are refreshed in place ([`Domain::refresh`],
//! [`Ranks`]). The wall particles are the same on every rank; the neighbours' halo walls get
//! their densities from their owner. Halo copies are marked in their id ([`crate::particles::HALO`]) and
//! left out of every pass and total.
//!
//! Because slabs are whole columns and the halo is two columns, a particle sees the same candidate
//! neighbours, in the same order (cells are ordered by particle id), as in one process: the rates, the
//! global time step (a minimum over ranks) and so the trajectories are bit for bit those of a serial run.
//! Totals (wall force and moment) are summed over ranks, so they differ from the serial sums only by the
//! order of the additions. Observables are computed by the rank whose slab holds the probe or sensor.
//!
//! Every rank runs the same calls: rank 0 drives a [`crate::distributed::Distributed`] solver that broadcasts
//! each call (and the tank motion, step by step) to the other ranks, which [`crate::distributed::serve`] until
//! rank 0 stops them. The transport is
//! the small [`Comm`] trait; `mpi` implements it with MPI (cargo feature `mpi`).

mod exchange;
#[cfg(feature = "mpi")]
pub mod mpi;
mod slabs;
pub mod threads;

pub use exchange::Domain;
pub use slabs::Slabs;

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, OnceLock};
use std::time::Instant;

/// A reduction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    Sum,
    Min,
    Max,
}

/// What a scheme needs across ranks (the MPI domain decomposition); `None` in one process.
pub trait Ranks<const D: usize> {
    /// Liquid particles on all ranks.
    fn total(&self) -> usize;
    /// The halo copies' values of a per-particle scalar, and of a per-particle vector, from their owners.
    fn sync_scalar(&mut self, k: &mut [f32]);
    fn sync_vector(&mut self, v: &mut [[f32; D]]);
    /// Element-wise sum or extreme over ranks.
    fn reduce(&mut self, v: &mut [f64], op: Op);
}

/// What the decomposition needs from the transport between ranks. Every call is collective: all ranks make
/// the same calls in the same order.
pub trait Comm: Send + Sync {
    fn rank(&self) -> usize;
    fn size(&self) -> usize;
    /// Rank 0's `buf` (any length) to every rank.
    fn broadcast(&self, buf: &mut Vec<f64>);
    /// Element-wise reduction of `v` over ranks, result on every rank.
    fn reduce(&self, v: &mut [f64], op: Op);
    /// Sends `send[r]` to rank r; `recv[r]` gets what rank r sent here (`recv` is resized to the size).
    fn all_to_all(&self, send: &[Vec<f64>], recv: &mut Vec<Vec<f64>>);
    /// Seconds spent in the calls so far, if counted ([`Timed`]).
    fn seconds(&self) -> f64 {
        0.0
    }
}

/// A [`Comm`] that adds up the time spent in its calls: communication, and waiting for the other ranks
/// (load imbalance shows here too).
pub struct Timed<C> {
    inner: C,
    nanos: AtomicU64,
}

impl<C: Comm> Timed<C> {
    pub fn new(inner: C) -> Self {
        Self {
            inner,
            nanos: AtomicU64::new(0),
        }
    }

    fn time<T>(&self, f: impl FnOnce(&C) -> T) -> T {
        let start = Instant::now();
        let r = f(&self.inner);
        self.nanos
            .fetch_add(start.elapsed().as_nanos() as u64, Ordering::Relaxed);
        r
    }
}

impl<C: Comm> Comm for Timed<C> {
    fn rank(&self) -> usize {
        self.inner.rank()
    }
    fn size(&self) -> usize {
        self.inner.size()
    }
    fn broadcast(&self, buf: &mut Vec<f64>) {
        self.time(|c| c.broadcast(buf))
    }
    fn reduce(&self, v: &mut [f64], op: Op) {
        self.time(|c| c.reduce(v, op))
    }
    fn all_to_all(&self, send: &[Vec<f64>], recv: &mut Vec<Vec<f64>>) {
        self.time(|c| c.all_to_all(send, recv))
    }
    fn seconds(&self) -> f64 {
        self.nanos.load(Ordering::Relaxed) as f64 * 1e-9
    }
}

pub(crate) static WORLD: OnceLock<Arc<dyn Comm>> = OnceLock::new();

/// The processes a simulation spans: one, or this rank's part of a decomposition over several. What crosses
/// ranks (sums, rank 0's values, which rank reads a place) is asked of it alike in both cases; with one
/// process each answer is the local value.
pub(crate) enum Processes {
    One,
    Many(Domain),
}

impl Processes {
    /// The decomposition, when there is one (exchanging particles, gathering them).
    pub(crate) fn domain(&self) -> Option<&Domain> {
        match self {
            Processes::One => None,
            Processes::Many(d) => Some(d),
        }
    }

    pub(crate) fn domain_mut(&mut self) -> Option<&mut Domain> {
        match self {
            Processes::One => None,
            Processes::Many(d) => Some(d),
        }
    }

    /// The same scheme-facing view as a trait object (None: one process).
    pub(crate) fn ranks<const D: usize>(&mut self) -> Option<&mut dyn Ranks<D>> {
        self.domain_mut().map(|d| d as &mut dyn Ranks<D>)
    }

    /// Element-wise reduction over ranks, result on every rank.
    pub(crate) fn reduce(&self, v: &mut [f64], op: Op) {
        if let Processes::Many(d) = self {
            d.comm.reduce(v, op);
        }
    }

    /// Rank 0's `local()` on every rank (only rank 0 evaluates it).
    pub(crate) fn root_values<const N: usize>(&self, local: impl FnOnce() -> [f64; N]) -> [f64; N] {
        match self {
            Processes::One => local(),
            Processes::Many(d) => {
                let mut buf = if d.is_root() {
                    local().to_vec()
                } else {
                    Vec::new()
                };
                d.comm.broadcast(&mut buf);
                std::array::from_fn(|k| buf[k])
            }
        }
    }

    /// Whether this rank reads the place at x along the tank (its slab holds it).
    pub(crate) fn owns<const D: usize>(&self, grid: &crate::neighbours::Grid<D>, x: f64) -> bool {
        self.domain().is_none_or(|d| d.owns(grid, x))
    }

    /// Ranks the simulation runs on.
    pub(crate) fn size(&self) -> usize {
        self.domain().map_or(1, |d| d.comm.size())
    }
}

/// Makes [`crate::build`] decompose every simulation over `comm`'s ranks (once per process, by the program
/// that started MPI; a world of one rank changes nothing).
pub fn install(comm: Arc<dyn Comm>) {
    if WORLD.set(comm).is_err() {
        panic!("sph::domain::install called twice");
    }
}

/// The installed ranks, if there is more than one.
pub fn world() -> Option<&'static Arc<dyn Comm>> {
    WORLD.get().filter(|c| c.size() > 1)
}

/// Seconds this rank has spent communicating and waiting for the others (0 without ranks).
pub fn comm_seconds() -> f64 {
    world().map_or(0.0, |c| c.seconds())
}

/// Number of ranks the simulations run on.
pub fn ranks() -> usize {
    world().map_or(1, |c| c.size())
}
