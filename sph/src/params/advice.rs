//! Settings that run as given but probably not as meant: what a front end says before it runs them.

use super::SimParams;
use crate::vector::from3;

/// The faces of the tank by axis (x, y, z): the name of its low and high face.
const TANK_FACES: [(&str, &str); 3] = [
    ("the tank's -x wall", "the tank's +x wall"),
    ("the tank's -y wall", "the tank's +y wall"),
    ("the tank's floor", "the tank's roof"),
];
const AXES: [&str; 3] = ["x", "y", "z"];

impl SimParams {
    /// Pressure sensors beside a wall but not on it: within the kernel's reach (2h) of a tank wall or an
    /// obstacle's face, yet more than half a particle spacing from it. Such a sensor reads the liquid's
    /// pressure at its point, not the wall's, and which of the two it reads changes with the spacing (a
    /// sensor 4 mm from a wall is on it at dp 10 mm and off it at 5 mm); next to a wall the incompressible
    /// scheme's liquid particles carry the wall's share of the pressure as well, so there it over-reads.
    /// One sentence per such sensor, naming the face and where on it the sensor would read the wall.
    pub fn sensors_beside_walls(&self) -> Vec<String> {
        let half = 0.5 * self.particle_spacing;
        let reach = 2.0 * self.h();
        let axes: &[usize] = if self.dimension == 2 {
            &[0, 2]
        } else {
            &[0, 1, 2]
        };
        let (lo, hi) = self.tank.inside();
        let mut out = vec![];
        for (i, s) in self.pressure_sensors.iter().enumerate() {
            let at = [s.x, s.y, s.z];
            // The nearest face: (distance, its name, its axis, where it lies along the axis).
            let mut near: Option<(f64, String, usize, f64)> = None;
            let mut consider = |d: f64, face: String, k: usize, plane: f64| {
                if near.as_ref().is_none_or(|n| d < n.0) {
                    near = Some((d, face, k, plane));
                }
            };
            for &k in axes {
                consider(at[k] - lo[k], TANK_FACES[k].0.to_string(), k, lo[k]);
                consider(hi[k] - at[k], TANK_FACES[k].1.to_string(), k, hi[k]);
            }
            for o in &self.obstacles {
                // Outside the obstacle: the face along the axis the sensor is furthest beyond.
                let (k, gap) = axes
                    .iter()
                    .map(|&k| (k, (at[k] - o.centre[k]).abs() - 0.5 * o.size[k]))
                    .max_by(|a, b| a.1.total_cmp(&b.1))
                    .expect("two or three axes");
                let beside = if self.dimension == 2 {
                    o.within::<2>(from3::<f64, 2>(at), reach)
                } else {
                    o.within::<3>(at, reach)
                };
                // (A sensor on the face, within half a spacing of it, reads that face.)
                if gap > -half && beside {
                    let side = (at[k] - o.centre[k]).signum();
                    let plane = o.centre[k] + side * 0.5 * o.size[k];
                    let name = format!("obstacle `{}`'s {}{} face", o.name, sign(side), AXES[k]);
                    consider(gap.max(0.0), name, k, plane);
                }
            }
            if let Some((d, face, k, plane)) = near {
                if d > half && d < reach {
                    out.push(format!(
                        "sensor {i} ({}) is {:.1} mm from {face}, more than half a particle spacing ({:.1} mm): \
                         it reads the liquid's pressure at its point, not the wall's (with `dfsph` that reads \
                         high next to a wall); set pressure_sensors.{} to {plane} to read the wall as a flush \
                         transducer does",
                        s.name,
                        d * 1e3,
                        half * 1e3,
                        AXES[k],
                    ));
                }
            }
        }
        out
    }
}

fn sign(side: f64) -> &'static str {
    if side < 0.0 {
        "-"
    } else {
        "+"
    }
}

#[cfg(test)]
mod tests {
    use crate::params::{RegionSpec, SensorSpec, SimParams, TankSpec};

    /// SPHERIC Test 10's tank (2D, 0.9 m long) with a sensor `inset` from its left wall, 93 mm up.
    fn spheric(dp: f64, inset: f64) -> SimParams {
        let tank = TankSpec {
            length: 0.9,
            breadth: 0.062,
            height: 0.508,
        };
        let mut p = SimParams::filled_tank(2, tank, 0.093, dp);
        p.pressure_sensors = vec![SensorSpec {
            name: "sensor1".into(),
            x: -0.45 + inset,
            y: 0.0,
            z: 0.093,
        }];
        p
    }

    #[test]
    fn a_sensor_beside_a_wall_but_off_it_is_named_with_the_face_it_would_read() {
        let w = spheric(0.004, 0.0039).sensors_beside_walls();
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].contains("sensor1") && w[0].contains("-x wall") && w[0].contains("to -0.45"),
            "{}",
            w[0]
        );
        // At 8 mm the same point is within half a spacing of the wall: it reads the wall.
        assert!(spheric(0.008, 0.0039).sensors_beside_walls().is_empty());
        // On the wall, or in the middle of the liquid: nothing to say.
        assert!(spheric(0.004, 0.0).sensors_beside_walls().is_empty());
        assert!(spheric(0.004, 0.3).sensors_beside_walls().is_empty());
    }

    #[test]
    fn a_sensor_beside_an_obstacle_names_the_obstacle_s_face() {
        let mut p = spheric(0.004, 0.3);
        p.obstacles = vec![RegionSpec {
            name: "step".into(),
            centre: [0.0, 0.0, 0.025],
            size: [0.1, 0.062, 0.05],
        }];
        p.pressure_sensors[0].x = -0.05 - 0.004;
        p.pressure_sensors[0].z = 0.02;
        let w = p.sensors_beside_walls();
        assert_eq!(w.len(), 1, "{w:?}");
        assert!(
            w[0].contains("obstacle `step`'s -x face") && w[0].contains("to -0.05"),
            "{}",
            w[0]
        );
        p.pressure_sensors[0].x = -0.05;
        assert!(p.sensors_beside_walls().is_empty());
    }
}
