//! `pelt bench --soak`: `pelt_core::sim::soak` (a million steps of the bunny under extreme,
//! changing inputs) on the CPU kernel, then on the GPU kernel through [`GpuSoak`].

use std::time::Instant;

use glam::Vec3;
use pelt_core::sim::{SimError, SoakReport, SoakStep, SoakSubject};
use pelt_core::texture::FurTextures;
use pelt_core::{FurStructure, Preset, Simulation};
use pelt_render::{Backend, FurDriver, Gpu, KernelChoice, RenderError};

/// The most a segment's length may move in the soak, as a fraction of its strand's length.
pub const SOAK_TOLERANCE: f64 = 1e-5;

/// The GPU kernel as a soak subject: a [`FurDriver`] with the GPU kernel takes each step's
/// inputs, its compute pass bends the strands, and the new state is read back from the buffer
/// the renderer would draw.
pub struct GpuSoak<'a> {
    device: &'a wgpu::Device,
    queue: &'a wgpu::Queue,
    driver: FurDriver,
    /// Keeps time and the inputs; the GPU bends.
    control: Simulation,
    staging: wgpu::Buffer,
    bytes: u64,
}

impl<'a> GpuSoak<'a> {
    /// The GPU simulation of `structure` on `device`.
    ///
    /// # Errors
    /// Whatever the fur, the GPU simulation or the controlling `Simulation` refuse.
    pub fn new(device: &'a wgpu::Device, queue: &'a wgpu::Queue, structure: &FurStructure) -> anyhow::Result<Self> {
        let renderer = crate::sim_kernel::timing_renderer(device)?;
        let driver = FurDriver::new(
            device,
            queue,
            &renderer,
            structure,
            &FurTextures::blank(),
            &Preset::default().simulation,
            KernelChoice::Gpu,
        )?;
        let bytes = structure.positions.len() as u64 * 12;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt soak readback"),
            size: bytes.max(4),
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let control = Simulation::new(structure, &Preset::default().simulation)?;
        Ok(Self { device, queue, driver, control, staging, bytes })
    }
}

fn failed(error: impl std::fmt::Display) -> SimError {
    SimError::Kernel { kernel: "GPU".to_owned(), message: error.to_string() }
}

impl SoakSubject for GpuSoak<'_> {
    fn step(&mut self, step: &SoakStep) -> Result<(), SimError> {
        self.driver
            .step_with(self.device, self.queue, &mut self.control, |simulation| SoakSubject::step(simulation, step))
            .map_err(|error| match error {
                RenderError::Simulation(error) => error,
                other => failed(other),
            })?;
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("soak") });
        self.driver.record(&mut encoder).map_err(failed)?;
        self.queue.submit([encoder.finish()]);
        Ok(())
    }

    fn read_state(&mut self, out: &mut [Vec3]) -> Result<(), SimError> {
        if out.len() as u64 * 12 != self.bytes {
            return Err(failed(RenderError::Count {
                what: "soak state nodes",
                expected: (self.bytes / 12) as usize,
                got: out.len(),
                rule: "(L + 1) * V",
            }));
        }
        if self.bytes == 0 {
            return Ok(());
        }
        let mut encoder = self.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("soak") });
        let current = self.driver.fur().current_positions();
        encoder.copy_buffer_to_buffer(current.buffer(), current.offset(), &self.staging, 0, self.bytes);
        self.queue.submit([encoder.finish()]);
        let slice = self.staging.slice(..self.bytes);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            let _ = sender.send(result);
        });
        self.device.poll(wgpu::PollType::wait_indefinitely()).map_err(failed)?;
        receiver.recv().map_err(failed)?.map_err(failed)?;
        {
            let mapped = slice.get_mapped_range().map_err(failed)?;
            let float = |bytes: &[u8]| f32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
            for (node, xyz) in out.iter_mut().zip(mapped.chunks_exact(12)) {
                *node = Vec3::new(float(&xyz[0..4]), float(&xyz[4..8]), float(&xyz[8..12]));
            }
        }
        self.staging.unmap();
        Ok(())
    }
}

fn print_report(kernel: &str, report: &SoakReport, secs: f64) {
    println!(
        "soak ({kernel}): {} steps in {secs:.1} s; worst segment length error {:.3e} of the strand length (step {}); steps with a non-finite node: {}",
        report.steps, report.worst_length_error, report.worst_step, report.non_finite_steps
    );
}

/// `pelt bench --soak`: the bunny at the default preset's 16 layers through `steps` soak steps on
/// the CPU kernel, then `gpu_steps` on the GPU kernel (the adapter `Gpu::new` finds; none found
/// is reported, not a failure). Fails if either kernel leaves a node non-finite or a length off
/// by more than [`SOAK_TOLERANCE`].
pub fn run(steps: u64, gpu_steps: u64) -> anyhow::Result<()> {
    let (mesh, _) = pelt_core::Builtin::Bunny.mesh();
    let preset = Preset::default();
    let fur = preset.grow(mesh, "bunny")?;
    let progress = |kernel: &'static str, started: Instant| {
        move |done: u64| {
            if done.is_multiple_of(100_000) {
                eprintln!("pelt bench --soak ({kernel}): {done} steps, {:.0} s", started.elapsed().as_secs_f64());
            }
        }
    };

    let mut simulation = Simulation::new(&fur, &preset.simulation)?;
    let cpu_kernel = format!("CPU kernel, {}", simulation.cpu_kernel().name());
    eprintln!(
        "pelt bench --soak: bunny, {} strands x {} layers; {steps} steps on the {cpu_kernel}",
        fur.vertex_count(),
        fur.layers
    );
    let started = Instant::now();
    let cpu = pelt_core::sim::soak(&fur, &mut simulation, steps, progress("CPU", started))?;
    print_report(&cpu_kernel, &cpu, started.elapsed().as_secs_f64());

    let gpu = if gpu_steps == 0 {
        None
    } else {
        match Gpu::new(Backend::Auto) {
            Err(error) => {
                println!("soak (GPU kernel): not run, no adapter: {error}");
                None
            }
            Ok(gpu) => {
                let info = gpu.adapter.get_info();
                let kernel = format!("GPU kernel, {} ({:?})", info.name, info.backend);
                eprintln!("pelt bench --soak: {gpu_steps} steps on the {kernel}");
                let mut subject = GpuSoak::new(&gpu.device, &gpu.queue, &fur)?;
                let started = Instant::now();
                let report = pelt_core::sim::soak(&fur, &mut subject, gpu_steps, progress("GPU", started))?;
                print_report(&kernel, &report, started.elapsed().as_secs_f64());
                Some(report)
            }
        }
    };
    anyhow::ensure!(cpu.passed(SOAK_TOLERANCE), "CPU soak failed (tolerance {SOAK_TOLERANCE:e}): {cpu:?}");
    if let Some(gpu) = gpu {
        anyhow::ensure!(gpu.passed(SOAK_TOLERANCE), "GPU soak failed (tolerance {SOAK_TOLERANCE:e}): {gpu:?}");
    }
    Ok(())
}
