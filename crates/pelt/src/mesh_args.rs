//! The mesh arguments every command shares: a file, or a built-in.

use std::path::PathBuf;

use anyhow::Context as _;
use pelt_core::anim::Rig;
use pelt_core::{Builtin, ImportOptions, Mesh, MeshReport};

/// Which mesh to grow fur on.
#[derive(Debug, Clone, clap::Args)]
pub struct MeshArgs {
    /// A mesh file (.obj, .gltf, .glb).
    #[arg(value_name = "MESH", conflicts_with = "builtin")]
    pub mesh: Option<PathBuf>,
    /// A built-in mesh: box, bunny, sphere, plane, torus.
    #[arg(long, value_name = "NAME")]
    pub builtin: Option<String>,
    /// Keep duplicate positions apart instead of welding them (fins need welded adjacency).
    #[arg(long)]
    pub no_weld: bool,
}

impl MeshArgs {
    /// Loads the chosen mesh, with the file's rig (skins, animations) when it has one; with
    /// neither a file nor `--builtin`, `default`.
    pub fn load_animated(&self, default: Builtin) -> anyhow::Result<(Mesh, MeshReport, Option<Rig>)> {
        let options = ImportOptions { weld: !self.no_weld, ..ImportOptions::default() };
        match &self.mesh {
            Some(path) => Ok(Mesh::load_animated(path, &options)?),
            None => self.load_builtin(default).map(|(mesh, report)| (mesh, report, None)),
        }
    }

    fn load_builtin(&self, default: Builtin) -> anyhow::Result<(Mesh, MeshReport)> {
        match &self.builtin {
            Some(name) => {
                let builtin = Builtin::from_name(name).with_context(|| {
                    let names: Vec<_> = Builtin::ALL.iter().map(|b| b.name()).collect();
                    format!("unknown built-in mesh {name:?}; choose one of {}", names.join(", "))
                })?;
                Ok(builtin.mesh())
            }
            None => Ok(default.mesh()),
        }
    }
}
