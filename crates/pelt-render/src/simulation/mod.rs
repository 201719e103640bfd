//! [`GpuSimulation`]: the steps of a [`pelt_core::Simulation`] as a compute pass that writes the
//! new state straight into the shared-array buffers a [`GpuFur`] draws from.
//!
//! The CPU `Simulation` stays the controller (time, fixed steps, touch, field, parameters, posed
//! roots), with its own bending turned off ([`Simulation::set_cpu_bending`]); after each
//! `advance_to` the host calls [`GpuSimulation::prepare`] (small queue writes: one uniform slot
//! per step, and a per-strand input only when its [`InputVersions`] counter moved) and
//! [`GpuSimulation::dispatch`] (one compute pass per step into the host's encoder, swapping the
//! fur's states). What changes every step per strand is computed here: the inertial force
//! (from the simulation's [`InertiaStep`]s and the roots) and the touch's weights (when a touch
//! begins). Nothing is read back and the shared array never crosses the bus.

use std::sync::{Arc, OnceLock};

use pelt_core::FurStructure;
use pelt_core::sim::{ContactStep, InputVersions, Simulation, kernel_rest};

use crate::RenderError;
use crate::contact::{CONTACT_SLOTS, GpuContact, Skin};
use crate::fur::GpuFur;
use crate::renderer::FurRenderer;
use crate::requirements::{ErrorScope, check_size};
use crate::sim_pipelines::SimPipelines;
use pool::Range;

mod contact_steps;
mod dispatch;
mod inputs;
mod pool;
mod pool_contact;
mod step;
mod wet;

pub(crate) use pool::SimPool;

use step::{STEP_SLOT_BYTES, StepUniform, settle_inertia, step_uniform};
use wet::WetInputs;

/// Strands per workgroup (`@workgroup_size` in `simulation.wgsl`).
const WORKGROUP: u32 = 64;
/// Which of the `solve_contact` pipelines (`SimPipelines::solve`) solves `step`'s listed
/// strands: the one compiled without colliders' code (0), without mesh colliders' (1), or with
/// both (2).
fn solve_kernel(step: &ContactStep) -> usize {
    if step.colliders.iter().any(|c| c.mesh.is_some()) { 2 } else { usize::from(!step.colliders.is_empty()) }
}

/// Steps one prepare/dispatch pair can hold: only the last two states are ever kept.
const STEP_SLOTS: usize = 2;
/// Uniform slots in the ring the steps take in turn: a host recording up to this many steps into
/// one submission gives each its own inputs (the queue writes all land before it runs).
const RING_SLOTS: u64 = 64;
// Each ring slot has its own contact slot, for the same reason.
const _: () = assert!(RING_SLOTS == CONTACT_SLOTS as u64);
/// Storage buffers the compute stage binds (WebGPU's default limit).
const STORAGE_BUFFERS: u32 = 8;

/// Bytes per strand of the resident inputs (root and stability, frame, field) and of the state
/// the GPU carries (last two roots and the touch weight, force, its rate of change).
const STRAND_BYTES: u64 = 3 * 16;
const STATE_BYTES: u64 = 4 * 16;

/// A fur's simulation on the GPU: bends every strand exactly as `pelt_core::sim` defines it
/// (Equation 1 as Pelt implements it, gravity, the wind with the same noise and seeds, the user
/// field and the touch over it, the inertial force, posed roots and frames) in a compute pass,
/// one invocation per strand, which also steps each strand's inertial force; a touch's weights
/// come from a small pass when it begins. A step with contact (skin, colliders, a grasp) lists
/// the strands its screen cannot clear and solves them in a second pass, dispatched indirectly. Each step writes the new state into
/// [`GpuFur::current_positions`] after
/// [`GpuFur::swap_states`]; the fur's vertex shader interpolates between its two states.
///
/// Per frame: `simulation.advance_to(t)`, then [`GpuSimulation::prepare`] and
/// [`GpuSimulation::dispatch`] into the host's encoder, then `fur.prepare` with
/// `interpolation: simulation.alpha()`. Nothing blocks or reads back. The device needs
/// [`GpuSimulation::required_downlevel_flags`] and [`GpuSimulation::required_limits`] (every
/// WebGPU, Vulkan, Metal, DX12 and GL 4.3 / GLES 3.1 device has them).
#[derive(Debug)]
pub struct GpuSimulation {
    /// Its kernels, shared with every fur simulated on the device through one renderer.
    pipelines: SimPipelines,
    step_uniforms: wgpu::Buffer,
    rest_segments: wgpu::Buffer,
    /// The rest segments are the asset's, counted with it.
    rest_shared: bool,
    /// The buffers of the copies made with this fur (its own when it was made alone), and its
    /// ranges there: strand inputs, strand state, wet strands.
    pool: Arc<SimPool>,
    ranges: [Range; 3],
    /// Whether its steps run in its pool's dispatches (with contact, through the pool's contact).
    pooled: bool,
    /// Its slot in its pool.
    slot: u32,
    /// The most workgroups a pooled contact list may ask to solve: the grid's width for every
    /// copy of the pool, within the device's limit.
    pooled_solve_cap: u32,
    wet: WetInputs,
    /// One bind group per shared-array state written so far (a fur has one or two), by its
    /// buffer and offset.
    bind_groups: Vec<((wgpu::Buffer, u64), wgpu::BindGroup)>,
    vertex_count: u32,
    layers: u32,
    grid: [u32; 2],
    /// The input versions `strands` holds (`None`: nothing uploaded yet), and the stability
    /// where no map is set that its roots section was written with.
    uploaded: Option<(InputVersions, f32)>,
    /// A touch began on the last step's roots: the `weigh_touch` pass runs before the next step.
    weigh_touch: bool,
    /// The touch's weights are the CPU's, uploaded beside the field (it began on roots no step
    /// used), not the `weigh_touch` pass's.
    touch_uploaded: bool,
    /// `Simulation::steps_taken` at the last prepare (`None`: replay the last two steps).
    seen_steps: Option<u64>,
    /// Whether the contact buffer holds the simulation's skin planes and triangles.
    skin_found: bool,
    /// Steps prepared and not yet dispatched (at most [`STEP_SLOTS`], in slot order).
    pending: Vec<StepUniform>,
    /// The ring slot of the first pending step.
    ring: u64,
    /// Steps the inertial state has seen since it started (up to 2) after the dispatched steps,
    /// and after the pending ones.
    dispatched_history: u8,
    pending_history: u8,
    /// The contact buffer (`simulation_contact.wgsl`).
    contact: GpuContact,
    /// The pending steps' contact, slot by slot.
    pending_contact: Vec<ContactStep>,
}

impl GpuSimulation {
    /// Downlevel capabilities the GPU simulation needs: compute shaders, and indirect dispatch
    /// for contact's second pass.
    #[must_use]
    pub fn required_downlevel_flags() -> wgpu::DownlevelFlags {
        wgpu::DownlevelFlags::COMPUTE_SHADERS | wgpu::DownlevelFlags::INDIRECT_EXECUTION
    }

    /// `base` raised where the GPU simulation needs more (workgroups of 64, four storage
    /// buffers); [`crate::required_limits`] already covers it, this is for hosts that only simulate.
    #[must_use]
    pub fn required_limits(base: &wgpu::Limits) -> wgpu::Limits {
        wgpu::Limits {
            max_compute_workgroup_size_x: base.max_compute_workgroup_size_x.max(WORKGROUP),
            max_compute_invocations_per_workgroup: base.max_compute_invocations_per_workgroup.max(WORKGROUP),
            max_compute_workgroups_per_dimension: base.max_compute_workgroups_per_dimension.max(1),
            max_storage_buffers_per_shader_stage: base.max_storage_buffers_per_shader_stage.max(STORAGE_BUFFERS),
            ..base.clone()
        }
    }

    /// Whether `adapter` can run the GPU simulation.
    ///
    /// # Errors
    /// [`RenderError::MissingDownlevelFlags`] without compute shaders, [`RenderError::Limit`].
    pub fn check_adapter(adapter: &wgpu::Adapter) -> Result<(), RenderError> {
        let missing = Self::required_downlevel_flags() - adapter.get_downlevel_capabilities().flags;
        if !missing.is_empty() {
            return Err(RenderError::MissingDownlevelFlags { adapter: adapter.get_info().name, missing });
        }
        check_limits(&adapter.limits())
    }

    /// Sets up the simulation of `fur`, grown as `structure` (its rest segments are read from
    /// `structure.positions`).
    ///
    /// # Errors
    /// [`RenderError::Count`] when `fur` was not made from `structure`, [`RenderError::Limit`] or
    /// [`RenderError::TooLarge`] when the device cannot hold it, [`RenderError::Gpu`] when the
    /// device refuses the compute pipeline (e.g. no compute shaders).
    pub fn new(device: &wgpu::Device, fur: &GpuFur, structure: &FurStructure) -> Result<Self, RenderError> {
        check_limits(&device.limits())?;
        Self::with_pipelines(device, SimPipelines::new(device)?, fur, structure, (None, None), false)
    }

    /// [`GpuSimulation::new`] with the kernels `renderer` keeps for its device, compiled the
    /// first time any fur asks: a herd's members share them.
    ///
    /// # Errors
    /// As [`GpuSimulation::new`].
    pub fn with_renderer(
        device: &wgpu::Device,
        renderer: &FurRenderer,
        fur: &GpuFur,
        structure: &FurStructure,
    ) -> Result<Self, RenderError> {
        Self::for_copy(device, renderer, fur, structure, (None, None))
    }

    /// [`GpuSimulation::with_renderer`]; for a copy of a fur grown as its asset's structure the
    /// rest segments are `shared_rest`'s, made by the first copy simulated on the GPU. A copy
    /// made with others keeps its per-strand buffers in their `pool` (at its [`GpuFur::slot`]),
    /// and steps with them where the renderer pools ([`FurRenderer::pooled_stepping`]).
    pub(crate) fn for_copy(
        device: &wgpu::Device,
        renderer: &FurRenderer,
        fur: &GpuFur,
        structure: &FurStructure,
        shared: (Option<&OnceLock<wgpu::Buffer>>, Option<&Arc<SimPool>>),
    ) -> Result<Self, RenderError> {
        check_limits(&device.limits())?;
        let pipelines = renderer.simulation_pipelines()?.clone();
        Self::with_pipelines(device, pipelines, fur, structure, shared, renderer.pooled_stepping())
    }

    /// Sets up the simulation with `pipelines`, the device's limits checked.
    fn with_pipelines(
        device: &wgpu::Device,
        pipelines: SimPipelines,
        fur: &GpuFur,
        structure: &FurStructure,
        (shared_rest, pool): (Option<&OnceLock<wgpu::Buffer>>, Option<&Arc<SimPool>>),
        pooling: bool,
    ) -> Result<Self, RenderError> {
        let (v, layers) = (structure.vertex_count(), structure.layers as usize);
        check_shape(fur, v, structure.layers)?;
        if structure.positions.len() != v * (layers + 1) {
            return Err(RenderError::Count {
                what: "shared vertex positions",
                expected: v * (layers + 1),
                got: structure.positions.len(),
                rule: "(L + 1) * V",
            });
        }
        let limits = device.limits();
        let groups = (v as u32).div_ceil(WORKGROUP);
        let grid_x = groups.clamp(1, limits.max_compute_workgroups_per_dimension);
        let grid = [grid_x, groups.div_ceil(grid_x)];
        if grid[1] > limits.max_compute_workgroups_per_dimension {
            return Err(RenderError::Limit {
                limit: "max_compute_workgroups_per_dimension",
                got: limits.max_compute_workgroups_per_dimension.into(),
                needed: grid[1].into(),
            });
        }
        // The CPU kernel's rest shape and forms, so the GPU bends every strand as it does.
        let kernel_rest = kernel_rest(structure).map_err(|_| RenderError::Count {
            what: "shared vertex positions",
            expected: v * (layers + 1),
            got: structure.positions.len(),
            rule: "(L + 1) * V",
        })?;
        let mut rest: Vec<[f32; 4]> =
            kernel_rest.segments.iter().map(|(d, length)| d.extend(*length).to_array()).collect();
        rest.extend(kernel_rest.straight.iter().map(|s| s.map_or([0.0; 4], |d| d.extend(1.0).to_array())));
        if rest.is_empty() {
            rest.push([0.0; 4]);
        }
        check_size(device, "simulation rest segments", rest.len() as u64 * 16)?;

        // A copy outside its pool's slots (none is made so) keeps buffers of its own.
        let (pool, slot) = match pool.filter(|pool| fur.slot() < pool.slots()) {
            Some(pool) => (pool.clone(), fur.slot()),
            None => (Arc::new(SimPool::new(device, v, 1)?), 0),
        };
        let scope = ErrorScope::push(device);
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        // Copied from into a pooled step's array.
        let step_uniforms = buffer(
            "pelt simulation steps",
            STEP_SLOT_BYTES * RING_SLOTS,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        let make_rest = || {
            wgpu::util::DeviceExt::create_buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor {
                    label: Some("pelt simulation rest segments"),
                    contents: bytemuck::cast_slice(&rest),
                    usage: wgpu::BufferUsages::STORAGE,
                },
            )
        };
        let (rest_segments, rest_shared) = match shared_rest {
            Some(cell) => (cell.get_or_init(make_rest).clone(), true),
            None => (make_rest(), false),
        };
        scope.pop("creating the GPU simulation")?;
        let pooled = pooling
            && pool.slots() > 1
            && pool.bind_pooled(
                device,
                pipelines.pooled(device)?,
                (&rest_segments, fur.current_positions().buffer()),
            )?;
        if pooled {
            // Compiled with the herd, so the first step with contact does not stall a frame.
            pipelines.pooled_contact(device)?;
        }
        let scope = ErrorScope::push(device);
        // The skin's planes and triangles come from the CPU simulation once it has found them
        // (skin contact on): a coat that never touches its skin never finds them. A pooled
        // copy's contact is its pool's.
        let contact = if pooled {
            GpuContact::unused(device, structure)
        } else {
            let skin = Skin::none(v);
            check_size(device, "simulation contact", GpuContact::bytes(&skin, 0))?;
            check_size(device, "simulation contact list", GpuContact::work_bytes(v))?;
            GpuContact::new(device, structure, &skin)
        };
        scope.pop("creating the GPU simulation's contact")?;
        Ok(Self {
            pipelines,
            step_uniforms,
            rest_segments,
            rest_shared,
            ranges: pool.ranges(slot),
            pooled_solve_cap: grid_x.saturating_mul(pool.slots()).min(limits.max_compute_workgroups_per_dimension),
            pool,
            pooled,
            slot,
            contact,
            pending_contact: Vec::with_capacity(STEP_SLOTS + 2),
            wet: WetInputs::default(),
            bind_groups: Vec::new(),
            vertex_count: v as u32,
            layers: structure.layers,
            grid,
            uploaded: None,
            weigh_touch: false,
            touch_uploaded: false,
            seen_steps: None,
            skin_found: false,
            pending: Vec::with_capacity(STEP_SLOTS + 2),
            ring: 0,
            dispatched_history: 0,
            pending_history: 0,
        })
    }

    /// Takes the steps `simulation` ran since the last call (all of its last two the first
    /// time): writes their uniforms (each with its own inertia step) and, when they changed, the
    /// resident per-strand inputs (roots, frames, stability, field). Queue writes only; call
    /// [`GpuSimulation::dispatch`] before the next submission. Steps not dispatched yet are kept
    /// (the last two). The resident inputs are the simulation's now: when it took two steps at
    /// once (a catch-up) after its base moved, both are bent from the newer roots. Steps this
    /// never saw (more than two between calls) start the inertial force over from rest.
    ///
    /// # Errors
    /// [`RenderError::Count`] when `simulation` or `fur` is not the shape this was made for;
    /// [`RenderError::Gpu`] if the device refuses a bind group.
    pub fn prepare(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        simulation: &Simulation,
        fur: &GpuFur,
    ) -> Result<(), RenderError> {
        let v = self.vertex_count as usize;
        check_shape(fur, v, self.layers)?;
        if simulation.vertex_count() != v || simulation.layers() != self.layers {
            return Err(RenderError::Count {
                what: "simulated strands",
                expected: v,
                got: simulation.vertex_count(),
                rule: "V strands of L layers, as the GPU simulation was made for",
            });
        }
        for buffer in [fur.current_positions(), fur.previous_positions()] {
            self.bind_group_for(device, buffer)?;
        }
        let taken = simulation.steps_taken();
        let recent = simulation.recent_step_times();
        let unseen = match self.seen_steps {
            None => u64::MAX,
            Some(seen) => taken.saturating_sub(seen),
        };
        let new = usize::try_from(unseen).unwrap_or(usize::MAX).min(recent.len());
        self.seen_steps = Some(taken);
        if new == 0 {
            return Ok(());
        }
        self.upload_inputs(queue, simulation);
        let touch_centre =
            simulation.touch().map_or([0.0, 0.0, 0.0, 1.0], |touch| touch.point.extend(touch.radius).to_array());
        let counts = [self.vertex_count, self.layers];
        let inertia_steps = simulation.recent_inertia_steps();
        // Steps the GPU never saw (or pending steps dropped below): its inertial state starts over.
        let mut start_over = unseen > recent.len() as u64;
        if start_over {
            self.pending.clear();
            self.pending_contact.clear();
        }
        for (&time_secs, &inertia) in
            recent[recent.len() - new..].iter().zip(&inertia_steps[inertia_steps.len() - new..])
        {
            self.pending.push(step_uniform(
                &simulation.step_inputs(time_secs),
                inertia,
                touch_centre,
                counts,
                self.grid[0],
            ));
            if let Some(uniform) = self.pending.last_mut() {
                uniform.inertia_kind[1] = u32::from(self.touch_uploaded);
            }
            self.pending_contact.push(simulation.contact_step(time_secs));
        }
        if self.pending.len() > STEP_SLOTS {
            self.pending.drain(..self.pending.len() - STEP_SLOTS);
            self.pending_contact.drain(..self.pending_contact.len() - STEP_SLOTS);
            start_over = true;
        }
        let history = if start_over { 0 } else { self.dispatched_history };
        self.pending_history = settle_inertia(&mut self.pending, history);
        let strands = simulation.contact_strands();
        if self.pooled {
            self.prepare_pooled_contact((device, queue), simulation, fur, &strands)?;
        } else {
            self.prepare_own_contact((device, queue), simulation, fur, &strands)?;
        }
        let written = [fur.previous_positions(), fur.current_positions()];
        let [strands, state, wet] = self.ranges;
        for slot in 0..self.pending.len() {
            let ring_slot = (self.ring + slot as u64) % RING_SLOTS;
            self.pending[slot].grid[1] = ring_slot as u32;
            if self.pooled {
                self.pending[slot].grid[2] = self.slot;
                self.pending[slot].grid[3] = self.pooled_solve_cap;
            }
            // Step `slot` writes the state that is current after `slot + 1` swaps.
            let positions = u32::try_from(written[slot % 2].offset() / 4).unwrap_or(u32::MAX);
            self.pending[slot].pool = [positions, strands.first(16), state.first(16), wet.first(pool::WET_BYTES)];
            queue.write_buffer(&self.step_uniforms, self.slot_offset(slot), bytemuck::bytes_of(&self.pending[slot]));
            if !self.pooled {
                self.contact.write_slot(queue, ring_slot as usize, &self.pending_contact[slot]);
            }
        }
        Ok(())
    }

    /// What the GPU carries from step to step, for tests that compare it with the CPU's
    /// inputs: `4 V` `vec4<f32>` in sections of `V`: the root at the last step (xyz) and the
    /// touch's weight (w), the root the step before, the inertial force, its rate of change.
    #[must_use]
    pub fn strand_state(&self) -> wgpu::BufferSlice<'_> {
        let state = self.ranges[1];
        self.pool.state.slice(state.at..state.at + state.size)
    }

    /// Steps prepared and not yet dispatched (0, 1 or 2).
    #[must_use]
    pub fn pending_steps(&self) -> usize {
        self.pending.len()
    }

    /// Bytes of this fur's own simulation buffers (step uniforms, rest segments unless its
    /// asset's, contact, and its ranges of the inputs, state and wetness its pool holds); its
    /// kernels are the renderer's, shared.
    #[must_use]
    pub fn gpu_bytes(&self) -> u64 {
        let contact = &self.contact;
        let own_rest = if self.rest_shared { 0 } else { self.rest_segments.size() };
        own_rest
            + self.pool.slot_bytes(self.slot)
            + [&self.step_uniforms, &contact.buffer, &contact.fields_buffer, &contact.work, &contact.work_groups]
                .iter()
                .map(|buffer| buffer.size())
                .sum::<u64>()
    }

    /// Node updates per step: `V * L` (the bench's unit).
    #[must_use]
    pub fn nodes_per_step(&self) -> u64 {
        u64::from(self.vertex_count) * u64::from(self.layers)
    }
}

fn check_shape(fur: &GpuFur, vertex_count: usize, layers: u32) -> Result<(), RenderError> {
    if fur.vertex_count() as usize != vertex_count || fur.layers() != layers {
        return Err(RenderError::Count {
            what: "strands in the fur",
            expected: vertex_count,
            got: fur.vertex_count() as usize,
            rule: "V strands of L layers: the fur, the structure and the simulation must match",
        });
    }
    Ok(())
}

fn check_limits(limits: &wgpu::Limits) -> Result<(), RenderError> {
    let checks = [
        ("max_compute_workgroup_size_x", limits.max_compute_workgroup_size_x, WORKGROUP),
        ("max_compute_invocations_per_workgroup", limits.max_compute_invocations_per_workgroup, WORKGROUP),
        ("max_compute_workgroups_per_dimension", limits.max_compute_workgroups_per_dimension, 1),
        ("max_storage_buffers_per_shader_stage", limits.max_storage_buffers_per_shader_stage, STORAGE_BUFFERS),
    ];
    for (limit, got, needed) in checks {
        if got < needed {
            return Err(RenderError::Limit { limit, got: got.into(), needed: needed.into() });
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_are_checked_by_name() {
        let limits = GpuSimulation::required_limits(&wgpu::Limits::downlevel_defaults());
        assert!(check_limits(&limits).is_ok());
        let small = wgpu::Limits { max_compute_workgroup_size_x: 32, ..limits };
        let error = check_limits(&small).unwrap_err().to_string();
        assert!(error.contains("max_compute_workgroup_size_x = 32"), "{error}");
    }
}
