//! Wendland C2 kernel: W = α_d (1 − q/2)⁴ (2q + 1) for q < 2, with α = 7/(4π h²) in 2D and 21/(16π h³) in 3D.

use super::Kernel;
use std::f32::consts::PI;

#[derive(Clone, Copy, Debug)]
pub struct WendlandC2 {
    h: f32,
    inv_h: f32,
    norm: f32,
}

impl Kernel for WendlandC2 {
    fn new(dim: usize, h: f32) -> Self {
        let norm = match dim {
            2 => 7.0 / (4.0 * PI * h * h),
            3 => 21.0 / (16.0 * PI * h * h * h),
            _ => panic!("dimension must be 2 or 3"),
        };
        Self {
            h,
            inv_h: 1.0 / h,
            norm,
        }
    }

    fn h(&self) -> f32 {
        self.h
    }

    #[inline(always)]
    fn w(&self, r: f32) -> f32 {
        let q = r * self.inv_h;
        if q < 2.0 {
            let t = 1.0 - 0.5 * q;
            let t2 = t * t;
            self.norm * t2 * t2 * (2.0 * q + 1.0)
        } else {
            0.0
        }
    }

    #[inline(always)]
    fn grad_factor(&self, r: f32) -> f32 {
        // dW/dq = -5 q (1 - q/2)^3 ; dW/dr / r = norm * (-5 (1-q/2)^3) / h^2
        // Branch-free (t clamps to 0 beyond the support) so the pair loop vectorises.
        let t = (1.0 - 0.5 * r * self.inv_h).max(0.0);
        -5.0 * self.norm * t * t * t * self.inv_h * self.inv_h
    }
}
