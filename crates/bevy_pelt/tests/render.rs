//! A headless Bevy app renders fur on lavapipe (or whatever adapter wgpu finds; no adapter is a
//! failure): the furred cube covers pixels the bare cube does not, fur is hidden behind a wall in
//! front of it and drawn over the backdrop behind it, and the picture matches a golden image.
//! Fur is lit by the scene's directional light. The animated Fox's fur follows Bevy's skeleton.
//! Also: a bad preset is an asset load error naming the file.

use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use bevy::asset::{LoadState, RenderAssetUsages};
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::mesh::VertexAttributeValues;
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy_pelt::{Fur, FurPreset, FurState};

pub(crate) const SIZE: u32 = 160;
const BACKDROP: Color = Color::srgb(0.1, 0.2, 0.6);
const CUBE: Color = Color::srgb(0.5, 0.5, 0.5);
const WALL: Color = Color::srgb(0.8, 0.1, 0.1);

use crate::common;
use common::{test_assets as assets, update};

fn headless_app(assets: &Path) -> App {
    common::headless_app(assets, false, None)
}

/// Runs a headless app with `targets` image targets (`SIZE` square, sRGB) until every furred
/// entity `setup` spawns is built, then captures each target.
pub(crate) fn capture(targets: usize, setup: impl FnOnce(&mut World, &[Handle<Image>])) -> Vec<image::RgbaImage> {
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

pub(crate) fn unlit(world: &mut World, color: Color) -> Handle<StandardMaterial> {
    world.resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial {
        base_color: color,
        unlit: true,
        ..default()
    })
}

pub(crate) fn cuboid(world: &mut World, size: Vec3) -> Handle<Mesh> {
    world.resource_mut::<Assets<Mesh>>().add(Cuboid::from_size(size))
}

pub(crate) fn preset(world: &mut World, path: &'static str) -> Handle<FurPreset> {
    world.resource::<AssetServer>().load(path)
}

/// The scene: a backdrop far behind, the cube (furred or not) in the middle, and a wall in front
/// of the cube's left third. Unlit materials, no tonemapping, so colours are exact.
/// Bevy's global ambient at the radiance Pelt's own ambient has (0.25) under the default exposure:
/// the scenes drawn before the fur took Bevy's ambient keep their look.
pub(crate) fn pelt_ambient(world: &mut World) {
    let brightness = 0.25 / bevy::camera::Exposure::default().exposure();
    world.insert_resource(bevy::light::GlobalAmbientLight { brightness, ..default() });
}

fn render(furred: bool) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        pelt_ambient(world);
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

/// The mean colour of the fur's pixels (those not the backdrop) in `image`.
fn mean_fur_colour(image: &image::RgbaImage) -> [f32; 3] {
    let fur: Vec<_> = image.pixels().filter(|p| !near(p, BACKDROP)).collect();
    assert!(fur.len() > 500, "{} fur pixels", fur.len());
    let mut sum = [0.0; 3];
    for p in &fur {
        for (s, c) in sum.iter_mut().zip(p.0) {
            *s += f32::from(c);
        }
    }
    sum.map(|s| s / fur.len() as f32)
}

/// The furred cube alone before the backdrop, lit by `light` (a directional light: colour,
/// illuminance, where it shines from) or by Pelt's default light.
fn render_lit(light: Option<(Color, f32, Vec3)>) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        let backdrop = unlit(world, BACKDROP);
        let backdrop_mesh = cuboid(world, Vec3::new(20.0, 20.0, 0.1));
        world.spawn((Mesh3d(backdrop_mesh), MeshMaterial3d(backdrop), Transform::from_xyz(0.0, 0.0, -3.0)));
        let cube = cuboid(world, Vec3::ONE);
        let fur = Fur::new(preset(world, "presets/cool.toml"));
        world.spawn((Mesh3d(cube), fur, Transform::from_rotation(Quat::from_euler(EulerRot::YXZ, 0.6, 0.4, 0.0))));
        if let Some((color, illuminance, from)) = light {
            world.spawn((
                DirectionalLight { color, illuminance, ..default() },
                Transform::from_translation(from).looking_at(Vec3::ZERO, Vec3::Y),
            ));
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

/// The scene's directional light lights the fur: its colour tints it, its illuminance (through
/// the camera's exposure) brightens it, and its direction decides which side is lit.
#[test]
fn the_scenes_directional_light_lights_the_fur() {
    // Bevy's default exposure: `lux * exposure / pi` = 1 at about 3,140 lux.
    let unit_lux = std::f32::consts::PI / bevy::camera::Exposure::default().exposure();
    let default_light = mean_fur_colour(&render_lit(None));
    let red = mean_fur_colour(&render_lit(Some((Color::srgb(1.0, 0.0, 0.0), unit_lux, Vec3::new(0.0, 0.0, 4.0)))));
    let white_dim = mean_fur_colour(&render_lit(Some((Color::WHITE, unit_lux * 0.2, Vec3::new(0.0, 0.0, 4.0)))));
    let white_behind = mean_fur_colour(&render_lit(Some((Color::WHITE, unit_lux, Vec3::new(0.0, 0.0, -4.0)))));
    let white_front = mean_fur_colour(&render_lit(Some((Color::WHITE, unit_lux, Vec3::new(0.0, 0.0, 4.0)))));
    // The cool preset is blue; red light leaves its blue to the ambient term.
    assert!(red[2] < white_front[2] * 0.7 && red[2] < default_light[2], "red light {red:?}, white {white_front:?}");
    let brightness = |c: [f32; 3]| c.iter().sum::<f32>();
    assert!(brightness(white_dim) < brightness(white_front) * 0.8, "dim {white_dim:?}, bright {white_front:?}");
    assert!(brightness(white_behind) < brightness(white_front) * 0.8, "behind {white_behind:?}, front {white_front:?}");
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

pub(crate) fn save(image: &image::RgbaImage, name: &str) {
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

/// Bevy's skinning of a mesh at the joints' current transforms, written here from Bevy's own
/// data (the oracle shares no code with pelt-core's skin): `sum_k w_k * world(joint_k) *
/// inverse_bind_k * p` per Bevy vertex, weights renormalised.
fn bevy_skinned_positions(world: &mut World, entity: Entity) -> Vec<Vec3> {
    let skinned = world.get::<SkinnedMesh>(entity).expect("a skinned mesh").clone();
    let mesh_handle = world.get::<Mesh3d>(entity).expect("a mesh").0.clone();
    let joints: Vec<Mat4> = skinned
        .joints
        .iter()
        .zip(world.resource::<Assets<SkinnedMeshInverseBindposes>>().get(&skinned.inverse_bindposes).unwrap().iter())
        .map(|(joint, inverse_bind)| world.get::<GlobalTransform>(*joint).unwrap().to_matrix() * *inverse_bind)
        .collect();
    let meshes = world.resource::<Assets<Mesh>>();
    let mesh = meshes.get(&mesh_handle).unwrap();
    let Some(VertexAttributeValues::Float32x3(positions)) = mesh.attribute(Mesh::ATTRIBUTE_POSITION) else {
        panic!("float positions")
    };
    let Some(VertexAttributeValues::Uint16x4(indices)) = mesh.attribute(Mesh::ATTRIBUTE_JOINT_INDEX) else {
        panic!("u16 joint indices")
    };
    let Some(VertexAttributeValues::Float32x4(weights)) = mesh.attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT) else {
        panic!("float joint weights")
    };
    positions
        .iter()
        .zip(indices)
        .zip(weights)
        .map(|((p, j), w)| {
            let sum: f32 = w.iter().sum();
            (0..4).map(|k| joints[j[k] as usize].transform_point3(Vec3::from_array(*p)) * (w[k] / sum)).sum()
        })
        .collect()
}

/// The largest distance from a point of `a` to its nearest point of `b`.
fn farthest_nearest(a: &[Vec3], b: &[Vec3]) -> f32 {
    a.iter().map(|p| b.iter().map(|q| p.distance(*q)).fold(f32::INFINITY, f32::min)).fold(0.0, f32::max)
}

/// The Fox's fur follows Bevy's animation: its Walk is paused at two times, and at each the fur's
/// roots (layer 0, in world space) are where Bevy's own skinning puts the mesh, and the picture
/// changes between the two.
#[test]
fn the_foxs_fur_follows_bevys_animation() {
    const FOX: &str = "meshes/Fox.glb";
    let repository_assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    let mut app = headless_app(&repository_assets);
    // Each frame a sixtieth of a second, however fast the machine draws: the simulation steps
    // at its own rate, so on wall-clock time a fast frame would not step it, and the roots
    // would still be where the last step left them.
    app.insert_resource(bevy::time::TimeUpdateStrategy::ManualDuration(std::time::Duration::from_secs_f64(1.0 / 60.0)));
    let world = app.world_mut();
    let mut target = Image::new_target_texture(SIZE, SIZE, TextureFormat::Rgba8UnormSrgb, None);
    target.asset_usage = RenderAssetUsages::RENDER_WORLD;
    let target = world.resource_mut::<Assets<Image>>().add(target);
    let assets = world.resource::<AssetServer>().clone();
    let walk = assets.load(GltfAssetLabel::Animation(1).from_asset(FOX));
    let (graph, nodes) = AnimationGraph::from_clips([walk]);
    let graph = world.resource_mut::<Assets<AnimationGraph>>().add(graph);
    world.spawn((
        WorldAssetRoot(assets.load(GltfAssetLabel::Scene(0).from_asset(FOX))),
        Transform::from_scale(Vec3::splat(0.01)),
    ));
    world.spawn((
        Camera3d::default(),
        RenderTarget::Image(target.clone().into()),
        Tonemapping::None,
        Transform::from_xyz(1.6, 0.5, 0.0).looking_at(Vec3::new(0.0, 0.4, 0.0), Vec3::Y),
    ));
    let preset: Handle<FurPreset> = assets.load("presets/mink.toml");

    // Wait for the scene; then fur on its skinned mesh (Pelt's skin instead of the Fox's own
    // material, so the picture is the fur's) and the Walk, paused.
    let mut fox = None;
    for _ in 0..1000 {
        update(&mut app);
        let world = app.world_mut();
        let skinned: Vec<Entity> = world.query_filtered::<Entity, With<SkinnedMesh>>().iter(world).collect();
        let players: Vec<Entity> = world.query_filtered::<Entity, With<AnimationPlayer>>().iter(world).collect();
        if let (Some(&mesh), Some(&player)) = (skinned.first(), players.first()) {
            world.entity_mut(mesh).insert(Fur::new(preset.clone())).remove::<MeshMaterial3d<StandardMaterial>>();
            let mut entity = world.entity_mut(player);
            entity.insert(AnimationGraphHandle(graph.clone()));
            entity.get_mut::<AnimationPlayer>().unwrap().play(nodes[0]).pause();
            fox = Some(mesh);
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let fox = fox.expect("the Fox's scene spawned a skinned mesh and an animation player");

    let mut poses = Vec::new();
    for time_secs in [0.1, 0.45] {
        let world = app.world_mut();
        for mut player in world.query::<&mut AnimationPlayer>().iter_mut(world) {
            player.animation_mut(nodes[0]).unwrap().seek_to(time_secs);
        }
        for _ in 0..600 {
            update(&mut app);
            if app.world().get::<FurState>(fox).is_some() {
                break;
            }
            std::thread::sleep(std::time::Duration::from_millis(10));
        }
        // Enough steps for the simulation's interpolated positions to be the new pose's.
        for _ in 0..6 {
            update(&mut app);
        }
        let world = app.world_mut();
        let state = world.get::<FurState>(fox).expect("the Fox's fur was built");
        let v = state.structure().vertex_count();
        let world_from_simulation = state.world_from_simulation();
        let roots: Vec<Vec3> = state.simulation().positions()[..v]
            .iter()
            .map(|p| Vec3::from_array(world_from_simulation.transform_point3(*p).to_array()))
            .collect();
        let expected = bevy_skinned_positions(world, fox);
        let (camera, camera_transform) = world.query::<(&Camera, &GlobalTransform)>().single(world).unwrap();
        // The vertices in the picture (the tail's tip leaves it), two pixels from its edges.
        let inside = |p: &Vec2| p.min_element() >= 2.0 && p.max_element() <= (SIZE - 2) as f32;
        let pixels: Vec<Vec2> = expected
            .iter()
            .filter_map(|p| camera.world_to_viewport(camera_transform, *p).ok())
            .filter(inside)
            .collect();
        assert!(pixels.len() * 10 > expected.len() * 8, "{} of {} vertices in view", pixels.len(), expected.len());
        let image = capture_now(&mut app, &target);
        save(&image, &format!("fox-{time_secs}"));
        // The drawn fur is where Bevy's skinning puts the mesh now: every skinned vertex lies on
        // a pixel the fur's skin or strands cover (or next to one: rasteriser edges).
        let clear = *image.get_pixel(0, 0);
        let covered = |x: i64, y: i64| {
            let (Ok(x), Ok(y)) = (u32::try_from(x), u32::try_from(y)) else { return false };
            x < SIZE && y < SIZE && image.get_pixel(x, y).0.iter().zip(clear.0).take(3).any(|(&a, b)| a.abs_diff(b) > 8)
        };
        let on_fur = pixels
            .iter()
            .filter(|p| {
                let (x, y) = (p.x.floor() as i64, p.y.floor() as i64);
                (-1..=1).any(|dy| (-1..=1).any(|dx| covered(x + dx, y + dy)))
            })
            .count();
        assert!(
            on_fur as f32 >= 0.99 * pixels.len() as f32,
            "at {time_secs} s only {on_fur} of {} skinned vertices fall on drawn fur",
            pixels.len()
        );
        poses.push((roots, expected, image));
    }
    let size = farthest_nearest(&poses[0].1, &[Vec3::ZERO]);
    for (roots, expected, _) in &poses {
        // Every root on Bevy's skinned mesh and every mesh vertex under a root.
        let (off, uncovered) = (farthest_nearest(roots, expected), farthest_nearest(expected, roots));
        assert!(off < 1e-3 * size && uncovered < 1e-3 * size, "roots {off}, mesh {uncovered} from each other");
    }
    let moved = farthest_nearest(&poses[0].1, &poses[1].1);
    assert!(moved > 0.02 * size, "the walk moves the mesh ({moved} of {size})");
    // The fur is drawn (the Fox's own material is gone, so nothing else covers the clear
    // colour in the corner), and the drawn fur moves with the walk.
    for (_, _, image) in &poses {
        let clear = *image.get_pixel(0, 0);
        let covered =
            image.pixels().filter(|p| p.0.iter().zip(clear.0).take(3).any(|(&a, b)| a.abs_diff(b) > 8)).count();
        assert!(covered > 1000, "the Fox's fur covers {covered} pixels");
    }
    let changed = poses[0].2.pixels().zip(poses[1].2.pixels()).filter(|(a, b)| a != b).count();
    assert!(changed > 200, "{changed} pixels changed between the two times");
}

/// Captures `target` now (a few frames).
pub(crate) fn capture_now(app: &mut App, target: &Handle<Image>) -> image::RgbaImage {
    let captured: Arc<Mutex<Option<Image>>> = Arc::new(Mutex::new(None));
    let sink = Arc::clone(&captured);
    app.world_mut().spawn(Screenshot::image(target.clone())).observe(move |shot: On<ScreenshotCaptured>| {
        *sink.lock().unwrap() = Some(shot.image.clone());
    });
    for _ in 0..10 {
        update(app);
        if captured.lock().unwrap().is_some() {
            break;
        }
    }
    let image = captured.lock().unwrap().take().expect("the screenshot arrived");
    image.try_into_dynamic().expect("an RGBA8 image").to_rgba8()
}

/// The fur follows the entity's `Transform` with pelt-core's inertia: a cube accelerating along
/// +X feels an inertial force along -X (it lags), none while it stands still.
#[test]
fn an_accelerating_entity_gives_its_fur_inertia() {
    use bevy::time::TimeUpdateStrategy;
    let mut app = headless_app(&assets());
    app.insert_resource(TimeUpdateStrategy::ManualDuration(std::time::Duration::from_secs_f64(1.0 / 60.0)));
    let world = app.world_mut();
    let mesh = cuboid(world, Vec3::ONE);
    let fur = Fur::new(preset(world, "presets/long.toml"));
    let cube = world.spawn((Mesh3d(mesh), fur, Transform::default())).id();
    for _ in 0..600 {
        update(&mut app);
        if app.world().get::<FurState>(cube).is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let mean_force = |app: &App| {
        let forces = app.world().get::<FurState>(cube).expect("the fur was built").simulation().inertial_forces();
        forces.iter().fold(Vec3::ZERO, |sum, f| sum + Vec3::from_array(f.to_array())) / forces.len() as f32
    };
    for _ in 0..30 {
        update(&mut app);
    }
    assert!(mean_force(&app).length() < 1e-6, "at rest: {}", mean_force(&app));
    // x = 2 t^2: an acceleration of 4 units/s^2 along +X for half a second.
    for frame in 1..=30 {
        let t = frame as f32 / 60.0;
        app.world_mut().get_mut::<Transform>(cube).unwrap().translation.x = 2.0 * t * t;
        update(&mut app);
    }
    let force = mean_force(&app);
    assert!(force.x < -1e-3 && force.y.abs() < force.x.abs() * 0.1, "accelerating along +X: {force}");
}
