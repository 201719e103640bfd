//! The GPU simulation's compute pipelines and their bind group layout: built once per device
//! and cloned (handles) into every [`GpuSimulation`](crate::GpuSimulation) a [`FurRenderer`]
//! makes, so a herd of a thousand furs on the GPU kernel compiles its kernels once.
//!
//! [`FurRenderer`]: crate::FurRenderer

use std::sync::{Arc, OnceLock};

use crate::RenderError;
use crate::requirements::ErrorScope;
use crate::shaders::{simulation_pooled_shader_source, simulation_shader_source};

/// Bytes of one step's uniform (`Step` in `simulation.wgsl`, `StepUniform` in `simulation`):
/// the binding's size.
pub(crate) const STEP_UNIFORM_BYTES: u64 = 15 * 16;

/// `step_pooled` (`simulation_pooled.wgsl`): every copy of a pool stepping without contact.
#[derive(Debug)]
pub(crate) struct PooledStep {
    pub(crate) pipeline: wgpu::ComputePipeline,
    pub(crate) layout: wgpu::BindGroupLayout,
}

/// `step_pooled_with_contact` and `solve_pooled_contact` (`simulation_pooled.wgsl`): every copy
/// of a pool stepping with contact, through the pool's contact buffer and list.
#[derive(Debug)]
pub(crate) struct PooledContact {
    pub(crate) contact: wgpu::ComputePipeline,
    /// As [`SimPipelines::solve`].
    pub(crate) solve: [wgpu::ComputePipeline; 3],
    pub(crate) layout: wgpu::BindGroupLayout,
}

/// `simulation.wgsl`'s entry points, compiled for one device.
#[derive(Clone, Debug)]
pub(crate) struct SimPipelines {
    /// `step_strands`: a step without contact.
    pub(crate) step: wgpu::ComputePipeline,
    /// `weigh_touch`: a touch's weights when it begins.
    pub(crate) touch: wgpu::ComputePipeline,
    /// `step_strands_with_contact`: the bend and screen of steps whose contact is active.
    pub(crate) contact: wgpu::ComputePipeline,
    /// `solve_contact`: the strands the screen listed, compiled without colliders' code, with
    /// colliders but no mesh's, and with both.
    pub(crate) solve: [wgpu::ComputePipeline; 3],
    pub(crate) layout: wgpu::BindGroupLayout,
    /// Compiled when the first herd simulates on the GPU.
    pooled: Arc<OnceLock<PooledStep>>,
    /// Compiled with the first herd that steps pooled.
    pooled_contact: Arc<OnceLock<PooledContact>>,
}

impl SimPipelines {
    /// Compiles the kernels.
    pub(crate) fn new(device: &wgpu::Device) -> Result<Self, RenderError> {
        let scope = ErrorScope::push(device);
        let step_uniform = wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::COMPUTE,
            ty: wgpu::BindingType::Buffer {
                ty: wgpu::BufferBindingType::Uniform,
                has_dynamic_offset: true,
                min_binding_size: wgpu::BufferSize::new(STEP_UNIFORM_BYTES),
            },
            count: None,
        };
        let kernels = Kernels::new(
            device,
            ("pelt simulation", simulation_shader_source()),
            &[
                step_uniform,
                storage(1, true),
                storage(2, true),
                storage(3, false),
                storage(4, false),
                storage(5, true),
                storage(6, true),
                storage(7, true),
                storage(8, false),
            ],
        );
        let compute_pipeline =
            |entry_point, constants: &[(&str, f64)]| kernels.pipeline(device, entry_point, constants);
        let pipelines = Self {
            step: compute_pipeline("step_strands", &[]),
            touch: compute_pipeline("weigh_touch", &[]),
            contact: compute_pipeline("step_strands_with_contact", &[]),
            solve: SOLVE_CONSTANTS.map(|constants| compute_pipeline("solve_contact", constants)),
            layout: kernels.layout,
            pooled: Arc::default(),
            pooled_contact: Arc::default(),
        };
        scope.pop("building the GPU simulation's pipelines")?;
        Ok(pipelines)
    }

    /// The pooled step's kernel, once compiled.
    pub(crate) fn pooled_built(&self) -> Option<&PooledStep> {
        self.pooled.get()
    }

    /// The pooled step's kernel, compiled the first time.
    pub(crate) fn pooled(&self, device: &wgpu::Device) -> Result<&PooledStep, RenderError> {
        if let Some(pooled) = self.pooled.get() {
            return Ok(pooled);
        }
        let scope = ErrorScope::push(device);
        let kernels = Kernels::new(
            device,
            ("pelt simulation pooled", simulation_pooled_shader_source()),
            &[
                storage(0, true),
                storage(1, true),
                storage(2, true),
                storage(3, false),
                storage(4, false),
                storage(6, true),
            ],
        );
        let pipeline = kernels.pipeline(device, "step_pooled", &[]);
        scope.pop("building the GPU simulation's pooled step")?;
        Ok(self.pooled.get_or_init(|| PooledStep { pipeline, layout: kernels.layout }))
    }

    /// The pooled contact kernels, once compiled.
    pub(crate) fn pooled_contact_built(&self) -> Option<&PooledContact> {
        self.pooled_contact.get()
    }

    /// The pooled contact kernels, compiled the first time: eight storage buffers (WebGPU's
    /// least), the fields inside the pool's contact buffer.
    pub(crate) fn pooled_contact(&self, device: &wgpu::Device) -> Result<&PooledContact, RenderError> {
        if let Some(pooled) = self.pooled_contact.get() {
            return Ok(pooled);
        }
        let scope = ErrorScope::push(device);
        let kernels = Kernels::new(
            device,
            ("pelt simulation pooled contact", simulation_pooled_shader_source()),
            &[
                storage(0, true),
                storage(1, true),
                storage(2, true),
                storage(3, false),
                storage(4, false),
                storage(5, true),
                storage(6, true),
                storage(8, false),
            ],
        );
        let contact = kernels.pipeline(device, "step_pooled_with_contact", &[]);
        let solve = SOLVE_CONSTANTS.map(|constants| kernels.pipeline(device, "solve_pooled_contact", constants));
        scope.pop("building the GPU simulation's pooled contact")?;
        Ok(self.pooled_contact.get_or_init(|| PooledContact { contact, solve, layout: kernels.layout }))
    }
}

/// The override constants of the three `solve_contact` kernels: without colliders' code, without
/// mesh colliders', with both.
const SOLVE_CONSTANTS: [&[(&str, f64)]; 3] =
    [&[("COLLIDERS", 0.0), ("MESH_COLLIDERS", 0.0)], &[("MESH_COLLIDERS", 0.0)], &[]];

/// A WGSL module with its one bind group's layout, and the pipeline layout of its kernels.
struct Kernels {
    module: wgpu::ShaderModule,
    layout: wgpu::BindGroupLayout,
    pipeline_layout: wgpu::PipelineLayout,
}

impl Kernels {
    fn new(device: &wgpu::Device, (label, source): (&str, String), entries: &[wgpu::BindGroupLayoutEntry]) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(label),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some(label),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        Self { module, layout, pipeline_layout }
    }

    /// The kernel `entry_point` with the override `constants`.
    fn pipeline(&self, device: &wgpu::Device, entry_point: &str, constants: &[(&str, f64)]) -> wgpu::ComputePipeline {
        device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
            label: Some(entry_point),
            layout: Some(&self.pipeline_layout),
            module: &self.module,
            entry_point: Some(entry_point),
            compilation_options: wgpu::PipelineCompilationOptions {
                constants,
                ..wgpu::PipelineCompilationOptions::default()
            },
            cache: None,
        })
    }
}

/// A storage buffer the compute stage binds at `binding`.
fn storage(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}
