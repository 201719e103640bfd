//! The bunny's fur with things that touch it, in Bevy: a ball (`FurCollider`) rolls back and
//! forth through the fur, a sponge (`FurSponge`) presses on its back, and a hand (`FurGrasp`)
//! grabs a tuft when you hold G and pulls it along with the cursor... or, without a person, on a
//! loop.
//!
//! `cargo run --release -p bevy_pelt --example play [--ignore-rust-version] -- [PRESET] [--screenshot PNG]`
//! (PRESET is relative to the repository's `assets/`, default `presets/wet.toml`, which dries in
//! a few seconds).
//!
//! Right-drag orbits, the wheel zooms. S presses the sponge or lifts it, G closes the hand while
//! held. `--screenshot PNG` saves a frame and exits.

mod common;

use bevy::prelude::*;
use bevy_pelt::pelt_core::Builtin;
use bevy_pelt::{Fur, FurCollider, FurGrasp, FurSponge, PeltPlugin};
use common::{Args, ExamplePlugin, Orbit};

fn main() {
    App::new()
        .add_plugins((
            common::default_plugins("Pelt in Bevy: ball, sponge and hand"),
            PeltPlugin,
            ExamplePlugin {
                orbit: Orbit {
                    yaw: 0.3,
                    pitch: 0.35,
                    distance: 3.4,
                    distance_range: (1.2, 12.0),
                    focus: Vec3::new(0.0, 0.7, 0.0),
                },
                sun_lux: 8000.0,
                screenshot_frame: 100,
            },
        ))
        .insert_resource(Args::from_env("presets/wet.toml"))
        .add_systems(Startup, setup)
        .add_systems(Update, (roll_ball, sponge_key, move_hand))
        .run();
}

#[derive(Component)]
struct Ball;

#[derive(Component)]
struct Hand;

/// The ball's radius.
const BALL_RADIUS: f32 = 0.22;

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    assets: Res<AssetServer>,
    args: Res<Args>,
) {
    // The bunny Pelt compiles in, scaled to a radius of 1 and standing on y = 0.
    let (bunny, _) = Builtin::Bunny.mesh();
    let (centre, radius) = bunny.bounding_sphere();
    let lowest = bunny.positions.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
    let mut mesh = Mesh::new(bevy::mesh::PrimitiveTopology::TriangleList, default());
    mesh.insert_attribute(Mesh::ATTRIBUTE_POSITION, bunny.positions.iter().map(|p| p.to_array()).collect::<Vec<_>>());
    mesh.insert_attribute(Mesh::ATTRIBUTE_NORMAL, bunny.normals.iter().map(|n| n.to_array()).collect::<Vec<_>>());
    mesh.insert_indices(bevy::mesh::Indices::U32(bunny.triangles.iter().flatten().copied().collect()));
    let scale = 1.0 / radius;
    commands.spawn((
        Name::new("bunny"),
        Mesh3d(meshes.add(mesh)),
        Fur::new(assets.load(args.preset.clone())),
        Transform::from_scale(Vec3::splat(scale)).with_translation(Vec3::new(
            -centre.x * scale,
            -lowest * scale,
            -centre.z * scale,
        )),
    ));
    // The ball, drawn by Bevy, pushes the fur as one shape with it.
    commands.spawn((
        Ball,
        Mesh3d(meshes.add(Sphere::new(BALL_RADIUS))),
        MeshMaterial3d(materials.add(Color::srgb(0.8, 0.15, 0.1))),
        FurCollider::sphere(BALL_RADIUS),
        Transform::default(),
    ));
    // The sponge on the bunny's back, a flat yellow block where it presses.
    commands.spawn((
        Mesh3d(meshes.add(Cuboid::new(0.3, 0.08, 0.3))),
        MeshMaterial3d(materials.add(Color::srgb(0.95, 0.85, 0.2))),
        FurSponge::new(0.35),
        Transform::from_xyz(-0.25, 1.05, 0.0),
    ));
    commands.spawn((
        Hand,
        Mesh3d(meshes.add(Sphere::new(0.05))),
        MeshMaterial3d(materials.add(Color::srgb(0.2, 0.4, 0.9))),
        FurGrasp { hand_radius: 0.05, ..FurGrasp::new(0.25) },
        Transform::from_xyz(0.0, 1.2, 0.3),
    ));
    info!("right-drag orbits, wheel zooms; S presses or lifts the sponge, hold G to grab a tuft");
}

/// The ball rolls to and fro across the bunny's flank, half buried in the fur.
fn roll_ball(time: Res<Time>, mut balls: Query<&mut Transform, With<Ball>>) {
    let t = time.elapsed_secs();
    for mut transform in &mut balls {
        transform.translation = Vec3::new(0.55 * (t * 0.9).sin(), 0.45, 0.45);
    }
}

fn sponge_key(keys: Res<ButtonInput<KeyCode>>, mut sponges: Query<(&mut FurSponge, &mut Transform)>) {
    if keys.just_pressed(KeyCode::KeyS) {
        for (mut sponge, mut transform) in &mut sponges {
            sponge.pressing = !sponge.pressing;
            // Lifted, it hovers above the fur.
            transform.translation.y = if sponge.pressing { 1.05 } else { 1.35 };
        }
    }
}

/// Holding G closes the hand over the bunny's back and it sways, pulling a tuft; without G it
/// hovers where the tuft is (open).
fn move_hand(
    time: Res<Time>,
    keys: Res<ButtonInput<KeyCode>>,
    mut hands: Query<(&mut FurGrasp, &mut Transform), With<Hand>>,
) {
    let t = time.elapsed_secs();
    for (mut grasp, mut transform) in &mut hands {
        grasp.closed = keys.pressed(KeyCode::KeyG) || (t % 6.0) > 1.0;
        let sway = if grasp.closed { 0.15 * (t * 1.5).sin() } else { 0.0 };
        transform.translation = Vec3::new(0.35 + sway, 1.05, 0.25);
    }
}
