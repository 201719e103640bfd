//! Does fetching shell positions through vertex buffers pay on this adapter? The bunny's L shells
//! drawn three ways with the same varyings and a near-constant fragment (`vertex_path.wgsl`):
//! scalar storage loads (the product's path), packed `vec4` storage loads, and vertex buffers that
//! are slices of the one position buffer (one draw per layer). A profiling aid for BENCHMARKS.md:
//! `cargo run --release -p pelt --example vertex_path` (`SIZES=256x256,64x64 FRAMES=21 ROUNDS=3
//! LAYERS=16 MSAA=1`).

mod profile;

use pelt_render::HEADLESS_FORMAT;
use profile::{
    Offscreen, Profile, ShellPipeline, Shells, buffer, env_frames, env_number, env_sizes, interleaved_rounds,
    pipeline_layout, shells_shader, storage_entry, uniform_entry, vec3_bytes,
};

const VARIANTS: [&str; 3] = ["storage f32", "storage vec4", "vertex buffers"];

fn main() -> anyhow::Result<()> {
    let profile = Profile::open()?;
    let (device, queue) = (profile.device(), profile.queue());
    let target = profile.target(HEADLESS_FORMAT);
    let storage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::VERTEX;
    let shells = Shells::bunny(device, storage)?;
    let (fur, positions) = (&shells.fur, &shells.positions);
    let normals = buffer(device, "normals", &vec3_bytes(&fur.mesh.normals, false), storage);
    let positions4 = buffer(device, "positions4", &vec3_bytes(&fur.positions, true), storage);
    let normals4 = buffer(device, "normals4", &vec3_bytes(&fur.mesh.normals, true), storage);

    let module = shells_shader(device, "vertex path", include_str!("vertex_path.wgsl"));
    let vertex = wgpu::ShaderStages::VERTEX;
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[
            uniform_entry(0, vertex),
            storage_entry(1, vertex),
            storage_entry(2, vertex),
            storage_entry(3, vertex),
            storage_entry(4, vertex),
        ],
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: None,
        layout: &layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: shells.uniform.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: positions.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 2, resource: normals.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 3, resource: positions4.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 4, resource: normals4.as_entire_binding() },
        ],
    });
    let pipeline_layout = pipeline_layout(device, &layout);
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
        let pipeline = ShellPipeline {
            layout: &pipeline_layout,
            module: &module,
            vertex: entry,
            fragment: "fs_main",
            buffers,
            blend: true,
        };
        pipeline.create(device, target, entry)
    };
    let pipelines =
        [pipeline("vs_storage", &[]), pipeline("vs_storage4", &[]), pipeline("vs_buffers", &vertex_layouts)];

    let (frames, rounds) = (env_frames(9), env_number("ROUNDS", 3));
    let layers = shells.layers();
    let layer_bytes = u64::from(shells.vertex_count()) * 12;
    for (width, height) in env_sizes(&[(256, 256), (64, 64)]) {
        let offscreen = Offscreen::new(device, target, width, height)?;
        shells.write_uniform(queue, offscreen.aspect_ratio());
        interleaved_rounds(&format!("{width}x{height}"), rounds, frames, &VARIANTS, 15, |variant| {
            profile.time_frame(|encoder| {
                let mut pass = offscreen.begin_pass(encoder);
                pass.set_pipeline(&pipelines[variant]);
                pass.set_bind_group(0, &bind_group, &[]);
                if variant < 2 {
                    shells.draw(&mut pass);
                } else {
                    pass.set_index_buffer(shells.indices.slice(..), wgpu::IndexFormat::Uint32);
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
                        pass.draw_indexed(0..shells.index_count, 0, layer..layer + 1);
                    }
                }
                Ok(())
            })
        })?;
    }
    Ok(())
}
