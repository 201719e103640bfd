//! A pool's contact: what the steps with contact of every copy made together read, in one buffer
//! (laid out as `simulation_pooled.wgsl` describes), and one list of the strands their screens
//! could not clear, so every copy's step with contact takes the same two dispatches.
//!
//! The buffer is made when the first copy steps with contact. It holds the skin once (the copies
//! share their rest mesh), the mesh colliders' fields the copies' steps use, and a block per copy
//! with room for as many colliders a slot as the busiest copy needs. When it grows, every copy's
//! pending slots and weights are written again from what is kept here, so a copy that wrote its
//! slots earlier in the frame keeps them.

use std::sync::{Arc, Mutex, MutexGuard, PoisonError};

use pelt_core::sim::{ColliderMesh, ContactStep, ContactStrands};

use super::STEP_SLOT_BYTES;
use crate::RenderError;
use crate::contact::{
    COLLIDER_WORDS, CONTACT_SLOTS, GpuContact, Skin, collider_words, field_words, fields_fit, packed_weights,
    slot_header, slot_room,
};
use crate::requirements::{ErrorScope, check_size};
use crate::sim_pipelines::PooledContact;

/// A pool's contact, made when a copy first steps with contact.
#[derive(Debug)]
pub(crate) struct PoolContact {
    vertex_count: usize,
    slots: u32,
    held: Mutex<Option<Held>>,
}

/// What one copy's block holds: its pending steps by ring slot, and its grasp's weights.
#[derive(Debug, Default)]
struct CopyContact {
    steps: Vec<(usize, ContactStep)>,
    weights: Vec<f32>,
}

/// Where the parts begin, in vec4s.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Layout {
    fields_first: usize,
    blocks_first: usize,
    /// vec4s of a copy's block.
    stride: usize,
    /// Colliders a slot has room for.
    room: usize,
}

#[derive(Debug)]
struct Held {
    buffer: wgpu::Buffer,
    layout: Layout,
    /// The skin's planes, cones and triangles (none until a copy has found them) and the rest
    /// roots its triangle headers start from.
    skin: Option<(Skin, Vec<glam::Vec3>)>,
    fields: Vec<(Arc<ColliderMesh>, u32)>,
    copies: Vec<CopyContact>,
    reach: f32,
    /// The steps of a pooled contact dispatch's copies, packed from 0.
    steps: wgpu::Buffer,
    /// `simulation_contact.wgsl`'s `ContactWork` for every copy's strands, and its dispatch
    /// arguments.
    work: wgpu::Buffer,
    work_groups: wgpu::Buffer,
    /// The bind group, for the rest segments and shared vertex arrays it binds; made again with
    /// the buffer.
    bind_group: Option<((wgpu::Buffer, wgpu::Buffer), wgpu::BindGroup)>,
}

/// What a pooled contact dispatch binds and reads its arguments from.
pub(crate) struct ContactRun {
    pub steps: wgpu::Buffer,
    pub work: wgpu::Buffer,
    pub work_groups: wgpu::Buffer,
    pub bind_group: wgpu::BindGroup,
}

/// What one copy's prepare gives its pool.
pub(crate) struct CopySteps<'a> {
    /// The copy's slot in the pool.
    pub copy: u32,
    /// Its pending steps with contact, by ring slot.
    pub steps: Vec<(usize, &'a ContactStep)>,
    pub strands: &'a ContactStrands<'a>,
    /// Whether its simulation has found the skin's planes and triangles.
    pub skin_found: bool,
    /// Its strands' reach ([`GpuContact::reach`]).
    pub reach: f32,
}

/// The buffers a pooled dispatch binds besides the contact's: the pool's strand inputs, state and
/// wet strands, the rest segments and the shared vertex arrays.
pub(crate) struct PoolBuffers<'a> {
    pub strands: &'a wgpu::Buffer,
    pub state: &'a wgpu::Buffer,
    pub wet: &'a wgpu::Buffer,
    pub rest: &'a wgpu::Buffer,
    pub positions: &'a wgpu::Buffer,
}

impl PoolContact {
    pub fn new(vertex_count: usize, slots: u32) -> Self {
        Self { vertex_count: vertex_count.max(1), slots: slots.max(1), held: Mutex::new(None) }
    }

    /// Whether a copy has stepped with contact.
    pub fn is_made(&self) -> bool {
        self.lock().is_some()
    }

    fn lock(&self) -> MutexGuard<'_, Option<Held>> {
        self.held.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Bytes it holds for copy `slot`: its block, its share of the list and its step; slot 0
    /// also counts the header, the skin and the fields. Nothing before a copy steps with contact.
    pub fn slot_bytes(&self, slot: u32) -> u64 {
        let held = self.lock();
        let Some(held) = held.as_ref() else { return 0 };
        let shared = if slot == 0 { held.layout.blocks_first as u64 * 16 + 16 + 16 } else { 0 };
        held.layout.stride as u64 * 16 + 8 * self.vertex_count as u64 + STEP_SLOT_BYTES + shared
    }

    /// Writes a copy's pending steps with contact and its grasp's weights into its block, making
    /// the buffer (or making it again, larger: more colliders, a new field, the skin found) first
    /// when it must; and the bind group for `buffers`.
    ///
    /// # Errors
    /// [`RenderError::TooLarge`] when the buffer would exceed the device's limits;
    /// [`RenderError::Gpu`] when the device refuses a buffer or the bind group.
    pub fn prepare_copy(
        &self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        pipeline: &PooledContact,
        copy: &CopySteps<'_>,
        buffers: &PoolBuffers<'_>,
    ) -> Result<(), RenderError> {
        let v = self.vertex_count;
        let mut guard = self.lock();
        let index = copy.copy as usize;
        let steps: Vec<(usize, ContactStep)> = copy.steps.iter().map(|&(slot, step)| (slot, step.clone())).collect();
        let weights_changed;
        let remake = {
            let held = guard.as_ref();
            let old_copy = held.and_then(|h| h.copies.get(index));
            let old_weights = old_copy.map_or(&[][..], |c| &c.weights[..]);
            weights_changed = old_weights != copy.strands.grasp_weights;
            match held {
                None => true,
                Some(held) => {
                    (copy.skin_found && held.skin.is_none() && steps.iter().any(|(_, s)| s.skin))
                        || slot_room(steps.iter().map(|(_, s)| s)) > held.layout.room
                        || steps
                            .iter()
                            .flat_map(|(_, s)| &s.colliders)
                            .filter_map(|c| c.mesh.as_ref())
                            .any(|m| !held.fields.iter().any(|(f, _)| Arc::ptr_eq(f, m)))
                }
            }
        };
        if remake {
            let previous = guard.take();
            let made = self.make(device, queue, previous, copy, steps)?;
            *guard = Some(made);
        } else if let Some(held) = guard.as_mut() {
            let kept = &mut held.copies[index];
            kept.steps = steps;
            if weights_changed {
                kept.weights = copy.strands.grasp_weights.to_vec();
                held.write_weights(queue, index, v);
            }
            held.write_steps(queue, index, v);
        }
        let Some(held) = guard.as_mut() else { return Ok(()) };
        let bound = held
            .bind_group
            .as_ref()
            .is_some_and(|((rest, positions), _)| rest == buffers.rest && positions == buffers.positions);
        if !bound {
            let scope = ErrorScope::push(device);
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pelt simulation pooled contact"),
                layout: &pipeline.layout,
                entries: &[
                    wgpu::BindGroupEntry { binding: 0, resource: held.steps.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 1, resource: buffers.rest.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 2, resource: buffers.strands.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 3, resource: buffers.state.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 4, resource: buffers.positions.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 5, resource: held.buffer.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 6, resource: buffers.wet.as_entire_binding() },
                    wgpu::BindGroupEntry { binding: 8, resource: held.work.as_entire_binding() },
                ],
            });
            scope.pop("binding a herd's GPU contact")?;
            held.bind_group = Some(((buffers.rest.clone(), buffers.positions.clone()), bind_group));
        }
        Ok(())
    }

    /// What a dispatch of the pool's copies with contact binds, once a copy prepared one.
    pub fn run(&self) -> Option<ContactRun> {
        let held = self.lock();
        let held = held.as_ref()?;
        let (_, bind_group) = held.bind_group.as_ref()?;
        Some(ContactRun {
            steps: held.steps.clone(),
            work: held.work.clone(),
            work_groups: held.work_groups.clone(),
            bind_group: bind_group.clone(),
        })
    }

    /// The buffer made (again) with room for every copy's kept steps and `copy`'s new ones, and
    /// every copy's slots and weights written into it.
    fn make(
        &self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        previous: Option<Held>,
        copy: &CopySteps<'_>,
        steps: Vec<(usize, ContactStep)>,
    ) -> Result<Held, RenderError> {
        let v = self.vertex_count;
        let index = copy.copy as usize;
        let (mut copies, mut skin, room, reach, old) = match previous {
            Some(held) => {
                (held.copies, held.skin, held.layout.room, held.reach, Some((held.steps, held.work, held.work_groups)))
            }
            None => {
                let copies = (0..self.slots).map(|_| CopyContact::default()).collect();
                (copies, None, 0, copy.reach, None)
            }
        };
        if let Some(kept) = copies.get_mut(index) {
            kept.steps = steps;
            kept.weights = copy.strands.grasp_weights.to_vec();
        }
        if skin.is_none() && copy.skin_found {
            skin = Some((Skin::of(copy.strands), copy.strands.rest_roots.to_vec()));
        }
        let kept_steps = || copies.iter().flat_map(|c| c.steps.iter().map(|(_, s)| s));
        let room = room.max(slot_room(kept_steps()));
        let (field_floats, fields) =
            field_words(kept_steps().flat_map(|s| s.colliders.iter().filter_map(|c| c.mesh.as_ref())));
        fields_fit(field_floats.len(), &device.limits())?;
        let none = Skin::none(v);
        let (skin_ref, roots): (&Skin, &[glam::Vec3]) = match &skin {
            Some((skin, roots)) => (skin, roots),
            None => (&none, &[]),
        };
        let fields_first = 1 + skin_ref.shared_words();
        let blocks_first = fields_first + field_floats.len().div_ceil(4);
        let stride = 2 * CONTACT_SLOTS + v.div_ceil(4) + CONTACT_SLOTS * room * COLLIDER_WORDS;
        let layout = Layout { fields_first, blocks_first, stride, room };
        let bytes = (blocks_first + self.slots as usize * stride) as u64 * 16;
        check_size(device, "a herd's simulation contact", bytes)?;
        let work_bytes = GpuContact::work_bytes(v * self.slots as usize);
        check_size(device, "a herd's simulation contact list", work_bytes)?;
        let mut words: Vec<[f32; 4]> = Vec::with_capacity(blocks_first);
        words.push([stride, blocks_first, fields_first, 0].map(|n| f32::from_bits(n as u32)));
        words.extend(skin_ref.planes_and_cones());
        words.extend(skin_ref.surface_words(roots));
        debug_assert_eq!(words.len(), fields_first);
        let mut floats = field_floats;
        floats.resize(floats.len().div_ceil(4) * 4, 0.0);
        words.extend(floats.chunks(4).map(|c| [c[0], c[1], c[2], c[3]]));
        let scope = ErrorScope::push(device);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt simulation herd contact"),
            size: bytes,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        queue.write_buffer(&buffer, 0, bytemuck::cast_slice(&words));
        let (steps, work, work_groups) = match old {
            Some(old) => old,
            None => (
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("pelt simulation herd contact steps"),
                    size: STEP_SLOT_BYTES * u64::from(self.slots),
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("pelt simulation herd contact list"),
                    size: work_bytes,
                    usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
                device.create_buffer(&wgpu::BufferDescriptor {
                    label: Some("pelt simulation herd contact dispatch"),
                    size: 16,
                    usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
                    mapped_at_creation: false,
                }),
            ),
        };
        scope.pop("making a herd's GPU contact")?;
        let held = Held { buffer, layout, skin, fields, copies, reach, steps, work, work_groups, bind_group: None };
        // The new buffer is zero: weights only where a copy holds some.
        for k in 0..held.copies.len() {
            if !held.copies[k].weights.is_empty() {
                held.write_weights(queue, k, v);
            }
            held.write_steps(queue, k, v);
        }
        Ok(held)
    }
}

impl Held {
    /// Where copy `k`'s block begins.
    fn block(&self, k: usize) -> usize {
        self.layout.blocks_first + k * self.layout.stride
    }

    /// Copy `k`'s grasp weights (zero where it holds none).
    fn write_weights(&self, queue: &wgpu::Queue, k: usize, v: usize) {
        let weights = &self.copies[k].weights;
        let packed = packed_weights(v, weights);
        let at = (self.block(k) + 2 * CONTACT_SLOTS) as u64 * 16;
        queue.write_buffer(&self.buffer, at, bytemuck::cast_slice(&packed));
    }

    /// Copy `k`'s pending slots: each header and its colliders.
    fn write_steps(&self, queue: &wgpu::Queue, k: usize, v: usize) {
        let block = self.block(k);
        let colliders = block + 2 * CONTACT_SLOTS + v.div_ceil(4);
        let offset =
            |mesh: &Arc<ColliderMesh>| self.fields.iter().find(|(m, _)| Arc::ptr_eq(m, mesh)).map(|(_, at)| *at);
        for (slot, step) in &self.copies[k].steps {
            let count = step.colliders.len().min(self.layout.room);
            let first = colliders + slot * self.layout.room * COLLIDER_WORDS;
            let header = slot_header(step, count, self.reach, first);
            queue.write_buffer(&self.buffer, (block + 2 * slot) as u64 * 16, bytemuck::cast_slice(&header));
            if count > 0 {
                let words = collider_words(&step.colliders[..count], offset);
                queue.write_buffer(&self.buffer, first as u64 * 16, bytemuck::cast_slice(&words));
            }
        }
    }
}
