//! Timing the kernels on a fur, for [`KernelChoice::Auto`](super::KernelChoice::Auto) and the
//! benchmarks.

use std::time::Instant;

use pelt_core::FurStructure;
use pelt_core::sim::{FurStepper, SimParams, Simulation};
use pelt_core::texture::FurTextures;

use super::{FurDriver, KernelChoice};
use crate::RenderError;
use crate::renderer::FurRenderer;

/// Steps per timing run and runs per kernel when choosing ([`KernelChoice::Auto`]).
pub(super) const TIMING_STEPS: u32 = 3;
pub(super) const TIMING_RUNS: usize = 5;

/// Median wall seconds per step of the CPU kernel on `structure`, `steps` consecutive steps per
/// run, on a simulation of its own.
///
/// # Errors
/// [`RenderError::Simulation`] for invalid `params`.
pub fn cpu_secs_per_step(
    structure: &FurStructure,
    params: &SimParams,
    steps: u32,
    runs: usize,
) -> Result<f64, RenderError> {
    let mut simulation = Simulation::new(structure, params)?;
    let rate = f64::from(params.rate_hz);
    let mut step = 1_u32;
    let mut samples: Vec<f64> = (0..runs.max(1))
        .map(|_| {
            let started = Instant::now();
            for _ in 0..steps {
                simulation.advance_to(f64::from(step) / rate);
                step += 1;
            }
            started.elapsed().as_secs_f64() / f64::from(steps.max(1))
        })
        .collect();
    Ok(median(&mut samples))
}

/// Median wall seconds per step of the GPU kernel on `structure`: per run, `steps` steps (each
/// advanced, prepared and recorded as a frame does) in one submission, then a wait for the GPU,
/// on a driver of its own (the first run compiles the pipeline on some drivers and is dropped).
///
/// # Errors
/// As [`FurDriver::new`], and a failed wait.
pub fn gpu_secs_per_step(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    renderer: &FurRenderer,
    structure: &FurStructure,
    params: &SimParams,
    steps: u32,
    runs: usize,
) -> Result<f64, RenderError> {
    let mut stepper = FurStepper::new(structure, params)?;
    gpu_secs_per_step_of(device, queue, renderer, structure, params, &mut stepper, steps, runs)
}

/// [`gpu_secs_per_step`] with the host's own `stepper` (colliders placed, a body set, a script).
///
/// # Errors
/// As [`gpu_secs_per_step`].
#[allow(clippy::too_many_arguments)]
pub fn gpu_secs_per_step_of(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    renderer: &FurRenderer,
    structure: &FurStructure,
    params: &SimParams,
    stepper: &mut FurStepper,
    steps: u32,
    runs: usize,
) -> Result<f64, RenderError> {
    let mut driver =
        FurDriver::new(device, queue, renderer, structure, &FurTextures::blank(), params, KernelChoice::Gpu)?;
    let rate = f64::from(params.rate_hz);
    let mut step = 1_u32;
    let mut run = |driver: &mut FurDriver| -> Result<f64, RenderError> {
        let started = Instant::now();
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("sim timing") });
        // Each step takes its own uniform slot of the GPU simulation's ring (up to 64 a
        // submission), so every dispatch bends with its own step's inputs.
        for _ in 0..steps {
            driver.advance_to(device, queue, stepper, f64::from(step) / rate)?;
            step += 1;
            driver.record(&mut encoder)?;
        }
        queue.submit([encoder.finish()]);
        device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| RenderError::Gpu { during: "timing the GPU simulation", message: e.to_string() })?;
        Ok(started.elapsed().as_secs_f64() / f64::from(steps.max(1)))
    };
    run(&mut driver)?;
    let mut samples = (0..runs.max(1)).map(|_| run(&mut driver)).collect::<Result<Vec<f64>, _>>()?;
    Ok(median(&mut samples))
}

fn median(samples: &mut [f64]) -> f64 {
    samples.sort_by(f64::total_cmp);
    samples[samples.len() / 2]
}
