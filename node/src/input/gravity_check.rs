//! A plausibility check of the input's frame conventions. A tank on a vessel feels about (0, 0, −g) in its own
//! frame (gravity less the vessel's acceleration, which averages out over seconds). A wrong convention gives
//! something else and the simulation goes on with it: poses read in a NED world with a FLU body frame turn the
//! tank over (gravity points up), an IMU whose accelerometer reads −9.81 m/s² at rest doubles the vessel's
//! acceleration into "up", a gravity-compensated IMU leaves the liquid weightless. The check averages the
//! apparent gravity over the first simulated half second and says once what looks wrong and where to look.

use nalgebra::Vector3;

/// Simulated seconds averaged before the check decides.
const WINDOW_S: f64 = 0.5;

/// What drives the tank, for the advice.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InputKind {
    Pose,
    Imu,
    State,
}

/// The check's running state.
#[derive(Debug, Default)]
pub struct GravityCheck {
    sum: Vector3<f64>,
    n: u32,
    done: bool,
}

impl GravityCheck {
    /// Adds the apparent gravity `g_tank` (tank frame, m/s²) at simulated time `t`; once the window is full,
    /// returns `Some(Ok(()))` if its mean points down within 60° and is at least half of `gravity`, or
    /// `Some(Err(warning))`; `None` before, and after it has decided.
    pub fn add(
        &mut self,
        t: f64,
        g_tank: Vector3<f64>,
        gravity: f64,
        kind: InputKind,
    ) -> Option<Result<(), String>> {
        if self.done || !g_tank.iter().all(|v| v.is_finite()) {
            return None;
        }
        self.sum += g_tank;
        self.n += 1;
        if t < WINDOW_S {
            return None;
        }
        self.done = true;
        let mean = self.sum / self.n as f64;
        let down = -mean.z;
        let norm = mean.norm();
        if down >= 0.5 * gravity && down >= 0.5 * norm {
            return Some(Ok(()));
        }
        let what = if norm < 0.5 * gravity {
            "far less than gravity (the liquid is nearly weightless)".to_string()
        } else if mean.z > 0.0 {
            "pointing up (the tank is upside down for the solver)".to_string()
        } else {
            format!(
                "{:.0}° from the tank's down axis",
                (down / norm).clamp(-1.0, 1.0).acos().to_degrees()
            )
        };
        let advice = match kind {
            InputKind::Imu => format!(
                "sensor_msgs/Imu linear_acceleration must be the specific force with gravity's reaction in it \
                 (+{gravity} m/s² up when at rest, REP 145): a gravity-compensated IMU reads about 0, one with \
                 its z axis or sign flipped -{gravity}; check too input.body_frame (flu or frd) against the \
                 sensor's axes"
            ),
            InputKind::Pose => "check input.world_frame and input.body_frame (enu with flu, ned with frd: \
                 a NED world with a FLU body turns the tank over) and frames.tank_pose"
                .to_string(),
            InputKind::State => "check the frames of the iceoryx2 sender (world ENU, tank FLU, z up) and \
                 frames.tank_pose"
                .to_string(),
        };
        Some(Err(format!(
            "input check: over the first {WINDOW_S} s the apparent gravity in the tank frame averages \
             ({:.2}, {:.2}, {:.2}) m/s², {what}; a tank on a vessel feels about (0, 0, -{gravity}): {advice}. \
             The simulation goes on with the motion as given",
            mean.x, mean.y, mean.z
        )))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run(g: Vector3<f64>, kind: InputKind) -> Result<(), String> {
        let mut c = GravityCheck::default();
        let mut out = None;
        for k in 0..=30 {
            let t = k as f64 * 0.02;
            if let Some(r) = c.add(t, g, 9.81, kind) {
                assert!(out.is_none(), "decides once");
                out = Some(r);
            }
        }
        out.expect("decides after the window")
    }

    #[test]
    fn a_tank_feeling_gravity_down_passes_and_the_wrong_conventions_are_named() {
        // Upright, heeled 30° with some heave: fine.
        assert!(run(Vector3::new(0.0, 0.0, -9.81), InputKind::Pose).is_ok());
        let heeled = Vector3::new(0.0, 9.81 * 0.5, -9.81 * 0.87) * 1.2;
        assert!(run(heeled, InputKind::Imu).is_ok());
        // Upside down (NED world, FLU body).
        let e = run(Vector3::new(0.0, 0.0, 9.81), InputKind::Pose).unwrap_err();
        assert!(
            e.contains("pointing up") && e.contains("input.world_frame"),
            "{e}"
        );
        // An IMU reading -9.81 at rest: the tank's acceleration is -2 g, its apparent gravity +g.
        let e = run(Vector3::new(0.0, 0.0, 9.81), InputKind::Imu).unwrap_err();
        assert!(e.contains("pointing up") && e.contains("REP 145"), "{e}");
        // A gravity-compensated IMU.
        let e = run(Vector3::new(0.01, 0.0, -0.02), InputKind::Imu).unwrap_err();
        assert!(e.contains("nearly weightless"), "{e}");
        // On its side.
        let e = run(Vector3::new(9.81, 0.0, -1.0), InputKind::State).unwrap_err();
        assert!(e.contains("84° from the tank's down axis"), "{e}");
    }

    #[test]
    fn non_finite_readings_are_left_out() {
        let mut c = GravityCheck::default();
        assert_eq!(
            c.add(1.0, Vector3::new(f64::NAN, 0.0, 0.0), 9.81, InputKind::Pose),
            None
        );
        assert_eq!(
            c.add(1.0, Vector3::new(0.0, 0.0, -9.81), 9.81, InputKind::Pose),
            Some(Ok(()))
        );
    }
}
