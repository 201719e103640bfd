//! What a driver gives the GPU after a step: the CPU kernel's positions or the GPU kernel's
//! steps, the posed normals, the wetness and the frame's uniform; and the fall-back to the CPU
//! kernel when a host leaves the GPU kernel's steps unrecorded.

use pelt_core::sim::{FurStepper, SimError, Simulation};

use super::{FurDriver, SimKernel};
use crate::RenderError;

impl FurDriver {
    /// The stepper's wetness and what it does to the look (`[wet]`), for the coming frame: the
    /// values uploaded while any vertex is wet, the shaders' wet paths off when none is.
    pub(super) fn show_wetness(&mut self, queue: &wgpu::Queue, stepper: &FurStepper) -> Result<(), RenderError> {
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
    pub(super) fn fall_back_when_unrecorded(&mut self) {
        if self.unrecorded && self.kernel == SimKernel::Gpu {
            self.use_cpu_kernel("the GPU kernel's steps were never recorded");
        }
    }

    /// From now on the stepper's simulation bends the strands (`claim` turns its bending on).
    pub(super) fn use_cpu_kernel(&mut self, reason: &str) {
        self.gpu_simulation = None;
        self.kernel = SimKernel::Cpu;
        self.kernel_reason = reason.to_owned();
        self.unrecorded = false;
    }

    pub(super) fn upload(
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
    pub(super) fn finish_upload(
        &mut self,
        queue: &wgpu::Queue,
        moved_normals: Option<&[glam::Vec3]>,
    ) -> Result<(), RenderError> {
        if let Some(normals) = moved_normals {
            self.fur.set_base_normals(queue, normals)?;
        }
        self.fur.prepare(queue, &self.frame);
        Ok(())
    }
}
