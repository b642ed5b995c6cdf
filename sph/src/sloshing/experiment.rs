//! The sloshing experiments a naval architect runs on a tank model, run on the solver: a free decay of the
//! first mode (its period and damping) and a forced sway or pitch (the force or moment per unit motion),
//! each beside linear theory for the same tank and fill.

use super::signal::{self, Decay};
use super::theory::{LaminarDamping, Tank};
use crate::motion::{AtRest, Dof6, Dof6Motion, RegularDof, RegularMotion, TankMotion};
use crate::params::SimParams;
use crate::{SimError, Solver};
use std::f64::consts::PI;

/// Interval of the recorded wall force, s.
pub const SAMPLE: f64 = 0.01;

/// Why an experiment gave no answer.
#[derive(Debug)]
pub enum ExperimentError {
    Sim(SimError),
    Signal(signal::SignalError),
}

impl std::fmt::Display for ExperimentError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Sim(e) => write!(f, "{e}"),
            Self::Signal(e) => write!(f, "reading the record: {e}"),
        }
    }
}

impl std::error::Error for ExperimentError {}

impl From<SimError> for ExperimentError {
    fn from(e: SimError) -> Self {
        Self::Sim(e)
    }
}

impl From<signal::SignalError> for ExperimentError {
    fn from(e: signal::SignalError) -> Self {
        Self::Signal(e)
    }
}

/// The seed case's tank (0.8 × 0.25 × 0.6 m, the paper's barge tank) filled to `fill` at spacing `dp`, in
/// `dimension` 2 or 3, with the default solver and no probes, sensors or bodies.
pub fn seed_tank(dimension: usize, fill: f64, dp: f64) -> SimParams {
    let tank = crate::params::TankSpec {
        length: 0.8,
        breadth: 0.25,
        height: 0.6,
    };
    SimParams::filled_tank(dimension, tank, fill, dp)
}

/// Linear theory's tank for these parameters: the tank's length and breadth, the fill as the depth.
pub fn theory_tank(p: &SimParams) -> Tank {
    Tank {
        length: p.tank.length,
        breadth: p.tank.breadth,
        depth: p.fill.height,
        gravity: p.gravity,
        density: p.fluid.density,
    }
}

/// A free decay's record and what it says.
#[derive(Clone, Debug)]
pub struct FreeDecay {
    /// Sample times, s, and the liquid's horizontal force on the tank, N.
    pub times: Vec<f64>,
    pub force: Vec<f64>,
    /// Period and damping read from the force after the first period.
    pub decay: Decay,
    /// Linear theory's first-mode period, s, and laminar Stokes-layer damping (with the side walls in 3D).
    pub theory_period: f64,
    pub laminar: LaminarDamping,
    /// Wall-clock seconds the run took, and the simulated seconds.
    pub wall_time: f64,
    pub simulated: f64,
}

impl FreeDecay {
    /// Period error against linear theory, as a fraction.
    pub fn period_error(&self) -> f64 {
        self.decay.period / self.theory_period - 1.0
    }
}

/// Starts the first mode in the liquid at rest: the linear standing wave's velocity field as its surface
/// passes through level, φ = B cos(kξ) cosh(kz), B = aω / (k sinh(kh)), ξ from the −x wall (the wave's
/// elevation then peaks at `amplitude` a quarter period later, rising at −x).
pub fn start_first_mode(sim: &mut dyn Solver, tank: &Tank, amplitude: f64) {
    let k = tank.wavenumber(1);
    let w = tank.natural_frequency(1);
    let b = amplitude * w / (k * (k * tank.depth).sinh());
    let l = tank.length;
    sim.set_fluid_velocity(&|x: [f64; 3]| {
        let xi = x[0] + l / 2.0;
        [
            -b * k * (k * xi).sin() * (k * x[2]).cosh(),
            0.0,
            b * k * (k * xi).cos() * (k * x[2]).sinh(),
        ]
    });
}

/// Free decay of the first mode started with wave amplitude `amplitude` (m), over `cycles` theoretical
/// periods; the first period (the start-up transient and the higher modes) is left out of the fit.
pub fn free_decay(
    params: SimParams,
    amplitude: f64,
    cycles: f64,
) -> Result<FreeDecay, ExperimentError> {
    let tank = theory_tank(&params);
    let three_d = params.dimension == 3;
    let nu = params.fluid.kinematic_viscosity;
    let period = tank.natural_period(1);
    let mut sim = crate::build(params)?;
    start_first_mode(sim.as_mut(), &tank, amplitude);
    let clock = std::time::Instant::now();
    let (times, force) = record(sim.as_mut(), &AtRest, cycles * period, |o| {
        o.wrench.force[0]
    })?;
    let skip = times.iter().position(|&t| t >= period).unwrap_or(0);
    let decay = signal::free_decay(&times[skip..], &force[skip..], period)?;
    Ok(FreeDecay {
        wall_time: clock.elapsed().as_secs_f64(),
        simulated: cycles * period,
        times,
        force,
        decay,
        theory_period: period,
        laminar: tank.laminar_damping(nu, three_d),
    })
}

/// Advances to `t_end`, sampling `what` every [`SAMPLE`] s: the sample times and values.
fn record<T>(
    sim: &mut dyn Solver,
    motion: &dyn TankMotion,
    t_end: f64,
    what: impl Fn(&crate::observe::Observation) -> T,
) -> Result<(Vec<f64>, Vec<T>), ExperimentError> {
    let (mut times, mut values) = (vec![], vec![]);
    let n = (t_end / SAMPLE).round() as usize;
    for i in 1..=n {
        sim.advance_to(motion, i as f64 * SAMPLE)?;
        let o = sim.observe(motion)?;
        times.push(o.time);
        values.push(what(&o));
    }
    Ok((times, values))
}

/// How the tank is forced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Forcing {
    /// x_T = a sin ωt (m); the answer is the horizontal force per metre.
    Sway,
    /// θ = a sin ωt about the tank origin's y axis (rad); the answer is the moment about y per radian.
    Pitch,
}

/// A forced run's answer at the forcing frequency beside linear theory's.
#[derive(Clone, Debug)]
pub struct Forced {
    pub forcing: Forcing,
    /// ω / ω₁ of linear theory.
    pub frequency_ratio: f64,
    /// Force (N/m) or moment (N·m/rad) per unit motion: amplitude and phase against the motion (rad), as
    /// simulated and in theory (the theory's phase is 0 or π).
    pub amplitude: f64,
    pub phase: f64,
    pub theory_amplitude: f64,
    pub theory_phase: f64,
    pub times: Vec<f64>,
    pub response: Vec<f64>,
    pub wall_time: f64,
    pub simulated: f64,
}

impl Forced {
    /// Amplitude error against theory, as a fraction.
    pub fn amplitude_error(&self) -> f64 {
        self.amplitude / self.theory_amplitude - 1.0
    }

    /// Phase error against theory, degrees, in (−180, 180].
    pub fn phase_error_deg(&self) -> f64 {
        let mut d = (self.phase - self.theory_phase).to_degrees() % 360.0;
        if d > 180.0 {
            d -= 360.0;
        }
        if d <= -180.0 {
            d += 360.0;
        }
        d
    }
}

/// Sways or pitches the tank with amplitude `a` at `ratio` × ω₁, ramped in over `ramp` forcing periods (a
/// half-cosine), then fits the force or moment at the forcing frequency (with the free first mode beside
/// it) over the next `fit` forcing periods.
pub fn forced(
    params: SimParams,
    forcing: Forcing,
    a: f64,
    ratio: f64,
    ramp: f64,
    fit: f64,
) -> Result<Forced, ExperimentError> {
    let tank = theory_tank(&params);
    let w1 = tank.natural_frequency(1);
    let w = ratio * w1;
    let period = 2.0 * PI / w;
    let mut dofs = [RegularDof::default(); 6];
    let dof = match forcing {
        Forcing::Sway => 0,
        Forcing::Pitch => 4,
    };
    dofs[dof] = RegularDof {
        amplitude: a,
        period,
        phase: 0.0,
    };
    let motion = RegularMotion {
        dofs,
        ramp: ramp * period,
    };
    let theory = match forcing {
        Forcing::Sway => tank.sway_force(w),
        Forcing::Pitch => tank.pitch_moment(w),
    };
    let mut sim = crate::build(params)?;
    let clock = std::time::Instant::now();
    let t_end = (ramp + fit) * period;
    let (times, response) = record(sim.as_mut(), &motion, t_end, |o| match forcing {
        Forcing::Sway => o.wrench.force[0],
        Forcing::Pitch => o.wrench.moment[1],
    })?;
    let from = times.iter().position(|&t| t >= ramp * period).unwrap_or(0);
    let (amp, phase) = signal::harmonic(&times[from..], &response[from..], w, &[w1])?;
    Ok(Forced {
        forcing,
        frequency_ratio: ratio,
        amplitude: amp / a,
        phase,
        theory_amplitude: theory.abs(),
        theory_phase: if theory >= 0.0 { 0.0 } else { PI },
        times,
        response,
        wall_time: clock.elapsed().as_secs_f64(),
        simulated: t_end,
    })
}

/// A tank held pitched: the liquid's mean force and moment, and the mean probe heights.
#[derive(Clone, Debug)]
pub struct Tilted {
    /// Pitch, rad.
    pub theta: f64,
    /// Mean force (N) and moment about y (N·m) of the liquid on the tank, tank frame.
    pub force: [f64; 3],
    pub moment: f64,
    /// The weight through the tilted liquid's centroid (`Tank::tilted_moment`), and the weight m g.
    pub theory_moment: f64,
    pub weight: f64,
    /// Mean height of each probe of the parameters, m.
    pub probes: Vec<f64>,
}

impl Tilted {
    /// The relative errors of the weight carried through the tilted liquid's centroid: the moment against
    /// [`Tilted::theory_moment`], the force along the tank's x against m g sin θ and the force along its z
    /// against m g cos θ.
    pub fn errors(&self) -> [f64; 3] {
        [
            self.moment / self.theory_moment - 1.0,
            self.force[0] / (self.weight * self.theta.sin()) - 1.0,
            -self.force[2] / (self.weight * self.theta.cos()) - 1.0,
        ]
    }
}

/// Pitch θ reached smoothly over `ramp` s (a half-cosine) and then held.
struct Tilt {
    theta: f64,
    ramp: f64,
}

impl Dof6Motion for Tilt {
    fn dof(&self, t: f64) -> Dof6 {
        let mut d = Dof6::default();
        let (r, dr, ddr) = crate::motion::ramp(t, self.ramp);
        d.q[4] = self.theta * r;
        d.dq[4] = self.theta * dr;
        d.ddq[4] = self.theta * ddr;
        d
    }
}

/// Tilts the tank by `theta` (pitch, rad) over `ramp` s and averages the wrench and the probes over the
/// `periods` first-mode periods (of linear theory) after `settle` more seconds: whole periods, so that what
/// is left of the sloshing the tilt started averages out.
pub fn tilted(
    params: SimParams,
    theta: f64,
    ramp: f64,
    settle: f64,
    periods: f64,
) -> Result<Tilted, ExperimentError> {
    let tank = theory_tank(&params);
    let motion = Tilt { theta, ramp };
    let mut sim = crate::build(params)?;
    let from = ramp + settle;
    let to = from + periods * tank.natural_period(1);
    let (times, rows) = record(sim.as_mut(), &motion, to, |o| {
        (o.wrench.force, o.wrench.moment[1], o.probes.clone())
    })?;
    // The samples held at the tilt, averaged.
    type Row = ([f64; 3], f64, Vec<f64>);
    let held: Vec<&Row> = times
        .iter()
        .zip(&rows)
        .filter(|(&t, _)| t >= from)
        .map(|(_, r)| r)
        .collect();
    let mean = |f: &dyn Fn(&Row) -> f64| held.iter().map(|r| f(r)).sum::<f64>() / held.len() as f64;
    let force = std::array::from_fn(|k| mean(&|r| r.0[k]));
    let moment = mean(&|r| r.1);
    let probes = (0..sim.params().probes.len())
        .map(|i| mean(&|r| r.2[i]))
        .collect();
    Ok(Tilted {
        theta,
        force,
        moment,
        theory_moment: tank.tilted_moment(theta),
        weight: tank.liquid_mass() * tank.gravity,
        probes,
    })
}
