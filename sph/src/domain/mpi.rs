//! [`Comm`] over MPI (rsmpi). The start of an MPI program is [`crate::distributed::mpi::start`].

use super::{Comm, Op};
use mpi::collective::SystemOperation;
use mpi::datatype::{Partition, PartitionMut};
use mpi::topology::{Communicator, SimpleCommunicator};
use mpi::traits::*;
use mpi::Count;

/// The world communicator.
pub struct MpiComm {
    world: SimpleCommunicator,
}

impl MpiComm {
    /// The world communicator of an MPI library initialised with `Threading::Serialized` or more (the
    /// caller checks).
    pub fn new(world: SimpleCommunicator) -> Self {
        Self { world }
    }
}

// SAFETY: MPI is initialised with `Threading::Serialized` (checked in `crate::distributed::mpi::start`) and the solver makes one call
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
