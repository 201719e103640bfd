//! The animated Fox walking with fur, in Bevy: Bevy loads the glTF scene and plays its animation
//! with its own `AnimationPlayer`; bevy_pelt takes Bevy's joints each frame, skins the fur's base
//! with pelt-core and simulates it (the fur swings as the Fox moves).
//!
//! `cargo run --release -p bevy_pelt --example fox [--ignore-rust-version] -- [PRESET] [--screenshot PNG]`
//! (PRESET is relative to the repository's `assets/`, default `presets/mink.toml`).
//!
//! Right-drag orbits, the wheel zooms. 1, 2 and 3 play Survey, Walk and Run; Space pauses.
//! `--screenshot PNG` saves a frame and exits.

use std::path::Path;

use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::mesh::skinning::SkinnedMesh;
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy::world_serialization::WorldInstanceReady;
use bevy_pelt::{Fur, PeltPlugin};

const FOX: &str = "meshes/Fox.glb";
/// The Fox is about 100 units long; the scene is scaled to about a metre.
const FOX_SCALE: f32 = 0.01;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let screenshot = args.iter().position(|a| a == "--screenshot").and_then(|i| args.get(i + 1)).cloned();
    let preset = args.iter().find(|a| a.ends_with(".toml")).cloned().unwrap_or_else(|| "presets/mink.toml".to_owned());
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    App::new()
        .add_plugins((
            DefaultPlugins.set(AssetPlugin { file_path: assets.to_string_lossy().into_owned(), ..default() }).set(
                WindowPlugin {
                    primary_window: Some(Window { title: "Pelt in Bevy: Fox".into(), ..default() }),
                    ..default()
                },
            ),
            PeltPlugin,
        ))
        .insert_resource(Settings { preset, screenshot })
        .init_resource::<Orbit>()
        .add_systems(Startup, setup)
        .add_systems(Update, (grow_fur, orbit, animation_keys, screenshot_then_exit))
        .run();
}

#[derive(Resource)]
struct Settings {
    preset: String,
    screenshot: Option<String>,
}

/// The clips (Survey, Walk, Run) as nodes of one animation graph.
#[derive(Resource)]
struct Clips {
    nodes: Vec<AnimationNodeIndex>,
    graph: Handle<AnimationGraph>,
}

#[derive(Resource)]
struct Orbit {
    yaw: f32,
    pitch: f32,
    distance: f32,
}

impl Default for Orbit {
    fn default() -> Self {
        Self { yaw: 0.9, pitch: 0.2, distance: 2.6 }
    }
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut graphs: ResMut<Assets<AnimationGraph>>,
    assets: Res<AssetServer>,
) {
    let (graph, nodes) =
        AnimationGraph::from_clips((0..3).map(|k| assets.load(GltfAssetLabel::Animation(k).from_asset(FOX))));
    commands.insert_resource(Clips { nodes, graph: graphs.add(graph) });
    commands
        .spawn((
            WorldAssetRoot(assets.load(GltfAssetLabel::Scene(0).from_asset(FOX))),
            Transform::from_scale(Vec3::splat(FOX_SCALE)),
        ))
        .observe(play_walk);
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(8.0, 8.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.35, 0.42, 0.3))),
    ));
    commands.spawn((
        DirectionalLight { illuminance: 6000.0, shadow_maps_enabled: true, ..default() },
        Transform::from_xyz(3.0, 6.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    // ACES needs no lookup tables (the crate leaves Bevy's `tonemapping_luts` feature off).
    commands.spawn((Camera3d::default(), Tonemapping::AcesFitted, Transform::default()));
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

/// Fur on every skinned mesh the scene spawns, over the Fox's own textured surface.
fn grow_fur(
    mut commands: Commands,
    skinned: Query<Entity, Added<SkinnedMesh>>,
    settings: Res<Settings>,
    assets: Res<AssetServer>,
) {
    for entity in &skinned {
        commands.entity(entity).insert(Fur::new(assets.load(settings.preset.clone())).without_skin());
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

fn orbit(
    mut orbit: ResMut<Orbit>,
    buttons: Res<ButtonInput<MouseButton>>,
    motion: Res<AccumulatedMouseMotion>,
    scroll: Res<AccumulatedMouseScroll>,
    mut cameras: Query<&mut Transform, With<Camera3d>>,
) {
    if buttons.pressed(MouseButton::Right) {
        orbit.yaw -= motion.delta.x * 0.008;
        orbit.pitch = (orbit.pitch + motion.delta.y * 0.008).clamp(-0.2, 1.4);
    }
    orbit.distance = (orbit.distance * (1.0 - scroll.delta.y * 0.1)).clamp(0.8, 10.0);
    let focus = Vec3::new(0.0, 0.5, 0.0);
    let offset = Quat::from_euler(EulerRot::YXZ, orbit.yaw, -orbit.pitch, 0.0) * Vec3::Z * orbit.distance;
    for mut transform in &mut cameras {
        *transform = Transform::from_translation(focus + offset).looking_at(focus, Vec3::Y);
    }
}

fn screenshot_then_exit(
    mut commands: Commands,
    settings: Res<Settings>,
    mut frames: Local<u32>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(path) = &settings.screenshot else { return };
    *frames += 1;
    if *frames == 120 {
        commands.spawn(Screenshot::primary_window()).observe(save_to_disk(path.clone()));
    }
    if *frames == 130 {
        exit.write(AppExit::Success);
    }
}
