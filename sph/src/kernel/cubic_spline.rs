//! The paper's cubic B-spline, eq. (6): W = σ/h^d · {1 − 3/2 q² + 3/4 q³ (q < 1); 1/4 (2 − q)³ (q < 2)}
//! with σ = 10/(7π) in 2D and 1/π in 3D (the paper's α, chosen so that ∫W dV = 1).

use super::{Kernel, KernelGradient};
use std::f32::consts::PI;

/// Where |dW/dr| peaks, q = r/h: inside it the Thomas & Couchman gradient holds that peak.
pub const TC_CORE: f32 = 2.0 / 3.0;

/// Smallest q the Thomas & Couchman gradient divides by: below it the gradient falls linearly to 0 at r = 0
/// (a particle's own term), instead of dividing by zero.
const Q_MIN: f32 = 1.0e-3;

#[derive(Clone, Copy, Debug)]
pub struct CubicSpline {
    h: f32,
    inv_h: f32,
    /// σ / h^d
    norm: f32,
    /// Hold |dW/dr| at its peak inside q < 2/3 ([`KernelGradient::ThomasCouchman`]).
    core: bool,
}

impl Kernel for CubicSpline {
    fn new(dim: usize, h: f32) -> Self {
        let sigma = match dim {
            2 => 10.0 / (7.0 * PI),
            3 => 1.0 / PI,
            _ => panic!("dimension must be 2 or 3"),
        };
        Self {
            h,
            inv_h: 1.0 / h,
            norm: sigma / h.powi(dim as i32),
            core: false,
        }
    }

    fn with_gradient(self, g: KernelGradient) -> Self {
        Self {
            core: g == KernelGradient::ThomasCouchman,
            ..self
        }
    }

    fn h(&self) -> f32 {
        self.h
    }

    #[inline(always)]
    fn w(&self, r: f32) -> f32 {
        let q = r * self.inv_h;
        if q < 1.0 {
            self.norm * (1.0 - 1.5 * q * q + 0.75 * q * q * q)
        } else if q < 2.0 {
            let t = 2.0 - q;
            self.norm * 0.25 * t * t * t
        } else {
            0.0
        }
    }

    #[inline(always)]
    fn grad_factor(&self, r: f32) -> f32 {
        // dW/dr = norm/h * dW/dq; divided by r = q h.
        let q = r * self.inv_h;
        let s = self.norm * self.inv_h * self.inv_h;
        // Every branch is computed and one selected, so the pair loop stays branch-free and vectorises; one
        // division serves the outer branch and the Thomas & Couchman core (|dW/dr| = s h there).
        let t = (2.0 - q).max(0.0);
        let core = self.core && q < TC_CORE;
        let num = if q >= 1.0 {
            -s * 0.75 * t * t
        } else if core {
            -s
        } else {
            s * (-3.0 + 2.25 * q)
        };
        let den = if q >= 1.0 {
            q
        } else if core {
            q.max(Q_MIN)
        } else {
            1.0
        };
        num / den
    }
}
