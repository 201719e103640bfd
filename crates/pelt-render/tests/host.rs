//! What a host embedding the renderer relies on, on a real adapter (lavapipe in CI): two
//! simulation states and interpolation, model transforms, several views in one submission,
//! reverse-Z targets, posed base normals, device checks and honest byte counts. They fail, never
//! skip, without an adapter.

use crate::common;

use common::*;
use glam::{Mat3, Mat4, Quat, Vec3};
use pelt_core::Builtin;
use pelt_core::sim::{SimParams, Simulation, WindParams};
use pelt_render::{
    Camera, DEFAULT_BACKGROUND, FurDrawSettings, FurFrame, FurRenderer, FurStates, FurTarget, FurView, GpuFur,
    HEADLESS_FORMAT, Headless, Light, RenderError, ViewData,
};

const SIZE: u32 = 160;

/// Mean and 99th percentile of the largest channel difference per pixel.
fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> (f64, u8) {
    let mut differences: Vec<u8> = a.pixels().zip(b.pixels()).map(|(p, q)| pixel_difference(p, q)).collect();
    let mean = differences.iter().map(|&d| f64::from(d)).sum::<f64>() / differences.len() as f64;
    differences.sort_unstable();
    (mean, differences[differences.len() * 99 / 100])
}

fn windy(fur: &pelt_core::FurStructure) -> Simulation {
    let wind =
        WindParams { direction: Vec3::X, strength: 3.0, gust_strength: 0.0, jitter: 0.0, ..WindParams::default() };
    Simulation::new(fur, &SimParams { wind, ..SimParams::default() }).expect("simulation")
}

/// The vertex shader's `mix(previous, current, t)` draws each state exactly at 0 and 1, and at
/// 0.5 the pose the CPU interpolates.
#[test]
fn two_states_interpolate_like_the_cpu() {
    let structure = grow(Builtin::Sphere.mesh().0, 12, 0.25);
    let rig = Rig::new(SIZE, SIZE);
    let textures = strand_textures(128, 12, BROWN_ROOT, BROWN_TIP);
    let mut fur = rig.fur_with_states(&structure, &textures, FurStates::Two);
    let single = rig.fur(&structure, &textures);
    let previous = structure.positions.clone();
    let mut simulation = windy(&structure);
    for frame in 0..=8 {
        simulation.advance_to(f64::from(frame) / 30.0);
    }
    let current = simulation.positions().to_vec();
    fur.push_state(rig.queue(), &previous).expect("previous state");
    fur.push_state(rig.queue(), &current).expect("current state");
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 6.0);
    let draw = |t: f32| {
        fur.prepare(rig.queue(), &FurFrame { interpolation: t, ..common::paper_frame() });
        rig.render(&fur, &camera, &settings())
    };
    let reference = |positions: &[Vec3]| {
        single.set_positions(rig.queue(), positions).expect("positions");
        rig.render(&single, &camera, &settings())
    };
    assert_eq!(draw(0.0), reference(&previous), "t = 0 draws the previous state");
    assert_eq!(draw(1.0), reference(&current), "t = 1 draws the current state");
    let halfway: Vec<Vec3> = previous.iter().zip(&current).map(|(a, c)| *a * 0.5 + *c * 0.5).collect();
    let (mean, p99) = difference(&draw(0.5), &reference(&halfway));
    assert!(mean < 0.5 && p99 < 8, "t = 0.5 against the CPU lerp: mean {mean:.3}, p99 {p99}");
    let (mean, _) = difference(&draw(0.5), &reference(&current));
    assert!(mean > 1.0, "and it is not the current state (mean difference {mean:.3})");
    // Each state is a buffer of its own; one state keeps one.
    assert_ne!(fur.previous_positions(), fur.current_positions());
    assert_eq!(single.previous_positions(), single.current_positions());
    let bytes = (fur.gpu_bytes(), single.gpu_bytes());
    assert_eq!(bytes.0.positions, 2 * structure.positions.len() as u64 * 12);
    assert_eq!(bytes.1.positions, structure.positions.len() as u64 * 12);
    assert_eq!(bytes.0.structure() - bytes.1.structure(), bytes.1.positions);
    assert_eq!(bytes.0.textures, bytes.1.textures);
}

/// An affine model transform (rotation, non-uniform scale, translation) draws what the same
/// transform applied on the CPU to the positions and (inverse-transpose) normals draws.
#[test]
fn model_transform_matches_transforming_on_the_cpu() {
    // The sphere has uvs, so its strand tiles do not depend on where it stands.
    let structure = grow(Builtin::Sphere.mesh().0, 12, 0.2);
    let rig = Rig::new(SIZE, SIZE);
    let textures = strand_textures(128, 12, BROWN_ROOT, BROWN_TIP);
    let world_from_model = Mat4::from_scale_rotation_translation(
        Vec3::new(1.3, 0.8, 1.0),
        Quat::from_rotation_y(0.7) * Quat::from_rotation_x(0.3),
        Vec3::new(0.4, -0.2, 0.3),
    );
    let moved = rig.fur(&structure, &textures);
    moved.prepare(rig.queue(), &FurFrame { world_from_model, ..common::paper_frame() });
    let baked = rig.fur(&structure, &textures);
    let positions: Vec<Vec3> = structure.positions.iter().map(|p| world_from_model.transform_point3(*p)).collect();
    let normal_matrix = Mat3::from_mat4(world_from_model).inverse().transpose();
    let normals: Vec<Vec3> = structure.mesh.normals.iter().map(|n| (normal_matrix * *n).normalize()).collect();
    baked.set_positions(rig.queue(), &positions).expect("positions");
    baked.set_base_normals(rig.queue(), &normals).expect("normals");
    let camera = Camera::orbit(Vec3::ZERO, 20.0, 10.0, 7.0);
    let (mean, p99) = difference(&rig.render(&moved, &camera, &settings()), &rig.render(&baked, &camera, &settings()));
    assert!(mean < 0.5 && p99 < 12, "transformed on the GPU against the CPU: mean {mean:.3}, p99 {p99}");
    let untransformed = rig.fur(&structure, &textures);
    let (mean, _) =
        difference(&rig.render(&untransformed, &camera, &settings()), &rig.render(&baked, &camera, &settings()));
    assert!(mean > 2.0, "the transform matters: {mean:.3}");
}

/// Two views drawn in one pass (two viewports) each show their own camera, as rendered alone.
#[test]
fn several_views_in_one_submission_keep_their_own_uniforms() {
    let structure = builtin_fur(Builtin::Box, 8);
    let rig = Rig::new(SIZE, SIZE);
    let fur = rig.fur(&structure, &strand_textures(128, 8, BROWN_ROOT, BROWN_TIP));
    let half = Rig::new(SIZE / 2, SIZE);
    let half_fur = half.fur(&structure, &strand_textures(128, 8, BROWN_ROOT, BROWN_TIP));
    let aspect = 0.5;
    let (centre, radius) = structure.mesh.bounding_sphere();
    let cameras = [framed(&structure, aspect), Camera::framing(centre, radius * 1.2, 75.0, 70.0, aspect)];
    let views = cameras.map(|camera| {
        let view = FurView::new(rig.device(), &rig.renderer);
        view.prepare(rig.queue(), &camera.view_data(aspect, &Light::default()));
        view
    });
    let both = rig
        .headless
        .render(DEFAULT_BACKGROUND, |pass| {
            for (k, view) in views.iter().enumerate() {
                let x = (k as u32 * SIZE / 2) as f32;
                pass.set_viewport(x, 0.0, (SIZE / 2) as f32, SIZE as f32, 0.0, 1.0);
                rig.renderer.draw(pass, view, &fur, &settings());
            }
        })
        .expect("frame");
    for (k, camera) in cameras.iter().enumerate() {
        let alone = half.render(&half_fur, camera, &settings());
        let part = image::imageops::crop_imm(&both, k as u32 * SIZE / 2, 0, SIZE / 2, SIZE).to_image();
        let (mean, p99) = difference(&part, &alone);
        assert!(mean < 0.5 && p99 < 16, "view {k}: mean {mean:.3}, p99 {p99}");
    }
    let (mean, _) = difference(
        &image::imageops::crop_imm(&both, 0, 0, SIZE / 2, SIZE).to_image(),
        &image::imageops::crop_imm(&both, SIZE / 2, 0, SIZE / 2, SIZE).to_image(),
    );
    assert!(mean > 2.0, "the two views differ: {mean:.3}");
}

/// A reverse-Z target (GreaterEqual, cleared to 0, infinite reverse projection) draws the same
/// fur as the conventional one.
#[test]
fn reverse_z_draws_what_conventional_depth_draws() {
    let structure = builtin_fur(Builtin::Torus, 12);
    let textures = strand_textures(128, 12, BROWN_ROOT, BROWN_TIP);
    let rig = Rig::new(SIZE, SIZE);
    let conventional = rig.render(&rig.fur(&structure, &textures), &framed(&structure, 1.0), &settings());

    let target = FurTarget::new(HEADLESS_FORMAT).reverse_z();
    let headless = Headless::with_target(gpu(), target, SIZE, SIZE).expect("reverse-Z target");
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = FurRenderer::new(device, target).expect("renderer");
    let fur = GpuFur::new(device, queue, &renderer, &structure, &textures, FurStates::One).expect("fur");
    fur.prepare(queue, &common::paper_frame());
    let camera = framed(&structure, 1.0);
    let view_from_world = camera.view_from_world();
    let clip_from_world =
        glam::camera::rh::proj::directx::perspective_infinite_reverse(camera.fov_y_rad, 1.0, camera.near)
            * view_from_world;
    let view = FurView::new(device, &renderer);
    let data = ViewData {
        camera_position_world: camera.eye,
        ..ViewData::new(clip_from_world, view_from_world.inverse(), &Light::default())
    };
    view.prepare(queue, &data);
    let reversed =
        headless.render(DEFAULT_BACKGROUND, |pass| renderer.draw(pass, &view, &fur, &settings())).expect("frame");
    let (mean, p99) = difference(&conventional, &reversed);
    assert!(mean < 1.0 && p99 < 40, "reverse-Z against conventional: mean {mean:.3}, p99 {p99}");
    let background = rig.background();
    let drawn = reversed.pixels().filter(|p| covered(p, background)).count();
    assert!(drawn > 2000, "reverse-Z draws the fur ({drawn} pixels)");
}

/// Posed base normals relight the skin and shells; the rest normals are the default.
#[test]
fn posed_base_normals_change_the_lighting() {
    let structure = builtin_fur(Builtin::Sphere, 8);
    let rig = Rig::new(SIZE, SIZE);
    let fur = rig.fur(&structure, &strand_textures(128, 8, BROWN_ROOT, BROWN_TIP));
    let camera = framed(&structure, 1.0);
    let rest = rig.render(&fur, &camera, &FurDrawSettings::SKIN);
    fur.set_base_normals(rig.queue(), &structure.mesh.normals).expect("normals");
    assert_eq!(rig.render(&fur, &camera, &FurDrawSettings::SKIN), rest, "the rest normals are the default");
    // Normals turned to face away from the light darken the lit side.
    let flipped: Vec<Vec3> = structure.mesh.normals.iter().map(|n| -*n).collect();
    fur.set_base_normals(rig.queue(), &flipped).expect("normals");
    let brightness =
        |image: &image::RgbaImage| image.pixels().map(|p| u64::from(p.0[0]) + u64::from(p.0[1])).sum::<u64>();
    let posed = rig.render(&fur, &camera, &FurDrawSettings::SKIN);
    assert!(brightness(&posed) * 10 < brightness(&rest) * 9, "posed normals relight the skin");
    let error = fur.set_base_normals(rig.queue(), &flipped[1..]).expect_err("wrong count");
    assert!(error.to_string().contains("base normals"), "{error}");
}

/// A device made without `required_limits` gets a clear error, not a wgpu panic.
#[test]
fn a_device_below_the_required_limits_is_a_clear_error() {
    let gpu = gpu();
    pelt_render::check_adapter(&gpu.adapter).expect("the test adapter can run Pelt");
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("too small"),
        required_limits: wgpu::Limits { max_storage_buffers_per_shader_stage: 4, ..wgpu::Limits::downlevel_defaults() },
        ..wgpu::DeviceDescriptor::default()
    };
    let (device, _queue) = pollster::block_on(gpu.adapter.request_device(&descriptor)).expect("a small device");
    let error = FurRenderer::new(&device, FurTarget::new(HEADLESS_FORMAT)).expect_err("too few storage buffers");
    assert!(matches!(error, RenderError::Limit { .. }), "{error}");
    assert!(error.to_string().contains("required_limits"), "{error}");
    let error = FurRenderer::new(&gpu.device, FurTarget::new(wgpu::TextureFormat::Depth32Float)).expect_err("bad");
    assert!(error.to_string().contains("not a colour format"), "{error}");
}
