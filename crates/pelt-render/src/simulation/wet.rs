//! Wet strands' weights as the GPU simulation reads them.

use pelt_core::sim::StrandInputs;

use super::pool::Range;

/// Wet strands' extra weight, kept apart from the other per-strand inputs (binding 6): per
/// strand, gravity's factor and the mass on the inertial spring, both `1 + added_weight * w`. A
/// wet strand's lower stability rides in the strands buffer ([`StrandInputs::stability_of`]).
/// The weights live in the fur's range of its pool's buffer, which starts as all ones.
#[derive(Debug, Default)]
pub(super) struct WetInputs {
    /// What the range holds; empty while it holds all ones.
    uploaded: Vec<[f32; 2]>,
}

impl WetInputs {
    pub fn upload(&mut self, queue: &wgpu::Queue, (buffer, range): (&wgpu::Buffer, Range), inputs: &StrandInputs<'_>) {
        if inputs.wetness.is_none() && self.uploaded.is_empty() {
            return;
        }
        let scales: Vec<[f32; 2]> = (0..inputs.roots.len()).map(|j| [inputs.gravity_scale_of(j); 2]).collect();
        if scales != self.uploaded {
            queue.write_buffer(buffer, range.at, bytemuck::cast_slice(&scales));
            self.uploaded = if inputs.wetness.is_none() { Vec::new() } else { scales };
        }
    }
}
