//! A `pelt export` file in Bevy, with Bevy's own glTF loader and no bevy_pelt: on the right, the
//! Fox with its fur exported as plain glTF (shells and fins bound to the Fox's skin, so Bevy's
//! skinning walks them); on the left, the same Fox with bevy_pelt's simulated fur.
//!
//! `cargo run --release -p bevy_pelt --example export [--ignore-rust-version] -- [PRESET] [--screenshot PNG]`
//!
//! The export is written at start to `assets/exported/fox-fur.glb` (ignored by git) with
//! `pelt_core::export`, as `pelt export assets/meshes/Fox.glb --preset assets/presets/fox.toml -o
//! assets/exported/fox-fur.glb` writes it. Right-drag orbits, the wheel zooms.

mod common;

use std::path::Path;

use bevy::mesh::skinning::SkinnedMesh;
use bevy::prelude::*;
use bevy::world_serialization::WorldInstanceReady;
use bevy_pelt::{Fur, PeltPlugin};
use common::{Args, ExamplePlugin, Orbit};
use glam::Vec3 as CoreVec3;
use pelt_core::anim::Pose;
use pelt_core::export::{AlphaMode, Export, ExportInput, FurSkin, bind_space_positions, source_skin_joints};
use pelt_core::{FurStepper, FurStructure, ImportOptions, Preset, Stage, StageSource};
use pelt_render::{FurLook, tile_mapping};

const FOX: &str = "meshes/Fox.glb";
/// Where the export is written, relative to the repository's `assets/`.
const EXPORTED: &str = "exported/fox-fur.glb";
const FOX_SCALE: f32 = 0.01;
/// The clip both Foxes play (Survey, Walk, Run).
const WALK: usize = 1;

fn main() {
    let args = Args::from_env("presets/fox.toml");
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    if let Err(error) = export_fox(&assets, &args.preset) {
        eprintln!("cannot export the Fox's fur: {error}");
        std::process::exit(1);
    }
    App::new()
        .add_plugins((
            common::default_plugins("Pelt in Bevy: an exported glTF beside the simulated fur"),
            PeltPlugin,
            ExamplePlugin {
                orbit: Orbit {
                    yaw: 0.0,
                    pitch: 0.2,
                    distance: 3.6,
                    distance_range: (0.8, 10.0),
                    focus: Vec3::new(0.0, 0.5, 0.0),
                },
                sun_lux: 6000.0,
                screenshot_frame: 120,
            },
        ))
        .insert_resource(args)
        .add_systems(Startup, setup)
        .run();
}

/// The Fox's fur settled under gravity at the rest pose, in the bind pose and bound to its skin,
/// written to `assets/EXPORTED`.
fn export_fox(assets: &Path, preset: &str) -> Result<(), Box<dyn std::error::Error>> {
    let source = assets.join(FOX);
    let preset = Preset::load(assets.join(preset))?;
    let stage = Stage::load(&StageSource::File(source.clone()), &[], &ImportOptions::default())?;
    let rig = stage.rig.ok_or("the Fox has no rig")?;
    let fur = FurStructure::new(stage.fur_mesh.clone(), &preset.fur_params(&stage.fur_mesh))?;
    let mut params = preset.simulation.clone();
    params.wind.strength = 0.0;
    let mut stepper = FurStepper::new(&fur, &params)?;
    for frame in 0..=45 {
        stepper.advance_to(f64::from(frame) / 30.0)?;
    }
    let mut pose = Pose::default();
    rig.pose(&fur.mesh, None, 0.0, &mut pose);
    let positions: Vec<CoreVec3> =
        bind_space_positions(stepper.simulation().positions(), &fur.positions, &rig.vertex_matrices(&pose));
    let joints = source_skin_joints(&source)?;
    let influences = rig.influences_in_skin(joints.first().ok_or("the Fox has no skin")?).ok_or("not one skin")?;
    let textures = preset.generate_textures()?;
    let look = FurLook::default();
    let input = ExportInput {
        fur: &fur,
        positions: &positions,
        textures: &textures,
        mapping: tile_mapping(&fur.mesh, &look),
        root_occlusion: look.root_occlusion,
        shells: fur.layers,
        alpha: AlphaMode::Mask,
        skin: Some(FurSkin { skin: 0, influences }),
        source: Some(&source),
        plain: &[],
        extras: serde_json::json!({ "example": "bevy_pelt export" }),
        morphs: None,
    };
    let path = assets.join(EXPORTED);
    std::fs::create_dir_all(path.parent().ok_or("no folder")?)?;
    Export::build(&input)?.write(&path)?;
    Ok(())
}

/// Marks the Fox whose fur bevy_pelt simulates.
#[derive(Component)]
struct Simulated;

/// The Walk clip of one file, as an animation graph.
#[derive(Component, Clone)]
struct Walk {
    node: AnimationNodeIndex,
    graph: Handle<AnimationGraph>,
}

fn setup(mut commands: Commands, mut graphs: ResMut<Assets<AnimationGraph>>, assets: Res<AssetServer>) {
    for (file, x, simulated) in [(FOX, -0.8, true), (EXPORTED, 0.8, false)] {
        let (graph, nodes) =
            AnimationGraph::from_clips([assets.load(GltfAssetLabel::Animation(WALK).from_asset(file))]);
        let walk = Walk { node: nodes[0], graph: graphs.add(graph) };
        let mut fox = commands.spawn((
            WorldAssetRoot(assets.load(GltfAssetLabel::Scene(0).from_asset(file))),
            Transform::from_xyz(x, 0.0, 0.0).with_scale(Vec3::splat(FOX_SCALE)),
            walk,
        ));
        if simulated {
            fox.insert(Simulated);
        }
        fox.observe(play_walk);
    }
    info!("left: bevy_pelt's simulated fur; right: the fur exported as glTF, drawn by Bevy alone");
}

/// Once a scene is in, its animation player walks; the left Fox's skinned meshes grow fur.
// A Bevy system takes each resource and query it touches as an argument.
#[allow(clippy::too_many_arguments)]
fn play_walk(
    ready: On<WorldInstanceReady>,
    mut commands: Commands,
    foxes: Query<(&Walk, Has<Simulated>)>,
    children: Query<&Children>,
    mut players: Query<&mut AnimationPlayer>,
    skinned: Query<(), With<SkinnedMesh>>,
    args: Res<Args>,
    assets: Res<AssetServer>,
) {
    let Ok((walk, simulated)) = foxes.get(ready.entity) else { return };
    for entity in children.iter_descendants(ready.entity) {
        if let Ok(mut player) = players.get_mut(entity) {
            player.play(walk.node).repeat();
            commands.entity(entity).insert(AnimationGraphHandle(walk.graph.clone()));
        }
        if simulated && skinned.contains(entity) {
            commands.entity(entity).insert(Fur::new(assets.load(args.preset.clone())).without_skin());
        }
    }
}
