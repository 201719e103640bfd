//! The harness the profiling examples share: their environment variables, the GPU with its
//! offscreen targets, the bunny's shells as raw buffers for the experiments' own pipelines, and
//! frames timed one by one (each submitted and waited for) after a warm-up frame.

// Each example uses the part of the harness it needs.
#![allow(dead_code)]

use std::str::FromStr;
use std::time::Instant;

use glam::{Mat4, Vec3};
use pelt_core::{Builtin, FurStructure, Preset};
use pelt_render::{Backend, Camera, DEFAULT_BACKGROUND, FurTarget, Gpu, RenderTargets, default_sample_count};
use wgpu::util::DeviceExt;

/// `name` parsed, or `default` when it is unset or does not parse.
pub fn env_number<T: FromStr>(name: &str, default: T) -> T {
    std::env::var(name).ok().and_then(|s| s.trim().parse().ok()).unwrap_or(default)
}

/// `FRAMES`: timed frames per variant (at least one), or `default`.
pub fn env_frames(default: usize) -> usize {
    env_number("FRAMES", default).max(1)
}

/// `name` as a comma-separated list (entries that do not parse are dropped), or `default` when
/// it is unset.
pub fn env_list<T: FromStr + Clone>(name: &str, default: &[T]) -> Vec<T> {
    match std::env::var(name) {
        Ok(list) => list.split(',').filter_map(|item| item.trim().parse().ok()).collect(),
        Err(_) => default.to_vec(),
    }
}

/// `SIZES=256x256,64x64`: the frame sizes (entries that do not parse are dropped), or `default`.
pub fn env_sizes(default: &[(u32, u32)]) -> Vec<(u32, u32)> {
    match std::env::var("SIZES") {
        Ok(list) => list
            .split(',')
            .filter_map(|size| size.split_once('x'))
            .filter_map(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
            .collect(),
        Err(_) => default.to_vec(),
    }
}

/// The names a comma-separated variable picks (`CASES`, `VARIANTS`); all of them when unset.
#[derive(Debug)]
pub struct Chosen(Option<Vec<String>>);

impl Chosen {
    pub fn from_env(name: &str) -> Self {
        Self(std::env::var(name).ok().map(|s| s.split(',').map(|c| c.trim().to_owned()).collect()))
    }

    pub fn includes(&self, name: &str) -> bool {
        self.0.as_ref().is_none_or(|chosen| chosen.iter().any(|c| c == name))
    }
}

/// The GPU a profile runs on, and the sample count its frames use.
#[derive(Debug)]
pub struct Profile {
    pub gpu: Gpu,
    /// `MSAA=1` (or 2, 4, 8) overrides the adapter's default.
    pub samples: u32,
}

impl Profile {
    /// Opens the best adapter, as `pelt` does.
    pub fn open() -> anyhow::Result<Self> {
        let gpu = Gpu::new(Backend::Auto)?;
        let samples = env_number("MSAA", default_sample_count(&gpu.adapter.get_info()));
        Ok(Self { gpu, samples })
    }

    pub fn device(&self) -> &wgpu::Device {
        &self.gpu.device
    }

    pub fn queue(&self) -> &wgpu::Queue {
        &self.gpu.queue
    }

    /// The adapter, its backend and the sample count, for the report's first line.
    pub fn describe(&self) -> String {
        let info = self.gpu.adapter.get_info();
        format!("{} ({:?}), {}x MSAA", info.name, info.backend, self.samples)
    }

    /// A headless target of `format` at the profile's sample count.
    pub fn target(&self, format: wgpu::TextureFormat) -> FurTarget {
        FurTarget::new(format).with_sample_count(self.samples)
    }

    /// Wall milliseconds of one frame: a new encoder filled by `record`, submitted and waited for.
    pub fn time_frame(
        &self,
        record: impl FnOnce(&mut wgpu::CommandEncoder) -> anyhow::Result<()>,
    ) -> anyhow::Result<f64> {
        let started = Instant::now();
        let mut encoder = self.device().create_command_encoder(&Default::default());
        record(&mut encoder)?;
        self.queue().submit([encoder.finish()]);
        self.device().poll(wgpu::PollType::wait_indefinitely())?;
        Ok(started.elapsed().as_secs_f64() * 1000.0)
    }
}

/// The attachments of one frame size and the single-sample texture the frames resolve into.
#[derive(Debug)]
pub struct Offscreen {
    targets: RenderTargets,
    output: wgpu::TextureView,
}

impl Offscreen {
    pub fn new(device: &wgpu::Device, target: FurTarget, width: u32, height: u32) -> anyhow::Result<Self> {
        let targets = RenderTargets::new(device, target, width, height)?;
        let output = device.create_texture(&wgpu::TextureDescriptor {
            label: None,
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: target.colour_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            view_formats: &[],
        });
        Ok(Self { targets, output: output.create_view(&Default::default()) })
    }

    pub fn aspect_ratio(&self) -> f32 {
        self.targets.aspect_ratio()
    }

    /// A pass clearing to Pelt's background, resolving into the output texture.
    pub fn begin_pass<'e>(&self, encoder: &'e mut wgpu::CommandEncoder) -> wgpu::RenderPass<'e> {
        self.targets.begin_pass(encoder, &self.output, DEFAULT_BACKGROUND)
    }
}

/// The camera every profile frames its fur with: the base's bounding sphere grown by the longest
/// strand, from 35 degrees round and 20 up.
pub fn framing_camera(fur: &FurStructure, aspect_ratio: f32) -> Camera {
    let (centre, radius) = fur.mesh.bounding_sphere();
    let radius = radius + fur.lengths.iter().copied().fold(0.0, f32::max);
    Camera::framing(centre, radius, 35.0, 20.0, aspect_ratio)
}

/// `builtin` with the default preset's fur at `layers` shells.
pub fn fur(builtin: Builtin, layers: u32) -> anyhow::Result<(FurStructure, Preset)> {
    let mesh = builtin.mesh().0;
    let mut preset = Preset::default();
    preset.layers = layers;
    let fur = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh))?;
    Ok((fur, preset))
}

/// `values` as native-endian `f32` triples, or quadruples ending in 1 when `padded`.
pub fn vec3_bytes(values: &[Vec3], padded: bool) -> Vec<u8> {
    let mut out = Vec::with_capacity(values.len() * if padded { 16 } else { 12 });
    for v in values {
        for c in v.to_array() {
            out.extend_from_slice(&c.to_ne_bytes());
        }
        if padded {
            out.extend_from_slice(&1.0f32.to_ne_bytes());
        }
    }
    out
}

pub fn buffer(device: &wgpu::Device, label: &str, contents: &[u8], usage: wgpu::BufferUsages) -> wgpu::Buffer {
    device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
}

/// The WGSL both experiments start with (`profile/shells.wgsl`): their uniform and positions.
const SHELLS_WGSL: &str = include_str!("shells.wgsl");

/// A shader module of [`SHELLS_WGSL`] followed by `body`.
pub fn shells_shader(device: &wgpu::Device, label: &str, body: &str) -> wgpu::ShaderModule {
    device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(format!("{SHELLS_WGSL}\n{body}").into()),
    })
}

/// The bunny's shells as the experiments draw them with pipelines of their own: its positions
/// (`(L + 1) * V` packed `f32` triples, layer-major), triangles and the uniform of
/// `shells.wgsl`.
#[derive(Debug)]
pub struct Shells {
    pub fur: FurStructure,
    pub positions: wgpu::Buffer,
    pub indices: wgpu::Buffer,
    pub index_count: u32,
    pub uniform: wgpu::Buffer,
}

impl Shells {
    /// `LAYERS` (default 16) shells of the bunny; the positions buffer has `position_usage`.
    pub fn bunny(device: &wgpu::Device, position_usage: wgpu::BufferUsages) -> anyhow::Result<Self> {
        let (fur, _) = fur(Builtin::Bunny, env_number("LAYERS", 16))?;
        let positions = buffer(device, "positions", &vec3_bytes(&fur.positions, false), position_usage);
        let indices: Vec<u8> = fur.mesh.triangles.iter().flatten().flat_map(|i| i.to_ne_bytes()).collect();
        let indices = buffer(device, "indices", &indices, wgpu::BufferUsages::INDEX);
        let index_count = 3 * fur.mesh.triangles.len() as u32;
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("uniforms"),
            size: 80,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Ok(Self { fur, positions, indices, index_count, uniform })
    }

    pub fn vertex_count(&self) -> u32 {
        self.fur.mesh.vertex_count() as u32
    }

    pub fn layers(&self) -> u32 {
        self.fur.layers
    }

    /// Writes the uniform for the framing camera at `aspect_ratio`.
    pub fn write_uniform(&self, queue: &wgpu::Queue, aspect_ratio: f32) {
        let clip_from_world: Mat4 = framing_camera(&self.fur, aspect_ratio).clip_from_world(aspect_ratio);
        let mut data = Vec::with_capacity(80);
        for c in clip_from_world.to_cols_array() {
            data.extend_from_slice(&c.to_ne_bytes());
        }
        data.extend_from_slice(&self.vertex_count().to_ne_bytes());
        data.extend_from_slice(&self.layers().to_ne_bytes());
        // Tiles per world unit (the texture coordinates' scale), then padding.
        data.extend_from_slice(&4.0f32.to_ne_bytes());
        data.extend_from_slice(&0u32.to_ne_bytes());
        queue.write_buffer(&self.uniform, 0, &data);
    }

    /// Every shell in one draw, instance `k` being layer `k + 1`.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>) {
        pass.set_index_buffer(self.indices.slice(..), wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..self.index_count, 0, 0..self.layers());
    }
}

pub fn uniform_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

pub fn storage_entry(binding: u32, visibility: wgpu::ShaderStages) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

pub fn pipeline_layout(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> wgpu::PipelineLayout {
    device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    })
}

/// One experimental shell pipeline into `target`: back faces culled, depth tested, and either
/// opaque (depth written) or blended as the product's shells are (premultiplied, no depth write).
#[derive(Debug)]
pub struct ShellPipeline<'a> {
    pub layout: &'a wgpu::PipelineLayout,
    pub module: &'a wgpu::ShaderModule,
    pub vertex: &'a str,
    pub fragment: &'a str,
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
    pub blend: bool,
}

impl ShellPipeline<'_> {
    pub fn create(&self, device: &wgpu::Device, target: FurTarget, label: &str) -> wgpu::RenderPipeline {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(label),
            layout: Some(self.layout),
            vertex: wgpu::VertexState {
                module: self.module,
                entry_point: Some(self.vertex),
                compilation_options: Default::default(),
                buffers: self.buffers,
            },
            primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: target.depth_format,
                depth_write_enabled: Some(!self.blend),
                depth_compare: Some(target.depth_compare),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState { count: target.sample_count, ..Default::default() },
            fragment: Some(wgpu::FragmentState {
                module: self.module,
                entry_point: Some(self.fragment),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target.colour_format,
                    blend: self.blend.then_some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    }
}

/// One variant's frame times in milliseconds, in the order they were taken.
#[derive(Clone, Debug, Default)]
pub struct Times(pub Vec<f64>);

impl Times {
    fn sorted(&self) -> Vec<f64> {
        let mut times = self.0.clone();
        times.sort_by(f64::total_cmp);
        times
    }

    /// The median (the upper one of an even count).
    pub fn median(&self) -> f64 {
        let times = self.sorted();
        times[times.len() / 2]
    }

    pub fn min(&self) -> f64 {
        self.sorted()[0]
    }
}

/// `frames` frames of one variant in a row, after one warm-up frame; `frame` draws one and
/// returns its milliseconds ([`Profile::time_frame`]).
pub fn in_a_row(frames: usize, mut frame: impl FnMut() -> anyhow::Result<f64>) -> anyhow::Result<Times> {
    frame()?;
    (0..frames).map(|_| frame()).collect::<anyhow::Result<_>>().map(Times)
}

/// `frames` frames of each of `count` variants after one warm-up frame each, interleaved
/// (A B C A B C ...) so that load changes hit all of them; `frame(i)` draws variant `i` once and
/// returns its milliseconds.
pub fn interleaved(
    count: usize,
    frames: usize,
    mut frame: impl FnMut(usize) -> anyhow::Result<f64>,
) -> anyhow::Result<Vec<Times>> {
    let mut times = vec![Times::default(); count];
    for round in 0..frames + 1 {
        for (variant, variant_times) in times.iter_mut().enumerate() {
            let ms = frame(variant)?;
            if round > 0 {
                variant_times.0.push(ms);
            }
        }
    }
    Ok(times)
}

/// `rounds` rounds of [`interleaved`] frames of the variants `names`, each round reported as
/// `{size} round {r}: {name} median {ms} ms (min {ms})`, names padded to `name_width`.
pub fn interleaved_rounds(
    size: &str,
    rounds: usize,
    frames: usize,
    names: &[&str],
    name_width: usize,
    mut frame: impl FnMut(usize) -> anyhow::Result<f64>,
) -> anyhow::Result<()> {
    for round in 0..rounds {
        let times = interleaved(names.len(), frames, &mut frame)?;
        for (name, times) in names.iter().zip(times) {
            println!(
                "{size} round {round}: {name:name_width$} median {:7.2} ms (min {:.2})",
                times.median(),
                times.min()
            );
        }
    }
    Ok(())
}
