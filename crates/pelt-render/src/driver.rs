//! [`FurDriver`]: one fur from its simulation to the host's render pass, the frame every host
//! (the `pelt` commands, the viewer, the web page, bevy_pelt, the examples) makes the same way.
//!
//! A frame is three calls: [`FurDriver::advance_to`] (pose, script, simulation step, queue
//! writes), [`FurDriver::record`] (the GPU work before the render pass: the GPU simulation's
//! steps and the silhouette fins) and [`FurDriver::draw`] (into the host's pass).

use std::fmt;
use std::time::Instant;

use pelt_core::sim::{FurStepper, HerdInstance, SimError, SimParams, Simulation};
use pelt_core::{FurStructure, texture::FurTextures};

use crate::RenderError;
use crate::asset::FurAsset;
use crate::fur::{FurStates, GpuFur};
use crate::lod::FurLevel;
use crate::object::{FurFrame, FurLook};
use crate::renderer::{FurDrawSettings, FurRenderer};
use crate::simulation::GpuSimulation;
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

/// Steps per timing run and runs per kernel when choosing ([`KernelChoice::Auto`]).
const TIMING_STEPS: u32 = 3;
const TIMING_RUNS: usize = 5;

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
        let mut drivers = Vec::with_capacity(furs.len());
        for fur in furs {
            let mut driver = Self {
                fur,
                gpu_simulation: None,
                kernel,
                kernel_reason: kernel_reason.clone(),
                frame: FurFrame::default(),
                unrecorded: false,
            };
            // Copies grown as the asset share its GPU rest segments.
            let shared_rest = asset.grown_as(structure).then_some(&*asset.simulation_rest);
            driver.use_kernel(device, renderer, structure, kernel, shared_rest)?;
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
        self.use_kernel(device, renderer, structure, kernel, None)?;
        self.fur.prepare(queue, &self.frame);
        Ok(())
    }

    fn use_kernel(
        &mut self,
        device: &wgpu::Device,
        renderer: &FurRenderer,
        structure: &FurStructure,
        kernel: SimKernel,
        shared_rest: Option<&std::sync::OnceLock<wgpu::Buffer>>,
    ) -> Result<(), RenderError> {
        self.kernel = kernel;
        self.unrecorded = false;
        self.gpu_simulation = match kernel {
            SimKernel::Gpu => Some(GpuSimulation::for_copy(device, renderer, &self.fur, structure, shared_rest)?),
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
        self.use_kernel(device, renderer, structure, kernel, None)?;
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

    /// [`FurDriver::advance_to`] for a herd: `drivers[k]` with `steppers[k]`, placed as
    /// `instances[k]`, each at its own clip time. The bases are posed (and on the CPU kernel the
    /// strands bent) in one parallel pass ([`FurStepper::advance_herd`]), then each member's GPU
    /// inputs are written: the CPU kernel's positions, or the GPU kernel's steps for
    /// [`FurDriver::record`]. Each member may have its own kernel.
    ///
    /// # Errors
    /// [`RenderError::Count`] unless there is one driver, stepper and instance per member; as
    /// [`FurDriver::advance_to`].
    pub fn advance_herd(
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        drivers: &mut [FurDriver],
        steppers: &mut [FurStepper],
        instances: &[HerdInstance],
        time_secs: f64,
    ) -> Result<(), RenderError> {
        for (what, got) in [("steppers of a herd", steppers.len()), ("instances of a herd", instances.len())] {
            if got != drivers.len() {
                return Err(RenderError::Count { what, expected: drivers.len(), got, rule: "one per driver" });
            }
        }
        for (driver, stepper) in drivers.iter_mut().zip(steppers.iter_mut()) {
            driver.claim_stepper(stepper);
        }
        FurStepper::advance_herd(steppers, instances, time_secs)?;
        for (driver, stepper) in drivers.iter_mut().zip(steppers.iter()) {
            driver.show_claimed(device, queue, stepper)?;
        }
        Ok(())
    }

    /// The first half of a step a host takes itself (a herd member it steps with the others, as
    /// the viewer does; [`FurDriver::advance_herd`] takes both halves): call before stepping
    /// `stepper`. On the GPU kernel its simulation then keeps time and poses while the GPU
    /// bends; on the CPU kernel it bends.
    pub fn claim_stepper(&mut self, stepper: &mut FurStepper) {
        self.fall_back_when_unrecorded();
        self.claim(stepper.simulation_mut());
    }

    /// The second half: what `stepper` stepped since [`FurDriver::claim_stepper`], on this
    /// driver's kernel (the CPU's positions, or the steps for [`FurDriver::record`]), with its
    /// wetness and posed normals.
    ///
    /// # Errors
    /// As [`FurDriver::advance_to`].
    pub fn show_claimed(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        stepper: &FurStepper,
    ) -> Result<(), RenderError> {
        self.show_wetness(queue, stepper)?;
        self.upload(device, queue, stepper.simulation(), stepper.moved_pose().map(|pose| &pose.normals[..]))
    }

    /// The stepper's wetness and what it does to the look (`[wet]`), for the coming frame: the
    /// values uploaded while any vertex is wet, the shaders' wet paths off when none is.
    fn show_wetness(&mut self, queue: &wgpu::Queue, stepper: &FurStepper) -> Result<(), RenderError> {
        let wetness = stepper.wetness();
        self.show_wet(queue, (!wetness.is_dry()).then(|| wetness.values()), stepper.wet())
    }

    /// Shows a wetness simulated elsewhere (a host whose [`FurStepper`] lives apart, as for
    /// [`FurDriver::show_state`]): `wetness` per base vertex in `0..=1` (`None` when dry, which
    /// draws the dry bytes) and what it does to the look (`wet`, the preset's `[wet]`).
    ///
    /// # Errors
    /// [`RenderError::Count`] unless there are `V` values.
    pub fn show_wet(
        &mut self,
        queue: &wgpu::Queue,
        wetness: Option<&[f32]>,
        wet: &pelt_core::wet::WetParams,
    ) -> Result<(), RenderError> {
        self.frame.wet = wetness.is_some();
        self.frame.look = self.frame.look.with_wet(wet);
        if let Some(values) = wetness {
            self.fur.set_wetness(queue, values)?;
        }
        Ok(())
    }

    /// Lets `step` change and step `simulation` itself (a test harness replaying recorded
    /// inputs), then writes what the GPU needs as [`FurDriver::advance_to`] does.
    ///
    /// # Errors
    /// `step`'s error as [`RenderError::Simulation`]; the upload's errors.
    pub fn step_with(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        simulation: &mut Simulation,
        step: impl FnOnce(&mut Simulation) -> Result<(), SimError>,
    ) -> Result<(), RenderError> {
        self.fall_back_when_unrecorded();
        self.claim(simulation);
        step(simulation)?;
        self.upload(device, queue, simulation, None)
    }

    /// Draws a state simulated elsewhere: a host whose [`FurStepper`] lives apart from its GPU
    /// objects (Bevy's main and render worlds) hands over the stepper's output
    /// ([`Simulation::positions`], model space) and, when the base moved, its normals. This is
    /// the CPU kernel's upload: a driver on the GPU kernel switches to the CPU kernel.
    ///
    /// # Errors
    /// [`RenderError::Count`] unless there are `(L + 1) * V` positions and `V` normals.
    pub fn show_state(
        &mut self,
        queue: &wgpu::Queue,
        positions: &[glam::Vec3],
        moved_normals: Option<&[glam::Vec3]>,
    ) -> Result<(), RenderError> {
        if self.kernel == SimKernel::Gpu {
            self.use_cpu_kernel("the host hands over states simulated on the CPU");
        }
        self.fur.set_positions(queue, positions)?;
        self.frame.interpolation = 1.0;
        self.finish_upload(queue, moved_normals)
    }

    /// Shows what `stepper` stepped on its own (a herd's member in a host that steps its herd
    /// itself; [`FurDriver::advance_herd`] does both): its positions, its posed normals when the
    /// base moved and its wetness, as [`FurDriver::show_state`] (the CPU kernel's upload) and
    /// [`FurDriver::show_wet`].
    ///
    /// # Errors
    /// As [`FurDriver::show_state`], for a stepper of another fur.
    pub fn show_stepped(&mut self, queue: &wgpu::Queue, stepper: &FurStepper) -> Result<(), RenderError> {
        let wetness = stepper.wetness();
        self.show_wet(queue, (!wetness.is_dry()).then(|| wetness.values()), stepper.wet())?;
        let normals = stepper.moved_pose().map(|pose| &pose.normals[..]);
        self.show_state(queue, stepper.simulation().positions(), normals)
    }

    /// With the GPU kernel, steps prepared and never recorded mean the host does not record:
    /// the CPU bends from now on.
    fn fall_back_when_unrecorded(&mut self) {
        if self.unrecorded && self.kernel == SimKernel::Gpu {
            self.use_cpu_kernel("the GPU kernel's steps were never recorded");
        }
    }

    /// From now on the stepper's simulation bends the strands (`claim` turns its bending on).
    fn use_cpu_kernel(&mut self, reason: &str) {
        self.gpu_simulation = None;
        self.kernel = SimKernel::Cpu;
        self.kernel_reason = reason.to_owned();
        self.unrecorded = false;
    }

    fn upload(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        simulation: &Simulation,
        moved_normals: Option<&[glam::Vec3]>,
    ) -> Result<(), RenderError> {
        match &mut self.gpu_simulation {
            Some(gpu_simulation) => {
                gpu_simulation.prepare(device, queue, simulation, &self.fur)?;
                self.unrecorded = gpu_simulation.pending_steps() > 0;
                self.frame.interpolation = simulation.alpha();
            }
            None => {
                self.fur.set_positions(queue, simulation.positions())?;
                self.frame.interpolation = 1.0;
            }
        }
        self.finish_upload(queue, moved_normals)
    }

    /// The posed normals (when the base moved) and this frame's uniform.
    fn finish_upload(&mut self, queue: &wgpu::Queue, moved_normals: Option<&[glam::Vec3]>) -> Result<(), RenderError> {
        if let Some(normals) = moved_normals {
            self.fur.set_base_normals(queue, normals)?;
        }
        self.fur.prepare(queue, &self.frame);
        Ok(())
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

    /// [`FurDriver::record`] for every driver of `drivers` (a herd's members): step by step,
    /// the contact-free steps of every member on the GPU kernel share one compute pass, so a
    /// step costs the herd one pass, not one a member. Returns the compute passes recorded.
    ///
    /// # Errors
    /// As [`FurDriver::record`], checked for every member before anything is recorded.
    pub fn record_herd<'a>(
        encoder: &mut wgpu::CommandEncoder,
        drivers: impl IntoIterator<Item = &'a mut FurDriver>,
    ) -> Result<usize, RenderError> {
        let mut drivers: Vec<&mut FurDriver> = drivers.into_iter().collect();
        let members = drivers
            .iter_mut()
            .filter_map(|driver| driver.gpu_simulation.as_mut().map(|simulation| (simulation, &mut driver.fur)));
        let passes = GpuSimulation::dispatch_all(encoder, members)?;
        for driver in drivers {
            driver.unrecorded = false;
        }
        Ok(passes)
    }

    /// Records the per-view GPU work into `encoder`: the silhouette pass choosing this view's
    /// fins (see [`FurRenderer::prepare_fins`]). Once per view and frame, after
    /// [`FurDriver::record`].
    pub fn record_view(&self, encoder: &mut wgpu::CommandEncoder, renderer: &FurRenderer, view: &FurView) {
        renderer.prepare_fins(encoder, view, &self.fur);
    }

    /// [`FurDriver::record_view`] for every driver of `drivers` (a herd's members), in one compute
    /// pass ([`FurRenderer::prepare_fins_of`]).
    pub fn record_views<'a>(
        encoder: &mut wgpu::CommandEncoder,
        renderer: &FurRenderer,
        view: &FurView,
        drivers: impl IntoIterator<Item = &'a FurDriver>,
    ) {
        renderer.prepare_fins_of(encoder, view, drivers.into_iter().map(|driver| &driver.fur));
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
