//! `--sim auto|cpu|gpu` for `pelt render` and `pelt view`, and the GPU kernel's cost per drawn
//! frame for `pelt bench`: both through [`FurDriver`], the code every host runs.

use std::time::Instant;

use pelt_core::FurStructure;
use pelt_core::sim::{FurStepper, SimParams};
use pelt_core::texture::FurTextures;
use pelt_render::{FurDriver, FurRenderer, FurTarget, KernelChoice};

/// Where the fur is simulated (`--sim`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum SimChoice {
    /// Whichever kernel is clearly faster here: both are timed on this fur before the first
    /// frame, the GPU's taken when it steps 1.25 times as fast (close timings would flip).
    #[default]
    Auto,
    /// `pelt_core::Simulation` on the CPU (all threads), interpolated on the CPU and uploaded
    /// every frame.
    Cpu,
    /// `pelt_render::GpuSimulation`, a compute pass writing the buffers the renderer draws;
    /// the vertex shader interpolates, nothing is uploaded per frame.
    Gpu,
}

impl From<SimChoice> for KernelChoice {
    fn from(choice: SimChoice) -> Self {
        match choice {
            SimChoice::Auto => Self::Auto,
            SimChoice::Cpu => Self::Cpu,
            SimChoice::Gpu => Self::Gpu,
        }
    }
}

/// A renderer for a fur that is simulated and timed but never drawn.
pub fn timing_renderer(device: &wgpu::Device) -> anyhow::Result<FurRenderer> {
    Ok(FurRenderer::new(device, FurTarget::new(wgpu::TextureFormat::Rgba8UnormSrgb))?)
}

/// CPU milliseconds per drawn frame when the GPU simulates: the driver advanced to `draw_hz`
/// render times (stepping at the preset's rate) and, for frames with a new step, the steps
/// recorded and submitted, as `pelt view` does; the GPU is not waited for.
pub fn gpu_cpu_ms_per_drawn_frame(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    structure: &FurStructure,
    params: &SimParams,
    draw_hz: f64,
    frames: u32,
) -> anyhow::Result<f64> {
    let renderer = timing_renderer(device)?;
    let mut driver =
        FurDriver::new(device, queue, &renderer, structure, &FurTextures::blank(), params, KernelChoice::Gpu)?;
    let mut stepper = FurStepper::new(structure, params)?;
    let frames = frames.max(1);
    let started = Instant::now();
    for frame in 1..=frames {
        driver.advance_to(device, queue, &mut stepper, f64::from(frame) / draw_hz)?;
        if driver.has_steps_to_record() {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("sim") });
            driver.record(&mut encoder)?;
            queue.submit([encoder.finish()]);
        }
    }
    let ms = started.elapsed().as_secs_f64() * 1000.0 / f64::from(frames);
    device.poll(wgpu::PollType::wait_indefinitely())?;
    Ok(ms)
}
