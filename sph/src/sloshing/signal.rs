//! Reading a sloshing record: the period and damping of a free decay (a damped sine fitted to it), and the
//! amplitude and phase of a forced response at its forcing frequency (a least-squares fit of sines).

use std::f64::consts::PI;

/// What a free decay record says about its mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decay {
    /// Damped period 2π/ω_d, s.
    pub period: f64,
    /// Damping ratio ζ (the logarithmic decrement per cycle is δ = 2πζ / sqrt(1 − ζ²)).
    pub damping_ratio: f64,
    /// Cycles the record spans.
    pub cycles: f64,
    /// The fitted amplitude at the record's start and end.
    pub first_amplitude: f64,
    pub last_amplitude: f64,
}

/// Why a record could not be read.
#[derive(Clone, Debug, PartialEq)]
pub struct SignalError(pub String);

impl std::fmt::Display for SignalError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for SignalError {}

/// Period and damping of the decaying oscillation in `y` (sampled at times `t`), expected near
/// `period_guess` s: the least-squares fit of y ≈ e^(−σt)(a cos ω_d t + b sin ω_d t) + c over the whole
/// record (ω_d and σ searched on a grid, then refined; a, b, c linear). Fitting the whole record, not its
/// extrema, keeps step-to-step noise from inflating the peaks. ζ = σ / sqrt(σ² + ω_d²).
pub fn free_decay(t: &[f64], y: &[f64], period_guess: f64) -> Result<Decay, SignalError> {
    if t.len() != y.len() || t.len() < 16 {
        return Err(SignalError(format!("{} samples: too few", t.len())));
    }
    let span = t[t.len() - 1] - t[0];
    let cycles = span / period_guess;
    if cycles < 3.0 {
        return Err(SignalError(format!(
            "the record spans {cycles:.1} periods: at least three are needed"
        )));
    }
    let t0 = t[0];
    let w0 = 2.0 * PI / period_guess;
    // Residual and coefficients of the linear fit at (ω, σ) (an infinite residual where it is singular).
    let fit = |w: f64, s: f64| -> (f64, [f64; 3]) {
        let basis = |ti: f64, j: usize| {
            let tt = ti - t0;
            match j {
                0 => (-s * tt).exp() * (w * tt).cos(),
                1 => (-s * tt).exp() * (w * tt).sin(),
                _ => 1.0,
            }
        };
        let Some(x) = least_squares(t, y, 3, basis) else {
            return (f64::INFINITY, [0.0; 3]);
        };
        let res: f64 = t
            .iter()
            .zip(y)
            .map(|(&ti, &yi)| (yi - (0..3).map(|j| x[j] * basis(ti, j)).sum::<f64>()).powi(2))
            .sum();
        (res, [x[0], x[1], x[2]])
    };
    // Grid: ω within ±20 % of the guess, σ from −0.05 ω to 0.3 ω.
    let (mut best, mut bw, mut bs) = (f64::INFINITY, w0, 0.0);
    for i in 0..=80 {
        let w = w0 * (0.8 + 0.4 * i as f64 / 80.0);
        for j in 0..=35 {
            let s = w0 * (-0.05 + 0.35 * j as f64 / 35.0);
            let (r, _) = fit(w, s);
            if r < best {
                (best, bw, bs) = (r, w, s);
            }
        }
    }
    // Refine by shrinking coordinate steps.
    let (mut dw, mut ds) = (0.4 * w0 / 80.0, 0.35 * w0 / 35.0);
    for _ in 0..60 {
        let mut moved = false;
        for (cw, cs) in [(dw, 0.0), (-dw, 0.0), (0.0, ds), (0.0, -ds)] {
            let (r, _) = fit(bw + cw, bs + cs);
            if r < best {
                (best, bw, bs) = (r, bw + cw, bs + cs);
                moved = true;
            }
        }
        if !moved {
            dw *= 0.5;
            ds *= 0.5;
        }
    }
    let (_, x) = fit(bw, bs);
    let amp = x[0].hypot(x[1]);
    Ok(Decay {
        period: 2.0 * PI / bw,
        damping_ratio: bs / bs.hypot(bw),
        cycles: span * bw / (2.0 * PI),
        first_amplitude: amp,
        last_amplitude: amp * (-bs * span).exp(),
    })
}

/// Least-squares coefficients of `m` basis functions (`basis(t, j)`, j < m) fitted to the samples, by the
/// normal equations and Gaussian elimination with partial pivoting; `None` where they are singular.
fn least_squares(
    t: &[f64],
    y: &[f64],
    m: usize,
    basis: impl Fn(f64, usize) -> f64,
) -> Option<Vec<f64>> {
    let mut a = vec![vec![0.0; m + 1]; m];
    for (&ti, &yi) in t.iter().zip(y) {
        let b: Vec<f64> = (0..m).map(|j| basis(ti, j)).collect();
        for r in 0..m {
            for c in 0..m {
                a[r][c] += b[r] * b[c];
            }
            a[r][m] += b[r] * yi;
        }
    }
    for col in 0..m {
        let p = (col..m).max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))?;
        a.swap(col, p);
        if a[col][col].abs() < 1e-12 {
            return None;
        }
        for r in 0..m {
            if r != col {
                let f = a[r][col] / a[col][col];
                for c in col..=m {
                    a[r][c] -= f * a[col][c];
                }
            }
        }
    }
    Some((0..m).map(|r| a[r][m] / a[r][r]).collect())
}

/// Amplitude and phase of `y` at `w` (rad/s): y ≈ amplitude · sin(w t + phase) + (sines at `others`) + a
/// constant, fitted by least squares over the whole record. Fitting the free mode's frequency among
/// `others` keeps a slowly decaying transient out of the forced amplitude.
pub fn harmonic(t: &[f64], y: &[f64], w: f64, others: &[f64]) -> Result<(f64, f64), SignalError> {
    let ws: Vec<f64> = std::iter::once(w).chain(others.iter().copied()).collect();
    let m = 1 + 2 * ws.len();
    if t.len() != y.len() || t.len() < 2 * m {
        return Err(SignalError(format!("{} samples: too few", t.len())));
    }
    let basis = |ti: f64, j: usize| -> f64 {
        if j == 0 {
            1.0
        } else {
            let (k, cos) = ((j - 1) / 2, (j - 1) % 2 == 1);
            let a = ws[k] * ti;
            if cos {
                a.cos()
            } else {
                a.sin()
            }
        }
    };
    let x = least_squares(t, y, m, basis).ok_or_else(|| {
        SignalError("the frequencies cannot be told apart over this record".into())
    })?;
    let (s, c) = (x[1], x[2]);
    // s sin + c cos = R sin(wt + φ), R = hypot, φ = atan2(c, s).
    Ok((s.hypot(c), c.atan2(s)))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_a_damped_sine() {
        let (w, zeta) = (5.0, 0.004);
        let wd = w * (1.0f64 - zeta * zeta).sqrt();
        let t: Vec<f64> = (0..1000).map(|i| i as f64 * 0.01).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| 3.0 + 2.0 * (-zeta * w * t).exp() * (wd * t + 0.3).cos())
            .collect();
        let d = free_decay(&t, &y, 1.2).unwrap();
        assert!((d.period - 2.0 * PI / wd).abs() < 1e-4 * d.period, "{d:?}");
        assert!((d.damping_ratio - zeta).abs() < 1e-4, "{d:?}");
        assert!(d.cycles > 6.0, "{d:?}");
    }

    #[test]
    fn separates_the_forced_sine_from_the_free_mode() {
        let (w, w1) = (4.0, 5.0);
        let t: Vec<f64> = (0..1500).map(|i| i as f64 * 0.01).collect();
        let y: Vec<f64> = t
            .iter()
            .map(|&t| 1.5 * (w * t + 0.2).sin() + 0.8 * (w1 * t).cos() - 0.1)
            .collect();
        let (a, p) = harmonic(&t, &y, w, &[w1]).unwrap();
        assert!((a - 1.5).abs() < 1e-9 && (p - 0.2).abs() < 1e-9, "{a} {p}");
    }

    #[test]
    fn too_short_a_record_is_refused() {
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
        let y: Vec<f64> = t.iter().map(|t| (5.0 * t).sin()).collect();
        assert!(free_decay(&t, &y, 1.25).is_err());
    }
}
