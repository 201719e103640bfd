//! A groom's density, clump and tint on the GPU: each changes the image where its map says and
//! nowhere else. A plane seen from above carries one shell of white strands; the maps split it
//! at x = 0 (left: the map's value, right: the uniform value), and the images are compared half
//! by half, in linear light over black, against the same fur without a groom.

use crate::common;

use common::{Rig, strand_textures};
use glam::{Vec3, Vec4Swizzles as _};
use pelt_core::groom::Groom;
use pelt_core::{Builtin, FurParams, FurStructure, GrowthDirection, fur::FurLength};
use pelt_render::{Camera, FurDrawSettings, FurFrame, FurLook, GpuFur, Light};

const SIZE_PX: u32 = 192;
const WHITE: [u8; 3] = [230, 230, 230];
/// Pixels this close to x = 0 (world) are left out: triangles there blend both sides' values.
const SPLIT_MARGIN: f32 = 0.2;
/// Shells only: the skin would hide the background the coverage is measured against.
const SHELLS: FurDrawSettings = FurDrawSettings { skin: false, fins: false, ..FurDrawSettings::ALL };

/// The 2 x 2 plane (16 x 16 vertices, facing +Y) with one shell, groomed by `groom`.
fn plane_fur(layers: u32, groom: Option<Groom>) -> FurStructure {
    let (mesh, _) = Builtin::Plane.mesh();
    let params = FurParams { layers, length: FurLength::Constant(0.05), direction: GrowthDirection::default() };
    FurStructure::new_groomed(mesh, &params, groom).expect("groomed plane")
}

/// `left` on the vertices with x < 0, `right` on the others.
fn split<T: Copy>(fur: &FurStructure, left: T, right: T) -> Vec<T> {
    fur.mesh.positions.iter().map(|p| if p.x < 0.0 { left } else { right }).collect()
}

fn camera() -> Camera {
    let corners = [Vec3::new(-0.7, 0.0, -0.7), Vec3::new(0.7, 0.0, 0.7)];
    Camera::framing_points(Vec3::ZERO, corners, 0.0, 0.0, 89.0, 1.0)
}

/// The fur over black, in linear RGB per pixel; about 1.5 tiles of 128 texels across the view
/// (two pixels a texel), no highlight, so each channel is the albedo times the coverage.
fn render(rig: &Rig, fur: &FurStructure, name: &str) -> Vec<Vec3> {
    let gpu_fur: GpuFur = rig.fur(fur, &strand_textures(128, fur.layers, WHITE, WHITE));
    let look = FurLook { specular: 0.0, tiles_per_radius: 1.4, ..common::paper_look() };
    gpu_fur.prepare(rig.queue(), &FurFrame { look, ..common::paper_frame() });
    let camera = camera();
    rig.view.prepare(rig.queue(), &camera.view_data(1.0, &Light::default()));
    let image =
        rig.headless.render(Vec3::ZERO, |pass| rig.renderer.draw(pass, &rig.view, &gpu_fur, &SHELLS)).expect("frame");
    image.save(common::out_dir().join(format!("groom-shading-{name}.png"))).expect("save");
    let linear = |c: u8| {
        let c = f32::from(c) / 255.0;
        if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) }
    };
    image.pixels().map(|p| Vec3::new(linear(p[0]), linear(p[1]), linear(p[2]))).collect()
}

/// Which side of x = 0 each pixel's ray meets the plane y = 0 on: `Some(true)` left, `Some(false)`
/// right, `None` within the margin or off the plane. Ray casting shares nothing with the renderer.
fn sides() -> Vec<Option<bool>> {
    let world_from_clip = camera().clip_from_world(1.0).inverse();
    (0..SIZE_PX * SIZE_PX)
        .map(|k| {
            let (x, y) = (k % SIZE_PX, k / SIZE_PX);
            let ndc = |z: f32| {
                let x_ndc = (x as f32 + 0.5) / SIZE_PX as f32 * 2.0 - 1.0;
                let y_ndc = 1.0 - (y as f32 + 0.5) / SIZE_PX as f32 * 2.0;
                let world = world_from_clip * glam::Vec4::new(x_ndc, y_ndc, z, 1.0);
                world.xyz() / world.w
            };
            let (near, far) = (ndc(0.0), ndc(1.0));
            let t = near.y / (near.y - far.y);
            let hit = near + (far - near) * t;
            let on_plane = hit.x.abs() < 0.95 && hit.z.abs() < 0.95;
            (on_plane && hit.x.abs() > SPLIT_MARGIN).then_some(hit.x < 0.0)
        })
        .collect()
}

/// Per side (left, right): the summed linear RGB.
fn sums(image: &[Vec3], sides: &[Option<bool>]) -> [Vec3; 2] {
    let mut sums = [Vec3::ZERO; 2];
    for (pixel, side) in image.iter().zip(sides) {
        if let Some(left) = side {
            sums[usize::from(!left)] += *pixel;
        }
    }
    sums
}

/// Per side (left, right): the mean absolute difference of two images, linear RGB summed.
fn differences(a: &[Vec3], b: &[Vec3], sides: &[Option<bool>]) -> [f32; 2] {
    let mut sum = [0.0; 2];
    let mut count = [0_u32; 2];
    for ((p, q), side) in a.iter().zip(b).zip(sides) {
        if let Some(left) = side {
            let k = usize::from(!left);
            sum[k] += (*p - *q).abs().element_sum();
            count[k] += 1;
        }
    }
    [sum[0] / count[0].max(1) as f32, sum[1] / count[1].max(1) as f32]
}

/// Density 0.5 keeps half the strands: the left half's light (the shell's coverage times a
/// constant albedo) is 0.5 +- 0.06 of the ungroomed fur's; the right half (density 1) keeps
/// all of it (+- 2 %).
#[test]
fn density_half_halves_coverage_where_the_map_says() {
    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let sides = sides();
    // Two layers: the test strands (0.7 to 1 of the length) end below the second.
    let plain = plane_fur(2, None);
    let groom = Groom { density: Some(split(&plain, 0.5, 1.0)), ..Groom::default() };
    let groomed = plane_fur(2, Some(groom));
    let [plain_left, plain_right] = sums(&render(&rig, &plain, "plain"), &sides);
    let [left, right] = sums(&render(&rig, &groomed, "density"), &sides);
    assert!(plain_left.x > 100.0, "the shell covers the left half (light {plain_left})");
    let (left_ratio, right_ratio) = (left.x / plain_left.x, right.x / plain_right.x);
    eprintln!("density coverage ratios: left {left_ratio:.3}, right {right_ratio:.3}");
    assert!((left_ratio - 0.5).abs() <= 0.06, "density 0.5 left {left_ratio} of the coverage");
    assert!((right_ratio - 1.0).abs() <= 0.02, "density 1 left {right_ratio} of the coverage");
}

/// A tint of (1, 0.25, 0.25) on the left half multiplies its green and blue by 0.25 and keeps
/// its red; the right half keeps every channel (+- 2 %).
#[test]
fn tint_multiplies_the_colour_where_the_map_says() {
    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let sides = sides();
    let plain = plane_fur(2, None);
    let groom = Groom { tint: Some(split(&plain, Vec3::new(1.0, 0.25, 0.25), Vec3::ONE)), ..Groom::default() };
    let [plain_left, plain_right] = sums(&render(&rig, &plain, "plain"), &sides);
    let [left, right] = sums(&render(&rig, &plane_fur(2, Some(groom)), "tint"), &sides);
    let left_ratio = left / plain_left;
    let right_ratio = right / plain_right;
    eprintln!("tint ratios: left {left_ratio}, right {right_ratio}");
    assert!((left_ratio.x - 1.0).abs() <= 0.02, "tinted red kept {}", left_ratio.x);
    for ratio in [left_ratio.y, left_ratio.z] {
        assert!((ratio - 0.25).abs() <= 0.03, "tinted green/blue scaled by {ratio}, not 0.25");
    }
    for ratio in right_ratio.to_array() {
        assert!((ratio - 1.0).abs() <= 0.02, "untinted half scaled by {ratio}");
    }
}

/// Clump 1 on the left half moves the strands there (the image changes by more than ten times
/// what it changes on the right, where the clump is 0 and the image stays within noise).
#[test]
fn clump_moves_the_strands_where_the_map_says() {
    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let sides = sides();
    let plain = plane_fur(4, None);
    let groom = Groom { clump: Some(split(&plain, 1.0, 0.0)), ..Groom::default() };
    let before = render(&rig, &plain, "plain-4");
    let after = render(&rig, &plane_fur(4, Some(groom)), "clump");
    let [left, right] = differences(&before, &after, &sides);
    eprintln!("clump differences: left {left:.4}, right {right:.4}");
    assert!(left > 0.02, "clump 1 changed the left half by {left} only");
    assert!(right * 10.0 < left, "clump 0 changed the right half by {right} (left {left})");
}

/// `GpuFur::set_groom` (the painting path: one buffer write) draws what a fur uploaded with that
/// groom draws, to the byte; a fur without a groom refuses it with an error, never a panic.
#[test]
fn set_groom_rewrites_the_shading_in_place() {
    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let textures = strand_textures(128, 2, WHITE, WHITE);
    let plain = plane_fur(2, None);
    let painted_groom = Groom {
        density: Some(split(&plain, 0.3, 0.9)),
        tint: Some(split(&plain, Vec3::new(0.2, 0.9, 0.4), Vec3::ONE)),
        clump: Some(split(&plain, 0.0, 0.7)),
        ..Groom::default()
    };
    let draw = |fur: &GpuFur| {
        let look = FurLook { tiles_per_radius: 1.4, ..common::paper_look() };
        fur.prepare(rig.queue(), &FurFrame { look, ..common::paper_frame() });
        rig.view.prepare(rig.queue(), &camera().view_data(1.0, &Light::default()));
        rig.headless.render(Vec3::ZERO, |pass| rig.renderer.draw(pass, &rig.view, fur, &SHELLS)).expect("frame")
    };
    let fresh = rig.fur(&plane_fur(2, Some(painted_groom.clone())), &textures);
    let uniform_density = Groom { density: Some(vec![1.0; plain.mesh.vertex_count()]), ..Groom::default() };
    let mut painted = rig.fur(&plane_fur(2, Some(uniform_density)), &textures);
    let before = draw(&painted);
    painted.set_groom(rig.queue(), &painted_groom).expect("set_groom");
    let after = draw(&painted);
    assert_ne!(before, after, "the new groom changed nothing");
    assert!(draw(&fresh) == after, "set_groom draws otherwise than a fur uploaded with the groom");

    let mut ungroomed = rig.fur(&plain, &textures);
    let error = ungroomed.set_groom(rig.queue(), &painted_groom).expect_err("no groom to rewrite");
    assert!(error.to_string().contains("without a groom"), "{error}");
    let short = Groom { tint: Some(vec![Vec3::ONE; 3]), ..Groom::default() };
    let error = painted.set_groom(rig.queue(), &short).expect_err("wrong size");
    assert!(error.to_string().contains("3 values"), "{error}");
}
