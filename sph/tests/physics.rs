//! Physics checks of the solver against analytic results and published experiments (numbers quoted from the
//! papers, no data files): hydrostatics, the first sloshing mode, the dam-break front, the frame terms of a
//! moving tank, and determinism across thread counts. Cases are coarse so the suite stays quick.
// Component loops over the const-generic dimension read as the formulas do; `!(x >= 0.0)` is used on purpose
// to catch NaN along with negatives.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

use sph::kernel::{KernelGradient, KernelKind};
use sph::motion::{AtRest, Dof6, Dof6Motion, RegularDof, RegularMotion, TankMotion, Uniform};
use sph::params::*;
use sph::Solver;

mod common;
use common::{probe, tank2d, G};

/// Runs to `t_end`, averaging observations taken every `every` seconds after `t_avg`.
fn run_and_average(
    sim: &mut dyn Solver,
    motion: &dyn TankMotion,
    t_avg: f64,
    t_end: f64,
    every: f64,
) -> sph::observe::Observation {
    let mut sum = sph::observe::Observation::default();
    let mut n = 0.0;
    let mut t = t_avg;
    while t <= t_end + 1e-9 {
        sim.advance_to(motion, t).unwrap();
        let o = sim.observe(motion).unwrap();
        if n == 0.0 {
            sum = o.clone();
        } else {
            for (a, b) in sum.probes.iter_mut().zip(&o.probes) {
                *a += b;
            }
            for (a, b) in sum.pressures.iter_mut().zip(&o.pressures) {
                *a += b;
            }
            for k in 0..3 {
                sum.wrench.force[k] += o.wrench.force[k];
                sum.wrench.moment[k] += o.wrench.moment[k];
            }
        }
        n += 1.0;
        t += every;
    }
    sum.probes.iter_mut().for_each(|v| *v /= n);
    sum.pressures.iter_mut().for_each(|v| *v /= n);
    sum.wrench.force.iter_mut().for_each(|v| *v /= n);
    sum.wrench.moment.iter_mut().for_each(|v| *v /= n);
    sum
}

fn check_hydrostatics(p: SimParams, t_end: f64) {
    check_hydrostatics_within(p, t_end, 0.25, 0.05)
}

/// As [`check_hydrostatics`], probes within `probe_tol` particle spacings of the fill height and sensors
/// within the fraction `sensor_tol` of ρ g (h − z).
fn check_hydrostatics_within(p: SimParams, t_end: f64, probe_tol: f64, sensor_tol: f64) {
    let fill = p.fill.height;
    let rho = p.fluid.density;
    let mut sim = sph::build(p.clone()).unwrap();
    let weight = sim.liquid_mass() * G;
    if p.solver.scheme == Scheme::Wcsph {
        // The weakly-compressible scheme starts hydrostatic, walls included: its first force is about the
        // weight (within 3 %: the mirror boundary and the 3D Wendland case read 2.9 % high and 2.8 % low
        // before the first step), straight down (with the +x wall's outer layers started without pressure,
        // fx was 1.3 % of the weight).
        let f = sim.observe(&AtRest).unwrap().wrench.force;
        assert!(
            (f[2] + weight).abs() < 0.03 * weight,
            "initial fz {} vs weight {weight}",
            f[2]
        );
        assert!(
            f[0].abs() < 0.002 * weight,
            "initial horizontal force {}",
            f[0]
        );
    }
    let o = run_and_average(sim.as_mut(), &AtRest, 0.6 * t_end, t_end, 0.02);
    let dp = p.particle_spacing;
    eprintln!(
        "at rest ({:?}, {}D): probes {:?} m (fill {fill}), sensors {:?} Pa",
        p.solver.scheme, p.dimension, o.probes, o.pressures
    );
    for (v, s) in o.probes.iter().zip(&p.probes) {
        assert!(
            (v - fill).abs() < probe_tol * dp,
            "probe {} reads {v}, fill {fill}",
            s.name
        );
    }
    let fz = o.wrench.force[2];
    assert!(
        (fz + weight).abs() < 0.01 * weight,
        "vertical force {fz} vs weight {weight}"
    );
    assert!(
        o.wrench.force[0].abs() < 0.005 * weight,
        "horizontal force {}",
        o.wrench.force[0]
    );
    assert!(
        o.wrench.force[1].abs() < 0.005 * weight,
        "transverse force {}",
        o.wrench.force[1]
    );
    // Liquid centred in the tank: the weight's moment about the origin vanishes.
    let arm = o.wrench.moment[1].abs() / weight;
    assert!(arm < 0.01 * p.tank.length, "moment arm {arm} m");
    for (v, s) in o.pressures.iter().zip(&p.pressure_sensors) {
        let expect = rho * G * (fill - s.z);
        assert!(
            (v - expect).abs() < sensor_tol * expect,
            "sensor {} reads {v} Pa, hydrostatic {expect} Pa",
            s.name
        );
    }
    assert_eq!(sim.counts().lost, 0);
}

fn sensors() -> Vec<SensorSpec> {
    vec![
        SensorSpec {
            name: "left_0.1".into(),
            x: -0.4,
            y: 0.0,
            z: 0.1,
        },
        SensorSpec {
            name: "right_0.2".into(),
            x: 0.4,
            y: 0.0,
            z: 0.2,
        },
    ]
}

/// The 2D tank filled 0.39 m at 20 mm with `walls`, probes by the wall, in the middle and 50 mm off it, and
/// the two wall sensors.
fn tank_at_rest(walls: BoundaryMethod) -> SimParams {
    let mut p = tank2d(0.8, 0.6, 0.39, 0.02);
    p.solver.boundary.method = walls;
    p.probes = vec![
        probe("wall", -0.376),
        probe("mid", 0.0),
        probe("p350", -0.05),
    ];
    p.pressure_sensors = sensors();
    p
}

#[test]
fn tank_at_rest_is_hydrostatic_with_dynamic_boundaries() {
    check_hydrostatics(tank_at_rest(BoundaryMethod::Dynamic), 1.0);
}

#[test]
fn tank_at_rest_is_hydrostatic_with_mirror_boundaries() {
    let mut p = tank2d(0.8, 0.6, 0.39, 0.02);
    p.solver.boundary.method = BoundaryMethod::Mirror;
    p.probes = vec![probe("wall", -0.376), probe("mid", 0.0)];
    p.pressure_sensors = sensors();
    check_hydrostatics(p, 1.0);
}

#[test]
fn tank_at_rest_is_hydrostatic_with_mdbc_walls() {
    check_hydrostatics(tank_at_rest(BoundaryMethod::Mdbc), 1.0);
}

/// Mean distance (in spacings) of the liquid's outermost row from the floor and of its outermost columns
/// from the end walls, over the particles within `band` spacings of each.
fn wall_gaps(sim: &dyn Solver, band: f64) -> [f64; 3] {
    let p = sim.params();
    let dp = p.particle_spacing;
    let (lo, hi) = p.tank.inside();
    let x = sim.fluid_positions();
    let gap = |d: &dyn Fn(&[f64; 3]) -> f64| {
        let near: Vec<f64> = x.iter().map(d).filter(|&g| g < band * dp).collect();
        near.iter().sum::<f64>() / near.len() as f64 / dp
    };
    [
        gap(&|x| x[2] - lo[2]),
        gap(&|x| x[0] - lo[0]),
        gap(&|x| hi[0] - x[0]),
    ]
}

#[test]
fn mdbc_walls_hold_the_liquid_at_rest_half_a_spacing_off_their_faces() {
    // A liquid particle stands for the cell around it: at rest its centre is half a spacing from a wall face.
    // The walls' layers continue the liquid's lattice normal to each face and carry the pressure extrapolated
    // from the liquid (with the layers themselves at half the spacing, the liquid's bottom row settled 0.32
    // spacings above the floor).
    let mut p = tank2d(0.4, 0.6, 0.39, 0.01);
    p.solver.boundary.method = BoundaryMethod::Mdbc;
    p.probes = vec![];
    let mut sim = sph::build(p).unwrap();
    sim.advance_to(&AtRest, 0.5).unwrap();
    let g = wall_gaps(sim.as_ref(), 1.0);
    eprintln!(
        "the outermost row {:.3} dp above the floor, columns {:.3} and {:.3} dp off the end walls",
        g[0], g[1], g[2]
    );
    assert!(g.iter().all(|g| (g - 0.5).abs() < 0.05), "{g:?}");
}

/// A small 3D tank with the Wendland kernel, probes in a corner and the middle, a wall sensor 2.5 dp up.
fn tank3d_wendland() -> SimParams {
    let mut p = tank2d(0.4, 0.3, 0.15, 0.02);
    p.dimension = 3;
    p.tank.breadth = 0.2;
    p.solver.kernel = KernelKind::Wendland;
    p.probes = vec![
        ProbeSpec {
            name: "corner".into(),
            x: -0.17,
            y: 0.07,
        },
        probe("mid", 0.0),
    ];
    p.pressure_sensors = vec![SensorSpec {
        name: "left".into(),
        x: -0.2,
        y: 0.0,
        z: 0.05,
    }];
    p
}

#[test]
fn tank_at_rest_is_hydrostatic_in_3d_with_the_wendland_kernel() {
    check_hydrostatics(tank3d_wendland(), 0.5);
}

/// Period of a signal from its upward zero crossings (interpolated), after removing its mean.
fn period(t: &[f64], y: &[f64]) -> f64 {
    let mean = y.iter().sum::<f64>() / y.len() as f64;
    let mut crossings = vec![];
    for i in 1..y.len() {
        let (a, b) = (y[i - 1] - mean, y[i] - mean);
        if a < 0.0 && b >= 0.0 {
            crossings.push(t[i - 1] + (t[i] - t[i - 1]) * (-a) / (b - a));
        }
    }
    assert!(crossings.len() >= 3, "too few crossings: {crossings:?}");
    (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64
}

/// Free decay of the first mode from its velocity field at zero elevation (linear potential flow):
/// phi = B cos(k x') cosh(k z) with x' from the left wall, B = a w / (k sinh(k h)); 1 m tank, 0.25 m deep
/// (kh = π/4), a = 1 cm. `setup` chooses the scheme and walls. Returns the simulation, the observation
/// times, the elevation near the left wall and Fx over 3.3 periods, the largest elevation, the linear
/// period and a.
#[allow(clippy::type_complexity)]
fn first_mode(
    setup: impl FnOnce(&mut SimParams),
) -> (Box<dyn Solver>, Vec<f64>, Vec<f64>, Vec<f64>, f64, f64, f64) {
    let (l, h, a) = (1.0, 0.25, 0.01);
    let mut p = tank2d(l, 0.6, h, 0.02);
    p.probes = vec![probe("left", -0.45)];
    setup(&mut p);
    let k = std::f64::consts::PI / l;
    let w = (G * k * (k * h).tanh()).sqrt();
    let b = a * w / (k * (k * h).sinh());
    let mut sim = sph::build(p).unwrap();
    sim.set_fluid_velocity(&|x: [f64; 3]| {
        let xs = x[0] + l / 2.0;
        [
            -b * k * (k * xs).sin() * (k * x[2]).cosh(),
            0.0,
            b * k * (k * xs).cos() * (k * x[2]).sinh(),
        ]
    });
    let (mut ts, mut eta, mut fx) = (vec![], vec![], vec![]);
    let mut amp: f64 = 0.0;
    for i in 1..=((3.3 * 2.0 * std::f64::consts::PI / w) / 0.01) as usize {
        sim.advance_to(&AtRest, i as f64 * 0.01).unwrap();
        let o = sim.observe(&AtRest).unwrap();
        ts.push(o.time);
        eta.push(o.probes[0]);
        fx.push(o.wrench.force[0]);
        amp = amp.max((o.probes[0] - h).abs());
    }
    (sim, ts, eta, fx, amp, 2.0 * std::f64::consts::PI / w, a)
}

#[test]
fn first_sloshing_mode_has_the_linear_frequency() {
    // Mirror (free-slip) walls, as linear theory assumes inviscid flow.
    let (_, ts, eta, fx, amp, expect, a) = first_mode(|p| {
        p.solver.sound_speed_coefficient = 10.0;
        p.solver.boundary.method = BoundaryMethod::Mirror;
    });
    let t_probe = period(&ts, &eta);
    let t_force = period(&ts, &fx);
    assert!(
        (t_probe - expect).abs() < 0.02 * expect,
        "probe period {t_probe} s, linear theory {expect} s"
    );
    assert!(
        (t_force - expect).abs() < 0.02 * expect,
        "force period {t_force} s, linear theory {expect} s"
    );
    // The mode was excited with the intended amplitude (near the wall cos(k x') ≈ 0.99).
    assert!(amp > 0.6 * a && amp < 1.4 * a, "amplitude {amp}");
}

/// Martin & Moyce (1952), square-based column n² = 2: T = t sqrt(2g/a), front Z/a (Phil. Trans. A 244, Fig. 3).
const MARTIN_MOYCE: [(f64, f64); 4] = [(1.22, 1.47), (2.00, 2.29), (2.55, 3.00), (3.35, 4.13)];

/// The dam-break case: a 0.2 m wide, 0.4 m high column against the left wall of a 1.2 m tank, dp = 5 mm.
fn dam_break() -> SimParams {
    let a = 0.2;
    let mut p = tank2d(1.2, 0.6, 2.0 * a, 0.005);
    p.fill.length = a;
    p
}

/// Runs the dam break `p` and checks its front against Martin & Moyce; returns the simulation.
fn check_dam_break(p: SimParams) -> Box<dyn Solver> {
    let a = p.fill.length;
    let scheme = p.solver.scheme;
    let mut sim = sph::build(p).unwrap();
    let n0 = sim.counts().fluid;
    let left = -0.6;
    for (t_star, z_expect) in MARTIN_MOYCE {
        let t = t_star / (2.0 * G / a).sqrt();
        sim.advance_to(&AtRest, t).unwrap();
        let front = sim
            .fluid_positions()
            .iter()
            .map(|x| x[0])
            .fold(f64::MIN, f64::max)
            - left;
        let z = front / a;
        eprintln!("{scheme:?} T = {t_star}: front Z/a = {z:.3}, Martin & Moyce {z_expect}");
        // Never slower than the experiment, never faster than inviscid shallow water (Ritter: Z/a = 1 + 2T).
        assert!(
            z > 0.97 * z_expect && z < 1.0 + 2.0 * t_star,
            "T = {t_star}: front Z/a = {z:.3}, Martin & Moyce {z_expect}"
        );
        // The surge front leads the experiment early on (its gate took time to lift; 16 % at T = 1.22 here),
        // and agrees within 10 % once the surge is established.
        if t_star > 3.0 {
            assert!(
                (z - z_expect).abs() < 0.10 * z_expect,
                "T = {t_star}: front Z/a = {z:.3}, Martin & Moyce {z_expect}"
            );
        }
    }
    assert_eq!(sim.counts().fluid, n0, "particles lost");
    sim
}

#[test]
fn dam_break_front_follows_martin_and_moyce() {
    let mut p = dam_break();
    p.solver.kernel = KernelKind::Wendland;
    p.solver.smoothing_ratio = 2f64.sqrt();
    p.solver.integrator = Integrator::Verlet;
    p.solver.sound_speed_coefficient = 20.0;
    p.solver.boundary.layers = 1;
    p.solver.artificial_viscosity.boundary_factor = 1.0;
    check_dam_break(p);
}

/// Smoothly ramped constant acceleration along x: a(t) = a0 r(t) with a half-cosine ramp over `ramp` s.
struct Accelerating {
    a0: f64,
    ramp: f64,
}

impl Dof6Motion for Accelerating {
    fn dof(&self, t: f64) -> Dof6 {
        let mut d = Dof6::default();
        let r = if t >= self.ramp {
            1.0
        } else {
            0.5 * (1.0 - (std::f64::consts::PI * t / self.ramp).cos())
        };
        // Position and velocity do not enter the tank-frame equations; only the acceleration does.
        d.ddq[0] = self.a0 * r;
        d
    }
}

/// The seed tank accelerated at 1 m/s² along x: the surface tilts to the apparent gravity and the liquid
/// pushes back with m a0.
fn check_accelerating(p: SimParams) {
    let a0 = 1.0;
    let mut p = p;
    p.probes = vec![probe("left", -0.3), probe("right", 0.3)];
    let mut sim = sph::build(p).unwrap();
    let mass = sim.liquid_mass();
    let m = Accelerating { a0, ramp: 3.0 };
    let o = run_and_average(sim.as_mut(), &m, 4.0, 5.0, 0.01);
    // Free surface perpendicular to the apparent gravity (−a0, −g): slope a0/g, higher at the rear (−x).
    let slope = (o.probes[0] - o.probes[1]) / 0.6;
    assert!(
        (slope - a0 / G).abs() < 0.1 * a0 / G,
        "slope {slope}, expected {}",
        a0 / G
    );
    // The tank pushes the liquid forward with m a0; the liquid pushes back on the tank.
    assert!(
        (o.wrench.force[0] + mass * a0).abs() < 0.05 * mass * a0,
        "fx {} vs {}",
        o.wrench.force[0],
        -mass * a0
    );
    assert!((o.wrench.force[2] + mass * G).abs() < 0.01 * mass * G);
}

#[test]
fn accelerating_tank_tilts_the_surface_and_pushes_back() {
    check_accelerating(tank2d(0.8, 0.6, 0.39, 0.02));
}

#[test]
fn tank_moving_at_constant_velocity_far_away_behaves_as_at_rest() {
    let mut p = tank2d(0.8, 0.6, 0.19, 0.02);
    p.probes = vec![probe("a", -0.375), probe("b", 0.2)];
    p.pressure_sensors = vec![SensorSpec {
        name: "s".into(),
        x: -0.4,
        y: 0.0,
        z: 0.05,
    }];
    // A first sloshing motion so that there is something to compare.
    let slosh = RegularMotion {
        dofs: [
            RegularDof {
                amplitude: 0.01,
                period: 1.2,
                phase: 0.0,
            },
            RegularDof::default(),
            RegularDof::default(),
            RegularDof::default(),
            RegularDof::default(),
            RegularDof::default(),
        ],
        ramp: 0.5,
    };
    // The same relative motion seen from a vessel 5 km out, sailing at 6 m/s on a steady heading.
    struct Far<'a>(&'a RegularMotion);
    impl Dof6Motion for Far<'_> {
        fn dof(&self, t: f64) -> Dof6 {
            let mut d = self.0.dof(t);
            let u = Uniform {
                start: [5000.0, -3000.0, 0.0, 0.0, 0.0, 0.0],
                velocity: [6.0, 0.0, 0.0, 0.0, 0.0, 0.0],
                acceleration: [0.0; 6],
            }
            .dof(t);
            for i in 0..6 {
                d.q[i] += u.q[i];
                d.dq[i] += u.dq[i];
            }
            d
        }
    }
    for scheme in [Scheme::Wcsph, Scheme::Dfsph] {
        let mut p = p.clone();
        p.solver.scheme = scheme;
        far_equals_near(p, &slosh, &Far(&slosh));
    }
}

fn far_equals_near(p: SimParams, slosh: &dyn TankMotion, far_motion: &dyn TankMotion) {
    let mut near = sph::build(p.clone()).unwrap();
    let mut far = sph::build(p).unwrap();
    let fill = near.observe(slosh).unwrap().probes[0];
    // How far probe 0 moved from its level at rest, at most, over the samples.
    let mut moved = 0.0f64;
    for i in 1..=10 {
        let t = i as f64 * 0.1;
        near.advance_to(slosh, t).unwrap();
        far.advance_to(far_motion, t).unwrap();
        let (a, b) = (
            near.observe(slosh).unwrap(),
            far.observe(far_motion).unwrap(),
        );
        assert_eq!(a.time, b.time);
        moved = moved.max((a.probes[0] - fill).abs());
        for (x, y) in a
            .probes
            .iter()
            .zip(&b.probes)
            .chain(a.pressures.iter().zip(&b.pressures))
        {
            assert!((x - y).abs() <= 1e-9 * x.abs().max(1.0), "{x} vs {y}");
        }
        for k in 0..3 {
            assert!(
                (a.wrench.force[k] - b.wrench.force[k]).abs()
                    <= 1e-9 * a.wrench.force[k].abs().max(1.0)
            );
        }
    }
    eprintln!("far equals near: probe 0 moved up to {moved:.4} m");
    // And the run did slosh: the probe moved (at some sample; any one may be a crossing of the level).
    assert!(moved > 2e-3, "no sloshing: probe 0 moved {moved} m at most");
}

#[test]
fn one_thread_and_two_threads_give_identical_results() {
    let mut p = tank2d(0.8, 0.6, 0.3, 0.02);
    p.probes = vec![probe("a", -0.375)];
    let m = RegularMotion {
        dofs: [
            RegularDof {
                amplitude: 0.02,
                period: 1.0,
                phase: 0.0,
            },
            RegularDof::default(),
            RegularDof::default(),
            RegularDof::default(),
            RegularDof {
                amplitude: 0.05,
                period: 1.3,
                phase: 0.0,
            },
            RegularDof::default(),
        ],
        ramp: 0.2,
    };
    let run = |threads: usize, p: SimParams| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let mut s = sph::build(p).unwrap();
            s.advance_to(&m, 0.4).unwrap();
            (s.fluid_positions(), s.observe(&m).unwrap())
        })
    };
    for (scheme, method) in [
        (Scheme::Wcsph, BoundaryMethod::Dynamic),
        (Scheme::Wcsph, BoundaryMethod::Mirror),
        (Scheme::Wcsph, BoundaryMethod::Mdbc),
        (Scheme::Dfsph, BoundaryMethod::Dynamic),
    ] {
        let mut q = p.clone();
        q.solver.scheme = scheme;
        q.solver.boundary.method = method;
        let (x1, o1) = run(1, q.clone());
        let (x2, o2) = run(2, q);
        assert_eq!(x1, x2, "{scheme:?} {method:?}: positions differ");
        assert_eq!(o1, o2, "{scheme:?} {method:?}: observations differ");
    }
}

// The divergence-free (incompressible) scheme on the same checks. Its walls are the dynamic boundary's
// particle layers; with no wall viscosity (boundary_factor 0) they are free-slip, as linear theory assumes.

fn dfsph(mut p: SimParams) -> SimParams {
    p.solver.scheme = Scheme::Dfsph;
    p
}

/// The pressure solver reached the tolerance it holds for the liquid on every step.
fn assert_converged(sim: &dyn Solver) {
    let s = sim.stats();
    let tol = sim.params().density_tolerance();
    assert_eq!(s.unconverged_steps, 0, "steps above the density tolerance");
    assert!(
        s.max_density_error <= tol,
        "density error {} above {tol}",
        s.max_density_error
    );
    assert!(s.solver_iterations >= 2 * s.steps, "{s:?}");
}

#[test]
fn dfsph_tank_at_rest_is_hydrostatic_and_the_solver_converges_every_step() {
    let mut p = dfsph(tank2d(0.8, 0.6, 0.39, 0.02));
    p.probes = vec![
        probe("wall", -0.376),
        probe("mid", 0.0),
        probe("p350", -0.05),
    ];
    // On the wall faces (read from the liquid's force on the wall particles) and inside the liquid.
    p.pressure_sensors = sensors();
    p.pressure_sensors.push(SensorSpec {
        name: "inside_0.05".into(),
        x: 0.0,
        y: 0.0,
        z: 0.05,
    });
    // The bottom and wall rows sit closer to the wall particles than with WCSPH (walls push with k_i alone):
    // the surface reads up to 0.35 dp low (a known gap; 0.21 dp with the relaxed iterations).
    check_hydrostatics_within(p.clone(), 1.0, 0.4, 0.05);
    let mut sim = sph::build(p).unwrap();
    sim.advance_to(&AtRest, 0.5).unwrap();
    assert_converged(sim.as_ref());
    // The time step follows the flow, not the speed of sound: at rest it is the largest allowed.
    let s = sim.stats();
    assert!(s.steps < 200, "{} steps for 0.5 s", s.steps);
}

#[test]
fn dfsph_tank_at_rest_is_hydrostatic_in_3d_with_the_wendland_kernel() {
    // The wall sensor 2.5 dp above the floor reads 2.9 % low here (5.6 % with the unrelaxed iterations; 5 % is
    // the WCSPH bar).
    check_hydrostatics_within(dfsph(tank3d_wendland()), 0.5, 0.4, 0.08);
}

/// Mean height of the liquid particles, m.
fn mean_height(sim: &dyn Solver) -> f64 {
    let x = sim.fluid_positions();
    x.iter().map(|x| x[2]).sum::<f64>() / x.len() as f64
}

/// Mean and largest liquid speed (m/s) of `p` at rest over its last `tail` s of `t_end`, and how far the
/// liquid's mean particle height rose by `t_end` (m).
fn speeds_at_rest(p: SimParams, t_end: f64, tail: f64) -> (f64, f64, f64) {
    let mut sim = sph::build(p).unwrap();
    let z0 = mean_height(sim.as_ref());
    let (mut mean, mut max, mut n) = (0.0f64, 0.0f64, 0.0);
    let mut t = t_end - tail;
    while t <= t_end + 1e-9 {
        sim.advance_to(&AtRest, t).unwrap();
        let v = sim.fluid_velocities();
        let s: Vec<f64> = v
            .iter()
            .map(|v| v.iter().map(|x| x * x).sum::<f64>().sqrt())
            .collect();
        mean += s.iter().sum::<f64>() / s.len() as f64;
        max = s.iter().copied().fold(max, f64::max);
        n += 1.0;
        t += 0.1;
    }
    (mean / n, max, mean_height(sim.as_ref()) - z0)
}

#[test]
fn dfsph_tank_at_rest_stays_still_in_3d_whatever_the_step() {
    // With the cubic spline at h = 1.3 dp (81 neighbours in 3D) unrelaxed Jacobi iterations (relaxation 1)
    // amplify the pressure's particle-to-particle modes: this tank stirred itself to a mean speed of
    // 0.05 m/s (largest 0.2-0.5 m/s), 0.14 m/s at 2.5 ms steps (the seed tank's liquid rose 17 % at 2.5 ms
    // steps, as the particles spread).
    let mut p = dfsph(tank2d(0.3, 0.3, 0.2, 0.02));
    p.dimension = 3;
    p.tank.breadth = 0.2;
    // The liquid settles from its lattice within ~2 s; then it is still (here 0.005 m/s at 5 ms steps).
    for dt_max in [0.005, 0.0025, 0.0015] {
        p.solver.dfsph.dt_max = dt_max;
        let (mean, max, rise) = speeds_at_rest(p.clone(), 3.0, 0.5);
        eprintln!(
            "dt_max {dt_max}: mean speed {mean:.4} m/s, largest {max:.3} m/s, liquid risen {:.2} dp",
            rise / p.particle_spacing
        );
        assert!(
            mean < 0.015,
            "dt_max {dt_max}: mean speed {mean} m/s at rest"
        );
        assert!(
            max < 0.15,
            "dt_max {dt_max}: a particle at {max} m/s at rest"
        );
        // Nor does it spread (the seed tank's paired liquid rose 9 % at 1.5 ms steps; this shallower one
        // settles by 0.2 dp at every step).
        assert!(
            rise.abs() < 0.5 * p.particle_spacing,
            "dt_max {dt_max}: the liquid's mean height moved by {rise} m at rest"
        );
    }
}

/// Share of the liquid particles whose nearest neighbour is closer than half a spacing (brute force).
fn paired_share(sim: &dyn Solver) -> f64 {
    let x = sim.fluid_positions();
    let near = (0.5 * sim.params().particle_spacing).powi(2);
    let paired = x
        .iter()
        .enumerate()
        .filter(|&(a, xa)| {
            x.iter().enumerate().any(|(b, xb)| {
                b != a && (0..3).map(|k| (xa[k] - xb[k]).powi(2)).sum::<f64>() < near
            })
        })
        .count();
    paired as f64 / x.len() as f64
}

#[test]
fn dfsph_liquid_at_rest_keeps_its_particles_apart() {
    // With the cubic spline's exact gradient (|dW/dr| → 0 as two particles meet) the incompressible
    // scheme's liquid pairs up, at rest too: here 62 % (2D) and 57 % (3D) of the particles within 2 s
    // (the seed tank at dp 20 mm in 3D: 72 % after 3 s, and at 1.5 ms steps its liquid rose 9 %). The
    // Thomas & Couchman gradient, the scheme's default, keeps them apart (0.5 % and 0.9 % here).
    let mut p2 = dfsph(tank2d(0.4, 0.3, 0.2, 0.01));
    p2.solver.dfsph.dt_max = 0.0025;
    let mut p3 = dfsph(tank2d(0.3, 0.3, 0.2, 0.02));
    p3.dimension = 3;
    p3.tank.breadth = 0.2;
    p3.solver.dfsph.dt_max = 0.0025;
    for p in [p2, p3] {
        for gradient in [None, Some(KernelGradient::Exact)] {
            let mut p = p.clone();
            p.solver.kernel_gradient = gradient;
            let mut sim = sph::build(p.clone()).unwrap();
            sim.advance_to(&AtRest, 2.0).unwrap();
            let share = paired_share(sim.as_ref());
            eprintln!(
                "{}D, gradient {:?}: {share:.3} of the particles closer than dp/2 to another",
                p.dimension,
                p.solver.kernel_gradient()
            );
            if gradient.is_none() {
                assert!(
                    share < 0.05,
                    "{}D: {share} of the particles paired",
                    p.dimension
                );
            } else {
                // The check sees pairing where there is some.
                assert!(
                    share > 0.3,
                    "{}D exact gradient: only {share} paired",
                    p.dimension
                );
            }
        }
    }
}

#[test]
fn dfsph_first_sloshing_mode_has_the_linear_frequency() {
    // At 1 cm (25 particles deep): at the 2 cm of the WCSPH test the 1 cm wave is half a particle high, and
    // rounding-level changes to the solver moved the probe's period by 1.2 % (+1.7 % → +2.95 %); at 1 cm the
    // same two builds agree within 0.1 % (probe) and 0.8 % (force).
    let (sim, ts, eta, fx, amp, expect, a) = first_mode(|p| {
        p.solver.scheme = Scheme::Dfsph;
        p.particle_spacing = 0.01;
    });
    // The wall force carries the solver's step-to-step pressure noise: its period is read from the 0.3 s
    // running mean.
    let smooth: Vec<f64> = (0..fx.len())
        .map(|i| {
            let w = &fx[i.saturating_sub(15)..(i + 15).min(fx.len())];
            w.iter().sum::<f64>() / w.len() as f64
        })
        .collect();
    let (t_probe, t_force) = (period(&ts, &eta), period(&ts, &smooth));
    eprintln!("dfsph first mode: probe {t_probe} s, force {t_force} s, theory {expect} s, amplitude {amp}");
    // The noise: what the running mean leaves, against the running mean itself (both rms). Half the last
    // pressure as the warm start made it 0.54 (2.5 N against 4.6 N); carrying its hydrostatic part whole
    // (`sph::scheme::warm_start`), 0.24; with the relaxed iterations (`relaxation` 0.7, 1e-4), 0.17. (Most of it alternates from step to step: outputs that average an
    // odd number of steps show more of it. Here the steps reach `dt_max`, two per output, with either warm
    // start; forced to 3–4 ms steps both read 0.6–1.2, at 2 ms 0.5 (hydrostatic) and 7 (half).)
    let rms = |v: &mut dyn Iterator<Item = f64>| {
        let (s, n) = v.fold((0.0, 0), |(s, n), x| (s + x * x, n + 1));
        (s / n as f64).sqrt()
    };
    let noise = rms(&mut fx.iter().zip(&smooth).map(|(f, m)| f - m));
    let signal = rms(&mut smooth.iter().copied());
    eprintln!(
        "dfsph first mode: wall force noise rms {noise:.2} N, running mean rms {signal:.2} N"
    );
    assert!(
        noise < 0.35 * signal,
        "wall force noise {noise} N rms against {signal} N of the running mean"
    );
    // The periods come out 1.2 % (probe) and 2.7 % (force) short: a known gap (WCSPH: within 2 %). Held
    // within 3 % and 6 % here so that it does not get worse unnoticed.
    assert!(
        (t_probe - expect).abs() < 0.03 * expect,
        "probe period {t_probe} s, linear theory {expect} s"
    );
    assert!(
        (t_force - expect).abs() < 0.06 * expect,
        "force period {t_force} s, linear theory {expect} s"
    );
    assert!(amp > 0.6 * a && amp < 1.4 * a, "amplitude {amp}");
    assert_converged(sim.as_ref());
}

#[test]
fn dfsph_dam_break_front_follows_martin_and_moyce() {
    let mut p = dfsph(dam_break());
    p.solver.artificial_viscosity.boundary_factor = 1.0;
    let sim = check_dam_break(p);
    eprintln!("dfsph dam break: {:?}", sim.stats());
    assert_eq!(sim.stats().unconverged_steps, 0);
}

/// A liquid 119 particle spacings deep, released from rest, carries its weight on the walls over its first
/// 80 ms (within 5 %: the column's start-up oscillation averages out over the window): the solver's
/// tolerance falls with the depth squared (`DfsphSpec::density_tolerance`). At a fixed 1e-4 the walls of
/// this tank carry 81 % of the weight over the same window, and a tank of the seed tank's length blows up.
#[test]
fn dfsph_deep_liquid_released_from_rest_carries_its_weight() {
    let p = dfsph(tank2d(0.2, 0.6, 0.19, 0.0016));
    let layers = p.fill.height / p.particle_spacing;
    assert!(layers > 118.0, "{layers} layers");
    assert!(p.density_tolerance() < 0.2 * p.solver.dfsph.max_density_error);
    let mut sim = sph::build(p).unwrap();
    let weight = sim.liquid_mass() * G;
    let o = run_and_average(sim.as_mut(), &AtRest, 0.02, 0.08, 0.01);
    let fz = -o.wrench.force[2];
    eprintln!(
        "deep: walls carry {fz:.1} N of {weight:.1} N, {:?}",
        sim.stats()
    );
    assert!(
        (fz - weight).abs() < 0.05 * weight,
        "walls carry {fz:.1} N of the liquid's {weight:.1} N"
    );
    assert_eq!(sim.counts().lost, 0, "particles left the tank");
}

#[test]
fn dfsph_accelerating_tank_tilts_the_surface_and_pushes_back() {
    check_accelerating(dfsph(tank2d(0.8, 0.6, 0.39, 0.02)));
}

/// A snapshot holds every particle (liquid first) with the hydrostatic pressure of a tank at rest, and
/// taking one changes nothing: a run that snapshots every step stays bit-identical to one that does not.
#[test]
fn snapshots_hold_every_particle_with_hydrostatic_pressure_and_change_nothing() {
    for scheme in [Scheme::Wcsph, Scheme::Dfsph] {
        let mut p = tank2d(0.4, 0.3, 0.15, 0.01);
        p.solver.scheme = scheme;
        p.solver.boundary.method = BoundaryMethod::Dynamic;
        let mut a = sph::build(p.clone()).unwrap();
        let mut b = sph::build(p).unwrap();
        a.advance_to(&AtRest, 0.2).unwrap();
        while b.time() < a.time() - 1e-12 {
            let _ = b.snapshot();
            b.step(&AtRest).unwrap();
        }
        assert_eq!(a.fluid_positions(), b.fluid_positions(), "{scheme:?}");
        assert_eq!(a.fluid_velocities(), b.fluid_velocities(), "{scheme:?}");
        let s = b.snapshot();
        let c = b.counts();
        assert_eq!((s.fluid, s.len()), (c.fluid, c.fluid + c.boundary));
        assert_eq!(s.time, b.time());
        assert!(s.position[..s.fluid]
            .iter()
            .zip(b.fluid_positions())
            .all(|(x, y)| (0..3).all(|k| x[k] == y[k] as f32)));
        // Liquid pressure against ρ g (fill − z): particle by particle below the surface rows (the
        // weakly-compressible scheme), and on average over the liquid (the incompressible scheme, whose
        // per-particle pressures are the solver's multipliers: noisy, and high in the bottom row).
        let bottom = 1000.0 * G * 0.15;
        let (mut worst, mut sum, mut want_sum): (f64, f64, f64) = (0.0, 0.0, 0.0);
        for i in 0..s.fluid {
            let z = s.position[i][2] as f64;
            let want = 1000.0 * G * (0.15 - z);
            sum += s.pressure[i] as f64;
            want_sum += want;
            if z < 0.1 {
                worst = worst.max((s.pressure[i] as f64 - want).abs() / bottom);
            }
        }
        let mean = sum / want_sum;
        if scheme == Scheme::Wcsph {
            assert!(worst < 0.03, "pressure off by {worst:.3} of ρgH");
        }
        assert!(
            (mean - 1.0).abs() < 0.15,
            "{scheme:?}: mean pressure {mean:.3} of hydrostatic"
        );
        assert!(s.density[..s.fluid]
            .iter()
            .all(|r| (980.0..1020.0).contains(r)));
    }
}

/// The iteration control shortens steps whose solve works too hard and solves a step that does not converge
/// again at half the step, so that every step ends below the density tolerance; without it, a tight
/// iteration cap leaves steps above the tolerance.
#[test]
fn dfsph_iteration_control_keeps_every_step_converged() {
    let run = |target: u32| {
        let mut p = dfsph(dam_break());
        p.solver.dfsph.max_iterations = 12;
        p.solver.dfsph.target_iterations = target;
        p.solver.dfsph.dt_max = 0.004;
        let mut sim = sph::build(p).unwrap();
        sim.advance_to(&AtRest, 0.4).unwrap();
        sim.stats()
    };
    let free = run(0);
    // (A target of a third of the cap: at 6, half of it, the steps the control shortened were barely
    // cheaper once the warm start carried 0.6 of the last non-hydrostatic pressure instead of half: 4.25
    // iterations a step against 4.12 without the control, as retried steps count their failed tries.)
    let controlled = run(4);
    eprintln!("uncontrolled {free:?}\ncontrolled {controlled:?}");
    assert!(free.unconverged_steps > 0, "{free:?}");
    assert_eq!(free.retried_steps, 0);
    assert_eq!(controlled.unconverged_steps, 0, "{controlled:?}");
    assert!(controlled.retried_steps > 0, "{controlled:?}");
    // Shorter steps where the solver works hard: more of them, each cheaper.
    assert!(controlled.steps > free.steps);
    assert!(
        (controlled.solver_iterations as f64 / controlled.steps as f64)
            < (free.solver_iterations as f64 / free.steps as f64)
    );
    assert!(controlled.max_density_error <= sph::params::DfsphSpec::default().max_density_error);
}

#[test]
fn steps_land_on_the_requested_times_without_slivers() {
    // Outputs every 7 ms, not a multiple of either scheme's step: the step before each lands on it, none
    // shorter than half a step (cutting the step that passes it leaves steps of 1e-7 s), and the time is
    // exactly the one asked for.
    for scheme in [Scheme::Wcsph, Scheme::Dfsph] {
        let mut p = tank2d(0.8, 0.6, 0.39, 0.04);
        p.solver.scheme = scheme;
        let mut sim = sph::build(p).unwrap();
        let mut longest: f64 = 0.0;
        for k in 1..=30 {
            let t = k as f64 * 0.007;
            while sim.time() < t {
                longest = longest.max(sim.step_to(&AtRest, t).unwrap());
            }
            assert_eq!(sim.time(), t, "{scheme:?}: output {k}");
        }
        let shortest = sim.stats().min_dt;
        assert!(
            shortest >= 0.3 * longest,
            "{scheme:?}: shortest step {shortest} s against {longest} s"
        );
    }
}

/// A block fixed to the floor in the middle of a 2D tank at rest (`obstacles`), with each scheme: the liquid
/// starts outside it and stays out, its surface is level on either side and above it at the height its mass
/// stands at (the block displaces exactly the liquid left out), and the tank, block included, carries the liquid's
/// weight straight down; sensors on the block's sides and top read the hydrostatic pressure there. The
/// block's size is no multiple of the spacing: its particles are the tank's wall lattice points inside it, its
/// faces as built half a spacing beyond them (0.0515 → 0.05, 0.083 → 0.08), which the liquid and the sensors
/// given on the faces as asked go by.
#[test]
fn an_obstacle_on_the_floor_holds_the_liquid_at_rest_and_carries_its_weight() {
    let (dp, fill) = (0.01, 0.15);
    let block = sph::params::RegionSpec {
        name: "block".into(),
        centre: [0.0, 0.0, 0.0415],
        size: [0.103, 0.25, 0.083],
    };
    for scheme in [Scheme::Wcsph, Scheme::Dfsph] {
        let mut p = tank2d(0.4, 0.3, fill, dp);
        p.solver.scheme = scheme;
        p.solver.boundary.method = BoundaryMethod::Dynamic;
        p.obstacles = vec![block.clone()];
        p.probes = vec![
            probe("left", -0.15),
            probe("over", 0.0),
            probe("right", 0.15),
        ];
        // Pressure sensors on the block's faces (its two sides and its top) and on the tank wall beside it.
        let sensor = |name: &str, x: f64, z: f64| SensorSpec {
            name: name.into(),
            x,
            y: 0.0,
            z,
        };
        p.pressure_sensors = vec![
            sensor("block_left", -0.0515, 0.03),
            sensor("block_right", 0.0515, 0.05),
            sensor("block_top", 0.02, 0.083),
            sensor("wall", -0.2, 0.04),
        ];
        let mut sim = sph::build(p.clone()).unwrap();
        let built = sph::tank::obstacle_as_built::<2>(&p, &block);
        assert!(
            (built.size[0] - 0.1).abs() < 1e-9 && (built.size[2] - 0.08).abs() < 1e-9,
            "the block as built: {built:?}"
        );
        // Liquid mass: the fill block less the block's section as built, over the tank's breadth (here the
        // liquid's lattice is the tank's: exactly, to the particle mass's f32 rounding).
        let (w, hb) = (built.size[0], built.size[2]);
        let want = 1000.0 * (0.4 * fill - w * hb) * p.tank.breadth;
        let slack = 1e-6 * want;
        let mass = sim.liquid_mass();
        assert!(
            (mass - want).abs() <= slack,
            "{scheme:?}: liquid mass {mass} kg, fill less the block {want} (within {slack})"
        );
        // The level that mass stands at once the liquid has closed up to the block.
        let level = (mass / (1000.0 * p.tank.breadth) + w * hb) / 0.4;
        let inside = |sim: &dyn Solver| {
            sim.fluid_positions()
                .iter()
                .filter(|x| x[0].abs() < 0.5 * w - 0.5 * dp && x[2] < hb - 0.5 * dp)
                .count()
        };
        assert_eq!(
            inside(sim.as_ref()),
            0,
            "{scheme:?}: liquid inside the block at the start"
        );
        let o = run_and_average(sim.as_mut(), &AtRest, 0.6, 1.0, 0.02);
        eprintln!(
            "obstacle at rest ({scheme:?}): probes {:?} m (level {level}), sensors {:?} Pa, force {:?} N, weight {} N",
            o.probes,
            o.pressures,
            o.wrench.force,
            mass * G
        );
        assert_eq!(
            inside(sim.as_ref()),
            0,
            "{scheme:?}: liquid got into the block"
        );
        for (v, s) in o.probes.iter().zip(&p.probes) {
            assert!(
                (v - level).abs() < 0.5 * dp,
                "{scheme:?}: probe {} reads {v}, level {level}",
                s.name
            );
        }
        for (v, s) in o.pressures.iter().zip(&p.pressure_sensors) {
            // The top's sensor reads the top as built. WCSPH's Shepard mean on a face reads the pressure
            // ~0.65 h into the liquid: on the top, ρ g 0.65 h (9 %) low; on the sides the depth is the same.
            let top = s.name == "block_top";
            let z = if top { hb } else { s.z };
            let expect = 1000.0 * G * (level - z);
            let tol = if top && scheme == Scheme::Wcsph {
                0.12
            } else {
                0.05
            };
            assert!(
                (v - expect).abs() < tol * expect,
                "{scheme:?}: sensor {} reads {v} Pa, hydrostatic {expect} Pa",
                s.name
            );
        }
        let weight = mass * G;
        assert!(
            (o.wrench.force[2] + weight).abs() < 0.01 * weight,
            "{scheme:?}: vertical force {} vs weight {weight}",
            o.wrench.force[2]
        );
        assert!(
            o.wrench.force[0].abs() < 0.005 * weight,
            "{scheme:?}: horizontal force {}",
            o.wrench.force[0]
        );
        assert_eq!(sim.counts().lost, 0);
    }
}

/// Obstacles that would not work are refused by name: thinner than the kernel support, reaching outside the
/// tank, or with mirror walls (they are made of wall particles); so is a pressure sensor buried in one.
#[test]
fn obstacles_that_would_not_work_are_refused_by_name() {
    let base = sph::params::RegionSpec {
        name: "block".into(),
        centre: [0.0, 0.0, 0.04],
        size: [0.1, 0.25, 0.08],
    };
    let refused = |o: sph::params::RegionSpec, method: BoundaryMethod| {
        let mut p = tank2d(0.4, 0.3, 0.15, 0.01);
        p.solver.boundary.method = method;
        p.obstacles = vec![o];
        sph::build(p).err().expect("refused").to_string()
    };
    let mut thin = base.clone();
    thin.size[0] = 0.01;
    let e = refused(thin, BoundaryMethod::Dynamic);
    assert!(
        e.contains("obstacles.block.size") && e.contains("kernel support"),
        "{e}"
    );
    let mut out = base.clone();
    out.centre[2] = 0.0;
    let e = refused(out, BoundaryMethod::Dynamic);
    assert!(
        e.contains("obstacles.block.centre") && e.contains("outside the tank"),
        "{e}"
    );
    // A pressure sensor inside the block (deeper than half a spacing from its faces).
    let mut p = tank2d(0.4, 0.3, 0.15, 0.01);
    p.solver.boundary.method = BoundaryMethod::Dynamic;
    p.obstacles = vec![base.clone()];
    p.pressure_sensors = vec![SensorSpec {
        name: "buried".into(),
        x: -0.04,
        y: 0.0,
        z: 0.03,
    }];
    let e = sph::build(p.clone()).err().expect("refused").to_string();
    assert!(
        e.contains("pressure_sensors")
            && e.contains("buried")
            && e.contains("inside obstacle `block`"),
        "{e}"
    );
    // On its face (within half a spacing) it is taken.
    p.pressure_sensors[0].x = -0.046;
    sph::build(p).expect("a sensor on the block's face");
    let e = refused(base, BoundaryMethod::Mirror);
    assert!(
        e.contains("obstacles.block") && e.contains("method: dynamic"),
        "{e}"
    );
}
