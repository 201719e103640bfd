//! `pelt stats`.

/// Arguments of `pelt stats`.
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("`pelt stats` is not built yet")
}
