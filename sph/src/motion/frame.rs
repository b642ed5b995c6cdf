//! The tank frame's motion in the terms a particle feels it.

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
