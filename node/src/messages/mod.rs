//! The messages of the program's outputs, built from observations and states with no transport: the DDS node,
//! the MCAP recorder and the replay publish and record the same messages. `convert` holds the conversions
//! between nalgebra values and geometry message fields, `motion` the motion messages of a rigid state.

pub mod convert;
pub mod motion;

use crate::config::Loaded;
use convert::{quat_msg, vec3_msg};
use nalgebra::UnitQuaternion;
use slosh_msgs::builtin_interfaces::Time;
use slosh_msgs::geometry_msgs::{Point, Transform, TransformStamped, Wrench, WrenchStamped};
use slosh_msgs::nav_msgs::Odometry;
use slosh_msgs::slosh_msgs::{PressureArray, ProbeArray};
use slosh_msgs::std_msgs::Header;
use slosh_msgs::tf2_msgs::TFMessage;
use sph::params::SimParams;

/// A header at `stamp` in `frame`.
pub fn header(stamp: Time, frame: &str) -> Header {
    Header {
        stamp,
        frame_id: frame.to_string(),
    }
}

fn point(x: f64, y: f64, z: f64) -> Point {
    Point { x, y, z }
}

/// Outputs of one observed state as messages.
pub struct OutputMessages {
    pub wrench: WrenchStamped,
    pub probes: ProbeArray,
    pub pressures: PressureArray,
    /// Per floating body: its motion and the liquid's force on it.
    pub bodies: Vec<BodyMessages>,
}

/// A floating body's outputs: `bodies/NAME/odom` (the pose of its centre of gravity in the tank frame, the
/// twist in its own axes, as nav_msgs/Odometry has it) and `bodies/NAME/wrench` (the liquid's force and
/// moment about the centre of gravity, tank axes).
pub struct BodyMessages {
    pub name: String,
    pub odom: Odometry,
    pub wrench: WrenchStamped,
}

/// The topic of a body's output `what` (`odom` or `wrench`) beside the tank's outputs.
pub fn body_topic(name: &str, what: &str) -> String {
    format!("bodies/{name}/{what}")
}

fn body_messages(tank_frame: &str, stamp: Time, b: &sph::body::BodyState) -> BodyMessages {
    let q = b.quaternion;
    let rot = UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q[3], q[0], q[1], q[2]));
    let state = sph::motion::RigidState {
        position: b.position.into(),
        orientation: rot,
        velocity: b.velocity.into(),
        angular_velocity: rot.inverse_transform_vector(&b.angular_velocity.into()),
        ..sph::motion::RigidState::at_rest()
    };
    BodyMessages {
        name: b.name.clone(),
        odom: motion::odometry(&state, stamp, tank_frame, &b.name),
        wrench: WrenchStamped {
            header: header(stamp, tank_frame),
            wrench: Wrench {
                force: vec3_msg(b.force.into()),
                torque: vec3_msg(b.moment.into()),
            },
        },
    }
}

/// Builds the output messages of an observation at `stamp`.
pub fn output_messages(
    params: &SimParams,
    tank_frame: &str,
    stamp: Time,
    o: &sph::observe::Observation,
) -> OutputMessages {
    OutputMessages {
        wrench: WrenchStamped {
            header: header(stamp, tank_frame),
            wrench: Wrench {
                force: vec3_msg(o.wrench.force.into()),
                torque: vec3_msg(o.wrench.moment.into()),
            },
        },
        probes: ProbeArray {
            header: header(stamp, tank_frame),
            names: params.probes.iter().map(|p| p.name.clone()).collect(),
            positions: params.probes.iter().map(|p| point(p.x, p.y, 0.0)).collect(),
            elevations: o.probes.clone(),
        },
        pressures: PressureArray {
            header: header(stamp, tank_frame),
            names: params
                .pressure_sensors
                .iter()
                .map(|s| s.name.clone())
                .collect(),
            positions: params
                .pressure_sensors
                .iter()
                .map(|s| point(s.x, s.y, s.z))
                .collect(),
            pressures: o.pressures.clone(),
        },
        bodies: o
            .bodies
            .iter()
            .map(|b| body_messages(tank_frame, stamp, b))
            .collect(),
    }
}

/// The static transforms vessel → tank → each probe and sensor.
pub fn static_transforms(cfg: &Loaded, params: &SimParams, stamp: Time) -> TFMessage {
    let f = &cfg.config.frames;
    let tp = f.tank_pose;
    let q = UnitQuaternion::from_euler_angles(tp.roll, tp.pitch, tp.yaw);
    let tf = |parent: &str, child: String, t: [f64; 3], q: UnitQuaternion<f64>| TransformStamped {
        header: header(stamp, parent),
        child_frame_id: child,
        transform: Transform {
            translation: vec3_msg(t.into()),
            rotation: quat_msg(q),
        },
    };
    let mut transforms = vec![tf(&f.vessel, f.tank.clone(), [tp.x, tp.y, tp.z], q)];
    for p in &params.probes {
        transforms.push(tf(
            &f.tank,
            format!("{}/probe/{}", f.tank, p.name),
            [p.x, p.y, 0.0],
            UnitQuaternion::identity(),
        ));
    }
    for s in &params.pressure_sensors {
        transforms.push(tf(
            &f.tank,
            format!("{}/pressure/{}", f.tank, s.name),
            [s.x, s.y, s.z],
            UnitQuaternion::identity(),
        ));
    }
    TFMessage { transforms }
}
