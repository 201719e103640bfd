//! Level of detail on a real adapter (lavapipe in CI; fails, never skips, without one): unseen
//! at the default framing, and far cheaper at 4x the distance.

use crate::common;

use common::*;
use std::collections::HashMap;

use pelt_core::{Builtin, FurStructure, Mesh};
use pelt_render::{Camera, FurDrawSettings, FurFrame, FurLevel, GpuFur, LodSettings, strand_pixels_in_view};

const SIZE: u32 = 256;

fn level(fur: &FurStructure, camera: &Camera, lod: &LodSettings) -> FurLevel {
    let length = fur.lengths.iter().copied().fold(0.0, f32::max);
    let (centre, radius) = fur.mesh.bounding_sphere();
    let pixels = strand_pixels_in_view(length, (centre, radius + length), camera.eye, camera.fov_y_rad, SIZE);
    lod.level(fur.layers, pixels)
}

/// Luma SSIM (image-compare's), the structure the eye sees.
fn ssim(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let luma = |image: &image::RgbaImage| image::DynamicImage::ImageRgba8(image.clone()).to_luma8();
    image_compare::gray_similarity_structure(&image_compare::Algorithm::MSSIMSimple, &luma(a), &luma(b))
        .expect("same size")
        .score
}

/// Mean signed luma difference `b - a` over the pixels either covers (0..255): a level that
/// drops layers without raising the kept ones' alpha shows more skin, a darker mean.
fn mean_luma_shift(a: &image::RgbaImage, b: &image::RgbaImage, background: [u8; 3]) -> f64 {
    let luma =
        |p: &image::Rgba<u8>| 0.2126 * f64::from(p.0[0]) + 0.7152 * f64::from(p.0[1]) + 0.0722 * f64::from(p.0[2]);
    let (mut sum, mut count) = (0.0, 0u32);
    for (x, y) in a.pixels().zip(b.pixels()) {
        if covered(x, background) || covered(y, background) {
            sum += luma(y) - luma(x);
            count += 1;
        }
    }
    sum / f64::from(count.max(1))
}

/// Triangles the last silhouette frame drew: skin, shells (those thinned by view angle over the
/// pass's list only) and the kept fins' segments.
fn triangles(rig: &Rig, fur: &FurStructure, gpu_fur: &GpuFur) -> u64 {
    let draw = rig.read_u32s(gpu_fur.silhouette_draw().expect("fins"));
    let faces = fur.mesh.triangles.len() as u64;
    let shells = u64::from(gpu_fur.drawn_shells());
    assert_eq!(u64::from(draw[0]), 6 * shells, "the indirect draw has the level's fin segments");
    let thinned = u64::from(gpu_fur.shells_thinned());
    let listed = if thinned > 0 { listed_triangles(rig, gpu_fur, &fur.mesh).len() as u64 } else { 0 };
    faces * (1 + shells - thinned) + listed * thinned + u64::from(draw[1]) * 2 * shells
}

/// The triangles the view-angle pass listed in the last frame, as [`triangle_key`]s.
fn listed_triangles(rig: &Rig, gpu_fur: &GpuFur, mesh: &Mesh) -> std::collections::BTreeSet<[usize; 3]> {
    let count = rig.read_u32s(gpu_fur.view_lod_count().expect("a shell list"))[0] as usize;
    let indices = rig.read_u32s(gpu_fur.view_lod_indices().expect("a shell list"));
    assert_eq!(count % 3, 0, "whole triangles");
    let by_wedges: Option<HashMap<[u32; 3], usize>> =
        wedge_triangles(mesh).map(|wedges| wedges.into_iter().enumerate().map(|(t, w)| (w, t)).collect());
    indices[..count].chunks_exact(3).map(|t| triangle_key([t[0], t[1], t[2]], by_wedges.as_ref())).collect()
}

/// Meshes with uvs: each triangle's corners as the shells index them, by wedge (a base vertex
/// with one uv), numbered here in the order the corners first use them; `None` without uvs.
fn wedge_triangles(mesh: &Mesh) -> Option<Vec<[u32; 3]>> {
    let uvs = mesh.corner_uvs.as_ref()?;
    let mut numbered = HashMap::new();
    let mut number = |vertex: u32, uv: glam::Vec2| {
        let next = numbered.len() as u32;
        *numbered.entry((vertex, uv.to_array().map(f32::to_bits))).or_insert(next)
    };
    Some(
        mesh.triangles
            .iter()
            .zip(uvs)
            .map(|(t, uv)| [number(t[0], uv[0]), number(t[1], uv[1]), number(t[2], uv[2])])
            .collect(),
    )
}

/// The list keeps the mesh's triangle order: triangles of one shell overlap near the outline and
/// blend in list order, so an order that followed the threads' timing changed the picture
/// between runs.
fn assert_in_triangle_order(rig: &Rig, gpu_fur: &GpuFur, mesh: &Mesh) {
    let count = rig.read_u32s(gpu_fur.view_lod_count().expect("a shell list"))[0] as usize;
    let indices = rig.read_u32s(gpu_fur.view_lod_indices().expect("a shell list"));
    // What the list holds for each triangle: its wedges with uvs, its base vertices without.
    let triangles = wedge_triangles(mesh).unwrap_or_else(|| mesh.triangles.clone());
    let mut next = 0;
    for triple in indices[..count].chunks_exact(3) {
        let found = (next..triangles.len()).find(|&t| triangles[t] == [triple[0], triple[1], triple[2]]);
        let Some(t) = found else { panic!("{triple:?} is not a later triangle than triangle {next}") };
        next = t + 1;
    }
}

/// A listed triple as a comparable key: meshes with uvs list triangle `t`'s wedges (the key is
/// `[t, t, t]`; `by_wedges` finds `t`), meshes without list the base vertices (the key is them,
/// sorted).
fn triangle_key(triple: [u32; 3], by_wedges: Option<&HashMap<[u32; 3], usize>>) -> [usize; 3] {
    if let Some(by_wedges) = by_wedges {
        let t = by_wedges.get(&triple).unwrap_or_else(|| panic!("wedges {triple:?} are no triangle's"));
        return [*t; 3];
    }
    let mut key = triple.map(|i| i as usize);
    key.sort_unstable();
    key
}

fn render_at(rig: &Rig, gpu_fur: &GpuFur, camera: &Camera, level: FurLevel) -> image::RgbaImage {
    gpu_fur.prepare(rig.queue(), &FurFrame { level, ..common::paper_frame() });
    rig.render_silhouette(gpu_fur, camera, &FurDrawSettings::SILHOUETTE)
}

#[test]
fn lod_is_unseen_at_the_default_framing_and_cheap_far_away() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let lod = LodSettings::default();
    let near = framed(&fur, 1.0);
    let near_level = level(&fur, &near, &lod);
    // The test means something only if the default framing already drops detail.
    assert!(near_level != FurLevel::FULL, "the default framing at {SIZE}px draws {near_level:?}");
    let full = render_at(&rig, &gpu_fur, &near, FurLevel::FULL);
    let reduced = render_at(&rig, &gpu_fur, &near, near_level);
    let similarity = ssim(&full, &reduced);
    eprintln!("default framing: {near_level:?}, SSIM {similarity:.4}");
    assert!(similarity >= 0.98, "LOD {near_level:?} vs full: SSIM {similarity:.4} < 0.98");

    let centre = fur.mesh.bounding_sphere().0;
    let far = Camera { eye: centre + (near.eye - centre) * 4.0, ..near };
    let far_level = level(&fur, &far, &lod);
    render_at(&rig, &gpu_fur, &far, FurLevel::FULL);
    let full_work = triangles(&rig, &fur, &gpu_fur);
    let far_image = render_at(&rig, &gpu_fur, &far, far_level);
    let lod_work = triangles(&rig, &fur, &gpu_fur);
    eprintln!("4x distance: {far_level:?}, triangles {full_work} full, {lod_work} at the level");
    assert!(3 * lod_work <= full_work, "4x the distance: {lod_work} triangles at {far_level:?} vs {full_work} full");
    // Far away the fur still shows: drawn pixels beside the full render's.
    let far_full = render_at(&rig, &gpu_fur, &far, FurLevel::FULL);
    let far_similarity = ssim(&far_full, &far_image);
    eprintln!("4x distance: SSIM {far_similarity:.4}");
    assert!(far_similarity >= 0.95, "4x the distance: SSIM {far_similarity:.4}");
}

/// The guard can fail: two shells at the default framing (stride 8) are seen (SSIM 0.87 on
/// lavapipe when written).
#[test]
fn too_coarse_a_level_fails_the_ssim_guard() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let near = framed(&fur, 1.0);
    let full = render_at(&rig, &gpu_fur, &near, FurLevel::FULL);
    let coarse = render_at(&rig, &gpu_fur, &near, FurLevel { stride: 8, blend: 0.0, ..FurLevel::FULL });
    let similarity = ssim(&full, &coarse);
    assert!(similarity < 0.98, "two shells passed the guard: SSIM {similarity:.4}");
}

/// The view-angle weight at a strand's root, written from the description in `lod.rs` (`|n . v|`
/// at the root, smoothstep over the range), not from the shader.
fn facing_weight(normal: glam::Vec3, root: glam::Vec3, eye: glam::Vec3, [start, full]: [f32; 2]) -> (f32, f32) {
    let facing = normal.normalize().dot((eye - root).normalize()).abs();
    let t = ((facing - start) / (full - start)).clamp(0.0, 1.0);
    (facing, t * t * (3.0 - 2.0 * t))
}

/// Bunny (no uvs) and Spot (uvs), 16 layers, at the default framing.
fn view_angle_models() -> Vec<(&'static str, FurStructure)> {
    vec![("bunny", builtin_fur(Builtin::Bunny, 16)), ("spot", grow(load_asset("spot.obj"), 16, 0.08))]
}

/// The most the mean luma may move (of 255): -0.9 to -1.0 on lavapipe when written; dropping the
/// layers without raising the kept ones' alpha (tried once) moved it by -4.3 to -5.6 while the
/// SSIM stayed above 0.989, so the SSIM alone would not catch it.
const SHIFT_LIMIT: f64 = 2.5;

/// Shells by view angle at the default framing: unseen against the full render, and the
/// thinned shells really skip triangles.
#[test]
fn view_angle_lod_is_unseen_and_draws_fewer_triangles() {
    for (name, fur) in view_angle_models() {
        let rig = Rig::new(SIZE, SIZE);
        let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
        let near = framed(&fur, 1.0);
        // View angle alone (the distance level off), then with the distance level.
        let by_view = FurLevel { facing: Some(LodSettings::DEFAULT_FACING), ..FurLevel::FULL };
        let full = render_at(&rig, &gpu_fur, &near, FurLevel::FULL);
        let full_work = triangles(&rig, &fur, &gpu_fur);
        for level in [by_view, level(&fur, &near, &LodSettings::default())] {
            assert!(level.facing.is_some(), "{name}: {level:?}");
            let reduced = render_at(&rig, &gpu_fur, &near, level);
            let work = triangles(&rig, &fur, &gpu_fur);
            let similarity = ssim(&full, &reduced);
            let shift = mean_luma_shift(&full, &reduced, rig.background());
            eprintln!(
                "{name}: {level:?}: SSIM {similarity:.4}, luma shift {shift:.2}, triangles {work} of {full_work}"
            );
            assert!(similarity >= 0.98, "{name}: {level:?} vs full: SSIM {similarity:.4} < 0.98");
            assert!(shift.abs() < SHIFT_LIMIT, "{name}: {level:?} shifts the mean luma by {shift:.2}");
            let listed = listed_triangles(&rig, &gpu_fur, &fur.mesh).len();
            let faces = fur.mesh.triangles.len();
            assert!(10 * listed < 9 * faces, "{name}: the thinned shells still draw {listed} of {faces} triangles");
            assert!(work < full_work, "{name}: {work} triangles against {full_work}");
        }
    }
}

/// The culling keeps every triangle a thinned shell still shows: each triangle with a corner
/// whose weight is below 1 (checked on the CPU from the mesh, not the shader) is listed, and
/// only triangles near such corners are (the weight must be 1 at all three corners to leave).
#[test]
fn view_angle_culling_keeps_every_triangle_that_still_shows() {
    for (name, fur) in view_angle_models() {
        let rig = Rig::new(SIZE, SIZE);
        let gpu_fur = rig.fur(&fur, &strand_textures(64, 16, BROWN_ROOT, BROWN_TIP));
        let facing = LodSettings::DEFAULT_FACING;
        for (azimuth, elevation) in [(30.0, 15.0), (120.0, -40.0), (250.0, 70.0)] {
            let (centre, radius) = fur.mesh.bounding_sphere();
            let camera = Camera::framing(centre, radius * 1.1, azimuth, elevation, 1.0);
            render_at(&rig, &gpu_fur, &camera, FurLevel { facing: Some(facing), ..FurLevel::FULL });
            let has_uvs = fur.mesh.corner_uvs.is_some();
            let listed = listed_triangles(&rig, &gpu_fur, &fur.mesh);
            assert_in_triangle_order(&rig, &gpu_fur, &fur.mesh);
            let (mut needed, mut borderline) = (0, 0);
            for (t, triangle) in fur.mesh.triangles.iter().enumerate() {
                let weights: Vec<(f32, f32)> = triangle
                    .iter()
                    .map(|&v| {
                        facing_weight(fur.mesh.normals[v as usize], fur.positions[v as usize], camera.eye, facing)
                    })
                    .collect();
                let key = if has_uvs { [t; 3] } else { triangle_key(*triangle, None) };
                // Far from the edge of the range the answer cannot depend on rounding.
                let shows = weights.iter().any(|&(f, _)| f < facing[1] - 1e-4);
                let gone = weights.iter().all(|&(f, w)| f > facing[1] + 1e-4 && w == 1.0);
                if shows {
                    needed += 1;
                    assert!(
                        listed.contains(&key),
                        "{name} from ({azimuth}, {elevation}): triangle {t} {weights:?} was culled"
                    );
                } else if gone {
                    assert!(
                        !listed.contains(&key),
                        "{name} from ({azimuth}, {elevation}): triangle {t} {weights:?} was kept"
                    );
                } else {
                    borderline += 1;
                }
            }
            eprintln!(
                "{name} from ({azimuth}, {elevation}): {} listed, {needed} needed, {borderline} borderline, {} faces",
                listed.len(),
                fur.mesh.triangles.len()
            );
            assert!(listed.len() < fur.mesh.triangles.len(), "{name}: nothing culled");
        }
    }
}
