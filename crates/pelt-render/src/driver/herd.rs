//! A herd's frame: every member advanced in one parallel pass, stepped on the GPU in one
//! dispatch a step, listed per view in one compute pass, and cast into each shadow pass in one
//! draw.

use pelt_core::sim::{FurStepper, HerdInstance};

use super::FurDriver;
use crate::RenderError;
use crate::renderer::{FurDrawSettings, FurRenderer};
use crate::simulation::GpuSimulation;
use crate::view::FurView;

impl FurDriver {
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

    /// [`FurDriver::record`] for every driver of `drivers` (a herd's members): step by step,
    /// the contact-free steps of every member on the GPU kernel share one compute pass, and those
    /// of the members made together ([`FurDriver::herd_with_asset`]) one dispatch, so a step
    /// costs a herd one dispatch, not one a member. Returns the compute dispatches recorded.
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

    /// [`FurDriver::draw`] for every driver of `drivers` (a herd's members), in that order: into
    /// a shadow map, the members made together cast in one draw a pass
    /// ([`FurRenderer::draw_herd`]). Returns the draws recorded.
    pub fn draw_herd<'a>(
        pass: &mut wgpu::RenderPass<'_>,
        renderer: &FurRenderer,
        view: &FurView,
        drivers: impl IntoIterator<Item = &'a FurDriver>,
        settings: &FurDrawSettings,
    ) -> usize {
        renderer.draw_herd(pass, view, drivers.into_iter().map(|driver| &driver.fur), settings)
    }
}
