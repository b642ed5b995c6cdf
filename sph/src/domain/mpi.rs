//! [`Comm`] over MPI (rsmpi), and the start of an MPI program: [`start`].

use super::{Comm, Op};
use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::environment::Universe;
use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::traits::*;
use mpi::{Count, Threading};
use std::sync::Arc;

/// The world communicator.
pub struct MpiComm {
    world: SimpleCommunicator,
}

// SAFETY: MPI is initialised with `Threading::Serialized` (checked in `start`) and the solver makes one call
// at a time: a step runs on one thread of rayon's pool, observations on the caller's, never both at once.
unsafe impl Send for MpiComm {}
unsafe impl Sync for MpiComm {}

impl Comm for MpiComm {
    fn rank(&self) -> usize {
        self.world.rank() as usize
    }

    fn size(&self) -> usize {
        self.world.size() as usize
    }

    fn broadcast(&self, buf: &mut Vec<f64>) {
        let root = self.world.process_at_rank(0);
        let mut n = buf.len() as u64;
        root.broadcast_into(&mut n);
        buf.resize(n as usize, 0.0);
        root.broadcast_into(&mut buf[..]);
    }

    fn reduce(&self, v: &mut [f64], op: Op) {
        let send = v.to_vec();
        let op = match op {
            Op::Sum => SystemOperation::sum(),
            Op::Min => SystemOperation::min(),
            Op::Max => SystemOperation::max(),
        };
        self.world.all_reduce_into(&send[..], v, op);
    }

    fn all_to_all(&self, send: &[Vec<f64>], recv: &mut Vec<Vec<f64>>) {
        let n = self.size();
        assert_eq!(send.len(), n);
        let counts: Vec<Count> = send.iter().map(|s| s.len() as Count).collect();
        let mut rcounts: Vec<Count> = vec![0; n];
        self.world.all_to_all_into(&counts[..], &mut rcounts[..]);
        let displs = |c: &[Count]| -> Vec<Count> {
            c.iter()
                .scan(0, |acc, &x| {
                    let d = *acc;
                    *acc += x;
                    Some(d)
                })
                .collect()
        };
        let (sd, rd) = (displs(&counts), displs(&rcounts));
        let flat: Vec<f64> = send.concat();
        let mut rflat = vec![0.0; rcounts.iter().sum::<Count>() as usize];
        {
            let sp = Partition::new(&flat[..], &counts[..], &sd[..]);
            let mut rp = PartitionMut::new(&mut rflat[..], &rcounts[..], &rd[..]);
            self.world.all_to_all_varcount_into(&sp, &mut rp);
        }
        recv.resize(n, Vec::new());
        for r in 0..n {
            recv[r].clear();
            let d = rd[r] as usize;
            recv[r].extend_from_slice(&rflat[d..d + rcounts[r] as usize]);
        }
    }
}

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
        super::install(Arc::new(super::Timed::new(MpiComm { world })));
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
