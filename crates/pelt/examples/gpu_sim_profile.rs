//! The GPU simulation's throughput and its CPU cost, through `FurDriver` as `--sim gpu` runs it,
//! on the bunny and the 35,000-strand torus at 32 layers with wind: node updates per second as
//! `pelt bench` times them (`pelt_render::gpu_secs_per_step`: `STEPS` steps advanced, prepared
//! and recorded per submission, fence-timed, the median of `RUNS` runs), then the CPU's share
//! of a step (`FurDriver::advance_to` and `FurDriver::record`, one submission for 60 steps).
//!
//! `cargo run --release -p pelt --example gpu_sim_profile` (the best adapter, as `pelt` opens it;
//! `STEPS=30 RUNS=7` are the defaults).

mod profile;

use std::time::Instant;

use pelt_core::Builtin;
use pelt_core::sim::FurStepper;
use pelt_render::{FurDriver, FurRenderer, FurTarget, KernelChoice};
use profile::Profile;

fn main() -> anyhow::Result<()> {
    let profile = Profile::open()?;
    let (device, queue) = (profile.device(), profile.queue());
    let (steps, runs) = (profile::env_number("STEPS", 30_u32).max(1), profile::env_number("RUNS", 7_usize).max(1));
    println!("{}", profile.describe());
    for builtin in [Builtin::Bunny, Builtin::Torus] {
        let (fur, preset) = profile::fur(builtin, 32)?;
        let mut params = preset.simulation.clone();
        // Wind on, as `pelt bench` times the GPU kernel.
        params.wind.strength = 0.5;
        let renderer = FurRenderer::new(device, FurTarget::new(wgpu::TextureFormat::Rgba8UnormSrgb))?;
        let secs = pelt_render::gpu_secs_per_step(device, queue, &renderer, &fur, &params, steps, runs)?;
        let nodes = fur.vertex_count() as f64 * f64::from(fur.layers);

        let textures = preset.generate_textures()?;
        let mut driver = FurDriver::new(device, queue, &renderer, &fur, &textures, &params, KernelChoice::Gpu)?;
        let mut stepper = FurStepper::new(&fur, &params)?;
        let rate = f64::from(params.rate_hz);
        let cpu_steps = 60;
        let (mut t_advance, mut t_record) = (0.0, 0.0);
        let mut encoder = device.create_command_encoder(&Default::default());
        for step in 1..=cpu_steps {
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
            "{builtin}: {n} strands, L = 32: {:.1} M node updates/s ({:.3} ms a step); CPU per step: advance {:.3} ms \
             ({:.2} ns a strand), record {:.3} ms",
            nodes / secs / 1e6,
            secs * 1e3,
            t_advance * 1e3 / f64::from(cpu_steps),
            t_advance * 1e9 / f64::from(cpu_steps) / n as f64,
            t_record * 1e3 / f64::from(cpu_steps),
        );
    }
    Ok(())
}
