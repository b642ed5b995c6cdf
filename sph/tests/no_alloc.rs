//! "No allocation inside a step": a global allocator that counts every allocation of the process (rayon's
//! threads included) around the system one, and a sloshing tank stepped with each scheme once its buffers
//! have settled. One test function only, so that no other test of this binary allocates meanwhile.

use sph::motion::{RegularDof, RegularMotion};
use sph::params::*;
use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicUsize, Ordering};

mod common;
use common::{probe, tank2d};

static ALLOCATIONS: AtomicUsize = AtomicUsize::new(0);

struct Counting;

// SAFETY: forwards every call to the system allocator unchanged; the counter has no effect on memory.
unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        ALLOCATIONS.fetch_add(1, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
}

#[global_allocator]
static COUNTING: Counting = Counting;

/// The seed tank (0.8 m, 0.39 m fill) at dp 2 cm, with a probe by the left wall; in 3D a 10 cm slice of
/// it.
fn seed_tank(scheme: Scheme, dimension: usize) -> SimParams {
    let mut p = tank2d(0.8, 0.6, 0.39, 0.02);
    p.solver.scheme = scheme;
    if dimension == 3 {
        p.dimension = 3;
        p.tank.breadth = 0.1;
    }
    p.probes = vec![probe("wall", -0.37)];
    p
}

#[test]
fn steps_allocate_nothing_once_the_buffers_have_settled() {
    let sway = |amplitude, period| RegularDof {
        amplitude,
        period,
        phase: 0.0,
    };
    let motion = RegularMotion {
        dofs: [
            sway(0.02, 1.2),
            RegularDof::default(),
            RegularDof::default(),
            RegularDof::default(),
            sway(3f64.to_radians(), 1.5),
            RegularDof::default(),
        ],
        ramp: 0.5,
    };
    // In 3D too: more chunks, each meeting runs of cells of its own (and the incompressible scheme keeps
    // its 3D neighbour lists and velocities in four lanes); and the mDBC walls, read from the liquid at
    // every evaluation.
    for (scheme, walls, dimension) in [
        (Scheme::Wcsph, BoundaryMethod::Dynamic, 2),
        (Scheme::Wcsph, BoundaryMethod::Dynamic, 3),
        (Scheme::Wcsph, BoundaryMethod::Mdbc, 2),
        (Scheme::Dfsph, BoundaryMethod::Dynamic, 2),
        (Scheme::Dfsph, BoundaryMethod::Dynamic, 3),
    ] {
        let mut p = seed_tank(scheme, dimension);
        p.solver.boundary.method = walls;
        let mut sim = sph::build(p).unwrap();
        // Buffers grow to the largest neighbourhood seen: let the flow get going first.
        for _ in 0..300 {
            sim.step(&motion).unwrap();
        }
        let steps = 300;
        let mut allocations = 0;
        // Stepped from inside rayon's pool, as `advance_to` does: entering the pool from outside (what a bare
        // `step` does) allocates a block of rayon's queue every 63 entries, which is rayon's, not the
        // solver's.
        rayon::scope(|_| {
            for window in 0..3 {
                let before = ALLOCATIONS.load(Ordering::Relaxed);
                for _ in 0..steps {
                    sim.step(&motion).unwrap();
                }
                allocations += ALLOCATIONS.load(Ordering::Relaxed) - before;
                eprintln!(
                    "{scheme:?} {walls:?} {dimension}D: {allocations} allocations in {} steps, t = {:.3} s",
                    (window + 1) * steps,
                    sim.time()
                );
            }
        });
        assert_eq!(
            allocations, 0,
            "{scheme:?} {walls:?} {dimension}D: {allocations} allocations"
        );
    }
}
