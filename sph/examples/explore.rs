use sph::motion::AtRest;
use sph::params::*;
use std::time::Instant;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let dp: f64 = args.get(1).map(|s| s.parse().unwrap()).unwrap_or(0.01);
    let method = if args.get(2).map(|s| s == "mirror").unwrap_or(false) {
        BoundaryMethod::Mirror
    } else {
        BoundaryMethod::Dynamic
    };
    let mut solver = SolverSpec::default();
    solver.boundary.method = method;
    solver.sound_speed_coefficient = 10.0;
    let p = SimParams {
        dimension: 2,
        tank: TankSpec {
            length: 0.8,
            breadth: 0.25,
            height: 0.6,
        },
        fill: FillSpec {
            height: 0.39,
            length: 0.0,
        },
        particle_spacing: dp,
        fluid: FluidSpec::default(),
        gravity: 9.81,
        solver,
        probes: vec![
            ProbeSpec {
                name: "a".into(),
                x: -0.376,
                y: 0.0,
            },
            ProbeSpec {
                name: "b".into(),
                x: 0.0,
                y: 0.0,
            },
        ],
        pressure_sensors: vec![SensorSpec {
            name: "s".into(),
            x: -0.4,
            y: 0.0,
            z: 0.1,
        }],
    };
    let mut sim = sph::build(p).unwrap();
    println!("mass {} counts {:?}", sim.liquid_mass(), sim.counts());
    let t0 = Instant::now();
    for i in 1..=10 {
        sim.advance_to(&AtRest, i as f64 * 0.1).unwrap();
        let o = sim.observe(&AtRest).unwrap();
        println!(
            "t {:.3} probes {:?} p {:?} F {:?} M {:?} steps {} dt {:.2e}",
            o.time,
            o.probes,
            o.pressures,
            o.wrench.force,
            o.wrench.moment,
            sim.stats().steps,
            sim.stats().last_dt
        );
    }
    let el = t0.elapsed().as_secs_f64();
    let ps = sim.stats().steps as f64 * sim.counts().fluid as f64;
    println!(
        "wall {el:.2}s  {:.2e} particle-steps/s weight {}",
        ps / el,
        sim.liquid_mass() * 9.81
    );
}
