//! `pelt textures`.

/// Arguments of `pelt textures`.
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("`pelt textures` is not built yet")
}
