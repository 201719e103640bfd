//! The embed example's scene, as a host app would write it: its own ground and box drawn by its
//! own pipeline, its own camera with reverse-Z depth (`Depth32Float`, `Greater`, cleared to 0, an
//! infinite reverse perspective) and 4x MSAA, and Pelt's fur drawn into the same render pass,
//! hidden by and hiding the host's geometry through the shared depth buffer.
//!
//! `main.rs` shows it in a window or writes one frame (`--screenshot FILE`); `tests/embed.rs`
//! renders it for a golden image.

use glam::{Mat4, Vec3};
use pelt_core::sim::WindParams;
use pelt_core::sim::{FurStepper, SimParams};
use pelt_core::{Builtin, FurStructure, Preset};
use pelt_render::{
    FurDrawSettings, FurDriver, FurRenderer, FurTarget, FurView, KernelChoice, Light, LightDirection, ViewData,
};
use wgpu::util::DeviceExt as _;

/// The host's depth format and comparison: reverse-Z.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;
pub const DEPTH_COMPARE: wgpu::CompareFunction = wgpu::CompareFunction::Greater;
/// Reverse-Z clears to the far plane at 0.
const DEPTH_CLEAR: f32 = 0.0;
const SAMPLES: u32 = 4;
/// Linear RGB.
const SKY: wgpu::Color = wgpu::Color { r: 0.30, g: 0.42, b: 0.58, a: 1.0 };
const SUN: Vec3 = Vec3::new(-0.4, 0.8, 0.45);

type Error = Box<dyn std::error::Error>;

/// Knobs the golden test turns to check that it notices a broken scene.
#[derive(Clone, Copy, Debug)]
pub struct SceneOptions {
    /// Draw the fur at all.
    pub fur: bool,
    /// The depth comparison the fur's pipelines are built with (the host's own when right).
    pub fur_depth_compare: wgpu::CompareFunction,
}

impl Default for SceneOptions {
    fn default() -> Self {
        Self { fur: true, fur_depth_compare: DEPTH_COMPARE }
    }
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct HostVertex {
    position: Vec3,
    normal: Vec3,
    colour: Vec3,
}

#[repr(C)]
#[derive(Clone, Copy, bytemuck::Pod, bytemuck::Zeroable)]
struct HostCamera {
    clip_from_world: Mat4,
    light_direction: Vec3,
    padding: f32,
}

/// The host's MSAA colour and depth attachments for one size.
struct Attachments {
    size: (u32, u32),
    msaa: wgpu::TextureView,
    depth: wgpu::TextureView,
}

pub struct Scene {
    options: SceneOptions,
    colour_format: wgpu::TextureFormat,
    host_pipeline: wgpu::RenderPipeline,
    host_vertices: wgpu::Buffer,
    host_vertex_count: u32,
    host_camera: wgpu::Buffer,
    host_bind_group: wgpu::BindGroup,
    renderer: FurRenderer,
    /// The fur on the GPU, simulated on the CPU by `stepper`.
    fur: FurDriver,
    stepper: FurStepper,
    view: FurView,
    attachments: Option<Attachments>,
}

impl Scene {
    /// Builds the host's pipeline and geometry and Pelt's renderer and fur (a bunny on the ground,
    /// a box in front of it) for passes on `colour_format`.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        colour_format: wgpu::TextureFormat,
        options: SceneOptions,
    ) -> Result<Self, Error> {
        let (host_pipeline, host_camera, host_bind_group) = host_pipeline(device, colour_format);
        let vertices = host_geometry();
        let host_vertices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("host geometry"),
            contents: bytemuck::cast_slice(&vertices),
            usage: wgpu::BufferUsages::VERTEX,
        });

        // Pelt: pipelines for the host's attachments, one fur, one view.
        let target = FurTarget::new(colour_format).with_depth(DEPTH_FORMAT, options.fur_depth_compare);
        let renderer = FurRenderer::new(device, target)?;
        let (mesh, _) = Builtin::Bunny.mesh();
        let preset = Preset::default();
        let params = preset.fur_params(&mesh);
        let (low, high) = mesh.bounds();
        let structure = FurStructure::new(mesh, &params)?;
        let wind = WindParams { direction: Vec3::X, strength: 1.2, ..preset.simulation.wind.clone() };
        let simulation = SimParams { wind, ..preset.simulation.clone() };
        let textures = preset.generate_textures()?;
        let mut fur = FurDriver::new(device, queue, &renderer, &structure, &textures, &simulation, KernelChoice::Cpu)?;
        let mut stepper = FurStepper::new(&structure, &preset.simulation)?;
        stepper.simulation_mut().set_wind(&simulation.wind)?;
        let view = FurView::new(device, &renderer);
        // The bunny's model space (about 10 units long) to the host's world: 1 unit tall, feet
        // on the ground at the origin.
        let scale = 1.0 / (high.y - low.y);
        let foot = Vec3::new((low.x + high.x) * 0.5, low.y, (low.z + high.z) * 0.5);
        fur.set_world_from_model(Mat4::from_scale(Vec3::splat(scale)) * Mat4::from_translation(-foot));
        Ok(Self {
            options,
            colour_format,
            host_pipeline,
            host_vertices,
            host_vertex_count: vertices.len() as u32,
            host_camera,
            host_bind_group,
            renderer,
            fur,
            stepper,
            view,
            attachments: None,
        })
    }

    /// Steps the simulation to `time_secs` and uploads what the fur draws.
    pub fn advance(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, time_secs: f64) -> Result<(), Error> {
        self.fur.advance_to(device, queue, &mut self.stepper, time_secs)?;
        Ok(())
    }

    /// Records one frame into `output` (a `size` view of the scene's colour format), the camera
    /// `azimuth_deg` around the bunny.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        output: &wgpu::TextureView,
        size: (u32, u32),
        azimuth_deg: f32,
    ) {
        if self.attachments.as_ref().is_none_or(|a| a.size != size) {
            self.attachments = Some(attachments(device, self.colour_format, size));
        }
        // The host's camera: an infinite reverse-Z perspective.
        let aspect = size.0 as f32 / size.1.max(1) as f32;
        let target = Vec3::new(0.0, 0.4, 0.0);
        let (azimuth, elevation) = (azimuth_deg.to_radians(), 18_f32.to_radians());
        let eye =
            target + 3.0 * Vec3::new(azimuth.sin() * elevation.cos(), elevation.sin(), azimuth.cos() * elevation.cos());
        let view_from_world = glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Y);
        let clip_from_world =
            glam::camera::rh::proj::directx::perspective_infinite_reverse(38_f32.to_radians(), aspect, 0.05)
                * view_from_world;
        let light = Light { direction: LightDirection::World(SUN.normalize()), colour: Vec3::ONE, ambient: 0.3 };
        let camera = HostCamera { clip_from_world, light_direction: SUN.normalize(), padding: 0.0 };
        queue.write_buffer(&self.host_camera, 0, bytemuck::bytes_of(&camera));
        // Pelt's per-frame data: the view from the host's camera (the fur's was written by
        // `advance`).
        self.view.prepare(queue, &ViewData::new(clip_from_world, view_from_world.inverse(), &light));

        let Some(attachments) = &self.attachments else { return };
        // The silhouette pass goes into the host's encoder, before the pass that draws the fur.
        if self.options.fur {
            self.fur.record_view(encoder, &self.renderer, &self.view);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("host frame"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &attachments.msaa,
                depth_slice: None,
                resolve_target: Some(output),
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(SKY), store: wgpu::StoreOp::Discard },
            })],
            depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                view: &attachments.depth,
                depth_ops: Some(wgpu::Operations {
                    load: wgpu::LoadOp::Clear(DEPTH_CLEAR),
                    store: wgpu::StoreOp::Discard,
                }),
                stencil_ops: None,
            }),
            ..wgpu::RenderPassDescriptor::default()
        });
        // The host's opaque geometry first, then the fur into the same pass and depth.
        pass.set_pipeline(&self.host_pipeline);
        pass.set_bind_group(0, &self.host_bind_group, &[]);
        pass.set_vertex_buffer(0, self.host_vertices.slice(..));
        pass.draw(0..self.host_vertex_count, 0..1);
        if self.options.fur {
            self.fur.draw(&mut pass, &self.renderer, &self.view, &FurDrawSettings::SILHOUETTE);
        }
    }

    /// Renders one frame of `width x height` offscreen and reads it back (the scene must have been
    /// made for `Rgba8UnormSrgb`).
    pub fn screenshot(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        (width, height): (u32, u32),
        azimuth_deg: f32,
    ) -> Result<image::RgbaImage, Error> {
        if self.colour_format != wgpu::TextureFormat::Rgba8UnormSrgb {
            return Err("screenshots need a scene made for Rgba8UnormSrgb".into());
        }
        let texture = device.create_texture(&wgpu::TextureDescriptor {
            label: Some("screenshot"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: self.colour_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
        let row_bytes = (4 * width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let readback = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("screenshot readback"),
            size: u64::from(row_bytes) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        self.render(device, queue, &mut encoder, &view, (width, height), azimuth_deg);
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &readback,
                layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row_bytes), rows_per_image: None },
            },
            texture.size(),
        );
        queue.submit([encoder.finish()]);
        let slice = readback.slice(..);
        slice.map_async(wgpu::MapMode::Read, |_| {});
        device.poll(wgpu::PollType::wait_indefinitely())?;
        let pixels: Vec<u8> = slice
            .get_mapped_range()?
            .chunks_exact(row_bytes as usize)
            .flat_map(|row| row[..4 * width as usize].to_vec())
            .collect();
        image::RgbaImage::from_raw(width, height, pixels).ok_or_else(|| "the frame has the wrong size".into())
    }
}

fn host_pipeline(
    device: &wgpu::Device,
    colour_format: wgpu::TextureFormat,
) -> (wgpu::RenderPipeline, wgpu::Buffer, wgpu::BindGroup) {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("host scene"),
        source: wgpu::ShaderSource::Wgsl(include_str!("scene.wgsl").into()),
    });
    let camera = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("host camera"),
        size: size_of::<HostCamera>() as u64,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("host camera"),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::VERTEX_FRAGMENT,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        }],
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("host camera"),
        layout: &layout,
        entries: &[wgpu::BindGroupEntry { binding: 0, resource: camera.as_entire_binding() }],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("host scene"),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("host scene"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_main"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            buffers: &[Some(wgpu::VertexBufferLayout {
                array_stride: size_of::<HostVertex>() as u64,
                step_mode: wgpu::VertexStepMode::Vertex,
                attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x3],
            })],
        },
        primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..wgpu::PrimitiveState::default() },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(DEPTH_COMPARE),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState { count: SAMPLES, ..wgpu::MultisampleState::default() },
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_main"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            targets: &[Some(colour_format.into())],
        }),
        multiview_mask: None,
        cache: None,
    });
    (pipeline, camera, bind_group)
}

/// A ground square and a box in front of where the bunny sits, as counter-clockwise triangles.
fn host_geometry() -> Vec<HostVertex> {
    let mut vertices = Vec::new();
    let mut quad = |corners: [Vec3; 4], colour: Vec3| {
        let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize();
        for k in [0, 1, 2, 0, 2, 3] {
            vertices.push(HostVertex { position: corners[k], normal, colour });
        }
    };
    let g = 2.5;
    quad(
        [Vec3::new(-g, 0.0, g), Vec3::new(g, 0.0, g), Vec3::new(g, 0.0, -g), Vec3::new(-g, 0.0, -g)],
        Vec3::new(0.18, 0.22, 0.14),
    );
    let (centre, half) = (Vec3::new(0.15, 0.2, 0.75), Vec3::new(0.32, 0.2, 0.16));
    let colour = Vec3::new(0.55, 0.16, 0.1);
    for axis in 0..3 {
        for sign in [-1.0, 1.0] {
            let mut normal = Vec3::ZERO;
            normal[axis] = sign;
            // (u, v, normal) right-handed, so the corners below run counter-clockwise seen from outside.
            let u = normal.any_orthonormal_vector();
            let v = normal.cross(u);
            let corner = |a: f32, b: f32| centre + (normal + u * a + v * b) * half;
            quad([corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)], colour);
        }
    }
    vertices
}

fn attachments(device: &wgpu::Device, colour_format: wgpu::TextureFormat, size: (u32, u32)) -> Attachments {
    let create = |label, format| {
        device
            .create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: size.0.max(1), height: size.1.max(1), depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: SAMPLES,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            })
            .create_view(&wgpu::TextureViewDescriptor::default())
    };
    Attachments { size, msaa: create("host msaa colour", colour_format), depth: create("host depth", DEPTH_FORMAT) }
}
