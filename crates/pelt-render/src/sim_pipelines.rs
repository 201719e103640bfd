//! The GPU simulation's compute pipelines and their bind group layout: built once per device
//! and cloned (handles) into every [`GpuSimulation`](crate::GpuSimulation) a [`FurRenderer`]
//! makes, so a herd of a thousand furs on the GPU kernel compiles its kernels once.
//!
//! [`FurRenderer`]: crate::FurRenderer

use crate::RenderError;
use crate::requirements::ErrorScope;
use crate::shaders::simulation_shader_source;

/// Bytes of one step's uniform (`Step` in `simulation.wgsl`, `StepUniform` in `simulation`):
/// the binding's size.
pub(crate) const STEP_UNIFORM_BYTES: u64 = 14 * 16;

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
}

impl SimPipelines {
    /// Compiles the kernels.
    pub(crate) fn new(device: &wgpu::Device) -> Result<Self, RenderError> {
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
                        min_binding_size: wgpu::BufferSize::new(STEP_UNIFORM_BYTES),
                    },
                    count: None,
                },
                storage(1, true),
                storage(2, true),
                storage(3, false),
                storage(4, false),
                storage(5, true),
                storage(6, true),
                storage(7, true),
                storage(8, false),
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pelt simulation"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let compute_pipeline = |entry_point, constants: &[(&str, f64)]| {
            device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
                label: Some(entry_point),
                layout: Some(&pipeline_layout),
                module: &module,
                entry_point: Some(entry_point),
                compilation_options: wgpu::PipelineCompilationOptions {
                    constants,
                    ..wgpu::PipelineCompilationOptions::default()
                },
                cache: None,
            })
        };
        let pipelines = Self {
            step: compute_pipeline("step_strands", &[]),
            touch: compute_pipeline("weigh_touch", &[]),
            contact: compute_pipeline("step_strands_with_contact", &[]),
            solve: [&[("COLLIDERS", 0.0), ("MESH_COLLIDERS", 0.0)][..], &[("MESH_COLLIDERS", 0.0)], &[]]
                .map(|constants| compute_pipeline("solve_contact", constants)),
            layout,
        };
        scope.pop("building the GPU simulation's pipelines")?;
        Ok(pipelines)
    }
}
