//! Where the GPU simulation's step goes on the CPU: the controlling `Simulation` advancing
//! (forces, touch and inertia per strand, its bending off), `GpuSimulation::prepare` (the per-strand
//! inputs and the step uniforms uploaded) and recording the dispatch, per step and per strand.
//! A profiling aid for BENCHMARKS.md: `cargo run --release --example gpu_sim_profile`.

use std::time::Instant;

use pelt_core::{Builtin, FurStructure, Preset, Simulation};
use pelt_render::{Backend, FurRenderer, FurStates, FurTarget, Gpu, GpuFur, GpuSimulation};

fn main() -> anyhow::Result<()> {
    let gpu = Gpu::new(Backend::Auto)?;
    let (device, queue) = (&gpu.device, &gpu.queue);
    for builtin in [Builtin::Bunny, Builtin::Torus] {
        let (mesh, _) = builtin.mesh();
        let mut preset = Preset::default();
        preset.layers = 32;
        let fur = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh))?;
        let mut params = preset.simulation.clone();
        // Wind on, as `pelt bench` times the GPU kernel.
        params.wind.strength = 0.5;
        let renderer = FurRenderer::new(device, FurTarget::new(wgpu::TextureFormat::Rgba8UnormSrgb))?;
        let textures = preset.generate_textures()?;
        let mut gfur = GpuFur::new(device, queue, &renderer, &fur, &textures, FurStates::Two)?;
        let mut sim = GpuSimulation::new(device, &gfur, &fur)?;
        let mut control = Simulation::new(&fur, &params)?;
        control.set_cpu_bending(false);
        let rate = f64::from(params.rate_hz);
        let steps = 60;
        let (mut t_adv, mut t_prep, mut t_disp) = (0.0, 0.0, 0.0);
        let mut encoder = device.create_command_encoder(&Default::default());
        for step in 1..=steps {
            let t = Instant::now();
            control.advance_to(f64::from(step) / rate);
            t_adv += t.elapsed().as_secs_f64();
            let t = Instant::now();
            sim.prepare(device, queue, &control, &gfur)?;
            t_prep += t.elapsed().as_secs_f64();
            let t = Instant::now();
            sim.dispatch(&mut encoder, &mut gfur)?;
            t_disp += t.elapsed().as_secs_f64();
        }
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        let n = fur.vertex_count();
        println!(
            "{builtin}: {n} strands; per step: advance {:.3} ms, prepare {:.3} ms, dispatch rec {:.3} ms; per strand advance {:.1} ns",
            t_adv * 1e3 / f64::from(steps),
            t_prep * 1e3 / f64::from(steps),
            t_disp * 1e3 / f64::from(steps),
            t_adv * 1e9 / f64::from(steps) / n as f64
        );
    }
    Ok(())
}
