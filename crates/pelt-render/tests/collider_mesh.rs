//! A plain mesh collider drawn with the fur: the pebble (a closed mesh, its distance field baked
//! from a scene script) pressed into a furry sphere shows in front of the fur it pushed aside,
//! where the same pebble, unknown to the simulation, is drawn over by the fur growing through
//! it. Fails, never skips, without an adapter. (The sphere rather than the bunny: the bunny's
//! shells, a few strands across the pebble, span straight through it between the strands around
//! it, so fur shows over it either way.)

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
const SIZE_PX: u32 = 220;
/// The pebble's scale; it reaches 0.75 of that back and 0.77 forward along Z, toward the camera.
const PEBBLE_SCALE: f32 = 0.3;
/// The pebble's centre: its back a little off the unit sphere, its front inside the fur (which
/// reaches out to 2).
const PEBBLE_CENTRE: Vec3 = Vec3::new(0.0, 0.0, 1.25);

/// Renders the furry sphere after a second, the pebble drawn where the script puts it; the
/// simulation knows of the pebble only when `collide`. Returns the image, the camera and the
/// pebble's centre and scale.
fn render(collide: bool) -> (image::RgbaImage, Camera, Vec3, f32) {
    let headless = Headless::with_gpu(gpu(), SIZE_PX, SIZE_PX).expect("headless");
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer().expect("renderer");
    let structure = grow(Builtin::Sphere.mesh().0, 16, 1.0);
    let (scale, centre) = (PEBBLE_SCALE, PEBBLE_CENTRE);
    // Beside the assets: the mesh path is relative to the script's folder.
    let name = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/collider-mesh-test.toml");
    let script = format!(
        "[[collider]]\nshape = {{ kind = \"mesh\", path = \"meshes/pebble.obj\", resolution = 24, scale = {scale} }}\n\
         appear_secs = 0.2\nkeys = [{{ time_secs = 0.0, position = [{}, {}, {}] }}]\n",
        centre.x, centre.y, centre.z
    );
    let scene = Scene::from_toml_str(&script, &name).expect("script");
    let textures = strand_textures(32, 16, BROWN_ROOT, BROWN_TIP);
    let mut params = SimParams { gravity_strength: 0.0, ..SimParams::default() };
    params.wind.strength = 0.0;
    let mut driver =
        FurDriver::new(device, queue, &renderer, &structure, &textures, &params, KernelChoice::Cpu).expect("driver");
    driver.set_look(common::paper_look());
    let mut stepper = FurStepper::new(&structure, &params).expect("stepper");
    if collide {
        stepper.set_scene(Some(scene));
    }
    let view = FurView::new(device, &renderer);
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 7.0);
    view.prepare(queue, &camera.view_data(headless.aspect_ratio(), &Light::default()));
    let time_secs = 1.0;
    for frame in 0..=(time_secs * RATE_HZ) as u32 {
        driver.advance_to(device, queue, &mut stepper, f64::from(frame) / RATE_HZ).expect("advance");
    }
    let shown: Vec<StepCollider> = if collide {
        stepper.simulation().shown_colliders(time_secs)
    } else {
        // The pebble as the scripted simulation would show it, drawn over a simulation without it.
        let mut scripted = FurStepper::new(&structure, &params).expect("stepper");
        scripted.set_scene(Some(Scene::from_toml_str(&script, &name).expect("script")));
        scripted.advance_to(time_secs).expect("advance");
        scripted.simulation().shown_colliders(time_secs)
    };
    assert_eq!(shown.len(), 1, "one pebble is drawn");
    assert!(shown[0].kind == StepCollider::MESH && shown[0].centre == centre);
    let mut colliders = ColliderMeshes::new();
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
    (image, camera, centre, scale)
}

/// The pixels within half the pebble's narrower half width (0.6 of its scale, along Y) of its
/// front's centre, as seen.
fn pebble_front(camera: &Camera, centre: Vec3, scale: f32) -> Vec<(u32, u32)> {
    let clip_from_world = camera.clip_from_world(1.0);
    let pixel = |p: Vec3| {
        let ndc = clip_from_world.project_point3(p);
        glam::Vec2::new((ndc.x * 0.5 + 0.5) * SIZE_PX as f32, (0.5 - ndc.y * 0.5) * SIZE_PX as f32)
    };
    let front = centre + Vec3::Z * (0.77 * scale);
    let middle = pixel(front);
    let inner = 0.5 * pixel(front + Vec3::Y * (0.55 * scale)).distance(middle);
    assert!(inner > 4.0, "the pebble covers enough pixels: {inner}");
    (0..SIZE_PX)
        .flat_map(|y| (0..SIZE_PX).map(move |x| (x, y)))
        .filter(|&(x, y)| glam::Vec2::new(x as f32 + 0.5, y as f32 + 0.5).distance(middle) < inner)
        .collect()
}

/// Whether a pixel is the pebble's cool grey rather than the brown fur (fur is red over blue,
/// the pebble blue over red, however each is lit).
fn is_pebble(pixel: &image::Rgba<u8>) -> bool {
    i32::from(pixel[2]) > i32::from(pixel[0]) + 8
}

fn pebble_share(image: &image::RgbaImage, region: &[(u32, u32)]) -> f32 {
    region.iter().filter(|&&(x, y)| is_pebble(image.get_pixel(x, y))).count() as f32 / region.len() as f32
}

#[test]
fn a_mesh_pressed_into_the_fur_shows_in_front_of_it() {
    const { assert!(COLLIDER_COLOUR.z > COLLIDER_COLOUR.x + 0.1, "the test tells the pebble by its blue") };
    let (pushed, camera, centre, scale) = render(true);
    let (through, ..) = render(false);
    let region = pebble_front(&camera, centre, scale);
    let out = common::out_dir();
    pushed.save(out.join("collider-mesh-pushed.png")).expect("save");
    through.save(out.join("collider-mesh-through.png")).expect("save");
    let (shown, covered) = (pebble_share(&pushed, &region), pebble_share(&through, &region));
    eprintln!("the pebble shows on {shown} of its front pushing the fur, {covered} inside it");
    assert!(shown > 0.75, "the pebble the fur is pushed out of shows: {:.0}% of its front", shown * 100.0);
    assert!(
        covered < 0.6,
        "fur growing through the pebble is drawn over it: {:.0}% of its front shows",
        covered * 100.0
    );
}
