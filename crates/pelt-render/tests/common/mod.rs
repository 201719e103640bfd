//! Test helpers: a small procedural strand texture (the real generator lives in pelt-core's
//! presets; this one only has to look like strands), scenes and image comparison.

#![allow(dead_code, reason = "each test binary uses a different part of the helpers")]

use std::path::{Path, PathBuf};

use glam::Vec3;
use pelt_core::fur::FurLength;
use pelt_core::preset::{ShadingModel, ShadingParams};
use pelt_core::sim::{SimParams, Simulation, WindParams};
use pelt_core::texture::FurTextures;
use pelt_core::{Builtin, FurParams, FurStructure, GrowthDirection, Mesh};
use pelt_render::{
    Backend, Camera, DEFAULT_BACKGROUND, FurDrawSettings, FurFrame, FurLook, FurRenderer, FurShading, FurStates,
    FurView, Gpu, GpuFur, Headless, Light, PlainMesh, Studio,
};

fn hash(x: u32, y: u32, salt: u32) -> u32 {
    let mut h = x.wrapping_mul(0x8da6_b343) ^ y.wrapping_mul(0xd816_3841) ^ salt.wrapping_mul(0xcb1a_b31f);
    h = (h ^ (h >> 15)).wrapping_mul(0x2c1b_3c6d);
    h ^ (h >> 12)
}

fn unit(x: u32, y: u32, salt: u32) -> f32 {
    (hash(x, y, salt) & 0xffff) as f32 / 65536.0
}

/// Shell slices with round strands that taper and lean, plus a matching fin texture.
pub fn strand_textures(size: u32, layers: u32, root: [u8; 3], tip: [u8; 3]) -> FurTextures {
    let mut shell = vec![0_u8; (size * size * layers * 4) as usize];
    // Each texel's keep value for a groom's density: its strand's, or its own where empty.
    let mut strand_keep: Vec<u8> =
        (0..size * size * layers).map(|k| (unit(k, 0, 6) * 255.0).min(254.0) as u8).collect();
    let mut fin_columns = Vec::new();
    for y in 0..size {
        for x in 0..size {
            if unit(x, y, 1) > 0.22 {
                continue;
            }
            let length = 0.7 + 0.3 * unit(x, y, 2);
            let lean = (unit(x, y, 3) - 0.5, unit(x, y, 4) - 0.5);
            // The fin shows a thin slab of the tile from the side.
            if y < size / 12 {
                fin_columns.push((x, length));
            }
            for k in 0..layers {
                let t = (k + 1) as f32 / layers as f32;
                if t > length {
                    break;
                }
                let radius = 1.3 * (1.0 - 0.6 * t / length);
                let (cx, cy) = (x as f32 + lean.0 * 3.0 * t, y as f32 + lean.1 * 3.0 * t);
                let colour = |c: usize| (f32::from(root[c]) + (f32::from(tip[c]) - f32::from(root[c])) * t) as u8;
                for dy in -2..=2 {
                    for dx in -2..=2 {
                        let (px, py) = (cx.round() as i32 + dx, cy.round() as i32 + dy);
                        let distance = ((px as f32 - cx).powi(2) + (py as f32 - cy).powi(2)).sqrt();
                        let alpha = (radius - distance + 0.5).clamp(0.0, 1.0);
                        if alpha <= 0.0 {
                            continue;
                        }
                        let (px, py) = (px.rem_euclid(size as i32) as u32, py.rem_euclid(size as i32) as u32);
                        let k4 = ((k * size * size + py * size + px) * 4) as usize;
                        let a = (alpha * 255.0) as u8;
                        if a > shell[k4 + 3] {
                            shell[k4..k4 + 4].copy_from_slice(&[colour(0), colour(1), colour(2), a]);
                            strand_keep[k4 / 4] = (unit(x, y, 5) * 255.0).min(254.0) as u8;
                        }
                    }
                }
            }
        }
    }
    let (fin_width, fin_height) = (size, 32);
    let mut fin = vec![0_u8; (fin_width * fin_height * 4) as usize];
    for (x, length) in fin_columns {
        for row in 0..fin_height {
            // Row 0 holds the tips.
            let t = 1.0 - (row as f32 + 0.5) / fin_height as f32;
            if t > length {
                continue;
            }
            let colour = |c: usize| (f32::from(root[c]) + (f32::from(tip[c]) - f32::from(root[c])) * t) as u8;
            // Two texels wide at the root, one at the tip.
            let width = if t < 0.5 * length { 2 } else { 1 };
            for dx in 0..width {
                let k = ((row * fin_width + (x + dx) % fin_width) * 4) as usize;
                fin[k..k + 4].copy_from_slice(&[colour(0), colour(1), colour(2), 230]);
            }
        }
    }
    FurTextures {
        size,
        layers,
        shell,
        fin_width,
        fin_height,
        fin,
        strand_keep,
        strand_tilt: Vec::new(),
        surface: None,
        lean: Default::default(),
    }
}

pub const BROWN_ROOT: [u8; 3] = [70, 45, 28];
pub const BROWN_TIP: [u8; 3] = [200, 160, 120];

/// Fur of `length_fraction` of the bounding radius on `mesh`.
pub fn grow(mesh: Mesh, layers: u32, length_fraction: f32) -> FurStructure {
    let radius = mesh.bounding_sphere().1;
    let params = FurParams {
        layers,
        length: FurLength::Constant(radius * length_fraction),
        direction: GrowthDirection::default(),
    };
    FurStructure::new(mesh, &params).expect("valid fur")
}

pub fn builtin_fur(builtin: Builtin, layers: u32) -> FurStructure {
    grow(builtin.mesh().0, layers, 0.08)
}

/// The GPU every GPU test uses (`PELT_TEST_BACKEND` picks the API): fails (never skips)
/// without an adapter.
pub fn gpu() -> Gpu {
    let backend = std::env::var("PELT_TEST_BACKEND").map_or(Backend::Auto, |name| name.parse().expect("backend"));
    match Gpu::new(backend) {
        Ok(gpu) => gpu,
        Err(error) => panic!("GPU tests need an adapter (CI uses lavapipe): {error}"),
    }
}

/// The headless target every GPU test uses: fails (never skips) without an adapter.
pub fn headless(width: u32, height: u32) -> Headless {
    Headless::with_gpu(gpu(), width, height).expect("headless target")
}

/// The paper's look: Kajiya-Kay, which goes with the rig's light that follows the camera. Tests of
/// what is not shading (fins, levels, grooms, colliders) draw in it; Pelt's look is
/// [`Rig::render_in_studio`]'s.
pub fn paper_look() -> FurLook {
    let params = ShadingParams { model: ShadingModel::KajiyaKay, ..ShadingParams::default() };
    FurLook { shading: FurShading::from_params(&params), ..FurLook::default() }
}

/// [`FurFrame::default`] in [`paper_look`].
pub fn paper_frame() -> FurFrame {
    FurFrame { look: paper_look(), ..FurFrame::default() }
}

/// A headless target with a renderer for it and one view: what most GPU tests draw with.
pub struct Rig {
    pub headless: Headless,
    pub renderer: FurRenderer,
    pub view: FurView,
}

impl Rig {
    pub fn new(width: u32, height: u32) -> Self {
        let headless = headless(width, height);
        let renderer = headless.renderer().expect("renderer");
        let view = FurView::new(&headless.gpu.device, &renderer);
        Self { headless, renderer, view }
    }

    pub fn device(&self) -> &wgpu::Device {
        &self.headless.gpu.device
    }

    pub fn queue(&self) -> &wgpu::Queue {
        &self.headless.gpu.queue
    }

    /// The rest pose of `structure`, one state, in the paper's look ([`paper_frame`]).
    pub fn fur(&self, structure: &FurStructure, textures: &FurTextures) -> GpuFur {
        self.fur_with_states(structure, textures, FurStates::One)
    }

    pub fn fur_with_states(&self, structure: &FurStructure, textures: &FurTextures, states: FurStates) -> GpuFur {
        let fur = GpuFur::new(self.device(), self.queue(), &self.renderer, structure, textures, states).expect("fur");
        fur.prepare(self.queue(), &paper_frame());
        fur
    }

    /// One frame of `fur` in Pelt's look: [`FurFrame::default`] (the fur model) lit by
    /// [`Studio::default`] (its key light fixed in the world, the sky-ground fill; no shadows,
    /// which a host adds).
    pub fn render_in_studio(&self, fur: &GpuFur, camera: &Camera, settings: &FurDrawSettings) -> image::RgbaImage {
        self.render_frame_in_studio(fur, &FurFrame::default(), camera, settings)
    }

    /// [`Rig::render_in_studio`] with `frame` (its look, level, transform) instead of the default.
    pub fn render_frame_in_studio(
        &self,
        fur: &GpuFur,
        frame: &FurFrame,
        camera: &Camera,
        settings: &FurDrawSettings,
    ) -> image::RgbaImage {
        fur.prepare(self.queue(), frame);
        let studio = Studio::default();
        self.view.prepare(self.queue(), &studio.view_data(camera, self.headless.aspect_ratio()));
        self.headless
            .render(studio.background, |pass| self.renderer.draw(pass, &self.view, fur, settings))
            .expect("frame")
    }

    pub fn plain(&self, mesh: &Mesh, colour: Vec3) -> PlainMesh {
        let plain = PlainMesh::new(self.device(), &self.renderer, mesh, colour).expect("plain mesh");
        plain.prepare(self.queue(), glam::Mat4::IDENTITY);
        plain
    }

    /// One frame: the plain meshes, then the fur, from `camera` with the paper's light (following
    /// the camera, [`Light::default`]).
    pub fn render_scene(
        &self,
        plain: &[&PlainMesh],
        fur: Option<&GpuFur>,
        camera: &Camera,
        settings: &FurDrawSettings,
    ) -> image::RgbaImage {
        self.view.prepare(self.queue(), &camera.view_data(self.headless.aspect_ratio(), &Light::default()));
        self.headless
            .render(DEFAULT_BACKGROUND, |pass| {
                for mesh in plain {
                    self.renderer.draw_plain(pass, &self.view, mesh);
                }
                if let Some(fur) = fur {
                    self.renderer.draw(pass, &self.view, fur, settings);
                }
            })
            .expect("frame")
    }

    pub fn render(&self, fur: &GpuFur, camera: &Camera, settings: &FurDrawSettings) -> image::RgbaImage {
        self.render_scene(&[], Some(fur), camera, settings)
    }

    /// One frame of the fur with the silhouette pass recorded before the render pass, as
    /// Pelt's commands draw it.
    pub fn render_silhouette(&self, fur: &GpuFur, camera: &Camera, settings: &FurDrawSettings) -> image::RgbaImage {
        self.render_silhouettes(&[fur], camera, settings, false)
    }

    /// One frame of `furs` with silhouette fins, their listings recorded in one compute pass
    /// (`FurRenderer::prepare_fins_of`, as a herd records them) or each in its own.
    pub fn render_silhouettes(
        &self,
        furs: &[&GpuFur],
        camera: &Camera,
        settings: &FurDrawSettings,
        one_pass: bool,
    ) -> image::RgbaImage {
        self.view.prepare(self.queue(), &camera.view_data(self.headless.aspect_ratio(), &Light::default()));
        let settings = FurDrawSettings { silhouette_fins: true, ..*settings };
        self.headless
            .render_with(
                DEFAULT_BACKGROUND,
                |encoder| {
                    if one_pass {
                        self.renderer.prepare_fins_of(encoder, &self.view, furs.iter().copied());
                    } else {
                        for fur in furs {
                            self.renderer.prepare_fins(encoder, &self.view, fur);
                        }
                    }
                },
                |pass| {
                    for fur in furs {
                        self.renderer.draw(pass, &self.view, fur, &settings);
                    }
                },
            )
            .expect("frame")
    }

    /// The `u32`s of a small range of a `COPY_SRC` buffer, read back (waits for the GPU).
    pub fn read_u32s(&self, buffer: wgpu::BufferSlice<'_>) -> Vec<u32> {
        let bytes = read_bytes(self.device(), self.queue(), buffer);
        bytes.chunks_exact(4).map(|w| u32::from_le_bytes([w[0], w[1], w[2], w[3]])).collect()
    }

    /// The background as stored in the image (sRGB of the default clear colour).
    pub fn background(&self) -> [u8; 3] {
        let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 1.0);
        let empty = self.render_scene(&[], None, &camera, &FurDrawSettings::ALL);
        let p = empty.get_pixel(0, 0).0;
        [p[0], p[1], p[2]]
    }
}

/// The bytes of a range of a `COPY_SRC` buffer, read back after everything submitted before
/// (waits for the GPU).
pub fn read_bytes(device: &wgpu::Device, queue: &wgpu::Queue, buffer: wgpu::BufferSlice<'_>) -> Vec<u8> {
    let staging = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("test readback"),
        size: buffer.size(),
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    encoder.copy_buffer_to_buffer(buffer.buffer(), buffer.offset(), &staging, 0, buffer.size());
    queue.submit([encoder.finish()]);
    staging.slice(..).map_async(wgpu::MapMode::Read, |result| result.expect("map"));
    device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
    staging.slice(..).get_mapped_range().expect("mapped").to_vec()
}

pub fn framed(fur: &FurStructure, aspect_ratio: f32) -> Camera {
    let (centre, radius) = fur.mesh.bounding_sphere();
    let length = fur.lengths.iter().copied().fold(0.0, f32::max);
    Camera::framing(centre, radius + length, 30.0, 15.0, aspect_ratio)
}

pub fn settings() -> FurDrawSettings {
    FurDrawSettings::ALL
}

pub fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes").join(name)
}

pub fn out_dir() -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("pelt-render");
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

/// Whether a pixel differs from the background (anything drawn).
pub fn covered(pixel: &image::Rgba<u8>, background: [u8; 3]) -> bool {
    pixel.0[..3].iter().zip(background).any(|(a, b)| a.abs_diff(b) > 6)
}

/// Per-pixel difference: the largest channel difference.
pub fn pixel_difference(a: &image::Rgba<u8>, b: &image::Rgba<u8>) -> u8 {
    a.0.iter().zip(b.0).map(|(x, y)| x.abs_diff(y)).max().unwrap_or(0)
}

/// Golden images live beside the tests and were rendered on lavapipe (Vulkan, CPU).
///
/// The comparison allows small differences: llvmpipe (GL) and hardware GPUs place MSAA samples
/// and filter textures slightly differently, which moves strand edges by a fraction of a pixel.
/// Lavapipe reproduces its own references exactly.
const GOLDEN_MEAN_LIMIT: f64 = 3.0;
const GOLDEN_P99_LIMIT: u8 = 64;
/// The silhouette band (pixels within `SILHOUETTE_BAND_PX` of the golden image's outline) is
/// where fins draw; over the whole image a missing fringe averages away, so the band has a limit
/// of its own, on colour only.
const SILHOUETTE_BAND_PX: i64 = 4;
const GOLDEN_SILHOUETTE_MEAN_LIMIT: f64 = 2.0;

fn golden_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/golden")
}

/// How an image differs from its golden one.
pub struct GoldenDifference {
    /// Mean of the per-pixel difference (largest channel), whole image.
    pub mean: f64,
    /// 99th percentile of the same.
    pub p99: u8,
    /// Mean of the largest RGB difference over the golden image's silhouette band.
    pub silhouette_mean: f64,
    /// The difference, 4x brighter.
    pub image: image::RgbaImage,
}

impl GoldenDifference {
    pub fn within_limits(&self) -> bool {
        self.mean <= GOLDEN_MEAN_LIMIT
            && self.p99 <= GOLDEN_P99_LIMIT
            && self.silhouette_mean <= GOLDEN_SILHOUETTE_MEAN_LIMIT
    }
}

/// Pixels within `SILHOUETTE_BAND_PX` of a pixel whose coverage (differs from the corner
/// pixel, the background) differs from its own: both sides of every outline.
pub fn silhouette_band(image: &image::RgbaImage) -> Vec<(u32, u32)> {
    let corner = image.get_pixel(0, 0).0;
    let background = [corner[0], corner[1], corner[2]];
    let (width, height) = (i64::from(image.width()), i64::from(image.height()));
    let drawn: Vec<bool> = image.pixels().map(|p| covered(p, background)).collect();
    let at = |x: i64, y: i64| drawn[(y * width + x) as usize];
    let edge = |x: i64, y: i64| {
        [(1, 0), (0, 1)].iter().any(|&(dx, dy)| x + dx < width && y + dy < height && at(x, y) != at(x + dx, y + dy))
    };
    let mut band = vec![false; drawn.len()];
    let r = SILHOUETTE_BAND_PX;
    for y in 0..height {
        for x in 0..width {
            if !edge(x, y) {
                continue;
            }
            for by in (y - r).max(0)..=(y + r).min(height - 1) {
                for bx in (x - r).max(0)..=(x + r).min(width - 1) {
                    band[(by * width + bx) as usize] = true;
                }
            }
        }
    }
    (0..height)
        .flat_map(|y| (0..width).map(move |x| (x, y)))
        .filter(|&(x, y)| band[(y * width + x) as usize])
        .map(|(x, y)| (x as u32, y as u32))
        .collect()
}

/// How `image` differs from `tests/golden/{name}.png`.
pub fn golden_difference(name: &str, image: &image::RgbaImage) -> GoldenDifference {
    let path = golden_dir().join(format!("{name}.png"));
    let golden = image::open(&path)
        .unwrap_or_else(|error| panic!("{}: {error} (PELT_UPDATE_GOLDEN=1 writes it)", path.display()))
        .to_rgba8();
    assert_eq!(golden.dimensions(), image.dimensions(), "{name}: size");
    let mut differences: Vec<u8> = golden.pixels().zip(image.pixels()).map(|(a, b)| pixel_difference(a, b)).collect();
    let mean = differences.iter().map(|&d| f64::from(d)).sum::<f64>() / differences.len() as f64;
    let diff = image::RgbaImage::from_fn(image.width(), image.height(), |x, y| {
        let d = differences[(y * image.width() + x) as usize].saturating_mul(4);
        image::Rgba([d, d, d, 255])
    });
    differences.sort_unstable();
    let band = silhouette_band(&golden);
    let rgb = |a: &image::Rgba<u8>, b: &image::Rgba<u8>| {
        a.0[..3].iter().zip(&b.0[..3]).map(|(x, y)| x.abs_diff(*y)).max().unwrap_or(0)
    };
    let silhouette_mean =
        band.iter().map(|&(x, y)| f64::from(rgb(golden.get_pixel(x, y), image.get_pixel(x, y)))).sum::<f64>()
            / band.len().max(1) as f64;
    GoldenDifference { mean, p99: differences[differences.len() * 99 / 100], silhouette_mean, image: diff }
}

/// Whether `image` is within the golden limits of `tests/golden/{name}.png`.
pub fn matches_golden(name: &str, image: &image::RgbaImage) -> bool {
    golden_difference(name, image).within_limits()
}

/// Compares `image` with `tests/golden/{name}.png`; `PELT_UPDATE_GOLDEN=1` rewrites it. On a
/// mismatch writes `{name}-actual.png` and `{name}-diff.png` next to it and panics.
pub fn check_golden(name: &str, image: &image::RgbaImage) {
    let dir = golden_dir();
    let path = dir.join(format!("{name}.png"));
    if std::env::var("PELT_UPDATE_GOLDEN").is_ok_and(|v| v == "1") {
        std::fs::create_dir_all(&dir).expect("golden dir");
        image.save(&path).expect("write golden");
        return;
    }
    let difference = golden_difference(name, image);
    eprintln!(
        "{name}: mean {:.2}, 99th percentile {}, silhouette band mean {:.2}",
        difference.mean, difference.p99, difference.silhouette_mean
    );
    if !difference.within_limits() {
        image.save(dir.join(format!("{name}-actual.png"))).expect("write actual");
        difference.image.save(dir.join(format!("{name}-diff.png"))).expect("write diff");
        let GoldenDifference { mean, p99, silhouette_mean, .. } = difference;
        panic!(
            "{name}: differs from the golden image (mean {mean:.2} > {GOLDEN_MEAN_LIMIT}, 99th percentile {p99} > \
             {GOLDEN_P99_LIMIT} or silhouette band mean {silhouette_mean:.2} > {GOLDEN_SILHOUETTE_MEAN_LIMIT}); see \
             {name}-actual.png and {name}-diff.png in {}",
            dir.display()
        );
    }
}

/// Loads one of the repository's meshes.
pub fn load_asset(name: &str) -> Mesh {
    Mesh::load(&asset(name), &pelt_core::ImportOptions::default()).expect("asset mesh").0
}

/// The simulation with a steady wind along `direction` (no gusts or shake, so the pose is exact).
pub fn windy_simulation(fur: &FurStructure, direction: Vec3, strength: f32, frames: u32) -> Simulation {
    let wind = WindParams { direction, strength, gust_strength: 0.0, jitter: 0.0, ..WindParams::default() };
    let mut simulation = Simulation::new(fur, &SimParams { wind, ..SimParams::default() }).expect("simulation");
    for frame in 0..=frames {
        simulation.advance_to(f64::from(frame) / 30.0);
    }
    simulation
}

/// The wind of the `bunny-wind` golden image.
pub fn golden_wind(fur: &FurStructure) -> Simulation {
    windy_simulation(fur, Vec3::new(1.0, 0.0, 0.3), 1.5, 12)
}
