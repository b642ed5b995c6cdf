//! The typed description of a case: tank, liquid, resolution, solver choices and observation points.
//! Plain data with defaults; [`SimParams::validate`] names the offending field of anything unusable.

mod bodies;
mod wave_maker;

pub use bodies::{BodySpec, Dof, RegionSpec, SpringSpec};
pub use wave_maker::PistonSpec;

use crate::kernel::{KernelGradient, KernelKind};
use serde::{Deserialize, Serialize};

/// A closed rectangular tank. Tank frame: origin at the centre of the tank bottom, x along `length`,
/// y along `breadth`, z up. A 2D run simulates the x–z plane and scales forces by `breadth`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TankSpec {
    /// m, along x.
    pub length: f64,
    /// m, along y (the thickness a 2D result stands for).
    pub breadth: f64,
    /// m, along z.
    pub height: f64,
}

impl TankSpec {
    /// The tank's inside in x, y, z (tank frame: origin at the centre of the bottom), lower and upper corner.
    pub fn inside(&self) -> ([f64; 3], [f64; 3]) {
        let (l, b) = (0.5 * self.length, 0.5 * self.breadth);
        ([-l, -b, 0.0], [l, b, self.height])
    }
}

/// Liquid properties.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct FluidSpec {
    /// Reference density ρ0, kg/m³.
    pub density: f64,
    /// Kinematic viscosity ν, m²/s (used when `solver.laminar_viscosity` is on).
    pub kinematic_viscosity: f64,
}

impl Default for FluidSpec {
    fn default() -> Self {
        Self {
            density: 1000.0,
            kinematic_viscosity: 1.0e-6,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Scheme {
    /// Weakly-compressible SPH (the paper's scheme).
    Wcsph,
    /// Divergence-free SPH (Bender & Koschier): incompressible, time step from the flow speed.
    Dfsph,
}

/// Settings of the divergence-free (incompressible) scheme.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DfsphSpec {
    /// Courant number on the particle spacing: dt ≤ cfl · dp / |v|max (and ≤ cfl · sqrt(dp / |a|max)).
    pub cfl: f64,
    /// Largest time step, s.
    pub dt_max: f64,
    /// Mean predicted density error the constant-density solver reaches every step (fraction of ρ0).
    pub max_density_error: f64,
    /// Mean density change per step the divergence solver leaves (fraction of ρ0).
    pub max_divergence_error: f64,
    /// Relaxation ω of both solvers' Jacobi iterations (each moves a particle's k by ω times what would
    /// remove its own error alone). At 1 the iterations amplify the particle-to-particle pressure modes of
    /// the 81-neighbour 3D kernel (h = 1.3 dp): a 3D tank at rest stirs itself to ~0.1 m/s. Unset: 0.5
    /// with `kernel_correction` (whose pressure passes burst into noise at 0.7 in a 0.39 m deep 2D tank),
    /// 0.7 without ([`DfsphSpec::relaxation`]).
    pub relaxation: Option<f64>,
    /// Iterations of the constant-density solver at least, and of either solver at most.
    pub min_iterations: u32,
    pub max_iterations: u32,
    /// Run the divergence solver (more stable at large steps).
    pub divergence_solve: bool,
    /// Pressure iterations a step should need: above it the next step is shorter (× 0.8), below half of it
    /// longer again (× 1.1, up to `dt_max` and the CFL limit). A step whose constant-density solve stops at
    /// `max_iterations` above the tolerance is solved again at half the step. 0 turns both off.
    pub target_iterations: u32,
    /// Share β of the hydrostatic pressure (per column of the liquid, below its highest particle) that the
    /// constant-density solve carries over whole from the last step; of the rest of the last pressure it
    /// carries 0.6 (`sph::scheme::dfsph::warm_start::REST`). 0: half the whole last pressure (Bender & Koschier 2017), as
    /// always with bodies (floating bodies, fixed or not, a wave maker) and with `smoothing_ratio` < 1.
    pub hydrostatic_warm_start: f64,
    /// Correct the kernel gradients of the pressure passes (`sph::scheme::dfsph::gradient_correction`: each
    /// particle's gradients times the inverse of its Σ V (x_b − x_a) ⊗ ∇W, symmetrised over the pair), so
    /// that the liquid's pressure forces do not depend on its particles' arrangement. Without it a small
    /// sloshing wave sees a stiff, lossy lattice: the first mode runs short and dies out tens of times
    /// faster than in a tank (see the manual's sloshing page). Off with bodies (floating bodies, fixed or
    /// not, a wave maker).
    pub kernel_correction: bool,
}

impl DfsphSpec {
    /// The Jacobi relaxation the solver uses: `relaxation`, or by configuration (0.5 where the kernel
    /// gradients are corrected, `corrected`, 0.7 where not).
    pub fn relaxation(&self, corrected: bool) -> f64 {
        self.relaxation.unwrap_or(if corrected { 0.5 } else { 0.7 })
    }
}

impl Default for DfsphSpec {
    fn default() -> Self {
        Self {
            cfl: 0.4,
            dt_max: 0.005,
            max_density_error: 1.0e-4,
            max_divergence_error: 1.0e-3,
            relaxation: None,
            min_iterations: 2,
            max_iterations: 100,
            divergence_solve: true,
            target_iterations: 20,
            hydrostatic_warm_start: 0.95,
            kernel_correction: false,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Integrator {
    /// Two-stage symplectic predictor–corrector (position-Verlet style, two force evaluations a step).
    Symplectic,
    /// Leap-frog Verlet with one force evaluation a step and an Euler step every `verlet_reset_steps`
    /// (as in DualSPHysics).
    Verlet,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DiffusionKind {
    None,
    /// Molteni & Colagrossi (2009).
    MolteniColagrossi,
    /// Fourtakas et al. (2019): diffuses only the dynamic (non-hydrostatic) part of the density.
    Fourtakas,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum BoundaryMethod {
    /// Layers of boundary particles fixed to the tank, density from continuity, pressure from the EOS
    /// (the paper's quasi-ghost particles; Crespo et al. 2007 "dynamic boundary condition").
    Dynamic,
    /// Mirror ("dynamic ghost") particles of the fluid near each wall, with opposite normal velocity and the
    /// paper's anti-penetration restraint.
    Mirror,
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct ArtificialViscosity {
    /// Linear coefficient α of Monaghan's artificial viscosity.
    pub alpha: f64,
    /// Quadratic coefficient β.
    pub beta: f64,
    /// η² = eta_factor · h² regularises 1/r² (the paper: 0.01).
    pub eta_factor: f64,
    /// Multiplies α and β between liquid and wall particles (DualSPHysics' ViscoBoundFactor). At 1 the walls
    /// act as no-slip with the artificial viscosity, which at sloshing resolutions is hundreds of times
    /// water's and over-damps sloshing; 0 (default) leaves wall friction to `solver.laminar_viscosity`.
    pub boundary_factor: f64,
}

impl Default for ArtificialViscosity {
    fn default() -> Self {
        Self {
            alpha: 0.02,
            beta: 0.0,
            eta_factor: 0.01,
            boundary_factor: 0.0,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct DensityDiffusion {
    pub kind: DiffusionKind,
    /// δ coefficient (0.1 is usual).
    pub delta: f64,
}

impl Default for DensityDiffusion {
    fn default() -> Self {
        Self {
            kind: DiffusionKind::Fourtakas,
            delta: 0.1,
        }
    }
}

#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct BoundarySpec {
    pub method: BoundaryMethod,
    /// Number of boundary particle layers of the tank walls (dynamic method); 0 = enough to cover the kernel
    /// support, ceil(2h/dp).
    pub layers: u32,
}

impl Default for BoundarySpec {
    fn default() -> Self {
        Self {
            method: BoundaryMethod::Dynamic,
            layers: 0,
        }
    }
}

/// Solver choices. Defaults follow the paper where it gives a value, DualSPHysics' practice elsewhere.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SolverSpec {
    pub scheme: Scheme,
    pub kernel: KernelKind,
    /// How the cubic spline's gradient is taken ([`KernelGradient`]); unset: the scheme's choice
    /// ([`SolverSpec::kernel_gradient`]).
    pub kernel_gradient: Option<KernelGradient>,
    /// h / particle spacing.
    pub smoothing_ratio: f64,
    pub integrator: Integrator,
    /// Courant number of the CFL condition.
    pub cfl: f64,
    /// c0 = coefficient · sqrt(g · H). The paper's bound κ = 200 g H ρ / γ is a coefficient of √200 ≈ 14.14.
    pub sound_speed_coefficient: f64,
    /// H in the sound speed, m; 0 = the liquid's initial height.
    pub reference_height: f64,
    /// Explicit c0 in m/s; 0 = from the coefficient.
    pub sound_speed: f64,
    pub artificial_viscosity: ArtificialViscosity,
    /// Adds the laminar viscous term of Lo & Shao (2002) with `fluid.kinematic_viscosity`.
    pub laminar_viscosity: bool,
    pub density_diffusion: DensityDiffusion,
    pub boundary: BoundarySpec,
    /// The run fails when the CFL time step falls below this, s; 0 = 1e-4 of the initial estimate.
    pub dt_min: f64,
    /// Largest time step, s (also bounded by the output interval).
    pub dt_max: f64,
    /// Verlet integrator: every n-th step is an Euler step.
    pub verlet_reset_steps: u32,
    /// The divergence-free scheme's own settings (`scheme: dfsph`).
    pub dfsph: DfsphSpec,
}

impl SolverSpec {
    /// The kernel gradient this run uses: the one set, else Thomas & Couchman's for the incompressible
    /// scheme (with the exact one its liquid pairs up, at rest too) and the exact one, the paper's, for
    /// the weakly-compressible scheme.
    pub fn kernel_gradient(&self) -> KernelGradient {
        self.kernel_gradient.unwrap_or(match self.scheme {
            Scheme::Dfsph => KernelGradient::ThomasCouchman,
            Scheme::Wcsph => KernelGradient::Exact,
        })
    }
}

impl Default for SolverSpec {
    fn default() -> Self {
        Self {
            scheme: Scheme::Wcsph,
            kernel: KernelKind::CubicSpline,
            kernel_gradient: None,
            smoothing_ratio: 1.3,
            integrator: Integrator::Symplectic,
            cfl: 0.2,
            sound_speed_coefficient: 200f64.sqrt(),
            reference_height: 0.0,
            sound_speed: 0.0,
            artificial_viscosity: ArtificialViscosity::default(),
            laminar_viscosity: false,
            density_diffusion: DensityDiffusion::default(),
            boundary: BoundarySpec::default(),
            dt_min: 0.0,
            dt_max: 1.0e-3,
            verlet_reset_steps: 40,
            dfsph: DfsphSpec::default(),
        }
    }
}

/// A wave probe: a vertical line at (x, y) in the tank frame.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ProbeSpec {
    pub name: String,
    pub x: f64,
    pub y: f64,
}

/// A pressure sensor at a point in the tank frame (on a wall face or slightly inside the liquid).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SensorSpec {
    pub name: String,
    pub x: f64,
    pub y: f64,
    pub z: f64,
}

/// The liquid's initial shape: a block against the tank's −x wall, `length` long (0 = the whole tank) and
/// `height` deep, at rest with hydrostatic pressure.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct FillSpec {
    pub height: f64,
    pub length: f64,
}

/// Everything needed to build a simulation.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SimParams {
    /// 2 or 3.
    pub dimension: usize,
    pub tank: TankSpec,
    pub fill: FillSpec,
    /// Particle spacing dp, m.
    pub particle_spacing: f64,
    pub fluid: FluidSpec,
    /// m/s².
    pub gravity: f64,
    pub solver: SolverSpec,
    pub probes: Vec<ProbeSpec>,
    pub pressure_sensors: Vec<SensorSpec>,
    /// Floating bodies in the tank (which then serves as the basin around them).
    #[serde(default)]
    pub bodies: Vec<BodySpec>,
    /// A piston wave maker at the tank's −x end.
    #[serde(default)]
    pub wave_maker: Option<PistonSpec>,
    /// Fixed obstacles: solid boxes of wall particles fixed to the tank (a block on the floor, a baffle), by
    /// centre and size in the tank frame (origin at the centre of the tank bottom).
    #[serde(default)]
    pub obstacles: Vec<RegionSpec>,
}

/// A parameter that cannot be used, with the field's dotted name and what would be accepted.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{field}: {message}")]
pub struct ParamError {
    pub field: String,
    pub message: String,
}

/// The most particles (liquid and walls) a case may start with: particle indices are 32-bit with one bit
/// marking halo copies across ranks.
pub const MAX_PARTICLES: f64 = (1u64 << 31) as f64;

fn err(field: &str, message: impl Into<String>) -> ParamError {
    ParamError {
        field: field.to_string(),
        message: message.into(),
    }
}

fn positive(field: &str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(err(field, format!("must be a positive number, got {v}")))
    }
}

fn non_negative(field: &str, v: f64) -> Result<(), ParamError> {
    if v.is_finite() && v >= 0.0 {
        Ok(())
    } else {
        Err(err(field, format!("must be zero or positive, got {v}")))
    }
}

impl SimParams {
    /// A closed `tank` filled to `fill` m over its whole length at spacing `dp`, in `dimension` 2 or 3,
    /// with the default fluid (water), gravity 9.81 m/s² and solver, and no probes, sensors, bodies, wave
    /// maker or obstacles.
    pub fn filled_tank(dimension: usize, tank: TankSpec, fill: f64, dp: f64) -> Self {
        SimParams {
            dimension,
            tank,
            fill: FillSpec {
                height: fill,
                length: 0.0,
            },
            particle_spacing: dp,
            fluid: FluidSpec::default(),
            gravity: 9.81,
            solver: SolverSpec::default(),
            probes: vec![],
            pressure_sensors: vec![],
            bodies: vec![],
            wave_maker: None,
            obstacles: vec![],
        }
    }

    /// Whether the incompressible scheme corrects its kernel gradients: `solver.dfsph.kernel_correction`,
    /// without bodies (floating bodies, fixed or not, a wave maker), whose moving walls it does not cover.
    pub fn gradients_corrected(&self) -> bool {
        self.solver.dfsph.kernel_correction && self.bodies.is_empty() && self.wave_maker.is_none()
    }

    /// The liquid block's length along x.
    pub fn fill_length(&self) -> f64 {
        if self.fill.length > 0.0 {
            self.fill.length
        } else {
            self.tank.length
        }
    }

    /// Smoothing length h.
    pub fn h(&self) -> f64 {
        self.solver.smoothing_ratio * self.particle_spacing
    }

    /// Reference sound speed c0.
    pub fn sound_speed(&self) -> f64 {
        if self.solver.sound_speed > 0.0 {
            return self.solver.sound_speed;
        }
        let href = if self.solver.reference_height > 0.0 {
            self.solver.reference_height
        } else {
            self.fill.height
        };
        self.solver.sound_speed_coefficient * (self.gravity * href).sqrt()
    }

    /// Wall layers actually built.
    pub fn wall_layers(&self) -> u32 {
        if self.solver.boundary.layers > 0 {
            self.solver.boundary.layers
        } else {
            (2.0 * self.solver.smoothing_ratio).ceil() as u32
        }
    }

    /// About how many liquid and tank-wall particles the case starts with (the liquid block and the wall
    /// layers around the tank; bodies not counted), before anything is allocated: what
    /// [`SimParams::validate`] and a caller's memory check go by.
    pub fn estimated_particles(&self) -> (f64, f64) {
        let dp = self.particle_spacing;
        let across = |len: f64| (len / dp).ceil().max(1.0);
        let wall = 2.0 * self.wall_layers() as f64;
        let (mut liquid, mut inner, mut outer) = (
            across(self.fill_length()) * across(self.fill.height),
            across(self.tank.length) * across(self.tank.height),
            (across(self.tank.length) + wall) * (across(self.tank.height) + wall),
        );
        if self.dimension == 3 {
            liquid *= across(self.tank.breadth);
            inner *= across(self.tank.breadth);
            outer *= across(self.tank.breadth) + wall;
        }
        (liquid, outer - inner)
    }

    /// The names of the moving bodies in the order observations list them: the floating bodies, then
    /// `wave_maker` if there is one.
    pub fn body_names(&self) -> Vec<String> {
        self.bodies
            .iter()
            .map(|b| b.name.clone())
            .chain(self.wave_maker.as_ref().map(|_| "wave_maker".to_string()))
            .collect()
    }

    /// The wave maker's plate thickness (its own, or the tank walls') and where its face rests (x).
    pub fn wave_maker_plate(&self) -> Option<(f64, f64)> {
        let wm = self.wave_maker.as_ref()?;
        let dp = self.particle_spacing;
        let thickness = if wm.thickness > 0.0 {
            wm.thickness
        } else {
            self.wall_layers() as f64 * dp
        };
        let face = wm.rest_face(-0.5 * self.tank.length, thickness, dp);
        Some((thickness, face))
    }

    /// Obstacles lie within the tank, are at least a kernel support thick (the liquid must not see through
    /// them) and are made of wall particles (the dynamic boundary).
    fn validate_obstacles(&self) -> Result<(), ParamError> {
        let Some(first) = self.obstacles.first() else {
            return Ok(());
        };
        if self.solver.boundary.method != BoundaryMethod::Dynamic {
            return Err(err(
                &format!("obstacles.{}", first.name),
                "obstacles are made of wall particles: set solver.boundary.method: dynamic",
            ));
        }
        let support = 2.0 * self.h();
        let (lo, hi) = self.tank.inside();
        let axes: &[usize] = if self.dimension == 2 {
            &[0, 2]
        } else {
            &[0, 1, 2]
        };
        for (i, o) in self.obstacles.iter().enumerate() {
            let f = |field: &str| format!("obstacles.{}.{field}", o.name);
            if o.name.is_empty() || self.obstacles[..i].iter().any(|p| p.name == o.name) {
                return Err(err(
                    "obstacles",
                    format!(
                        "obstacle names must be unique and not empty; got `{}`",
                        o.name
                    ),
                ));
            }
            for (field, v) in [("centre", &o.centre), ("size", &o.size)] {
                if let Some(k) = v.iter().position(|x| !x.is_finite()) {
                    return Err(err(
                        &f(field),
                        format!("element {k} is not a finite number"),
                    ));
                }
            }
            for &k in axes {
                if !(o.size[k] >= support) {
                    return Err(err(
                        &f("size"),
                        format!(
                            "element {k} ({} m) is thinner than the kernel support {support:.4} m: the liquid \
                             would see through the obstacle; make it at least that (or use a smaller \
                             particle_spacing)",
                            o.size[k]
                        ),
                    ));
                }
                let (a, b) = (o.centre[k] - 0.5 * o.size[k], o.centre[k] + 0.5 * o.size[k]);
                if a < lo[k] - 1e-9 || b > hi[k] + 1e-9 {
                    return Err(err(
                        &f("centre"),
                        format!(
                            "the box reaches outside the tank (axis {k}: {a:.4}..{b:.4} m, tank {:.4}..{:.4} m; \
                             the tank frame's origin is the centre of the tank bottom)",
                            lo[k], hi[k]
                        ),
                    ));
                }
            }
        }
        Ok(())
    }

    /// Floating bodies need wall particle layers (and with WCSPH its symplectic integrator), each checked
    /// against the tank.
    fn validate_bodies(&self) -> Result<(), ParamError> {
        if let (Some(wm), Some((thickness, _))) = (&self.wave_maker, self.wave_maker_plate()) {
            wm.validate(self.tank.length, thickness, self.particle_spacing)?;
        }
        let field = match (self.bodies.first(), &self.wave_maker) {
            (Some(first), _) => format!("bodies.{}", first.name),
            (None, Some(_)) => "wave_maker".to_string(),
            (None, None) => return Ok(()),
        };
        let s = &self.solver;
        if s.scheme == Scheme::Wcsph && s.integrator != Integrator::Symplectic {
            return Err(err(&field, "floating bodies and wave makers move with the liquid's symplectic steps: set solver.integrator: symplectic (or solver.scheme: dfsph)"));
        }
        if s.boundary.method != BoundaryMethod::Dynamic {
            return Err(err(
                &field,
                "floating bodies and wave makers are made of wall particles: set solver.boundary.method: dynamic",
            ));
        }
        let support = 2.0 * self.h();
        let (lo, hi) = self.tank.inside();
        for (i, b) in self.bodies.iter().enumerate() {
            let ok = b.name.starts_with(|c: char| c.is_ascii_alphabetic())
                && b.name
                    .chars()
                    .all(|c| c.is_ascii_alphanumeric() || c == '_');
            if !ok || b.name == "wave_maker" || self.bodies[..i].iter().any(|o| o.name == b.name) {
                return Err(err("bodies", format!("body names must be unique, start with a letter and hold only letters, digits and `_` (they become ROS 2 topic names), and `wave_maker` is taken; got `{}`", b.name)));
            }
            b.validate(self.dimension, lo, hi, self.particle_spacing, support)?;
            if let (Some(wm), Some((_, face))) = (&self.wave_maker, self.wave_maker_plate()) {
                let start = b.position[0] - 0.5 * b.size[0];
                let clear = face + 0.5 * wm.stroke + self.particle_spacing;
                if start < clear {
                    return Err(err(&format!("bodies.{}.position", b.name), format!("the box starts at x = {start:.4} m, within the wave maker's reach (its plate's face comes forward to {clear:.4} m with a spacing to spare)")));
                }
            }
        }
        Ok(())
    }

    /// Checks every field; the error names the first unusable one.
    pub fn validate(&self) -> Result<(), ParamError> {
        if self.solver.kernel == KernelKind::Wendland
            && self.solver.kernel_gradient == Some(KernelGradient::ThomasCouchman)
        {
            return Err(err(
                "solver.kernel_gradient",
                "thomas_couchman is for the cubic spline (the Wendland kernel's gradient does not vanish between close particles): leave it unset or set `exact`",
            ));
        }
        if self.solver.scheme == Scheme::Dfsph
            && self.solver.boundary.method != BoundaryMethod::Dynamic
        {
            return Err(err(
                "solver.boundary.method",
                "the dfsph scheme uses the wall particle layers (`dynamic`); `mirror` is for wcsph",
            ));
        }
        // The dfsph settings are checked whichever the scheme: a case run with wcsph and switched to dfsph
        // later (`--set solver.scheme=dfsph`) must not meet a bad value only then.
        {
            let d = &self.solver.dfsph;
            if !(d.cfl > 0.0 && d.cfl <= 1.0) {
                return Err(err(
                    "solver.dfsph.cfl",
                    format!("must be in (0, 1], got {}", d.cfl),
                ));
            }
            positive("solver.dfsph.dt_max", d.dt_max)?;
            positive("solver.dfsph.max_density_error", d.max_density_error)?;
            positive("solver.dfsph.max_divergence_error", d.max_divergence_error)?;
            if let Some(w) = d.relaxation {
                if !(w > 0.0 && w <= 1.0) {
                    return Err(err(
                        "solver.dfsph.relaxation",
                        format!(
                            "must be in (0, 1] (0.7 keeps a 3D tank at rest still; leave it unset for the default), got {w}"
                        ),
                    ));
                }
            }
            if d.target_iterations > d.max_iterations {
                return Err(err(
                    "solver.dfsph.target_iterations",
                    format!(
                        "must be at most max_iterations ({}), got {}; 0 turns the control off",
                        d.max_iterations, d.target_iterations
                    ),
                ));
            }
            if !(0.0..=1.0).contains(&d.hydrostatic_warm_start) {
                return Err(err(
                    "solver.dfsph.hydrostatic_warm_start",
                    format!(
                        "must be in [0, 1] (0: half the last pressure), got {}",
                        d.hydrostatic_warm_start
                    ),
                ));
            }
            if d.max_iterations == 0 || d.min_iterations > d.max_iterations {
                return Err(err(
                    "solver.dfsph.max_iterations",
                    format!(
                        "must be at least 1 and at least min_iterations ({}), got {}",
                        d.min_iterations, d.max_iterations
                    ),
                ));
            }
        }
        if self.dimension != 2 && self.dimension != 3 {
            return Err(err(
                "dimension",
                format!("must be 2 or 3, got {}", self.dimension),
            ));
        }
        positive("tank.length", self.tank.length)?;
        positive("tank.breadth", self.tank.breadth)?;
        positive("tank.height", self.tank.height)?;
        positive("particle_spacing", self.particle_spacing)?;
        positive("fill_height", self.fill.height)?;
        non_negative("fill_length", self.fill.length)?;
        positive("fluid.density", self.fluid.density)?;
        non_negative("fluid.kinematic_viscosity", self.fluid.kinematic_viscosity)?;
        non_negative("gravity", self.gravity)?;
        let dp = self.particle_spacing;
        if self.fill.height > self.tank.height {
            return Err(err(
                "fill_height",
                format!(
                    "{} m is above the tank height {} m",
                    self.fill.height, self.tank.height
                ),
            ));
        }
        if self.fill.length > self.tank.length {
            return Err(err(
                "fill_length",
                format!(
                    "{} m is longer than the tank ({} m)",
                    self.fill.length, self.tank.length
                ),
            ));
        }
        let min_extent = if self.dimension == 3 {
            self.tank.breadth.min(self.tank.length)
        } else {
            self.tank.length
        };
        if min_extent < 4.0 * dp || self.tank.height < 4.0 * dp {
            return Err(err(
                "particle_spacing",
                format!(
                    "{dp} m is too coarse for the tank: use at most a quarter of its smallest side"
                ),
            ));
        }
        let (liquid, walls) = self.estimated_particles();
        if liquid + walls > MAX_PARTICLES {
            // The solver indexes particles with 32 bits (one of them a flag).
            let finest = dp * ((liquid + walls) / MAX_PARTICLES).powf(1.0 / self.dimension as f64);
            return Err(err(
                "particle_spacing",
                format!(
                    "{dp} m makes about {:.1e} particles, more than the solver can index ({MAX_PARTICLES:.1e}): use a spacing of at least {:.2e} m",
                    liquid + walls,
                    finest
                ),
            ));
        }
        if self.fill.height < 2.0 * dp {
            return Err(err(
                "fill_height",
                format!(
                    "{} m is less than two particle spacings ({dp} m)",
                    self.fill.height
                ),
            ));
        }
        let s = &self.solver;
        if !(s.smoothing_ratio >= 0.9 && s.smoothing_ratio <= 3.0) {
            return Err(err(
                "solver.smoothing_ratio",
                format!("h/dp must be within 0.9..3, got {}", s.smoothing_ratio),
            ));
        }
        if !(s.cfl > 0.0 && s.cfl <= 1.0) {
            return Err(err(
                "solver.cfl",
                format!("must be within (0, 1], got {}", s.cfl),
            ));
        }
        positive("solver.sound_speed_coefficient", s.sound_speed_coefficient)?;
        non_negative("solver.reference_height", s.reference_height)?;
        non_negative("solver.sound_speed", s.sound_speed)?;
        non_negative(
            "solver.artificial_viscosity.alpha",
            s.artificial_viscosity.alpha,
        )?;
        non_negative(
            "solver.artificial_viscosity.beta",
            s.artificial_viscosity.beta,
        )?;
        positive(
            "solver.artificial_viscosity.eta_factor",
            s.artificial_viscosity.eta_factor,
        )?;
        non_negative(
            "solver.artificial_viscosity.boundary_factor",
            s.artificial_viscosity.boundary_factor,
        )?;
        non_negative("solver.density_diffusion.delta", s.density_diffusion.delta)?;
        self.validate_bodies()?;
        self.validate_obstacles()?;
        non_negative("solver.dt_min", s.dt_min)?;
        positive("solver.dt_max", s.dt_max)?;
        if s.verlet_reset_steps == 0 {
            return Err(err("solver.verlet_reset_steps", "must be at least 1"));
        }
        if s.laminar_viscosity && self.fluid.kinematic_viscosity <= 0.0 {
            return Err(err(
                "fluid.kinematic_viscosity",
                "must be positive when solver.laminar_viscosity is on",
            ));
        }
        if self.gravity == 0.0 && s.sound_speed <= 0.0 {
            return Err(err(
                "solver.sound_speed",
                "set an explicit sound speed when gravity is 0",
            ));
        }
        let (hl, hb) = (self.tank.length / 2.0, self.tank.breadth / 2.0);
        for (i, p) in self.probes.iter().enumerate() {
            if !(p.x.abs() < hl) {
                return Err(err(
                    "probes.x",
                    format!(
                        "probe {i} ({}) at x = {} m is outside the tank (|x| < {hl})",
                        p.name, p.x
                    ),
                ));
            }
            if self.dimension == 3 && !(p.y.abs() < hb) {
                return Err(err(
                    "probes.y",
                    format!(
                        "probe {i} ({}) at y = {} m is outside the tank (|y| < {hb})",
                        p.name, p.y
                    ),
                ));
            }
        }
        for (i, p) in self.pressure_sensors.iter().enumerate() {
            let tol = 1e-9;
            if !(p.x.abs() <= hl + tol) {
                return Err(err(
                    "pressure_sensors.x",
                    format!(
                        "sensor {i} ({}) at x = {} m is outside the tank",
                        p.name, p.x
                    ),
                ));
            }
            if self.dimension == 3 && !(p.y.abs() <= hb + tol) {
                return Err(err(
                    "pressure_sensors.y",
                    format!(
                        "sensor {i} ({}) at y = {} m is outside the tank",
                        p.name, p.y
                    ),
                ));
            }
            if !(p.z >= -tol && p.z <= self.tank.height + tol) {
                return Err(err(
                    "pressure_sensors.z",
                    format!(
                        "sensor {i} ({}) at z = {} m is outside the tank",
                        p.name, p.z
                    ),
                ));
            }
            // On an obstacle's face (within half a spacing) it reads that face; deeper, it would be
            // inside the solid.
            let inside = |o: &RegionSpec| {
                let margin = -0.5 * self.particle_spacing;
                if self.dimension == 2 {
                    o.within::<2>([p.x, p.z], margin)
                } else {
                    o.within::<3>([p.x, p.y, p.z], margin)
                }
            };
            if let Some(o) = self.obstacles.iter().find(|o| inside(o)) {
                return Err(err(
                    "pressure_sensors",
                    format!(
                        "sensor {i} ({}) at ({}, {}, {}) m is inside obstacle `{}`: put it on one of the \
                         obstacle's faces (within half a particle spacing) or in the liquid",
                        p.name, p.x, p.y, p.z, o.name
                    ),
                ));
            }
        }
        Ok(())
    }
}
