//! The components a host puts on entities reach the fur's simulation in a headless Bevy app:
//! a collider pushes the fur out of it (standing or moving fast), a grasp gathers the strands it
//! holds at the grip and lets them go, a sponge wets what it touches (and the wet fur draws
//! darker), and a groomed preset, hot reloaded, leaves bald vertices bare.

use std::path::Path;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use bevy::asset::RenderAssetUsages;
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy_pelt::{Fur, FurCollider, FurGrasp, FurPreset, FurSponge, FurState};

const SIZE: u32 = 128;

use crate::common;
use common::{test_assets, update};

/// A headless app on `assets` whose frames are each a sixtieth of a second, however fast the
/// machine draws; `watch` turns on Bevy's file watcher.
fn headless_app(assets: &Path, watch: bool) -> App {
    common::headless_app(assets, watch, Some(Duration::from_secs_f64(1.0 / 60.0)))
}

/// A ball of radius 0.5 (1,692 vertices) furred with `preset`.
fn spawn_furred_ball(app: &mut App, preset: &str) -> Entity {
    let world = app.world_mut();
    let mesh = world.resource_mut::<Assets<Mesh>>().add(Sphere::new(0.5).mesh().ico(12).unwrap());
    let preset: Handle<FurPreset> = world.resource::<AssetServer>().load(preset.to_owned());
    world.spawn((Mesh3d(mesh), Fur::new(preset), Transform::default())).id()
}

/// Updates until `entity`'s fur is built (at most ten seconds), then `frames` more.
fn wait_built(app: &mut App, entity: Entity, frames: usize) {
    for _ in 0..1000 {
        update(app);
        if app.world().get::<FurState>(entity).is_some() {
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(app.world().get::<FurState>(entity).is_some(), "the fur was built");
    for _ in 0..frames {
        update(app);
    }
}

/// The fur's nodes in world space, layer-major (`(L + 1) * V`), and `V`.
fn world_nodes(app: &App, entity: Entity) -> (Vec<Vec3>, usize) {
    let state = app.world().get::<FurState>(entity).expect("the fur was built");
    let world_from_simulation = state.world_from_simulation();
    let nodes = state
        .simulation()
        .positions()
        .iter()
        .map(|p| Vec3::from_array(world_from_simulation.transform_point3(*p).to_array()))
        .collect();
    (nodes, state.structure().vertex_count())
}

fn inside(nodes: &[Vec3], centre: Vec3, radius: f32) -> usize {
    nodes.iter().filter(|p| p.distance(centre) < radius).count()
}

/// A ball standing in the fur pushes every node out of it; one moving fast through the fur
/// (more than its radius a frame) leaves no node inside it either, frame after frame.
#[test]
fn a_collider_pushes_the_fur_out_of_it() {
    let mut app = headless_app(&test_assets(), false);
    let ball = spawn_furred_ball(&mut app, "presets/contact.toml");
    wait_built(&mut app, ball, 5);
    let (rest, v) = world_nodes(&app, ball);
    let length = rest[rest.len() - v].distance(rest[0]);
    assert!(length > 0.05, "strands of {length}");
    // Clear of the skin (roots stay put), in the strands over the top.
    let (centre, radius) = (Vec3::new(0.0, 0.5 + 0.6 * length, 0.0), 0.5 * length);
    let before = inside(&rest, centre, radius);
    assert!(before > 10, "only {before} nodes stand where the collider goes");

    let collider = app.world_mut().spawn((FurCollider::sphere(radius), Transform::from_translation(centre))).id();
    for _ in 0..30 {
        update(&mut app);
    }
    let (pushed, _) = world_nodes(&app, ball);
    assert_eq!(inside(&pushed, centre, radius * 0.995), 0, "nodes left inside the standing collider");
    let moved = rest.iter().zip(&pushed).filter(|(a, b)| a.distance(**b) > 1e-3).count();
    assert!(moved >= before, "{moved} nodes moved");
    // Segment lengths are kept.
    for (k, (a, b)) in rest.iter().zip(&pushed).enumerate().skip(v) {
        let (rest_segment, pushed_segment) = (a.distance(rest[k - v]), b.distance(pushed[k - v]));
        assert!((rest_segment - pushed_segment).abs() < 1e-4, "node {k}: {rest_segment} -> {pushed_segment}");
    }

    // Across the top at 1.5 radii a frame: each frame's nodes are outside that frame's ball
    // (a collider that appeared anew each frame would grow in, leaving nodes inside).
    let step = 1.5 * radius;
    let mut x = -0.6;
    while x < 0.6 {
        x += step;
        let here = Vec3::new(x, centre.y, 0.0);
        app.world_mut().get_mut::<Transform>(collider).unwrap().translation = here;
        update(&mut app);
        let (nodes, _) = world_nodes(&app, ball);
        let (left, near) = (inside(&nodes, here, radius * 0.995), inside(&rest, here, radius));
        assert_eq!(left, 0, "at x = {x}: {left} nodes inside the moving collider ({near} at rest there)");
    }
}

/// A closed mesh on an entity (pelt's built-in sphere, scaled by the transform) pushes the fur
/// out of it as a sphere collider does: no node stays inside the mesh's inscribed ball.
#[test]
fn a_mesh_collider_pushes_the_fur_out_of_it() {
    let mut app = headless_app(&test_assets(), false);
    let ball = spawn_furred_ball(&mut app, "presets/contact.toml");
    wait_built(&mut app, ball, 5);
    let (rest, v) = world_nodes(&app, ball);
    let length = rest[rest.len() - v].distance(rest[0]);
    let (centre, radius) = (Vec3::new(0.0, 0.5 + 0.6 * length, 0.0), 0.5 * length);
    let before = inside(&rest, centre, radius);
    assert!(before > 10, "only {before} nodes stand where the collider goes");
    let (sphere, _) = bevy_pelt::pelt_core::Builtin::Sphere.mesh();
    let mesh_radius = sphere.positions.iter().map(|p| p.length()).fold(0.0, f32::max);
    let collider = FurCollider::mesh(sphere, 24).expect("the built-in sphere is closed");
    app.world_mut()
        .spawn((collider, Transform::from_translation(centre).with_scale(Vec3::splat(radius / mesh_radius))));
    for _ in 0..30 {
        update(&mut app);
    }
    let (pushed, _) = world_nodes(&app, ball);
    // The mesh's faces lie a little inside its vertices' sphere, and the field is trilinear:
    // 0.9 of the radius is well inside both.
    assert_eq!(inside(&pushed, centre, radius * 0.9), 0, "nodes left inside the mesh collider");
    let moved = rest.iter().zip(&pushed).filter(|(a, b)| a.distance(**b) > 1e-3).count();
    assert!(moved >= before, "{moved} nodes moved");
}

/// A closed grasp gathers the tips it holds toward the grip and carries them when it moves;
/// opened, they spring back to rest.
#[test]
fn a_grasp_holds_the_strands_at_the_grip() {
    let mut app = headless_app(&test_assets(), false);
    let ball = spawn_furred_ball(&mut app, "presets/contact.toml");
    wait_built(&mut app, ball, 5);
    let (rest, v) = world_nodes(&app, ball);
    let length = rest[rest.len() - v].distance(rest[0]);
    let top = Vec3::new(0.0, 0.5, 0.0);
    let radius = 0.12;
    // The hand closes in the fur over the top; the strands rooted well inside its radius of
    // that point are held fully.
    let close = top + Vec3::new(0.0, 0.3 * length, 0.0);
    let held: Vec<usize> = (0..v).filter(|&j| rest[j].distance(close) < 0.6 * radius).collect();
    assert!(held.len() >= 3, "{} strands under the hand", held.len());
    // How much farther from the grip the held tips are than their strands could reach: a tip
    // reaches within `max(0, |grip - root| - length)` of it.
    let shortfall = |nodes: &[Vec3], grip: Vec3| {
        held.iter()
            .map(|&j| {
                let reach = (grip.distance(rest[j]) - length).max(0.0);
                nodes[nodes.len() - v + j].distance(grip) - reach
            })
            .sum::<f32>()
            / held.len() as f32
    };

    // Then pulled out to one side, beyond the strands' length.
    let grip = top + Vec3::new(0.8 * length, 0.8 * length, 0.0);
    let at_rest = shortfall(&rest, grip);
    assert!(at_rest > 0.3 * length, "the tips at rest are {at_rest} short of the grip");
    let hand = app
        .world_mut()
        .spawn((FurGrasp { closed: true, ..FurGrasp::new(radius) }, Transform::from_translation(close)))
        .id();
    update(&mut app);
    app.world_mut().get_mut::<Transform>(hand).unwrap().translation = grip;
    for _ in 0..30 {
        update(&mut app);
    }
    let (gathered, _) = world_nodes(&app, ball);
    let closed = shortfall(&gathered, grip);
    assert!(closed < 0.15 * length, "held tips {closed} short of the grip ({at_rest} at rest)");

    // The grip moves to the other side: the tips follow.
    let other = top + Vec3::new(-0.8 * length, 0.8 * length, 0.0);
    app.world_mut().get_mut::<Transform>(hand).unwrap().translation = other;
    for _ in 0..10 {
        update(&mut app);
    }
    let (carried, _) = world_nodes(&app, ball);
    let followed = shortfall(&carried, other);
    assert!(followed < 0.15 * length, "tips {followed} short of the moved grip ({} at rest)", shortfall(&rest, other));

    // Opened: the strands spring back and settle at rest.
    app.world_mut().get_mut::<FurGrasp>(hand).unwrap().closed = false;
    for _ in 0..240 {
        update(&mut app);
    }
    let (released, _) = world_nodes(&app, ball);
    let tip = |nodes: &[Vec3], j: usize| nodes[nodes.len() - v + j];
    let back = held.iter().map(|&j| tip(&released, j).distance(tip(&rest, j))).fold(0.0, f32::max);
    assert!(back < 0.05 * length, "released tips {back} from rest");
}

/// A sponge wets the strands it touches (the simulation's wetness), none elsewhere, and they
/// dry at the preset's rate once it lifts.
#[test]
fn a_sponge_wets_the_fur_it_touches() {
    let mut app = headless_app(&test_assets(), false);
    let ball = spawn_furred_ball(&mut app, "presets/contact.toml");
    wait_built(&mut app, ball, 5);
    let state = app.world().get::<FurState>(ball).unwrap();
    assert!(state.wetness().iter().all(|&w| w == 0.0), "dry before the sponge");
    let (rest, v) = world_nodes(&app, ball);
    let top = Vec3::new(0.0, 0.5, 0.0);
    let sponge = app.world_mut().spawn((FurSponge::new(0.3), Transform::from_translation(top))).id();
    for _ in 0..3 {
        update(&mut app);
    }
    let wetness = app.world().get::<FurState>(ball).unwrap().wetness().to_vec();
    for j in 0..v {
        let distance = rest[j].distance(top);
        if distance < 0.1 {
            assert!(wetness[j] > 0.8, "vertex {j} at {distance} from the sponge: {}", wetness[j]);
        } else if distance > 0.3 {
            assert_eq!(wetness[j], 0.0, "vertex {j} at {distance} from the sponge");
        }
    }
    let soaked = wetness.iter().cloned().fold(0.0, f32::max);
    app.world_mut().get_mut::<FurSponge>(sponge).unwrap().pressing = false;
    for _ in 0..60 {
        update(&mut app);
    }
    let dried = app.world().get::<FurState>(ball).unwrap().wetness().iter().cloned().fold(0.0, f32::max);
    // The default `[wet]` dries 0.05 a second.
    assert!(dried < soaked - 0.03 && dried > soaked - 0.08, "{soaked} a second ago, {dried} now");
}

/// Renders the furred ball from above with Pelt's skin, with or without a soaking sponge on it.
fn render_ball(sponge: bool) -> image::RgbaImage {
    let mut app = headless_app(&test_assets(), false);
    let ball = spawn_furred_ball(&mut app, "presets/contact.toml");
    let world = app.world_mut();
    crate::render::pelt_ambient(world);
    let mut target = Image::new_target_texture(SIZE, SIZE, TextureFormat::Rgba8UnormSrgb, None);
    target.asset_usage = RenderAssetUsages::RENDER_WORLD;
    let target = world.resource_mut::<Assets<Image>>().add(target);
    world.spawn((
        Camera3d::default(),
        RenderTarget::Image(target.clone().into()),
        Tonemapping::None,
        Transform::from_xyz(0.0, 2.5, 0.0).looking_at(Vec3::ZERO, Vec3::Z),
    ));
    if sponge {
        world.spawn((FurSponge::new(2.0), Transform::default()));
    }
    wait_built(&mut app, ball, 5);
    let captured: Arc<Mutex<Option<Image>>> = Arc::new(Mutex::new(None));
    let sink = Arc::clone(&captured);
    app.world_mut().spawn(Screenshot::image(target)).observe(move |shot: On<ScreenshotCaptured>| {
        *sink.lock().unwrap() = Some(shot.image.clone());
    });
    for _ in 0..10 {
        update(&mut app);
        if captured.lock().unwrap().is_some() {
            break;
        }
    }
    let image = captured.lock().unwrap().take().expect("the screenshot arrived");
    image.try_into_dynamic().expect("an RGBA8 image").to_rgba8()
}

/// Wetness reaches the renderer: the soaked fur is darker than the dry fur where both cover the
/// picture (the preset's `[wet]` default darkens the albedo by half).
#[test]
fn wet_fur_draws_darker() {
    let dry = render_ball(false);
    let wet = render_ball(true);
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bevy_pelt");
    std::fs::create_dir_all(&dir).unwrap();
    dry.save(dir.join("ball-dry.png")).unwrap();
    wet.save(dir.join("ball-wet.png")).unwrap();
    let clear = *dry.get_pixel(0, 0);
    let luma = |p: &image::Rgba<u8>| p.0.iter().take(3).map(|&c| f32::from(c)).sum::<f32>();
    let covered: Vec<(f32, f32)> = dry
        .pixels()
        .zip(wet.pixels())
        .filter(|(d, w)| **d != clear && **w != clear)
        .map(|(d, w)| (luma(d), luma(w)))
        .collect();
    assert!(covered.len() > 2000, "{} fur pixels", covered.len());
    let darker = covered.iter().filter(|(d, w)| w < &(d * 0.85)).count();
    assert!(darker * 10 > covered.len() * 7, "{darker} of {} fur pixels darker when wet", covered.len());
}

/// The lengths a groom file holds (the file format read here, apart from pelt-core): `None`
/// without a length map.
fn groom_lengths(bytes: &[u8]) -> Option<Vec<f32>> {
    assert_eq!(&bytes[..8], b"PELTGROM");
    let vertices = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
    let present = u32::from_le_bytes(bytes[24..28].try_into().unwrap());
    (present & 1 != 0).then(|| {
        bytes[28..28 + 4 * vertices].chunks_exact(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect()
    })
}

/// Whether each strand is bare (every node at its root), from the fur's nodes.
fn bare_strands(nodes: &[Vec3], v: usize) -> Vec<bool> {
    (0..v).map(|j| nodes.iter().skip(j).step_by(v).all(|p| p.distance(nodes[j]) < 1e-6)).collect()
}

/// The Fox with `fox_groomed`: the vertices its groom file makes bald (eyes, nose, inner ears)
/// grow no fur, and every other vertex does.
#[test]
fn the_groomed_fox_is_bald_where_its_groom_says() {
    let repository_assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    let lengths = groom_lengths(&std::fs::read(repository_assets.join("presets/fox_groomed.groom")).unwrap())
        .expect("the Fox's groom has a length map");
    let bald_in_file = lengths.iter().filter(|&&l| l == 0.0).count();
    assert!(bald_in_file > 10, "{bald_in_file} bald vertices in the file");

    let mut app = headless_app(&repository_assets, false);
    let world = app.world_mut();
    let assets = world.resource::<AssetServer>().clone();
    world.spawn(WorldAssetRoot(assets.load(GltfAssetLabel::Scene(0).from_asset("meshes/Fox.glb"))));
    let preset: Handle<FurPreset> = assets.load("presets/fox_groomed.toml");
    let mut fox = None;
    for _ in 0..1000 {
        update(&mut app);
        let world = app.world_mut();
        let meshes: Vec<Entity> =
            world.query_filtered::<Entity, With<bevy::mesh::skinning::SkinnedMesh>>().iter(world).collect();
        if let Some(&mesh) = meshes.first() {
            world.entity_mut(mesh).insert(Fur::new(preset.clone()));
            fox = Some(mesh);
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    let fox = fox.expect("the Fox's scene spawned its skinned mesh");
    wait_built(&mut app, fox, 2);
    let (nodes, v) = world_nodes(&app, fox);
    assert_eq!(v, lengths.len(), "the groom's vertices are the fur's");
    let bare = bare_strands(&nodes, v);
    for (j, (&length, &bare)) in lengths.iter().zip(&bare).enumerate() {
        assert_eq!(bare, length == 0.0, "vertex {j}: groom length {length}, bare {bare}");
    }
}

/// Writes a grey PNG of one value.
fn write_grey(path: &Path, value: u8) {
    let image = image::GrayImage::from_pixel(4, 4, image::Luma([value]));
    let temporary = path.with_extension("tmp");
    image.save_with_format(&temporary, image::ImageFormat::Png).unwrap();
    std::fs::rename(&temporary, path).unwrap();
}

/// A preset whose `[groom]` length map is a PNG, loaded through Bevy's asset server with its
/// file watcher on: painting the map black while the app runs reloads the preset and regrows
/// the fur bald.
#[test]
fn editing_the_groom_map_regrows_the_fur() {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("bevy_pelt_groom_reload");
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(folder.join("presets")).unwrap();
    let preset = std::fs::read_to_string(test_assets().join("presets/contact.toml")).unwrap();
    std::fs::write(folder.join("presets/groomed.toml"), format!("{preset}\n[groom]\nlength = \"length.png\"\n"))
        .unwrap();
    let map = folder.join("presets/length.png");
    write_grey(&map, 255);

    let mut app = headless_app(&folder, true);
    let ball = spawn_furred_ball(&mut app, "presets/groomed.toml");
    wait_built(&mut app, ball, 2);
    let (nodes, v) = world_nodes(&app, ball);
    assert!(bare_strands(&nodes, v).iter().all(|bare| !bare), "a white length map grows every strand");
    assert!(app.world().get::<FurState>(ball).unwrap().structure().groom.is_some(), "the fur is groomed");

    write_grey(&map, 0);
    let mut all_bare = false;
    for _ in 0..1000 {
        update(&mut app);
        let (nodes, v) = world_nodes(&app, ball);
        all_bare = bare_strands(&nodes, v).iter().all(|&bare| bare);
        if all_bare {
            break;
        }
        std::thread::sleep(Duration::from_millis(10));
    }
    assert!(all_bare, "the fur did not regrow bald after its length map turned black");
}
