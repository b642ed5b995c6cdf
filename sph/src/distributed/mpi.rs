//! The start of an MPI program: rank 0 leads, the other ranks serve it ([`super::serve`]).

use crate::domain::mpi::MpiComm;
use crate::domain::Timed;
use mpi::environment::Universe;
use mpi::topology::Communicator;
use mpi::Threading;
use std::sync::Arc;

/// An MPI program's start: rank 0 gets [`Role::Lead`] and runs the program (its simulations spread over
/// all ranks; dropping the `Lead` releases the others and ends MPI); the other ranks get [`Role::Follow`]
/// after they have served rank 0 to its end, and should exit. In a world of one rank (a binary started
/// without `mpirun`) nothing is installed and the program runs serially.
pub enum Role {
    Lead(Lead),
    Follow,
}

pub struct Lead {
    _universe: Universe,
    ranks: usize,
}

impl Lead {
    pub fn ranks(&self) -> usize {
        self.ranks
    }
}

impl Drop for Lead {
    fn drop(&mut self) {
        super::shutdown();
    }
}

/// Starts MPI. Errors if MPI was started already or does not allow calls from a thread other than the
/// main one at a time (`MPI_THREAD_SERIALIZED`). `following` runs on the ranks other than 0 before they
/// start serving (e.g. to ignore the SIGINT/SIGTERM that `mpirun` sends every rank: rank 0 stops them once
/// it has finished its files).
pub fn start(following: impl FnOnce()) -> Result<Role, String> {
    let (universe, threading) = mpi::initialize_with_threading(Threading::Serialized)
        .ok_or("MPI was already initialised")?;
    if threading < Threading::Serialized {
        return Err(format!(
            "this MPI library provides {threading:?} threading, the solver needs Serialized (calls from one thread at a time, not always the main one): use OpenMPI 4 or later"
        ));
    }
    let world = universe.world();
    let ranks = world.size() as usize;
    let rank = world.rank();
    if ranks > 1 {
        crate::domain::install(Arc::new(Timed::new(MpiComm::new(world))));
        if rank != 0 {
            following();
            super::serve();
            drop(universe);
            return Ok(Role::Follow);
        }
    }
    Ok(Role::Lead(Lead {
        _universe: universe,
        ranks,
    }))
}
