//! Particle frames for ParaView: `slosh run ... --snapshots HZ` writes every particle (position, velocity,
//! pressure, density, liquid/boundary flag, id) as `OUT/snapshots/frame_NNNNNN.vtu` and the time series
//! `OUT/snapshots/run.pvd`.
//!
//! The step thread only copies the particles ([`sph::Solver::snapshot`]); a writer thread turns them into
//! the requested frame, encodes and writes them. The queue between them holds a few frames: a run waits on
//! the disk only when the disk is slower than the frames come.

pub mod pvd;
pub mod vtu;

use sph::motion::RigidState;
use sph::observe::snapshot::Snapshot;
use std::path::{Path, PathBuf};
use std::sync::mpsc::{sync_channel, SyncSender};
use std::thread::JoinHandle;

/// The frame the particles are written in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SnapshotFrame {
    /// The tank frame (origin at the centre of the tank bottom), velocities relative to the tank.
    #[default]
    Tank,
    /// The world frame of the motion: positions moved with the tank, velocities absolute.
    World,
}

/// What `--snapshots` asks for.
#[derive(Clone, Debug, PartialEq)]
pub struct SnapshotOptions {
    /// Frames per simulated second.
    pub rate_hz: f64,
    pub frame: SnapshotFrame,
    /// The folder of the frames and `run.pvd`.
    pub dir: PathBuf,
}

/// File name of the time series in the snapshot folder.
pub const SERIES: &str = "run.pvd";

/// Frames waiting to be written before the step thread waits.
const QUEUE: usize = 4;

/// Moves a tank-frame snapshot into the world frame of `pose`.
pub fn to_world(s: &mut Snapshot, pose: &RigidState) {
    use nalgebra::Vector3;
    for (x, v) in s.position.iter_mut().zip(s.velocity.iter_mut()) {
        let r = Vector3::new(x[0] as f64, x[1] as f64, x[2] as f64);
        let rel = Vector3::new(v[0] as f64, v[1] as f64, v[2] as f64);
        let xw = pose.position + pose.orientation * r;
        let vw = pose.orientation * rel + pose.point_velocity(&r);
        *x = [xw.x as f32, xw.y as f32, xw.z as f32];
        *v = [vw.x as f32, vw.y as f32, vw.z as f32];
    }
}

/// The writer thread and its queue.
pub struct SnapshotWriter {
    tx: Option<SyncSender<(Snapshot, Option<RigidState>)>>,
    thread: Option<JoinHandle<Result<usize, String>>>,
    frame: SnapshotFrame,
    dir: PathBuf,
}

impl SnapshotWriter {
    /// Creates the folder (removing the frames of an earlier run there) and starts the writer thread.
    pub fn create(opts: &SnapshotOptions) -> std::io::Result<Self> {
        let dir = opts.dir.clone();
        let ctx =
            |e: std::io::Error| std::io::Error::new(e.kind(), format!("{}: {e}", dir.display()));
        std::fs::create_dir_all(&dir).map_err(ctx)?;
        for e in std::fs::read_dir(&dir).map_err(ctx)?.flatten() {
            let name = e.file_name().to_string_lossy().into_owned();
            if (name.starts_with("frame_") && name.ends_with(".vtu")) || name == SERIES {
                std::fs::remove_file(e.path()).map_err(ctx)?;
            }
        }
        pvd::write(&dir.join(SERIES), &[]).map_err(ctx)?;
        let (tx, rx) = sync_channel::<(Snapshot, Option<RigidState>)>(QUEUE);
        let wdir = dir.clone();
        let thread = std::thread::Builder::new().name("snapshots".into()).spawn(
            move || -> Result<usize, String> {
                let mut entries = Vec::new();
                for (mut s, pose) in rx {
                    if let Some(pose) = pose {
                        to_world(&mut s, &pose);
                    }
                    let file = format!("frame_{:06}.vtu", entries.len());
                    let path = wdir.join(&file);
                    vtu::write(&path, &s).map_err(|e| format!("{}: {e}", path.display()))?;
                    entries.push(pvd::Entry { time: s.time, file });
                    let series = wdir.join(SERIES);
                    pvd::write(&series, &entries)
                        .map_err(|e| format!("{}: {e}", series.display()))?;
                }
                Ok(entries.len())
            },
        )?;
        Ok(Self {
            tx: Some(tx),
            thread: Some(thread),
            frame: opts.frame,
            dir,
        })
    }

    pub fn dir(&self) -> &Path {
        &self.dir
    }

    pub fn frame(&self) -> SnapshotFrame {
        self.frame
    }

    /// Queues one frame; `pose` is the tank's at the frame's time (used for world-frame output). Fails with
    /// the writer's error if it has stopped.
    pub fn send(&mut self, s: Snapshot, pose: RigidState) -> std::io::Result<()> {
        let pose = (self.frame == SnapshotFrame::World).then_some(pose);
        let sent = self
            .tx
            .as_ref()
            .is_some_and(|tx| tx.send((s, pose)).is_ok());
        if sent {
            Ok(())
        } else {
            Err(std::io::Error::other(match self.join() {
                Err(e) => format!("writing snapshots: {e}"),
                Ok(_) => "writing snapshots: the writer has stopped".to_string(),
            }))
        }
    }

    fn join(&mut self) -> Result<usize, String> {
        self.tx = None;
        match self.thread.take() {
            Some(t) => t
                .join()
                .unwrap_or_else(|_| Err("the snapshot writer panicked".into())),
            None => Err("the snapshot writer has already stopped".into()),
        }
    }

    /// Writes the queued frames and stops the thread; returns the number of frames written.
    pub fn finish(mut self) -> std::io::Result<usize> {
        self.join()
            .map_err(|e| std::io::Error::other(format!("writing snapshots: {e}")))
    }
}

impl Drop for SnapshotWriter {
    fn drop(&mut self) {
        if self.thread.is_some() {
            let _ = self.join();
        }
    }
}
