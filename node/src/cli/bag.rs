//! `slosh bag`.

use super::*;

#[derive(clap::Args)]
pub struct Args {
    #[command(subcommand)]
    pub command: BagCommand,
}

pub fn run(a: Args) -> anyhow::Result<()> {
    let BagCommand::Repair { bag, out } = a.command;
    let out = out.unwrap_or_else(|| beside(&bag, "_repaired"));
    let r = crate::record::repair(&bag, &out)?;
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
    Ok(())
}
