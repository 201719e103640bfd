//! `pelt bench`.

/// Arguments of `pelt bench`.
#[derive(Debug, clap::Args)]
pub struct Args {}

pub fn run(_args: &Args) -> anyhow::Result<()> {
    anyhow::bail!("`pelt bench` is not built yet")
}
