//! The headless Bevy app the GPU tests run in (lavapipe in CI; no adapter is a failure).

use std::path::{Path, PathBuf};
use std::time::Duration;

use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::render_resource::PollType;
use bevy::render::renderer::RenderDevice;
use bevy::time::TimeUpdateStrategy;
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;
use bevy_pelt::PeltPlugin;

/// The tests' own assets folder.
pub fn test_assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/assets")
}

/// A windowless app with Pelt on `assets`; `watch` turns on Bevy's file watcher, and `frame`
/// makes every frame that long, however fast the machine draws.
pub fn headless_app(assets: &Path, watch: bool, frame: Option<Duration>) -> App {
    headless_app_with(assets, watch, frame, |_| {})
}

/// `headless_app` with `configure` run before the plugins finish: the last moment the render
/// world is reachable as a sub-app (pipelined rendering moves it to its own thread at cleanup).
pub fn headless_app_with(assets: &Path, watch: bool, frame: Option<Duration>, configure: impl FnOnce(&mut App)) -> App {
    let mut app = App::new();
    app.add_plugins((
        DefaultPlugins
            .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, ..default() })
            .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() })
            .set(AssetPlugin {
                file_path: assets.to_string_lossy().into_owned(),
                watch_for_changes_override: Some(watch),
                ..default()
            })
            .disable::<WinitPlugin>(),
        PeltPlugin,
    ));
    if let Some(frame) = frame {
        app.insert_resource(TimeUpdateStrategy::ManualDuration(frame));
    }
    configure(&mut app);
    app.finish();
    app.cleanup();
    app
}

/// A pixel's luma (Rec. 709 weights on the stored sRGB values).
pub fn luma(p: &image::Rgba<u8>) -> f32 {
    0.2126 * f32::from(p[0]) + 0.7152 * f32::from(p[1]) + 0.0722 * f32::from(p[2])
}

/// One frame, waited for on the GPU.
pub fn update(app: &mut App) {
    app.update();
    app.world()
        .resource::<RenderDevice>()
        .wgpu_device()
        .poll(PollType::Wait { submission_index: None, timeout: None })
        .expect("the device answers");
}
