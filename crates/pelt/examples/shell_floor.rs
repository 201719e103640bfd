//! What does a shell triangle and a shell fragment cost on this adapter? The bunny's L shells
//! drawn with a growing number of interpolated components, with and without blending and a
//! texture sample (`shell_floor.wgsl`), frames interleaved across the variants. A profiling aid
//! for BENCHMARKS.md: `cargo run --release -p pelt --example shell_floor`
//! (`SIZES=256x256,1280x720 FRAMES=9 ROUNDS=3 LAYERS=16 VARIANTS=bare,sixteen MSAA=1`).

mod profile;

use pelt_render::HEADLESS_FORMAT;
use profile::{
    Chosen, Offscreen, Profile, ShellPipeline, Shells, env_frames, env_number, env_sizes, interleaved_rounds,
    pipeline_layout, shells_shader, storage_entry, uniform_entry,
};

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
    let profile = Profile::open()?;
    let (device, queue) = (profile.device(), profile.queue());
    let target = profile.target(HEADLESS_FORMAT);
    let shells = Shells::bunny(device, wgpu::BufferUsages::STORAGE)?;
    let module = shells_shader(device, "shell floor", include_str!("shell_floor.wgsl"));
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: None,
        entries: &[
            uniform_entry(0, wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT),
            storage_entry(1, wgpu::ShaderStages::VERTEX),
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
                    wgpu::BindGroupEntry { binding: 0, resource: shells.uniform.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: shells.positions.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(view) },
                    wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&sampler) },
                ],
            })
        })
        .collect();
    let pipeline_layout = pipeline_layout(device, &layout);
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
    let chosen = Chosen::from_env("VARIANTS");
    let variants: Vec<&Variant> = all.iter().filter(|v| chosen.includes(v.name)).collect();
    let pipelines: Vec<wgpu::RenderPipeline> = variants
        .iter()
        .map(|v| {
            let pipeline = ShellPipeline {
                layout: &pipeline_layout,
                module: &module,
                vertex: v.vertex,
                fragment: v.fragment,
                buffers: &[],
                blend: v.blend,
            };
            pipeline.create(device, target, v.name)
        })
        .collect();
    let names: Vec<&str> = variants.iter().map(|v| v.name).collect();

    let (frames, rounds) = (env_frames(9), env_number("ROUNDS", 3));
    for (width, height) in env_sizes(&[(256, 256), (1280, 720)]) {
        let offscreen = Offscreen::new(device, target, width, height)?;
        shells.write_uniform(queue, offscreen.aspect_ratio());
        interleaved_rounds(&format!("{width}x{height}"), rounds, frames, &names, 20, |index| {
            profile.time_frame(|encoder| {
                let mut pass = offscreen.begin_pass(encoder);
                pass.set_pipeline(&pipelines[index]);
                pass.set_bind_group(0, &bind_groups[variants[index].texture], &[]);
                shells.draw(&mut pass);
                Ok(())
            })
        })?;
    }
    Ok(())
}
