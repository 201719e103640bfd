//! [`Stage`]: the meshes one fur scene is made of, loaded in one place for every command and
//! host: the mesh the fur grows on (a file, a built-in, or the try-on garment), its rig when the
//! file moves, and the plain meshes drawn beside it (the try-on body, `--plain-mesh` files).

use std::path::{Path, PathBuf};

use crate::anim::Rig;
use crate::mesh::builtin::{Builtin, TRY_ON_NAME, try_on_scene};
use crate::mesh::{ImportOptions, Mesh, MeshError, MeshReport};

/// Where the furred mesh comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StageSource {
    /// A mesh file (.obj, .gltf, .glb); an animated glTF brings its rig.
    File(PathBuf),
    /// A built-in mesh.
    Builtin(Builtin),
    /// The paper's virtual try-on: the fur grows on the garment, the body is drawn plain.
    TryOn,
}

impl StageSource {
    /// A built-in by name: one of [`Builtin::ALL`]'s names or `tryon`.
    ///
    /// # Errors
    /// [`MeshError::UnknownBuiltin`] naming every choice.
    pub fn builtin(name: &str) -> Result<Self, MeshError> {
        if name == TRY_ON_NAME {
            return Ok(Self::TryOn);
        }
        Builtin::from_name(name).map(Self::Builtin).ok_or_else(|| {
            let mut names: Vec<&str> = Builtin::ALL.iter().map(|b| b.name()).collect();
            names.push(TRY_ON_NAME);
            MeshError::UnknownBuiltin { name: name.to_owned(), choices: names.join(", ") }
        })
    }

    /// A short name for reports and file names: the file's stem or the built-in's name.
    #[must_use]
    pub fn name(&self) -> String {
        match self {
            Self::File(path) => {
                path.file_stem().map_or_else(|| "mesh".to_owned(), |s| s.to_string_lossy().into_owned())
            }
            Self::Builtin(builtin) => builtin.name().to_owned(),
            Self::TryOn => TRY_ON_NAME.to_owned(),
        }
    }
}

/// The meshes of one fur scene.
#[derive(Clone, Debug)]
pub struct Stage {
    /// The mesh the fur grows on.
    pub fur_mesh: Mesh,
    /// What import did to it.
    pub report: MeshReport,
    /// Its rig, when it came from an animated glTF file.
    pub rig: Option<Rig>,
    /// Meshes drawn without fur: the try-on body, then the extra files in order.
    pub plain: Vec<Mesh>,
}

impl Stage {
    /// Loads `source` (welded as `options` says) and the plain meshes in `plain_files`.
    ///
    /// # Errors
    /// The first file that fails to load, named in the error.
    pub fn load(source: &StageSource, plain_files: &[PathBuf], options: &ImportOptions) -> Result<Self, MeshError> {
        let mut stage = match source {
            StageSource::File(path) => {
                let (fur_mesh, report, rig) = Mesh::load_animated(path, options)?;
                Self { fur_mesh, report, rig, plain: Vec::new() }
            }
            StageSource::Builtin(builtin) => {
                let (fur_mesh, report) = builtin.mesh();
                Self { fur_mesh, report, rig: None, plain: Vec::new() }
            }
            StageSource::TryOn => {
                let scene = try_on_scene(options)?;
                Self { fur_mesh: scene.garment, report: scene.garment_report, rig: None, plain: vec![scene.body] }
            }
        };
        for path in plain_files {
            stage.plain.push(load_plain(path)?);
        }
        Ok(stage)
    }
}

fn load_plain(path: &Path) -> Result<Mesh, MeshError> {
    Ok(Mesh::load(path, &ImportOptions::default())?.0)
}
