//! The bunny with fur on a ground plane, in Bevy.
//!
//! `cargo run --release -p bevy_pelt --example bunny [--ignore-rust-version] -- [PRESET] [--screenshot PNG]`
//! (PRESET is relative to the repository's `assets/`, default `presets/mink.toml`; edit it while
//! the example runs and the fur reloads).
//!
//! Right-drag orbits, the wheel zooms, left-drag pats the fur. W turns the wind on or off, Up and
//! Down change its strength, Left and Right turn it. `--screenshot PNG` saves a frame and exits.

use std::path::Path;

use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy_pelt::pelt_core::Builtin;
use bevy_pelt::{Fur, FurTouch, FurWind, PeltPlugin};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let screenshot = args.iter().position(|a| a == "--screenshot").and_then(|i| args.get(i + 1)).cloned();
    let preset = args.iter().find(|a| a.ends_with(".toml")).cloned().unwrap_or_else(|| "presets/mink.toml".to_owned());
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    App::new()
        .add_plugins((
            DefaultPlugins
                .set(AssetPlugin {
                    file_path: assets.to_string_lossy().into_owned(),
                    watch_for_changes_override: Some(true),
                    ..default()
                })
                .set(WindowPlugin {
                    primary_window: Some(Window { title: "Pelt in Bevy: bunny".into(), ..default() }),
                    ..default()
                }),
            PeltPlugin,
        ))
        .insert_resource(Settings { preset, screenshot })
        .insert_resource(FurWind { direction: Vec3::new(1.0, 0.0, 0.3), strength: 0.0, gust_strength: 0.5 })
        .init_resource::<Orbit>()
        .add_systems(Startup, setup)
        .add_systems(Update, (orbit, wind_keys, touch, screenshot_then_exit))
        .run();
}

#[derive(Resource)]
struct Settings {
    preset: String,
    screenshot: Option<String>,
}

#[derive(Resource)]
struct Orbit {
    yaw: f32,
    pitch: f32,
    distance: f32,
}

impl Default for Orbit {
    fn default() -> Self {
        Self { yaw: 0.5, pitch: 0.25, distance: 3.2 }
    }
}

fn setup(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    assets: Res<AssetServer>,
    settings: Res<Settings>,
) {
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
        Fur::new(assets.load(settings.preset.clone())),
        Transform::from_scale(Vec3::splat(scale)).with_translation(Vec3::new(
            -centre.x * scale,
            -lowest * scale,
            -centre.z * scale,
        )),
    ));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(8.0, 8.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.35, 0.42, 0.3))),
    ));
    commands.spawn((
        DirectionalLight { illuminance: 8000.0, shadow_maps_enabled: true, ..default() },
        Transform::from_xyz(3.0, 6.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    // ACES needs no lookup tables (the crate leaves Bevy's `tonemapping_luts` feature off).
    commands.spawn((Camera3d::default(), Tonemapping::AcesFitted, Transform::default()));
    info!("right-drag orbits, wheel zooms, left-drag pats; W wind on/off, Up/Down strength, Left/Right direction");
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
    orbit.distance = (orbit.distance * (1.0 - scroll.delta.y * 0.1)).clamp(1.2, 12.0);
    let focus = Vec3::new(0.0, 0.8, 0.0);
    let offset = Quat::from_euler(EulerRot::YXZ, orbit.yaw, -orbit.pitch, 0.0) * Vec3::Z * orbit.distance;
    for mut transform in &mut cameras {
        *transform = Transform::from_translation(focus + offset).looking_at(focus, Vec3::Y);
    }
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

fn screenshot_then_exit(
    mut commands: Commands,
    settings: Res<Settings>,
    mut frames: Local<u32>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(path) = &settings.screenshot else { return };
    *frames += 1;
    if *frames == 90 {
        commands.spawn(Screenshot::primary_window()).observe(save_to_disk(path.clone()));
    }
    if *frames == 100 {
        exit.write(AppExit::Success);
    }
}
