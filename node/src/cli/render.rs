//! `slosh render`.

use super::*;

#[derive(clap::Args)]
pub struct Args {
    /// The folder of a run made with --snapshots (or its snapshots folder).
    pub dir: PathBuf,
    /// Colour the liquid by speed or by pressure.
    #[arg(long, value_enum, default_value_t = crate::render::Colour::Speed)]
    pub colour: crate::render::Colour,
    /// Picture size in pixels.
    #[arg(long, default_value = "960x640")]
    pub size: String,
    /// GIF frames per second.
    #[arg(long, default_value_t = 10.0)]
    pub fps: f64,
    /// 3D runs: draw the layer of particles nearest y = SLICE (m, tank frame) instead of a side view.
    #[arg(long, allow_negative_numbers = true)]
    pub slice: Option<f64>,
    /// Output folder (default: DIR/render).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args {
        dir,
        colour,
        size,
        fps,
        slice,
        out,
    } = a;
    let opts = crate::render::RenderOptions {
        colour,
        size: crate::plot::parse_size(&size).map_err(anyhow::Error::msg)?,
        fps,
        slice,
        out,
    };
    let r = crate::render::render(&dir, &opts).map_err(anyhow::Error::msg)?;
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
    Ok(())
}
