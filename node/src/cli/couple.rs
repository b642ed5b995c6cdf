//! `slosh couple`.

use super::*;

#[derive(clap::Args)]
pub struct Args {
    /// Config file or built-in case (its `motion.*` is not used).
    pub config: String,
    /// Service prefix: NAME/coupling, NAME/outputs, NAME/particles.
    #[arg(long, default_value = "slosh")]
    pub service: String,
    /// Publish particle frames on NAME/particles at this many per second of sample time.
    #[arg(long, default_value_t = 0.0)]
    pub particles: f64,
    /// Answer without simulating (to time the transport alone).
    #[arg(long)]
    pub dry: bool,
    /// Also write probes.csv, wrench.csv and pressure.csv here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Stop after this many steps past the first sample (which starts the simulation): N + 1 answers, as
    /// many as a client's `--steps N` sends (default: until SIGINT/SIGTERM).
    #[arg(long)]
    pub max_steps: Option<u64>,
    /// Override a parameter by its dotted name, value as YAML.
    #[arg(long = "set", value_name = "KEY=VALUE")]
    pub set: Vec<String>,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let Args {
        config: cfg,
        service,
        particles,
        dry,
        out,
        max_steps,
        set,
    } = a;
    let loaded = config::load(&cfg, &set)?;
    let opts = crate::iox::couple::CoupleOptions {
        service: service.clone(),
        particles_hz: particles,
        dry,
        out,
        max_steps,
    };
    let s = crate::iox::couple::serve(&loaded, &opts, || {
        eprintln!(
            "slosh: serving {} on iceoryx2 service {service}/coupling (outputs on {service}/outputs{})",
            loaded.source_name,
            if particles > 0.0 { format!(", particles on {service}/particles") } else { String::new() }
        );
    })?;
    println!("{}", serde_json::to_string(&s)?);
    Ok(())
}
