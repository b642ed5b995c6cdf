//! Rank 0 drives, the other ranks follow: [`Distributed`] broadcasts each call of the [`Solver`] interface
//! to the ranks in [`serve`], so that the program around the solver (files, topics, recordings) runs on rank
//! 0 alone and unchanged.

#[cfg(feature = "mpi")]
pub mod mpi;

use crate::domain::{world, Comm, WORLD};
use crate::motion::{AtRest, TankMotion};
use crate::observe::snapshot::Snapshot;
use crate::observe::Observation;
use crate::params::SimParams;
use crate::simulation::{Counts, Solver, Stats};
use crate::SimError;
use std::sync::Arc;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
#[repr(u8)]
enum Call {
    Build = 1,
    Step,
    AdvanceTo,
    Observe,
    Snapshot,
    Positions,
    Velocities,
    Stop,
}

impl Call {
    fn from(v: f64) -> Option<Self> {
        use Call::*;
        [
            Build, Step, AdvanceTo, Observe, Snapshot, Positions, Velocities, Stop,
        ]
        .into_iter()
        .find(|c| *c as u8 as f64 == v)
    }
}

fn announce(comm: &dyn Comm, call: Call, args: &[f64]) {
    let mut buf = Vec::with_capacity(1 + args.len());
    buf.push(call as u8 as f64);
    buf.extend_from_slice(args);
    comm.broadcast(&mut buf);
}

/// Rank 0's handle on a simulation spread over all ranks: each collective call is announced to the
/// following ranks first. Its outputs are those of a serial run.
pub struct Distributed {
    comm: Arc<dyn Comm>,
    local: Box<dyn Solver>,
}

impl Distributed {
    /// Announces the build to the other ranks (the parameters travel as JSON) and builds rank 0's part.
    pub(crate) fn build(comm: Arc<dyn Comm>, params: SimParams) -> Result<Self, SimError> {
        assert_eq!(comm.rank(), 0, "only rank 0 builds; the others serve");
        let json = serde_json::to_vec(&params).expect("parameters serialise");
        let args: Vec<f64> = json.iter().map(|&b| b as f64).collect();
        announce(&*comm, Call::Build, &args);
        let local = crate::simulation::build_local(params, Some(comm.clone()))?;
        Ok(Self { comm, local })
    }

    fn call(&self, call: Call, args: &[f64]) {
        announce(&*self.comm, call, args);
    }
}

impl Solver for Distributed {
    fn step(&mut self, motion: &dyn TankMotion) -> Result<f64, SimError> {
        self.call(Call::Step, &[]);
        self.local.step(motion)
    }
    fn step_to(&mut self, motion: &dyn TankMotion, limit: f64) -> Result<f64, SimError> {
        // The other ranks take rank 0's limit with its motion's end (broadcast within the step).
        self.call(Call::Step, &[]);
        self.local.step_to(motion, limit)
    }
    fn advance_to(&mut self, motion: &dyn TankMotion, t_end: f64) -> Result<(), SimError> {
        self.call(Call::AdvanceTo, &[t_end]);
        self.local.advance_to(motion, t_end)
    }
    fn observe(&mut self, motion: &dyn TankMotion) -> Result<Observation, SimError> {
        self.call(Call::Observe, &[]);
        self.local.observe(motion)
    }
    fn time(&self) -> f64 {
        self.local.time()
    }
    fn stats(&self) -> Stats {
        self.local.stats()
    }
    fn counts(&self) -> Counts {
        self.local.counts()
    }
    fn params(&self) -> &SimParams {
        self.local.params()
    }
    fn liquid_mass(&self) -> f64 {
        self.local.liquid_mass()
    }
    fn fluid_positions(&self) -> Vec<[f64; 3]> {
        self.call(Call::Positions, &[]);
        self.local.fluid_positions()
    }
    fn fluid_velocities(&self) -> Vec<[f64; 3]> {
        self.call(Call::Velocities, &[]);
        self.local.fluid_velocities()
    }
    fn set_fluid_velocity(&mut self, _f: &dyn Fn([f64; 3]) -> [f64; 3]) {
        panic!("set_fluid_velocity takes a closure, which cannot travel to other ranks: set initial velocities in a serial run");
    }
    fn snapshot(&self) -> Snapshot {
        self.call(Call::Snapshot, &[]);
        self.local.snapshot()
    }
    fn ranks(&self) -> usize {
        self.comm.size()
    }
    fn rebalances(&self) -> u64 {
        self.local.rebalances()
    }
}

/// The loop of a rank other than 0: follows rank 0's calls on its own part of the simulation until rank 0
/// calls [`shutdown`]. Errors are rank 0's to report (every rank meets the same ones, from the same global
/// sums), so they are dropped here.
pub fn serve() {
    let comm = WORLD.get().expect("serve needs install() first").clone();
    assert_ne!(comm.rank(), 0, "rank 0 drives; the others serve");
    let mut sim: Option<Box<dyn Solver>> = None;
    let motion = AtRest;
    loop {
        let mut buf = Vec::new();
        comm.broadcast(&mut buf);
        let call = buf.first().and_then(|&c| Call::from(c));
        match (call, sim.as_mut()) {
            (Some(Call::Build), _) => {
                let json: Vec<u8> = buf[1..].iter().map(|&b| b as u8).collect();
                let params: SimParams =
                    serde_json::from_slice(&json).expect("rank 0 sends valid parameters");
                sim = crate::simulation::build_local(params, Some(comm.clone())).ok();
            }
            (Some(Call::Stop), _) => return,
            (Some(Call::Step), Some(s)) => {
                let _ = s.step(&motion);
            }
            (Some(Call::AdvanceTo), Some(s)) => {
                let _ = s.advance_to(&motion, buf[1]);
            }
            (Some(Call::Observe), Some(s)) => {
                let _ = s.observe(&motion);
            }
            (Some(Call::Snapshot), Some(s)) => {
                let _ = s.snapshot();
            }
            (Some(Call::Positions), Some(s)) => {
                let _ = s.fluid_positions();
            }
            (Some(Call::Velocities), Some(s)) => {
                let _ = s.fluid_velocities();
            }
            (call, s) => panic!(
                "rank {}: unexpected call {call:?} (simulation built: {})",
                comm.rank(),
                s.is_some()
            ),
        }
    }
}

/// Rank 0: releases the serving ranks (at the end of the program, also after an error).
pub fn shutdown() {
    if let Some(comm) = world() {
        if comm.rank() == 0 {
            announce(&**comm, Call::Stop, &[]);
        }
    }
}
