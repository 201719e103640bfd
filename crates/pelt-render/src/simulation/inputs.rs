//! What a fur's GPU simulation binds and uploads: one bind group per shared-array state it
//! writes, and the per-strand inputs whose versions moved.

use pelt_core::sim::{InputVersions, Simulation};

use super::{GpuSimulation, StepUniform};
use crate::RenderError;
use crate::requirements::ErrorScope;

impl GpuSimulation {
    /// The bind group writing `output` (one of the fur's states), made the first time.
    pub(super) fn bind_group_for(
        &mut self,
        device: &wgpu::Device,
        output: wgpu::BufferSlice<'_>,
    ) -> Result<(), RenderError> {
        let key = (output.buffer(), output.offset());
        if self.bind_groups.iter().any(|((b, at), _)| b == key.0 && *at == key.1) {
            return Ok(());
        }
        let scope = ErrorScope::push(device);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt simulation"),
            layout: &self.pipelines.layout,
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
                wgpu::BindGroupEntry { binding: 2, resource: self.ranges[0].binding(&self.pool.strands) },
                wgpu::BindGroupEntry { binding: 3, resource: self.ranges[1].binding(&self.pool.state) },
                wgpu::BindGroupEntry { binding: 4, resource: crate::pool::binding(output) },
                wgpu::BindGroupEntry { binding: 5, resource: self.contact.buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 6, resource: self.ranges[2].binding(&self.pool.wet) },
                wgpu::BindGroupEntry { binding: 7, resource: self.contact.fields_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 8, resource: self.contact.work.as_entire_binding() },
            ],
        });
        scope.pop("binding the GPU simulation to the fur")?;
        // A fur replaced by another (new structure) leaves its buffers behind: keep the newest.
        if self.bind_groups.len() >= 4 {
            self.bind_groups.remove(0);
        }
        self.bind_groups.push(((key.0.clone(), key.1), bind_group));
        Ok(())
    }

    /// Writes the resident per-strand inputs whose version moved since they were written, and
    /// marks a new touch for the `weigh_touch` pass.
    pub(super) fn upload_inputs(&mut self, queue: &wgpu::Queue, simulation: &Simulation) {
        let versions = simulation.input_versions();
        let inputs = simulation.strand_inputs();
        let v = self.vertex_count as u64;
        let (buffer, at) = (&self.pool.strands, self.ranges[0].at);
        let old = self.uploaded.filter(|(old, _)| old.id == versions.id);
        let changed =
            |version: fn(&InputVersions) -> u64| old.is_none_or(|(old, _)| version(&old) != version(&versions));
        let stability_changed = old.is_none_or(|(_, stability)| {
            inputs.stability_map.is_none() && stability.to_bits() != inputs.stability.to_bits()
        });
        // A base posed on the GPU (`HerdPosing`) has its roots and frames written there, each
        // frame; the roots' section is still written here for its stability (w), the posing
        // then writing over the positions it holds.
        let base_here = changed(|x| x.base) && !simulation.base_posed_elsewhere();
        if base_here || changed(|x| x.stability) || stability_changed {
            let roots: Vec<[f32; 4]> = inputs
                .roots
                .iter()
                .enumerate()
                .map(|(j, root)| root.extend(inputs.stability_of(j)).to_array())
                .collect();
            queue.write_buffer(buffer, at, bytemuck::cast_slice(&roots));
        }
        if base_here {
            let frames: Vec<[f32; 4]> = inputs.frames.iter().map(|frame| frame.to_array()).collect();
            queue.write_buffer(buffer, at + v * 16, bytemuck::cast_slice(&frames));
        }
        let new_touch = changed(|x| x.touch) && simulation.touch().is_some();
        let touch_uploaded = if new_touch { !simulation.touch_began_on_step_roots() } else { self.touch_uploaded };
        self.weigh_touch |= new_touch && !touch_uploaded;
        if changed(|x| x.field) || (new_touch && (touch_uploaded || self.touch_uploaded)) {
            // The field, with the touch's weights in w when they are the CPU's.
            let mut field: Vec<[f32; 4]> = inputs.field.iter().map(|force| force.extend(0.0).to_array()).collect();
            if touch_uploaded {
                for &(j, weight) in inputs.touch_weights {
                    field[j as usize][3] = weight;
                }
            }
            queue.write_buffer(buffer, at + 2 * v * 16, bytemuck::cast_slice(&field));
        }
        self.touch_uploaded = touch_uploaded;
        self.uploaded = Some((versions, inputs.stability));
        self.wet.upload(queue, (&self.pool.wet, self.ranges[2]), &inputs);
    }
}

impl GpuSimulation {
    /// The buffer holding this fur's resident inputs and where its posed roots start in it (the
    /// frames follow, `V` `vec4`s on), for a posing that writes them on the GPU.
    pub(crate) fn posed_inputs(&self) -> (&wgpu::Buffer, u64) {
        (&self.pool.strands, self.ranges[0].at)
    }
}
