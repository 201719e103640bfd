//! The scenes the page shows and how each grows its fur: the meshes (the Fox embedded), the
//! groomed structure and its simulation with the preset's `[simulation]` and `[wet]`; the
//! try-on's body walks, as in `pelt render --builtin tryon`.

use glam::Vec3;
use pelt_core::anim::{Pose, Rig};
use pelt_core::sim::FurStepper;
use pelt_core::stage::StageBody;
use pelt_core::{Builtin, FurStructure, ImportOptions, Mesh, Preset, Stage, StageSource};

use crate::model::ModelError;
use crate::presets;

/// What the page shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneChoice {
    /// The Stanford bunny, furred all over.
    Bunny,
    /// The paper's try-on: a plain body walking on the spot in a furred skirt.
    TryOn,
    /// The glTF Fox in its rest pose (the groomed Fox's mesh).
    Fox,
    /// Sixteen Foxes walking on the spot on a ground ([`crate::herd`]).
    Herd,
}

impl SceneChoice {
    /// `"bunny"`, `"tryon"`, `"fox"` or `"herd"`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "bunny" => Some(Self::Bunny),
            "tryon" => Some(Self::TryOn),
            "fox" => Some(Self::Fox),
            "herd" => Some(Self::Herd),
            _ => None,
        }
    }

    /// The name [`SceneChoice::from_name`] takes.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Bunny => "bunny",
            Self::TryOn => "tryon",
            Self::Fox => "fox",
            Self::Herd => "herd",
        }
    }
}

/// The glTF Fox (Khronos glTF-Sample-Assets; credits and licence in assets/CREDITS.md, and on
/// the page), embedded: a page reads no files. Its groom (`fox_groomed.groom`) is tied to this mesh as `Mesh::load` reads it.
const FOX_GLB: &[u8] = include_bytes!("../../../assets/meshes/Fox.glb");
/// The Fox's name in messages, as `pelt render` names it.
pub const FOX_NAME: &str = "assets/meshes/Fox.glb";

/// The clip the try-on body walks with (its only one).
const WALK_CLIP: usize = 0;

/// The try-on's walking body: drawn plain, posed with the skirt's clip at the page's clock, its
/// capsules colliding with the skirt's fur (the stage `pelt render --builtin tryon` loads).
#[derive(Clone, Debug)]
pub struct WalkingBody {
    /// The body in its bind pose.
    pub mesh: Mesh,
    /// The skirt's rig: the body's skeleton and walk, with the skirt's transferred weights.
    pub garment_rig: Rig,
    /// The body's rig and capsules.
    pub body: StageBody,
    pose: Pose,
}

impl WalkingBody {
    /// The walk's length in seconds (it loops).
    #[must_use]
    pub fn cycle_secs(&self) -> f32 {
        self.garment_rig.animations()[WALK_CLIP].duration_secs()
    }

    /// Poses the body at `clip_secs` of the walk: its positions and normals.
    pub fn pose(&mut self, clip_secs: f64) -> (&[Vec3], &[Vec3]) {
        self.body.rig.pose(&self.mesh, Some(WALK_CLIP), clip_secs, &mut self.pose);
        (&self.pose.positions, &self.pose.normals)
    }
}

/// The furred mesh, the try-on's walking body and the herd's rig (the Fox's, with its Walk).
pub(crate) fn load_scene(scene: SceneChoice) -> Result<(Mesh, Option<WalkingBody>, Option<Rig>), ModelError> {
    Ok(match scene {
        SceneChoice::Bunny => (Builtin::Bunny.mesh().0, None, None),
        SceneChoice::TryOn => {
            let stage = Stage::load(&StageSource::TryOn, &[], &ImportOptions::default())?;
            let missing = || pelt_core::MeshError::Parse {
                file: "tryon".into(),
                line: None,
                message: "the try-on stage has no walking body".to_owned(),
            };
            let (Some(garment_rig), Some(body), Some(mesh)) = (stage.rig, stage.body, stage.plain.into_iter().next())
            else {
                return Err(missing().into());
            };
            (stage.fur_mesh, Some(WalkingBody { mesh, garment_rig, body, pose: Pose::default() }), None)
        }
        SceneChoice::Fox => {
            (Mesh::from_gltf_slice(FOX_GLB, std::path::Path::new(FOX_NAME), &ImportOptions::default())?.0, None, None)
        }
        SceneChoice::Herd => {
            let name = std::path::Path::new(FOX_NAME);
            let (mesh, _, rig) = Mesh::from_gltf_slice_animated(FOX_GLB, name, &ImportOptions::default())?;
            let rig = rig.ok_or_else(|| pelt_core::MeshError::Parse {
                file: FOX_NAME.into(),
                line: None,
                message: "the Fox has no skeleton to walk with".to_owned(),
            })?;
            (mesh, None, Some(rig))
        }
    })
}

/// Grows the rest pose of `preset`'s fur on `scene`'s `mesh` (length relative to the mesh's
/// radius), groomed as its `[groom]` says (from the grooms the page ships).
pub(crate) fn grow(mesh: Mesh, scene: SceneChoice, preset: &Preset) -> Result<FurStructure, ModelError> {
    let params = preset.fur_params(&mesh);
    let mesh_name = match scene {
        SceneChoice::Fox | SceneChoice::Herd => FOX_NAME.to_owned(),
        other => format!("the {} mesh", other.name()),
    };
    let groom = presets::web_groom(preset, &mesh, &mesh_name)?;
    Ok(FurStructure::new_groomed(mesh, &params, groom)?)
}

/// The simulation of `structure` with `preset`'s `[simulation]` and `[wet]`; on the try-on the
/// skirt plays the walk (clip time = simulation time, as `pelt render`'s catwalk) and the body's
/// capsules push its fur out of the legs.
pub(crate) fn stepper(
    structure: &FurStructure,
    preset: &Preset,
    walking: Option<&WalkingBody>,
) -> Result<FurStepper, ModelError> {
    let mut stepper = FurStepper::new(structure, &preset.simulation)?;
    stepper.set_wet(&preset.wet)?;
    if let Some(walking) = walking {
        stepper.set_clip(walking.garment_rig.clone(), Some(WALK_CLIP));
        let body = &walking.body;
        stepper.set_body(Some((walking.mesh.clone(), body.rig.clone(), body.capsules.clone())));
    }
    Ok(stepper)
}
