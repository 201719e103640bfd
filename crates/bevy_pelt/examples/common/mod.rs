//! What the `bunny` and `fox` examples share: their command line, Bevy's plugins pointed at the
//! repository's `assets/`, the scenery (ground, sun with shadows, camera with TAA), the orbit
//! camera, a frame-time log and `--screenshot`.

use std::path::Path;

use bevy::anti_alias::taa::TemporalAntiAliasing;
use bevy::app::PluginGroupBuilder;
use bevy::core_pipeline::prepass::{DepthPrepass, MotionVectorPrepass};
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::input::mouse::{AccumulatedMouseMotion, AccumulatedMouseScroll};
use bevy::prelude::*;
use bevy::render::view::screenshot::{Screenshot, save_to_disk};
use bevy::transform::TransformSystems;
use bevy_pelt::Fur;

/// The command line: `[PRESET] [--screenshot PNG] [--no-taa] [--no-shadows] [--no-fur]`.
#[derive(Resource)]
pub struct Args {
    /// The fur preset, relative to the repository's `assets/`.
    pub preset: String,
    /// Save a frame to this PNG and exit.
    pub screenshot: Option<String>,
    /// TAA on the camera (with the depth and motion-vector prepasses it needs).
    pub taa: bool,
    /// The sun casts shadows.
    pub shadows: bool,
    /// Grow the fur (off: the same scene bare, for comparing frame times).
    pub fur: bool,
}

impl Args {
    /// `default_preset` (relative to `assets/`) where the command line names none.
    pub fn from_env(default_preset: &str) -> Self {
        let args: Vec<String> = std::env::args().skip(1).collect();
        let screenshot = args.iter().position(|a| a == "--screenshot").and_then(|i| args.get(i + 1)).cloned();
        let preset = args.iter().find(|a| a.ends_with(".toml")).cloned().unwrap_or_else(|| default_preset.to_owned());
        let off = |flag: &str| args.iter().any(|a| a == flag);
        Self { preset, screenshot, taa: !off("--no-taa"), shadows: !off("--no-shadows"), fur: !off("--no-fur") }
    }
}

/// Bevy's default plugins with a titled window, reading (and watching, so an edited preset
/// reloads) the repository's `assets/`.
pub fn default_plugins(title: &str) -> PluginGroupBuilder {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    DefaultPlugins
        .set(AssetPlugin {
            file_path: assets.to_string_lossy().into_owned(),
            watch_for_changes_override: Some(true),
            ..default()
        })
        .set(WindowPlugin { primary_window: Some(Window { title: title.into(), ..default() }), ..default() })
}

/// The camera's orbit around `focus`: right-drag turns it, the wheel zooms.
#[derive(Resource, Clone, Debug)]
pub struct Orbit {
    pub yaw: f32,
    pub pitch: f32,
    pub distance: f32,
    /// The nearest and farthest the wheel zooms.
    pub distance_range: (f32, f32),
    pub focus: Vec3,
}

/// The scenery and camera controls both examples use.
pub struct ExamplePlugin {
    /// Where the camera starts.
    pub orbit: Orbit,
    /// The sun's illuminance, lux.
    pub sun_lux: f32,
    /// With `--screenshot`, the frame saved (the app exits ten frames later): late enough for
    /// the fur to have settled.
    pub screenshot_frame: u32,
}

#[derive(Resource)]
struct SceneSettings {
    sun_lux: f32,
    screenshot_frame: u32,
}

impl Plugin for ExamplePlugin {
    fn build(&self, app: &mut App) {
        app.insert_resource(self.orbit.clone())
            .insert_resource(SceneSettings { sun_lux: self.sun_lux, screenshot_frame: self.screenshot_frame })
            .add_systems(Startup, scenery)
            .add_systems(Update, (orbit, log_frame_time, screenshot_then_exit))
            .add_systems(PostUpdate, drop_fur.before(TransformSystems::Propagate));
    }
}

fn scenery(
    mut commands: Commands,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    settings: Res<SceneSettings>,
    args: Option<Res<Args>>,
) {
    let (taa, shadows) = args.map_or((true, true), |args| (args.taa, args.shadows));
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(8.0, 8.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.35, 0.42, 0.3))),
    ));
    commands.spawn((
        DirectionalLight { illuminance: settings.sun_lux, shadow_maps_enabled: shadows, ..default() },
        Transform::from_xyz(3.0, 6.0, 2.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    // ACES needs no lookup tables (the crate leaves Bevy's `tonemapping_luts` feature off).
    let mut camera = commands.spawn((Camera3d::default(), Tonemapping::AcesFitted, Transform::default()));
    if taa {
        // TAA reads the fur's depth and motion vectors from Bevy's prepasses.
        camera.insert((Msaa::Off, DepthPrepass, MotionVectorPrepass, TemporalAntiAliasing::default()));
    }
}

/// `--no-fur`: the scene without the fur its example grows, for comparing frame times.
fn drop_fur(mut commands: Commands, args: Option<Res<Args>>, added: Query<Entity, Added<Fur>>) {
    if args.is_some_and(|args| !args.fur) {
        for entity in &added {
            commands.entity(entity).remove::<Fur>();
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
    let (nearest, farthest) = orbit.distance_range;
    orbit.distance = (orbit.distance * (1.0 - scroll.delta.y * 0.1)).clamp(nearest, farthest);
    let offset = Quat::from_euler(EulerRot::YXZ, orbit.yaw, -orbit.pitch, 0.0) * Vec3::Z * orbit.distance;
    for mut transform in &mut cameras {
        *transform = Transform::from_translation(orbit.focus + offset).looking_at(orbit.focus, Vec3::Y);
    }
}

/// Logs the mean frame time every two seconds (wall clock), so a run shows what it costs.
fn log_frame_time(time: Res<Time<Real>>, mut window: Local<(f32, u32)>) {
    let (seconds, frames) = &mut *window;
    *seconds += time.delta_secs();
    *frames += 1;
    if *seconds >= 2.0 {
        info!("frame_ms {:.1} (mean of {} frames)", 1000.0 * *seconds / *frames as f32, *frames);
        *window = (0.0, 0);
    }
}

fn screenshot_then_exit(
    mut commands: Commands,
    args: Res<Args>,
    settings: Res<SceneSettings>,
    mut frames: Local<u32>,
    mut exit: MessageWriter<AppExit>,
) {
    let Some(path) = &args.screenshot else { return };
    *frames += 1;
    if *frames == settings.screenshot_frame {
        commands.spawn(Screenshot::primary_window()).observe(save_to_disk(path.clone()));
    }
    if *frames == settings.screenshot_frame + 10 {
        exit.write(AppExit::Success);
    }
}
