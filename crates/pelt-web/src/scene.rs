//! The scenes the page shows and how each grows its fur: the meshes (the Fox embedded), the
//! groomed structure and its simulation with the preset's `[simulation]` and `[wet]`.

use pelt_core::mesh::builtin::{TryOnScene, try_on_scene};
use pelt_core::sim::FurStepper;
use pelt_core::{Builtin, FurStructure, ImportOptions, Mesh, Preset};

use crate::model::ModelError;
use crate::presets;

/// What the page shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SceneChoice {
    /// The Stanford bunny, furred all over.
    Bunny,
    /// The paper's try-on: a plain body wearing a furred skirt.
    TryOn,
    /// The glTF Fox in its rest pose (the groomed Fox's mesh).
    Fox,
}

impl SceneChoice {
    /// `"bunny"`, `"tryon"` or `"fox"`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "bunny" => Some(Self::Bunny),
            "tryon" => Some(Self::TryOn),
            "fox" => Some(Self::Fox),
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
        }
    }
}

/// The glTF Fox (Khronos glTF-Sample-Assets; credits and licence in assets/CREDITS.md, and on
/// the page), embedded: a page reads no files. Its groom (`fox_groomed.groom`) is tied to this mesh as `Mesh::load` reads it.
const FOX_GLB: &[u8] = include_bytes!("../../../assets/meshes/Fox.glb");
/// The Fox's name in messages, as `pelt render` names it.
pub const FOX_NAME: &str = "assets/meshes/Fox.glb";

/// The furred mesh and the plain body (try-on only).
pub(crate) fn load_scene(scene: SceneChoice) -> Result<(Mesh, Option<Mesh>), ModelError> {
    Ok(match scene {
        SceneChoice::Bunny => (Builtin::Bunny.mesh().0, None),
        SceneChoice::TryOn => {
            let TryOnScene { garment, body, .. } = try_on_scene(&ImportOptions::default())?;
            (garment, Some(body))
        }
        SceneChoice::Fox => {
            (Mesh::from_gltf_slice(FOX_GLB, std::path::Path::new(FOX_NAME), &ImportOptions::default())?.0, None)
        }
    })
}

/// Grows the rest pose of `preset`'s fur on `scene`'s `mesh` (length relative to the mesh's
/// radius), groomed as its `[groom]` says (from the grooms the page ships).
pub(crate) fn grow(mesh: Mesh, scene: SceneChoice, preset: &Preset) -> Result<FurStructure, ModelError> {
    let params = preset.fur_params(&mesh);
    let mesh_name = match scene {
        SceneChoice::Fox => FOX_NAME.to_owned(),
        other => format!("the {} mesh", other.name()),
    };
    let groom = presets::web_groom(preset, &mesh, &mesh_name)?;
    Ok(FurStructure::new_groomed(mesh, &params, groom)?)
}

/// The simulation of `structure` with `preset`'s `[simulation]` and `[wet]`.
pub(crate) fn stepper(structure: &FurStructure, preset: &Preset) -> Result<FurStepper, ModelError> {
    let mut stepper = FurStepper::new(structure, &preset.simulation)?;
    stepper.set_wet(&preset.wet)?;
    Ok(stepper)
}
