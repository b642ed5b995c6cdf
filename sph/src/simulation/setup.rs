//! The start of a simulation: the liquid at rest in its lattice with hydrostatic pressure, the wall layers,
//! the floating bodies and obstacles, the neighbour grid, and the decomposition over ranks.

use super::{flooded_volumes, Simulation};
use crate::body::{piston, shell, RigidBody};
use crate::boundary::dynamic;
use crate::domain::{Comm, Domain, Processes};
use crate::eos::Tait;
use crate::error::SimError;
use crate::kernel::Kernel;
use crate::neighbours::Grid;
use crate::observe::probes::Shell;
use crate::observe::wall_pressure;
use crate::params::{BoundaryMethod, Scheme, SimParams};
use crate::particles::{Boundary, Fluid, SortScratch};
use crate::scheme::dfsph::Dfsph;
use crate::scheme::wcsph::{Coefficients, Wcsph};
use crate::scheme::{PassTotals, PressureScheme, State, Stats};
use crate::tank::{fluid_lattice, wall_lattice, TankBox};
use crate::vector::{from3, to3};
use std::sync::Arc;

impl<const D: usize, K: Kernel> Simulation<D, K> {
    pub fn new(params: SimParams) -> Result<Self, SimError> {
        Self::new_in(params, None)
    }

    /// This rank's part of the simulation decomposed over `comm`'s ranks (see [`crate::domain`]); serial
    /// without `comm` or with a single rank.
    pub fn new_in(params: SimParams, comm: Option<Arc<dyn Comm>>) -> Result<Self, SimError> {
        params.validate()?;
        assert_eq!(params.dimension, D, "dimension mismatch");
        let dp = params.particle_spacing;
        let h = params.h();
        let c0 = params.sound_speed();
        let rho0 = params.fluid.density;
        let eos = Tait::new(rho0, c0);
        let kernel = K::new(D, h as f32).with_gradient(params.solver.kernel_gradient());
        let tank = TankBox::<D>::new(&params);
        let layers = params.wall_layers();
        let support = kernel.support() as f64;

        // Grid over the tank, its wall layers and one kernel support beyond.
        let shell_layers = layers.max((support / dp).ceil() as u32 + 1);
        let margin = shell_layers as f64 * dp + support;
        let lo: [f64; D] = std::array::from_fn(|k| tank.lo[k] - margin);
        let hi: [f64; D] = std::array::from_fn(|k| tank.hi[k] + margin);
        let grid = Grid::new(lo, hi, 0.5 * support);

        // Liquid at rest with hydrostatic pressure below its own top.
        let (mut points, volume) = fluid_lattice::<D>(&params);
        // Floating bodies start where their box and half a spacing around it hold no liquid (liquid exactly
        // half a spacing off a face stays: one spacing from the body's outer particles, as at a wall).
        let mut bodies = crate::body::Bodies::default();
        let mut body_points: Vec<Vec<[f64; 3]>> = Vec::new();
        for spec in &params.bodies {
            let pts = shell::wall_points(spec, D, dp);
            points.retain(|x| {
                let x = to3(*x);
                let b = std::array::from_fn(|k| x[k] - spec.position[k]);
                !shell::covers(spec, D, b, 0.499 * dp)
            });
            bodies.list.push(RigidBody::new(spec, D, &pts));
            body_points.push(
                pts.iter()
                    .map(|p| std::array::from_fn(|k| p[k] + spec.position[k]))
                    .collect(),
            );
        }
        // A wave maker's plate at the −x end, the liquid in front of it.
        if let (Some(wm), Some((thickness, face))) = (&params.wave_maker, params.wave_maker_plate())
        {
            let n = ((thickness / dp).round() as usize).max(2);
            let pts = piston::plate_points(face, n, params.tank.height, params.tank.breadth, D, dp);
            points.retain(|x| x[0] > face + 0.499 * dp);
            bodies.list.push(RigidBody::driven("wave_maker", wm, &pts));
            body_points.push(pts);
        }
        // Fixed obstacles, as their particles make them: the liquid starts where they and half a spacing
        // around them hold none (one spacing from their outer particles, as at a wall).
        let built: Vec<crate::params::RegionSpec> = params
            .obstacles
            .iter()
            .map(|o| crate::tank::obstacle_as_built::<D>(&params, o))
            .collect();
        points.retain(|x| !built.iter().any(|o| o.within(*x, 0.499 * dp)));
        let (g, top) = (params.gravity, params.fill.height);
        // (A liquid block against the −x wall: walls beyond its end start without pressure. A tank filled
        // end to end: every wall layer, the +x wall's outer ones too, starts hydrostatic; were those beyond
        // its face to start at ρ0, the liquid's first force on the tank would lean 1.3 % of its weight
        // towards −x.)
        let fill_x1 = if params.fill_length() < params.tank.length {
            tank.lo[0] + params.fill_length()
        } else {
            f64::INFINITY
        };
        let hydro = move |x: [f64; D]| -> f64 {
            let z = x[D - 1];
            if x[0] <= fill_x1 + 0.5 * dp {
                eos.density(rho0 * g * (top - z.min(top)))
            } else {
                rho0
            }
        };
        let mut fluid = Fluid::new(&points, hydro);
        let m_fluid = rho0 * volume;

        let refine = match params.solver.boundary.method {
            BoundaryMethod::Mdbc => crate::boundary::mdbc::REFINE,
            BoundaryMethod::Dynamic | BoundaryMethod::Mirror => 1,
        };
        let (mut wall_pts, wall_volume) = wall_lattice::<D>(&params, layers, refine);
        wall_pts.extend(crate::tank::obstacle_lattice::<D>(&params));
        let mut scratch = SortScratch::default();
        let mut bound = match params.solver.boundary.method {
            BoundaryMethod::Dynamic | BoundaryMethod::Mdbc => {
                dynamic::build(&wall_pts, hydro, &eos)
            }
            BoundaryMethod::Mirror => Boundary::default(),
        };
        for (b, pts) in body_points.iter().enumerate() {
            for (i, p) in pts.iter().enumerate() {
                let x: [f64; D] = from3(*p);
                let rho = hydro(x).max(rho0);
                bound.push(x, [0.0; D], rho, eos.pressure(rho as f32));
                *bound.tag.last_mut().expect("just pushed") = bodies.which.len() as u32;
                bodies.which.push((b as u32, i as u32));
            }
        }
        if bound.sort(&grid, &mut scratch) > 0 && !bodies.is_empty() {
            return Err(SimError::BodyLeftTank {
                name: bodies.list[0].name.clone(),
                time: 0.0,
            });
        }
        bodies.reindex(&bound);
        let (shell_pts, shell_volume) = wall_lattice::<D>(&params, shell_layers, 1);
        let mut shell = Shell {
            points: dynamic::build(&shell_pts, |_| rho0, &eos),
            volume: shell_volume as f32,
        };
        shell.points.sort(&grid, &mut scratch);
        let rho_rest = {
            let m_bound = (rho0 * wall_volume) as f32;
            // Not a particle by a body or the wave maker's plate, whose neighbourhood may be cut short (a
            // hole, a corner) where the middle of the liquid falls.
            let near_body = |x: [f64; D]| {
                let x = to3(x);
                params.bodies.iter().any(|b| {
                    let p = std::array::from_fn(|k| x[k] - b.position[k]);
                    shell::covers(b, D, p, support)
                }) || built.iter().any(|o| o.within::<3>(x, support))
                    || params.wave_maker_plate().is_some_and(|(_, face)| {
                        x[0] < face + support + params.wave_maker.as_ref().map_or(0.0, |w| w.stroke)
                    })
            };
            rest_density(&kernel, &fluid, &bound, m_fluid as f32, m_bound, near_body) as f32
        };
        let processes = match comm.filter(|c| c.size() > 1) {
            None => Processes::One,
            Some(_) if params.solver.boundary.method == BoundaryMethod::Mdbc => {
                return Err(SimError::Decomposition(
                    "solver.boundary.method: mdbc runs in one process; across MPI ranks use `dynamic` or `mirror`".into(),
                ));
            }
            Some(c) => {
                // Mirror ghosts are rebuilt from where particles are mid-step, which may be a column
                // beyond where they were sorted: one more halo column brings their sources.
                let halo = match params.solver.boundary.method {
                    BoundaryMethod::Mirror => crate::neighbours::REACH + 1,
                    BoundaryMethod::Dynamic | BoundaryMethod::Mdbc => crate::neighbours::REACH,
                };
                Processes::Many(
                    Domain::split(c, &grid, &mut fluid, halo).map_err(SimError::Decomposition)?,
                )
            }
        };
        fluid.sort(&grid, &mut scratch);

        let s = &params.solver;
        let coef = Coefficients {
            h: h as f32,
            support2: (support * support) as f32,
            m_fluid: m_fluid as f32,
            m_bound: (rho0 * wall_volume) as f32,
            rho0: rho0 as f32,
            c0: c0 as f32,
            alpha: s.artificial_viscosity.alpha as f32,
            beta: s.artificial_viscosity.beta as f32,
            alpha_bound: (s.artificial_viscosity.alpha * s.artificial_viscosity.boundary_factor)
                as f32,
            beta_bound: (s.artificial_viscosity.beta * s.artificial_viscosity.boundary_factor)
                as f32,
            eta2: (s.artificial_viscosity.eta_factor * h * h) as f32,
            diffusion: s.density_diffusion.kind,
            delta_h_c0: (s.density_diffusion.delta * h * c0) as f32,
            nu4: if s.laminar_viscosity {
                (4.0 * params.fluid.kinematic_viscosity) as f32
            } else {
                0.0
            },
        };
        let dt_min = if s.dt_min > 0.0 {
            s.dt_min
        } else {
            1e-4 * s.cfl * h / c0
        };
        let spacing = crate::tank::wall_spacing::<D>(&params);
        let spots = params
            .pressure_sensors
            .iter()
            .map(|s| {
                let at: [f64; D] = from3([s.x, s.y, s.z]);
                let obstacles = (params.obstacles.as_slice(), built.as_slice());
                wall_pressure::FaceSpot::locate(&tank, obstacles, at, 0.5 * dp, spacing, h)
            })
            .collect();
        let mut state = State {
            params,
            kernel,
            coef,
            eos,
            grid,
            tank,
            fluid,
            bound,
            time: 0.0,
            stats: Stats {
                min_dt: f64::INFINITY,
                ..Default::default()
            },
            lost: 0,
            dt_min,
            rest_density: rho_rest,
            last: PassTotals::default(),
            rates_current: false,
            scratch,
            step_limit: f64::INFINITY,
            processes,
            bodies,
        };
        let scheme: Box<dyn PressureScheme<D, K>> = match state.params.solver.scheme {
            Scheme::Wcsph => Box::new(Wcsph::default()),
            Scheme::Dfsph => Box::new(Dfsph::new(&state)),
        };
        if !state.bodies.is_empty() {
            state.bodies.last_flooded = Some((0.0, flooded_volumes(&state)));
        }
        Ok(Self {
            state,
            scheme,
            shell,
            spots,
        })
    }
}

/// The density a liquid particle inside the initial lattice sums to (the incompressible scheme holds it):
/// that of the particle nearest the middle of the liquid block, of those not `excluded`.
fn rest_density<const D: usize, K: Kernel>(
    k: &K,
    fluid: &Fluid<D>,
    bound: &Boundary<D>,
    m_fluid: f32,
    m_bound: f32,
    excluded: impl Fn([f64; D]) -> bool,
) -> f64 {
    let n = fluid.len();
    let centre: [f64; D] =
        std::array::from_fn(|d| fluid.pos[d].iter().sum::<f64>() / n.max(1) as f64);
    let dist2 = |i: usize| {
        (0..D)
            .map(|d| (fluid.pos[d][i] - centre[d]).powi(2))
            .sum::<f64>()
    };
    // (If every particle is excluded, the nearest of all.)
    let Some(a) = (0..n)
        .filter(|&i| !excluded(fluid.position(i)))
        .min_by(|&i, &j| dist2(i).total_cmp(&dist2(j)))
        .or_else(|| (0..n).min_by(|&i, &j| dist2(i).total_cmp(&dist2(j))))
    else {
        return 0.0;
    };
    let xa = fluid.position(a);
    let support = k.support() as f64;
    let sum = |m: f32, count: usize, at: &dyn Fn(usize) -> [f64; D]| {
        (0..count)
            .map(|j| {
                let x = at(j);
                let r = (0..D).map(|d| (x[d] - xa[d]).powi(2)).sum::<f64>().sqrt();
                if r < support {
                    m as f64 * k.w(r as f32) as f64
                } else {
                    0.0
                }
            })
            .sum::<f64>()
    };
    sum(m_fluid, n, &|j| fluid.position(j))
        + sum(m_bound, bound.len(), &|j| {
            std::array::from_fn(|d| bound.x[d][j] as f64)
        })
}
