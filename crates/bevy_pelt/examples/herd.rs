//! A herd in Bevy: a hundred furry Foxes walking across a field in the wind, each its own glTF
//! scene instance with its own `AnimationPlayer` at its own phase. Every Fox's fur shares one
//! grown structure and one GPU asset (topology, uvs, fin strip, textures), since all use one mesh
//! and one preset; each keeps its own simulation, pose and shadow.
//!
//! `cargo run --release -p bevy_pelt --example herd [--ignore-rust-version] -- [PRESET]
//! [--screenshot PNG] [--no-taa] [--no-shadows] [--no-fur]`
//! (PRESET is relative to the repository's `assets/`, default `presets/fox.toml`).
//!
//! Right-drag orbits, the wheel zooms. `--screenshot PNG` saves a frame and exits.

mod common;

use bevy::mesh::skinning::SkinnedMesh;
use bevy::prelude::*;
use bevy::world_serialization::WorldInstanceReady;
use bevy_pelt::{Fur, FurWind, PeltPlugin};
use common::{Args, ExamplePlugin, Orbit};

const FOX: &str = "meshes/Fox.glb";
/// The Fox is about 100 units long; the scene is scaled to about a metre.
const FOX_SCALE: f32 = 0.01;
/// Foxes on a side of the square field, and metres between them.
const SIDE: usize = 10;
const SPACING: f32 = 2.4;
/// Metres a second: about the Walk clip's stride.
const PACE: f32 = 0.7;

fn main() {
    App::new()
        .add_plugins((
            common::default_plugins("Pelt in Bevy: a herd of Foxes"),
            PeltPlugin,
            ExamplePlugin {
                orbit: Orbit {
                    yaw: 0.5,
                    pitch: 0.45,
                    distance: 26.0,
                    distance_range: (2.0, 60.0),
                    focus: Vec3::new(0.0, 0.3, 0.0),
                },
                sun_lux: 6000.0,
                // A hundred Foxes take seconds a frame on a CPU rasteriser: the herd is built and
                // walking by then.
                screenshot_frame: 40,
            },
        ))
        .insert_resource(Args::from_env("presets/fox.toml"))
        .insert_resource(FurWind { strength: 0.6, ..default() })
        .add_systems(Startup, setup)
        .add_systems(Update, (grow_fur, walk))
        .run();
}

#[derive(Resource)]
struct Walk {
    node: AnimationNodeIndex,
    graph: Handle<AnimationGraph>,
}

/// One Fox: how far into its stride it started, and how it walks.
#[derive(Component)]
struct Walker {
    phase: f32,
    speed: f32,
}

fn setup(
    mut commands: Commands,
    mut graphs: ResMut<Assets<AnimationGraph>>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    assets: Res<AssetServer>,
) {
    let (graph, node) = AnimationGraph::from_clip(assets.load(GltfAssetLabel::Animation(1).from_asset(FOX)));
    commands.insert_resource(Walk { node, graph: graphs.add(graph) });
    // A field wide enough for the walk, just under the examples' common ground.
    let field = SIDE as f32 * SPACING * 2.0;
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(field, field))),
        MeshMaterial3d(materials.add(Color::srgb(0.36, 0.42, 0.28))),
        Transform::from_xyz(0.0, -0.002, 0.0),
    ));
    let scene = assets.load(GltfAssetLabel::Scene(0).from_asset(FOX));
    for k in 0..SIDE * SIDE {
        // A jittered grid, all heading roughly along +X, each at its own phase and pace.
        let hash = |salt: u32| {
            ((k as u32).wrapping_mul(2_654_435_761).wrapping_add(salt.wrapping_mul(40_503)) % 1000) as f32 / 1000.0
        };
        let x = ((k % SIDE) as f32 - 0.5 * (SIDE - 1) as f32 + 0.35 * (hash(1) - 0.5)) * SPACING;
        let z = ((k / SIDE) as f32 - 0.5 * (SIDE - 1) as f32 + 0.35 * (hash(2) - 0.5)) * SPACING;
        let heading = std::f32::consts::FRAC_PI_2 + 0.5 * (hash(3) - 0.5);
        commands
            .spawn((
                WorldAssetRoot(scene.clone()),
                Transform::from_xyz(x, 0.0, z)
                    .with_rotation(Quat::from_rotation_y(heading))
                    .with_scale(Vec3::splat(FOX_SCALE)),
                Walker { phase: hash(4) * 0.7, speed: PACE * (0.85 + 0.3 * hash(5)) },
            ))
            .observe(play_walk);
    }
    info!("a hundred Foxes sharing one fur asset; right-drag orbits, wheel zooms");
}

/// Once a Fox's scene is in, its animation player walks from its own phase.
fn play_walk(
    ready: On<WorldInstanceReady>,
    mut commands: Commands,
    walk: Res<Walk>,
    walkers: Query<&Walker>,
    children: Query<&Children>,
    mut players: Query<&mut AnimationPlayer>,
) {
    let phase = walkers.get(ready.entity).map_or(0.0, |w| w.phase);
    for entity in children.iter_descendants(ready.entity) {
        if let Ok(mut player) = players.get_mut(entity) {
            player.play(walk.node).repeat().seek_to(phase);
            commands.entity(entity).insert(AnimationGraphHandle(walk.graph.clone()));
        }
    }
}

/// Fur on every skinned mesh the scenes spawn: one mesh and one preset, so one shared asset;
/// every third Fox a shade darker, every fifth greyer (`Fur::with_tint`).
fn grow_fur(
    mut commands: Commands,
    skinned: Query<Entity, Added<SkinnedMesh>>,
    args: Res<Args>,
    assets: Res<AssetServer>,
) {
    let preset = assets.load(args.preset.clone());
    for (k, entity) in skinned.iter().enumerate() {
        let tint = match (k % 3, k % 5) {
            (_, 0) => Vec3::new(0.8, 0.8, 0.9),
            (0, _) => Vec3::splat(0.65),
            _ => Vec3::ONE,
        };
        commands.entity(entity).insert(Fur::new(preset.clone()).without_skin().with_tint(tint));
    }
}

/// Each Fox walks ahead (its model's +Z) at its pace.
fn walk(time: Res<Time>, mut walkers: Query<(&Walker, &mut Transform)>) {
    for (walker, mut transform) in &mut walkers {
        let ahead = transform.back().as_vec3();
        transform.translation += ahead * walker.speed * time.delta_secs();
    }
}
