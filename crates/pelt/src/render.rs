//! `pelt render`.

/// Arguments of `pelt render`.
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("`pelt render` is not built yet")
}
