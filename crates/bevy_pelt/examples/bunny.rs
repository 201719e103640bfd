//! The bunny with fur on a ground plane, in Bevy.
//!
//! `cargo run --release -p bevy_pelt --example bunny [--ignore-rust-version] -- [PRESET] [--screenshot PNG]`
//! (PRESET is relative to the repository's `assets/`, default `presets/mink.toml`; edit it while
//! the example runs and the fur reloads).
//!
//! Right-drag orbits, the wheel zooms, left-drag pats the fur. W turns the wind on or off, Up and
//! Down change its strength, Left and Right turn it. `--screenshot PNG` saves a frame and exits.

mod common;

use bevy::prelude::*;
use bevy_pelt::pelt_core::Builtin;
use bevy_pelt::{Fur, FurTouch, FurWind, PeltPlugin};
use common::{Args, ExamplePlugin, Orbit};

fn main() {
    App::new()
        .add_plugins((
            common::default_plugins("Pelt in Bevy: bunny"),
            PeltPlugin,
            ExamplePlugin {
                orbit: Orbit {
                    yaw: 0.5,
                    pitch: 0.25,
                    distance: 3.2,
                    distance_range: (1.2, 12.0),
                    focus: Vec3::new(0.0, 0.8, 0.0),
                },
                sun_lux: 8000.0,
                screenshot_frame: 90,
            },
        ))
        .insert_resource(Args::from_env("presets/mink.toml"))
        .insert_resource(FurWind { direction: Vec3::new(1.0, 0.0, 0.3), strength: 0.0, gust_strength: 0.5 })
        .add_systems(Startup, setup)
        .add_systems(Update, (wind_keys, touch))
        .run();
}

fn setup(mut commands: Commands, mut meshes: ResMut<Assets<Mesh>>, assets: Res<AssetServer>, args: Res<Args>) {
    // The bunny Pelt compiles in, as a Bevy mesh scaled to a radius of 1 and standing on y = 0.
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
    info!("right-drag orbits, wheel zooms, left-drag pats; W wind on/off, Up/Down strength, Left/Right direction");
}

fn wind_keys(keys: Res<ButtonInput<KeyCode>>, mut wind: ResMut<FurWind>, mut last_on: Local<Option<f32>>) {
    let before = wind.clone();
    if keys.just_pressed(KeyCode::KeyW) {
        if wind.strength > 0.0 {
            *last_on = Some(wind.strength);
            wind.strength = 0.0;
        } else {
            wind.strength = last_on.unwrap_or(0.6);
        }
    }
    if keys.just_pressed(KeyCode::ArrowUp) {
        wind.strength = (wind.strength + 0.2).min(4.0);
    }
    if keys.just_pressed(KeyCode::ArrowDown) {
        wind.strength = (wind.strength - 0.2).max(0.0);
    }
    let turn =
        f32::from(u8::from(keys.pressed(KeyCode::ArrowRight))) - f32::from(u8::from(keys.pressed(KeyCode::ArrowLeft)));
    if turn != 0.0 {
        wind.direction = Quat::from_rotation_y(turn * 0.03) * wind.direction;
    }
    if keys.any_just_pressed([KeyCode::KeyW, KeyCode::ArrowUp, KeyCode::ArrowDown]) && *wind != before {
        info!("wind strength {:.1}", wind.strength);
    }
}

fn touch(
    buttons: Res<ButtonInput<MouseButton>>,
    windows: Query<&Window>,
    cameras: Query<(&Camera, &GlobalTransform)>,
    mut touch: ResMut<FurTouch>,
) {
    touch.ray = None;
    if !buttons.pressed(MouseButton::Left) {
        return;
    }
    let (Ok(window), Ok((camera, transform))) = (windows.single(), cameras.single()) else { return };
    touch.ray = window.cursor_position().and_then(|cursor| camera.viewport_to_world(transform, cursor).ok());
}
