//! Run outputs: `probes.csv`, `wrench.csv`, `pressure.csv` (a row per output time), `bodies.csv` (a row
//! per floating body and output time, if the case has bodies) and `summary.json`.
//! Rows are flushed as they are written, so a run that fails keeps everything up to the failure.

use sph::observe::Observation;
use sph::params::SimParams;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

pub struct CsvOutputs {
    probes: Csv,
    wrench: Csv,
    pressure: Csv,
    bodies: Option<Csv>,
    dir: PathBuf,
    /// What an earlier run had left in the folder and was removed (see [`CsvOutputs::create`]).
    pub replaced: Vec<String>,
}

/// Columns of `bodies.csv`: the body's centre of gravity, orientation (rad), velocities, the liquid's force
/// and moment about the centre of gravity, and the liquid inside it (2D: per metre of breadth).
pub const BODY_COLUMNS: &str =
    "time,body,x,y,z,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,fx,fy,fz,mx,my,mz,flooded_volume,inflow_rate";

/// One CSV file being written.
struct Csv {
    w: BufWriter<File>,
    path: PathBuf,
    /// A write failed: what reached the file may end inside a row.
    failed: bool,
}

impl Csv {
    fn create(dir: &Path, name: &str, header: &str) -> std::io::Result<Self> {
        let path = dir.join(name);
        let mut w = BufWriter::new(File::create(&path).map_err(|e| {
            std::io::Error::new(e.kind(), format!("{}: cannot create: {e}", path.display()))
        })?);
        writeln!(w, "{header}").map_err(|e| named(&path, e))?;
        Ok(Self {
            w,
            path,
            failed: false,
        })
    }

    /// Appends whole lines and writes them out: every file holds the rows up to the last output time, so a
    /// disk that fills leaves each file its rows up to about the same time (a buffer that filled up first
    /// would otherwise take the last room and leave another file empty).
    fn append(&mut self, lines: &str) -> std::io::Result<()> {
        let w = &mut self.w;
        w.write_all(lines.as_bytes())
            .and_then(|()| w.flush())
            .map_err(|e| {
                self.failed = true;
                named(&self.path, e)
            })
    }

    /// Writes the buffered rows out and closes the file; if that fails, cuts the file after its last whole
    /// row (a full disk leaves part of a row behind), so that it stays readable.
    fn close(self) -> std::io::Result<()> {
        let Self { w, path, failed } = self;
        match w.into_inner() {
            Ok(_) if !failed => Ok(()),
            Ok(_) => cut_after_last_row(&path).map_err(|e| named(&path, e)),
            Err(e) => {
                let (kind, message) = (e.error().kind(), e.error().to_string());
                // The rows that could not be written are dropped, not written again when the writer goes.
                let (_file, _unwritten) = e.into_parts();
                let _ = cut_after_last_row(&path);
                Err(named(
                    &path,
                    std::io::Error::new(kind, format!("{message} (cut after its last whole row)")),
                ))
            }
        }
    }
}

/// `e` with the file it happened to.
fn named(path: &Path, e: std::io::Error) -> std::io::Error {
    std::io::Error::new(e.kind(), format!("{}: {e}", path.display()))
}

/// Truncates a text file after its last newline.
fn cut_after_last_row(path: &Path) -> std::io::Result<()> {
    let bytes = std::fs::read(path)?;
    let keep = bytes.iter().rposition(|b| *b == b'\n').map_or(0, |i| i + 1);
    if keep < bytes.len() {
        std::fs::OpenOptions::new()
            .write(true)
            .open(path)?
            .set_len(keep as u64)?;
    }
    Ok(())
}

/// Files a run writes into its folder (besides the bag): the CSVs and `summary.json`.
const RUN_FILES: [&str; 5] = [
    "probes.csv",
    "wrench.csv",
    "pressure.csv",
    "bodies.csv",
    "summary.json",
];

/// Removes, from a folder that holds an earlier run's outputs, what this run would not replace and a user
/// would take for this run's: its `bodies.csv` (when this run has no bodies), its particle frames (when this
/// run writes none), and the figures and pictures drawn from them (`slosh plot`'s `plots/`, `slosh
/// render`'s `render/`). Files of other programs are left alone. Returns what was removed, in words.
fn clear_earlier_run(dir: &Path, bodies: bool, snapshots: bool) -> std::io::Result<Vec<String>> {
    if !RUN_FILES.iter().any(|f| dir.join(f).is_file()) {
        return Ok(Vec::new());
    }
    let mut removed = Vec::new();
    if !bodies && dir.join("bodies.csv").is_file() {
        std::fs::remove_file(dir.join("bodies.csv"))
            .map_err(|e| named(&dir.join("bodies.csv"), e))?;
        removed.push("bodies.csv".to_string());
    }
    let mut sweep = |sub: &str, what: &str, ours: &dyn Fn(&str) -> bool| -> std::io::Result<()> {
        let d = dir.join(sub);
        let Ok(entries) = std::fs::read_dir(&d) else {
            return Ok(());
        };
        let mut n = 0;
        for e in entries.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if e.path().is_file() && ours(&name) {
                std::fs::remove_file(e.path()).map_err(|err| named(&e.path(), err))?;
                n += 1;
            }
        }
        if n > 0 {
            removed.push(format!("{sub}/ ({n} {what})"));
        }
        Ok(())
    };
    if !snapshots {
        sweep("snapshots", "particle frame files", &|n| {
            (n.starts_with("frame_") && n.ends_with(".vtu")) || n == crate::snapshot::SERIES
        })?;
    }
    sweep("plots", "figure files", &|n| {
        let stem = n.trim_end_matches(".png").trim_end_matches(".svg");
        n != stem && ["probes", "wrench", "pressure", "bodies"].contains(&stem)
    })?;
    sweep("render", "pictures", &|n| {
        (n.starts_with("frame_") && n.ends_with(".png")) || n == "run.gif"
    })?;
    Ok(removed)
}

impl CsvOutputs {
    /// Creates the folder and the CSV files with their headers, after removing what an earlier run in the
    /// same folder left that this run would not replace (its `bodies.csv`, particle frames unless
    /// `snapshots`, figures and pictures; listed in [`Self::replaced`]).
    pub fn create(dir: &Path, params: &SimParams, snapshots: bool) -> std::io::Result<Self> {
        std::fs::create_dir_all(dir).map_err(|e| {
            std::io::Error::new(
                e.kind(),
                format!(
                    "output folder (--out) {}: cannot create it: {e}",
                    dir.display()
                ),
            )
        })?;
        let bodies = !params.bodies.is_empty() || params.wave_maker.is_some();
        let replaced = clear_earlier_run(dir, bodies, snapshots)?;
        let names = |v: Vec<&str>| {
            std::iter::once("time")
                .chain(v)
                .collect::<Vec<_>>()
                .join(",")
        };
        Ok(Self {
            probes: Csv::create(
                dir,
                "probes.csv",
                &names(params.probes.iter().map(|p| p.name.as_str()).collect()),
            )?,
            wrench: Csv::create(dir, "wrench.csv", "time,fx,fy,fz,mx,my,mz")?,
            pressure: Csv::create(
                dir,
                "pressure.csv",
                &names(
                    params
                        .pressure_sensors
                        .iter()
                        .map(|p| p.name.as_str())
                        .collect(),
                ),
            )?,
            bodies: if bodies {
                Some(Csv::create(dir, "bodies.csv", BODY_COLUMNS)?)
            } else {
                None
            },
            dir: dir.to_path_buf(),
            replaced,
        })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Appends one row to each file.
    pub fn write(&mut self, o: &Observation) -> std::io::Result<()> {
        let row = |c: &mut Csv, vals: &mut dyn Iterator<Item = f64>| -> std::io::Result<()> {
            let mut line = format!("{:.6}", o.time);
            for v in vals {
                // (+ 0.0: a negative zero, e.g. a 2D run's fy, is written as 0.000000e0, not -0.000000e0.)
                line += &format!(",{:.6e}", v + 0.0);
            }
            line.push('\n');
            c.append(&line)
        };
        row(&mut self.probes, &mut o.probes.iter().copied())?;
        row(
            &mut self.wrench,
            &mut o.wrench.force.iter().chain(o.wrench.moment.iter()).copied(),
        )?;
        row(&mut self.pressure, &mut o.pressures.iter().copied())?;
        if let Some(c) = &mut self.bodies {
            let mut lines = String::new();
            for b in &o.bodies {
                lines += &format!("{:.6},{}", o.time, b.name);
                for v in b
                    .position
                    .iter()
                    .chain(&b.roll_pitch_yaw)
                    .chain(&b.velocity)
                    .chain(&b.angular_velocity)
                    .chain(&b.force)
                    .chain(&b.moment)
                    .chain([&b.flooded_volume, &b.inflow_rate])
                {
                    lines += &format!(",{:.6e}", v + 0.0);
                }
                lines.push('\n');
            }
            c.append(&lines)?;
        }
        Ok(())
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        for c in [&mut self.probes, &mut self.wrench, &mut self.pressure]
            .into_iter()
            .chain(self.bodies.as_mut())
        {
            c.w.flush().map_err(|e| named(&c.path, e))?;
        }
        Ok(())
    }

    /// Writes out and closes every file; a file that cannot be written whole is cut after its last whole row
    /// (the first such failure is returned).
    pub fn close(self) -> std::io::Result<()> {
        let mut first = Ok(());
        for c in [self.probes, self.wrench, self.pressure]
            .into_iter()
            .chain(self.bodies)
        {
            let r = c.close();
            if first.is_ok() {
                first = r;
            }
        }
        first
    }
}

/// Contents of `summary.json`.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Summary {
    pub dimension: usize,
    pub particles_fluid: usize,
    pub particles_boundary: usize,
    pub particles_lost: usize,
    pub steps: u64,
    pub force_evaluations: u64,
    pub sim_time_s: f64,
    pub wall_time_s: f64,
    pub realtime_factor: f64,
    pub particle_steps_per_s: f64,
    pub min_dt_s: f64,
    pub liquid_mass_kg: f64,
    /// Processes the liquid was spread over (MPI ranks; 1 for a run in one process), and how often the
    /// subdomains were moved to even out their particle counts.
    pub mpi_ranks: usize,
    pub rebalances: u64,
    /// Why the run stopped early, if it did.
    pub error: Option<String>,
    /// The incompressible scheme's pressure solver: iterations (all, mean per step), largest mean density
    /// error after a step's solve, steps that stopped at `max_iterations` above the tolerance.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pressure_solver: Option<serde_json::Value>,
    /// Where the motion came from, for runs not driven by the config's `motion.*` (e.g. `slosh replay`).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input: Option<serde_json::Value>,
    /// Particle frames written (`--snapshots`): folder, series file, frames, rate and frame of reference.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub snapshots: Option<serde_json::Value>,
    /// The parameters given (file and overrides, with the duration run).
    pub parameters: serde_json::Value,
    /// Every parameter as run, defaults included ([`crate::config::Loaded::effective_parameters`]).
    pub effective_parameters: serde_json::Value,
}

/// Writes `summary.json` whole or not at all (through a temporary file renamed into place: a full disk leaves
/// no empty or cut summary behind).
pub fn write_summary(dir: &Path, s: &Summary) -> std::io::Result<()> {
    let text = serde_json::to_string_pretty(s).expect("summary serialises");
    let (path, tmp) = (dir.join("summary.json"), dir.join(".summary.json.tmp"));
    let named =
        |e: std::io::Error| std::io::Error::new(e.kind(), format!("{}: {e}", path.display()));
    if let Err(e) = std::fs::write(&tmp, text + "\n") {
        let _ = std::fs::remove_file(&tmp);
        return Err(named(e));
    }
    std::fs::rename(&tmp, &path).map_err(named)
}
