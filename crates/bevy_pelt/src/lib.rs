//! Shell-and-fin fur for Bevy 0.20: Pelt's fur (Lee et al. 2010) on any mesh, simulated in Bevy
//! systems and drawn with `pelt-render` on Bevy's own wgpu device, in Bevy's 3D pass.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy_pelt::{Fur, FurWind, PeltPlugin};
//!
//! fn main() {
//!     App::new()
//!         .add_plugins((DefaultPlugins, PeltPlugin))
//!         .insert_resource(FurWind { strength: 0.4, ..default() })
//!         .add_systems(Startup, setup)
//!         .run();
//! }
//!
//! fn setup(mut commands: Commands, mut meshes: ResMut<Assets<Mesh>>, assets: Res<AssetServer>) {
//!     commands.spawn((Mesh3d(meshes.add(Sphere::new(1.0))), Fur::new(assets.load("presets/mink.toml"))));
//!     commands.spawn((Camera3d::default(), Transform::from_xyz(0.0, 1.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y)));
//! }
//! ```
//!
//! - [`Fur`] on an entity with a `Mesh3d` grows fur from a [`FurPreset`] (a `.toml` asset, hot
//!   reloaded with Bevy's `file_watcher` feature; a bad file is an asset load error naming it).
//!   A preset's `[groom]` (a `.groom` file, PNG maps) loads with it and reloads when its files
//!   change: bald, short, long, combed, clumped and tinted regions.
//! - [`FurCollider`] (sphere, capsule, box, plane, closed mesh) on any entity pushes every fur out of its
//!   shape, following the entity's `GlobalTransform` (a physics body, an animated prop); a fast
//!   one sweeps the fur along its path. [`FurGrasp`] is a hand a host moves, closes and opens.
//! - [`FurSponge`] wets (or dries) the fur it touches; the preset's `[wet]` says what wetness
//!   does (heavier, softer strands; darker, shinier, clumped look) and how fast it dries.
//! - The simulation runs in `PostUpdate` after transforms (and after Bevy's animation): the
//!   preset's gravity (world space), [`FurWind`], touch from a ray ([`FurTouch`]), and pelt-core's
//!   inertia (the fur lags, swings and settles as the base accelerates). The base follows the
//!   entity's `GlobalTransform`, or, on an entity with Bevy's `SkinnedMesh`, Bevy's joints: their
//!   matrices skin the base with pelt-core each frame, so fur walks with an `AnimationPlayer`.
//! - The render world draws every fur into each 3D camera's main pass between the opaque and the
//!   transparent phase, on the camera's colour target (HDR or not), depth buffer (reverse-Z) and
//!   MSAA, so fur and Bevy's geometry occlude each other. Fur is lit by the scene's first
//!   `DirectionalLight` (its direction and colour, its illuminance times the camera's exposure
//!   over pi, as Bevy lights a white diffuse surface facing it), or by [`FurLight`]'s light when
//!   there is none; Bevy's ambient light (the camera's `AmbientLight`, else the
//!   `GlobalAmbientLight`) is the fur's ambient, [`FurLight`]'s only where the render world has
//!   neither. A camera's `EnvironmentMapLight` adds its diffuse cube map (read from the main
//!   world's `Assets<Image>` once per image: `Rgba16Float`, `Rgba32Float` or `Rgb9e5Ufloat`
//!   data on the CPU; see [`FurLight`]) as the fur's environment, by direction and colour,
//!   turned by its rotation, times its intensity and the exposure.
//! - Fur casts into Bevy's shadow maps (directional cascades, point and spot lights) unless its
//!   entity has `NotShadowCaster`, and receives them all (the directional cascades, spot lights'
//!   maps and point lights' cube faces, copied into pelt-render's `HostShadows`) unless it has
//!   `NotShadowReceiver`; on a camera
//!   with `DepthPrepass` (and
//!   `MotionVectorPrepass`, as TAA and motion blur need) writes its depth (and motion vectors)
//!   into Bevy's prepass textures; under TAA it is drawn with the camera's jitter.

#![warn(missing_docs)]
// Bevy systems take their queries and resources as parameters; splitting them up to please these
// two lints would only hide what a system reads.
#![allow(clippy::type_complexity, clippy::too_many_arguments)]

mod base;
mod contact;
mod convert;
mod environment;
mod fur;
mod mesh;
mod passes;
mod preset;
mod receive;
mod render;
mod wet;

use bevy::app::{App, Plugin, PostUpdate};
use bevy::asset::{AssetApp, AssetEventSystems};
use bevy::core_pipeline::core_3d::{main_opaque_pass_3d, main_transparent_pass_3d};
use bevy::core_pipeline::prepass::node::late_prepass;
use bevy::core_pipeline::{Core3dSystems, schedule::Core3d};
use bevy::ecs::schedule::IntoScheduleConfigs;
use bevy::pbr::{LATE_SHADOW_PASS, per_view_shadow_pass, shared_shadow_pass};
use bevy::render::render_asset::AssetExtractionSystems;
use bevy::render::{ExtractSchedule, Render, RenderApp, RenderSystems};
use bevy::transform::TransformSystems;

pub use contact::{FurCollider, FurGrasp, FurShape};
pub use fur::{Fur, FurState, FurTouch, FurWind};
/// Pelt's core (presets, structure, simulation).
pub use pelt_core;
/// Pelt's renderer, for [`FurLight`]'s `Light`.
pub use pelt_render;
pub use preset::{FurPreset, FurPresetLoader};
pub use render::{FurGpuStats, FurLight};
pub use wet::FurSponge;

/// Adds fur: the [`FurPreset`] asset and loader, the build and simulation systems, and the
/// render-world extraction, upload and drawing. Add it after Bevy's `DefaultPlugins`.
#[derive(Debug, Default, Clone, Copy)]
pub struct PeltPlugin;

impl Plugin for PeltPlugin {
    fn build(&self, app: &mut App) {
        app.init_asset::<FurPreset>()
            .init_asset_loader::<FurPresetLoader>()
            .init_resource::<FurWind>()
            .init_resource::<FurTouch>()
            .init_resource::<FurLight>()
            .init_resource::<environment::ImageVersions>()
            .add_systems(PostUpdate, (fur::build_furs, fur::simulate_furs).chain().after(TransformSystems::Propagate))
            .add_systems(PostUpdate, environment::track_image_versions.after(AssetEventSystems));
        let Some(render_app) = app.get_sub_app_mut(RenderApp) else { return };
        render_app
            .init_resource::<render::ExtractedFurs>()
            .init_resource::<render::FurGpu>()
            .init_resource::<render::FurGpuStats>()
            .init_resource::<passes::FurPasses>()
            .init_resource::<receive::FurReceivers>()
            .init_resource::<environment::FurEnvironments>()
            .add_systems(
                ExtractSchedule,
                (render::extract_furs, environment::extract_environments.before(AssetExtractionSystems)),
            )
            .add_systems(
                Render,
                (render::prepare_furs, passes::prepare_fur_passes, receive::prepare_fur_receivers)
                    .chain()
                    .in_set(RenderSystems::PrepareResources),
            )
            .add_systems(
                Core3d,
                render::draw_furs
                    .after(main_opaque_pass_3d)
                    .before(main_transparent_pass_3d)
                    .in_set(Core3dSystems::MainPass),
            )
            .add_systems(
                Core3d,
                (
                    passes::draw_fur_prepass.after(late_prepass).in_set(Core3dSystems::Prepass),
                    passes::draw_fur_cascades
                        .after(per_view_shadow_pass::<LATE_SHADOW_PASS>)
                        .before(Core3dSystems::MainPass),
                    passes::draw_fur_shared_shadows
                        .after(shared_shadow_pass::<LATE_SHADOW_PASS>)
                        .before(Core3dSystems::MainPass),
                    // After the fur's own depth is in Bevy's cascades, before the fur reads them.
                    receive::copy_fur_receivers.after(passes::draw_fur_cascades).before(Core3dSystems::MainPass),
                ),
            );
    }
}
