//! `builtin_interfaces`: [`Time`] and [`Duration`].

use serde::{Deserialize, Serialize};

use crate::message::ros_message;

const NANOS_PER_SEC: i64 = 1_000_000_000;

/// Splits seconds into whole seconds (rounded down, so negative values count back from the
/// previous whole second) and nanoseconds in `[0, 1e9)`, rounded to the nearest nanosecond.
/// Saturates outside the `i32` range of seconds; NaN gives zero.
fn split_secs_f64(t: f64) -> (i32, u32) {
    if t.is_nan() {
        return (0, 0);
    }
    let whole = t.floor();
    if whole < f64::from(i32::MIN) {
        return (i32::MIN, 0);
    }
    if whole > f64::from(i32::MAX) {
        return (i32::MAX, 999_999_999);
    }
    // `t - whole` is exact, so the fraction loses nothing before the rounding.
    let nanos = ((t - whole) * 1e9).round();
    // In range: checked above, and the rounded fraction is in [0, 1e9].
    let (sec, nanos) = (whole as i32, nanos as u32);
    if nanos >= 1_000_000_000 {
        match sec.checked_add(1) {
            Some(sec) => (sec, 0),
            None => (i32::MAX, 999_999_999),
        }
    } else {
        (sec, nanos)
    }
}

/// Splits nanoseconds into whole seconds (rounded down) and nanoseconds in `[0, 1e9)`,
/// saturating outside the `i32` range of seconds.
fn split_nanos(nanos: i64) -> (i32, u32) {
    let sec = nanos.div_euclid(NANOS_PER_SEC);
    // rem_euclid is in [0, 1e9), so it fits in u32.
    let sub = nanos.rem_euclid(NANOS_PER_SEC) as u32;
    match i32::try_from(sec) {
        Ok(sec) => (sec, sub),
        Err(_) if sec < 0 => (i32::MIN, 0),
        Err(_) => (i32::MAX, 999_999_999),
    }
}

/// Conversions of a `sec` + `nanosec` pair (Time and Duration share them).
macro_rules! seconds_and_nanoseconds {
    ($t:ident, $what:literal) => {
        impl $t {
            #[doc = concat!("The ", $what, " `t` seconds, rounded to the nearest nanosecond, saturating")]
            /// outside the range of `i32` seconds (NaN gives zero).
            pub fn from_secs_f64(t: f64) -> Self {
                let (sec, nanosec) = split_secs_f64(t);
                Self { sec, nanosec }
            }

            #[doc = concat!("The ", $what, " in seconds.")]
            pub fn as_secs_f64(&self) -> f64 {
                f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
            }

            #[doc = concat!("The ", $what, " `nanos` nanoseconds, saturating outside the range of `i32` seconds.")]
            pub fn from_nanos(nanos: i64) -> Self {
                let (sec, nanosec) = split_nanos(nanos);
                Self { sec, nanosec }
            }

            #[doc = concat!("The ", $what, " in nanoseconds.")]
            pub fn as_nanos(&self) -> i64 {
                i64::from(self.sec) * NANOS_PER_SEC + i64::from(self.nanosec)
            }
        }
    };
}

/// `builtin_interfaces/msg/Time`: a point in ROS time, `sec + nanosec·1e-9` seconds.
///
/// `nanosec` is in `[0, 1e9)` also for negative times: −0.25 s is `sec = −1, nanosec =
/// 750_000_000`. The derived ordering is chronological for such normalized values.
#[derive(
    Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default,
)]
pub struct Time {
    /// Whole seconds (rounded down).
    pub sec: i32,
    /// Nanoseconds after `sec`, in `[0, 1e9)`.
    pub nanosec: u32,
}

seconds_and_nanoseconds!(Time, "time");

/// `builtin_interfaces/msg/Duration`: a span of ROS time, `sec + nanosec·1e-9` seconds.
///
/// `nanosec` is in `[0, 1e9)` also for negative durations, as for [`Time`].
#[derive(
    Serialize, Deserialize, Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord, Default,
)]
pub struct Duration {
    /// Whole seconds (rounded down).
    pub sec: i32,
    /// Nanoseconds after `sec`, in `[0, 1e9)`.
    pub nanosec: u32,
}

seconds_and_nanoseconds!(Duration, "duration");

ros_message!(Time, "builtin_interfaces", "Time", TIME_MSG, []);
ros_message!(Duration, "builtin_interfaces", "Duration", DURATION_MSG, []);

// The interface files of ROS 2 Jazzy, verbatim.

const TIME_MSG: &str = r#"# This message communicates ROS Time defined here:
# https://design.ros2.org/articles/clock_and_time.html

# The seconds component, valid over all int32 values.
int32 sec

# The nanoseconds component, valid in the range [0, 1e9).
uint32 nanosec
"#;

const DURATION_MSG: &str = r#"# Duration defines a period between two time points.
# Messages of this datatype are of ROS Time following this design:
# https://design.ros2.org/articles/clock_and_time.html

# Seconds component, range is valid over any possible int32 value.
int32 sec

# Nanoseconds component in the range of [0, 1e9).
uint32 nanosec
"#;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn from_secs_f64_keeps_nanosec_in_range() {
        // (t, sec, nanosec, allowed nanosec error)
        let cases: [(f64, i32, u32, u32); 9] = [
            (0.0, 0, 0, 0),
            (1.5, 1, 500_000_000, 0),
            (-0.25, -1, 750_000_000, 0),
            (-1.0, -1, 0, 0),
            (-2.000_000_000_1, -2, 0, 0),
            // f64 resolution at 1.7e9 s is about 238 ns.
            (1_700_000_000.123_456_7, 1_700_000_000, 123_456_700, 240),
            (0.999_999_999_9, 1, 0, 0),
            (-0.000_000_000_1, 0, 0, 0),
            (f64::NAN, 0, 0, 0),
        ];
        for (t, sec, nanosec, tol) in cases {
            let time = Time::from_secs_f64(t);
            assert!(time.nanosec < 1_000_000_000, "{t}: {time:?}");
            assert_eq!(time.sec, sec, "{t}");
            assert!(time.nanosec.abs_diff(nanosec) <= tol, "{t}: {time:?}");
        }
    }

    #[test]
    fn round_trips_through_seconds_and_nanoseconds() {
        for t in [-1234.5678, -0.5, -1e-9, 0.0, 3e-9, 0.25, 86_400.000_001] {
            let time = Time::from_secs_f64(t);
            assert!(
                (time.as_secs_f64() - t).abs() < 1e-9 * (1.0 + t.abs()),
                "{t}"
            );
            assert_eq!(Time::from_nanos(time.as_nanos()), time);
            let d = Duration::from_secs_f64(t);
            assert_eq!((d.sec, d.nanosec), (time.sec, time.nanosec));
            assert_eq!(Duration::from_nanos(d.as_nanos()), d);
        }
        assert_eq!(
            Time::from_nanos(-1),
            Time {
                sec: -1,
                nanosec: 999_999_999
            }
        );
        assert!(Time::from_secs_f64(-0.5) < Time::from_secs_f64(-0.25));
    }

    #[test]
    fn saturates_outside_i32_seconds() {
        assert_eq!(
            Time::from_secs_f64(1e12),
            Time {
                sec: i32::MAX,
                nanosec: 999_999_999
            }
        );
        assert_eq!(
            Time::from_secs_f64(-1e12),
            Time {
                sec: i32::MIN,
                nanosec: 0
            }
        );
        assert_eq!(Time::from_secs_f64(f64::INFINITY).sec, i32::MAX);
        assert_eq!(Time::from_secs_f64(f64::NEG_INFINITY).sec, i32::MIN);
        assert_eq!(Time::from_nanos(i64::MAX).sec, i32::MAX);
        assert_eq!(Time::from_nanos(i64::MIN).sec, i32::MIN);
        let max = Time::from_secs_f64(f64::from(i32::MAX) + 0.999_999_999_9);
        assert_eq!(
            max,
            Time {
                sec: i32::MAX,
                nanosec: 999_999_999
            }
        );
    }
}
