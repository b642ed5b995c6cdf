//! Reading a sloshing record: the period and damping of a free decay (from its successive extrema), and the
//! amplitude and phase of a forced response at its forcing frequency (a least-squares fit of sines).

use std::f64::consts::PI;

/// What a free decay record says about its mode.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decay {
    /// Period, s: twice the slope of the extrema's times against their count.
    pub period: f64,
    /// Damping ratio ζ from the logarithmic decrement δ per cycle (the slope of ln|extremum| against the
    /// count of half cycles, fitted over all of them): ζ = δ / sqrt(4π² + δ²).
    pub damping_ratio: f64,
    /// Whole cycles the fit spans.
    pub cycles: f64,
    /// The first and last extremum's magnitude.
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

/// Least-squares line y = a + b x: (a, b).
fn line(x: &[f64], y: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let (mx, my) = (x.iter().sum::<f64>() / n, y.iter().sum::<f64>() / n);
    let sxy: f64 = x.iter().zip(y).map(|(a, b)| (a - mx) * (b - my)).sum();
    let sxx: f64 = x.iter().map(|a| (a - mx).powi(2)).sum();
    let b = sxy / sxx;
    (my - b * mx, b)
}

/// Period and damping of the decaying oscillation in `y` (sampled at the uniformly spaced times `t`) about
/// `equilibrium`, expected near `period_guess` s. The record is smoothed over `smooth` s (a centred running
/// mean: it scales every extremum alike and keeps their times), and its extrema are taken as the largest
/// |y| within a quarter period either side, refined by a parabola through their neighbours.
pub fn free_decay(
    t: &[f64],
    y: &[f64],
    equilibrium: f64,
    period_guess: f64,
    smooth: f64,
) -> Result<Decay, SignalError> {
    if t.len() != y.len() || t.len() < 8 {
        return Err(SignalError(format!("{} samples: too few", t.len())));
    }
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1) as f64;
    let half = ((smooth / dt / 2.0).round() as usize).max(0);
    let n = y.len();
    let s: Vec<f64> = (0..n)
        .map(|i| {
            let (a, b) = (i.saturating_sub(half), (i + half + 1).min(n));
            y[a..b].iter().sum::<f64>() / (b - a) as f64 - equilibrium
        })
        .collect();
    let reach = ((period_guess / 4.0 / dt).round() as usize).max(1);
    // Extrema whose neighbourhood lies wholly in the record (and beyond the smoothing's edge).
    let edge = reach.max(half + 1);
    let mut ext: Vec<(f64, f64)> = vec![];
    for i in edge..n.saturating_sub(edge) {
        let m = s[i].abs();
        if m == 0.0 || s[i - reach..=i + reach].iter().any(|v| v.abs() > m) {
            continue;
        }
        // Only alternating signs (a flat top seen twice counts once).
        if let Some(&(_, last)) = ext.last() {
            if last.signum() == s[i].signum() {
                continue;
            }
        }
        let (a, b, c) = (s[i - 1], s[i], s[i + 1]);
        let curv = a - 2.0 * b + c;
        let off = if curv != 0.0 {
            0.5 * (a - c) / curv
        } else {
            0.0
        };
        let off = off.clamp(-0.5, 0.5);
        ext.push((t[i] + off * dt, b - 0.25 * (a - c) * off));
    }
    if ext.len() < 5 {
        return Err(SignalError(format!(
            "{} extrema in the record: at least five half cycles are needed",
            ext.len()
        )));
    }
    let count: Vec<f64> = (0..ext.len()).map(|i| i as f64).collect();
    let times: Vec<f64> = ext.iter().map(|e| e.0).collect();
    let logs: Vec<f64> = ext.iter().map(|e| e.1.abs().ln()).collect();
    let (_, half_period) = line(&count, &times);
    let (_, slope) = line(&count, &logs);
    let delta = -2.0 * slope;
    Ok(Decay {
        period: 2.0 * half_period,
        damping_ratio: delta / (4.0 * PI * PI + delta * delta).sqrt(),
        cycles: (ext.len() - 1) as f64 / 2.0,
        first_amplitude: ext[0].1.abs(),
        last_amplitude: ext[ext.len() - 1].1.abs(),
    })
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
    // Normal equations, solved by Gaussian elimination with partial pivoting.
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
        let p = (col..m)
            .max_by(|&i, &j| a[i][col].abs().total_cmp(&a[j][col].abs()))
            .unwrap();
        a.swap(col, p);
        if a[col][col].abs() < 1e-12 {
            return Err(SignalError(
                "the frequencies cannot be told apart over this record".into(),
            ));
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
    let (s, c) = (a[1][m] / a[1][1], a[2][m] / a[2][2]);
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
        let d = free_decay(&t, &y, 3.0, 1.2, 0.05).unwrap();
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
        assert!(free_decay(&t, &y, 0.0, 1.25, 0.0).is_err());
    }
}
