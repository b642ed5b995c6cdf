//! `slosh plot`.

use super::*;

#[derive(clap::Args)]
pub struct Args {
    /// The folder a `slosh run` or `slosh replay` wrote.
    pub dir: PathBuf,
    /// A CSV of a time column and columns named like the run's (probe names, fx..mz, sensor names) to
    /// overlay; repeat for several.
    #[arg(long = "reference", value_name = "FILE.csv")]
    pub references: Vec<PathBuf>,
    /// Image size in pixels.
    #[arg(long, default_value = "1200x800")]
    pub size: String,
    /// Output folder (default: DIR/plots).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args {
        dir,
        references,
        size,
        out,
    } = a;
    let opts = crate::plot::PlotOptions {
        size: crate::plot::parse_size(&size).map_err(anyhow::Error::msg)?,
        references,
        out,
    };
    let p = crate::plot::plot(&dir, &opts).map_err(anyhow::Error::msg)?;
    for u in &p.unmatched {
        eprintln!("slosh: reference column left out (no run column of that name): {u}");
    }
    for f in &p.files {
        println!("{}", f.display());
    }
    Ok(())
}
