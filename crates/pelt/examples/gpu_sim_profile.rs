//! Where the GPU simulation's step goes on the CPU: `FurDriver::advance_to` (the stepper's
//! forces, touch and inertia per strand with its bending off, then the per-strand inputs and the
//! step uniforms uploaded) and `FurDriver::record` (the dispatch recorded), per step and per
//! strand. A profiling aid for BENCHMARKS.md: `cargo run --release --example gpu_sim_profile`.

mod profile;

use std::time::Instant;

use pelt_core::Builtin;
use pelt_core::sim::FurStepper;
use pelt_render::{FurDriver, FurRenderer, FurTarget, KernelChoice};
use profile::Profile;

fn main() -> anyhow::Result<()> {
    let profile = Profile::open()?;
    let (device, queue) = (profile.device(), profile.queue());
    for builtin in [Builtin::Bunny, Builtin::Torus] {
        let (fur, preset) = profile::fur(builtin, 32)?;
        let mut params = preset.simulation.clone();
        // Wind on, as `pelt bench` times the GPU kernel.
        params.wind.strength = 0.5;
        let renderer = FurRenderer::new(device, FurTarget::new(wgpu::TextureFormat::Rgba8UnormSrgb))?;
        let textures = preset.generate_textures()?;
        let mut driver = FurDriver::new(device, queue, &renderer, &fur, &textures, &params, KernelChoice::Gpu)?;
        let mut stepper = FurStepper::new(&fur, &params)?;
        let rate = f64::from(params.rate_hz);
        let steps = 60;
        let (mut t_advance, mut t_record) = (0.0, 0.0);
        let mut encoder = device.create_command_encoder(&Default::default());
        for step in 1..=steps {
            let t = Instant::now();
            driver.advance_to(device, queue, &mut stepper, f64::from(step) / rate)?;
            t_advance += t.elapsed().as_secs_f64();
            let t = Instant::now();
            driver.record(&mut encoder)?;
            t_record += t.elapsed().as_secs_f64();
        }
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        let n = fur.vertex_count();
        println!(
            "{builtin}: {n} strands; per step: advance {:.3} ms, record {:.3} ms; per strand advance {:.1} ns",
            t_advance * 1e3 / f64::from(steps),
            t_record * 1e3 / f64::from(steps),
            t_advance * 1e9 / f64::from(steps) / n as f64
        );
    }
    Ok(())
}
