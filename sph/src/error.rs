use crate::params::ParamError;

/// Why a simulation cannot go on.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SimError {
    /// (Not the error's source: its message is already in this one's, and a chain of causes would repeat it.)
    #[error("invalid parameter {0}")]
    Params(ParamError),
    #[error("the solution blew up at t = {time:.6} s (step {step}): a non-finite acceleration or density. Reduce solver.cfl, refine particle_spacing, or check the motion for jumps")]
    NonFinite { time: f64, step: u64 },
    #[error("the time step collapsed to {dt:.3e} s (below solver.dt_min = {dt_min:.3e} s) at t = {time:.6} s, step {step}: the flow is too violent for this resolution, or the motion jumps")]
    TimeStepCollapsed {
        time: f64,
        step: u64,
        dt: f64,
        dt_min: f64,
    },
    #[error("all liquid particles have left the tank by t = {time:.6} s")]
    AllParticlesLost { time: f64 },
    #[error("cannot spread the simulation over MPI ranks: {0}")]
    Decomposition(String),
    #[error("floating body `{name}` left the tank at t = {time:.6} s: keep it clear of the walls (a larger tank, springs or fixed degrees of freedom)")]
    BodyLeftTank { name: String, time: f64 },
    #[error("the motion ends at t = {end:.6} s but the run was asked to go on to t = {time:.6} s: shorten --duration or extend the motion")]
    MotionEnded { time: f64, end: f64 },
}

impl From<ParamError> for SimError {
    fn from(e: ParamError) -> Self {
        Self::Params(e)
    }
}
