//! `slosh node`.

use super::*;

#[derive(clap::Args)]
pub struct Args {
    /// Stop after this many simulated seconds (default: run until SIGINT/SIGTERM).
    #[arg(long, value_parser = positive_seconds)]
    pub duration: Option<f64>,
    /// ROS arguments (`--ros-args ...`); a plain first argument names the parameters file or built-in case.
    #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
    pub args: Vec<String>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args { duration, args } = a;
    let (plain, ros_args) = ros::args::parse(&args)?;
    if plain.len() > 1 {
        anyhow::bail!(
            "unexpected arguments {:?}: ROS arguments go after --ros-args",
            &plain[1..]
        );
    }
    ros::node::run(
        &ros_args,
        plain.first().map(String::as_str),
        &ros::node::NodeOptionsCli { duration },
    )?;
    Ok(())
}
