//! Does fetching shell positions through vertex buffers pay on this adapter? The bunny's L shells
//! drawn three ways with the same varyings and a near-constant fragment (`vertex_path.wgsl`):
//! scalar storage loads (the product's path), packed `vec4` storage loads, and vertex buffers that
//! are slices of the one position buffer (one draw per layer). A profiling aid for BENCHMARKS.md:
//! `cargo run --release -p pelt --example vertex_path` (`SIZES=256x256,64x64 FRAMES=21 ROUNDS=3`).

use std::time::Instant;

use glam::Vec3;
use pelt_core::{Builtin, FurStructure, Preset};
use pelt_render::{
    Backend, Camera, DEFAULT_BACKGROUND, FurTarget, Gpu, HEADLESS_FORMAT, RenderTargets, default_sample_count,
};
use wgpu::util::DeviceExt;

const VARIANTS: [&str; 3] = ["storage f32", "storage vec4", "vertex buffers"];

fn bytes_of_vec3(values: &[Vec3], padded: bool) -> Vec<u8> {
    let mut out = Vec::new();
    for v in values {
        let mut components = v.to_array().to_vec();
        if padded {
            components.push(1.0);
        }
        for c in components {
            out.extend_from_slice(&c.to_ne_bytes());
        }
    }
    out
}

fn env_number(name: &str, default: usize) -> usize {
    std::env::var(name).ok().and_then(|s| s.parse().ok()).unwrap_or(default)
}

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(Backend::Auto)?;
    let (device, queue) = (&gpu.device, &gpu.queue);
    let target = FurTarget::new(HEADLESS_FORMAT).with_sample_count(default_sample_count(&gpu.adapter.get_info()));
    let mesh = Builtin::Bunny.mesh().0;
    let mut preset = Preset::default();
    preset.layers = env_number("LAYERS", 16) as u32;
    let fur = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh))?;
    let vertex_count = fur.mesh.vertex_count() as u64;
    let layers = fur.layers;

    let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX;
    let buffer = |label, contents: &[u8], usage| {
        device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
    };
    let positions = buffer("positions", &bytes_of_vec3(&fur.positions, false), storage);
    let normals = buffer("normals", &bytes_of_vec3(&fur.mesh.normals, false), storage);
    let positions4 = buffer("positions4", &bytes_of_vec3(&fur.positions, true), storage);
    let normals4 = buffer("normals4", &bytes_of_vec3(&fur.mesh.normals, true), storage);
    let indices: Vec<u8> = fur.mesh.triangles.iter().flatten().flat_map(|i| i.to_ne_bytes()).collect();
    let index_buffer = buffer("indices", &indices, wgpu::BufferUsages::INDEX);
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
        label: Some("vertex path"),
        source: wgpu::ShaderSource::Wgsl(include_str!("vertex_path.wgsl").into()),
    });
    let storage_entry = |binding| wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    };
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[
            wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::VERTEX,
                ty: wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
                count: None,
            },
            storage_entry(1),
            storage_entry(2),
            storage_entry(3),
            storage_entry(4),
        ],
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: positions.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: normals.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 3, resource: positions4.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 4, resource: normals4.as_entire_binding() },
        ],
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: None,
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let attributes: Vec<[wgpu::VertexAttribute; 1]> = (0..4)
        .map(|location| {
            [wgpu::VertexAttribute { format: wgpu::VertexFormat::Float32x3, offset: 0, shader_location: location }]
        })
        .collect();
    let vertex_layouts: Vec<Option<wgpu::VertexBufferLayout>> = attributes
        .iter()
        .map(|attributes| {
            Some(wgpu::VertexBufferLayout { array_stride: 12, step_mode: wgpu::VertexStepMode::Vertex, attributes })
        })
        .collect();
    let pipeline = |entry: &str, buffers: &[Option<wgpu::VertexBufferLayout>]| {
        device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some(entry),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some(entry),
                compilation_options: Default::default(),
                buffers,
            },
            primitive: wgpu::PrimitiveState { cull_mode: Some(wgpu::Face::Back), ..Default::default() },
            depth_stencil: Some(wgpu::DepthStencilState {
                format: target.depth_format,
                depth_write_enabled: Some(false),
                depth_compare: Some(target.depth_compare),
                stencil: Default::default(),
                bias: Default::default(),
            }),
            multisample: wgpu::MultisampleState { count: target.sample_count, ..Default::default() },
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_main"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: target.colour_format,
                    blend: Some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        })
    };
    let pipelines =
        [pipeline("vs_storage", &[]), pipeline("vs_storage4", &[]), pipeline("vs_buffers", &vertex_layouts)];

    let frames = env_number("FRAMES", 9);
    let rounds = env_number("ROUNDS", 3);
    let sizes: Vec<(u32, u32)> = std::env::var("SIZES")
        .unwrap_or_else(|_| "256x256,64x64".into())
        .split(',')
        .filter_map(|size| size.split_once('x'))
        .filter_map(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
        .collect();
    let layer_bytes = vertex_count * 12;
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
        data.extend_from_slice(&(vertex_count as u32).to_ne_bytes());
        data.extend_from_slice(&layers.to_ne_bytes());
        data.extend_from_slice(&4.0f32.to_ne_bytes());
        data.extend_from_slice(&0u32.to_ne_bytes());
        queue.write_buffer(&uniform, 0, &data);
        // Frames interleave the variants (A B C A B C ...), so load changes hit all of them.
        for round in 0..rounds {
            let mut times = vec![Vec::new(); VARIANTS.len()];
            for frame in 0..frames + 1 {
                for (variant, variant_times) in times.iter_mut().enumerate() {
                    let started = Instant::now();
                    let mut encoder = device.create_command_encoder(&Default::default());
                    {
                        let mut pass = targets.begin_pass(&mut encoder, &output_view, DEFAULT_BACKGROUND);
                        pass.set_pipeline(&pipelines[variant]);
                        pass.set_bind_group(0, &bind_group, &[]);
                        pass.set_index_buffer(index_buffer.slice(..), wgpu::IndexFormat::Uint32);
                        if variant < 2 {
                            pass.draw_indexed(0..index_count, 0, 0..layers);
                        } else {
                            let slice = |layer: u32| {
                                let start = u64::from(layer) * layer_bytes;
                                positions.slice(start..start + layer_bytes)
                            };
                            pass.set_vertex_buffer(2, slice(0));
                            pass.set_vertex_buffer(3, normals.slice(..));
                            for layer in 1..=layers {
                                pass.set_vertex_buffer(0, slice(layer));
                                let other = if layer < layers { layer + 1 } else { layer - 1 };
                                pass.set_vertex_buffer(1, slice(other));
                                pass.draw_indexed(0..index_count, 0, layer..layer + 1);
                            }
                        }
                    }
                    queue.submit([encoder.finish()]);
                    device.poll(wgpu::PollType::wait_indefinitely())?;
                    // The first frame of each variant warms it up.
                    if frame > 0 {
                        variant_times.push(started.elapsed().as_secs_f64() * 1000.0);
                    }
                }
            }
            for (name, mut times) in VARIANTS.iter().zip(times) {
                times.sort_by(f64::total_cmp);
                println!(
                    "{width}x{height} round {round}: {name:15} median {:7.2} ms (min {:.2})",
                    times[times.len() / 2],
                    times[0]
                );
            }
        }
    }
    Ok(())
}
