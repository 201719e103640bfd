//! Pelt's core: everything about fur that needs no GPU.
//!
//! Data flows one way through the modules:
//! [`mesh`] (import and repair; [`anim`] poses a moving one; [`body`] skins a garment to a body
//! and gives the fur the body's surface) -> [`groom`] (per-vertex maps over
//! it) -> [`fur`] (the unified shell-and-fin structure) ->
//! [`texture`] (seeded shell and fin textures) -> [`sim`] (gravity, wind, touch) -> the renderer
//! in `pelt-render`. [`preset`] holds everything about one fur in one TOML file; [`stage`] loads
//! the meshes of one scene (the furred one, its rig, the plain ones) for every host; [`export`]
//! writes the fur as glTF and its strands as USD hair, through [`usd`] (USD's text format), which
//! also reads a strand groom for [`groom`] to bake. [`rng`] and [`param`] (the range error every
//! parameter check returns) sit below them all.

#![warn(missing_docs)]

pub mod anim;
pub mod body;
pub mod export;
pub mod fur;
pub mod groom;
pub mod light;
pub mod mesh;
pub mod param;
pub mod preset;
pub mod reference;
pub mod rng;
pub mod sim;
pub mod stage;
pub mod texture;
pub mod usd;
pub mod wet;

pub use fur::{FurParams, FurStructure, GrowthDirection, SeparatedStructure};
pub use groom::{Groom, GroomError, GroomParams};
pub use mesh::{ImportOptions, Mesh, MeshError, MeshReport, builtin::Builtin};
pub use preset::{LodParams, Preset, PresetError, RenderParams};
pub use sim::{FurStepper, Scene, SimError, SimParams, Simulation};
pub use stage::{Stage, StageSource};
pub use texture::{FurTextures, TextureParams};
