//! Motion as it comes in, before the solver sees it: the frame conventions of incoming poses (`frames`), the
//! checks and the motion a sample stream makes (`live_motion` for poses, `live_imu` for IMU readings,
//! `live_state` and `sample` for full states), what a received message says (`live`), and the check that
//! the frame conventions match gravity (`gravity_check`). No transport: the DDS node, the replay of a bag and
//! the iceoryx2 coupling server feed it alike.

pub mod frames;
pub mod gravity_check;
pub mod live;
pub mod live_imu;
pub mod live_motion;
pub mod live_state;
pub mod sample;
