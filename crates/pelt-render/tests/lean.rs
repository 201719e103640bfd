//! The lean shell path on a real adapter (lavapipe in CI; fails, never skips, without one): the
//! economies it makes must not be seen.

use crate::common;

use std::path::Path;

use common::*;
use glam::{Mat4, Vec3};
use pelt_core::Builtin;
use pelt_render::{CpuSilhouette, FurDrawSettings, FurFrame, FurLevel, GpuFur};

const SIZE: u32 = 256;

/// Luma SSIM (image-compare's), the structure the eye sees.
fn ssim(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let luma = |image: &image::RgbaImage| image::DynamicImage::ImageRgba8(image.clone()).to_luma8();
    image_compare::gray_similarity_structure(&image_compare::Algorithm::MSSIMSimple, &luma(a), &luma(b))
        .expect("same size")
        .score
}

/// Meshes without uvs take the one axis-aligned projection of the tiles their surface faces most
/// (one texture fetch a fragment) instead of a blend of all three (0.983 when this was written;
/// one projection per face, from the first vertex's normal, scored 0.974 and was dropped). The
/// reference is the bunny as the three-projection blend drew it, with its lighting per fragment
/// (`golden/bunny-still-triplanar-blend.png`, the `bunny-still` golden before the change, kept
/// apart so that updating the goldens does not move it); since the shells' lighting terms come
/// from the vertices (`per_vertex_lighting_looks_like_per_fragment`) the two economies together
/// score 0.977 (0.980 before), hence 0.97 here. Sampling every fragment through the z projection (strands
/// smeared where the surface faces sideways) scores 0.924 and fails.
#[test]
fn one_projection_looks_like_the_blend() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    assert!(fur.mesh.corner_uvs.is_none(), "the bunny has no uvs: it is drawn through the projections");
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let image = rig.render(&gpu_fur, &framed(&fur, 1.0), &settings());
    let similarity = ssim(&reference("bunny-still-triplanar-blend.png"), &image);
    eprintln!("one projection against the blend: SSIM {similarity:.4}");
    assert!(similarity >= 0.97, "one projection vs the three-projection blend: SSIM {similarity:.4} < 0.97");
}

fn reference(name: &str) -> image::RgbaImage {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden").join(name);
    image::open(&path).unwrap_or_else(|error| panic!("{}: {error}", path.display())).to_rgba8()
}

/// Mean luma over the pixels either image covers (not the background).
fn fur_luma(a: &image::RgbaImage, b: &image::RgbaImage, background: [u8; 3]) -> (f64, f64) {
    let luma = |p: &image::Rgba<u8>| 0.299 * f64::from(p[0]) + 0.587 * f64::from(p[1]) + 0.114 * f64::from(p[2]);
    let (mut sums, mut count) = ((0.0, 0.0), 0.0);
    for (p, q) in a.pixels().zip(b.pixels()) {
        if covered(p, background) || covered(q, background) {
            sums.0 += luma(p);
            sums.1 += luma(q);
            count += 1.0;
        }
    }
    (sums.0 / count, sums.1 / count)
}

/// The shells' lighting terms (the Kajiya-Kay sines, the lit side, occlusion) are computed per
/// vertex and interpolated, instead of the normal, tangent and position they come from (a quarter
/// of the shells' frame at 1280x720 on lavapipe, BENCHMARKS.md). The references are the
/// `bunny-still` and `bunny-wind` scenes as lighting per fragment drew them just before the change,
/// kept apart: SSIM 0.997 and 0.998 when this was written, the fur's mean luma within 0.25 of 255.
/// Wind bends the strands away from the surface normal, so the windy scene is the one that tells
/// the strand's tangent from the normal: lighting the shells by their base normal, tried once,
/// scores 0.984 there and darkens the fur by 12, and fails.
#[test]
fn per_vertex_lighting_looks_like_per_fragment() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let still = rig.render(&gpu_fur, &framed(&fur, 1.0), &settings());
    gpu_fur.set_positions(rig.queue(), golden_wind(&fur).positions()).expect("positions");
    let windy = rig.render(&gpu_fur, &framed(&fur, 1.0), &settings());
    for (name, image) in [("bunny-still-fragment-lighting.png", still), ("bunny-wind-fragment-lighting.png", windy)] {
        let per_fragment = reference(name);
        let similarity = ssim(&per_fragment, &image);
        let (before, after) = fur_luma(&per_fragment, &image, rig.background());
        eprintln!("{name}: SSIM {similarity:.4}, fur luma {before:.2} -> {after:.2}");
        assert!(similarity >= 0.99, "{name}: per-vertex lighting SSIM {similarity:.4} < 0.99");
        assert!((after - before).abs() < 1.0, "{name}: fur luma moved {before:.2} -> {after:.2}");
    }
}

/// `(edge, fade)` of the fins the last silhouette decision kept, which must be in edge order:
/// fins overlap along the outline and blend in list order, so an order that followed the
/// threads' timing (the compute pass's atomic append before) changed the picture between runs.
fn kept_fins(rig: &Rig, fur: &GpuFur) -> Vec<(u32, f32)> {
    let count = rig.read_u32s(fur.silhouette_draw().expect("fins"))[1] as usize;
    let words = rig.read_u32s(fur.silhouette_instances().expect("fins"));
    let fins: Vec<(u32, f32)> = words[..2 * count].chunks_exact(2).map(|w| (w[0], f32::from_bits(w[1]))).collect();
    for pair in fins.windows(2) {
        assert!(pair[0].0 < pair[1].0, "fins out of edge order: {} before {}", pair[0].0, pair[1].0);
    }
    fins
}

/// The CPU silhouette keeps the fins the compute pass keeps, with the same fades, on a small and
/// a larger mesh and under a model transform with rotation and non-uniform scale. Edges right at
/// the fade's end may fall either way in floating point: only fins faded below 1e-3 may be in one
/// list and not the other.
#[test]
fn cpu_and_compute_silhouettes_keep_the_same_fins() {
    let rig = Rig::new(64, 64);
    for builtin in [Builtin::Box, Builtin::Bunny] {
        let fur = builtin_fur(builtin, 8);
        let gpu_fur = rig.fur(&fur, &strand_textures(32, 8, BROWN_ROOT, BROWN_TIP));
        let mut silhouette = CpuSilhouette::new(&fur.mesh);
        let turned = Mat4::from_rotation_y(0.7) * Mat4::from_scale(Vec3::new(1.0, 1.6, 0.8));
        for world_from_model in [Mat4::IDENTITY, turned] {
            let frame = FurFrame {
                world_from_model,
                level: FurLevel { stride: 2, blend: 0.0, ..FurLevel::FULL },
                ..common::paper_frame()
            };
            gpu_fur.prepare(rig.queue(), &frame);
            let camera = framed(&fur, 1.0);
            rig.render_silhouette(&gpu_fur, &camera, &FurDrawSettings::SILHOUETTE);
            let compute = kept_fins(&rig, &gpu_fur);
            let kept = gpu_fur
                .prepare_fins_on_cpu(rig.queue(), &mut silhouette, &fur.positions, &frame, camera.eye)
                .expect("CPU silhouette");
            let cpu = kept_fins(&rig, &gpu_fur);
            let draw = rig.read_u32s(gpu_fur.silhouette_draw().expect("fins"));
            assert_eq!(draw[0], 6 * 4, "{builtin}: the CPU draw has the level's 4 segments");
            assert_eq!(kept as usize, cpu.len(), "{builtin}: the count returned is the count written");
            assert!(compute.len() > 10, "{builtin}: the compute pass kept {} fins", compute.len());
            eprintln!("{builtin}: compute pass {} fins, CPU {} fins", compute.len(), cpu.len());
            let (mut i, mut j) = (0, 0);
            loop {
                let only_compute = |(edge, fade): (u32, f32)| {
                    assert!(fade < 1e-3, "{builtin}: only the compute pass kept edge {edge} (fade {fade})");
                };
                match (compute.get(i).copied(), cpu.get(j).copied()) {
                    (Some((a, fade_a)), Some((b, fade_b))) if a == b => {
                        assert!((fade_a - fade_b).abs() < 1e-4, "{builtin}: edge {a} fades {fade_a} vs {fade_b}");
                        (i, j) = (i + 1, j + 1);
                    }
                    (Some(fin), Some((b, _))) if fin.0 < b => {
                        only_compute(fin);
                        i += 1;
                    }
                    (Some(fin), None) => {
                        only_compute(fin);
                        i += 1;
                    }
                    (_, Some((b, fade))) => {
                        assert!(fade < 1e-3, "{builtin}: only the CPU kept edge {b} (fade {fade})");
                        j += 1;
                    }
                    (None, None) => break,
                }
            }
        }
    }
    // A silhouette made for another mesh is refused, not drawn.
    let bunny = builtin_fur(Builtin::Bunny, 8);
    let gpu_fur = rig.fur(&bunny, &strand_textures(32, 8, BROWN_ROOT, BROWN_TIP));
    let mut other = CpuSilhouette::new(&Builtin::Box.mesh().0);
    let refused = gpu_fur.prepare_fins_on_cpu(
        rig.queue(),
        &mut other,
        &bunny.positions,
        &common::paper_frame(),
        Vec3::new(0.0, 0.0, 5.0),
    );
    assert!(refused.is_err(), "a silhouette of the box drew the bunny's fins");
}
