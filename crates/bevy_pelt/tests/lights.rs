//! Bevy's lights on the fur: a point light, with no directional light in the scene, lights a coat
//! shaded with the fur model.

use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
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
