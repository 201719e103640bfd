//! Bevy's lights on the fur: a point light, with no directional light in the scene, lights a coat
//! shaded with the fur model; a plate between the sun and the fur shades it through Bevy's shadow
//! maps, a sun's cascades, a spot light's map and a point light's cube alike.

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::light::{AmbientLight, GlobalAmbientLight, NotShadowCaster, NotShadowReceiver};
use bevy::prelude::*;
use bevy_pelt::Fur;

use crate::common::luma;
use crate::render::{capture, cuboid, preset, save};

/// The skinless furred cube (fur model) before a camera, with a point light in front of it and
/// to the upper right, or without one.
fn point_lit(bulb: bool) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        let cube = cuboid(world, Vec3::ONE);
        let fur = Fur::new(preset(world, "presets/long_fur_model.toml")).without_skin();
        world.spawn((Mesh3d(cube), fur, Transform::from_rotation(Quat::from_rotation_y(0.5))));
        if bulb {
            world.spawn((
                PointLight { intensity: 4_000_000.0, range: 20.0, ..default() },
                Transform::from_xyz(1.5, 1.5, 2.0),
            ));
        }
        world.spawn((
            Camera3d::default(),
            RenderTarget::Image(targets[0].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(0.0, 0.5, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
    });
    images.into_iter().next().unwrap()
}

#[test]
fn a_point_light_reaches_fur_shaded_with_the_fur_model() {
    let lit = point_lit(true);
    let unlit = point_lit(false);
    save(&lit, "point_light_on");
    save(&unlit, "point_light_off");
    let brighter = lit.pixels().zip(unlit.pixels()).filter(|(a, b)| luma(a) > luma(b) + 20.0).count();
    let darker = lit.pixels().zip(unlit.pixels()).filter(|(a, b)| luma(a) + 20.0 < luma(b)).count();
    assert!(brighter > 1000, "{brighter} pixels brighter with the point light");
    assert!(darker < brighter / 20, "{darker} pixels darker, {brighter} brighter");
}

/// The skinless furred cube (fur model) with no light but Bevy's global ambient of `brightness`
/// (cd/m^2), and optionally a camera `AmbientLight` of `camera_brightness` over it.
fn ambient_lit(brightness: f32, camera_brightness: Option<f32>) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        world.insert_resource(GlobalAmbientLight { brightness, ..default() });
        let cube = cuboid(world, Vec3::ONE);
        let fur = Fur::new(preset(world, "presets/long_fur_model.toml")).without_skin();
        world.spawn((Mesh3d(cube), fur, Transform::from_rotation(Quat::from_rotation_y(0.5))));
        let mut camera = world.spawn((
            Camera3d::default(),
            RenderTarget::Image(targets[0].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(0.0, 0.5, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        if let Some(brightness) = camera_brightness {
            camera.insert(AmbientLight { brightness, ..default() });
        }
    });
    images.into_iter().next().unwrap()
}

/// Mean luma of the pixels that differ from the background in `image`.
fn mean_fur_luma(image: &image::RgbaImage, background: &image::RgbaImage) -> (f32, usize) {
    let fur: Vec<f32> = image
        .pixels()
        .zip(background.pixels())
        .filter(|(a, b)| (luma(a) - luma(b)).abs() > 4.0)
        .map(|(a, _)| luma(a))
        .collect();
    (fur.iter().sum::<f32>() / fur.len().max(1) as f32, fur.len())
}

#[test]
fn bevys_ambient_light_reaches_the_fur() {
    // Under the default exposure (EV100 9.7) an ambient of 400 cd/m^2 shows a white diffuse
    // surface at about 0.4; none leaves the coat black.
    let dark = ambient_lit(0.0, None);
    let lit = ambient_lit(400.0, None);
    let camera_lit = ambient_lit(0.0, Some(400.0));
    save(&dark, "ambient_none");
    save(&lit, "ambient_global");
    save(&camera_lit, "ambient_camera");
    let brighter = lit.pixels().zip(dark.pixels()).filter(|(a, b)| luma(a) > luma(b) + 20.0).count();
    assert!(brighter > 1000, "{brighter} pixels brighter under the global ambient");
    let (global, global_pixels) = mean_fur_luma(&lit, &dark);
    let (camera, camera_pixels) = mean_fur_luma(&camera_lit, &dark);
    assert!(global_pixels > 1000 && camera_pixels > 1000, "{global_pixels} and {camera_pixels} fur pixels");
    // The camera's own ambient replaces the global one, at the same brightness the same look.
    assert!((global - camera).abs() < 0.1 * global, "mean fur luma {global} (global) against {camera} (camera)");
}

/// The skinless furred cube (`preset`) seen from the side, lit from above by a sun (or a spot
/// light) with shadows, under a plate out of the camera's view that casts into Bevy's shadow
/// maps, or does not (`NotShadowCaster`); the fur receives shadows unless `NotShadowReceiver`.
fn under_a_plate(preset_path: &'static str, spot: bool, (plate_casts, fur_receives): (bool, bool)) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        let cube = cuboid(world, Vec3::ONE);
        let fur = Fur::new(preset(world, preset_path)).without_skin();
        let mut furred = world.spawn((Mesh3d(cube), fur, Transform::from_rotation(Quat::from_rotation_y(0.5))));
        if !fur_receives {
            furred.insert(NotShadowReceiver);
        }
        let plate = cuboid(world, Vec3::new(3.0, 0.1, 3.0));
        let material = world.resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial::from(Color::WHITE));
        let mut plate = world.spawn((Mesh3d(plate), MeshMaterial3d(material), Transform::from_xyz(0.0, 2.5, 0.0)));
        if !plate_casts {
            plate.insert(NotShadowCaster);
        }
        let above = Transform::from_xyz(0.3, 6.0, 0.2).looking_at(Vec3::ZERO, Vec3::Y);
        if spot {
            world.spawn((
                SpotLight {
                    intensity: 40_000_000.0,
                    range: 30.0,
                    outer_angle: 0.5,
                    shadow_maps_enabled: true,
                    ..default()
                },
                above,
            ));
        } else {
            world.spawn((DirectionalLight { illuminance: 4000.0, shadow_maps_enabled: true, ..default() }, above));
        }
        world.spawn((
            Camera3d::default(),
            RenderTarget::Image(targets[0].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(0.0, 0.2, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
    });
    images.into_iter().next().unwrap()
}

/// The pixels darker and brighter (by over 10 levels) with the plate casting than without, on a
/// fur that receives shadows or not.
fn shaded_by_the_plate(preset_path: &'static str, spot: bool, fur_receives: bool, name: &str) -> (usize, usize) {
    let shaded = under_a_plate(preset_path, spot, (true, fur_receives));
    let open = under_a_plate(preset_path, spot, (false, fur_receives));
    save(&shaded, &format!("{name}_shaded"));
    save(&open, &format!("{name}_open"));
    let darker = shaded.pixels().zip(open.pixels()).filter(|(a, b)| luma(a) + 10.0 < luma(b)).count();
    let brighter = shaded.pixels().zip(open.pixels()).filter(|(a, b)| luma(a) > luma(b) + 10.0).count();
    (darker, brighter)
}

#[test]
fn a_plate_between_the_sun_and_the_fur_darkens_it() {
    for (preset_path, name) in
        [("presets/long.toml", "plate_kajiya_kay"), ("presets/long_fur_model.toml", "plate_fur_model")]
    {
        let (darker, brighter) = shaded_by_the_plate(preset_path, false, true, name);
        assert!(darker > 1000, "{name}: {darker} fur pixels darker under the casting plate");
        assert!(brighter < darker / 20, "{name}: {brighter} pixels brighter, {darker} darker");
    }
    // `NotShadowReceiver` on the fur: the plate's shadow does not reach it.
    let (darker, brighter) = shaded_by_the_plate("presets/long_fur_model.toml", false, false, "plate_not_receiver");
    assert!(darker + brighter < 20, "{darker} pixels darker, {brighter} brighter on a fur that receives no shadows");
}

#[test]
fn a_plate_between_a_spot_light_and_the_fur_darkens_it() {
    let (darker, brighter) = shaded_by_the_plate("presets/long_fur_model.toml", true, true, "plate_spot");
    assert!(darker > 1000, "{darker} fur pixels darker under the casting plate");
    assert!(brighter < darker / 20, "{brighter} pixels brighter, {darker} darker");
}

/// Where a point light shines on the fur from, and the plate between them.
#[derive(Clone, Copy, Debug)]
enum Beside {
    /// From +Z of the fur (Bevy's left-handed "+z" cube face, which looks along -Z).
    Front,
    /// From above (the "-y" face), with a sun of another shadow map size in the scene too.
    AboveWithASun,
}

/// The skinless furred cube (fur model) seen from the front right, lit by a point light with
/// shadows, a plate between them that casts into Bevy's cube map or does not.
fn beside_a_point_light(beside: Beside, plate_casts: bool) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        let cube = cuboid(world, Vec3::ONE);
        let fur = Fur::new(preset(world, "presets/long_fur_model.toml")).without_skin();
        world.spawn((Mesh3d(cube), fur, Transform::from_rotation(Quat::from_rotation_y(0.5))));
        let (light, plate_size, plate) = match beside {
            Beside::Front => (Vec3::new(0.3, 0.5, 5.5), Vec3::new(3.0, 3.0, 0.1), Vec3::new(0.0, 0.0, 2.5)),
            Beside::AboveWithASun => (Vec3::new(0.3, 6.0, 0.2), Vec3::new(3.0, 0.1, 3.0), Vec3::new(0.0, 2.5, 0.0)),
        };
        let plate_mesh = cuboid(world, plate_size);
        let material = world.resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial::from(Color::WHITE));
        let mut plate = world.spawn((Mesh3d(plate_mesh), MeshMaterial3d(material), Transform::from_translation(plate)));
        if !plate_casts {
            plate.insert(NotShadowCaster);
        }
        world.spawn((
            PointLight { intensity: 40_000_000.0, range: 30.0, shadow_maps_enabled: true, ..default() },
            Transform::from_translation(light),
        ));
        if let Beside::AboveWithASun = beside {
            // A dim sun from the camera's side, casting too: its cascades' maps are larger than
            // the point light's cube faces.
            world.spawn((
                DirectionalLight { illuminance: 300.0, shadow_maps_enabled: true, ..default() },
                Transform::from_xyz(3.0, 1.0, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
            ));
        }
        world.spawn((
            Camera3d::default(),
            RenderTarget::Image(targets[0].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(3.0, 0.5, 3.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
    });
    images.into_iter().next().unwrap()
}

#[test]
fn a_plate_between_a_point_light_and_the_fur_darkens_it() {
    for beside in [Beside::Front, Beside::AboveWithASun] {
        let shaded = beside_a_point_light(beside, true);
        let open = beside_a_point_light(beside, false);
        save(&shaded, &format!("plate_point_{beside:?}_shaded"));
        save(&open, &format!("plate_point_{beside:?}_open"));
        let darker = shaded.pixels().zip(open.pixels()).filter(|(a, b)| luma(a) + 10.0 < luma(b)).count();
        let brighter = shaded.pixels().zip(open.pixels()).filter(|(a, b)| luma(a) > luma(b) + 10.0).count();
        assert!(darker > 1000, "{beside:?}: {darker} fur pixels darker behind the casting plate");
        assert!(brighter < darker / 20, "{beside:?}: {brighter} pixels brighter, {darker} darker");
    }
}
