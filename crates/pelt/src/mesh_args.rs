//! The mesh arguments every command shares: a file, or a built-in.

use std::path::PathBuf;

use pelt_core::{Builtin, ImportOptions, Stage, StageSource};

/// Which mesh to grow fur on.
#[derive(Debug, Clone, clap::Args)]
pub struct MeshArgs {
    /// A mesh file (.obj, .gltf, .glb).
    #[arg(value_name = "MESH", conflicts_with = "builtin")]
    pub mesh: Option<PathBuf>,
    /// A built-in mesh: box, bunny, sphere, plane, torus, or tryon (a furry skirt on a body).
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<String>,
    /// Keep duplicate positions apart instead of welding them (fins need welded adjacency).
    #[arg(long)]
    pub no_weld: bool,
}

impl MeshArgs {
    /// Where the furred mesh comes from: the file, `--builtin` (`tryon` included), or `default`.
    pub fn source(&self, default: Builtin) -> anyhow::Result<StageSource> {
        Ok(match (&self.mesh, &self.builtin) {
            (Some(path), _) => StageSource::File(path.clone()),
            (None, Some(name)) => StageSource::builtin(name)?,
            (None, None) => StageSource::Builtin(default),
        })
    }

    /// The scene's meshes: the furred one (with its rig, for an animated file), the try-on body
    /// for `--builtin tryon`, and `plain_files`.
    pub fn stage(&self, default: Builtin, plain_files: &[PathBuf]) -> anyhow::Result<Stage> {
        let options = ImportOptions { weld: !self.no_weld, ..ImportOptions::default() };
        Ok(Stage::load(&self.source(default)?, plain_files, &options)?)
    }
}
