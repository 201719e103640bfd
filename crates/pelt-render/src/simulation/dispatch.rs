//! Recording the prepared steps: one compute pass a step (a second, dispatched indirectly, for
//! a step with contact), a herd's contact-free steps sharing one pass, and the copies made
//! together stepping in one dispatch (two with contact, whatever their number).

use std::sync::Arc;

use pelt_core::sim::ContactStep;

use super::{GpuSimulation, RING_SLOTS, STEP_SLOT_BYTES, SimPool, solve_kernel};
use crate::RenderError;
use crate::fur::GpuFur;
use crate::sim_pipelines::PooledStep;

impl GpuSimulation {
    /// Records the prepared steps into `encoder`: per step, [`GpuFur::swap_states`] and one
    /// compute pass writing the new current state (with contact, a second one, dispatched
    /// indirectly, solving the strands the first listed). Does nothing when no step is pending.
    ///
    /// # Errors
    /// [`RenderError::Count`] when `fur` is not the fur last given to
    /// [`GpuSimulation::prepare`] (its buffers are unknown); no state is swapped then.
    pub fn dispatch(&mut self, encoder: &mut wgpu::CommandEncoder, fur: &mut GpuFur) -> Result<(), RenderError> {
        Self::dispatch_all(encoder, [(self, fur)]).map(|_| ())
    }

    /// [`GpuSimulation::dispatch`] for every simulation of `members` (a herd's, each with its
    /// fur), step by step: each step's contact-free dispatches of every member share one compute
    /// pass (each writes its own buffers only), and the members made together
    /// ([`crate::FurDriver::herd_with_asset`]) that take it step in one dispatch (their steps
    /// copied into their pool's array first); a step with contact keeps its own passes. Returns
    /// the compute dispatches recorded.
    ///
    /// # Errors
    /// As [`GpuSimulation::dispatch`], checked for every member before anything is recorded.
    pub(crate) fn dispatch_all<'a>(
        encoder: &mut wgpu::CommandEncoder,
        members: impl IntoIterator<Item = (&'a mut Self, &'a mut GpuFur)>,
    ) -> Result<usize, RenderError> {
        let mut members: Vec<_> =
            members.into_iter().filter(|(simulation, _)| !simulation.pending.is_empty()).collect();
        let mut groups = Vec::with_capacity(members.len());
        for (simulation, fur) in &members {
            groups.push(simulation.state_groups(fur)?);
            let contact = simulation.pending_contact.iter().any(ContactStep::is_active);
            if simulation.pooled && contact && simulation.pool.contact.run().is_none() {
                return Err(RenderError::Count {
                    what: "pool contact buffers prepared for a step with contact",
                    expected: 1,
                    got: 0,
                    rule: "call GpuSimulation::prepare before dispatching",
                });
            }
        }
        let mut dispatches = 0;
        for ((simulation, _), &groups) in members.iter_mut().zip(&groups) {
            dispatches += simulation.weigh_touch(encoder, groups);
        }
        let steps = members.iter().map(|(simulation, _)| simulation.pending.len()).max().unwrap_or(0);
        for slot in 0..steps {
            let mut shared = Vec::new();
            let mut alone = Vec::new();
            let mut pooled_contact = Vec::new();
            for (k, (simulation, fur)) in members.iter_mut().enumerate() {
                if slot >= simulation.pending.len() {
                    continue;
                }
                fur.swap_states();
                if simulation.vertex_count == 0 {
                    continue;
                }
                match simulation.pending_contact.get(slot).filter(|step| step.is_active()) {
                    Some(_) if simulation.pooled => pooled_contact.push(k),
                    Some(_) => alone.push(k),
                    None => shared.push(k),
                }
            }
            let (pools, lone) = pool_runs(&members, &shared);
            // Each pool's steps side by side in its array, in the order its run dispatches them.
            for run in &pools {
                for (i, &k) in run.members.iter().enumerate() {
                    let simulation = &members[k].0;
                    let (from, to) = (simulation.slot_offset(slot), i as u64 * STEP_SLOT_BYTES);
                    encoder.copy_buffer_to_buffer(
                        &simulation.step_uniforms,
                        from,
                        &run.pool.steps,
                        to,
                        STEP_SLOT_BYTES,
                    );
                }
            }
            if !shared.is_empty() {
                let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                    label: Some("pelt simulation step"),
                    timestamp_writes: None,
                });
                for run in &pools {
                    let grid = members[run.members[0]].0.grid;
                    pass.set_pipeline(&run.step.pipeline);
                    pass.set_bind_group(0, run.bind_group, &[]);
                    pass.dispatch_workgroups(grid[0], grid[1], run.members.len() as u32);
                    dispatches += 1;
                }
                for &k in &lone {
                    let simulation = &members[k].0;
                    pass.set_pipeline(&simulation.pipelines.step);
                    pass.set_bind_group(
                        0,
                        simulation.step_group(groups[k], slot),
                        &[simulation.slot_offset(slot) as u32],
                    );
                    pass.dispatch_workgroups(simulation.grid[0], simulation.grid[1], 1);
                    dispatches += 1;
                }
            }
            for run in contact_runs(&members, &pooled_contact) {
                dispatches += record_contact_run(encoder, &members, &run, slot);
            }
            for &k in &alone {
                dispatches += members[k].0.contact_step(encoder, groups[k], slot);
            }
        }
        for (simulation, _) in &mut members {
            simulation.ring = (simulation.ring + simulation.pending.len() as u64) % RING_SLOTS;
            simulation.pending.clear();
            simulation.dispatched_history = simulation.pending_history;
            simulation.pending_contact.clear();
        }
        Ok(dispatches)
    }

    /// The pooled step's kernel and bind group, when this fur steps with its pool.
    fn pooled_step(&self, fur: &GpuFur) -> Option<(&PooledStep, &wgpu::BindGroup)> {
        let bind_group = self.pool.pooled_group((&self.rest_segments, fur.current_positions().buffer()));
        self.pipelines.pooled_built().zip(bind_group).filter(|_| self.pooled)
    }

    /// The bind groups of `fur`'s two states: the one step 0 writes, then the other.
    fn state_groups(&self, fur: &GpuFur) -> Result<(usize, usize), RenderError> {
        let find = |state: wgpu::BufferSlice<'_>| {
            self.bind_groups.iter().position(|((b, at), _)| b == state.buffer() && *at == state.offset())
        };
        // Step `slot` writes the buffer that is current after `slot + 1` swaps.
        match (find(fur.previous_positions()), find(fur.current_positions())) {
            (Some(next), Some(after_next)) => Ok((next, after_next)),
            _ => Err(RenderError::Count {
                what: "shared-array buffers of this fur known to the GPU simulation",
                expected: 2,
                got: 0,
                rule: "call GpuSimulation::prepare with the same fur first",
            }),
        }
    }

    /// The bind group pending step `slot` writes through.
    fn step_group(&self, (next, after_next): (usize, usize), slot: usize) -> &wgpu::BindGroup {
        &self.bind_groups[if slot.is_multiple_of(2) { next } else { after_next }].1
    }

    /// The touch's weights, once a touch began (its roots are those of the last step: the
    /// state that is current now); the dispatches recorded.
    fn weigh_touch(&mut self, encoder: &mut wgpu::CommandEncoder, (_, after_next): (usize, usize)) -> usize {
        if !std::mem::take(&mut self.weigh_touch) || self.vertex_count == 0 {
            return 0;
        }
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("pelt simulation touch weights"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipelines.touch);
        pass.set_bind_group(0, &self.bind_groups[after_next].1, &[self.slot_offset(0) as u32]);
        pass.dispatch_workgroups(self.grid[0], self.grid[1], 1);
        1
    }

    /// Pending step `slot` with contact: the step's pass listing the strands near something,
    /// then the solve's, dispatched indirectly; the dispatches recorded.
    fn contact_step(&self, encoder: &mut wgpu::CommandEncoder, groups: (usize, usize), slot: usize) -> usize {
        let Some(step) = self.pending_contact.get(slot) else { return 0 };
        let bind_group = self.step_group(groups, slot);
        let offset = [self.slot_offset(slot) as u32];
        self.contact.clear_work(encoder);
        {
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pelt simulation step"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipelines.contact);
            pass.set_bind_group(0, bind_group, &offset);
            pass.dispatch_workgroups(self.grid[0], self.grid[1], 1);
        }
        // The listed strands' workgroups become the solve's dispatch arguments.
        self.contact.copy_work_groups(encoder);
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("pelt simulation contact"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipelines.solve[solve_kernel(step)]);
        pass.set_bind_group(0, bind_group, &offset);
        pass.dispatch_workgroups_indirect(&self.contact.work_groups, 0);
        2
    }

    /// The byte offset of pending step `slot`'s uniform in the ring.
    pub(super) fn slot_offset(&self, slot: usize) -> u64 {
        (self.ring + slot as u64) % RING_SLOTS * STEP_SLOT_BYTES
    }
}

/// Two or more copies of one pool stepping in one dispatch.
struct PoolRun<'a> {
    pool: &'a SimPool,
    step: &'a PooledStep,
    bind_group: &'a wgpu::BindGroup,
    /// Indices into the members, in the order their steps are copied.
    members: Vec<usize>,
}

/// `shared` (members stepping without contact) split into runs that step in one dispatch (two or
/// more copies of one pool, in the order first met) and those that step alone.
fn pool_runs<'a>(members: &'a [(&mut GpuSimulation, &mut GpuFur)], shared: &[usize]) -> (Vec<PoolRun<'a>>, Vec<usize>) {
    let mut runs: Vec<PoolRun<'a>> = Vec::new();
    let mut lone = Vec::new();
    for &k in shared {
        let (simulation, fur) = &members[k];
        let Some((step, bind_group)) = simulation.pooled_step(fur) else {
            lone.push(k);
            continue;
        };
        match runs.iter_mut().find(|run| std::ptr::eq(run.pool, &*simulation.pool)) {
            Some(run) => run.members.push(k),
            None => runs.push(PoolRun { pool: &simulation.pool, step, bind_group, members: vec![k] }),
        }
    }
    let (pooled, single): (Vec<_>, Vec<_>) = runs.into_iter().partition(|run| run.members.len() > 1);
    lone.extend(single.into_iter().flat_map(|run| run.members));
    (pooled, lone)
}

/// `pooled` (members stepping with contact through their pools) split by pool, in the order first
/// met.
fn contact_runs(members: &[(&mut GpuSimulation, &mut GpuFur)], pooled: &[usize]) -> Vec<Vec<usize>> {
    let mut runs: Vec<Vec<usize>> = Vec::new();
    for &k in pooled {
        let pool = &members[k].0.pool;
        match runs.iter_mut().find(|run| Arc::ptr_eq(&members[run[0]].0.pool, pool)) {
            Some(run) => run.push(k),
            None => runs.push(vec![k]),
        }
    }
    runs
}

/// Pending step `slot` of one pool's copies with contact (`run`): their steps copied side by
/// side, the pooled step listing every copy's strands near something, then the pooled solve,
/// dispatched indirectly; the dispatches recorded.
fn record_contact_run(
    encoder: &mut wgpu::CommandEncoder,
    members: &[(&mut GpuSimulation, &mut GpuFur)],
    run: &[usize],
    slot: usize,
) -> usize {
    let first = &members[run[0]].0;
    // Made by every member's prepare (checked before recording).
    let (Some(contact), Some(kernels)) = (first.pool.contact.run(), first.pipelines.pooled_contact_built()) else {
        return 0;
    };
    for (i, &k) in run.iter().enumerate() {
        let simulation = &members[k].0;
        encoder.copy_buffer_to_buffer(
            &simulation.step_uniforms,
            simulation.slot_offset(slot),
            &contact.steps,
            i as u64 * STEP_SLOT_BYTES,
            STEP_SLOT_BYTES,
        );
    }
    // The kernel with the code the busiest copy's colliders need.
    let solve = run.iter().filter_map(|&k| members[k].0.pending_contact.get(slot)).map(solve_kernel).max().unwrap_or(0);
    encoder.clear_buffer(&contact.work, 0, Some(16));
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("pelt simulation pooled step"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&kernels.contact);
        pass.set_bind_group(0, &contact.bind_group, &[]);
        pass.dispatch_workgroups(first.grid[0], first.grid[1], run.len() as u32);
    }
    encoder.copy_buffer_to_buffer(&contact.work, 0, &contact.work_groups, 0, 12);
    let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
        label: Some("pelt simulation pooled contact"),
        timestamp_writes: None,
    });
    pass.set_pipeline(&kernels.solve[solve]);
    pass.set_bind_group(0, &contact.bind_group, &[]);
    pass.dispatch_workgroups_indirect(&contact.work_groups, 0);
    2
}
