//! What does a shell triangle and a shell fragment cost on this adapter? The bunny's L shells
//! drawn with a growing number of interpolated components, with and without blending and a
//! texture sample (`shell_floor.wgsl`), frames interleaved across the variants. A profiling aid
//! for BENCHMARKS.md: `cargo run --release -p pelt --example shell_floor`
//! (`SIZES=256x256,1280x720 FRAMES=9 ROUNDS=3 LAYERS=16 VARIANTS=bare,sixteen`).

use std::time::Instant;

use glam::Vec3;
use pelt_core::{Builtin, FurStructure, Preset};
use pelt_render::{
    Backend, Camera, DEFAULT_BACKGROUND, FurTarget, Gpu, HEADLESS_FORMAT, RenderTargets, default_sample_count,
};
use wgpu::util::DeviceExt;

fn env_number(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

/// One variant: its name, vertex and fragment entries, whether it blends, and which texture.
struct Variant {
    name: &'static str,
    vertex: &'static str,
    fragment: &'static str,
    blend: bool,
    texture: usize,
}

const TEXTURE_SIZE: u32 = 256;

/// A noise texture with a full mip chain (or one level): the cost of sampling, not its look.
fn noise_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    format: wgpu::TextureFormat,
    mips: bool,
) -> wgpu::TextureView {
    let levels = if mips { TEXTURE_SIZE.ilog2() + 1 } else { 1 };
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("noise"),
        size: wgpu::Extent3d { width: TEXTURE_SIZE, height: TEXTURE_SIZE, depth_or_array_layers: 1 },
        mip_level_count: levels,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    let mut state = 0x2545_f491_u32;
    for level in 0..levels {
        let side = TEXTURE_SIZE >> level;
        let data: Vec<u8> = (0..side * side * 4)
            .map(|_| {
                state ^= state << 13;
                state ^= state >> 17;
                state ^= state << 5;
                (state >> 24) as u8
            })
            .collect();
        queue.write_texture(
            wgpu::TexelCopyTextureInfo {
                texture: &texture,
                mip_level: level,
                origin: wgpu::Origin3d::ZERO,
                aspect: wgpu::TextureAspect::All,
            },
            &data,
            wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(side * 4), rows_per_image: None },
            wgpu::Extent3d { width: side, height: side, depth_or_array_layers: 1 },
        );
    }
    texture.create_view(&Default::default())
}

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(Backend::Auto)?;
    let (device, queue) = (&gpu.device, &gpu.queue);
    let target = FurTarget::new(HEADLESS_FORMAT).with_sample_count(default_sample_count(&gpu.adapter.get_info()));
    let mesh = Builtin::Bunny.mesh().0;
    let mut preset = Preset::default();
    preset.layers = env_number("LAYERS", 16) as u32;
    let fur = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh))?;
    let vertex_count = fur.mesh.vertex_count() as u32;
    let layers = fur.layers;

    let bytes: Vec<u8> = fur.positions.iter().flat_map(|v: &Vec3| v.to_array()).flat_map(f32::to_ne_bytes).collect();
    let positions = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("positions"),
        contents: &bytes,
        usage: wgpu::BufferUsages::STORAGE,
    });
    let indices: Vec<u8> = fur.mesh.triangles.iter().flatten().flat_map(|i| i.to_ne_bytes()).collect();
    let index_buffer = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
        label: Some("indices"),
        contents: &indices,
        usage: wgpu::BufferUsages::INDEX,
    });
    let index_count = 3 * fur.mesh.triangles.len() as u32;
    let (centre, radius) = fur.mesh.bounding_sphere();
    let radius = radius + fur.lengths.iter().copied().fold(0.0, f32::max);
    let uniform = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("uniforms"),
        size: 80,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("shell floor"),
        source: wgpu::ShaderSource::Wgsl(include_str!("shell_floor.wgsl").into()),
    });
    let stages = wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: stages,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 1,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Storage { read_only: true },
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 2,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Float { filterable: true },
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            },
            wgpu::BindGroupLayoutEntry {
                binding: 3,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                count: None,
            },
        ],
    });
    let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
        address_mode_u: wgpu::AddressMode::Repeat,
        address_mode_v: wgpu::AddressMode::Repeat,
        mag_filter: wgpu::FilterMode::Linear,
        min_filter: wgpu::FilterMode::Linear,
        mipmap_filter: wgpu::MipmapFilterMode::Linear,
        ..Default::default()
    });
    // 0: sRGB with mips (the product's), 1: unorm with mips, 2: sRGB, one level.
    let views = [
        noise_texture(device, queue, wgpu::TextureFormat::Rgba8UnormSrgb, true),
        noise_texture(device, queue, wgpu::TextureFormat::Rgba8Unorm, true),
        noise_texture(device, queue, wgpu::TextureFormat::Rgba8UnormSrgb, false),
    ];
    let bind_groups: Vec<wgpu::BindGroup> = views
        .iter()
        .map(|view| {
            device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: None,
                layout: &layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: positions.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(view) },
                    wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&sampler) },
                ],
            })
        })
        .collect();
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let all = [
        Variant { name: "bare opaque", vertex: "vs_bare", fragment: "fs_bare", blend: false, texture: 0 },
        Variant { name: "bare", vertex: "vs_bare", fragment: "fs_bare", blend: true, texture: 0 },
        Variant { name: "four", vertex: "vs_four", fragment: "fs_four", blend: true, texture: 0 },
        Variant { name: "eight", vertex: "vs_eight", fragment: "fs_eight", blend: true, texture: 0 },
        Variant { name: "sixteen", vertex: "vs_sixteen", fragment: "fs_sixteen", blend: true, texture: 0 },
        Variant { name: "sixteen+tex", vertex: "vs_sixteen", fragment: "fs_sixteen_texture", blend: true, texture: 0 },
        Variant {
            name: "sixteen+tex unorm",
            vertex: "vs_sixteen",
            fragment: "fs_sixteen_texture",
            blend: true,
            texture: 1,
        },
        Variant {
            name: "sixteen+tex 1 level",
            vertex: "vs_sixteen",
            fragment: "fs_sixteen_texture",
            blend: true,
            texture: 2,
        },
        Variant { name: "four+tex", vertex: "vs_four", fragment: "fs_four_texture", blend: true, texture: 0 },
    ];
    let chosen: Option<Vec<String>> =
        std::env::var("VARIANTS").ok().map(|s| s.split(',').map(|c| c.trim().to_owned()).collect());
    let variants: Vec<&Variant> =
        all.iter().filter(|v| chosen.as_ref().is_none_or(|c| c.iter().any(|n| n == v.name))).collect();
    let pipelines: Vec<wgpu::RenderPipeline> = variants
        .iter()
        .map(|v| {
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(v.name),
                layout: Some(&pipeline_layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(v.vertex),
                    compilation_options: Default::default(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: target.depth_format,
                    depth_write_enabled: Some(!v.blend),
                    depth_compare: Some(target.depth_compare),
                    stencil: Default::default(),
                    bias: Default::default(),
                }),
                multisample: wgpu::MultisampleState { count: target.sample_count, ..Default::default() },
                fragment: Some(wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(v.fragment),
                    compilation_options: Default::default(),
                    targets: &[Some(wgpu::ColorTargetState {
                        format: target.colour_format,
                        blend: v.blend.then_some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                        write_mask: wgpu::ColorWrites::ALL,
                    })],
                }),
                multiview_mask: None,
                cache: None,
            })
        })
        .collect();

    let frames = env_number("FRAMES", 9);
    let rounds = env_number("ROUNDS", 3);
    let sizes: Vec<(u32, u32)> = std::env::var("SIZES")
        .unwrap_or_else(|_| "256x256,1280x720".into())
        .split(',')
        .filter_map(|size| size.split_once('x'))
        .filter_map(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
        .collect();
    for (width, height) in sizes {
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
        let output_view = output.create_view(&Default::default());
        let camera = Camera::framing(centre, radius, 35.0, 20.0, targets.aspect_ratio());
        let mut data = Vec::new();
        for c in camera.clip_from_world(targets.aspect_ratio()).to_cols_array() {
            data.extend_from_slice(&c.to_ne_bytes());
        }
        data.extend_from_slice(&vertex_count.to_ne_bytes());
        data.extend_from_slice(&layers.to_ne_bytes());
        data.extend_from_slice(&4.0f32.to_ne_bytes());
        data.extend_from_slice(&0u32.to_ne_bytes());
        queue.write_buffer(&uniform, 0, &data);
        for round in 0..rounds {
            let mut times = vec![Vec::new(); variants.len()];
            for frame in 0..frames + 1 {
                for (index, variant_times) in times.iter_mut().enumerate() {
                    let started = Instant::now();
                    let mut encoder = device.create_command_encoder(&Default::default());
                    {
                        let mut pass = targets.begin_pass(&mut encoder, &output_view, DEFAULT_BACKGROUND);
                        pass.set_pipeline(&pipelines[index]);
                        pass.set_bind_group(0, &bind_groups[variants[index].texture], &[]);
                        pass.set_index_buffer(index_buffer.slice(..), wgpu::IndexFormat::Uint32);
                        pass.draw_indexed(0..index_count, 0, 0..layers);
                    }
                    queue.submit([encoder.finish()]);
                    device.poll(wgpu::PollType::wait_indefinitely())?;
                    if frame > 0 {
                        variant_times.push(started.elapsed().as_secs_f64() * 1000.0);
                    }
                }
            }
            for (variant, mut times) in variants.iter().zip(times) {
                times.sort_by(f64::total_cmp);
                println!(
                    "{width}x{height} round {round}: {:20} median {:7.2} ms (min {:.2})",
                    variant.name,
                    times[times.len() / 2],
                    times[0]
                );
            }
        }
    }
    Ok(())
}
