//! The `slosh` command's library: configuration, motion sources, the offline runner, outputs and benchmarks,
//! and the ROS 2 node and motion publisher (`ros`); the binary stays a thin layer over these modules.
// Component loops over the const-generic dimension read as the formulas do; `!(x >= 0.0)` is used on purpose
// to catch NaN along with negatives.
#![allow(clippy::needless_range_loop, clippy::neg_cmp_op_on_partial_ord)]

pub mod accuracy;
pub mod bag;
pub mod bench;
pub mod cli;
pub mod config;
pub mod drive;
pub mod input;
pub mod iox;
pub mod manual;
pub mod mcap_bounds;
pub mod memory;
pub mod messages;
pub mod motion_source;
pub mod output;
pub mod param_file;
pub mod plot;
pub mod record;
pub mod render;
pub mod replay;
pub mod resolution;
pub mod ros;
pub mod runner;
pub mod signals;
pub mod sinks;
pub mod snapshot;
pub mod transport_bench;
