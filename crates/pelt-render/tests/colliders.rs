//! Colliders drawn with the fur: a ball pressed into a furry sphere shows in front of the fur
//! it pushed aside, where the same ball, unknown to the simulation, is drawn over by the fur
//! growing through it. Fails, never skips, without an adapter.

use crate::common;

use std::path::Path;

use common::{BROWN_ROOT, BROWN_TIP, gpu, grow, strand_textures};
use glam::Vec3;
use pelt_core::Builtin;
use pelt_core::sim::{FurStepper, Scene, SimParams, StepCollider};
use pelt_render::{
    COLLIDER_COLOUR, Camera, ColliderMeshes, DEFAULT_BACKGROUND, FurDrawSettings, FurDriver, FurView, Headless,
    KernelChoice, Light,
};

const RATE_HZ: f64 = 30.0;
const SIZE_PX: u32 = 160;
/// The ball, pressed into the unit sphere's fur (which reaches out to 2) facing the camera.
const BALL_CENTRE: Vec3 = Vec3::new(0.0, 0.0, 1.2);
const BALL_RADIUS: f32 = 0.3;

/// A still ball in the fur from time 0, without gravity or wind, so nothing but the ball moves
/// the strands.
const SCRIPT: &str = r#"
[[collider]]
shape = { kind = "sphere", radius = 0.3 }
appear_secs = 0.2
keys = [{ time_secs = 0.0, position = [0.0, 0.0, 1.2] }]
"#;

/// Renders the furry sphere after a second, the ball drawn where it is; the simulation knows of
/// the ball only when `collide`.
fn render(collide: bool) -> (image::RgbaImage, Camera) {
    let headless = Headless::with_gpu(gpu(), SIZE_PX, SIZE_PX).expect("headless");
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer().expect("renderer");
    let structure = grow(Builtin::Sphere.mesh().0, 16, 1.0);
    let textures = strand_textures(32, 16, BROWN_ROOT, BROWN_TIP);
    let mut params = SimParams { gravity_strength: 0.0, ..SimParams::default() };
    params.wind.strength = 0.0;
    let mut driver =
        FurDriver::new(device, queue, &renderer, &structure, &textures, &params, KernelChoice::Cpu).expect("driver");
    driver.set_look(common::paper_look());
    let mut stepper = FurStepper::new(&structure, &params).expect("stepper");
    if collide {
        stepper.set_scene(Some(Scene::from_toml_str(SCRIPT, Path::new("colliders-test.toml")).expect("script")));
    }
    let view = FurView::new(device, &renderer);
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 7.0);
    view.prepare(queue, &camera.view_data(headless.aspect_ratio(), &Light::default()));
    let mut colliders = ColliderMeshes::new();
    let time_secs = 1.0;
    for frame in 0..=(time_secs * RATE_HZ) as u32 {
        driver.advance_to(device, queue, &mut stepper, f64::from(frame) / RATE_HZ).expect("advance");
    }
    let shown = if collide {
        stepper.simulation().shown_colliders(time_secs)
    } else {
        vec![StepCollider::ball(BALL_CENTRE, BALL_RADIUS)]
    };
    assert_eq!(shown.len(), 1, "one ball is drawn");
    assert!((shown[0].radius - BALL_RADIUS).abs() < 1e-6 && shown[0].centre == BALL_CENTRE);
    colliders.update(device, queue, &renderer, &shown, glam::Mat4::IDENTITY, 1.0).expect("collider meshes");
    let image = headless
        .render_with(
            DEFAULT_BACKGROUND,
            |encoder| driver.record_view(encoder, &renderer, &view),
            |pass| {
                colliders.draw(pass, &renderer, &view);
                driver.draw(pass, &renderer, &view, &FurDrawSettings::SILHOUETTE);
            },
        )
        .expect("render");
    (image, camera)
}

/// The pixels inside half the ball's projected disc (its rim meets the fur around it).
fn ball_disc(camera: &Camera) -> Vec<(u32, u32)> {
    let clip_from_world = camera.clip_from_world(1.0);
    let project = |p: Vec3| {
        let ndc = clip_from_world.project_point3(p);
        (ndc.x * 0.5 + 0.5) * SIZE_PX as f32
    };
    let centre_ndc = clip_from_world.project_point3(BALL_CENTRE);
    let (cx, cy) = ((centre_ndc.x * 0.5 + 0.5) * SIZE_PX as f32, (0.5 - centre_ndc.y * 0.5) * SIZE_PX as f32);
    // The ball's silhouette seen from the eye, measured sideways at its centre's depth.
    let right = (camera.eye - BALL_CENTRE).cross(Vec3::Y).normalize();
    let radius_px = (project(BALL_CENTRE + right * BALL_RADIUS) - cx).abs();
    assert!(radius_px > 4.0, "the ball covers enough pixels: {radius_px}");
    let inner = 0.5 * radius_px;
    (0..SIZE_PX)
        .flat_map(|y| (0..SIZE_PX).map(move |x| (x, y)))
        .filter(|&(x, y)| (x as f32 + 0.5 - cx).hypot(y as f32 + 0.5 - cy) < inner)
        .collect()
}

/// Whether a pixel is the ball's cool grey rather than the brown fur (fur is red over blue, the
/// ball blue over red, however each is lit).
fn is_ball(pixel: &image::Rgba<u8>) -> bool {
    i32::from(pixel[2]) > i32::from(pixel[0]) + 8
}

fn ball_share(image: &image::RgbaImage, disc: &[(u32, u32)]) -> f32 {
    disc.iter().filter(|&&(x, y)| is_ball(image.get_pixel(x, y))).count() as f32 / disc.len() as f32
}

#[test]
fn a_ball_pressed_into_the_fur_shows_in_front_of_it() {
    const { assert!(COLLIDER_COLOUR.z > COLLIDER_COLOUR.x + 0.1, "the test tells the ball by its blue") };
    let (pushed, camera) = render(true);
    let (through, _) = render(false);
    let disc = ball_disc(&camera);
    let out = common::out_dir();
    pushed.save(out.join("colliders-pushed.png")).expect("save");
    through.save(out.join("colliders-through.png")).expect("save");
    let (shown, covered) = (ball_share(&pushed, &disc), ball_share(&through, &disc));
    eprintln!("ball shows on {shown} of its disc pushing the fur, {covered} inside it");
    assert!(shown > 0.75, "the ball the fur is pushed out of shows: {:.0}% of its disc", shown * 100.0);
    assert!(covered < 0.6, "fur growing through a ball is drawn over it: {:.0}% of its disc shows", covered * 100.0);
}
