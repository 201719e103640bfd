//! A herd in Bevy: a hundred entities of one mesh and preset grow one structure and upload one
//! GPU asset, each drawn where it stands; one far outside the camera's view is not drawn;
//! despawning one leaves the others drawn and the asset shared, and tinting one colours it alone
//! (`FurGpuStats`, copied out of the render world each frame).

use std::sync::{Arc, Mutex};

use bevy::asset::RenderAssetUsages;
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::{Render, RenderApp, RenderSystems};
use bevy_pelt::{Fur, FurGpuStats, FurState};

use crate::common::{self, test_assets as assets, update};
use crate::render::{SIZE, capture_now, cuboid, preset};

/// The render world's stats (furs, assets, drawn), readable from the main world.
#[derive(Resource, Clone, Default)]
struct StatsCopy(Arc<Mutex<(usize, usize, usize)>>);

fn copy_stats(stats: Res<FurGpuStats>, copy: Res<StatsCopy>) {
    *copy.0.lock().unwrap() = (stats.furs, stats.assets, stats.drawn.load(std::sync::atomic::Ordering::Relaxed));
}

const HERD: usize = 100;

#[test]
fn a_hundred_entities_of_one_mesh_and_preset_share_one_asset() {
    let copy = StatsCopy::default();
    let mut app = common::headless_app_with(&assets(), false, None, |app| {
        app.sub_app_mut(RenderApp)
            .insert_resource(copy.clone())
            .add_systems(Render, copy_stats.after(RenderSystems::Render).before(RenderSystems::Cleanup));
    });
    let world = app.world_mut();
    let mut image = Image::new_target_texture(SIZE, SIZE, TextureFormat::Rgba8UnormSrgb, None);
    image.asset_usage = RenderAssetUsages::RENDER_WORLD;
    let target = world.resource_mut::<Assets<Image>>().add(image);
    let cube = cuboid(world, Vec3::splat(0.5));
    let coat = preset(world, "presets/long.toml");
    // A 10 x 10 field of small furred cubes, one mesh and one preset.
    let entities: Vec<Entity> = (0..HERD)
        .map(|k| {
            let (x, z) = ((k % 10) as f32 - 4.5, (k / 10) as f32 - 4.5);
            world.spawn((Mesh3d(cube.clone()), Fur::new(coat.clone()), Transform::from_xyz(x, 0.0, z))).id()
        })
        .collect();
    // One more of the same, far outside the camera's view.
    world.spawn((Mesh3d(cube.clone()), Fur::new(coat.clone()), Transform::from_xyz(500.0, 0.0, 0.0)));
    world.spawn((
        Camera3d::default(),
        RenderTarget::Image(target.clone().into()),
        Tonemapping::None,
        Transform::from_xyz(0.0, 12.0, 0.1).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    loop {
        update(&mut app);
        let world = app.world_mut();
        if world.query::<&FurState>().iter(world).count() == HERD + 1 {
            break;
        }
        assert!(std::time::Instant::now() < deadline, "the herd was not built in two minutes");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    for _ in 0..3 {
        update(&mut app);
    }
    let first = app.world().get::<FurState>(entities[0]).unwrap();
    for &entity in &entities[1..] {
        assert!(app.world().get::<FurState>(entity).unwrap().shares_structure_with(first), "{entity}");
    }
    // Uploaded: every fur on one asset; drawn: all but the one out of view.
    assert_eq!(*copy.0.lock().unwrap(), (HERD + 1, 1, HERD));
    let before = capture_now(&mut app, &target);
    // The middle one goes; the others stay drawn, on the same asset.
    app.world_mut().despawn(entities[44]);
    for _ in 0..3 {
        update(&mut app);
    }
    assert_eq!(*copy.0.lock().unwrap(), (HERD, 1, HERD - 1));
    let after = capture_now(&mut app, &target);
    crate::render::save(&before, "herd_before");
    crate::render::save(&after, "herd_after");
    let changed = before.pixels().zip(after.pixels()).filter(|(a, b)| (common::luma(a) - common::luma(b)).abs() > 24.0);
    let changed = changed.count();
    let total = (SIZE * SIZE) as usize;
    // One cube of a hundred (with its fur and what the light leaves round it) changes, no more.
    assert!(changed > total / 400, "{changed} pixels changed: the despawned fur was still drawn");
    assert!(changed < total / 25, "{changed} pixels changed: more than the despawned fur went");
    // One animal in its own colour: the same asset, and only its pixels turn toward blue.
    app.world_mut().get_mut::<Fur>(entities[0]).unwrap().tint = Vec3::new(0.2, 0.4, 1.0);
    for _ in 0..3 {
        update(&mut app);
    }
    assert_eq!(*copy.0.lock().unwrap(), (HERD, 1, HERD - 1));
    let tinted = capture_now(&mut app, &target);
    crate::render::save(&tinted, "herd_tinted");
    let blueness = |p: &[u8]| i32::from(p[2]) - i32::from(p[0]);
    let bluer = after.pixels().zip(tinted.pixels()).filter(|(a, b)| blueness(&b.0) > blueness(&a.0) + 16).count();
    let moved = after.pixels().zip(tinted.pixels()).filter(|(a, b)| a.0 != b.0).count();
    assert!(bluer > total / 400, "{bluer} pixels turned bluer: the tint did not reach the fur");
    assert!(moved < total / 25, "{moved} pixels changed: the tint reached more than one fur");
}
