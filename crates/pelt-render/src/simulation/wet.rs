//! Wet strands' weights as the GPU simulation reads them.

use pelt_core::sim::StrandInputs;

/// Wet strands' extra weight, kept apart from the other per-strand inputs (binding 6): per
/// strand, gravity's factor and the mass on the inertial spring, both `1 + added_weight * w`. A
/// wet strand's lower stability rides in the strands buffer ([`StrandInputs::stability_of`]).
#[derive(Debug)]
pub(super) struct WetInputs {
    pub buffer: wgpu::Buffer,
    /// What the buffer holds; empty while it holds all ones.
    uploaded: Vec<[f32; 2]>,
}

impl WetInputs {
    pub fn new(device: &wgpu::Device, strands: usize) -> Self {
        let buffer = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("pelt simulation wet strands"),
                contents: bytemuck::cast_slice(&vec![[1.0_f32; 2]; strands.max(1)]),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            },
        );
        Self { buffer, uploaded: Vec::new() }
    }

    pub fn upload(&mut self, queue: &wgpu::Queue, inputs: &StrandInputs<'_>) {
        if inputs.wetness.is_none() && self.uploaded.is_empty() {
            return;
        }
        let scales: Vec<[f32; 2]> = (0..inputs.roots.len()).map(|j| [inputs.gravity_scale_of(j); 2]).collect();
        if scales != self.uploaded {
            queue.write_buffer(&self.buffer, 0, bytemuck::cast_slice(&scales));
            self.uploaded = if inputs.wetness.is_none() { Vec::new() } else { scales };
        }
    }
}
