//! The animated Fox walking with fur, in Bevy: Bevy loads the glTF scene and plays its animation
//! with its own `AnimationPlayer`; bevy_pelt takes Bevy's joints each frame, skins the fur's base
//! with pelt-core and simulates it (the fur swings as the Fox moves).
//!
//! `cargo run --release -p bevy_pelt --example fox [--ignore-rust-version] -- [PRESET] [--screenshot PNG]
//! [--no-taa] [--no-shadows] [--no-fur]`
//! (PRESET is relative to the repository's `assets/`, default `presets/fox_groomed.toml`: the
//! Fox's own texture carried into its fur, groomed by `fox_groomed.groom`: bald eyes, nose and
//! inner ears, a short face and legs, a long tail and a chest ruff; editing the preset or the
//! groom file while the example runs regrows the fur).
//!
//! The fur casts the Fox's shadow on the ground and writes its depth and motion vectors in
//! Bevy's prepass, so the camera's TAA keeps it sharp as it walks.
//!
//! Right-drag orbits, the wheel zooms. 1, 2 and 3 play Survey, Walk and Run; Space pauses.
//! `--screenshot PNG` saves a frame and exits.

mod common;

use bevy::mesh::skinning::SkinnedMesh;
use bevy::prelude::*;
use bevy::world_serialization::WorldInstanceReady;
use bevy_pelt::{Fur, PeltPlugin};
use common::{Args, ExamplePlugin, Orbit};

const FOX: &str = "meshes/Fox.glb";
/// The Fox is about 100 units long; the scene is scaled to about a metre.
const FOX_SCALE: f32 = 0.01;

fn main() {
    App::new()
        .add_plugins((
            common::default_plugins("Pelt in Bevy: Fox"),
            PeltPlugin,
            ExamplePlugin {
                orbit: Orbit {
                    yaw: 0.9,
                    pitch: 0.2,
                    distance: 2.6,
                    distance_range: (0.8, 10.0),
                    focus: Vec3::new(0.0, 0.5, 0.0),
                },
                sun_lux: 6000.0,
                screenshot_frame: 120,
            },
        ))
        .insert_resource(Args::from_env("presets/fox_groomed.toml"))
        .add_systems(Startup, setup)
        .add_systems(Update, (grow_fur, animation_keys))
        .run();
}

/// The clips (Survey, Walk, Run) as nodes of one animation graph.
#[derive(Resource)]
struct Clips {
    nodes: Vec<AnimationNodeIndex>,
    graph: Handle<AnimationGraph>,
}

fn setup(mut commands: Commands, mut graphs: ResMut<Assets<AnimationGraph>>, assets: Res<AssetServer>) {
    let (graph, nodes) =
        AnimationGraph::from_clips((0..3).map(|k| assets.load(GltfAssetLabel::Animation(k).from_asset(FOX))));
    commands.insert_resource(Clips { nodes, graph: graphs.add(graph) });
    commands
        .spawn((
            WorldAssetRoot(assets.load(GltfAssetLabel::Scene(0).from_asset(FOX))),
            Transform::from_scale(Vec3::splat(FOX_SCALE)),
        ))
        .observe(play_walk);
    info!("right-drag orbits, wheel zooms; 1/2/3 Survey/Walk/Run, Space pauses");
}

/// Once the scene is in, its animation player plays Walk.
fn play_walk(
    ready: On<WorldInstanceReady>,
    mut commands: Commands,
    clips: Res<Clips>,
    children: Query<&Children>,
    mut players: Query<&mut AnimationPlayer>,
) {
    for entity in children.iter_descendants(ready.entity) {
        if let Ok(mut player) = players.get_mut(entity) {
            player.play(clips.nodes[1]).repeat();
            commands.entity(entity).insert(AnimationGraphHandle(clips.graph.clone()));
        }
    }
}

/// Fur on every skinned mesh the scene spawns, over the Fox's own textured surface (the default
/// preset colours the fur from that texture, so the two agree where the surface shows through).
fn grow_fur(
    mut commands: Commands,
    skinned: Query<Entity, Added<SkinnedMesh>>,
    args: Res<Args>,
    assets: Res<AssetServer>,
) {
    for entity in &skinned {
        commands.entity(entity).insert(Fur::new(assets.load(args.preset.clone())).without_skin());
    }
}

fn animation_keys(keys: Res<ButtonInput<KeyCode>>, clips: Res<Clips>, mut players: Query<&mut AnimationPlayer>) {
    for mut player in &mut players {
        for (key, node) in [KeyCode::Digit1, KeyCode::Digit2, KeyCode::Digit3].into_iter().zip(&clips.nodes) {
            if keys.just_pressed(key) {
                player.stop_all();
                player.play(*node).repeat();
            }
        }
        if keys.just_pressed(KeyCode::Space) {
            if player.all_paused() {
                player.resume_all();
            } else {
                player.pause_all();
            }
        }
    }
}
