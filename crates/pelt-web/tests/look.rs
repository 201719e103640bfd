//! One look for every host: the page's frame (its `PageGpu`, copied into a texture of the
//! canvas's format as into the browser's canvas) against `pelt render`'s (a `Headless` target of
//! `HEADLESS_FORMAT`, the preset's own textures, `Studio::default` and its shadows), same preset, camera, size and
//! simulated time, on lavapipe. The bunny's mean colour must agree, and `pelt render`'s must be
//! the one in `web/test/look.json`, which the browser test holds the real page to. The page's
//! key light, fixed in the world, casts the bunny's shadow on its ground.
//!
//! The measurements here read raw bytes and share no code with the renderer: a pixel is the
//! bunny's when it differs from its image's corner (the background) by more than `DRAWN`.

use glam::Vec3;
use pelt_core::sim::FurStepper;
use pelt_core::{FurStructure, Preset};
use pelt_render::{
    Backend, FurDrawSettings, FurDriver, FurTarget, FurView, Gpu, HEADLESS_FORMAT, Headless, KernelChoice, Studio,
    Surroundings, default_sample_count,
};
use pelt_web::light::PageLight;
use pelt_web::model::{Model, SceneChoice};
use pelt_web::page_gpu::{CANVAS_USAGE, PageGpu};
use pelt_web::presets;

/// The canvas of the browser test (its 720 x 400 viewport less the 250 px panel).
const WIDTH_PX: u32 = 470;
const HEIGHT_PX: u32 = 400;
/// Frames of simulated time before the picture (the fur settles under gravity).
const FRAMES: u32 = 30;
const FRAME_SECS: f64 = 1.0 / 30.0;
const CANVAS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
/// A channel further than this (of 255) from the background makes a pixel the bunny's.
const DRAWN: u8 = 12;
/// Largest difference of the bunny's mean colour between the two hosts, per channel (of 255).
/// The page's shell tile has a quarter of the texels (256 instead of 512, repeated twice as
/// often) and it draws with 4x MSAA where `pelt render` draws with 1 on lavapipe: here these
/// leave the means within 1 of each other. A page writing linear values into its canvas is 61
/// below on red, and its background 49.
const MEAN_BOUND: f32 = 5.0;

/// `web/test/look.json`: what the browser test expects of the page.
#[derive(serde::Deserialize)]
struct Look {
    canvas_px: [u32; 2],
    background: [u8; 3],
    bunny_mean: [f32; 3],
    drawn: u8,
    mean_bound: f32,
}

/// The GPU: fails, never skips, without an adapter (CI has lavapipe).
fn gpu() -> Gpu {
    let backend = std::env::var("PELT_TEST_BACKEND").map_or(Backend::Auto, |name| name.parse().expect("backend"));
    Gpu::new(backend).unwrap_or_else(|error| panic!("GPU tests need an adapter (CI uses lavapipe): {error}"))
}

/// The page's default bunny after `FRAMES` frames, drawn as the page draws into its canvas:
/// a texture of the headless Chromium's canvas format (`rgba8unorm`), as the page configures it.
fn page_frame(gpu: &Gpu, preset: &Preset, light: PageLight) -> (image::RgbaImage, Model) {
    let (device, queue) = (&gpu.device, &gpu.queue);
    let mut model = Model::new(SceneChoice::Bunny, preset.clone(), WIDTH_PX as f32 / HEIGHT_PX as f32).expect("model");
    model.light = light;
    let made = presets::web_textures(&model.preset).expect("web textures");
    let canvas = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("canvas"),
        size: wgpu::Extent3d { width: WIDTH_PX, height: HEIGHT_PX, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: CANVAS_FORMAT,
        usage: CANVAS_USAGE | wgpu::TextureUsages::COPY_SRC,
        view_formats: &[],
    });
    let mut page = PageGpu::new(device, queue, CANVAS_FORMAT, &model, &made.textures, made.tile_scale).expect("page");
    page.resize(device, WIDTH_PX, HEIGHT_PX).expect("size");
    for _ in 0..FRAMES {
        page.advance(device, queue, &mut model, FRAME_SECS).expect("advance");
    }
    page.render(device, queue, &model, &canvas).expect("render");
    (read_back(gpu, &canvas), model)
}

/// The same bunny, preset, camera and time as `pelt render` draws it (`--sim cpu --no-lod`).
fn render_frame(gpu: Gpu, preset: &Preset, model: &Model) -> image::RgbaImage {
    let samples = default_sample_count(&gpu.adapter.get_info());
    let target = FurTarget::new(HEADLESS_FORMAT).with_sample_count(samples);
    let headless = Headless::with_target(gpu, target, WIDTH_PX, HEIGHT_PX).expect("headless");
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer().expect("renderer");
    let structure =
        FurStructure::new(model.structure.mesh.clone(), &preset.fur_params(&model.structure.mesh)).expect("structure");
    let textures = preset.generate_textures().expect("textures");
    let mut driver =
        FurDriver::new(device, queue, &renderer, &structure, &textures, &preset.simulation, KernelChoice::Cpu)
            .expect("driver");
    let mut stepper = FurStepper::new(&structure, &preset.simulation).expect("stepper");
    for frame in 1..=FRAMES {
        driver.advance_to(device, queue, &mut stepper, f64::from(frame) * FRAME_SECS).expect("advance");
    }
    // Pelt's studio and its key light's shadows, as `pelt render` draws by default.
    let studio = Studio::default();
    let view_data = studio.view_data(&model.orbit.camera(), headless.aspect_ratio());
    let mut surroundings =
        Surroundings::new(device, queue, &renderer, true, None, (&structure, &[])).expect("shadow maps");
    surroundings.fit_to_frame(device, &renderer, (WIDTH_PX, HEIGHT_PX)).expect("fitted maps");
    let mut view = FurView::new(device, &renderer);
    view.prepare(queue, &view_data);
    surroundings.prepare((device, queue), &renderer, &view_data, &mut view).expect("aimed maps");
    headless
        .render_with(
            studio.background,
            |encoder| {
                driver.record_view(encoder, &renderer, &view);
                surroundings.record(encoder, |pass, light| driver.draw(pass, &renderer, light, &FurDrawSettings::ALL));
            },
            |pass| driver.draw(pass, &renderer, &view, &FurDrawSettings::SILHOUETTE),
        )
        .expect("frame")
}

fn read_back(gpu: &Gpu, texture: &wgpu::Texture) -> image::RgbaImage {
    let (width, height) = (texture.width(), texture.height());
    let row_bytes = (4 * width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
    let buffer = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("readback"),
        size: u64::from(row_bytes * height),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row_bytes), rows_per_image: None },
        },
        texture.size(),
    );
    gpu.queue.submit([encoder.finish()]);
    buffer.slice(..).map_async(wgpu::MapMode::Read, |result| result.expect("map"));
    gpu.device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    let mapped = buffer.slice(..).get_mapped_range().expect("mapped");
    let pixels =
        mapped.chunks_exact(row_bytes as usize).flat_map(|row| &row[..(4 * width) as usize]).copied().collect();
    image::RgbaImage::from_raw(width, height, pixels).expect("image")
}

/// The background (the top-left corner) and the mean colour of the pixels unlike it, with their count.
fn bunny_mean(image: &image::RgbaImage) -> ([u8; 3], Vec3, usize) {
    let background = image.get_pixel(0, 0).0;
    let background = [background[0], background[1], background[2]];
    let drawn: Vec<Vec3> = image
        .pixels()
        .filter(|p| (0..3).any(|c| p.0[c].abs_diff(background[c]) > DRAWN))
        .map(|p| Vec3::new(f32::from(p.0[0]), f32::from(p.0[1]), f32::from(p.0[2])))
        .collect();
    let mean = drawn.iter().sum::<Vec3>() / drawn.len().max(1) as f32;
    (background, mean, drawn.len())
}

#[test]
fn the_page_shows_the_default_bunny_as_pelt_render_does() {
    let gpu = gpu();
    let preset = Preset::default();
    let (page, model) = page_frame(&gpu, &preset, PageLight::default());
    let render = render_frame(gpu, &preset, &model);
    let output = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("look");
    std::fs::create_dir_all(&output).expect("output folder");
    page.save(output.join("page.png")).expect("page.png");
    render.save(output.join("render.png")).expect("render.png");

    let (page_background, page_mean, page_count) = bunny_mean(&page);
    let (render_background, render_mean, render_count) = bunny_mean(&render);
    let report = format!(
        "page: background {page_background:?}, bunny mean {page_mean:.1} over {page_count} pixels; \
         pelt render: background {render_background:?}, bunny mean {render_mean:.1} over {render_count} pixels \
         (images in {})",
        output.display()
    );
    println!("{report}");
    let difference = (page_mean - render_mean).abs().max_element();
    assert!(difference <= MEAN_BOUND, "the means differ by {difference:.1} (bound {MEAN_BOUND}): {report}");
    assert!(page_background.iter().zip(render_background).all(|(a, b)| a.abs_diff(b) <= 1), "{report}");
    let area = (WIDTH_PX * HEIGHT_PX) as usize;
    assert!(render_count > area / 10 && page_count > area / 10, "the bunny is hardly drawn: {report}");
    assert!(page_count.abs_diff(render_count) < render_count / 20, "the bunny covers different areas: {report}");

    // What the browser test holds the real page to stays `pelt render`'s picture.
    let look: Look = serde_json::from_str(include_str!("../../../web/test/look.json")).expect("look.json");
    assert_eq!((look.canvas_px, look.drawn), ([WIDTH_PX, HEIGHT_PX], DRAWN), "look.json measures another picture");
    let off = (Vec3::from(look.bunny_mean) - render_mean).abs().max_element();
    assert!(
        render_background == look.background && off <= look.mean_bound,
        "web/test/look.json says background {:?} and mean {:?}; update it to pelt render's: {report}",
        look.background,
        look.bunny_mean
    );
}

/// Pixels of the ground in `image`: grey (channels within 24 of each other, the fur is brown) and
/// not the background (the top-left corner's colour, which the ground does not reach).
fn ground_pixels(image: &image::RgbaImage) -> Vec<(u32, u32)> {
    let background = image.get_pixel(0, 0).0;
    image
        .enumerate_pixels()
        .filter(|(_, _, p)| {
            let [r, g, b, _] = p.0;
            let grey = r.max(g).max(b) - r.min(g).min(b) < 24;
            grey && (0..3).any(|c| p.0[c].abs_diff(background[c]) > DRAWN)
        })
        .map(|(x, y, _)| (x, y))
        .collect()
}

/// How many of `pixels` are darker in `after` than in `before` by more than 10 on every channel.
fn darker(pixels: &[(u32, u32)], before: &image::RgbaImage, after: &image::RgbaImage) -> usize {
    pixels
        .iter()
        .filter(|&&(x, y)| {
            let (a, b) = (before.get_pixel(x, y).0, after.get_pixel(x, y).0);
            (0..3).all(|c| i16::from(b[c]) < i16::from(a[c]) - 10)
        })
        .count()
}

/// The page's key light, fixed in the world, casts the bunny's shadow on the page's ground (and
/// on the fur), and moving the light moves the shadow. Without shadows passed to the frame
/// (tried once), no ground pixel darkens.
#[test]
fn the_pages_key_light_casts_the_bunnys_shadow_on_the_ground() {
    let gpu = gpu();
    let preset = Preset::default();
    let lit = |shadows: bool, azimuth: f32| {
        let mut light = PageLight::default();
        (light.shadows, light.ground) = (shadows, true);
        light.set(azimuth, 50.0).expect("angles");
        light
    };
    let (bare, _) = page_frame(&gpu, &preset, lit(false, 40.0));
    let (shadowed, _) = page_frame(&gpu, &preset, lit(true, 40.0));
    let (moved, _) = page_frame(&gpu, &preset, lit(true, 220.0));
    let output = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("look");
    std::fs::create_dir_all(&output).expect("output folder");
    for (name, image) in [("ground.png", &bare), ("shadow.png", &shadowed), ("shadow-moved.png", &moved)] {
        image.save(output.join(name)).expect(name);
    }

    let ground = ground_pixels(&bare);
    let area = (WIDTH_PX * HEIGHT_PX) as usize;
    let (shaded, lightened) = (darker(&ground, &bare, &shadowed), darker(&ground, &shadowed, &bare));
    let report = format!(
        "{} ground pixels; {shaded} darker with shadows, {lightened} lighter (images in {})",
        ground.len(),
        output.display()
    );
    println!("{report}");
    assert!(ground.len() > area / 10, "the ground is hardly drawn: {report}");
    assert!(shaded > area / 100, "the bunny's shadow does not darken the ground: {report}");
    assert!(lightened < shaded / 20, "shadows lightened the ground: {report}");
    // The light turned half round: its shadow falls on the other side.
    let (left, came) = (darker(&ground, &moved, &shadowed), darker(&ground, &shadowed, &moved));
    println!("the light turned: {left} ground pixels darkened where the shadow was, {came} where it went");
    assert!(left > area / 200 && came > area / 200, "the shadow did not move with the light: {left}, {came}");
}
