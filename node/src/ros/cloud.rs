//! The liquid's particles as a sensor_msgs/PointCloud2 for RViz and Foxglove: x, y, z (tank frame, m) and
//! speed (m/s, relative to the tank), float32 little endian, every `decimation`-th particle.

use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::sensor_msgs::{PointCloud2, PointField};
use slosh_msgs::std_msgs::Header;

/// Bytes per point: four float32.
const POINT_STEP: u32 = 16;

/// A cloud of every `decimation`-th particle (1 = all).
pub fn particle_cloud(
    stamp: Time,
    frame: &str,
    positions: &[[f64; 3]],
    velocities: &[[f64; 3]],
    decimation: usize,
) -> PointCloud2 {
    let step = decimation.max(1);
    let n = positions.len().div_ceil(step);
    let mut data = Vec::with_capacity(n * POINT_STEP as usize);
    for (p, v) in positions.iter().zip(velocities).step_by(step) {
        let speed = (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]).sqrt();
        for value in [p[0], p[1], p[2], speed] {
            data.extend_from_slice(&(value as f32).to_le_bytes());
        }
    }
    let width = (data.len() / POINT_STEP as usize) as u32;
    PointCloud2 {
        header: Header {
            stamp,
            frame_id: frame.to_string(),
        },
        height: 1,
        width,
        fields: ["x", "y", "z", "speed"]
            .iter()
            .enumerate()
            .map(|(i, name)| PointField::new(*name, 4 * i as u32, PointField::FLOAT32, 1))
            .collect(),
        is_bigendian: false,
        point_step: POINT_STEP,
        row_step: POINT_STEP * width,
        data,
        is_dense: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn points_decode_from_the_declared_layout() {
        let pos = [[0.1, 0.0, 0.2], [0.3, 0.0, 0.4], [0.5, 0.0, 0.6]];
        let vel = [[3.0, 0.0, 4.0], [0.0; 3], [1.0, 0.0, 0.0]];
        let c = particle_cloud(Time::from_secs_f64(1.5), "tank", &pos, &vel, 2);
        assert_eq!((c.width, c.height, c.row_step), (2, 1, 32));
        assert_eq!(c.data.len(), (c.row_step * c.height) as usize);
        let field = |name: &str| c.fields.iter().find(|f| f.name == name).unwrap().offset as usize;
        let read = |i: usize, name: &str| {
            let o = i * c.point_step as usize + field(name);
            f32::from_le_bytes(c.data[o..o + 4].try_into().unwrap())
        };
        assert_eq!(
            (read(0, "x"), read(0, "z"), read(0, "speed")),
            (0.1, 0.2, 5.0)
        );
        assert_eq!(
            (read(1, "x"), read(1, "z"), read(1, "speed")),
            (0.5, 0.6, 1.0)
        );
        assert!(c
            .fields
            .iter()
            .all(|f| f.datatype == PointField::FLOAT32 && f.count == 1));
    }
}
