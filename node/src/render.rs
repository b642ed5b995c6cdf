//! `slosh render DIR`: pictures of a run from its particle frames (`--snapshots`): a PNG per frame and an
//! animated GIF, the liquid coloured by speed or pressure (one colour scale for the whole run, shown as a
//! bar), boundary particles grey, the tank outline drawn. A 2D run is drawn in its x–z plane; a 3D run as a
//! side view (looking along +y, nearer particles in front) or, with `--slice Y`, the particles of one
//! layer around y = Y.

use crate::plot::figure::register_font;
use crate::snapshot::{pvd, vtu, SERIES};
use plotters::prelude::*;
use plotters::style::colors::colormaps::ViridisRGB;
use sph::observe::snapshot::Snapshot;
use std::path::{Path, PathBuf};

/// The quantity the liquid is coloured by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Colour {
    /// Speed, m/s.
    #[default]
    Speed,
    /// Gauge pressure, Pa.
    Pressure,
}

#[derive(Clone, Debug)]
pub struct RenderOptions {
    pub colour: Colour,
    /// Picture size in pixels.
    pub size: (u32, u32),
    /// GIF frames per second of wall-clock time.
    pub fps: f64,
    /// 3D: draw only the layer of particles nearest y = this (within half a particle spacing of the liquid
    /// row nearest it; tank frame, m).
    pub slice: Option<f64>,
    /// Output folder (None: `DIR/render`).
    pub out: Option<PathBuf>,
}

impl Default for RenderOptions {
    fn default() -> Self {
        Self {
            colour: Colour::Speed,
            size: (960, 640),
            fps: 10.0,
            slice: None,
            out: None,
        }
    }
}

/// What [`render`] wrote.
#[derive(Clone, Debug)]
pub struct Rendered {
    pub frames: Vec<PathBuf>,
    pub gif: PathBuf,
}

/// What the run's summary says about the drawing.
struct Facts {
    /// Tank length and height, m (tank frame: x from −L/2 to L/2, z from 0 to H).
    tank: Option<(f64, f64)>,
    spacing: Option<f64>,
    /// Whether the frames are in the tank frame (the outline is drawn only then).
    tank_frame: bool,
}

fn facts(run: &Path) -> Facts {
    let s: Option<serde_json::Value> = std::fs::read_to_string(run.join("summary.json"))
        .ok()
        .and_then(|t| serde_json::from_str(&t).ok());
    // (summaries written by older versions have the given parameters only)
    let p = s.as_ref().map(|s| match &s["effective_parameters"] {
        serde_json::Value::Null => &s["parameters"],
        e => e,
    });
    Facts {
        tank: p.and_then(|p| Some((p["tank"]["length"].as_f64()?, p["tank"]["height"].as_f64()?))),
        spacing: p.and_then(|p| p["particle_spacing"].as_f64()),
        tank_frame: s
            .as_ref()
            .and_then(|s| s["snapshots"]["frame"].as_str())
            .is_none_or(|f| f == "tank"),
    }
}

/// Finds the series: `DIR/snapshots/run.pvd` of a run folder, or `DIR/run.pvd` of a snapshot folder.
fn series(dir: &Path) -> Result<(PathBuf, PathBuf), String> {
    for (pvd, run) in [
        (dir.join("snapshots").join(SERIES), dir.to_path_buf()),
        (
            dir.join(SERIES),
            dir.parent().unwrap_or(Path::new(".")).to_path_buf(),
        ),
    ] {
        if pvd.exists() {
            return Ok((pvd, run));
        }
    }
    Err(format!(
        "{}: no particle frames (snapshots/{SERIES}); write them with `slosh run CASE --out {} --snapshots 20`",
        dir.display(),
        dir.display()
    ))
}

/// The particles drawn and the order they are drawn in (back to front): boundary first, then liquid.
fn visible(s: &Snapshot, f: &Facts, slice: Option<f64>) -> Vec<usize> {
    let dp = f.spacing.unwrap_or(0.01);
    // The slice is the layer of liquid particles nearest y = Y: the lattice's rows may sit off Y (spread to
    // fit the tank's breadth, a row's y need not be a multiple of the spacing).
    let slice = slice.map(|y| {
        (0..s.len())
            .filter(|&i| s.is_fluid(i))
            .map(|i| s.position[i][1] as f64)
            .min_by(|a, b| (a - y).abs().total_cmp(&(b - y).abs()))
            .unwrap_or(y)
    });
    let mut idx: Vec<usize> = (0..s.len())
        .filter(|&i| {
            let p = s.position[i];
            if s.dimension == 2 {
                return true;
            }
            if let Some(y) = slice {
                return (p[1] as f64 - y).abs() <= 0.5 * dp + 1e-6;
            }
            if s.is_fluid(i) {
                return true;
            }
            // Side view: the front and back walls would hide the liquid; keep the end walls and bottom.
            match (f.tank, f.tank_frame) {
                (Some((l, _)), true) => (p[0] as f64).abs() > 0.5 * l || p[2] < 0.0,
                _ => false,
            }
        })
        .collect();
    // Boundary first; in 3D the far side (large y) first so the near side is drawn over it.
    idx.sort_by(|&a, &b| {
        s.is_fluid(a)
            .cmp(&s.is_fluid(b))
            .then(s.position[b][1].total_cmp(&s.position[a][1]))
    });
    idx
}

fn value(s: &Snapshot, i: usize, c: Colour) -> f64 {
    match c {
        Colour::Speed => {
            let v = s.velocity[i];
            ((v[0] * v[0] + v[1] * v[1] + v[2] * v[2]) as f64).sqrt()
        }
        Colour::Pressure => s.pressure[i] as f64,
    }
}

/// A frame's colour scale: 0 (or the lowest value, if negative) to its 99th percentile (the run's scale
/// ends at the 90th percentile of those over the frames).
fn scale(values: &mut Vec<f64>) -> (f64, f64) {
    values.retain(|v| v.is_finite());
    if values.is_empty() {
        return (0.0, 1.0);
    }
    values.sort_by(f64::total_cmp);
    let hi = values[((values.len() - 1) as f64 * 0.99) as usize];
    (values[0].min(0.0), hi.max(values[0].min(0.0) + 1e-9))
}

struct View {
    /// World window: x and z bounds, m.
    x: (f64, f64),
    z: (f64, f64),
    /// Pixels per metre and the drawing's pixel origin.
    px: f64,
    origin: (f64, f64),
    height: f64,
}

impl View {
    fn new(x: (f64, f64), z: (f64, f64), area: (u32, u32), top: u32) -> Self {
        let (w, h) = (area.0 as f64 - 40.0, area.1 as f64 - top as f64 - 30.0);
        let px = (w / (x.1 - x.0)).min(h / (z.1 - z.0));
        let origin = (
            20.0 + 0.5 * (w - px * (x.1 - x.0)),
            top as f64 + 10.0 + 0.5 * (h - px * (z.1 - z.0)),
        );
        Self {
            x,
            z,
            px,
            origin,
            height: px * (z.1 - z.0),
        }
    }

    fn at(&self, x: f64, z: f64) -> (i32, i32) {
        (
            (self.origin.0 + (x - self.x.0) * self.px).round() as i32,
            (self.origin.1 + self.height - (z - self.z.0) * self.px).round() as i32,
        )
    }
}

/// Draws one frame into an RGB buffer.
#[allow(clippy::too_many_arguments)]
fn draw(
    buf: &mut [u8],
    size: (u32, u32),
    s: &Snapshot,
    f: &Facts,
    opts: &RenderOptions,
    range: (f64, f64),
    window: ((f64, f64), (f64, f64)),
) -> Result<(), String> {
    let e = |e: DrawingAreaErrorKind<_>| format!("drawing: {e}");
    let root = BitMapBackend::with_buffer(buf, size).into_drawing_area();
    root.fill(&WHITE).map_err(e)?;
    let bar_w = 110;
    let (plot, bar) = root.split_horizontally(size.0.saturating_sub(bar_w));
    let title = match (s.dimension, opts.slice) {
        (2, _) => String::new(),
        (_, Some(y)) => format!(", slice y = {y} m"),
        _ => ", side view".to_string(),
    };
    plot.draw(&Text::new(
        format!("t = {:.2} s{title}", s.time),
        (20, 10),
        ("sans-serif", 22).into_font().color(&BLACK),
    ))
    .map_err(e)?;
    let view = View::new(window.0, window.1, (size.0 - bar_w, size.1), 40);
    let dp = f.spacing.unwrap_or(0.01);
    let radius = ((0.5 * dp * view.px).round() as i32).max(1);
    let grey = RGBColor(160, 160, 160);
    for i in visible(s, f, opts.slice) {
        let p = s.position[i];
        let at = view.at(p[0] as f64, p[2] as f64);
        let colour = if s.is_fluid(i) {
            ViridisRGB.get_color_normalized(
                value(s, i, opts.colour) as f32,
                range.0 as f32,
                range.1 as f32,
            )
        } else {
            grey
        };
        plot.draw(&Circle::new(at, radius, colour.filled()))
            .map_err(e)?;
    }
    if let (Some((l, h)), true) = (f.tank, f.tank_frame) {
        let corners = [(-0.5 * l, h), (-0.5 * l, 0.0), (0.5 * l, 0.0), (0.5 * l, h)]
            .map(|(x, z)| view.at(x, z));
        plot.draw(&PathElement::new(corners.to_vec(), BLACK.stroke_width(2)))
            .map_err(e)?;
    }
    // The colour bar.
    let (label, unit) = match opts.colour {
        Colour::Speed => ("speed", "m/s"),
        Colour::Pressure => ("pressure", "Pa"),
    };
    let (top, bottom) = (60, size.1 as i32 - 40);
    bar.draw(&Text::new(
        format!("{label} ({unit})"),
        (8, 30),
        ("sans-serif", 16).into_font().color(&BLACK),
    ))
    .map_err(e)?;
    for y in top..bottom {
        let h = (bottom - y) as f32 / (bottom - top) as f32;
        bar.draw(&Rectangle::new(
            [(10, y), (34, y + 1)],
            ViridisRGB.get_color(h).filled(),
        ))
        .map_err(e)?;
    }
    for k in 0..=4 {
        let v = range.0 + (range.1 - range.0) * k as f64 / 4.0;
        let y = bottom - (bottom - top) * k / 4;
        let text = if v.abs() >= 1000.0 {
            format!("{v:.0}")
        } else {
            format!("{v:.3}")
        };
        bar.draw(&Text::new(
            text,
            (40, y - 7),
            ("sans-serif", 14).into_font().color(&BLACK),
        ))
        .map_err(e)?;
    }
    root.present().map_err(e)
}

/// Renders the frames of the run (or snapshot folder) `dir`.
pub fn render(dir: &Path, opts: &RenderOptions) -> Result<Rendered, String> {
    if !(opts.fps.is_finite() && opts.fps > 0.0 && opts.fps <= 100.0) {
        return Err(format!(
            "--fps {}: must be more than 0 and at most 100 frames per second",
            opts.fps
        ));
    }
    register_font();
    let (series_path, run) = series(dir)?;
    let list = pvd::read(&series_path)?;
    if list.is_empty() {
        return Err(format!(
            "{}: the series lists no frames (did the run stop before its first snapshot?)",
            series_path.display()
        ));
    }
    let f = facts(&run);
    // First pass: the colour scale and the window over the whole run.
    let (mut x, mut z) = (
        (f64::INFINITY, f64::NEG_INFINITY),
        (f64::INFINITY, f64::NEG_INFINITY),
    );
    let mut highs = Vec::new();
    let mut lows = Vec::new();
    for (_, path) in &list {
        let s = vtu::read(path).map_err(|e| e.to_string())?;
        let shown = visible(&s, &f, opts.slice);
        if shown.is_empty() {
            return Err(format!(
                "{}: no particle to draw{}",
                path.display(),
                opts.slice
                    .map(|y| format!(" in the slice y = {y} m"))
                    .unwrap_or_default()
            ));
        }
        let mut v: Vec<f64> = shown
            .iter()
            .filter(|&&i| s.is_fluid(i))
            .map(|&i| value(&s, i, opts.colour))
            .collect();
        let (lo, hi) = scale(&mut v);
        lows.push(lo);
        highs.push(hi);
        for &i in &shown {
            let p = s.position[i];
            x = (x.0.min(p[0] as f64), x.1.max(p[0] as f64));
            z = (z.0.min(p[2] as f64), z.1.max(p[2] as f64));
        }
    }
    let pad = f.spacing.unwrap_or(0.01);
    let window = ((x.0 - pad, x.1 + pad), (z.0 - pad, z.1 + pad));
    // One scale for the run: robust to a few frames with outliers (a pressure spike in a corner).
    highs.sort_by(f64::total_cmp);
    let range = (
        lows.iter().copied().fold(f64::INFINITY, f64::min),
        highs[((highs.len() - 1) as f64 * 0.9).round() as usize],
    );
    let out = opts.out.clone().unwrap_or_else(|| run.join("render"));
    std::fs::create_dir_all(&out).map_err(|e| format!("{}: {e}", out.display()))?;
    // The pictures of an earlier render into the same folder (perhaps of more frames) would be taken for
    // this run's.
    for old in std::fs::read_dir(&out).map_err(|e| format!("{}: {e}", out.display()))? {
        let p = old.map_err(|e| format!("{}: {e}", out.display()))?.path();
        let name = p.file_name().and_then(|n| n.to_str()).unwrap_or("");
        if name.starts_with("frame_") && name.ends_with(".png") {
            std::fs::remove_file(&p).map_err(|e| format!("{}: {e}", p.display()))?;
        }
    }
    let (w, h) = opts.size;
    let gif_path = out.join("run.gif");
    let gif_file =
        std::fs::File::create(&gif_path).map_err(|e| format!("{}: {e}", gif_path.display()))?;
    let gerr = |e: gif::EncodingError| format!("{}: {e}", gif_path.display());
    let mut gif = gif::Encoder::new(
        std::io::BufWriter::new(gif_file),
        w.min(u16::MAX as u32) as u16,
        h.min(u16::MAX as u32) as u16,
        &[],
    )
    .map_err(gerr)?;
    gif.set_repeat(gif::Repeat::Infinite).map_err(gerr)?;
    let delay = (100.0 / opts.fps).round().max(1.0) as u16;
    let mut frames = Vec::new();
    let mut buf = vec![0u8; (w * h * 3) as usize];
    for (k, (_, path)) in list.iter().enumerate() {
        let s = vtu::read(path).map_err(|e| e.to_string())?;
        draw(&mut buf, (w, h), &s, &f, opts, range, window)?;
        let png = out.join(format!("frame_{k:06}.png"));
        image::save_buffer(&png, &buf, w, h, image::ColorType::Rgb8)
            .map_err(|e| format!("{}: {e}", png.display()))?;
        frames.push(png);
        let mut frame = gif::Frame::from_rgb_speed(w as u16, h as u16, &buf, 10);
        frame.delay = delay;
        gif.write_frame(&frame).map_err(gerr)?;
    }
    gif.into_inner()
        .and_then(|w| w.into_inner().map_err(|e| e.into_error()))
        .and_then(|f| f.sync_data())
        .map_err(|e| format!("{}: {e}", gif_path.display()))?;
    Ok(Rendered {
        frames,
        gif: gif_path,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_colour_scale_ignores_the_top_percent_and_nan() {
        let mut v: Vec<f64> = (0..1000).map(|i| i as f64).chain([f64::NAN, 1e9]).collect();
        let (lo, hi) = scale(&mut v);
        assert_eq!(lo, 0.0);
        assert!((985.0..1000.0).contains(&hi), "{hi}");
    }
}
