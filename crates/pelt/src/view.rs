//! `pelt view`.

/// Arguments of `pelt view`.
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("`pelt view` is not built yet")
}
