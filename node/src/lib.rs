//! The `slosh` command's library: configuration, motion sources, the offline runner, outputs and benchmarks.
//! The ROS 2 node will live here too; the binary stays a thin layer over these modules.

pub mod bench;
pub mod config;
pub mod motion_source;
pub mod output;
pub mod runner;
