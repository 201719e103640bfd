//! [`FurDriver`]: one fur from its simulation to the host's render pass, the frame every host
//! (the `pelt` commands, the viewer, the web page, bevy_pelt, the examples) makes the same way.
//!
//! A frame is three calls: [`FurDriver::advance_to`] (pose, script, simulation step, queue
//! writes), [`FurDriver::record`] (the GPU work before the render pass: the GPU simulation's
//! steps and the silhouette fins) and [`FurDriver::draw`] (into the host's pass).

mod herd;
mod posing;
mod timing;
mod upload;

use std::fmt;
use std::sync::Arc;

use pelt_core::FurStructure;
use pelt_core::sim::{FurStepper, SimError, SimParams, Simulation};
use pelt_core::texture::FurTextures;

pub use posing::HerdPosing;
use timing::{TIMING_RUNS, TIMING_STEPS};
pub use timing::{cpu_secs_per_step, gpu_secs_per_step, gpu_secs_per_step_of};

use crate::RenderError;
use crate::asset::FurAsset;
use crate::fur::{FurStates, GpuFur};
use crate::lod::FurLevel;
use crate::object::{FurFrame, FurLook};
use crate::pool::MemberPool;
use crate::renderer::{FurDrawSettings, FurRenderer};
use crate::simulation::{GpuSimulation, SimPool};
use crate::view::FurView;

/// Where the strands are bent.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SimKernel {
    /// [`Simulation`] on the CPU (all threads), interpolated there and uploaded every frame.
    Cpu,
    /// [`GpuSimulation`], a compute pass writing the buffers the renderer draws; the vertex
    /// shader interpolates, and only the per-step inputs are uploaded.
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

/// Which kernel a [`FurDriver`] is to use (`--sim`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum KernelChoice {
    /// Whichever is clearly faster here: both are timed on this fur before the first frame, and
    /// the GPU kernel is taken when it steps at least [`AUTO_GPU_MARGIN`] times as fast.
    #[default]
    Auto,
    /// The CPU kernel.
    Cpu,
    /// The GPU kernel.
    Gpu,
}

impl From<SimKernel> for KernelChoice {
    /// That kernel, asked for (a copy made to bend where another fur already does).
    fn from(kernel: SimKernel) -> Self {
        match kernel {
            SimKernel::Cpu => Self::Cpu,
            SimKernel::Gpu => Self::Gpu,
        }
    }
}

/// How much faster the GPU kernel must step for [`KernelChoice::Auto`] to take it. The kernels
/// draw pictures that differ in their last bits, so timings within noise of each other (a CPU
/// rasteriser's) would make the same command draw other bytes from run to run; a GPU's kernel
/// wins by far more.
pub const AUTO_GPU_MARGIN: f64 = 1.25;

/// One fur's frame on the GPU: its [`GpuFur`], the kernel that bends it (and with the GPU
/// kernel its [`GpuSimulation`]) and its per-frame uniform, driven from the host's
/// [`FurStepper`] (the CPU half: simulation, posing, script).
///
/// The stepper stays the host's so that a host without a GPU (tests, a server) or with its CPU
/// state elsewhere (Bevy's main world) keeps it; the driver decides on each call whether the
/// stepper's simulation bends the strands (the CPU kernel) or only keeps time and inputs.
///
/// Each frame, in order: [`FurDriver::advance_to`] before the host records its encoder (queue
/// writes only), [`FurDriver::record`] into the host's encoder before its render pass, then
/// [`FurDriver::draw`] into the pass. A host that never calls `record` still sees the fur move:
/// with the GPU kernel, steps left unrecorded at the next `advance_to` switch the driver to the
/// CPU kernel (the reason says so), and the CPU kernel needs no recording (the silhouette fins
/// do: without [`FurDriver::record_view`], [`FurDrawSettings::silhouette_fins`] draws none).
#[derive(Debug)]
pub struct FurDriver {
    fur: GpuFur,
    gpu_simulation: Option<GpuSimulation>,
    kernel: SimKernel,
    kernel_reason: String,
    frame: FurFrame,
    /// The GPU kernel's steps were prepared and not yet recorded.
    unrecorded: bool,
}

impl FurDriver {
    /// The fur grown as `structure`, with `textures`, simulated with `params` on the kernel
    /// `choice` picks (`Auto` times a few steps of each on this fur first).
    ///
    /// # Errors
    /// The simulation's ([`RenderError::Simulation`]) or the upload's errors.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        structure: &FurStructure,
        textures: &FurTextures,
        params: &SimParams,
        choice: KernelChoice,
    ) -> Result<Self, RenderError> {
        let asset = FurAsset::new(device, queue, renderer, structure, textures)?;
        Self::with_asset(device, queue, renderer, &asset, structure, params, choice)
    }

    /// One more copy of a fur whose shared data is `asset` (grown as `structure`; a herd's member):
    /// its own state, simulated with `params` on the kernel `choice` picks. A herd picks once
    /// (`Auto` times the kernels on every call) and gives the others that kernel.
    ///
    /// # Errors
    /// [`RenderError::Count`] when `structure` is not the asset's (other `V` or `L`); as
    /// [`FurDriver::new`].
    pub fn with_asset(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        asset: &FurAsset,
        structure: &FurStructure,
        params: &SimParams,
        choice: KernelChoice,
    ) -> Result<Self, RenderError> {
        let mut herd = Self::herd_with_asset(device, queue, renderer, (asset, structure), params, choice, 1)?;
        Ok(herd.remove(0))
    }

    /// `count` copies of a fur whose shared data is `asset`, as
    /// [`FurDriver::with_asset`] makes one, made together ([`GpuFur::herd_from_asset`]): their
    /// silhouette and view-angle passes list in a few dispatches for the whole herd. `choice`
    /// is made once for all.
    ///
    /// # Errors
    /// As [`FurDriver::with_asset`].
    pub fn herd_with_asset(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        (asset, structure): (&FurAsset, &FurStructure),
        params: &SimParams,
        choice: KernelChoice,
        count: usize,
    ) -> Result<Vec<Self>, RenderError> {
        let expected = (asset.layers() as usize + 1) * asset.vertex_count() as usize;
        if structure.positions.len() != expected {
            return Err(RenderError::Count {
                what: "shared vertex positions of the asset's structure",
                expected,
                got: structure.positions.len(),
                rule: "(L + 1) * V",
            });
        }
        let (kernel, kernel_reason) = match choice {
            KernelChoice::Cpu => (SimKernel::Cpu, "asked for".to_owned()),
            KernelChoice::Gpu => (SimKernel::Gpu, "asked for".to_owned()),
            KernelChoice::Auto => {
                let cpu = cpu_secs_per_step(structure, params, TIMING_STEPS, TIMING_RUNS)?;
                let gpu = gpu_secs_per_step(device, queue, renderer, structure, params, TIMING_STEPS, TIMING_RUNS)?;
                let kernel = if gpu * AUTO_GPU_MARGIN < cpu { SimKernel::Gpu } else { SimKernel::Cpu };
                (kernel, format!("auto: GPU {:.2} ms a step, CPU {:.2} ms", gpu * 1000.0, cpu * 1000.0))
            }
        };
        let furs = GpuFur::herd_from_asset(device, renderer, asset, states(kernel), count)?;
        // Copies grown as the asset share its GPU rest segments.
        let shared_rest = asset.grown_as(structure).then_some(&*asset.simulation_rest);
        // On the GPU kernel the copies of each pool keep their per-strand buffers together too.
        let mut sim_pools: Vec<(Arc<MemberPool>, Arc<SimPool>)> = Vec::new();
        if kernel == SimKernel::Gpu {
            for fur in &furs {
                if !sim_pools.iter().any(|(pool, _)| Arc::ptr_eq(pool, fur.pool())) {
                    let slots = furs.iter().filter(|other| Arc::ptr_eq(other.pool(), fur.pool())).count();
                    let sim_pool = SimPool::new(device, structure.vertex_count(), slots as u32)?;
                    sim_pools.push((fur.pool().clone(), Arc::new(sim_pool)));
                }
            }
        }
        let mut drivers = Vec::with_capacity(furs.len());
        for fur in furs {
            let sim_pool = sim_pools.iter().find(|(pool, _)| Arc::ptr_eq(pool, fur.pool())).map(|(_, sim)| sim.clone());
            let mut driver = Self {
                fur,
                gpu_simulation: None,
                kernel,
                kernel_reason: kernel_reason.clone(),
                frame: FurFrame::default(),
                unrecorded: false,
            };
            driver.use_kernel(device, renderer, structure, kernel, (shared_rest, sim_pool.as_ref()))?;
            driver.fur.prepare(queue, &driver.frame);
            drivers.push(driver);
        }
        Ok(drivers)
    }

    /// Bytes of the GPU kernel's own buffers for this fur ([`GpuSimulation::gpu_bytes`]); 0 on
    /// the CPU kernel.
    #[must_use]
    pub fn simulation_bytes(&self) -> u64 {
        self.gpu_simulation.as_ref().map_or(0, GpuSimulation::gpu_bytes)
    }

    /// The kernel bending the strands.
    #[must_use]
    pub fn kernel(&self) -> SimKernel {
        self.kernel
    }

    /// Why that kernel: `asked for`, `auto` with both timings, or a fallback.
    #[must_use]
    pub fn kernel_reason(&self) -> &str {
        &self.kernel_reason
    }

    /// Switches kernels (`structure` is the fur's current one); the GPU fur is rebuilt with the
    /// number of states the kernel needs.
    ///
    /// # Errors
    /// As [`FurDriver::new`].
    pub fn set_kernel(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        structure: &FurStructure,
        textures: &FurTextures,
        kernel: SimKernel,
    ) -> Result<(), RenderError> {
        self.kernel_reason = "set by the host".to_owned();
        if kernel == self.kernel {
            return Ok(());
        }
        self.fur = GpuFur::new(device, queue, renderer, structure, textures, states(kernel))?;
        self.use_kernel(device, renderer, structure, kernel, (None, None))?;
        self.fur.prepare(queue, &self.frame);
        Ok(())
    }

    fn use_kernel(
        &mut self,
        device: &wgpu::Device,
        renderer: &FurRenderer,
        structure: &FurStructure,
        kernel: SimKernel,
        shared: (Option<&std::sync::OnceLock<wgpu::Buffer>>, Option<&Arc<SimPool>>),
    ) -> Result<(), RenderError> {
        self.kernel = kernel;
        self.unrecorded = false;
        self.gpu_simulation = match kernel {
            SimKernel::Gpu => Some(GpuSimulation::for_copy(device, renderer, &self.fur, structure, shared)?),
            SimKernel::Cpu => None,
        };
        Ok(())
    }

    /// Makes `simulation` bend the strands exactly when the CPU kernel is in use.
    fn claim(&self, simulation: &mut Simulation) {
        let cpu = self.kernel == SimKernel::Cpu;
        if simulation.cpu_bending() != cpu {
            simulation.set_cpu_bending(cpu);
            if cpu {
                // The CPU kept time only: bend from the current inputs (a quasi-static jump).
                simulation.restart();
            }
        }
    }

    /// Replaces the structure (a new mesh or layer count), keeping the kernel and the textures;
    /// the host gives its stepper the same structure ([`FurStepper::set_structure`]).
    ///
    /// # Errors
    /// As [`FurDriver::new`].
    pub fn set_structure(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        structure: &FurStructure,
    ) -> Result<(), RenderError> {
        self.fur.set_structure(device, renderer, structure)?;
        let kernel = self.kernel;
        self.use_kernel(device, renderer, structure, kernel, (None, None))?;
        self.fur.prepare(queue, &self.frame);
        Ok(())
    }

    /// Replaces the shell and fin textures.
    ///
    /// # Errors
    /// As [`GpuFur::set_textures`].
    pub fn set_textures(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        textures: &FurTextures,
    ) -> Result<(), RenderError> {
        self.fur.set_textures(device, queue, renderer, textures)?;
        // The root colour and the slice count live in the fur's uniform.
        self.fur.prepare(queue, &self.frame);
        Ok(())
    }

    /// Rewrites the groom's density, clump and tint in place (no new textures or geometry): the
    /// cheap path for painting them; see [`GpuFur::set_groom`]. Lengths and directions change
    /// with [`FurDriver::set_structure`].
    ///
    /// # Errors
    /// As [`GpuFur::set_groom`].
    pub fn set_groom(&mut self, queue: &wgpu::Queue, groom: &pelt_core::groom::Groom) -> Result<(), RenderError> {
        self.fur.set_groom(queue, groom)?;
        // Whether the groom shades lives in the fur's uniform.
        self.fur.prepare(queue, &self.frame);
        Ok(())
    }

    /// The level of detail from the next frame on.
    pub fn set_level(&mut self, level: FurLevel) {
        self.frame.level = level;
    }

    /// The look (lighting, fading, density) from the next frame on; its wet terms follow the
    /// stepper's `[wet]` at each [`FurDriver::advance_to`].
    pub fn set_look(&mut self, look: FurLook) {
        self.frame.look = look;
    }

    /// The fur's model transform from the next frame on (the shared array stays in model space).
    pub fn set_world_from_model(&mut self, world_from_model: glam::Mat4) {
        self.frame.world_from_model = world_from_model;
    }

    /// Writes the fur's uniform now, for a frame drawn without an [`FurDriver::advance_to`]
    /// (paused) after a setter.
    pub fn prepare(&self, queue: &wgpu::Queue) {
        self.fur.prepare(queue, &self.frame);
    }

    /// This frame's uniform as the last [`FurDriver::advance_to`] or setter left it.
    #[must_use]
    pub fn frame(&self) -> &FurFrame {
        &self.frame
    }

    /// Advances `stepper` to `time_secs` (the clip at the same time): poses the base, plays the
    /// script, steps the simulation, and writes what the GPU needs (the CPU kernel's
    /// interpolated positions, or the GPU kernel's per-step inputs; the posed normals; the
    /// fur's uniform). Queue writes only.
    ///
    /// # Errors
    /// [`RenderError::Simulation`] for a pose or script key the simulation refuses;
    /// [`RenderError::Count`] for a stepper of another fur; the upload's errors.
    pub fn advance_to(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stepper: &mut FurStepper,
        time_secs: f64,
    ) -> Result<(), RenderError> {
        self.advance_with_clip_at(device, queue, stepper, time_secs, time_secs)
    }

    /// [`FurDriver::advance_to`] with the clip at `clip_time_secs` (a viewer's own clock).
    ///
    /// # Errors
    /// As [`FurDriver::advance_to`].
    pub fn advance_with_clip_at(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stepper: &mut FurStepper,
        time_secs: f64,
        clip_time_secs: f64,
    ) -> Result<(), RenderError> {
        self.fall_back_when_unrecorded();
        self.claim(stepper.simulation_mut());
        stepper.advance_with_clip_at(time_secs, clip_time_secs)?;
        self.show_wetness(queue, stepper)?;
        self.upload(device, queue, stepper.simulation(), stepper.moved_pose().map(|pose| &pose.normals[..]))
    }

    /// Whether [`FurDriver::record`] has steps to record: a host that submits the simulation in
    /// an encoder of its own can skip it on frames between steps.
    #[must_use]
    pub fn has_steps_to_record(&self) -> bool {
        self.unrecorded
    }

    /// Records the GPU simulation's pending steps into `encoder` (nothing with the CPU kernel).
    /// Call once per frame, before [`FurDriver::record_view`] and the render pass.
    ///
    /// # Errors
    /// [`RenderError::Count`] when the GPU simulation and the fur disagree (a bug).
    pub fn record(&mut self, encoder: &mut wgpu::CommandEncoder) -> Result<(), RenderError> {
        if let Some(gpu_simulation) = &mut self.gpu_simulation {
            gpu_simulation.dispatch(encoder, &mut self.fur)?;
        }
        self.unrecorded = false;
        Ok(())
    }

    /// Records the per-view GPU work into `encoder`: the silhouette pass choosing this view's
    /// fins (see [`FurRenderer::prepare_fins`]). Once per view and frame, after
    /// [`FurDriver::record`].
    pub fn record_view(&self, encoder: &mut wgpu::CommandEncoder, renderer: &FurRenderer, view: &FurView) {
        renderer.prepare_fins(encoder, view, &self.fur);
    }

    /// Draws the fur into the host's `pass` (after its opaque geometry).
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        renderer: &FurRenderer,
        view: &FurView,
        settings: &FurDrawSettings,
    ) {
        renderer.draw(pass, view, &self.fur, settings);
    }

    /// The fur's GPU data.
    #[must_use]
    pub fn fur(&self) -> &GpuFur {
        &self.fur
    }
}

fn states(kernel: SimKernel) -> FurStates {
    // The CPU simulation interpolates, so one uploaded state is all the GPU needs; the GPU one
    // writes two states and the vertex shader interpolates.
    match kernel {
        SimKernel::Cpu => FurStates::One,
        SimKernel::Gpu => FurStates::Two,
    }
}

impl From<SimError> for RenderError {
    fn from(error: SimError) -> Self {
        Self::Simulation(error)
    }
}
