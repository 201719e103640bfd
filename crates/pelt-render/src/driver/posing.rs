//! [`HerdPosing`]: a herd's bases skinned on the GPU, every member in one dispatch, and placed
//! into the members' simulation inputs and base normals in a second, so a GPU-kernel herd's CPU
//! poses joints only.

use bytemuck::{Pod, Zeroable};
use pelt_core::Mesh;
use pelt_core::anim::Rig;
use pelt_core::sim::FurStepper;

use super::FurDriver;
use crate::RenderError;
use crate::requirements::ErrorScope;
use crate::shaders::herd_posing_shader_source;
use crate::skinning::{GpuSkin, buffers_pipeline, gapped_buffers};

/// Vertices one workgroup places (`herd_posing.wgsl`'s `workgroup_size`).
const WORKGROUP: u32 = 64;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct PlaceParams {
    vertex_count: u32,
    rows: u32,
    padding: [u32; 2],
}

/// The bases of a herd's members skinned on the GPU ([`GpuSkin`]): each frame the CPU poses
/// each member's joints only ([`FurStepper::set_joint_posing`], [`FurStepper::posed_joints`]),
/// and [`HerdPosing::record`] skins the members in one dispatch, writing their posed roots,
/// frames and normals straight where each member's GPU simulation and skin read them (the
/// skinning of [`GpuSkin`], without its buffer of posed vertices).
///
/// For members made together ([`FurDriver::herd_with_asset`]) that bend on the GPU kernel. A
/// member its stepper posed on the CPU (a touch, a collider, wetness: see
/// [`FurStepper::set_joint_posing`]) keeps the CPU's pose until its stepper poses joints again.
///
/// Per frame: [`FurDriver::advance_herd`], [`HerdPosing::prepare`], then [`HerdPosing::record`]
/// and [`FurDriver::record_herd`] into one encoder, in that order.
#[derive(Debug)]
pub struct HerdPosing {
    skin: GpuSkin,
    pipeline: wgpu::ComputePipeline,
    layout: wgpu::BindGroupLayout,
    params: wgpu::Buffer,
    table: wgpu::Buffer,
    /// The rows written to `table`: skin instance, roots' first `vec4`, normals' first `f32`.
    rows: Vec<[u32; 4]>,
    /// The bind group, by the strands and normals buffers it writes.
    bind_group: Option<((wgpu::Buffer, wgpu::Buffer), wgpu::BindGroup)>,
    /// Whether each member's last pose is the GPU's.
    on_gpu: Vec<bool>,
}

impl HerdPosing {
    /// GPU posing for a herd of `members` copies of `mesh` (the rest base every member's fur
    /// grew on) skinned by `rig`.
    ///
    /// # Errors
    /// [`RenderError::Count`] for a rig of another mesh or no members; as [`GpuSkin::new`].
    pub fn new(device: &wgpu::Device, mesh: &Mesh, rig: &Rig, members: usize) -> Result<Self, RenderError> {
        if rig.vertex_count() != mesh.vertex_count() {
            return Err(RenderError::Count {
                what: "rig vertices",
                expected: mesh.vertex_count(),
                got: rig.vertex_count(),
                rule: "the rig of the mesh the fur grew on",
            });
        }
        // Skinned straight into the members' buffers: the skin keeps no posed vertices.
        let skin = GpuSkin::with_output(
            device,
            (&mesh.positions, &mesh.normals),
            &rig.vertex_influences(),
            rig.joint_count(),
            (members, false),
        )?;
        let scope = ErrorScope::push(device);
        let storage = |read_only| Some(wgpu::BufferBindingType::Storage { read_only });
        let uniform = Some(wgpu::BufferBindingType::Uniform);
        // The skin's inputs (0 to 3), not its output (4), then the placing's.
        let (layout, pipeline) = buffers_pipeline(
            device,
            ("pelt herd posing", herd_posing_shader_source(), "place"),
            &[
                uniform,
                storage(true),
                storage(true),
                storage(true),
                None,
                uniform,
                storage(true),
                storage(false),
                storage(false),
            ],
        );
        let params = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt herd posing params"),
            size: size_of::<PlaceParams>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let table = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt herd posing table"),
            size: (members.max(1) * 16) as u64,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        scope.pop("creating the herd's GPU posing")?;
        Ok(Self {
            skin,
            pipeline,
            layout,
            params,
            table,
            rows: Vec::new(),
            bind_group: None,
            on_gpu: vec![false; members],
        })
    }

    /// Takes each member's last advance: the joints of those whose stepper posed joints only,
    /// for [`HerdPosing::record`]; a member its stepper posed on the CPU (or that bends on the
    /// CPU) is left as the CPU wrote it.
    ///
    /// # Errors
    /// [`RenderError::Count`] unless there is one driver and stepper per member, or when the
    /// members posed here do not share their simulation's and skin's buffers (made apart); as
    /// [`GpuSkin::set_joints`].
    pub fn prepare(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        drivers: &[FurDriver],
        steppers: &[FurStepper],
    ) -> Result<(), RenderError> {
        for (what, got) in [("drivers of a posed herd", drivers.len()), ("steppers of a posed herd", steppers.len())] {
            if got != self.on_gpu.len() {
                return Err(RenderError::Count { what, expected: self.on_gpu.len(), got, rule: "one per member" });
            }
        }
        let mut rows = Vec::with_capacity(self.rows.len());
        let mut buffers: Option<(&wgpu::Buffer, &wgpu::Buffer)> = None;
        for (k, (driver, stepper)) in drivers.iter().zip(steppers).enumerate() {
            let Some(simulation) = &driver.gpu_simulation else {
                self.on_gpu[k] = false;
                continue;
            };
            if let Some(joints) = stepper.posed_joints() {
                self.skin.set_joints(queue, k, joints)?;
                self.on_gpu[k] = true;
            } else if stepper.moved_pose().is_some() {
                self.on_gpu[k] = false;
            }
            if !self.on_gpu[k] {
                continue;
            }
            let (strands, roots_at) = simulation.posed_inputs();
            let normals = driver.fur.base_normals();
            match buffers {
                None => buffers = Some((strands, normals.buffer())),
                Some((s, n)) if s == strands && n == normals.buffer() => {}
                Some(_) => {
                    return Err(RenderError::Count {
                        what: "buffers of a posed herd",
                        expected: 1,
                        got: 2,
                        rule: "members made together (FurDriver::herd_with_asset)",
                    });
                }
            }
            let word = |bytes: u64, size: u64| u32::try_from(bytes / size).unwrap_or(u32::MAX);
            rows.push([k as u32, word(roots_at, 16), word(normals.offset(), 4), 0]);
        }
        if let Some((strands, normals)) = buffers
            && self.bind_group.as_ref().is_none_or(|((s, n), _)| s != strands || n != normals)
        {
            let scope = ErrorScope::push(device);
            let [skin_params, rest, influences, joints] = self.skin.inputs();
            let bind_group = gapped_buffers(
                device,
                "pelt herd posing",
                &self.layout,
                &[skin_params, rest, influences, joints]
                    .map(Some)
                    .into_iter()
                    .chain([None, Some(&self.params), Some(&self.table), Some(strands), Some(normals)])
                    .collect::<Vec<_>>(),
            );
            scope.pop("binding the herd's GPU posing")?;
            self.bind_group = Some(((strands.clone(), normals.clone()), bind_group));
        }
        if rows != self.rows {
            queue.write_buffer(&self.table, 0, bytemuck::cast_slice(&rows));
            let params =
                PlaceParams { vertex_count: self.skin.vertex_count() as u32, rows: rows.len() as u32, padding: [0; 2] };
            queue.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
            self.rows = rows;
        }
        Ok(())
    }

    /// Records the skinning of the members posed on the GPU into their inputs: one dispatch
    /// (none when no member is), before [`FurDriver::record_herd`]. Members are placed every
    /// frame, so a root section rewritten for a new stability gets its position back.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder) {
        let Some((_, bind_group)) = self.bind_group.as_ref().filter(|_| !self.rows.is_empty()) else { return };
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor {
            label: Some("pelt herd posing"),
            timestamp_writes: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, bind_group, &[]);
        let vertices = self.skin.vertex_count() as u32;
        pass.dispatch_workgroups(vertices.div_ceil(WORKGROUP), self.rows.len() as u32, 1);
    }

    /// Members whose last pose is the GPU's.
    #[must_use]
    pub fn members_on_gpu(&self) -> usize {
        self.rows.len()
    }

    /// GPU bytes: the skin's inputs (the rest pose, influences and every member's joints), the
    /// table and its uniform.
    #[must_use]
    pub fn gpu_bytes(&self) -> u64 {
        self.skin.bytes() + self.table.size() + self.params.size()
    }
}
