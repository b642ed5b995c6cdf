//! `slosh motion`.

use super::*;

#[derive(clap::Args)]
pub struct Args {
    /// Config file or built-in case whose `motion.*` parameters give the motion.
    pub config: String,
    /// Samples per second.
    #[arg(long, default_value_t = 50.0)]
    pub rate: f64,
    /// Seconds of motion.
    #[arg(long, value_parser = positive_seconds, default_value_t = 10.0)]
    pub duration: f64,
    /// Also publish geometry_msgs/PoseStamped on `motion/pose`.
    #[arg(long)]
    pub pose: bool,
    /// Also publish sensor_msgs/Imu on `motion/imu` (an IMU at the vessel's origin).
    #[arg(long)]
    pub imu: bool,
    /// Also publish geometry_msgs/AccelStamped on `motion/accel` (body frame).
    #[arg(long)]
    pub accel: bool,
    /// Wait for this many subscribers on `motion/odom` before the first sample.
    #[arg(long, default_value_t = 0)]
    pub wait_for_subscribers: usize,
    /// Stay a few samples ahead of the simulation's `/clock` instead of pacing by the wall clock
    /// (for `realtime.mode: lockstep`).
    #[arg(long)]
    pub lockstep: bool,
    /// Stamp of the first sample in seconds since the epoch (default: now).
    #[arg(long, allow_negative_numbers = true)]
    pub start_stamp: Option<f64>,
    /// Publish `slosh::MotionSample`s on the iceoryx2 service NAME/motion instead of DDS (for a node
    /// with `input.type: iceoryx2`).
    #[arg(long, value_name = "NAME")]
    iceoryx2: Option<String>,
    /// Parameter overrides of the case, KEY=VALUE (with --iceoryx2; over DDS use --ros-args -p).
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
    /// ROS arguments (`--ros-args -r __ns:=/ship1 ...`).
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub args: Vec<String>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args {
        config: cfg,
        rate,
        duration,
        pose,
        imu,
        accel,
        wait_for_subscribers,
        lockstep,
        start_stamp,
        iceoryx2,
        set,
        args,
    } = a;
    let (plain, ros_args) = ros::args::parse(&args)?;
    if !plain.is_empty() {
        anyhow::bail!("unexpected arguments {plain:?}: ROS arguments go after --ros-args");
    }
    let opts = crate::motion_source::MotionOptions {
        rate_hz: rate,
        duration,
        pose,
        imu,
        accel,
        wait_for_subscribers,
        lockstep,
        start_stamp,
    };
    match iceoryx2 {
        Some(service) => crate::iox::motion_pub::run(&cfg, &set, &service, &opts)?,
        None => {
            if !set.is_empty() {
                anyhow::bail!("--set goes with --iceoryx2; over DDS give parameters as --ros-args -p KEY:=VALUE");
            }
            ros::motion_pub::run(&ros_args, &cfg, &opts)?
        }
    }
    Ok(())
}
