//! Where a unified frame's time goes on this adapter: the bunny drawn whole and with parts left
//! out (skin, shells, fins), with fewer layers and at several sizes. A profiling aid for
//! BENCHMARKS.md, not part of the report: `cargo run --release --example frame_profile`.

use std::time::Instant;

use pelt_core::{Builtin, FurStructure, Preset};
use pelt_render::{
    Backend, Camera, CpuSilhouette, DEFAULT_BACKGROUND, FurDrawSettings, FurFrame, FurRenderer, FurStates, FurTarget,
    FurView, Gpu, GpuFur, HEADLESS_FORMAT, Light, RenderTargets, SeparatedFur, SeparatedRenderer, default_sample_count,
};

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(Backend::Auto)?;
    let (device, queue) = (&gpu.device, &gpu.queue);
    // `MSAA=1` (or 2, 4, 8) overrides the adapter's default sample count.
    let samples = std::env::var("MSAA")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| default_sample_count(&gpu.adapter.get_info()));
    println!("{} ({:?}), {samples}x MSAA", gpu.adapter.get_info().name, gpu.adapter.get_info().backend);
    let format = match std::env::var("FORMAT").as_deref() {
        Ok("unorm") => wgpu::TextureFormat::Rgba8Unorm,
        Ok("f16") => wgpu::TextureFormat::Rgba16Float,
        _ => HEADLESS_FORMAT,
    };
    let target = FurTarget::new(format).with_sample_count(samples);
    let renderer = FurRenderer::new(device, target)?;
    let view = FurView::new(device, &renderer);
    // `MODEL=box` profiles the small Box instead of the bunny.
    let builtin = if std::env::var("MODEL").is_ok_and(|m| m == "box") { Builtin::Box } else { Builtin::Bunny };
    let mesh = builtin.mesh().0;
    let frames: usize = std::env::var("FRAMES").ok().and_then(|s| s.parse().ok()).unwrap_or(5);
    // `SIZES=256x256,64x64` picks the sizes, `DISTANCES=1` the distances, `CASES=skin,skin+shells`
    // the parts (default: all of them).
    let sizes: Vec<(u32, u32)> = std::env::var("SIZES")
        .ok()
        .map(|s| {
            s.split(',')
                .filter_map(|size| size.split_once('x'))
                .filter_map(|(w, h)| Some((w.trim().parse().ok()?, h.trim().parse().ok()?)))
                .collect()
        })
        .unwrap_or_else(|| vec![(1280, 720), (256, 256), (64, 64)]);
    let distances: Vec<f32> = std::env::var("DISTANCES")
        .ok()
        .map(|s| s.split(',').filter_map(|d| d.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![1.0, 4.0]);
    let chosen: Option<Vec<String>> =
        std::env::var("CASES").ok().map(|s| s.split(',').map(|c| c.trim().to_owned()).collect());
    // `LAYERS=16,8` picks the layer counts (default 16, 8 and 4).
    let layer_counts: Vec<u32> = std::env::var("LAYERS")
        .ok()
        .map(|s| s.split(',').filter_map(|n| n.trim().parse().ok()).collect())
        .unwrap_or_else(|| vec![16, 8, 4]);
    for &layers in &layer_counts {
        let mut preset = Preset::default();
        preset.layers = layers;
        let fur = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh))?;
        let textures = preset.generate_textures()?;
        let unified = GpuFur::new(device, queue, &renderer, &fur, &textures, FurStates::One)?;
        let frame = FurFrame::default();
        unified.prepare(queue, &frame);
        // The separated structure with 2-face fins, drawn as `pelt bench` draws it.
        let separated_renderer = SeparatedRenderer::new(device, &renderer)?;
        let separated = SeparatedFur::new(device, queue, &renderer, &fur, &textures, 2)?;
        separated.prepare(queue, &frame);
        let mut silhouette = CpuSilhouette::new(&fur.mesh);
        let base = &fur.positions[..fur.mesh.vertex_count()];
        // The CPU silhouette decision alone (no upload), from the default framing.
        let (centre, radius) = fur.mesh.bounding_sphere();
        let eye = Camera::framing(centre, radius * 1.2, 35.0, 20.0, 1.0).eye;
        let started = Instant::now();
        let repeats = 200;
        let mut kept = 0;
        for _ in 0..repeats {
            kept = silhouette.decide(base, &frame, eye)?.len();
        }
        println!(
            "L={layers:2} CPU silhouette decision: {:.1} us ({kept} of {} edges kept)",
            started.elapsed().as_secs_f64() * 1e6 / f64::from(repeats),
            silhouette.edge_count()
        );
        let (centre, radius) = fur.mesh.bounding_sphere();
        let radius = radius + fur.lengths.iter().copied().fold(0.0, f32::max);
        for &(width, height) in &sizes {
            let targets = RenderTargets::new(device, target, width, height)?;
            let output = device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                view_formats: &[],
            });
            let output_view = output.create_view(&Default::default());
            for &distance in &distances {
                let mut camera = Camera::framing(centre, radius, 35.0, 20.0, targets.aspect_ratio());
                camera.eye = centre + (camera.eye - centre) * distance;
                let view_data = camera.view_data(targets.aspect_ratio(), &Light::default());
                let all = FurDrawSettings::SILHOUETTE;
                let skin_fins = FurDrawSettings { shells: false, ..all };
                // The last field: the silhouette decided on the CPU instead of the compute pass.
                // `sep2` cases draw the separated structure with 2-face fins.
                let cases: [(&str, FurDrawSettings, bool); 12] = [
                    ("all", all, false),
                    ("all (CPU silhouette)", all, true),
                    ("skin", FurDrawSettings { shells: false, fins: false, ..all }, false),
                    ("skin+shells", FurDrawSettings { fins: false, ..all }, false),
                    ("skin+fins", skin_fins, false),
                    ("skin+fins (CPU silhouette)", skin_fins, true),
                    ("all (every-edge fins)", FurDrawSettings { silhouette_fins: false, ..all }, false),
                    ("nothing (clear)", FurDrawSettings { skin: false, shells: false, fins: false, ..all }, false),
                    ("sep2 all", all, false),
                    ("sep2 skin", FurDrawSettings { shells: false, fins: false, ..all }, false),
                    ("sep2 skin+shells", FurDrawSettings { fins: false, ..all }, false),
                    ("sep2 skin+fins", skin_fins, false),
                ];
                // `ROUNDS=3` walks the cases that many times in turn (interleaved A/B on a noisy machine).
                let rounds: usize = std::env::var("ROUNDS").ok().and_then(|s| s.parse().ok()).unwrap_or(1);
                for (name, settings, on_cpu) in (0..rounds).flat_map(|_| cases) {
                    if chosen.as_ref().is_some_and(|chosen| !chosen.iter().any(|c| c == name)) {
                        continue;
                    }
                    let mut times = Vec::new();
                    for _ in 0..frames + 1 {
                        let started = Instant::now();
                        let mut encoder = device.create_command_encoder(&Default::default());
                        view.prepare(queue, &view_data);
                        if settings.fins && settings.silhouette_fins && !name.starts_with("sep2") {
                            if on_cpu {
                                let camera_position = view_data.camera_position_world;
                                unified.prepare_fins_on_cpu(queue, &mut silhouette, base, &frame, camera_position)?;
                            } else {
                                renderer.prepare_fins(&mut encoder, &view, &unified);
                            }
                        }
                        {
                            let mut pass = targets.begin_pass(&mut encoder, &output_view, DEFAULT_BACKGROUND);
                            if name.starts_with("sep2") {
                                separated_renderer.draw(&mut pass, &view, &separated, &settings);
                            } else {
                                renderer.draw(&mut pass, &view, &unified, &settings);
                            }
                        }
                        queue.submit([encoder.finish()]);
                        device.poll(wgpu::PollType::wait_indefinitely())?;
                        times.push(started.elapsed().as_secs_f64() * 1000.0);
                    }
                    times.remove(0);
                    if std::env::var("ALL_TIMES").is_ok() {
                        println!("{name}: {times:.1?}");
                    }
                    times.sort_by(f64::total_cmp);
                    println!(
                        "L={layers:2} {width}x{height} dist x{distance}: {name:22} {:8.2} ms (min {:.2})",
                        times[times.len() / 2],
                        times[0]
                    );
                }
            }
        }
    }
    Ok(())
}
