use anyhow::Context;
use clap::{Parser, Subcommand};
use slosh_node::snapshot::{SnapshotFrame, SnapshotOptions};
use slosh_node::{bench, config, ros, runner};
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
    Run {
        /// Config file (ROS 2 parameters layout) or the name of a built-in case (seed_tank_039, dambreak_2d, ...).
        config: String,
        /// Output folder.
        #[arg(long)]
        out: PathBuf,
        /// Simulated seconds (default: the config's `duration`).
        #[arg(long, value_parser = positive_seconds)]
        duration: Option<f64>,
        /// Override a parameter by its dotted name, value as YAML: --set solver.cfl=0.15 --set probes.x=[-0.3,0.0]
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        #[command(flatten)]
        visuals: Visuals,
    },
    /// Replay the vessel motion recorded in a rosbag2 MCAP bag through a case: the outputs of `slosh run`
    /// (CSV) and a new bag with the motion and every output.
    Replay {
        /// The bag: a rosbag2 folder (metadata.yaml + .mcap files) or a bare .mcap file.
        bag: PathBuf,
        /// Config file or built-in case: the tank, liquid, probes, frames (its `motion.*` is not used).
        #[arg(long)]
        config: String,
        /// The motion topic (default: the bag's only nav_msgs/Odometry, geometry_msgs/PoseStamped or
        /// sensor_msgs/Imu topic).
        #[arg(long)]
        topic: Option<String>,
        /// At most this many simulated seconds per wall-clock second (1 = real time).
        #[arg(long, conflicts_with = "as_fast_as_possible")]
        rate: Option<f64>,
        /// As fast as the solver can (the default).
        #[arg(long)]
        as_fast_as_possible: bool,
        /// Output folder (default: BAG_replay beside the bag); the new bag goes to OUT/bag unless
        /// `record.path` is set.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Simulated seconds (default: the whole recorded motion).
        #[arg(long, value_parser = positive_seconds)]
        duration: Option<f64>,
        /// Override a parameter by its dotted name, value as YAML: --set replay.bad_samples=drop
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        #[command(flatten)]
        visuals: Visuals,
    },
    /// Draw a run's outputs as PNG and SVG figures in DIR/plots: probe elevations (fill level marked), the
    /// six wrench components, pressure sensors; --reference overlays measured or analytic data.
    Plot {
        /// The folder a `slosh run` or `slosh replay` wrote.
        dir: PathBuf,
        /// A CSV of a time column and columns named like the run's (probe names, fx..mz, sensor names) to
        /// overlay; repeat for several.
        #[arg(long = "reference", value_name = "FILE.csv")]
        references: Vec<PathBuf>,
        /// Image size in pixels.
        #[arg(long, default_value = "1200x800")]
        size: String,
        /// Output folder (default: DIR/plots).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Turn a run's particle frames (`--snapshots`) into PNG pictures and an animated GIF in DIR/render.
    Render {
        /// The folder of a run made with --snapshots (or its snapshots folder).
        dir: PathBuf,
        /// Colour the liquid by speed or by pressure.
        #[arg(long, value_enum, default_value_t = slosh_node::render::Colour::Speed)]
        colour: slosh_node::render::Colour,
        /// Picture size in pixels.
        #[arg(long, default_value = "960x640")]
        size: String,
        /// GIF frames per second.
        #[arg(long, default_value_t = 10.0)]
        fps: f64,
        /// 3D runs: draw the layer of particles nearest y = SLICE (m, tank frame) instead of a side view.
        #[arg(long, allow_negative_numbers = true)]
        slice: Option<f64>,
        /// Output folder (default: DIR/render).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Serve the case to a co-simulation over iceoryx2 (shared memory): each request is the vessel's state at
    /// the sender's time t, each answer the liquid's wrench, probes and pressures at t.
    Couple {
        /// Config file or built-in case (its `motion.*` is not used).
        config: String,
        /// Service prefix: NAME/coupling, NAME/outputs, NAME/particles.
        #[arg(long, default_value = "slosh")]
        service: String,
        /// Publish particle frames on NAME/particles at this many per second of sample time.
        #[arg(long, default_value_t = 0.0)]
        particles: f64,
        /// Answer without simulating (to time the transport alone).
        #[arg(long)]
        dry: bool,
        /// Also write probes.csv, wrench.csv and pressure.csv here.
        #[arg(long)]
        out: Option<PathBuf>,
        /// Stop after this many steps past the first sample (which starts the simulation): N + 1 answers, as
        /// many as a client's `--steps N` sends (default: until SIGINT/SIGTERM).
        #[arg(long)]
        max_steps: Option<u64>,
        /// Override a parameter by its dotted name, value as YAML.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
    },
    /// Time the benchmark cases: particle-steps per second and real-time factor.
    Bench {
        /// Only this case (dambreak_2d, seed_2d_dp8mm, seed_3d_dp20mm, seed_2d_dp8mm_dfsph,
        /// seed_3d_dp20mm_dfsph); default: all.
        #[arg(long)]
        case: Vec<String>,
        /// Simulated seconds per case (default: each case's own).
        #[arg(long, value_parser = positive_seconds)]
        duration: Option<f64>,
        /// Override a setting of every case after its own (`--set solver.dfsph.max_density_error=1e-3`).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// Print one JSON object per case instead of a table.
        #[arg(long)]
        json: bool,
        /// Run each case this many times and report the run of median wall time, with the fastest and
        /// slowest (a shared machine's speed can wander by tens of percent between runs).
        #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..))]
        repeat: u32,
    },
    /// Time the transports without the physics: coupling round trips and particle frames over iceoryx2 and
    /// over DDS on loopback (run DDS inside `unshare -rn` to keep its discovery traffic on this machine).
    BenchTransport {
        /// Coupling round trips timed per transport.
        #[arg(long, default_value_t = 2000)]
        round_trips: usize,
        /// Particles per frame (repeatable).
        #[arg(long, default_values_t = vec![10_000usize, 100_000])]
        particles: Vec<usize>,
        /// Frames timed per particle count.
        #[arg(long, default_value_t = 30)]
        frames: usize,
        /// Transports (repeatable): iceoryx2, dds.
        #[arg(long, default_values_t = vec!["iceoryx2".to_string(), "dds".to_string()])]
        transport: Vec<String>,
        /// Print one JSON object per result instead of tables.
        #[arg(long)]
        json: bool,
    },
    /// Work on recorded bags.
    Bag {
        #[command(subcommand)]
        command: BagCommand,
    },
    /// Run as a ROS 2 node: `slosh node --ros-args --params-file CASE.yaml [-p name:=value] [-r from:=to]`.
    Node {
        /// Stop after this many simulated seconds (default: run until SIGINT/SIGTERM).
        #[arg(long, value_parser = positive_seconds)]
        duration: Option<f64>,
        /// ROS arguments (`--ros-args ...`); a plain first argument names the parameters file or built-in case.
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
    /// Publish synthetic vessel motion (the config's `motion.*`) as nav_msgs/Odometry on `motion/odom`.
    Motion {
        /// Config file or built-in case whose `motion.*` parameters give the motion.
        config: String,
        /// Samples per second.
        #[arg(long, default_value_t = 50.0)]
        rate: f64,
        /// Seconds of motion.
        #[arg(long, value_parser = positive_seconds, default_value_t = 10.0)]
        duration: f64,
        /// Also publish geometry_msgs/PoseStamped on `motion/pose`.
        #[arg(long)]
        pose: bool,
        /// Also publish sensor_msgs/Imu on `motion/imu` (an IMU at the vessel's origin).
        #[arg(long)]
        imu: bool,
        /// Also publish geometry_msgs/AccelStamped on `motion/accel` (body frame).
        #[arg(long)]
        accel: bool,
        /// Wait for this many subscribers on `motion/odom` before the first sample.
        #[arg(long, default_value_t = 0)]
        wait_for_subscribers: usize,
        /// Stay a few samples ahead of the simulation's `/clock` instead of pacing by the wall clock
        /// (for `realtime.mode: lockstep`).
        #[arg(long)]
        lockstep: bool,
        /// Stamp of the first sample in seconds since the epoch (default: now).
        #[arg(long, allow_negative_numbers = true)]
        start_stamp: Option<f64>,
        /// Publish `slosh::MotionSample`s on the iceoryx2 service NAME/motion instead of DDS (for a node
        /// with `input.type: iceoryx2`).
        #[arg(long, value_name = "NAME")]
        iceoryx2: Option<String>,
        /// Parameter overrides of the case, KEY=VALUE (with --iceoryx2; over DDS use --ros-args -p).
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<String>,
        /// ROS arguments (`--ros-args -r __ns:=/ship1 ...`).
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<String>,
    },
}

/// Pictures and particle frames of a run.
#[derive(clap::Args)]
struct Visuals {
    /// Write particle frames for ParaView at this many per simulated second: OUT/snapshots/run.pvd and
    /// frame_NNNNNN.vtu (position, velocity, pressure, density, fluid flag, id).
    #[arg(long, value_name = "HZ")]
    snapshots: Option<f64>,
    /// The frame of the particle frames: the tank's, or the world's (moved with the tank).
    #[arg(long, value_enum, default_value_t = SnapshotFrame::Tank)]
    snapshot_frame: SnapshotFrame,
    /// Draw the figures of `slosh plot` into OUT/plots when the run ends.
    #[arg(long)]
    plot: bool,
}

impl Visuals {
    fn snapshots(&self, out: &std::path::Path) -> Option<SnapshotOptions> {
        self.snapshots.map(|rate_hz| SnapshotOptions {
            rate_hz,
            frame: self.snapshot_frame,
            dir: out.join("snapshots"),
        })
    }

    /// Draws the run's figures if asked to (also after a run that stopped early: the outputs so far).
    fn plot_after<T>(&self, out: &std::path::Path, run: anyhow::Result<T>) -> anyhow::Result<T> {
        if self.plot && out.join("probes.csv").exists() {
            match slosh_node::plot::plot(out, &slosh_node::plot::PlotOptions::default()) {
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
enum BagCommand {
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

/// A path beside `bag` named after it with `suffix` (`runs/ship1` → `runs/ship1_replay`).
/// The output files a run wrote into `out`, as `out/{a.csv, b.csv, ...}`.
fn outputs(out: &std::path::Path) -> String {
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

fn beside(bag: &std::path::Path, suffix: &str) -> PathBuf {
    let name = bag
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default();
    bag.with_file_name(format!("{name}{suffix}"))
}

/// Errors are the user's to act on: printed as one line of causes (`a: b: c`), never with a backtrace (even
/// where `RUST_BACKTRACE` is set; panics keep theirs), exit status 1.
fn main() -> std::process::ExitCode {
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
    if let Some(n) = slosh_node::memory::mpi_world_size().filter(|n| *n > 1) {
        anyhow::bail!("started as one of {n} MPI ranks, but this slosh was built without MPI: build it with `cargo build --release -p slosh-node --features mpi` (see the manual's MPI page, docs/src/guide/mpi.md), or run it without mpirun");
    }
    // Under mpirun every rank runs this binary: rank 0 goes on with the command (its simulations spread
    // over all ranks), the others follow its solver calls until it is done.
    #[cfg(feature = "mpi")]
    let _lead = match sph::distributed::mpi::start(|| {
        // mpirun passes SIGINT/SIGTERM to every rank; rank 0 finishes its outputs, then releases the
        // others: here the signals only set a flag nobody reads.
        let _ = slosh_node::signals::shutdown_flag();
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
        Command::Bag {
            command: BagCommand::Repair { bag, out },
        } => {
            let out = out.unwrap_or_else(|| beside(&bag, "_repaired"));
            let r = slosh_node::record::repair(&bag, &out)?;
            println!(
                "recovered {} message{} on {} topic{} from {} file{} into {}{}",
                r.messages,
                if r.messages == 1 { "" } else { "s" },
                r.topics,
                if r.topics == 1 { "" } else { "s" },
                r.files,
                if r.files == 1 { "" } else { "s" },
                out.display(),
                r.stopped
                    .map(|e| format!(" (the input ends early: {e})"))
                    .unwrap_or_default()
            );
        }
        Command::Node { duration, args } => {
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
        }
        Command::Motion {
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
        } => {
            let (plain, ros_args) = ros::args::parse(&args)?;
            if !plain.is_empty() {
                anyhow::bail!("unexpected arguments {plain:?}: ROS arguments go after --ros-args");
            }
            let opts = slosh_node::motion_source::MotionOptions {
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
                Some(service) => slosh_node::iox::motion_pub::run(&cfg, &set, &service, &opts)?,
                None => {
                    if !set.is_empty() {
                        anyhow::bail!("--set goes with --iceoryx2; over DDS give parameters as --ros-args -p KEY:=VALUE");
                    }
                    ros::motion_pub::run(&ros_args, &cfg, &opts)?
                }
            }
        }
        Command::Run {
            config: cfg,
            out,
            duration,
            set,
            visuals,
        } => {
            let loaded = config::load(&cfg, &set)?;
            let opts = runner::RunOptions {
                duration,
                progress: true,
                rate: None,
                snapshots: visuals.snapshots(&out),
            };
            // Said once the case and options have passed their checks and the outputs exist.
            let announce = || {
                eprintln!(
                    "slosh: running {} for {} s, writing to {}",
                    loaded.source_name,
                    duration.unwrap_or(loaded.config.duration),
                    out.display()
                )
            };
            let s = visuals.plot_after(
                &out,
                runner::run(&loaded, &out, &opts, announce).map_err(Into::into),
            )?;
            println!(
                "done: {:.3} s simulated in {:.1} s (real-time factor {:.3}, {:.2e} particle-steps/s, {} liquid + {} boundary particles, {} lost)",
                s.sim_time_s, s.wall_time_s, s.realtime_factor, s.particle_steps_per_s, s.particles_fluid, s.particles_boundary, s.particles_lost
            );
            println!("outputs: {}", outputs(&out));
        }
        Command::Replay {
            bag,
            config: cfg,
            topic,
            rate,
            as_fast_as_possible: _,
            out,
            duration,
            set,
            visuals,
        } => {
            let loaded = config::load(&cfg, &set)?;
            let out = out.unwrap_or_else(|| beside(&bag, "_replay"));
            let opts = slosh_node::replay::ReplayOptions {
                topic,
                duration,
                rate,
                progress: true,
                snapshots: visuals.snapshots(&out),
            };
            let s = visuals.plot_after(&out, slosh_node::replay::replay(&bag, &loaded, &out, &opts, |f| {
                eprintln!(
                    "slosh: replaying {} ({}, {} of {} messages, {:.3} s, times from {}) through {}, writing to {} and the bag {}",
                    f.topic, f.type_name, f.samples, f.messages, f.span_s,
                    if f.time_source == "header" { "the header stamps" } else { "the log times" },
                    loaded.source_name, out.display(), f.recording
                );
                for d in &f.dropped {
                    eprintln!("slosh: dropped {d}");
                }
                if f.input_check.starts_with("input check") {
                    eprintln!("slosh: warning: {}", f.input_check);
                }
            }).map_err(Into::into))?;
            println!(
                "done: {:.3} s replayed in {:.1} s (real-time factor {:.3}, {:.2e} particle-steps/s)",
                s.sim_time_s, s.wall_time_s, s.realtime_factor, s.particle_steps_per_s
            );
            println!("outputs: {}", outputs(&out));
        }
        Command::Couple {
            config: cfg,
            service,
            particles,
            dry,
            out,
            max_steps,
            set,
        } => {
            let loaded = config::load(&cfg, &set)?;
            let opts = slosh_node::iox::couple::CoupleOptions {
                service: service.clone(),
                particles_hz: particles,
                dry,
                out,
                max_steps,
            };
            let s = slosh_node::iox::couple::serve(&loaded, &opts, || {
                eprintln!(
                    "slosh: serving {} on iceoryx2 service {service}/coupling (outputs on {service}/outputs{})",
                    loaded.source_name,
                    if particles > 0.0 { format!(", particles on {service}/particles") } else { String::new() }
                );
            })?;
            println!("{}", serde_json::to_string(&s)?);
        }
        Command::Plot {
            dir,
            references,
            size,
            out,
        } => {
            let opts = slosh_node::plot::PlotOptions {
                size: slosh_node::plot::parse_size(&size).map_err(anyhow::Error::msg)?,
                references,
                out,
            };
            let p = slosh_node::plot::plot(&dir, &opts).map_err(anyhow::Error::msg)?;
            for u in &p.unmatched {
                eprintln!("slosh: reference column left out (no run column of that name): {u}");
            }
            for f in &p.files {
                println!("{}", f.display());
            }
        }
        Command::Render {
            dir,
            colour,
            size,
            fps,
            slice,
            out,
        } => {
            let opts = slosh_node::render::RenderOptions {
                colour,
                size: slosh_node::plot::parse_size(&size).map_err(anyhow::Error::msg)?,
                fps,
                slice,
                out,
            };
            let r = slosh_node::render::render(&dir, &opts).map_err(anyhow::Error::msg)?;
            println!(
                "{} frames: {} .. {}",
                r.frames.len(),
                r.frames
                    .first()
                    .map(|p| p.display().to_string())
                    .unwrap_or_default(),
                r.frames
                    .last()
                    .map(|p| p.display().to_string())
                    .unwrap_or_default()
            );
            println!("{}", r.gif.display());
        }
        Command::BenchTransport {
            round_trips,
            particles,
            frames,
            transport,
            json,
        } => {
            let (lat, thr) =
                slosh_node::transport_bench::run(&slosh_node::transport_bench::Options {
                    round_trips,
                    particles,
                    frames,
                    transports: transport,
                })?;
            if json {
                for l in &lat {
                    println!("{}", serde_json::to_string(l)?);
                }
                for t in &thr {
                    println!("{}", serde_json::to_string(t)?);
                }
            } else {
                println!("coupling round trip (motion sample out, outputs back), µs");
                println!(
                    "{:<10} {:>8} {:>9} {:>9} {:>9} {:>9}",
                    "transport", "trips", "p50", "p90", "p99", "max"
                );
                for l in &lat {
                    println!(
                        "{:<10} {:>8} {:>9.1} {:>9.1} {:>9.1} {:>9.1}",
                        l.transport, l.round_trips, l.p50_us, l.p90_us, l.p99_us, l.max_us
                    );
                }
                println!("particle frames (32 B per particle, one frame in flight)");
                println!(
                    "{:<10} {:>10} {:>10} {:>8} {:>10} {:>10} {:>10}",
                    "transport", "particles", "MB/frame", "frames", "frames/s", "MB/s", "ms/frame"
                );
                for t in &thr {
                    println!(
                        "{:<10} {:>10} {:>10.2} {:>8} {:>10.1} {:>10.1} {:>10.3}",
                        t.transport,
                        t.particles,
                        t.bytes_per_frame as f64 / 1e6,
                        t.frames,
                        t.frames_per_s,
                        t.mb_per_s,
                        t.ms_per_frame
                    );
                }
            }
        }
        Command::Bench {
            case,
            duration,
            set,
            json,
            repeat,
        } => {
            let cases: Vec<&bench::Case> = if case.is_empty() {
                bench::CASES.iter().collect()
            } else {
                case.iter()
                    .map(|c| {
                        bench::CASES.iter().find(|k| k.name == c).with_context(|| {
                            format!(
                                "unknown case {c}; cases: {}",
                                bench::CASES
                                    .iter()
                                    .map(|k| k.name)
                                    .collect::<Vec<_>>()
                                    .join(", ")
                            )
                        })
                    })
                    .collect::<anyhow::Result<_>>()?
            };
            // Every case checked first: a bad --set leaves no half table on stdout.
            for c in &cases {
                bench::check_case(c, &set).with_context(|| format!("case {}", c.name))?;
            }
            if !json {
                println!(
                    "{:<22} {:>5} {:>7} {:>9} {:>8} {:>8} {:>10} {:>14} {:>10} {:>12} {:>7}",
                    "case",
                    "ranks",
                    "threads",
                    "particles",
                    "steps",
                    "sim s",
                    "wall s",
                    "particle-st/s",
                    "RT factor",
                    "wall s/sim s",
                    "comm %"
                );
            }
            for c in cases {
                let r = bench::run_repeated(c, duration, &set, repeat)?;
                if json {
                    println!("{}", serde_json::to_string(&r)?);
                } else {
                    // With --repeat: the median run, and the real-time factors of the slowest and fastest.
                    let range = if r.repeats > 1 {
                        format!(
                            "  ({} runs: RT factor {:.4}–{:.4})",
                            r.repeats,
                            r.sim_time_s / r.wall_time_s_max,
                            r.sim_time_s / r.wall_time_s_min
                        )
                    } else {
                        String::new()
                    };
                    println!(
                        "{:<22} {:>5} {:>7} {:>9} {:>8} {:>8.3} {:>10.2} {:>14.3e} {:>10.4} {:>12.1} {:>7.1}{range}",
                        r.case,
                        r.ranks,
                        r.threads,
                        r.particles_fluid,
                        r.steps,
                        r.sim_time_s,
                        r.wall_time_s,
                        r.particle_steps_per_s,
                        r.realtime_factor,
                        r.wall_s_per_sim_s,
                        100.0 * r.comm_share
                    );
                }
            }
        }
    }
    Ok(())
}

/// A `--duration`: a positive, finite number of seconds.
fn positive_seconds(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        Ok(v) => Err(format!("must be a positive number of seconds, got {v}")),
        Err(e) => Err(format!("not a number of seconds: {e}")),
    }
}
