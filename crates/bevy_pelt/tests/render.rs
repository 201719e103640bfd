//! A headless Bevy app renders fur on lavapipe (or whatever adapter wgpu finds; no adapter is a
//! failure): the furred cube covers pixels the bare cube does not, fur is hidden behind a wall in
//! front of it and drawn over the backdrop behind it, and the picture matches a golden image.
//! Also: a bad preset is an asset load error naming the file.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use bevy::asset::{LoadState, RenderAssetUsages};
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::render_resource::{PollType, TextureFormat};
use bevy::render::renderer::RenderDevice;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::ExitCondition;
use bevy::winit::WinitPlugin;
use bevy_pelt::{Fur, FurPreset, FurState, PeltPlugin};

const SIZE: u32 = 160;
const BACKDROP: Color = Color::srgb(0.1, 0.2, 0.6);
const CUBE: Color = Color::srgb(0.5, 0.5, 0.5);
const WALL: Color = Color::srgb(0.8, 0.1, 0.1);

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/assets")
}

fn headless_app(assets: &Path) -> App {
    let mut app = App::new();
    app.add_plugins((
        DefaultPlugins
            .set(WindowPlugin { primary_window: None, exit_condition: ExitCondition::DontExit, ..default() })
            .set(RenderPlugin { synchronous_pipeline_compilation: true, ..default() })
            .set(AssetPlugin { file_path: assets.to_string_lossy().into_owned(), ..default() })
            .disable::<WinitPlugin>(),
        PeltPlugin,
    ));
    app.finish();
    app.cleanup();
    app
}

fn update(app: &mut App) {
    app.update();
    app.world()
        .resource::<RenderDevice>()
        .wgpu_device()
        .poll(PollType::Wait { submission_index: None, timeout: None })
        .expect("the device answers");
}

/// Runs a headless app with `targets` image targets (`SIZE` square, sRGB) until every furred
/// entity `setup` spawns is built, then captures each target.
fn capture(targets: usize, setup: impl FnOnce(&mut World, &[Handle<Image>])) -> Vec<image::RgbaImage> {
    let mut app = headless_app(&assets());
    let world = app.world_mut();
    let handles: Vec<Handle<Image>> = (0..targets)
        .map(|_| {
            let mut image = Image::new_target_texture(SIZE, SIZE, TextureFormat::Rgba8UnormSrgb, None);
            image.asset_usage = RenderAssetUsages::RENDER_WORLD;
            world.resource_mut::<Assets<Image>>().add(image)
        })
        .collect();
    setup(world, &handles);
    let furs = world.query::<&Fur>().iter(world).count();
    let built = |app: &mut App| {
        let world = app.world_mut();
        world.query::<&FurState>().iter(world).count()
    };
    for _ in 0..600 {
        update(&mut app);
        if built(&mut app) == furs {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert_eq!(built(&mut app), furs, "every fur was built");
    // A few frames so the simulation has settled and the fur is on the GPU.
    for _ in 0..3 {
        update(&mut app);
    }
    let captured: Arc<Mutex<Vec<Option<Image>>>> = Arc::new(Mutex::new(vec![None; targets]));
    for (i, handle) in handles.iter().enumerate() {
        let sink = Arc::clone(&captured);
        app.world_mut().spawn(Screenshot::image(handle.clone())).observe(move |shot: On<ScreenshotCaptured>| {
            sink.lock().unwrap()[i] = Some(shot.image.clone());
        });
    }
    for _ in 0..10 {
        update(&mut app);
        if captured.lock().unwrap().iter().all(Option::is_some) {
            break;
        }
    }
    let images = std::mem::take(&mut *captured.lock().unwrap());
    images
        .into_iter()
        .map(|image| {
            let rgba = image.expect("the screenshot arrived").try_into_dynamic().expect("an RGBA8 image").to_rgba8();
            assert_eq!(rgba.dimensions(), (SIZE, SIZE));
            rgba
        })
        .collect()
}

fn unlit(world: &mut World, color: Color) -> Handle<StandardMaterial> {
    world.resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial {
        base_color: color,
        unlit: true,
        ..default()
    })
}

fn cuboid(world: &mut World, size: Vec3) -> Handle<Mesh> {
    world.resource_mut::<Assets<Mesh>>().add(Cuboid::from_size(size))
}

fn preset(world: &mut World, path: &'static str) -> Handle<FurPreset> {
    world.resource::<AssetServer>().load(path)
}

/// The scene: a backdrop far behind, the cube (furred or not) in the middle, and a wall in front
/// of the cube's left third. Unlit materials, no tonemapping, so colours are exact.
fn render(furred: bool) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        let (backdrop, cube, wall) = (unlit(world, BACKDROP), unlit(world, CUBE), unlit(world, WALL));
        let (backdrop_mesh, cube_mesh, wall_mesh) = (
            cuboid(world, Vec3::new(20.0, 20.0, 0.1)),
            cuboid(world, Vec3::ONE),
            cuboid(world, Vec3::new(0.6, 3.0, 0.1)),
        );
        world.spawn((Mesh3d(backdrop_mesh), MeshMaterial3d(backdrop), Transform::from_xyz(0.0, 0.0, -3.0)));
        world.spawn((Mesh3d(wall_mesh), MeshMaterial3d(wall), Transform::from_xyz(-0.7, 0.0, 1.5)));
        let fur = furred.then(|| Fur::new(preset(world, "presets/long.toml")).without_skin());
        let mut cube = world.spawn((
            Mesh3d(cube_mesh),
            MeshMaterial3d(cube),
            Transform::from_rotation(Quat::from_euler(EulerRot::YXZ, 0.6, 0.4, 0.0)),
        ));
        if let Some(fur) = fur {
            cube.insert(fur);
        }
        world.spawn((
            Camera3d::default(),
            RenderTarget::Image(targets[0].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(0.0, 0.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
    });
    images.into_iter().next().unwrap()
}

fn near(pixel: &image::Rgba<u8>, colour: Color) -> bool {
    let srgb = colour.to_srgba().to_u8_array();
    pixel.0.iter().zip(srgb).take(3).all(|(&a, b)| a.abs_diff(b) <= 3)
}

#[test]
fn fur_covers_more_than_the_bare_cube_and_respects_depth() {
    let bare = render(false);
    let furred = render(true);
    save(&bare, "cube-bare");
    save(&furred, "cube-furred");

    let cube_pixels = bare.pixels().filter(|p| near(p, CUBE)).count();
    let wall_pixels = bare.pixels().filter(|p| near(p, WALL)).count();
    assert!(cube_pixels > 1000 && wall_pixels > 1000, "the scene is framed: {cube_pixels} cube, {wall_pixels} wall");

    // Fur over the backdrop: pixels that were backdrop around the cube are fur now.
    let grown = bare.pixels().zip(furred.pixels()).filter(|(b, f)| near(b, BACKDROP) && !near(f, BACKDROP)).count();
    assert!(grown > cube_pixels / 10, "fur covers {grown} backdrop pixels around a cube of {cube_pixels}");
    // The wall in front hides the fur behind it: every wall pixel is still the wall.
    let wall_kept = bare.pixels().zip(furred.pixels()).filter(|(b, f)| near(b, WALL) && near(f, WALL)).count();
    assert_eq!(wall_kept, wall_pixels, "fur was drawn over the wall in front of it");
    // The fur is the preset's colour (warm: red above blue), not Bevy's grey cube.
    let warm = furred.pixels().filter(|p| u16::from(p.0[0]) > u16::from(p.0[2]) + 40 && !near(p, WALL)).count();
    assert!(warm > cube_pixels / 4, "{warm} fur-coloured pixels");

    golden(&furred, "cube-furred");
}

/// Two furs (warm on the left, cool on the right as seen from the front) and two cameras, one
/// in front (4x MSAA, LDR) and one behind (HDR, no MSAA: a second target description). Each
/// camera must see each fur where its own view puts it, so views and furs do not overwrite each
/// other's uniforms.
#[test]
fn several_furs_and_cameras() {
    let images = capture(2, |world, targets| {
        let cube = cuboid(world, Vec3::splat(0.8));
        for (x, path) in [(-1.0, "presets/long.toml"), (1.0, "presets/cool.toml")] {
            let fur = Fur::new(preset(world, path));
            world.spawn((Mesh3d(cube.clone()), fur, Transform::from_xyz(x, 0.0, 0.0)));
        }
        world.spawn((
            Camera3d::default(),
            RenderTarget::Image(targets[0].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(0.0, 0.0, 5.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        world.spawn((
            Camera3d::default(),
            bevy::camera::Hdr,
            Msaa::Off,
            RenderTarget::Image(targets[1].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(0.0, 0.0, -5.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
    });
    save(&images[0], "two-front");
    save(&images[1], "two-back");
    let warm = |p: &image::Rgba<u8>| u16::from(p.0[0]) > u16::from(p.0[2]) + 40;
    let cool = |p: &image::Rgba<u8>| u16::from(p.0[2]) > u16::from(p.0[0]) + 40;
    let count = |image: &image::RgbaImage, left: bool, wanted: &dyn Fn(&image::Rgba<u8>) -> bool| {
        image.enumerate_pixels().filter(|(x, _, p)| (*x < SIZE / 2) == left && wanted(p)).count()
    };
    for (name, image, warm_on_left) in [("front", &images[0], true), ("back", &images[1], false)] {
        let (warm_here, warm_there) = (count(image, warm_on_left, &warm), count(image, !warm_on_left, &warm));
        let (cool_here, cool_there) = (count(image, !warm_on_left, &cool), count(image, warm_on_left, &cool));
        assert!(
            warm_here > 500 && warm_there < 20,
            "{name}: warm fur {warm_here} on its side, {warm_there} on the other"
        );
        assert!(
            cool_here > 500 && cool_there < 20,
            "{name}: cool fur {cool_here} on its side, {cool_there} on the other"
        );
    }
}

#[test]
fn a_bad_preset_is_an_asset_error_naming_the_file() {
    let mut app = headless_app(&assets());
    let handle: Handle<FurPreset> = app.world().resource::<AssetServer>().load("presets/bad.toml");
    let mut state = LoadState::Loading;
    for _ in 0..500 {
        app.update();
        state = app.world().resource::<AssetServer>().load_state(&handle);
        if matches!(state, LoadState::Failed(_) | LoadState::Loaded) {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let LoadState::Failed(error) = state else { panic!("expected a load error, got {state:?}") };
    let message = error.to_string();
    assert!(message.contains("bad.toml") && message.contains("length"), "{message}");
}

fn out_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bevy_pelt");
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn save(image: &image::RgbaImage, name: &str) {
    image.save(out_dir().join(format!("{name}.png"))).unwrap();
}

/// Compares with `tests/golden/NAME.png` (`PELT_UPDATE_GOLDEN=1` rewrites it): at most 1% of
/// pixels may differ by more than 24 in a channel (rasterisers differ a little at edges).
fn golden(actual: &image::RgbaImage, name: &str) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden").join(format!("{name}.png"));
    if std::env::var_os("PELT_UPDATE_GOLDEN").is_some() {
        actual.save(&path).unwrap();
        return;
    }
    let expected = image::open(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display())).to_rgba8();
    assert_eq!(expected.dimensions(), actual.dimensions());
    let differing = expected
        .pixels()
        .zip(actual.pixels())
        .filter(|(e, a)| e.0.iter().zip(a.0).take(3).any(|(&x, y)| x.abs_diff(y) > 24))
        .count();
    let allowed = (SIZE * SIZE / 100) as usize;
    if differing > allowed {
        save(actual, &format!("{name}-actual"));
        panic!("{differing} pixels differ from {} (allowed {allowed})", path.display());
    }
}
