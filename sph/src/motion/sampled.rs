//! Motion from time-stamped 6-DOF samples (a CSV file, a recording), interpolated by a natural cubic spline
//! per coordinate so that velocity and acceleration are continuous. Angles are unwrapped first.

use super::{Dof6, Dof6Motion};
use std::f64::consts::PI;

#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SampleError {
    #[error("need at least 2 samples, got {0}")]
    TooFew(usize),
    #[error("sample {index}: {what} is not a finite number")]
    NotFinite { index: usize, what: &'static str },
    #[error("sample {index}: time {time} s is not after the previous sample's {previous} s (times must increase strictly)")]
    NotIncreasing {
        index: usize,
        time: f64,
        previous: f64,
    },
}

/// One cubic spline: knots and second derivatives.
#[derive(Clone, Debug)]
struct Spline {
    y: Vec<f64>,
    m: Vec<f64>,
}

impl Spline {
    /// Natural spline (zero curvature at the ends) through (t, y).
    fn new(t: &[f64], y: Vec<f64>) -> Self {
        let n = t.len();
        let mut m = vec![0.0; n];
        if n > 2 {
            // Tridiagonal system for the interior second derivatives (Thomas algorithm).
            let mut c = vec![0.0; n];
            let mut d = vec![0.0; n];
            for i in 1..n - 1 {
                let h0 = t[i] - t[i - 1];
                let h1 = t[i + 1] - t[i];
                let a = h0 / 6.0;
                let b = (h0 + h1) / 3.0;
                let cc = h1 / 6.0;
                let rhs = (y[i + 1] - y[i]) / h1 - (y[i] - y[i - 1]) / h0;
                let denom = b - a * c[i - 1];
                c[i] = cc / denom;
                d[i] = (rhs - a * d[i - 1]) / denom;
            }
            for i in (1..n - 1).rev() {
                m[i] = d[i] - c[i] * m[i + 1];
            }
        }
        Self { y, m }
    }

    /// (value, first, second derivative) in interval i at t.
    fn eval(&self, t: &[f64], i: usize, x: f64) -> (f64, f64, f64) {
        let h = t[i + 1] - t[i];
        let a = (t[i + 1] - x) / h;
        let b = (x - t[i]) / h;
        let (m0, m1, y0, y1) = (self.m[i], self.m[i + 1], self.y[i], self.y[i + 1]);
        let v = a * y0 + b * y1 + ((a * a * a - a) * m0 + (b * b * b - b) * m1) * h * h / 6.0;
        let d1 =
            (y1 - y0) / h - (3.0 * a * a - 1.0) / 6.0 * h * m0 + (3.0 * b * b - 1.0) / 6.0 * h * m1;
        let d2 = a * m0 + b * m1;
        (v, d1, d2)
    }
}

/// 6-DOF samples interpolated smoothly; before the first sample and after the last the pose is held still.
#[derive(Clone, Debug)]
pub struct SampledMotion {
    t: Vec<f64>,
    splines: Vec<Spline>,
}

impl SampledMotion {
    /// `times` in s, `poses` as x, y, z (m), roll, pitch, yaw (rad).
    pub fn new(times: Vec<f64>, poses: &[[f64; 6]]) -> Result<Self, SampleError> {
        if times.len() < 2 || poses.len() != times.len() {
            return Err(SampleError::TooFew(times.len().min(poses.len())));
        }
        const NAMES: [&str; 6] = ["x", "y", "z", "roll", "pitch", "yaw"];
        for (i, (t, p)) in times.iter().zip(poses).enumerate() {
            if !t.is_finite() {
                return Err(SampleError::NotFinite {
                    index: i,
                    what: "time",
                });
            }
            for (k, v) in p.iter().enumerate() {
                if !v.is_finite() {
                    return Err(SampleError::NotFinite {
                        index: i,
                        what: NAMES[k],
                    });
                }
            }
            if i > 0 && *t <= times[i - 1] {
                return Err(SampleError::NotIncreasing {
                    index: i,
                    time: *t,
                    previous: times[i - 1],
                });
            }
        }
        let splines = (0..6)
            .map(|k| {
                let mut y: Vec<f64> = poses.iter().map(|p| p[k]).collect();
                if k >= 3 {
                    for i in 1..y.len() {
                        let turns = ((y[i] - y[i - 1]) / (2.0 * PI)).round();
                        y[i] -= turns * 2.0 * PI;
                    }
                }
                Spline::new(&times, y)
            })
            .collect();
        Ok(Self { t: times, splines })
    }

    pub fn start_time(&self) -> f64 {
        self.t[0]
    }
}

impl Dof6Motion for SampledMotion {
    fn dof(&self, x: f64) -> Dof6 {
        let n = self.t.len();
        let mut d = Dof6::default();
        if x <= self.t[0] || x >= self.t[n - 1] {
            let idx = if x <= self.t[0] { 0 } else { n - 1 };
            for k in 0..6 {
                d.q[k] = self.splines[k].y[idx];
            }
            return d;
        }
        let i = self
            .t
            .partition_point(|&v| v <= x)
            .saturating_sub(1)
            .min(n - 2);
        for k in 0..6 {
            let (v, d1, d2) = self.splines[k].eval(&self.t, i, x);
            d.q[k] = v;
            d.dq[k] = d1;
            d.ddq[k] = d2;
        }
        d
    }

    fn end_time(&self) -> f64 {
        self.t[self.t.len() - 1]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn spline_reproduces_a_smooth_signal_and_its_derivatives() {
        let times: Vec<f64> = (0..=400).map(|i| i as f64 * 0.025).collect();
        let poses: Vec<[f64; 6]> = times
            .iter()
            .map(|&t| {
                [
                    0.1 * (2.0 * t).sin(),
                    0.0,
                    5000.0 + 3.0 * t,
                    0.0,
                    0.05 * t.cos(),
                    0.0,
                ]
            })
            .collect();
        let m = SampledMotion::new(times, &poses).unwrap();
        for &t in &[1.013, 3.5, 7.777] {
            let d = m.dof(t);
            assert!((d.q[0] - 0.1 * (2.0 * t).sin()).abs() < 1e-6);
            assert!((d.dq[0] - 0.2 * (2.0 * t).cos()).abs() < 1e-4);
            assert!((d.ddq[0] + 0.4 * (2.0 * t).sin()).abs() < 2e-3);
            assert!((d.q[2] - (5000.0 + 3.0 * t)).abs() < 1e-9);
            assert!((d.dq[2] - 3.0).abs() < 1e-9);
            assert!((d.q[4] - 0.05 * t.cos()).abs() < 1e-6);
        }
        assert_eq!(m.end_time(), 10.0);
    }

    #[test]
    fn bad_samples_are_rejected_with_their_index() {
        let p = [[0.0; 6]; 3];
        assert_eq!(
            SampledMotion::new(vec![0.0, 1.0, 1.0], &p).unwrap_err(),
            SampleError::NotIncreasing {
                index: 2,
                time: 1.0,
                previous: 1.0
            }
        );
        let mut q = p;
        q[1][3] = f64::NAN;
        assert_eq!(
            SampledMotion::new(vec![0.0, 1.0, 2.0], &q).unwrap_err(),
            SampleError::NotFinite {
                index: 1,
                what: "roll"
            }
        );
        assert!(matches!(
            SampledMotion::new(vec![0.0], &p[..1]),
            Err(SampleError::TooFew(1))
        ));
    }

    #[test]
    fn angles_are_unwrapped() {
        let times = vec![0.0, 1.0, 2.0, 3.0];
        let poses = [
            [0.0, 0.0, 0.0, 0.0, 0.0, 3.0],
            [0.0, 0.0, 0.0, 0.0, 0.0, 3.1],
            [0.0, 0.0, 0.0, 0.0, 0.0, -3.1],
            [0.0, 0.0, 0.0, 0.0, 0.0, -3.0],
        ];
        let m = SampledMotion::new(times, &poses).unwrap();
        assert!(m.dof(1.5).q[5] > 3.1 && m.dof(1.5).q[5] < 3.2);
    }
}
