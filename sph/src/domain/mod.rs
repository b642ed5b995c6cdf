//! Domain decomposition across processes (the paper's MPI parallelisation, §2).
//!
//! The tank is cut across its length into slabs of whole neighbour-grid columns, one per rank ([`Slabs`]).
//! A rank integrates the liquid particles in its slab; before every force evaluation it exchanges, in one
//! all-to-all, the particles that crossed into another slab (with their whole state) and copies of its
//! particles within two columns (one kernel support) of a neighbour's slab, the neighbour's halo; the
//! wall particles are the same on every rank and the neighbours' halo walls get their densities from their
//! owner. Halo copies are marked in their id ([`crate::particles::HALO`]) and left out of every total.
//!
//! Because slabs are whole columns and the halo is two columns, a particle sees the same candidate
//! neighbours, in the same order (cells are ordered by particle id), as in one process: the rates, the
//! global time step (a minimum over ranks) and so the trajectories are bit for bit those of a serial run.
//! Totals (wall force and moment) are summed over ranks, so they differ from the serial sums only by the
//! order of the additions. Observables are computed by the rank whose slab holds the probe or sensor.
//!
//! Every rank runs the same calls: rank 0 drives a [`Distributed`] solver that broadcasts each call (and the
//! tank motion, step by step) to the other ranks, which [`serve`] until rank 0 stops them. The transport is
//! the small [`Comm`] trait; [`mpi`] implements it with MPI (cargo feature `mpi`).

mod exchange;
#[cfg(feature = "mpi")]
pub mod mpi;
mod service;
mod slabs;

pub use exchange::Domain;
pub use service::{install, ranks, serve, shutdown, world, Distributed};
pub use slabs::Slabs;

/// A reduction.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Op {
    Sum,
    Min,
    Max,
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
}
