//! Linear blend skinning on the GPU: one base mesh posed for many instances in one dispatch,
//! each with its own joint matrices (a herd's members at their own clip times).

use bytemuck::{Pod, Zeroable};
use glam::{Mat3, Mat4, Quat, Vec3, Vec4};

use crate::RenderError;
use crate::requirements::{ErrorScope, check_size};
use crate::shaders::skinning_shader_source;

/// Vertices one workgroup skins (`skinning.wgsl`'s `workgroup_size`).
const WORKGROUP: u32 = 64;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct SkinParams {
    vertex_count: u32,
    joint_count: u32,
    instance_count: u32,
    padding: u32,
}

/// A base mesh's rest pose and joint influences on the GPU, and every instance's joint matrices
/// and posed vertices: [`GpuSkin::set_joints`] per instance, then [`GpuSkin::record`] poses them
/// all in one compute pass. The blend is `pelt_core::anim`'s (the Rig's or a `Skin`'s): positions
/// by the joints' matrices, normals by their normal matrices and the fur's frames by the joints'
/// rotations, weighted, the normal renormalised and the frame turned to meet it. Morph targets
/// stay on the CPU.
#[derive(Debug)]
pub struct GpuSkin {
    pipeline: wgpu::ComputePipeline,
    bind_group: wgpu::BindGroup,
    /// The params, rest pose, influences and joints: bindings 0 to 3 of `skinning.wgsl`.
    inputs: [wgpu::Buffer; 4],
    posed: wgpu::Buffer,
    vertex_count: u32,
    joint_count: u32,
    instance_count: u32,
    bytes: u64,
}

impl GpuSkin {
    /// Uploads the rest pose (`positions`, unit `normals`) and each vertex's four joints and
    /// weights (`pelt_core::anim::Rig::vertex_influences`; unused slots weigh 0) over `joint_count`
    /// joints, with room for `instances` instances, every joint matrix the identity until set.
    ///
    /// # Errors
    /// [`RenderError::Count`] for lists of different lengths, none at all, no joints or no
    /// instances; [`RenderError::Target`] for a joint past `joint_count` with a weight or a
    /// non-finite position, normal or weight; [`RenderError::TooLarge`] past the device's
    /// buffer limits; a GPU error while creating the buffers.
    pub fn new(
        device: &wgpu::Device,
        (positions, normals): (&[Vec3], &[Vec3]),
        influences: &[([u32; 4], [f32; 4])],
        joint_count: usize,
        instances: usize,
    ) -> Result<Self, RenderError> {
        Self::with_output(device, (positions, normals), influences, joint_count, (instances, true))
    }

    /// [`GpuSkin::new`]; without `posed_output` its posed vertices hold one vertex (for a kernel
    /// that skins into buffers of its own through [`GpuSkin::inputs`], not [`GpuSkin::record`]).
    pub(crate) fn with_output(
        device: &wgpu::Device,
        (positions, normals): (&[Vec3], &[Vec3]),
        influences: &[([u32; 4], [f32; 4])],
        joint_count: usize,
        (instances, posed_output): (usize, bool),
    ) -> Result<Self, RenderError> {
        let count = |what, expected: usize, got: usize, rule| RenderError::Count { what, expected, got, rule };
        if positions.is_empty() {
            return Err(count("rest positions", 1, 0, "at least one vertex"));
        }
        if normals.len() != positions.len() {
            return Err(count("rest normals", positions.len(), normals.len(), "one per vertex"));
        }
        if influences.len() != positions.len() {
            return Err(count("vertex influences", positions.len(), influences.len(), "one per vertex"));
        }
        if joint_count == 0 {
            return Err(count("joints", 1, 0, "at least one"));
        }
        if instances == 0 {
            return Err(count("instances", 1, 0, "at least one"));
        }
        let too_many = |what| RenderError::Target(format!("GPU skinning: too many {what}"));
        let vertex_count = u32::try_from(positions.len()).map_err(|_| too_many("vertices"))?;
        let joint_total = u32::try_from(joint_count).map_err(|_| too_many("joints"))?;
        let instance_count = u32::try_from(instances).map_err(|_| too_many("instances"))?;
        if let Some(v) = (0..positions.len()).find(|&v| !(positions[v].is_finite() && normals[v].is_finite())) {
            return Err(RenderError::Target(format!(
                "GPU skinning: vertex {v}'s rest position or normal is not finite"
            )));
        }
        let mut influence_words = Vec::with_capacity(2 * influences.len());
        for (v, (joints, weights)) in influences.iter().enumerate() {
            for (&joint, &weight) in joints.iter().zip(weights) {
                if !(weight.is_finite() && weight >= 0.0) {
                    return Err(RenderError::Target(format!("GPU skinning: vertex {v} has a weight of {weight}")));
                }
                if weight > 0.0 && joint >= joint_total {
                    return Err(RenderError::Target(format!(
                        "GPU skinning: vertex {v} is moved by joint {joint} of {joint_count}"
                    )));
                }
            }
            influence_words.push(*joints);
            influence_words.push(weights.map(f32::to_bits));
        }
        let rest: Vec<[f32; 4]> = positions
            .iter()
            .zip(normals)
            .flat_map(|(p, n)| [p.extend(1.0).to_array(), n.extend(0.0).to_array()])
            .collect();
        let joint_bytes = u64::from(instance_count) * u64::from(joint_total) * 2 * 64;
        let posed_bytes = if posed_output { u64::from(instance_count) * u64::from(vertex_count) * 3 * 16 } else { 16 };
        check_size(device, "GPU skinning's joint matrices", joint_bytes)?;
        check_size(device, "GPU skinning's posed vertices", posed_bytes)?;

        let scope = ErrorScope::push(device);
        let init = |label, contents: &[u8], usage| {
            wgpu::util::DeviceExt::create_buffer_init(
                device,
                &wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage },
            )
        };
        let params = SkinParams { vertex_count, joint_count: joint_total, instance_count, padding: 0 };
        let params = init("pelt skin params", bytemuck::bytes_of(&params), wgpu::BufferUsages::UNIFORM);
        let rest = init("pelt skin rest", bytemuck::cast_slice(&rest), wgpu::BufferUsages::STORAGE);
        let influences =
            init("pelt skin influences", bytemuck::cast_slice(&influence_words), wgpu::BufferUsages::STORAGE);
        let identity: Vec<[f32; 16]> = vec![Mat4::IDENTITY.to_cols_array(); 2 * joint_count * instances];
        let joints = init(
            "pelt skin joints",
            bytemuck::cast_slice(&identity),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let posed = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt skin posed"),
            size: posed_bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::VERTEX,
            mapped_at_creation: false,
        });
        let storage = |read_only| wgpu::BufferBindingType::Storage { read_only };
        let (layout, pipeline) = buffers_pipeline(
            device,
            ("pelt skinning", skinning_shader_source(), "skin"),
            &[
                Some(wgpu::BufferBindingType::Uniform),
                Some(storage(true)),
                Some(storage(true)),
                Some(storage(true)),
                Some(storage(false)),
            ],
        );
        let bind_group =
            whole_buffers(device, "pelt skinning", &layout, &[&params, &rest, &influences, &joints, &posed]);
        scope.pop("creating the GPU skinning")?;
        let bytes = params.size() + rest.size() + influences.size() + joints.size() + posed.size();
        let inputs = [params, rest, influences, joints];
        Ok(Self { pipeline, bind_group, inputs, posed, vertex_count, joint_count: joint_total, instance_count, bytes })
    }

    /// The buffers of bindings 0 to 3 of `skinning.wgsl`: its params, the rest pose, the
    /// influences and every instance's joints.
    pub(crate) fn inputs(&self) -> &[wgpu::Buffer; 4] {
        &self.inputs
    }

    /// Sets instance `instance`'s joint matrices (`world(joint) * inverse_bind`, one per joint,
    /// as `pelt_core::anim::Rig::joint_matrices` gives them, times the instance's placement when
    /// it has one) for the next [`GpuSkin::record`].
    ///
    /// # Errors
    /// [`RenderError::Count`] for another number of matrices or an instance past the last;
    /// [`RenderError::Target`] for a matrix with a NaN or infinite entry.
    pub fn set_joints(&self, queue: &wgpu::Queue, instance: usize, matrices: &[Mat4]) -> Result<(), RenderError> {
        if instance >= self.instance_count as usize {
            return Err(RenderError::Count {
                what: "instance index",
                expected: self.instance_count as usize,
                got: instance,
                rule: "below the instances made",
            });
        }
        if matrices.len() != self.joint_count as usize {
            return Err(RenderError::Count {
                what: "joint matrices",
                expected: self.joint_count as usize,
                got: matrices.len(),
                rule: "one per joint",
            });
        }
        if let Some(joint) = matrices.iter().position(|m| !m.is_finite()) {
            return Err(RenderError::Target(format!("GPU skinning: joint {joint}'s matrix is not finite")));
        }
        // Normals go by the inverse transpose; a singular joint (scaled to nothing) keeps its
        // upper 3x3, whose blend the renormalisation then sorts out. The joint's rotation rides in
        // the normal matrix's fourth column, as `pelt_core::anim` takes it (identity when singular).
        let words: Vec<[f32; 16]> = matrices
            .iter()
            .flat_map(|m| {
                let upper = Mat3::from_mat4(*m);
                let normal =
                    if upper.determinant().abs() > f32::MIN_POSITIVE { upper.inverse().transpose() } else { upper };
                let (scale, rotation, _) = m.to_scale_rotation_translation();
                let rotation = if scale.abs().min_element() > f32::MIN_POSITIVE && rotation.is_finite() {
                    rotation.normalize()
                } else {
                    Quat::IDENTITY
                };
                let mut normal = Mat4::from_mat3(normal);
                normal.w_axis = Vec4::from(rotation);
                [m.to_cols_array(), normal.to_cols_array()]
            })
            .collect();
        let offset = (instance * self.joint_count as usize * 2 * 64) as u64;
        queue.write_buffer(&self.inputs[3], offset, bytemuck::cast_slice(&words));
        Ok(())
    }

    /// Records the skinning of every instance: one compute pass, one dispatch.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder) {
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("pelt skinning"), timestamp_writes: None });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &self.bind_group, &[]);
        pass.dispatch_workgroups(self.vertex_count.div_ceil(WORKGROUP), self.instance_count, 1);
    }

    /// The posed vertices: per instance three sections of four `f32`s per vertex: the positions
    /// (`w` = 1), the unit normals (`w` = 0), and the rotations from the rest frame (unit
    /// quaternions, `xyzw`: `pelt_core::anim::Pose::rotations`, the fur's frames).
    #[must_use]
    pub fn posed(&self) -> &wgpu::Buffer {
        &self.posed
    }

    /// Base vertices per instance.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.vertex_count as usize
    }

    /// Instances posed by one [`GpuSkin::record`].
    #[must_use]
    pub fn instance_count(&self) -> usize {
        self.instance_count as usize
    }

    /// GPU bytes of every buffer.
    #[must_use]
    pub fn bytes(&self) -> u64 {
        self.bytes
    }
}

/// A compute pipeline of `source`'s `entry` over one bind group of whole buffers, bound in order
/// from 0 as `buffers` says (`None`: a binding the entry does not use, left out), visible to the
/// compute stage; and that group's layout. For the small kernels beside the renderer's (the
/// skinning, a herd's posing).
pub(crate) fn buffers_pipeline(
    device: &wgpu::Device,
    (label, source, entry): (&'static str, String, &str),
    buffers: &[Option<wgpu::BufferBindingType>],
) -> (wgpu::BindGroupLayout, wgpu::ComputePipeline) {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    });
    let entries: Vec<_> = (0..)
        .zip(buffers)
        .filter_map(|(binding, ty)| {
            Some(wgpu::BindGroupLayoutEntry {
                binding,
                visibility: wgpu::ShaderStages::COMPUTE,
                ty: wgpu::BindingType::Buffer { ty: (*ty)?, has_dynamic_offset: false, min_binding_size: None },
                count: None,
            })
        })
        .collect();
    let layout =
        device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor { label: Some(label), entries: &entries });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(label),
        layout: Some(&pipeline_layout),
        module: &module,
        entry_point: Some(entry),
        compilation_options: wgpu::PipelineCompilationOptions::default(),
        cache: None,
    });
    (layout, pipeline)
}

/// A bind group of `layout` binding each of `buffers` whole, in order from 0 (`None`: a binding
/// left out, as in [`buffers_pipeline`]).
pub(crate) fn whole_buffers(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[&wgpu::Buffer],
) -> wgpu::BindGroup {
    gapped_buffers(device, label, layout, &buffers.iter().map(|&b| Some(b)).collect::<Vec<_>>())
}

/// [`whole_buffers`] with gaps: binding `k` holds `buffers[k]` where it is `Some`.
pub(crate) fn gapped_buffers(
    device: &wgpu::Device,
    label: &str,
    layout: &wgpu::BindGroupLayout,
    buffers: &[Option<&wgpu::Buffer>],
) -> wgpu::BindGroup {
    let entries: Vec<_> = (0..)
        .zip(buffers)
        .filter_map(|(binding, buffer)| {
            Some(wgpu::BindGroupEntry { binding, resource: (*buffer)?.as_entire_binding() })
        })
        .collect();
    device.create_bind_group(&wgpu::BindGroupDescriptor { label: Some(label), layout, entries: &entries })
}
