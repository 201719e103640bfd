//! [`Stage`]: the meshes one fur scene is made of, loaded in one place for every command and
//! host: the mesh the fur grows on (a file, a built-in, or the try-on garment), its rig when the
//! file moves, and the plain meshes drawn beside it (the try-on body, `--plain-mesh` files); the
//! try-on body walks, with its own rig and colliders ([`StageBody`]).

use std::path::{Path, PathBuf};

use crate::anim::{Pose, Rig};
use crate::body::{BodyCapsules, BodyError, Capsule, TransferReport, walking_try_on};
use crate::mesh::builtin::{Builtin, TRY_ON_NAME};
use crate::mesh::{ImportOptions, Mesh, MeshError, MeshReport};

/// Where the furred mesh comes from.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum StageSource {
    /// A mesh file (.obj, .gltf, .glb); an animated glTF brings its rig.
    File(PathBuf),
    /// A built-in mesh.
    Builtin(Builtin),
    /// The paper's virtual try-on: the fur grows on a skirt skinned to a walking body
    /// ([`walking_try_on`]), the body is drawn plain.
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
    /// What moves `plain[0]` with the fur's rig: the try-on body.
    pub body: Option<StageBody>,
}

/// A plain mesh skinned to the same skeleton and clips as the fur's rig (the walking try-on
/// body): the host poses it at the fur's clip time.
#[derive(Clone, Debug)]
pub struct StageBody {
    /// The body's rig (its clips are the fur rig's, in the same order).
    pub rig: Rig,
    /// The body as one capsule per bone, for the fur to collide with.
    pub capsules: BodyCapsules,
    /// How the garment took the body's weights.
    pub transfer: TransferReport,
}

impl StageBody {
    /// Poses `body` (the stage's `plain[0]`) with `clip` at `clip_time_secs` into `pose`, and
    /// returns the body's capsules there, placed by `world_from_model`.
    pub fn pose(
        &self,
        body: &Mesh,
        clip: Option<usize>,
        clip_time_secs: f64,
        world_from_model: glam::Mat4,
        pose: &mut Pose,
    ) -> Vec<Capsule> {
        self.rig.pose(body, clip, clip_time_secs, pose);
        self.capsules.posed(&self.rig, pose, world_from_model)
    }
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
                Self { fur_mesh, report, rig, plain: Vec::new(), body: None }
            }
            StageSource::Builtin(builtin) => {
                let (fur_mesh, report) = builtin.mesh();
                Self { fur_mesh, report, rig: None, plain: Vec::new(), body: None }
            }
            StageSource::TryOn => {
                let scene = walking_try_on(options).map_err(|e| match e {
                    BodyError::Mesh(e) => e,
                    other => MeshError::Parse { file: TRY_ON_NAME.into(), line: None, message: other.to_string() },
                })?;
                Self {
                    fur_mesh: scene.garment,
                    report: scene.garment_report,
                    rig: Some(scene.garment_rig),
                    plain: vec![scene.body],
                    body: Some(StageBody { rig: scene.body_rig, capsules: scene.capsules, transfer: scene.transfer }),
                }
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
