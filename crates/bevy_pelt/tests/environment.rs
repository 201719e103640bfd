//! Bevy's environment map light on the fur: a camera's `EnvironmentMapLight`, with no other
//! light in the scene, lights a coat shaded with the fur model, by direction (a sky above
//! lights it more than the same sky below) and by colour (a blue sky makes it bluish); Bevy's
//! own gradient map, kept for the render world only, lights it too.

use bevy::asset::RenderAssetUsages;
use bevy::camera::RenderTarget;
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::light::{EnvironmentMapLight, GlobalAmbientLight};
use bevy::prelude::*;
use bevy::render::render_resource::{
    Extent3d, TextureDimension, TextureFormat, TextureViewDescriptor, TextureViewDimension,
};
use bevy_pelt::Fur;

use crate::common::luma;
use crate::render::{capture, cuboid, preset, save};

/// Sky and ground radiance (linear, before the light's intensity).
const SKY: [f32; 3] = [0.25, 0.5, 1.0];
const GROUND: [f32; 3] = [0.02, 0.02, 0.02];

/// An f32 as half-float bits (normal numbers and zero, mantissa truncated).
fn half(v: f32) -> u16 {
    if v == 0.0 {
        return 0;
    }
    let bits = v.to_bits();
    let exponent = ((bits >> 23) & 0xff) as i32 - 127 + 15;
    (((bits >> 16) & 0x8000) | ((exponent as u32) << 10) | ((bits >> 13) & 0x3ff)) as u16
}

/// A cube map 8x8 a face (`Rgba16Float`, layers +X, -X, +Y, -Y, +Z, -Z as wgpu's cube textures):
/// `SKY` above the horizon, `GROUND` below, or the other way round. A side face's upper rows
/// look above the horizon.
fn sky_cube(upside_down: bool) -> Image {
    let side = 8;
    let (above, below) = if upside_down { (GROUND, SKY) } else { (SKY, GROUND) };
    let data: Vec<u8> = (0..6)
        .flat_map(|layer| (0..side * side).map(move |i| (layer, i / side)))
        .map(|(layer, row)| match layer {
            2 => above,
            3 => below,
            _ if row < side / 2 => above,
            _ => below,
        })
        .flat_map(|c| [half(c[0]), half(c[1]), half(c[2]), half(1.0)])
        .flat_map(u16::to_le_bytes)
        .collect();
    let mut image = Image::new(
        Extent3d { width: side as u32, height: side as u32, depth_or_array_layers: 6 },
        TextureDimension::D2,
        data,
        TextureFormat::Rgba16Float,
        // Kept in the main world, where the fur reads it.
        RenderAssetUsages::default(),
    );
    image.texture_view_descriptor =
        Some(TextureViewDescriptor { dimension: Some(TextureViewDimension::Cube), ..default() });
    image
}

/// What lights the scene.
#[derive(Clone, Copy)]
enum Lighting {
    Nothing,
    Sky {
        upside_down: bool,
    },
    /// Bevy's own `EnvironmentMapLight::hemispherical_gradient`: a 1x1 cube kept for the render
    /// world only, read in the frame Bevy hands it over.
    BevysGradient,
    /// Bevy's global ambient at this brightness.
    Grey(f32),
}

/// The skinless furred cube (fur model), seen from above the front, lit by `lighting` alone.
fn environment_lit(lighting: Lighting) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        let ambient = if let Lighting::Grey(brightness) = lighting { brightness } else { 0.0 };
        world.insert_resource(GlobalAmbientLight { brightness: ambient, ..default() });
        let cube = cuboid(world, Vec3::ONE);
        let fur = Fur::new(preset(world, "presets/long_fur_model.toml")).without_skin();
        world.spawn((Mesh3d(cube), fur, Transform::from_rotation(Quat::from_rotation_y(0.5))));
        let mut camera = world.spawn((
            Camera3d::default(),
            RenderTarget::Image(targets[0].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(0.0, 2.5, 3.5).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        if let Lighting::Sky { upside_down } = lighting {
            let map = camera.world_scope(|world| world.resource_mut::<Assets<Image>>().add(sky_cube(upside_down)));
            // Under the default exposure (about 1/1000) the sky shows at about its texels' values.
            camera.insert(EnvironmentMapLight {
                diffuse_map: map.clone(),
                specular_map: map,
                intensity: 1000.0,
                ..default()
            });
        }
        if let Lighting::BevysGradient = lighting {
            let colour = |c: [f32; 3]| Color::linear_rgb(c[0], c[1], c[2]);
            let light = camera.world_scope(|world| {
                let mut images = world.resource_mut::<Assets<Image>>();
                EnvironmentMapLight::hemispherical_gradient(&mut images, colour(SKY), colour(SKY), colour(GROUND))
            });
            camera.insert(light.with_intensity(1000.0));
        }
    });
    images.into_iter().next().unwrap()
}

/// Mean linear-ish (stored) red, green, blue and luma of `image` over `pixels`.
fn mean_colour(image: &image::RgbaImage, pixels: &[usize]) -> [f32; 4] {
    let mut sum = [0.0f32; 4];
    for &i in pixels {
        let p = image.as_raw()[4 * i..4 * i + 4].try_into().map(image::Rgba::<u8>).unwrap();
        for (s, v) in sum.iter_mut().zip([f32::from(p[0]), f32::from(p[1]), f32::from(p[2]), luma(&p)]) {
            *s += v;
        }
    }
    sum.map(|s| s / pixels.len().max(1) as f32)
}

#[test]
fn an_environment_map_light_lights_the_fur_by_direction_and_colour() {
    let dark = environment_lit(Lighting::Nothing);
    let sky = environment_lit(Lighting::Sky { upside_down: false });
    let ground = environment_lit(Lighting::Sky { upside_down: true });
    // A grey ambient about as bright as the sky's mean.
    let grey = environment_lit(Lighting::Grey(250.0));
    for (image, name) in [(&dark, "dark"), (&sky, "sky"), (&ground, "sky_below"), (&grey, "grey")] {
        save(image, &format!("environment_{name}"));
    }
    let lit: Vec<usize> = sky
        .pixels()
        .zip(dark.pixels())
        .enumerate()
        .filter(|(_, (a, b))| luma(a) > luma(b) + 20.0)
        .map(|(i, _)| i)
        .collect();
    assert!(lit.len() > 1000, "{} fur pixels brighter under the environment map than under nothing", lit.len());
    let [red, green, blue, sky_luma] = mean_colour(&sky, &lit);
    let [grey_red, _, grey_blue, _] = mean_colour(&grey, &lit);
    // The same fur under a grey light: the blue sky shifts it toward blue.
    assert!(
        blue / red.max(1.0) > 1.3 * grey_blue / grey_red.max(1.0),
        "fur under the sky ({red}, {green}, {blue}), under grey ({grey_red}, _, {grey_blue})"
    );
    let [.., ground_luma] = mean_colour(&ground, &lit);
    assert!(sky_luma > ground_luma + 5.0, "mean fur luma {sky_luma} with the sky above, {ground_luma} below");
}

#[test]
fn bevys_own_gradient_environment_map_lights_the_fur() {
    let dark = environment_lit(Lighting::Nothing);
    let gradient = environment_lit(Lighting::BevysGradient);
    save(&gradient, "environment_bevys_gradient");
    let lit = gradient.pixels().zip(dark.pixels()).filter(|(a, b)| luma(a) > luma(b) + 20.0).count();
    assert!(lit > 1000, "{lit} fur pixels brighter under Bevy's gradient than under nothing");
}
