//! The paper's cubic B-spline, eq. (6): W = σ/h^d · {1 − 3/2 q² + 3/4 q³ (q < 1); 1/4 (2 − q)³ (q < 2)}
//! with σ = 10/(7π) in 2D and 1/π in 3D (the paper's α, chosen so that ∫W dV = 1).

use super::Kernel;
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct CubicSpline {
    h: f32,
    inv_h: f32,
    /// σ / h^d
    norm: f32,
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
        // Both branches are computed and one selected, so the pair loop stays branch-free and vectorises.
        let t = (2.0 - q).max(0.0);
        let outer = -s * 0.75 * t * t / q.max(1.0);
        let inner = s * (-3.0 + 2.25 * q);
        if q < 1.0 {
            inner
        } else {
            outer
        }
    }
}
