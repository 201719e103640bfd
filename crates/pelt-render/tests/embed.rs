//! The embed example's scene on a real adapter (lavapipe in CI): the host's own geometry and
//! reverse-Z depth buffer with Pelt's fur drawn into the host's pass, against a golden
//! screenshot. The golden comparison is checked to notice a scene without fur and fur built for
//! the wrong depth convention.

use crate::common;
#[path = "../examples/embed/scene.rs"]
mod scene;

use common::{check_golden, gpu, matches_golden, pixel_difference};
use scene::{Scene, SceneOptions};

const SIZE: (u32, u32) = (256, 192);

fn screenshot(options: SceneOptions) -> image::RgbaImage {
    let gpu = gpu();
    let mut scene =
        Scene::new(&gpu.device, &gpu.queue, wgpu::TextureFormat::Rgba8UnormSrgb, options).expect("the scene");
    scene.advance(&gpu.device, &gpu.queue, 1.0).expect("simulation");
    scene.screenshot(&gpu.device, &gpu.queue, SIZE, 30.0).expect("screenshot")
}

#[test]
fn golden_embed() {
    check_golden("embed", &screenshot(SceneOptions::default()));
}

#[test]
fn the_golden_notices_missing_fur_and_the_wrong_depth_test() {
    let no_fur = screenshot(SceneOptions { fur: false, ..SceneOptions::default() });
    assert!(!matches_golden("embed", &no_fur), "a scene without fur passed the golden test");
    // A host that forgot `reverse_z()`: the fur tests `LessEqual` against a buffer cleared to 0.
    let conventional =
        screenshot(SceneOptions { fur_depth_compare: wgpu::CompareFunction::LessEqual, ..SceneOptions::default() });
    assert!(!matches_golden("embed", &conventional), "fur with the wrong depth test passed the golden test");
    // Fur that ignores the host's depth is drawn over the box in front of it.
    let always =
        screenshot(SceneOptions { fur_depth_compare: wgpu::CompareFunction::Always, ..SceneOptions::default() });
    assert!(!matches_golden("embed", &always), "fur drawn through the box passed the golden test");
}

/// Depth is shared both ways: the box hides the fur behind it (those pixels are the bare scene's),
/// and the fur hides the ground behind it (many pixels differ from the bare scene).
#[test]
fn fur_and_host_geometry_hide_each_other() {
    let with_fur = screenshot(SceneOptions::default());
    let bare = screenshot(SceneOptions { fur: false, ..SceneOptions::default() });
    let always =
        screenshot(SceneOptions { fur_depth_compare: wgpu::CompareFunction::Always, ..SceneOptions::default() });
    let changed = |a: &image::RgbaImage, b: &image::RgbaImage| {
        a.pixels().zip(b.pixels()).filter(|(p, q)| pixel_difference(p, q) > 24).count()
    };
    let fur_pixels = changed(&with_fur, &bare);
    assert!(fur_pixels > 3000, "the fur covers the ground: {fur_pixels} pixels");
    // Box pixels of the bare scene (the box is the only red thing) where fur drawn through
    // everything shows: the fur behind the box. With the depth test they show the bare box.
    let is_box = |p: &image::Rgba<u8>| p.0[0] > p.0[1].saturating_add(50);
    let hidden: Vec<(u32, u32)> = always
        .enumerate_pixels()
        .filter(|(x, y, p)| is_box(bare.get_pixel(*x, *y)) && pixel_difference(p, bare.get_pixel(*x, *y)) > 24)
        .map(|(x, y, _)| (x, y))
        .collect();
    assert!(hidden.len() > 400, "the box hides part of the fur: {} pixels", hidden.len());
    let box_shown =
        hidden.iter().filter(|&&(x, y)| pixel_difference(with_fur.get_pixel(x, y), bare.get_pixel(x, y)) <= 24).count();
    assert!(
        box_shown * 10 >= hidden.len() * 9,
        "where the box hides the fur it shows the bare box: {box_shown} of {}",
        hidden.len()
    );
}
