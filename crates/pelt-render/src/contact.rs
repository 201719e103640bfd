//! The GPU side of `pelt_core::sim::contact`: one storage buffer holding what the kernel's
//! `contact_strand` (`simulation_contact.wgsl`) reads, packed from the simulation's
//! `ContactStep` per step slot, its skin planes and the grasp's weights.

use pelt_core::FurStructure;
use pelt_core::sim::contact::{MAX_STEP_COLLIDERS, SKIN_PLANES, skin_planes};
use pelt_core::sim::{ContactStep, ContactStrands};

/// Step slots: one per slot of the simulation's uniform ring.
pub(crate) const CONTACT_SLOTS: usize = 64;
/// vec4s per collider.
const COLLIDER_WORDS: usize = 5;
/// The first skin plane, after the slots' headers.
const SKIN_FIRST: usize = 2 * CONTACT_SLOTS;

/// The contact buffer of one fur and what it holds.
#[derive(Debug)]
pub(crate) struct GpuContact {
    pub buffer: wgpu::Buffer,
    vertex_count: usize,
    /// The grasp weights uploaded (empty: all zero).
    weights: Vec<f32>,
}

fn weights_first(v: usize) -> usize {
    SKIN_FIRST + SKIN_PLANES * v
}

fn colliders_first(v: usize, slot: usize) -> usize {
    weights_first(v) + v.div_ceil(4) + slot * MAX_STEP_COLLIDERS * COLLIDER_WORDS
}

impl GpuContact {
    /// The buffer's size in bytes for `v` strands.
    pub fn bytes(v: usize) -> u64 {
        colliders_first(v, CONTACT_SLOTS) as u64 * 16
    }

    /// The buffer with `structure`'s skin planes and no collider or grasp.
    pub fn new(device: &wgpu::Device, structure: &FurStructure) -> Self {
        let v = structure.vertex_count();
        let mut words = vec![[0.0_f32; 4]; colliders_first(v, CONTACT_SLOTS)];
        for (j, planes) in skin_planes(structure).iter().enumerate() {
            for (p, plane) in planes.iter().enumerate() {
                words[SKIN_FIRST + j * SKIN_PLANES + p] = plane.to_array();
            }
        }
        let buffer = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("pelt simulation contact"),
                contents: bytemuck::cast_slice(&words),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            },
        );
        Self { buffer, vertex_count: v, weights: Vec::new() }
    }

    /// Writes step slot `slot`'s header and colliders.
    pub fn write_slot(&self, queue: &wgpu::Queue, slot: usize, step: &ContactStep) {
        let count = step.colliders.len().min(MAX_STEP_COLLIDERS);
        let header = [
            [f32::from_bits(count as u32), if step.skin { 1.0 } else { 0.0 }, step.grip_presence, 0.0],
            step.grip.extend(0.0).to_array(),
        ];
        queue.write_buffer(&self.buffer, (2 * slot) as u64 * 16, bytemuck::cast_slice(&header));
        if count == 0 {
            return;
        }
        let words: Vec<[f32; 4]> = step.colliders[..count]
            .iter()
            .flat_map(|c| {
                [
                    c.centre.extend(c.radius).to_array(),
                    c.half_extents.extend(f32::from_bits(c.kind)).to_array(),
                    c.rotation.to_array(),
                    c.travel.extend(c.friction).to_array(),
                    [c.bound, if c.grasp_hand { 1.0 } else { 0.0 }, 0.0, 0.0],
                ]
            })
            .collect();
        queue.write_buffer(
            &self.buffer,
            colliders_first(self.vertex_count, slot) as u64 * 16,
            bytemuck::cast_slice(&words),
        );
    }

    /// Writes the grasp's weights when they changed.
    pub fn write_strands(&mut self, queue: &wgpu::Queue, strands: &ContactStrands<'_>) {
        let v = self.vertex_count;
        if strands.grasp_weights == self.weights.as_slice()
            || (strands.grasp_weights.is_empty() && self.weights.is_empty())
        {
            return;
        }
        let mut packed = vec![0.0_f32; v.div_ceil(4).max(1) * 4];
        packed[..strands.grasp_weights.len().min(v)]
            .copy_from_slice(&strands.grasp_weights[..strands.grasp_weights.len().min(v)]);
        packed.truncate(v.div_ceil(4) * 4);
        if !packed.is_empty() {
            queue.write_buffer(&self.buffer, weights_first(v) as u64 * 16, bytemuck::cast_slice(&packed));
        }
        self.weights = strands.grasp_weights.to_vec();
    }
}
