//! A copy of every particle's state for writing out (particle frames for ParaView, pictures): the liquid
//! first, then the boundary particles, in the tank frame. Taking one reads the state and changes nothing.

/// The particles of one state. Vector fields are x, y, z (a 2D run has y = 0); the first `fluid` entries
/// are liquid particles, the rest boundary particles (wall layers or mirror ghosts).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Snapshot {
    /// Simulation time of the state, s.
    pub time: f64,
    /// 2 or 3.
    pub dimension: usize,
    /// Number of liquid particles (the first entries).
    pub fluid: usize,
    /// Position in the tank frame, m.
    pub position: Vec<[f32; 3]>,
    /// Velocity relative to the tank, m/s (zero for wall particles, which are fixed in the tank).
    pub velocity: Vec<[f32; 3]>,
    /// Gauge pressure, Pa: the equation of state's (weakly-compressible scheme) or the pressure solver's
    /// (incompressible scheme, whose walls carry none: 0 there).
    pub pressure: Vec<f32>,
    /// Density, kg/m³ (the incompressible scheme holds the rest density: it reports that).
    pub density: Vec<f32>,
    /// Liquid particles: a stable identity through the run (boundary particles: their index among them).
    pub id: Vec<u32>,
}

impl Snapshot {
    /// All particles, liquid and boundary.
    pub fn len(&self) -> usize {
        self.position.len()
    }

    pub fn is_empty(&self) -> bool {
        self.position.is_empty()
    }

    /// Whether particle `i` is liquid.
    pub fn is_fluid(&self, i: usize) -> bool {
        i < self.fluid
    }
}
