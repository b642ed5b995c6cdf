//! One rank's part of the decomposition: the exchange of particles, halos and halo wall densities before
//! each force evaluation, the rebalancing of the slabs, and the global counts.

use super::{Comm, Op, Slabs};
use crate::neighbours::{Grid, OUTSIDE};
use crate::particles::{Boundary, Fluid, HALO};
use std::sync::Arc;

/// A rank's view of the decomposition.
pub struct Domain {
    pub comm: Arc<dyn Comm>,
    pub slabs: Slabs,
    /// Liquid particles on all ranks, and those lost from the tank on all ranks, as of the last exchange.
    pub fluid_total: usize,
    pub lost_total: usize,
    /// Times the slabs were moved to even out the particle counts.
    pub rebalances: u64,
    send: Vec<Vec<f64>>,
    recv: Vec<Vec<f64>>,
    hist: Vec<f64>,
    /// Since the last exchange: the particles copied to each rank's halo, and the halo copies from each
    /// rank, both in the order of their ids (local indices), for [`Domain::refresh`].
    halo_out: Vec<Vec<u32>>,
    halo_in: Vec<Vec<u32>>,
}

/// f64 values per halo refresh: pos, vel (D each), rho.
const fn refresh_len(d: usize) -> usize {
    2 * d + 1
}

/// f64 values per particle record: pos, vel, pos0, vel0 (D each), rho, rho0, pressure, kappa, kappa_div, id.
const fn record_len(d: usize) -> usize {
    4 * d + 6
}

fn push_record<const D: usize>(buf: &mut Vec<f64>, f: &Fluid<D>, i: usize, id: u32) {
    for k in 0..D {
        buf.extend_from_slice(&[f.pos[k][i], f.vel[k][i], f.pos0[k][i], f.vel0[k][i]]);
    }
    buf.extend_from_slice(&[
        f.rho[i],
        f.rho0[i],
        f.pressure[i],
        f.kappa[i],
        f.kappa_div[i],
        id as f64,
    ]);
}

fn pull_record<const D: usize>(f: &mut Fluid<D>, r: &[f64]) {
    for k in 0..D {
        f.pos[k].push(r[4 * k]);
        f.vel[k].push(r[4 * k + 1]);
        f.pos0[k].push(r[4 * k + 2]);
        f.vel0[k].push(r[4 * k + 3]);
    }
    let s = &r[4 * D..];
    f.rho.push(s[0]);
    f.rho0.push(s[1]);
    f.pressure.push(s[2]);
    f.kappa.push(s[3]);
    f.kappa_div.push(s[4]);
    f.id.push(s[5] as u32);
}

/// Owned liquid particles per grid column (those off the grid counted in the end columns).
fn column_counts<const D: usize>(grid: &Grid<D>, fluid: &Fluid<D>, hist: &mut [f64]) {
    let last = hist.len() as i64 - 1;
    hist.iter_mut().for_each(|h| *h = 0.0);
    for i in (0..fluid.len()).filter(|&i| fluid.owned(i)) {
        hist[grid.column(fluid.pos[0][i]).clamp(0, last) as usize] += 1.0;
    }
}

fn unpack_walls<const D: usize>(w: &mut Boundary<D>, pairs: &[f64]) {
    for p in pairs.chunks_exact(2) {
        w.rho[p[0] as usize] = p[1];
    }
}

/// Keeps the particles i with `keep[i]`, in order, with the ids `ids[i]`.
fn compact<const D: usize>(f: &mut Fluid<D>, keep: &[Option<u32>]) {
    fn retain<T: Copy>(v: &mut Vec<T>, keep: &[Option<u32>]) {
        let mut w = 0;
        for (i, k) in keep.iter().enumerate() {
            if k.is_some() {
                v[w] = v[i];
                w += 1;
            }
        }
        v.truncate(w);
    }
    for k in 0..D {
        retain(&mut f.pos[k], keep);
        retain(&mut f.vel[k], keep);
        retain(&mut f.pos0[k], keep);
        retain(&mut f.vel0[k], keep);
    }
    retain(&mut f.rho, keep);
    retain(&mut f.rho0, keep);
    retain(&mut f.pressure, keep);
    retain(&mut f.kappa, keep);
    retain(&mut f.kappa_div, keep);
    f.id = keep.iter().flatten().copied().collect();
}

impl Domain {
    /// The slabs that share `fluid` (the whole initial liquid, the same on every rank) evenly; keeps this
    /// rank's part of it.
    /// `halo`: columns of the halos (a kernel support is [`crate::neighbours::REACH`]).
    pub fn split<const D: usize>(
        comm: Arc<dyn Comm>,
        grid: &Grid<D>,
        fluid: &mut Fluid<D>,
        halo: i64,
    ) -> Result<Self, String> {
        let mut hist = vec![0.0; grid.dims()[0]];
        column_counts(grid, fluid, &mut hist);
        let slabs = Slabs::balanced(&hist, comm.size(), halo)?;
        let me = comm.rank();
        let keep: Vec<Option<u32>> = (0..fluid.len())
            .map(|i| (slabs.owner(grid.column(fluid.pos[0][i])) == me).then_some(fluid.id[i]))
            .collect();
        compact(fluid, &keep);
        Ok(Self {
            fluid_total: keep.len(),
            lost_total: 0,
            rebalances: 0,
            send: vec![Vec::new(); comm.size()],
            recv: Vec::new(),
            hist,
            halo_out: vec![Vec::new(); comm.size()],
            halo_in: vec![Vec::new(); comm.size()],
            slabs,
            comm,
        })
    }

    pub fn is_root(&self) -> bool {
        self.comm.rank() == 0
    }

    /// Whether this rank owns the column of abscissa `x` (probes and sensors are read by their owner).
    pub fn owns<const D: usize>(&self, grid: &Grid<D>, x: f64) -> bool {
        self.slabs.owner(grid.column(x)) == self.comm.rank()
    }

    /// Moves the cuts so that the ranks hold equal shares of the liquid again, if the largest share is
    /// more than `tolerance` above the mean. Collective.
    fn rebalance<const D: usize>(&mut self, grid: &Grid<D>, fluid: &Fluid<D>, tolerance: f64) {
        let (n, me) = (self.comm.size(), self.comm.rank());
        let mut counts = vec![0.0; n];
        counts[me] = (0..fluid.len()).filter(|&i| fluid.owned(i)).count() as f64;
        self.comm.reduce(&mut counts, Op::Sum);
        let mean = counts.iter().sum::<f64>() / n as f64;
        let max = counts.iter().fold(0.0f64, |m, &c| m.max(c));
        if max <= (1.0 + tolerance) * mean {
            return;
        }
        column_counts(grid, fluid, &mut self.hist);
        self.comm.reduce(&mut self.hist, Op::Sum);
        // The same sums on every rank give the same cuts; they fit, as the first ones did.
        if let Ok(s) = Slabs::balanced(&self.hist, n, self.slabs.halo()) {
            if s != self.slabs {
                self.slabs = s;
                self.rebalances += 1;
            }
        }
    }

    /// Before a force evaluation: drops the halo copies and the particles that left the grid (returned,
    /// counted as lost here), optionally rebalances, sends each particle that crossed into another slab to
    /// its owner and a copy of each particle within reach of a neighbour's slab to that neighbour, sends the
    /// densities of this rank's walls in the neighbours' halos, and takes in what the others sent. The
    /// liquid is left unsorted. Collective.
    pub fn exchange<const D: usize>(
        &mut self,
        grid: &Grid<D>,
        fluid: &mut Fluid<D>,
        walls: Option<&mut Boundary<D>>,
        rebalance: Option<f64>,
    ) -> usize {
        let me = self.comm.rank();
        // Halos go first (only owned particles travel or are copied), and owned particles off the grid.
        let mut lost = 0;
        let kept: Vec<Option<u32>> = (0..fluid.len())
            .map(|i| {
                let id = fluid.id[i];
                if id & HALO != 0 {
                    return None;
                }
                let inside = grid.cell_of(fluid.position(i)) != OUTSIDE;
                lost += usize::from(!inside);
                inside.then_some(id)
            })
            .collect();
        compact(fluid, &kept);
        let mut walls = walls.filter(|w| !w.rho.is_empty());
        if let Some(tolerance) = rebalance {
            let before = self.slabs.clone();
            self.rebalance(grid, fluid, tolerance);
            if let Some(w) = walls.as_deref_mut().filter(|_| self.slabs != before) {
                // Wall densities (now and the previous step's, for Verlet) are kept up to date by their
                // owners only: every rank learns them all.
                let n = w.len();
                let mut rho = vec![0.0; 2 * n];
                for j in 0..n {
                    if before.owner(grid.column(w.x[0][j] as f64)) == me {
                        rho[j] = w.rho[j];
                        rho[n + j] = w.rho0[j];
                    }
                }
                self.comm.reduce(&mut rho, Op::Sum);
                w.rho.copy_from_slice(&rho[..n]);
                w.rho0.copy_from_slice(&rho[n..]);
            }
        }

        let rec = record_len(D);
        for s in &mut self.send {
            s.clear();
            s.push(0.0);
        }
        let mut keep: Vec<Option<u32>> = Vec::with_capacity(fluid.len());
        for i in 0..fluid.len() {
            let id = fluid.id[i];
            let col = grid.column(fluid.pos[0][i]);
            let owner = self.slabs.owner(col);
            let mut here = None;
            if owner == me {
                here = Some(id);
            } else {
                push_record(&mut self.send[owner], fluid, i, id);
            }
            for r in self.slabs.halo_of(owner, col).into_iter().flatten() {
                if r == me {
                    here = Some(id | HALO);
                } else {
                    push_record(&mut self.send[r], fluid, i, id | HALO);
                }
            }
            keep.push(here);
        }
        compact(fluid, &keep);
        for s in &mut self.send {
            s[0] = ((s.len() - 1) / rec) as f64;
        }
        self.pack_walls(grid, walls.as_deref());
        self.comm.all_to_all(&self.send, &mut self.recv);
        for msg in &self.recv {
            let Some((&n, body)) = msg.split_first() else {
                continue;
            };
            let (records, pairs) = body.split_at(n as usize * rec);
            for r in records.chunks_exact(rec) {
                pull_record(fluid, r);
            }
            if let Some(w) = walls.as_deref_mut() {
                unpack_walls(w, pairs);
            }
        }
        lost
    }

    /// After an exchange and the sort that follows it: which particles go to which neighbour's halo, and
    /// where the halo copies from each neighbour are, for [`Domain::refresh`].
    pub fn index_halos<const D: usize>(&mut self, grid: &Grid<D>, fluid: &Fluid<D>) {
        let me = self.comm.rank();
        self.halo_out.iter_mut().for_each(Vec::clear);
        self.halo_in.iter_mut().for_each(Vec::clear);
        for i in 0..fluid.len() {
            let col = grid.column(fluid.pos[0][i]);
            if fluid.owned(i) {
                for r in self.slabs.halo_of(me, col).into_iter().flatten() {
                    self.halo_out[r].push(i as u32);
                }
            } else {
                self.halo_in[self.slabs.owner(col)].push(i as u32);
            }
        }
        let key = |&i: &u32| fluid.id[i as usize] & !HALO;
        for l in self.halo_out.iter_mut().chain(self.halo_in.iter_mut()) {
            l.sort_unstable_by_key(key);
        }
    }

    /// Between exchanges (the middle of a step): the halo copies take their owners' new positions,
    /// velocities and densities, in place (the particles keep their cells until the next sort, as in one
    /// process), and the halo walls their owners' densities. Collective.
    pub fn refresh<const D: usize>(
        &mut self,
        grid: &Grid<D>,
        fluid: &mut Fluid<D>,
        walls: Option<&mut Boundary<D>>,
    ) {
        let rec = refresh_len(D);
        for (s, out) in self.send.iter_mut().zip(&self.halo_out) {
            s.clear();
            for &i in out {
                let i = i as usize;
                for k in 0..D {
                    s.extend_from_slice(&[fluid.pos[k][i], fluid.vel[k][i]]);
                }
                s.push(fluid.rho[i]);
            }
        }
        let mut walls = walls.filter(|w| !w.rho.is_empty());
        self.pack_walls(grid, walls.as_deref());
        self.comm.all_to_all(&self.send, &mut self.recv);
        for (msg, into) in self.recv.iter().zip(&self.halo_in) {
            let (records, pairs) = msg.split_at(into.len() * rec);
            for (r, &i) in records.chunks_exact(rec).zip(into) {
                let i = i as usize;
                for k in 0..D {
                    fluid.pos[k][i] = r[2 * k];
                    fluid.vel[k][i] = r[2 * k + 1];
                }
                fluid.rho[i] = r[2 * D];
            }
            if let Some(w) = walls.as_deref_mut() {
                unpack_walls(w, pairs);
            }
        }
    }

    /// Brings a per-particle quantity of the halo copies up to date from their owners: `get` appends a
    /// particle's `width` values, `set` takes them. Collective.
    pub fn sync_halo<T>(
        &mut self,
        field: &mut [T],
        width: usize,
        get: fn(&T, &mut Vec<f64>),
        set: fn(&mut T, &[f64]),
    ) {
        for (s, out) in self.send.iter_mut().zip(&self.halo_out) {
            s.clear();
            for &i in out {
                get(&field[i as usize], s);
            }
        }
        self.comm.all_to_all(&self.send, &mut self.recv);
        for (msg, into) in self.recv.iter().zip(&self.halo_in) {
            for (r, &i) in msg.chunks_exact(width).zip(into) {
                set(&mut field[i as usize], r);
            }
        }
    }

    /// Appends to each neighbour's message the densities of this rank's wall particles in its halo (wall
    /// particles are the same, in the same order, on every rank).
    fn pack_walls<const D: usize>(&mut self, grid: &Grid<D>, walls: Option<&Boundary<D>>) {
        let me = self.comm.rank();
        let Some(w) = walls else {
            return;
        };
        for j in 0..w.len() {
            let col = grid.column(w.x[0][j] as f64);
            if self.slabs.owner(col) == me {
                for r in self.slabs.halo_of(me, col).into_iter().flatten() {
                    self.send[r].extend_from_slice(&[j as f64, w.rho[j]]);
                }
            }
        }
    }

    /// Sums this rank's owned liquid and lost particles over all ranks (after an exchange). Collective.
    pub fn count<const D: usize>(&mut self, fluid: &Fluid<D>, lost_here: usize) {
        let mut v = [
            (0..fluid.len()).filter(|&i| fluid.owned(i)).count() as f64,
            lost_here as f64,
        ];
        self.comm.reduce(&mut v, Op::Sum);
        self.fluid_total = v[0] as usize;
        self.lost_total = v[1] as usize;
    }

    /// Everyone's `v` on rank 0, in rank order (empty elsewhere). Collective.
    pub fn gather(&self, v: Vec<f64>) -> Vec<Vec<f64>> {
        let mut send = vec![Vec::new(); self.comm.size()];
        send[0] = v;
        let mut recv = Vec::new();
        self.comm.all_to_all(&send, &mut recv);
        if self.is_root() {
            recv
        } else {
            Vec::new()
        }
    }
}

impl<const D: usize> super::Ranks<D> for Domain {
    fn total(&self) -> usize {
        self.fluid_total
    }
    fn sync_scalar(&mut self, k: &mut [f32]) {
        self.sync_halo(k, 1, |k, s| s.push(*k as f64), |k, r| *k = r[0] as f32);
    }
    fn sync_vector(&mut self, v: &mut [[f32; D]]) {
        self.sync_halo(
            v,
            D,
            |v, s| s.extend(v.iter().map(|&x| x as f64)),
            |v, r| *v = std::array::from_fn(|d| r[d] as f32),
        );
    }
    fn reduce(&mut self, v: &mut [f64], op: Op) {
        self.comm.reduce(v, op);
    }
}
