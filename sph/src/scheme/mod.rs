//! Pressure schemes. Each scheme evaluates the rates of change of the liquid (and of the wall particles'
//! density) from the current state; the integrator and the simulation are shared.

pub mod candidates;
pub mod dfsph;
pub mod gradient_correction;
pub mod half;
pub mod landing;
pub mod near;
pub mod pair_sums;
pub mod warm_start;
pub mod wcsph;

/// Particles per parallel work item of every scheme's passes (fixed, so reductions do not depend on the
/// number of threads).
pub const CHUNK: usize = 256;

/// What a scheme needs across ranks (MPI domain decomposition, [`crate::domain`]); `None` in one process.
pub trait Ranks<const D: usize> {
    /// Liquid particles on all ranks.
    fn total(&self) -> usize;
    /// The halo copies' values of a per-particle scalar, and of a per-particle vector, from their owners.
    fn sync_scalar(&mut self, k: &mut [f32]);
    fn sync_vector(&mut self, v: &mut [[f32; D]]);
    /// Element-wise sum or extreme over ranks.
    fn reduce(&mut self, v: &mut [f64], op: crate::domain::Op);
}

/// The tank frame's motion as the particles feel it, in the tank frame (x, y, z).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct FrameTerms {
    /// Apparent gravity R^T (g − a_origin), m/s².
    pub g: [f32; 3],
    /// Angular velocity ω, rad/s.
    pub w: [f32; 3],
    /// Angular acceleration ω̇, rad/s².
    pub dw: [f32; 3],
}

impl FrameTerms {
    /// Acceleration of a particle at r moving at v relative to the frame, from gravity and the frame's motion:
    /// g − ω̇ × r − ω × (ω × r) − 2 ω × v.
    #[inline(always)]
    pub fn acceleration(&self, r: [f32; 3], v: [f32; 3]) -> [f32; 3] {
        let cross = |a: [f32; 3], b: [f32; 3]| {
            [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ]
        };
        let euler = cross(self.dw, r);
        let wr = cross(self.w, r);
        let centri = cross(self.w, wr);
        let cor = cross(self.w, v);
        std::array::from_fn(|k| self.g[k] - euler[k] - centri[k] - 2.0 * cor[k])
    }
}

/// What one force evaluation found, summed over the liquid.
#[derive(Clone, Copy, Debug, Default)]
pub struct PassTotals {
    /// Force of the boundary on the liquid (x, y, z), per unit breadth in 2D.
    pub force: [f64; 3],
    /// Its moment about the tank origin.
    pub moment: [f64; 3],
    /// Largest acceleration magnitude.
    pub max_acc: f32,
    /// Largest |h v·r / (r² + η²)| over interacting pairs.
    pub max_mu: f32,
    /// Any non-finite rate.
    pub non_finite: bool,
}

impl PassTotals {
    /// Sums force, moment and the non-finite flag with `reduce` (over ranks).
    pub fn reduce_with(&mut self, reduce: impl FnOnce(&mut [f64])) {
        let mut v = [0.0; 7];
        v[..3].copy_from_slice(&self.force);
        v[3..6].copy_from_slice(&self.moment);
        v[6] = f64::from(u8::from(self.non_finite));
        reduce(&mut v);
        self.force.copy_from_slice(&v[..3]);
        self.moment.copy_from_slice(&v[3..6]);
        self.non_finite = v[6] > 0.0;
    }

    pub fn merge(&mut self, o: &PassTotals) {
        for k in 0..3 {
            self.force[k] += o.force[k];
            self.moment[k] += o.moment[k];
        }
        self.max_acc = self.max_acc.max(o.max_acc);
        self.max_mu = self.max_mu.max(o.max_mu);
        self.non_finite |= o.non_finite;
    }
}
