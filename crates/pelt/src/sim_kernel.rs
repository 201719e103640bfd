//! `--sim auto|cpu|gpu`: which kernel bends the fur in `pelt render` and `pelt view`, the
//! measurement `auto` decides by, and the GPU simulation's throughput for `pelt bench`.

use std::fmt;
use std::time::Instant;

use pelt_core::FurStructure;
use pelt_core::sim::{SimParams, Simulation};
use pelt_core::texture::FurTextures;
use pelt_render::{FurRenderer, FurStates, FurTarget, GpuFur, GpuSimulation};

/// Where the fur is simulated (`--sim`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum SimChoice {
    /// Whichever kernel is faster here: both are timed on this fur before the first frame.
    #[default]
    Auto,
    /// `pelt_core::Simulation` on the CPU (all threads), interpolated on the CPU and uploaded
    /// every frame.
    Cpu,
    /// `pelt_render::GpuSimulation`, a compute pass writing the buffers the renderer draws;
    /// the vertex shader interpolates, nothing is uploaded per frame.
    Gpu,
}

/// The kernel that runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimKernel {
    Cpu,
    Gpu,
}

impl fmt::Display for SimKernel {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(match self {
            Self::Cpu => "CPU",
            Self::Gpu => "GPU",
        })
    }
}

/// The kernel `choice` asks for, with why. `auto` times a few steps of each on `structure`
/// (median seconds per step; the GPU's submitted and waited for, so it includes the
/// submission, as the CPU's includes its threads) and takes the faster.
pub fn choose(
    choice: SimChoice,
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    structure: &FurStructure,
    params: &SimParams,
) -> anyhow::Result<(SimKernel, String)> {
    Ok(match choice {
        SimChoice::Cpu => (SimKernel::Cpu, "--sim cpu".to_owned()),
        SimChoice::Gpu => (SimKernel::Gpu, "--sim gpu".to_owned()),
        SimChoice::Auto => {
            const STEPS: u32 = 3;
            const RUNS: usize = 5;
            let cpu = cpu_secs_per_step(structure, params, STEPS, RUNS)?;
            let gpu = gpu_secs_per_step(device, queue, structure, params, STEPS, RUNS)?;
            let kernel = if gpu < cpu { SimKernel::Gpu } else { SimKernel::Cpu };
            (kernel, format!("auto: GPU {:.2} ms a step, CPU {:.2} ms", gpu * 1000.0, cpu * 1000.0))
        }
    })
}

/// Median wall seconds per step of the CPU simulation, `steps` consecutive steps per run.
pub fn cpu_secs_per_step(structure: &FurStructure, params: &SimParams, steps: u32, runs: usize) -> anyhow::Result<f64> {
    let mut simulation = Simulation::new(structure, params)?;
    let rate = f64::from(params.rate_hz);
    let mut step = 1_u32;
    let mut samples: Vec<f64> = (0..runs)
        .map(|_| {
            let started = Instant::now();
            for _ in 0..steps {
                simulation.advance_to(f64::from(step) / rate);
                step += 1;
            }
            started.elapsed().as_secs_f64() / f64::from(steps)
        })
        .collect();
    Ok(median(&mut samples))
}

/// A fur of its own with two states, the GPU simulation writing them, and a CPU `Simulation`
/// that only keeps time and inputs (its bending off), for timing the GPU kernel.
pub fn gpu_rig(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    structure: &FurStructure,
    params: &SimParams,
) -> anyhow::Result<(GpuFur, GpuSimulation, Simulation)> {
    let renderer = FurRenderer::new(device, FurTarget::new(wgpu::TextureFormat::Rgba8UnormSrgb))?;
    let fur = GpuFur::new(device, queue, &renderer, structure, &blank_textures(), FurStates::Two)?;
    let gpu = GpuSimulation::new(device, &fur, structure)?;
    let mut control = Simulation::new(structure, params)?;
    control.set_cpu_bending(false);
    Ok((fur, gpu, control))
}

/// Median wall seconds per step of the GPU simulation: per run, `steps` steps (each advanced,
/// prepared and dispatched as a frame would) in one submission, then a wait for the GPU to
/// finish (the fence), on a fur of its own.
pub fn gpu_secs_per_step(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    structure: &FurStructure,
    params: &SimParams,
    steps: u32,
    runs: usize,
) -> anyhow::Result<f64> {
    let (mut fur, mut gpu, mut control) = gpu_rig(device, queue, structure, params)?;
    let rate = f64::from(params.rate_hz);
    let mut step = 1_u32;
    let mut run = |fur: &mut GpuFur| -> anyhow::Result<f64> {
        let started = Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("sim timing") });
        // The steps' uniform writes all land before the submission, so every dispatch reads the
        // last step's inputs: the same work per step, which is what is timed.
        for _ in 0..steps {
            control.advance_to(f64::from(step) / rate);
            step += 1;
            gpu.prepare(device, queue, &control, fur)?;
            gpu.dispatch(&mut encoder, fur)?;
        }
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        Ok(started.elapsed().as_secs_f64() / f64::from(steps))
    };
    // The first run compiles the pipeline on some drivers.
    run(&mut fur)?;
    let mut samples = (0..runs).map(|_| run(&mut fur)).collect::<anyhow::Result<Vec<f64>>>()?;
    Ok(median(&mut samples))
}

/// CPU milliseconds per drawn frame when the GPU simulates: `advance_to` at `draw_hz` render
/// times (stepping at the preset's rate), `prepare`, and for frames with a new step the
/// dispatch recorded and submitted, as `pelt view` does; the GPU is not waited for. No
/// interpolation or upload is left on the CPU.
pub fn gpu_cpu_ms_per_drawn_frame(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    structure: &FurStructure,
    params: &SimParams,
    draw_hz: f64,
    frames: u32,
) -> anyhow::Result<f64> {
    let (mut fur, mut gpu, mut control) = gpu_rig(device, queue, structure, params)?;
    let frames = frames.max(1);
    let started = Instant::now();
    for frame in 1..=frames {
        control.advance_to(f64::from(frame) / draw_hz);
        gpu.prepare(device, queue, &control, &fur)?;
        if gpu.pending_steps() > 0 {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("sim") });
            gpu.dispatch(&mut encoder, &mut fur)?;
            queue.submit([encoder.finish()]);
        }
    }
    let ms = started.elapsed().as_secs_f64() * 1000.0 / f64::from(frames);
    device.poll(wgpu::PollType::wait_indefinitely())?;
    Ok(ms)
}

fn median(samples: &mut [f64]) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}

/// The smallest valid textures: the timing fur is never drawn.
fn blank_textures() -> FurTextures {
    FurTextures { size: 4, layers: 1, shell: vec![0; 64], fin_width: 4, fin_height: 4, fin: vec![0; 64], surface: None }
}
