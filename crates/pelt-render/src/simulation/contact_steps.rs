//! The pending steps' contact, written where their kernels read it: a fur's own contact buffer,
//! or its block of its pool's (`pool_contact`) where it steps with its pool.

use pelt_core::sim::{ContactStep, ContactStrands, Simulation};

use super::pool_contact::{CopySteps, PoolBuffers};
use super::{GpuSimulation, RING_SLOTS};
use crate::RenderError;
use crate::contact::{GpuContact, Skin};
use crate::fur::GpuFur;
use crate::requirements::check_size;

impl GpuSimulation {
    /// The pending steps' contact in the fur's own buffer: the skin once found, room for the
    /// colliders, the grasp's weights and the mesh colliders' fields (the slots are written with
    /// the steps).
    pub(super) fn prepare_own_contact(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        simulation: &Simulation,
        fur: &GpuFur,
        strands: &ContactStrands<'_>,
    ) -> Result<(), RenderError> {
        let mut rebind = false;
        if !self.skin_found && simulation.has_skin_setup() {
            let skin = Skin::of(strands);
            check_size(device, "simulation contact", GpuContact::bytes(&skin, self.contact.slot_colliders()))?;
            self.contact.set_skin(device, strands.rest_roots, &skin);
            self.skin_found = true;
            rebind = true;
        }
        // Room for the pending steps' colliders (a coat nothing touches keeps none).
        rebind |= self.contact.make_room((device, queue), &self.pending_contact)?;
        self.contact.write_strands(queue, strands);
        if self.contact.upload_fields(device, &self.pending_contact)? || rebind {
            // The fields or the contact buffer is new: bind it.
            self.bind_groups.clear();
            for buffer in [fur.current_positions(), fur.previous_positions()] {
                self.bind_group_for(device, buffer)?;
            }
        }
        Ok(())
    }

    /// The pending steps with contact in the copy's block of its pool's contact (nothing while
    /// no copy of the pool has stepped with contact).
    pub(super) fn prepare_pooled_contact(
        &self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        simulation: &Simulation,
        fur: &GpuFur,
        strands: &ContactStrands<'_>,
    ) -> Result<(), RenderError> {
        let steps: Vec<(usize, &ContactStep)> = (self.pending_contact.iter().enumerate())
            .filter(|(_, step)| step.is_active())
            .map(|(slot, step)| (((self.ring + slot as u64) % RING_SLOTS) as usize, step))
            .collect();
        if steps.is_empty() && !self.pool.contact.is_made() {
            return Ok(());
        }
        let pipeline = self.pipelines.pooled_contact(device)?;
        let copy = CopySteps {
            copy: self.slot,
            steps,
            strands,
            skin_found: simulation.has_skin_setup(),
            reach: self.contact.reach(),
        };
        let buffers = PoolBuffers {
            strands: &self.pool.strands,
            state: &self.pool.state,
            wet: &self.pool.wet,
            rest: &self.rest_segments,
            positions: fur.current_positions().buffer(),
        };
        self.pool.contact.prepare_copy((device, queue), pipeline, &copy, &buffers)
    }
}
