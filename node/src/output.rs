//! Run outputs: `probes.csv`, `wrench.csv`, `pressure.csv` (a row per output time), `bodies.csv` (a row
//! per floating body and output time, if the case has bodies) and `summary.json`.
//! Rows are flushed as they are written, so a run that fails keeps everything up to the failure.

use sph::observe::Observation;
use sph::params::SimParams;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

pub struct CsvOutputs {
    probes: BufWriter<File>,
    wrench: BufWriter<File>,
    pressure: BufWriter<File>,
    bodies: Option<BufWriter<File>>,
    dir: PathBuf,
}

/// Columns of `bodies.csv`: the body's centre of gravity, orientation (rad), velocities, the liquid's force
/// and moment about the centre of gravity, and the liquid inside it (2D: per metre of breadth).
pub const BODY_COLUMNS: &str =
    "time,body,x,y,z,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,fx,fy,fz,mx,my,mz,flooded_volume,inflow_rate";

fn create(dir: &Path, name: &str, header: &str) -> std::io::Result<BufWriter<File>> {
    let path = dir.join(name);
    let mut w = BufWriter::new(File::create(&path).map_err(|e| {
        std::io::Error::new(e.kind(), format!("{}: cannot create: {e}", path.display()))
    })?);
    writeln!(w, "{header}")?;
    Ok(w)
}

impl CsvOutputs {
    /// Creates the folder and the three CSV files with their headers.
    pub fn create(dir: &Path, params: &SimParams) -> std::io::Result<Self> {
        std::fs::create_dir_all(dir).map_err(|e| {
            std::io::Error::new(
                e.kind(),
                format!(
                    "output folder (--out) {}: cannot create it: {e}",
                    dir.display()
                ),
            )
        })?;
        let names = |v: Vec<&str>| {
            std::iter::once("time")
                .chain(v)
                .collect::<Vec<_>>()
                .join(",")
        };
        Ok(Self {
            probes: create(
                dir,
                "probes.csv",
                &names(params.probes.iter().map(|p| p.name.as_str()).collect()),
            )?,
            wrench: create(dir, "wrench.csv", "time,fx,fy,fz,mx,my,mz")?,
            pressure: create(
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
            bodies: if params.bodies.is_empty() && params.wave_maker.is_none() {
                None
            } else {
                Some(create(dir, "bodies.csv", BODY_COLUMNS)?)
            },
            dir: dir.to_path_buf(),
        })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    /// Appends one row to each file.
    pub fn write(&mut self, o: &Observation) -> std::io::Result<()> {
        let row =
            |w: &mut BufWriter<File>, vals: &mut dyn Iterator<Item = f64>| -> std::io::Result<()> {
                write!(w, "{:.6}", o.time)?;
                for v in vals {
                    write!(w, ",{v:.6e}")?;
                }
                writeln!(w)
            };
        row(&mut self.probes, &mut o.probes.iter().copied())?;
        row(
            &mut self.wrench,
            &mut o.wrench.force.iter().chain(o.wrench.moment.iter()).copied(),
        )?;
        row(&mut self.pressure, &mut o.pressures.iter().copied())?;
        if let Some(w) = &mut self.bodies {
            for b in &o.bodies {
                write!(w, "{:.6},{}", o.time, b.name)?;
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
                    write!(w, ",{v:.6e}")?;
                }
                writeln!(w)?;
            }
        }
        Ok(())
    }

    pub fn flush(&mut self) -> std::io::Result<()> {
        self.probes.flush()?;
        self.wrench.flush()?;
        if let Some(w) = &mut self.bodies {
            w.flush()?;
        }
        self.pressure.flush()
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
    pub parameters: serde_json::Value,
}

pub fn write_summary(dir: &Path, s: &Summary) -> std::io::Result<()> {
    let text = serde_json::to_string_pretty(s).expect("summary serialises");
    std::fs::write(dir.join("summary.json"), text + "\n")
}
