//! [`Comm`] between threads of one process: the decomposition's reference transport, so that it is tested
//! (and can be tried) without MPI. Each rank is a thread holding one [`Threads`]; every call waits for all.

use super::{Comm, Op};
use std::sync::{Arc, Barrier, Mutex};

struct Shared {
    size: usize,
    barrier: Barrier,
    /// size × size mailboxes: slot `from * size + to`.
    slots: Mutex<Vec<Vec<f64>>>,
}

/// One rank's end of a world of threads.
pub struct Threads {
    shared: Arc<Shared>,
    rank: usize,
}

impl Threads {
    /// A world of `size` ranks: hand one to each thread.
    pub fn world(size: usize) -> Vec<Threads> {
        let shared = Arc::new(Shared {
            size,
            barrier: Barrier::new(size),
            slots: Mutex::new(vec![Vec::new(); size * size]),
        });
        (0..size)
            .map(|rank| Threads {
                shared: shared.clone(),
                rank,
            })
            .collect()
    }

    fn slots(&self) -> std::sync::MutexGuard<'_, Vec<Vec<f64>>> {
        self.shared.slots.lock().unwrap_or_else(|e| e.into_inner())
    }
}

impl Comm for Threads {
    fn rank(&self) -> usize {
        self.rank
    }

    fn size(&self) -> usize {
        self.shared.size
    }

    fn broadcast(&self, buf: &mut Vec<f64>) {
        if self.rank == 0 {
            self.slots()[0] = buf.clone();
        }
        self.shared.barrier.wait();
        if self.rank != 0 {
            *buf = self.slots()[0].clone();
        }
        self.shared.barrier.wait();
    }

    fn reduce(&self, v: &mut [f64], op: Op) {
        let n = self.shared.size;
        self.slots()[self.rank * n] = v.to_vec();
        self.shared.barrier.wait();
        {
            // Every rank reduces all contributions in rank order: the same result everywhere.
            let slots = self.slots();
            for (k, x) in v.iter_mut().enumerate() {
                let mut acc = slots[0][k];
                for r in 1..n {
                    let y = slots[r * n][k];
                    acc = match op {
                        Op::Sum => acc + y,
                        Op::Min => acc.min(y),
                        Op::Max => acc.max(y),
                    };
                }
                *x = acc;
            }
        }
        self.shared.barrier.wait();
    }

    fn all_to_all(&self, send: &[Vec<f64>], recv: &mut Vec<Vec<f64>>) {
        let n = self.shared.size;
        {
            let mut slots = self.slots();
            for (to, s) in send.iter().enumerate() {
                slots[self.rank * n + to].clone_from(s);
            }
        }
        self.shared.barrier.wait();
        recv.resize(n, Vec::new());
        {
            let slots = self.slots();
            for (from, r) in recv.iter_mut().enumerate() {
                r.clone_from(&slots[from * n + self.rank]);
            }
        }
        self.shared.barrier.wait();
    }
}
