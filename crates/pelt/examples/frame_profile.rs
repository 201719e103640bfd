//! Where a unified frame's time goes on this adapter: the bunny drawn whole and with parts left
//! out (skin, shells, fins), with fewer layers and at several sizes. A profiling aid for
//! BENCHMARKS.md, not part of the report: `cargo run --release --example frame_profile`.

mod profile;

use std::time::Instant;

use pelt_core::Builtin;
use pelt_render::{
    Camera, CpuSilhouette, FurDrawSettings, FurDriver, FurRenderer, FurView, HEADLESS_FORMAT, KernelChoice, Light,
    SeparatedFur, SeparatedRenderer,
};
use profile::{Chosen, Offscreen, Profile, env_frames, env_list, env_number, env_sizes, framing_camera, in_a_row};

fn main() -> anyhow::Result<()> {
    // `MSAA=1` (or 2, 4, 8) overrides the adapter's default sample count.
    let profile = Profile::open()?;
    let (device, queue) = (profile.device(), profile.queue());
    println!("{}", profile.describe());
    let format = match std::env::var("FORMAT").as_deref() {
        Ok("unorm") => wgpu::TextureFormat::Rgba8Unorm,
        Ok("f16") => wgpu::TextureFormat::Rgba16Float,
        _ => HEADLESS_FORMAT,
    };
    let target = profile.target(format);
    let renderer = FurRenderer::new(device, target)?;
    let view = FurView::new(device, &renderer);
    // `MODEL=box` profiles the small Box instead of the bunny.
    let builtin = if std::env::var("MODEL").is_ok_and(|m| m == "box") { Builtin::Box } else { Builtin::Bunny };
    let frames = env_frames(5);
    // `SIZES=256x256,64x64` picks the sizes, `DISTANCES=1` the distances, `CASES=skin,skin+shells`
    // the parts (default: all of them).
    let sizes = env_sizes(&[(1280, 720), (256, 256), (64, 64)]);
    let distances: Vec<f32> = env_list("DISTANCES", &[1.0, 4.0]);
    let chosen = Chosen::from_env("CASES");
    // `LAYERS=16,8` picks the layer counts (default 16, 8 and 4).
    let layer_counts: Vec<u32> = env_list("LAYERS", &[16, 8, 4]);
    // `ROUNDS=3` walks the cases that many times in turn (interleaved A/B on a noisy machine).
    let rounds = env_number("ROUNDS", 1);
    for &layers in &layer_counts {
        let (fur, preset) = profile::fur(builtin, layers)?;
        let textures = preset.generate_textures()?;
        // Drawn by the driver every host uses, at rest as `pelt bench` draws it: a stepper would
        // bend the strands under gravity and part them from the separated fur's.
        let mut driver =
            FurDriver::new(device, queue, &renderer, &fur, &textures, &preset.simulation, KernelChoice::Cpu)?;
        let frame = *driver.frame();
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
        for &(width, height) in &sizes {
            let offscreen = Offscreen::new(device, target, width, height)?;
            for &distance in &distances {
                let mut camera = framing_camera(&fur, offscreen.aspect_ratio());
                camera.eye = camera.target + (camera.eye - camera.target) * distance;
                let view_data = camera.view_data(offscreen.aspect_ratio(), &Light::default());
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
                for (name, settings, on_cpu) in (0..rounds).flat_map(|_| cases) {
                    if !chosen.includes(name) {
                        continue;
                    }
                    let separated_case = name.starts_with("sep2");
                    let times = in_a_row(frames, || {
                        profile.time_frame(|encoder| {
                            view.prepare(queue, &view_data);
                            if !separated_case {
                                driver.record(encoder)?;
                            }
                            if settings.fins && settings.silhouette_fins && !separated_case {
                                if on_cpu {
                                    let camera_position = view_data.camera_position_world;
                                    driver.fur().prepare_fins_on_cpu(
                                        queue,
                                        &mut silhouette,
                                        base,
                                        &frame,
                                        camera_position,
                                    )?;
                                } else {
                                    driver.record_view(encoder, &renderer, &view);
                                }
                            }
                            let mut pass = offscreen.begin_pass(encoder);
                            if separated_case {
                                separated_renderer.draw(&mut pass, &view, &separated, &settings);
                            } else {
                                driver.draw(&mut pass, &renderer, &view, &settings);
                            }
                            Ok(())
                        })
                    })?;
                    if std::env::var("ALL_TIMES").is_ok() {
                        println!("{name}: {:.1?}", times.0);
                    }
                    println!(
                        "L={layers:2} {width}x{height} dist x{distance}: {name:22} {:8.2} ms (min {:.2})",
                        times.median(),
                        times.min()
                    );
                }
            }
        }
    }
    Ok(())
}
