//! The domain decomposition without MPI: ranks as threads of this process (`domain::threads`), against one
//! process. Particles, probes and sensors must come out bit for bit the same, the wrench up to the order
//! of its sums, for both schemes and both boundary methods, while the liquid sloshes across the cuts.

use sph::domain::threads::Threads;
use sph::kernel::CubicSpline;
use sph::motion::{RegularDof, RegularMotion};
use sph::observe::Observation;
use sph::params::*;
use sph::Simulation;
use std::sync::Arc;

mod common;
use common::{probe, tank2d};

fn case(scheme: Scheme, method: BoundaryMethod) -> SimParams {
    let mut p = tank2d(0.8, 0.6, 0.25, 0.02);
    p.solver.scheme = scheme;
    p.solver.boundary.method = method;
    p.probes = [-0.375, -0.1, 0.0, 0.2]
        .iter()
        .enumerate()
        .map(|(i, &x)| probe(&format!("p{i}"), x))
        .collect();
    p.pressure_sensors = [(-0.4, 0.1), (0.0, 0.0), (0.4, 0.05)]
        .iter()
        .enumerate()
        .map(|(i, &(x, z))| SensorSpec {
            name: format!("s{i}"),
            x,
            y: 0.0,
            z,
        })
        .collect();
    p
}

fn motion() -> RegularMotion {
    let dof = |amplitude, period| RegularDof {
        amplitude,
        period,
        phase: 0.0,
    };
    RegularMotion {
        dofs: [
            dof(0.03, 1.0),
            RegularDof::default(),
            RegularDof::default(),
            RegularDof::default(),
            dof(0.05, 1.3),
            RegularDof::default(),
        ],
        ramp: 0.2,
    }
}

/// The final liquid: (id, position) in the order of the ids.
type Liquid = Vec<(u32, [f32; 3])>;

/// Observations every 0.1 s to 0.8 s, the final liquid and the rebalances, on `ranks` threads (0: one
/// process without a decomposition); each rank on a one-thread rayon pool of its own.
fn run(p: &SimParams, ranks: usize) -> (Vec<Observation>, Liquid, u64) {
    let go = |comm: Option<Threads>| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .unwrap();
        pool.install(|| {
            let m = motion();
            let comm = comm.map(|c| Arc::new(c) as Arc<dyn sph::domain::Comm>);
            let mut sim = Simulation::<2, CubicSpline>::new_in(p.clone(), comm).unwrap();
            let mut obs = Vec::new();
            for k in 1..=8 {
                sim.advance_to(&m, 0.1 * k as f64).unwrap();
                obs.push(sim.observe(&m).unwrap());
            }
            let s = sim.snapshot();
            let liquid: Liquid = (0..s.fluid).map(|i| (s.id[i], s.position[i])).collect();
            (obs, liquid, sim.rebalances())
        })
    };
    if ranks == 0 {
        let (o, mut l, r) = go(None);
        l.sort_by_key(|x| x.0);
        return (o, l, r);
    }
    std::thread::scope(|s| {
        let handles: Vec<_> = Threads::world(ranks)
            .into_iter()
            .map(|c| s.spawn(|| go(Some(c))))
            .collect();
        let mut results: Vec<_> = handles.into_iter().map(|h| h.join().unwrap()).collect();
        results.swap_remove(0)
    })
}

#[test]
fn ranks_as_threads_reproduce_one_process() {
    for (scheme, method, obstacle, corrected) in [
        (Scheme::Wcsph, BoundaryMethod::Dynamic, false, false),
        (Scheme::Wcsph, BoundaryMethod::Mirror, false, false),
        (Scheme::Dfsph, BoundaryMethod::Dynamic, false, false),
        // The corrected kernel gradients: halo copies take their owners' correction.
        (Scheme::Dfsph, BoundaryMethod::Dynamic, false, true),
        // A block fixed to the floor across the middle cut: its wall particles on every rank.
        (Scheme::Dfsph, BoundaryMethod::Dynamic, true, false),
    ] {
        let mut p = case(scheme, method);
        p.solver.dfsph.kernel_correction = corrected;
        if obstacle {
            p.obstacles = vec![sph::params::RegionSpec {
                name: "block".into(),
                centre: [0.05, 0.0, 0.05],
                size: [0.1, 0.25, 0.1],
            }];
        }
        let (o1, l1, _) = run(&p, 0);
        assert!(l1.len() > 400);
        // The liquid must move across the cuts for this to test anything.
        let swing = o1.iter().map(|o| o.probes[0]).fold(f64::MIN, f64::max)
            - o1.iter().map(|o| o.probes[0]).fold(f64::MAX, f64::min);
        assert!(
            swing > 0.02,
            "{scheme:?}: the probe at the wall moved {swing} m"
        );
        for ranks in [2, 3] {
            let (o, l, rebalances) = run(&p, ranks);
            let what = format!(
                "{scheme:?} {method:?} (obstacle: {obstacle}, corrected: {corrected}) on {ranks} ranks"
            );
            assert_eq!(l, l1, "{what}: the liquid differs");
            assert_eq!(o.len(), o1.len());
            for (a, b) in o.iter().zip(&o1) {
                assert_eq!(a.time, b.time, "{what}");
                assert_eq!(a.probes, b.probes, "{what} at t = {}", a.time);
                let tol = |x: f64| 1e-9 * (1.0 + x.abs());
                for (x, y) in a.pressures.iter().zip(&b.pressures) {
                    assert!((x - y).abs() <= tol(*y), "{what}: sensor {x} vs {y}");
                }
                let (fa, fb) = (&a.wrench, &b.wrench);
                for k in 0..3 {
                    assert!(
                        (fa.force[k] - fb.force[k]).abs() <= tol(fb.force[k]),
                        "{what}"
                    );
                    assert!(
                        (fa.moment[k] - fb.moment[k]).abs() <= tol(fb.moment[k]),
                        "{what}"
                    );
                }
            }
            if ranks == 3 && scheme == Scheme::Wcsph {
                assert!(
                    rebalances > 0,
                    "{what}: the slabs never followed the liquid"
                );
            }
        }
    }
}
