//! [`GpuSimulation`]: the steps of a [`pelt_core::Simulation`] as a compute pass that writes the
//! new state straight into the shared-array buffers a [`GpuFur`] draws from.
//!
//! The CPU `Simulation` stays the controller (time, fixed steps, touch, field, parameters, posed
//! roots), with its own bending turned off ([`Simulation::set_cpu_bending`]); after each
//! `advance_to` the host calls [`GpuSimulation::prepare`] (small queue writes: one uniform slot
//! per step, and the per-strand inputs only when they changed) and [`GpuSimulation::dispatch`]
//! (one compute pass per step into the host's encoder, swapping the fur's states). Nothing is
//! read back and the shared array never crosses the bus.

use pelt_core::FurStructure;
use pelt_core::sim::{Simulation, StepInputs, StrandInputs, kernel_rest};

use crate::RenderError;
use crate::fur::GpuFur;
use crate::requirements::{ErrorScope, check_size};
use crate::shaders::simulation_shader_source;

/// Strands per workgroup (`@workgroup_size` in `simulation.wgsl`).
const WORKGROUP: u32 = 64;
/// Bytes per step's uniform slot: the largest `min_uniform_buffer_offset_alignment` allowed.
const STEP_SLOT_BYTES: u64 = 256;
/// Steps one prepare/dispatch pair can hold: only the last two states are ever kept.
const STEP_SLOTS: usize = 2;
/// Storage buffers the compute stage binds.
const STORAGE_BUFFERS: u32 = 5;

/// One step's inputs; the layout of `Step` in `simulation.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
struct StepUniform {
    gravity: [f32; 4],
    wind_direction: [f32; 4],
    wind_shape: [f32; 4],
    travelled_fraction: [f32; 4],
    travelled_xy: [u32; 4],
    travelled_z_seed: [u32; 4],
    jitter_seed_tick: [u32; 4],
    next_tick_counts: [u32; 4],
    touch: [f32; 4],
    grid: [u32; 4],
}

// A slot holds one step, in the 16-byte units WGSL lays `Step` out in.
const _: () =
    assert!(size_of::<StepUniform>() as u64 <= STEP_SLOT_BYTES && (size_of::<StepUniform>() as u64).is_multiple_of(16));

/// A u64 as WGSL's `vec2<u32>` (low word, high word).
fn words(value: u64) -> [u32; 2] {
    [value as u32, (value >> 32) as u32]
}

/// The uniform of one step: `inputs` repacked into `Step`'s layout (the gust travel's whole
/// cells negated, as the shader adds them; 64-bit values as two words).
fn step_uniform(inputs: &StepInputs, counts: [u32; 2], grid_x: u32) -> StepUniform {
    let wind = &inputs.wind;
    let [x, y, z] = wind.gust_travel_cells.map(|cells| words(cells.wrapping_neg() as u64));
    let seed = words(wind.noise_seed);
    let [tick_a, tick_b] = wind.jitter_ticks.map(words);
    let jitter_seed = words(wind.jitter_seed);
    StepUniform {
        gravity: inputs.gravity.extend(0.0).to_array(),
        wind_direction: wind.direction.extend(wind.strength).to_array(),
        wind_shape: [
            wind.gust_strength,
            wind.jitter_force.unwrap_or(0.0),
            wind.jitter_blend,
            (1.0 / wind.gust_size) as f32,
        ],
        travelled_fraction: wind.gust_travel_fraction.extend(inputs.gain).to_array(),
        travelled_xy: [x[0], x[1], y[0], y[1]],
        travelled_z_seed: [z[0], z[1], seed[0], seed[1]],
        jitter_seed_tick: [jitter_seed[0], jitter_seed[1], tick_a[0], tick_a[1]],
        next_tick_counts: [tick_b[0], tick_b[1], counts[0], counts[1]],
        touch: inputs.touch_force.extend(inputs.touch_presence).to_array(),
        grid: [grid_x, 0, 0, 0],
    }
}

/// A fur's simulation on the GPU: bends every strand exactly as `pelt_core::sim` defines it
/// (Equation 1 as Pelt implements it, gravity, the wind with the same noise and seeds, the user
/// field and the touch over it, the inertial force, posed roots and frames) in a compute pass, one invocation per
/// strand, writing the new state into [`GpuFur::current_positions`] after
/// [`GpuFur::swap_states`]; the fur's vertex shader interpolates between its two states.
///
/// Per frame: `simulation.advance_to(t)`, then [`GpuSimulation::prepare`] and
/// [`GpuSimulation::dispatch`] into the host's encoder, then `fur.prepare` with
/// `interpolation: simulation.alpha()`. Nothing blocks or reads back. The device needs
/// [`GpuSimulation::required_downlevel_flags`] and [`GpuSimulation::required_limits`] (every
/// WebGPU, Vulkan, Metal, DX12 and GL 4.3 / GLES 3.1 device has them).
#[derive(Debug)]
pub struct GpuSimulation {
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    step_uniforms: wgpu::Buffer,
    rest_segments: wgpu::Buffer,
    strands: wgpu::Buffer,
    forces: wgpu::Buffer,
    wet: WetInputs,
    /// One bind group per shared-array buffer written so far (a fur has one or two).
    bind_groups: Vec<(wgpu::Buffer, wgpu::BindGroup)>,
    vertex_count: u32,
    layers: u32,
    grid: [u32; 2],
    /// What `strands` and `forces` hold, so unchanged inputs are not uploaded again.
    strand_data: Vec<[f32; 8]>,
    force_data: Vec<[f32; 8]>,
    /// `Simulation::steps_taken` at the last prepare (`None`: replay the last two steps).
    seen_steps: Option<u64>,
    /// Steps prepared and not yet dispatched (at most [`STEP_SLOTS`], in slot order).
    pending: Vec<StepUniform>,
}

impl GpuSimulation {
    /// Downlevel capabilities the GPU simulation needs beyond the renderer's: compute shaders.
    #[must_use]
    pub fn required_downlevel_flags() -> wgpu::DownlevelFlags {
        wgpu::DownlevelFlags::COMPUTE_SHADERS
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
        check_limits(&limits)?;
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
        check_size(device, "simulation strands and forces", v.max(1) as u64 * 32)?;

        let scope = ErrorScope::push(device);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pelt simulation"),
            source: wgpu::ShaderSource::Wgsl(simulation_shader_source().into()),
        });
        let storage = |binding, read_only| wgpu::BindGroupLayoutEntry {
            binding,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Storage { read_only },
                has_dynamic_offset: false,
                min_binding_size: None,
            },
            count: None,
        };
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt simulation"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::COMPUTE,
                    ty: wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: true,
                        min_binding_size: wgpu::BufferSize::new(size_of::<StepUniform>() as u64),
                    },
                    count: None,
                },
                storage(1, true),
                storage(2, true),
                storage(3, true),
                storage(4, false),
                storage(5, true),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pelt simulation"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some("pelt simulation"),
            layout: Some(&pipeline_layout),
            module: &module,
            entry_point: Some("step_strands"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            cache: None,
        });
        let buffer = |label, size: u64, usage| {
            device.create_buffer(&wgpu::BufferDescriptor { label: Some(label), size, usage, mapped_at_creation: false })
        };
        let storage_usage = wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST;
        let step_uniforms = buffer(
            "pelt simulation steps",
            STEP_SLOT_BYTES * STEP_SLOTS as u64,
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        );
        let rest_segments = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("pelt simulation rest segments"),
                contents: bytemuck::cast_slice(&rest),
                usage: wgpu::BufferUsages::STORAGE,
            },
        );
        let strands = buffer("pelt simulation strands", v.max(1) as u64 * 32, storage_usage);
        let forces = buffer("pelt simulation forces", v.max(1) as u64 * 32, storage_usage);
        let wet = WetInputs::new(device, v);
        scope.pop("creating the GPU simulation")?;
        Ok(Self {
            pipeline,
            layout,
            step_uniforms,
            rest_segments,
            strands,
            forces,
            wet,
            bind_groups: Vec::new(),
            vertex_count: v as u32,
            layers: structure.layers,
            grid,
            strand_data: Vec::new(),
            force_data: Vec::new(),
            seen_steps: None,
            pending: Vec::with_capacity(STEP_SLOTS + 2),
        })
    }

    /// Takes the steps `simulation` ran since the last call (all of its last two the first
    /// time): writes their uniforms and, when they changed, the per-strand inputs (roots,
    /// frames, stability, field, touch weights, inertial forces). Queue writes only; call
    /// [`GpuSimulation::dispatch`] before the next submission. Steps not dispatched yet are kept
    /// (the last two). The per-strand inputs are the simulation's now: when it took two steps
    /// at once (a catch-up), the older one is bent with the newer one's inertial force (the CPU
    /// keeps no older one); everything else of a step is its own.
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
        let new = match self.seen_steps {
            None => recent.len(),
            Some(seen) => usize::try_from(taken.saturating_sub(seen)).unwrap_or(usize::MAX).min(recent.len()),
        };
        self.seen_steps = Some(taken);
        if new == 0 {
            return Ok(());
        }
        self.upload_inputs(queue, simulation);
        let counts = [self.vertex_count, self.layers];
        for &time_secs in &recent[recent.len() - new..] {
            self.pending.push(step_uniform(&simulation.step_inputs(time_secs), counts, self.grid[0]));
        }
        if self.pending.len() > STEP_SLOTS {
            self.pending.drain(..self.pending.len() - STEP_SLOTS);
        }
        for (slot, uniform) in self.pending.iter().enumerate() {
            queue.write_buffer(&self.step_uniforms, slot as u64 * STEP_SLOT_BYTES, bytemuck::bytes_of(uniform));
        }
        Ok(())
    }

    /// Records the prepared steps into `encoder`: per step, [`GpuFur::swap_states`] and one
    /// compute pass writing the new current state. Does nothing when no step is pending.
    ///
    /// # Errors
    /// [`RenderError::Count`] when `fur` is not the fur last given to
    /// [`GpuSimulation::prepare`] (its buffers are unknown); no state is swapped then.
    pub fn dispatch(&mut self, encoder: &mut wgpu::CommandEncoder, fur: &mut GpuFur) -> Result<(), RenderError> {
        if self.pending.is_empty() {
            return Ok(());
        }
        let find = |buffer: &wgpu::Buffer| self.bind_groups.iter().position(|(b, _)| b == buffer);
        // Step `slot` writes the buffer that is current after `slot + 1` swaps.
        let (Some(next), Some(after_next)) = (find(fur.previous_positions()), find(fur.current_positions())) else {
            return Err(RenderError::Count {
                what: "shared-array buffers of this fur known to the GPU simulation",
                expected: 2,
                got: 0,
                rule: "call GpuSimulation::prepare with the same fur first",
            });
        };
        for slot in 0..self.pending.len() {
            fur.swap_states();
            let bind_group = &self.bind_groups[if slot % 2 == 0 { next } else { after_next }].1;
            if self.vertex_count == 0 {
                continue;
            }
            let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some("pelt simulation step"),
                timestamp_writes: None,
            });
            pass.set_pipeline(&self.pipeline);
            pass.set_bind_group(0, bind_group, &[(slot as u64 * STEP_SLOT_BYTES) as u32]);
            pass.dispatch_workgroups(self.grid[0], self.grid[1], 1);
        }
        self.pending.clear();
        Ok(())
    }

    /// Steps prepared and not yet dispatched (0, 1 or 2).
    #[must_use]
    pub fn pending_steps(&self) -> usize {
        self.pending.len()
    }

    /// Node updates per step: `V * L` (the bench's unit).
    #[must_use]
    pub fn nodes_per_step(&self) -> u64 {
        u64::from(self.vertex_count) * u64::from(self.layers)
    }

    fn bind_group_for(&mut self, device: &wgpu::Device, output: &wgpu::Buffer) -> Result<(), RenderError> {
        if self.bind_groups.iter().any(|(b, _)| b == output) {
            return Ok(());
        }
        let scope = ErrorScope::push(device);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt simulation"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::Buffer(wgpu::BufferBinding {
                        buffer: &self.step_uniforms,
                        offset: 0,
                        size: wgpu::BufferSize::new(size_of::<StepUniform>() as u64),
                    }),
                },
                wgpu::BindGroupEntry { binding: 1, resource: self.rest_segments.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: self.strands.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: self.forces.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: output.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: self.wet.gravity_scales.as_entire_binding() },
            ],
        });
        scope.pop("binding the GPU simulation to the fur")?;
        // A fur replaced by another (new structure) leaves its buffers behind: keep the newest.
        if self.bind_groups.len() >= 4 {
            self.bind_groups.remove(0);
        }
        self.bind_groups.push((output.clone(), bind_group));
        Ok(())
    }

    /// Writes the per-strand inputs that differ from what the GPU holds.
    fn upload_inputs(&mut self, queue: &wgpu::Queue, simulation: &Simulation) {
        let inputs = simulation.strand_inputs();
        let strands: Vec<[f32; 8]> = inputs
            .roots
            .iter()
            .zip(inputs.frames)
            .enumerate()
            .map(|(j, (root, frame))| {
                let [x, y, z, w] = frame.to_array();
                [root.x, root.y, root.z, inputs.stability_of(j), x, y, z, w]
            })
            .collect();
        if strands != self.strand_data {
            queue.write_buffer(&self.strands, 0, bytemuck::cast_slice(&strands));
            self.strand_data = strands;
        }
        let mut forces: Vec<[f32; 8]> =
            inputs.field.iter().zip(inputs.inertial).map(|(f, i)| [f.x, f.y, f.z, 0.0, i.x, i.y, i.z, 0.0]).collect();
        for &(j, weight) in inputs.touch_weights {
            forces[j as usize][3] = weight;
        }
        // Bitwise, so a NaN in the field does not count as a change every step.
        if bytemuck::cast_slice::<_, u32>(&forces) != bytemuck::cast_slice::<_, u32>(&self.force_data) {
            queue.write_buffer(&self.forces, 0, bytemuck::cast_slice(&forces));
            self.force_data = forces;
        }
        self.wet.upload(queue, &inputs);
    }
}

/// Wet strands' extra weight: gravity's factor per strand (binding 5), kept apart from the other
/// per-strand inputs. A wet strand's lower stability rides in the strands buffer
/// ([`StrandInputs::stability_of`]).
#[derive(Debug)]
struct WetInputs {
    gravity_scales: wgpu::Buffer,
    /// What the buffer holds; empty while it holds all ones.
    uploaded: Vec<f32>,
}

impl WetInputs {
    fn new(device: &wgpu::Device, strands: usize) -> Self {
        let gravity_scales = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("pelt simulation wet gravity"),
                contents: bytemuck::cast_slice(&vec![1.0_f32; strands.max(1)]),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            },
        );
        Self { gravity_scales, uploaded: Vec::new() }
    }

    fn upload(&mut self, queue: &wgpu::Queue, inputs: &StrandInputs<'_>) {
        if inputs.wetness.is_none() && self.uploaded.is_empty() {
            return;
        }
        let scales: Vec<f32> = (0..inputs.roots.len()).map(|j| inputs.gravity_scale_of(j)).collect();
        if scales != self.uploaded {
            queue.write_buffer(&self.gravity_scales, 0, bytemuck::cast_slice(&scales));
            self.uploaded = if inputs.wetness.is_none() { Vec::new() } else { scales };
        }
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
    fn u64_splits_into_low_and_high_words() {
        assert_eq!(words(0x0123_4567_89AB_CDEF), [0x89AB_CDEF, 0x0123_4567]);
        assert_eq!(words(1_i64.wrapping_neg() as u64), [u32::MAX, u32::MAX]);
    }

    #[test]
    fn limits_are_checked_by_name() {
        let limits = GpuSimulation::required_limits(&wgpu::Limits::downlevel_defaults());
        assert!(check_limits(&limits).is_ok());
        let small = wgpu::Limits { max_compute_workgroup_size_x: 32, ..limits };
        let error = check_limits(&small).unwrap_err().to_string();
        assert!(error.contains("max_compute_workgroup_size_x = 32"), "{error}");
    }
}

#[cfg(test)]
mod mirror_tests {
    use super::StepUniform;
    use crate::shaders::{assert_mirrors, rust_layout, simulation_shader_source};

    /// Member by member as naga lays `Step` out, not only the size.
    #[test]
    fn step_uniform_mirrors_step() {
        let rust = rust_layout!(StepUniform {
            gravity,
            wind_direction,
            wind_shape,
            travelled_fraction,
            travelled_xy,
            travelled_z_seed,
            jitter_seed_tick,
            next_tick_counts,
            touch,
            grid
        });
        assert_mirrors(&simulation_shader_source(), "Step", &rust);
    }
}
