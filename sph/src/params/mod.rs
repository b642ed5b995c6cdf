//! The typed description of a case: tank, liquid, resolution, solver choices and observation points.
//! Plain data with defaults; [`SimParams::validate`] names the offending field of anything unusable.

mod advice;
mod bodies;
pub mod records;
mod validate;
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
    /// Mean predicted density error the constant-density solver reaches every step (fraction of ρ0), in a
    /// liquid up to [`DfsphSpec::TOLERANCE_LAYERS`] particle spacings deep; deeper, the solver holds a
    /// tighter one ([`DfsphSpec::density_tolerance`]).
    pub max_density_error: f64,
    /// Mean density change per step the divergence solver leaves (fraction of ρ0).
    pub max_divergence_error: f64,
    /// Relaxation ω of both solvers' Jacobi iterations (each moves a particle's k by ω times what would
    /// remove its own error alone). At 1 the iterations amplify the particle-to-particle pressure modes of
    /// the 81-neighbour 3D kernel (h = 1.3 dp): a 3D tank at rest stirs itself to ~0.1 m/s. Unset: 0.5
    /// with `kernel_correction` (whose pressure passes burst into noise at 0.7 in a 0.39 m deep 2D tank),
    /// 0.7 without ([`DfsphSpec::relaxation`]).
    pub relaxation: Option<f64>,
    /// Iterations of the constant-density solver at least, and of either solver at most (a step solved
    /// again at half the step may take twice as many as its last try, see `target_iterations`).
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
    /// carries 0.6 (`sph::scheme::dfsph::warm_start::REST`). 0: half the whole last pressure (Bender & Koschier
    /// 2017), as always with `smoothing_ratio` < 1.
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
    /// Depth of liquid, in particle spacings, up to which the constant-density solver holds
    /// `max_density_error` itself.
    pub const TOLERANCE_LAYERS: f64 = 50.0;

    /// The mean density error the constant-density solver holds in a liquid `layers` particle spacings
    /// deep: `max_density_error`, times (`TOLERANCE_LAYERS` / layers)² deeper. The Jacobi iterations
    /// build the liquid's weight one layer of particles an iteration, so the error left in that smoothest
    /// mode, for the same mean error, grows with the square of the depth; at a fixed tolerance a deep
    /// liquid released from rest sags onto its floor, or blows up (measured in the manual's
    /// incompressible-scheme decisions, "A deep liquid's start").
    pub fn density_tolerance(&self, layers: f64) -> f64 {
        let scale = (Self::TOLERANCE_LAYERS / layers.max(1.0)).min(1.0);
        self.max_density_error * scale * scale
    }

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
    /// Modified dynamic boundary conditions (English et al. 2022), `wcsph` only, one process: the tank's wall
    /// layers with each point split in two along its face (four in 3D), each wall particle's density
    /// extrapolated from the liquid at its mirror image across the wall face; the particles of bodies and
    /// obstacles keep the dynamic walls' continuity.
    Mdbc,
}

impl BoundaryMethod {
    /// Whether the walls are particles fixed to the tank (`dynamic`, `mdbc`), not ghosts of the liquid.
    pub fn has_wall_particles(self) -> bool {
        matches!(self, Self::Dynamic | Self::Mdbc)
    }
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
    #[serde(default, with = "records::probes")]
    pub probes: Vec<ProbeSpec>,
    #[serde(default, with = "records::sensors")]
    pub pressure_sensors: Vec<SensorSpec>,
    /// Floating bodies in the tank (which then serves as the basin around them), by name.
    #[serde(default, with = "records::by_name")]
    pub bodies: Vec<BodySpec>,
    /// A piston wave maker at the tank's −x end.
    #[serde(default)]
    pub wave_maker: Option<PistonSpec>,
    /// Fixed obstacles: solid boxes of wall particles fixed to the tank (a block on the floor, a baffle), by
    /// centre and size in the tank frame (origin at the centre of the tank bottom), by name.
    #[serde(default, with = "records::by_name")]
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

impl SimParams {
    /// The mean density error the incompressible scheme's constant-density solver holds for this liquid
    /// ([`DfsphSpec::density_tolerance`] at the fill's depth in particle spacings).
    pub fn density_tolerance(&self) -> f64 {
        self.solver
            .dfsph
            .density_tolerance(self.fill.height / self.particle_spacing)
    }

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
}
