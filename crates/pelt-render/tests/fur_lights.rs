//! The fur model on the GPU: a furnace (white fur under a uniform white environment and no
//! light returns at most the environment's radiance) and back light (the rim glows through the
//! strands with the fur model, far more than with Kajiya-Kay).

use crate::common;

use common::{Rig, builtin_fur, framed, strand_textures};
use glam::Vec3;
use pelt_core::Builtin;
use pelt_core::light::{Environment, LightSource};
use pelt_render::{FurDrawSettings, FurFrame, FurLook, FurShading, GpuFur, Light};

const SIZE_PX: u32 = 160;
const WHITE: [u8; 3] = [255, 255, 255];

fn look(fur_model: bool) -> FurLook {
    FurLook { shading: FurShading { fur_model, ..FurShading::default() }, ..common::paper_look() }
}

/// The sphere's fur in `look`, lit by `lights` and `environment`, over black.
fn render(
    rig: &Rig,
    fur: &GpuFur,
    look: FurLook,
    lights: &[LightSource],
    environment: Environment,
    name: &str,
) -> image::RgbaImage {
    fur.prepare(rig.queue(), &FurFrame { look, ..common::paper_frame() });
    let structure = builtin_fur(Builtin::Sphere, 16);
    let camera = framed(&structure, 1.0);
    let view = camera.view_data(1.0, &Light::default()).with_lights(lights, Some(environment));
    rig.view.prepare(rig.queue(), &view);
    let image = rig
        .headless
        .render(Vec3::ZERO, |pass| rig.renderer.draw(pass, &rig.view, fur, &FurDrawSettings::ALL))
        .expect("frame");
    image.save(common::out_dir().join(format!("fur-lights-{name}.png"))).expect("save");
    image
}

fn srgb_encode(linear: f32) -> f32 {
    if linear <= 0.003_130_8 { linear * 12.92 } else { 1.055 * linear.powf(1.0 / 2.4) - 0.055 }
}

#[test]
fn white_fur_in_a_white_furnace_returns_at_most_the_radiance() {
    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let structure = builtin_fur(Builtin::Sphere, 16);
    let fur = rig.fur(&structure, &strand_textures(128, 16, WHITE, WHITE));
    let radiance = 0.5;
    let image = render(&rig, &fur, look(true), &[], Environment::uniform(Vec3::splat(radiance)), "furnace");
    // One 8-bit step of rounding above the encoded radiance.
    let limit = (srgb_encode(radiance) * 255.0).round() + 1.0;
    let brightest = image.pixels().flat_map(|p| [p[0], p[1], p[2]]).max().unwrap();
    assert!(f32::from(brightest) <= limit, "a pixel of {brightest} exceeds the environment's {limit}");
    // The furnace is lit: the tips return nearly all of it.
    assert!(f32::from(brightest) >= limit - 40.0, "the fur is too dark to tell: {brightest} of {limit}");
}

/// Mean brightness of the covered pixels within `band` pixels of the background (the rim) and
/// of those farther in (the interior).
fn rim_and_interior(image: &image::RgbaImage, band: i32) -> (f32, f32) {
    let (w, h) = (image.width() as i32, image.height() as i32);
    let covered = |x: i32, y: i32| {
        (0..w).contains(&x) && (0..h).contains(&y) && {
            let p = image.get_pixel(x as u32, y as u32);
            p[0] > 2 || p[1] > 2 || p[2] > 2
        }
    };
    let (mut rim, mut interior) = ((0.0, 0), (0.0, 0));
    for y in 0..h {
        for x in 0..w {
            if !covered(x, y) {
                continue;
            }
            let near_edge = (-band..=band).any(|dy| (-band..=band).any(|dx| !covered(x + dx, y + dy)));
            let p = image.get_pixel(x as u32, y as u32);
            let value = (f32::from(p[0]) + f32::from(p[1]) + f32::from(p[2])) / 3.0;
            let sum = if near_edge { &mut rim } else { &mut interior };
            sum.0 += value;
            sum.1 += 1;
        }
    }
    assert!(rim.1 > 0 && interior.1 > 0, "no rim or no interior");
    (rim.0 / rim.1 as f32, interior.0 / interior.1 as f32)
}

#[test]
fn back_light_makes_the_rim_glow_with_the_fur_model_only() {
    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let structure = builtin_fur(Builtin::Sphere, 16);
    let fur = rig.fur(&structure, &strand_textures(128, 16, common::BROWN_ROOT, common::BROWN_TIP));
    let camera = framed(&structure, 1.0);
    let to_camera = (camera.view_data(1.0, &Light::default()).camera_position_world).normalize();
    // Behind the sphere, a little above it.
    let back = LightSource::directional(-to_camera + Vec3::new(0.0, 0.25, 0.0), Vec3::ONE, 3.0);
    let fill = Environment::uniform(Vec3::splat(0.1));
    let fur_model = render(&rig, &fur, look(true), &[back], fill, "back-fur");
    let kajiya_kay = render(&rig, &fur, look(false), &[back], fill, "back-kajiya-kay");
    let (rim, interior) = rim_and_interior(&fur_model, 4);
    assert!(rim > 1.3 * interior, "fur model: rim {rim} against interior {interior}");
    let glow = rim / interior;
    // Kajiya-Kay has no transmitted lobe: its rim is lit only where the soft terminator reaches
    // round the sphere (1.29 here, the fur model 1.94).
    let (rim, interior) = rim_and_interior(&kajiya_kay, 4);
    assert!(1.3 * rim / interior < glow, "kajiya-kay: rim {rim} against interior {interior}, the fur model {glow}");
}
