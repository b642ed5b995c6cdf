//! The `slosh` command line: the commands and their options (clap), one file per command, each a thin layer
//! over the library. `main.rs` only calls [`main`].

mod bag;
mod bench;
mod bench_transport;
mod couple;
mod motion;
mod node;
mod plot;
mod render;
mod replay;
mod run;

use crate::snapshot::{SnapshotFrame, SnapshotOptions};
use crate::{config, ros, runner};
use clap::{Parser, Subcommand};
use std::path::PathBuf;

/// Sloshing of a liquid in a moving tank, by SPH.
#[derive(Parser)]
#[command(name = "slosh", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run a case headless and write probes.csv, wrench.csv, pressure.csv and summary.json.
    Run(run::Args),
    /// Replay the vessel motion recorded in a rosbag2 MCAP bag through a case: the outputs of `slosh run`
    /// (CSV) and a new bag with the motion and every output.
    Replay(replay::Args),
    /// Draw a run's outputs as PNG and SVG figures in DIR/plots: probe elevations (fill level marked), the
    /// six wrench components, pressure sensors; --reference overlays measured or analytic data.
    Plot(plot::Args),
    /// Turn a run's particle frames (`--snapshots`) into PNG pictures and an animated GIF in DIR/render.
    Render(render::Args),
    /// Serve the case to a co-simulation over iceoryx2 (shared memory): each request is the vessel's state at
    /// the sender's time t, each answer the liquid's wrench, probes and pressures at t.
    Couple(couple::Args),
    /// Time the benchmark cases: particle-steps per second and real-time factor.
    Bench(bench::Args),
    /// Time the transports without the physics: coupling round trips and particle frames over iceoryx2 and
    /// over DDS on loopback (run DDS inside `unshare -rn` to keep its discovery traffic on this machine).
    BenchTransport(bench_transport::Args),
    /// Work on recorded bags.
    Bag(bag::Args),
    /// Run as a ROS 2 node: `slosh node --ros-args --params-file CASE.yaml [-p name:=value] [-r from:=to] [--log-level LEVEL]`.
    Node(node::Args),
    /// Publish synthetic vessel motion (the config's `motion.*`) as nav_msgs/Odometry on `motion/odom`.
    Motion(motion::Args),
}

/// Parses the command line and runs the command. Errors are the user's to act on: printed as one line of
/// causes (`a: b: c`), never with a backtrace (even where `RUST_BACKTRACE` is set; panics keep theirs), exit
/// status 1.
pub fn main() -> std::process::ExitCode {
    match run(Cli::parse()) {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("Error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> anyhow::Result<()> {
    // Started by mpirun without MPI support, every rank would run the whole case on its own, all writing the
    // same outputs.
    #[cfg(not(feature = "mpi"))]
    if let Some(n) = crate::memory::mpi_world_size().filter(|n| *n > 1) {
        anyhow::bail!("started as one of {n} MPI ranks, but this slosh was built without MPI: build it with `cargo build --release -p slosh-node --features mpi` (see the manual's MPI page, docs/src/guide/mpi.md), or run it without mpirun");
    }
    // Under mpirun every rank runs this binary: rank 0 goes on with the command (its simulations spread
    // over all ranks), the others follow its solver calls until it is done.
    #[cfg(feature = "mpi")]
    let _lead = match sph::distributed::mpi::start(|| {
        // mpirun passes SIGINT/SIGTERM to every rank; rank 0 finishes its outputs, then releases the
        // others: here the signals only set a flag nobody reads.
        let _ = crate::signals::shutdown_flag();
    })
    .map_err(anyhow::Error::msg)?
    {
        sph::distributed::mpi::Role::Follow => return Ok(()),
        sph::distributed::mpi::Role::Lead(l) => {
            if l.ranks() > 1 {
                eprintln!("slosh: MPI with {} ranks", l.ranks());
            }
            l
        }
    };
    match cli.command {
        Command::Run(a) => run::run(a),
        Command::Replay(a) => replay::run(a),
        Command::Plot(a) => plot::run(a),
        Command::Render(a) => render::run(a),
        Command::Couple(a) => couple::run(a),
        Command::Bench(a) => bench::run(a),
        Command::BenchTransport(a) => bench_transport::run(a),
        Command::Bag(a) => bag::run(a),
        Command::Node(a) => node::run(a),
        Command::Motion(a) => motion::run(a),
    }
}

/// Pictures and particle frames of a run.
#[derive(clap::Args)]
pub struct Visuals {
    /// Write particle frames for ParaView at this many per simulated second: OUT/snapshots/run.pvd and
    /// frame_NNNNNN.vtu (position, velocity, pressure, density, fluid flag, id).
    #[arg(long, value_name = "HZ")]
    pub snapshots: Option<f64>,
    /// The frame of the particle frames: the tank's, or the world's (moved with the tank).
    #[arg(long, value_enum, default_value_t = SnapshotFrame::Tank)]
    pub snapshot_frame: SnapshotFrame,
    /// Draw the figures of `slosh plot` into OUT/plots when the run ends.
    #[arg(long)]
    pub plot: bool,
}

impl Visuals {
    pub(crate) fn snapshots(&self, out: &std::path::Path) -> Option<SnapshotOptions> {
        self.snapshots.map(|rate_hz| SnapshotOptions {
            rate_hz,
            frame: self.snapshot_frame,
            dir: out.join("snapshots"),
        })
    }

    /// Draws the run's figures if asked to (also after a run that stopped early: the outputs so far).
    pub(crate) fn plot_after<T>(
        &self,
        out: &std::path::Path,
        run: anyhow::Result<T>,
    ) -> anyhow::Result<T> {
        if self.plot && out.join("probes.csv").exists() {
            match crate::plot::plot(out, &crate::plot::PlotOptions::default()) {
                Ok(p) => eprintln!(
                    "slosh: figures in {}/plots ({} files)",
                    out.display(),
                    p.files.len()
                ),
                Err(e) if run.is_ok() => return Err(anyhow::anyhow!("plotting: {e}")),
                Err(e) => eprintln!("slosh: plotting: {e}"),
            }
        }
        run
    }
}

#[derive(Subcommand)]
pub enum BagCommand {
    /// Make a whole bag from an unfinished or damaged one (e.g. after the recorder was killed): every message
    /// of its complete chunks goes into a new bag folder.
    Repair {
        /// The damaged bag folder or .mcap file.
        bag: PathBuf,
        /// The new bag folder (default: BAG_repaired).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// The output files a run wrote into `out`, as `out/{a.csv, b.csv, ...}`.
pub(crate) fn outputs(out: &std::path::Path) -> String {
    let written: Vec<&str> = [
        "probes.csv",
        "wrench.csv",
        "pressure.csv",
        "bodies.csv",
        "summary.json",
    ]
    .into_iter()
    .filter(|f| out.join(f).exists())
    .collect();
    format!("{}/{{{}}}", out.display(), written.join(", "))
}

/// A path beside `bag` named after it with `suffix` (`runs/ship1` → `runs/ship1_replay`).
pub(crate) fn beside(bag: &std::path::Path, suffix: &str) -> PathBuf {
    let name = bag
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    bag.with_file_name(format!("{name}{suffix}"))
}

/// A `--duration`: a positive, finite number of seconds.
pub(crate) fn positive_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) => Err(format!("must be a positive number of seconds, got {v}")),
        Err(e) => Err(format!("not a number of seconds: {e}")),
    }
}
