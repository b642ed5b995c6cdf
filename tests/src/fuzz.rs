//! Property-based fuzzing of what `slosh` reads from users and from disk: generated inputs, each made by
//! mutating a valid one (bit flips, bytes set, spans zeroed, duplicated or cut, truncation) or by
//! assembling tokens, are fed to the parameter-file and `--set` parser, the `--ros-args` parser, the motion
//! CSV reader, the MCAP/rosbag2 motion reader and the iceoryx2 sample check. An input passes when the
//! reader returns (a value or an error with a message); a panic fails the run and its input is kept, and an
//! abort (an allocation the size of a corrupted length) ends the process, which fails it too.
//!
//! `cargo run --release -p slosh-tests --example fuzz -- --inputs 1000000` runs a million inputs for each
//! target; `tests/tests/fuzz.rs` runs a few thousand in the test command.

use slosh_node::config::{self, Loaded};
use slosh_node::input::frames::Frames;
use slosh_node::iox::{self, MotionSample};
use slosh_node::replay::motion::{self, Reading};
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::{Path, PathBuf};

/// SplitMix64: small, fast, and the same inputs for the same seed.
pub struct Rng(u64);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Rng(seed)
    }

    pub fn word(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    /// Uniform in 0..n (n > 0).
    pub fn below(&mut self, n: usize) -> usize {
        (self.word() % n as u64) as usize
    }

    pub fn pick<'a, T>(&mut self, items: &'a [T]) -> &'a T {
        &items[self.below(items.len())]
    }
}

/// A copy of `seed` with one to four mutations.
pub fn mutate(seed: &[u8], rng: &mut Rng) -> Vec<u8> {
    let mut b = seed.to_vec();
    for _ in 0..1 + rng.below(4) {
        if b.is_empty() {
            b.push(rng.word() as u8);
            continue;
        }
        let i = rng.below(b.len());
        let span = 1 + rng.below(64.min(b.len() - i));
        match rng.below(7) {
            0 => b[i] ^= 1 << rng.below(8),
            1 => b[i] = rng.word() as u8,
            2 => b[i..i + span].iter_mut().for_each(|x| *x = 0),
            3 => {
                let copy = b[i..i + span].to_vec();
                let at = rng.below(b.len());
                b.splice(at..at, copy);
            }
            4 => {
                b.drain(i..i + span);
            }
            5 => b.truncate(i),
            _ => {
                // A plausible number where one was: lengths and counts read from files live there.
                let v = [0u64, 1, u32::MAX as u64, u64::MAX, 1 << 40][rng.below(5)];
                let end = (i + 8).min(b.len());
                let bytes = v.to_le_bytes();
                b[i..end].copy_from_slice(&bytes[..end - i]);
            }
        }
    }
    b
}

/// What a run of one target found.
#[derive(Debug, Default)]
pub struct Tally {
    pub inputs: usize,
    pub accepted: usize,
    pub refused: usize,
    /// Inputs that panicked (their bytes), at most a few.
    pub panics: Vec<(String, Vec<u8>)>,
    /// Refusals whose message was empty.
    pub silent: usize,
}

impl Tally {
    fn take(&mut self, input: &[u8], r: std::thread::Result<Result<(), String>>) {
        self.inputs += 1;
        match r {
            Ok(Ok(())) => self.accepted += 1,
            Ok(Err(m)) => {
                self.refused += 1;
                if m.trim().is_empty() {
                    self.silent += 1;
                }
            }
            Err(p) => {
                let what = p
                    .downcast_ref::<String>()
                    .cloned()
                    .or_else(|| p.downcast_ref::<&str>().map(|s| s.to_string()))
                    .unwrap_or_default();
                if self.panics.len() < 5 {
                    self.panics.push((what, input.to_vec()));
                }
            }
        }
    }
}

/// Runs `check` on `n` inputs from `make`, catching panics.
fn run(
    n: usize,
    rng: &mut Rng,
    mut make: impl FnMut(&mut Rng) -> Vec<u8>,
    check: impl Fn(&[u8]) -> Result<(), String>,
) -> Tally {
    let mut t = Tally::default();
    for _ in 0..n {
        let input = make(rng);
        let r = catch_unwind(AssertUnwindSafe(|| check(&input)));
        t.take(&input, r);
    }
    t
}

/// Parameter files (the built-in cases, mutated) with `--set` overrides (keys of the schema with values
/// from a list of awkward YAML).
pub fn parameters(n: usize, rng: &mut Rng) -> Tally {
    let keys = [
        "dimension",
        "particle_spacing",
        "fill_height",
        "tank",
        "tank.length",
        "solver.scheme",
        "solver.cfl",
        "solver.dfsph.relaxation",
        "probes",
        "probes.x",
        "motion.source",
        "motion.regular.amplitude",
        "motion.irregular.seed",
        "record.chunk_size",
        "obstacles",
        "bodies",
        "output_rate_hz",
        "nonsense.key",
    ];
    let values = [
        "0",
        "-1",
        "1e308",
        "nan",
        ".inf",
        "[]",
        "{}",
        "[1, 2]",
        "null",
        "~",
        "'x'",
        "true",
        "2",
        "3",
        "0.02",
        "wcsph",
        "dfsph",
        "{a: 1}",
        "[[1]]",
        "1e-300",
        "99999999999999999999",
        "\"\"",
    ];
    run(
        n,
        rng,
        |rng| {
            let (_, text) = rng.pick(config::BUILTIN);
            let mut input = if rng.below(4) == 0 {
                text.as_bytes().to_vec()
            } else {
                mutate(text.as_bytes(), rng)
            };
            input.push(0);
            for _ in 0..rng.below(3) {
                input.extend(format!("{}={}\0", rng.pick(&keys), rng.pick(&values)).bytes());
            }
            input
        },
        |input| {
            let mut parts = input.split(|&b| b == 0);
            let text = String::from_utf8_lossy(parts.next().unwrap_or_default());
            let sets: Vec<String> = parts
                .filter(|p| !p.is_empty())
                .map(|p| String::from_utf8_lossy(p).into_owned())
                .collect();
            let loaded =
                config::from_str(&text, "fuzz.yaml", None, &sets).map_err(|e| e.to_string())?;
            let params = loaded.sim_params().map_err(|e| e.to_string())?;
            let _ = loaded.regular().map_err(|e| e.to_string());
            let _ = loaded.irregular().map_err(|e| e.to_string());
            let _ = loaded.effective_parameters(&params);
            Ok(())
        },
    )
}

/// `--ros-args` lines assembled from the tokens ROS 2 users write.
pub fn ros_args(n: usize, rng: &mut Rng) -> Tally {
    let tokens = [
        "--ros-args",
        "-p",
        "-r",
        "--params-file",
        "--log-level",
        "--",
        "__ns:=/ship1",
        "__node:=tank2",
        "motion/odom:=/nav/odom",
        "solver.cfl:=0.15",
        ":=",
        "a:=",
        ":=b",
        "__ns:=",
        "__ns:=relative",
        "__node:=bad name",
        "node:from:=to",
        "x:=[1,2",
        "-p",
        "dimension:=2",
        "file.yaml",
        "",
        "=",
        "/**:",
        "ü:=ö",
    ];
    run(
        n,
        rng,
        |rng| {
            let k = rng.below(8);
            let mut line = Vec::new();
            for _ in 0..k {
                line.extend(rng.pick(&tokens).bytes());
                line.push(0);
            }
            line
        },
        |input| {
            let args: Vec<String> = input
                .split(|&b| b == 0)
                .filter(|p| !p.is_empty())
                .map(|p| String::from_utf8_lossy(p).into_owned())
                .collect();
            let (_, ros) = slosh_node::ros::args::parse(&args).map_err(|e| e.to_string())?;
            let names =
                slosh_node::ros::args::Names::new(&ros, "slosh").map_err(|e| e.to_string())?;
            let _ = names.node_fqn();
            let _ = names.resolve("motion/odom").map_err(|e| e.to_string())?;
            Ok(())
        },
    )
}

/// A motion CSV of `rows` samples of a rolling, heaving tank.
pub fn motion_csv(rows: usize) -> String {
    let mut s = String::from("time,x,y,z,roll,pitch,yaw\n");
    for i in 0..rows {
        let t = 0.02 * i as f64;
        s += &format!(
            "{t},{},0,{},{},0,0\n",
            0.01 * t.sin(),
            0.005 * (2.0 * t).sin(),
            0.05 * (1.3 * t).sin()
        );
    }
    s
}

/// A file in memory-backed storage (one per process and target), rewritten for each input.
fn scratch(name: &str) -> PathBuf {
    let dir = if Path::new("/dev/shm").is_dir() {
        PathBuf::from("/dev/shm")
    } else {
        std::env::temp_dir()
    };
    dir.join(format!("slosh-fuzz-{}-{name}", std::process::id()))
}

/// Motion CSV files, mutated.
pub fn csv(n: usize, rng: &mut Rng) -> Tally {
    let seed = motion_csv(60);
    let path = scratch("motion.csv");
    let t = run(
        n,
        rng,
        |rng| mutate(seed.as_bytes(), rng),
        |input| {
            std::fs::write(&path, input).map_err(|e| e.to_string())?;
            slosh_node::motion_source::read_csv(&path).map_err(|e| e.to_string())?;
            Ok(())
        },
    );
    let _ = std::fs::remove_file(&path);
    t
}

/// The motion of recorded bags (`seed`: the bytes of an .mcap file), mutated, read as `slosh replay` reads
/// them.
pub fn bags(n: usize, rng: &mut Rng, seed: &[u8], cfg: &Loaded) -> Tally {
    let c = &cfg.config;
    let frames = Frames::new(c.input.world_frame, c.input.body_frame, c.frames.tank_pose);
    let path = scratch("bag.mcap");
    let t = run(
        n,
        rng,
        |rng| mutate(seed, rng),
        |input| {
            std::fs::write(&path, input).map_err(|e| e.to_string())?;
            let how = Reading::of(c, &frames, None, 9.81);
            let files = slosh_node::bag::files(&path).map_err(|e| e.to_string())?;
            let m = motion::read(&path, &files, &how).map_err(|e| e.to_string())?;
            let _ = m.motion.state(0.0);
            Ok(())
        },
    );
    let _ = std::fs::remove_file(&path);
    t
}

/// iceoryx2 motion samples: random bit patterns, and valid samples with a field made odd.
pub fn iox_samples(n: usize, rng: &mut Rng) -> Tally {
    // A tank 1 m forward of the vessel's reference point, turned 90° about z.
    let frames = Frames::new(
        Default::default(),
        Default::default(),
        slosh_node::config::TankPose {
            x: 1.0,
            yaw: std::f64::consts::FRAC_PI_2,
            ..Default::default()
        },
    );
    let (offset, rotation) = frames.mount();
    let mount = iox::Mount { offset, rotation };
    run(
        n,
        rng,
        |rng| {
            let mut s = iox::sample_of(1.0, &sph::motion::RigidState::at_rest());
            let words: &mut [f64] = bytemuck_f64(&mut s);
            if rng.below(2) == 0 {
                for w in words.iter_mut() {
                    *w = f64::from_bits(rng.word());
                }
            } else {
                let i = rng.below(words.len());
                words[i] = *rng.pick(&[f64::NAN, f64::INFINITY, -0.0, 1e308, 2.0, -1.0, 0.0]);
            }
            let b: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
            b
        },
        |input| {
            let mut s = MotionSample::default();
            for (w, c) in bytemuck_f64(&mut s).iter_mut().zip(input.chunks_exact(8)) {
                *w = f64::from_le_bytes(c.try_into().unwrap());
            }
            iox::check(&s)?;
            let _ = iox::tank_state(&s, &mount);
            Ok(())
        },
    )
}

/// The f64 fields of a sample, in order.
fn bytemuck_f64(s: &mut MotionSample) -> &mut [f64] {
    const N: usize = std::mem::size_of::<MotionSample>() / 8;
    // SAFETY: MotionSample is repr(C) and made of f64 fields only (its size is N f64s, no padding).
    unsafe { std::slice::from_raw_parts_mut(s as *mut MotionSample as *mut f64, N) }
}

/// A short recording of `slosh run` (a coarse 2D seed tank, 1 s of its irregular motion): the bytes of its
/// .mcap file and the case, whose input settings the reading uses.
pub fn recorded_bag() -> (Vec<u8>, Loaded) {
    let dir = scratch("bag-seed");
    let _ = std::fs::remove_dir_all(&dir);
    let bag = dir.join("bag");
    let sets = [
        "dimension=2".to_string(),
        "particle_spacing=0.04".to_string(),
        format!("record.path={}", bag.display()),
    ];
    let cfg = config::load("seed_tank_019", &sets).expect("the seed case loads");
    let opts = slosh_node::runner::RunOptions {
        duration: Some(1.0),
        progress: false,
        rate: None,
        snapshots: None,
    };
    slosh_node::runner::run(&cfg, &dir.join("out"), &opts, || {}).expect("the seed case runs");
    let mcap = std::fs::read_dir(&bag)
        .expect("the recording")
        .map(|e| e.unwrap().path())
        .find(|p| p.extension().is_some_and(|x| x == "mcap"))
        .expect("an .mcap file in the recording");
    let bytes = std::fs::read(mcap).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    (bytes, cfg)
}
