//! Kernel gradients in half precision: the records the incompressible scheme's 3D neighbour lists hold.
//!
//! The pressure iterations read every pair's gradient twice an iteration, ~10 iterations a step, and in 3D
//! the lists (~55 liquid neighbours a particle) outgrow the cores' L2 caches: the passes wait on memory.
//! A [`Half4`] holds ∇W_ab · h⁴ (dimensionless, below 1 for the cubic spline and Wendland kernels, so far
//! from the format's largest value, 65504) in four IEEE 754 binary16 lanes, the last 0: 8 bytes a pair
//! instead of 16 in f32. Each lane is rounded to nearest, ties to even: within 2⁻¹¹ of the f32 value
//! relatively, or 2⁻²⁵ absolutely at the kernel's edge (subnormals), far below the density error the
//! solver iterates to (1e-4 of ρ0). Pairs stay antisymmetric (rounding is symmetric in the sign).
//!
//! [`to_half`] and [`from_half`] convert in software, to the bit as x86's F16C instructions (`vcvtps2ph`
//! with round-to-nearest, `vcvtph2ps`) do (tested against them): the AVX2 passes convert with F16C, the
//! plain passes with these, and both get the same bits.

/// A kernel gradient times h⁴, in four binary16 lanes (x, y, z, 0).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(transparent)]
pub struct Half4(pub [u16; 4]);

impl Half4 {
    /// The scale of the stored gradients: a record holds ∇W · [`Half4::scale`]`(h)`.
    #[inline(always)]
    pub fn scale(h: f32) -> f32 {
        (h * h) * (h * h)
    }

    /// The record of the (already scaled) gradient `g`.
    #[inline(always)]
    pub fn pack(g: [f32; 3]) -> Self {
        Half4([to_half(g[0]), to_half(g[1]), to_half(g[2]), 0])
    }

    /// The four lanes in f32 (exact).
    #[inline(always)]
    pub fn unpack(self) -> [f32; 4] {
        self.0.map(from_half)
    }
}

/// `x` in binary16, rounded to nearest, ties to even (±∞ beyond 65520 in magnitude; NaN stays NaN).
#[inline(always)]
pub fn to_half(x: f32) -> u16 {
    let b = x.to_bits();
    let sign = ((b >> 16) & 0x8000) as u16;
    let a = b & 0x7fff_ffff;
    if a >= 0x7f80_0000 {
        // ∞, or NaN made quiet with the top of its payload.
        let nan = if a > 0x7f80_0000 {
            0x0200 | ((a >> 13) & 0x03ff) as u16
        } else {
            0
        };
        return sign | 0x7c00 | nan;
    }
    if a >= 0x477f_f000 {
        // 65520 and above round to ∞.
        return sign | 0x7c00;
    }
    if a >= 0x3880_0000 {
        // A normal binary16 (2⁻¹⁴ and above): the 13 bits dropped round to nearest, ties to the even
        // mantissa; a carry out of the mantissa raises the exponent, as it should. Rebias 127 → 15.
        let r = a + 0x0fff + ((a >> 13) & 1);
        return sign | ((r - 0x3800_0000) >> 13) as u16;
    }
    // Subnormal (or zero): multiples of 2⁻²⁴; scaling by 2²⁴ is exact, the rounding is to the even integer
    // (1024 is the smallest normal's encoding, as it should be).
    sign | (f32::from_bits(a) * 16_777_216.0).round_ties_even() as u16
}

/// The binary16 `h` in f32 (exact; a NaN comes back quiet).
#[inline(always)]
pub fn from_half(h: u16) -> f32 {
    let sign = ((h & 0x8000) as u32) << 16;
    let e = ((h >> 10) & 0x1f) as u32;
    let m = (h & 0x03ff) as u32;
    match e {
        0 => {
            let v = m as f32 * (1.0 / 16_777_216.0);
            f32::from_bits(sign | v.to_bits())
        }
        31 if m != 0 => f32::from_bits(sign | 0x7fc0_0000 | (m << 13)),
        31 => f32::from_bits(sign | 0x7f80_0000),
        _ => f32::from_bits(sign | ((e + 112) << 23) | (m << 13)),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_and_rounds_to_nearest_even() {
        for (x, h) in [
            (0.0f32, 0x0000u16),
            (-0.0, 0x8000),
            (1.0, 0x3c00),
            (-2.0, 0xc000),
            (65504.0, 0x7bff),
            (65519.0, 0x7bff),
            (65520.0, 0x7c00),
            (f32::INFINITY, 0x7c00),
            (6.103_515_6e-5, 0x0400),
            (5.960_464_5e-8, 0x0001),
            // Halfway between 1 and the next binary16 (1 + 2⁻¹⁰): to the even one, 1.
            (1.0 + 1.0 / 2048.0, 0x3c00),
            // Halfway above 1 + 2⁻¹⁰: to the even one, 1 + 2⁻⁹.
            (1.0 + 3.0 / 2048.0, 0x3c02),
            // Half the smallest subnormal: ties to even, 0; a little more: the smallest subnormal.
            (2.980_232_2e-8, 0x0000),
            (2.980_233e-8, 0x0001),
        ] {
            assert_eq!(to_half(x), h, "{x:e}");
        }
        assert!(from_half(to_half(f32::NAN)).is_nan());
        // Every binary16 but NaN comes back to itself through f32.
        for h in 0..=u16::MAX {
            let x = from_half(h);
            if x.is_nan() {
                assert_eq!(h & 0x7c00, 0x7c00);
                continue;
            }
            assert_eq!(to_half(x), h, "{h:#06x}");
        }
        // Within half a unit in the last place.
        let mut seed = 12345u64;
        for _ in 0..100_000 {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            // Both signs, any mantissa, exponents from 2⁻³⁰ (below binary16's subnormals) to 2¹⁵.
            let r = (seed >> 32) as u32;
            let e = 97 + (r >> 23) % 46;
            let x = f32::from_bits((r & 0x8000_0000) | (e << 23) | (r & 0x007f_ffff));
            if x.abs() > 65504.0 {
                continue;
            }
            let y = from_half(to_half(x));
            let tol = if x.abs() >= 6.103_515_6e-5 {
                x.abs() / 2048.0
            } else {
                2.980_232_2e-8
            };
            assert!((y - x).abs() <= tol, "{x:e} → {y:e}");
        }
    }

    /// The software conversions give F16C's bits (`vcvtps2ph` rounding to nearest, `vcvtph2ps`).
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn same_bits_as_f16c() {
        use std::arch::x86_64::*;
        // Every x86_64 CPU with AVX2 has F16C (the machines this project runs its tests on have both);
        // one without never takes the F16C passes (`candidates::wide_lanes`).
        assert!(
            std::arch::is_x86_feature_detected!("f16c"),
            "this CPU has no F16C: nothing to compare the software conversions with"
        );
        #[target_feature(enable = "f16c")]
        fn hw_to(x: f32) -> u16 {
            _mm_extract_epi16::<0>(_mm_cvtps_ph::<_MM_FROUND_TO_NEAREST_INT>(_mm_set1_ps(x))) as u16
        }
        #[target_feature(enable = "f16c")]
        fn hw_from(h: u16) -> f32 {
            _mm_cvtss_f32(_mm_cvtph_ps(_mm_set1_epi16(h as i16)))
        }
        for h in 0..=u16::MAX {
            // SAFETY: F16C checked above.
            let (a, b) = (from_half(h), unsafe { hw_from(h) });
            assert_eq!(a.to_bits(), b.to_bits(), "{h:#06x}");
        }
        // Every f32 whose bits are a multiple of 251 (17 million values, all exponents, both signs).
        let mut b = 0u32;
        while let Some(n) = b.checked_add(251) {
            let x = f32::from_bits(b);
            // SAFETY: F16C checked above.
            let (a, hw) = (to_half(x), unsafe { hw_to(x) });
            assert_eq!(a, hw, "{x:e} ({b:#010x})");
            b = n;
        }
    }
}
