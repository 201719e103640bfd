//! The bunny's fur with things that touch it, in Bevy: a ball (`FurCollider`) rolls back and
//! forth through the fur on its flank, a sponge (`FurSponge`) presses on its rump, and a hand
//! (`FurGrasp`) grabs a tuft on its flank, pulls it up and sways it, then lets go, on a loop.
//!
//! `cargo run --release -p bevy_pelt --example play [--ignore-rust-version] -- [PRESET] [--screenshot PNG]`
//! (PRESET is relative to the repository's `assets/`, default `presets/wet.toml`, which dries in
//! a few seconds).
//!
//! Right-drag orbits, the wheel zooms. S presses the sponge or lifts it. `--screenshot PNG` saves
//! a frame and exits.

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
                screenshot_frame: 40,
            },
        ))
        .insert_resource(Args::from_env("presets/wet.toml"))
        .add_systems(Startup, setup)
        .add_systems(Update, (roll_ball, sponge_key, move_hand))
        .run();
}

#[derive(Component)]
struct Ball;

/// The hand, closing over the flank at `surface`.
#[derive(Component)]
struct Hand {
    surface: Vec3,
}

/// The sponge, pressing on the rump at `surface`.
#[derive(Component)]
struct Sponge {
    surface: Vec3,
}

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
    let world = |p: Vec3| (p - Vec3::new(centre.x, lowest, centre.z)) * scale;
    // The highest point of the bunny within 0.15 of (x, z): where the sponge and hand go.
    let top_near = |x: f32, z: f32| {
        bunny
            .positions
            .iter()
            .map(|p| world(Vec3::from_array(p.to_array())))
            .filter(|p| (p.x - x).abs() < 0.15 && (p.z - z).abs() < 0.15)
            .max_by(|a, b| a.y.total_cmp(&b.y))
            .unwrap_or(Vec3::new(x, 1.0, z))
    };
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
    // The sponge on the bunny's rump, a flat yellow block where it presses.
    let rump_top = top_near(0.45, 0.0);
    commands.spawn((
        Sponge { surface: rump_top },
        Mesh3d(meshes.add(Cuboid::new(0.3, 0.06, 0.3))),
        MeshMaterial3d(materials.add(Color::srgb(0.95, 0.85, 0.2))),
        FurSponge::new(0.4),
        Transform::from_translation(rump_top + Vec3::Y * 0.03),
    ));
    let flank = top_near(0.3, 0.3);
    commands.spawn((
        Hand { surface: flank },
        Mesh3d(meshes.add(Sphere::new(0.04))),
        MeshMaterial3d(materials.add(Color::srgb(0.2, 0.4, 0.9))),
        FurGrasp { hand_radius: 0.04, ..FurGrasp::new(0.2) },
        Transform::from_translation(flank + Vec3::Y * 0.05),
    ));
    info!("right-drag orbits, wheel zooms; S presses or lifts the sponge");
}

/// The ball rolls to and fro across the bunny's flank, half buried in the fur.
fn roll_ball(time: Res<Time>, mut balls: Query<&mut Transform, With<Ball>>) {
    let t = time.elapsed_secs();
    for mut transform in &mut balls {
        transform.translation = Vec3::new(0.55 * (t * 0.9).sin(), 0.45, 0.45);
    }
}

fn sponge_key(keys: Res<ButtonInput<KeyCode>>, mut sponges: Query<(&Sponge, &mut FurSponge, &mut Transform)>) {
    if keys.just_pressed(KeyCode::KeyS) {
        for (place, mut sponge, mut transform) in &mut sponges {
            sponge.pressing = !sponge.pressing;
            // Lifted, it hovers above the fur.
            let lift = if sponge.pressing { 0.03 } else { 0.3 };
            transform.translation = place.surface + Vec3::Y * lift;
        }
    }
}

/// Every six seconds the hand closes in the fur on the flank, pulls the tuft up and sways it for
/// four seconds, then opens and lets it spring back.
fn move_hand(time: Res<Time>, mut hands: Query<(&Hand, &mut FurGrasp, &mut Transform)>) {
    let t = time.elapsed_secs() % 6.0;
    for (hand, mut grasp, mut transform) in &mut hands {
        grasp.closed = (0.5..4.5).contains(&t);
        let pull = if grasp.closed { (t - 0.5).min(1.0) } else { 0.0 };
        let sway = Vec3::new(0.12 * (t * 2.0).sin(), 0.0, 0.0) * pull;
        transform.translation = hand.surface + Vec3::Y * (0.05 + 0.1 * pull) + sway;
    }
}
