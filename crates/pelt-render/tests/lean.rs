//! The lean shell path on a real adapter (lavapipe in CI; fails, never skips, without one): the
//! economies it makes must not be seen.

mod common;

use std::path::Path;

use common::*;
use pelt_core::Builtin;

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
/// one projection per face, from the first vertex's normal, scored 0.974 and was dropped). The reference is the bunny as the three-projection
/// blend drew it (`golden/bunny-still-triplanar-blend.png`, the `bunny-still` golden before the
/// change, kept apart so that updating the goldens does not move it). Sampling every fragment
/// through the z projection (strands smeared where the surface faces sideways) scores 0.924 and
/// fails.
#[test]
fn one_projection_looks_like_the_blend() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    assert!(fur.mesh.corner_uvs.is_none(), "the bunny has no uvs: it is drawn through the projections");
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let image = rig.render(&gpu_fur, &framed(&fur, 1.0), &settings());
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden/bunny-still-triplanar-blend.png");
    let blend = image::open(&path).unwrap_or_else(|error| panic!("{}: {error}", path.display())).to_rgba8();
    let similarity = ssim(&blend, &image);
    eprintln!("one projection against the blend: SSIM {similarity:.4}");
    assert!(similarity >= 0.98, "one projection vs the three-projection blend: SSIM {similarity:.4} < 0.98");
}
