//! The GPU side of `pelt_core::sim::contact`: one storage buffer holding what the kernels of
//! `simulation_contact.wgsl` read, packed from the simulation's `ContactStep` per step slot, its
//! skin planes and cones and the grasp's weights; one holding the distance fields of mesh
//! colliders, each uploaded once; and the list of strands a step's screen could not clear, with
//! the dispatch arguments of the kernel that solves them.
//!
//! Each step slot holds as many colliders as the fur's busiest step has needed so far (a power of
//! two, up to `MAX_STEP_COLLIDERS`), so a coat nothing touches keeps no collider room in its 64
//! slots; more colliders grow the buffer (and its bind groups are made again).

use std::sync::Arc;

use pelt_core::FurStructure;
use pelt_core::sim::ColliderMesh;
use pelt_core::sim::contact::{MAX_STEP_COLLIDERS, SKIN_PLANES, SURFACE_WORDS, SkinSurface, skin_cone};
use pelt_core::sim::{ContactStep, ContactStrands, StepCollider};

use crate::RenderError;
use crate::requirements::check_size;

/// Step slots: one per slot of the simulation's uniform ring.
pub(crate) const CONTACT_SLOTS: usize = 64;
/// vec4s per collider.
pub(crate) const COLLIDER_WORDS: usize = 5;
/// The first skin plane, after the slots' headers.
const SKIN_FIRST: usize = 2 * CONTACT_SLOTS;
/// The fewest colliders a slot makes room for once any step has one.
const MIN_SLOT_COLLIDERS: usize = 4;

/// The contact buffer of one fur and what it holds.
#[derive(Debug)]
pub(crate) struct GpuContact {
    pub buffer: wgpu::Buffer,
    vertex_count: usize,
    /// vec4s before the first slot's colliders (headers, skin, weights, triangles): what a
    /// buffer grown for more colliders copies from the one before.
    prefix_words: usize,
    /// Colliders each step slot has room for (0 until a step has one).
    slot_colliders: usize,
    /// The longest strand's length (a little over), in each slot's header: the solve's bound on
    /// how far from its root a strand reaches.
    reach: f32,
    /// The grasp weights uploaded (empty: all zero).
    weights: Vec<f32>,
    /// Mesh colliders' distance fields (`simulation_contact.wgsl`'s `sdf_fields`).
    pub fields_buffer: wgpu::Buffer,
    /// `simulation_contact.wgsl`'s `ContactWork`: the solve's workgroups and the listed strands.
    pub work: wgpu::Buffer,
    /// The solve's indirect dispatch arguments, copied from `work` (a dispatch cannot read its
    /// arguments from a buffer it writes).
    pub work_groups: wgpu::Buffer,
    /// The fields in `fields_buffer` and where each begins (in f32s); kept alive, so no other
    /// field can take an `Arc`'s address while it is listed.
    fields: Vec<(Arc<ColliderMesh>, u32)>,
}

/// f32s before a field's values: (origin xyz, cell), (dims xyz as bits, -).
const FIELD_HEADER: usize = 8;

fn fields_buffer(device: &wgpu::Device, words: &[f32]) -> wgpu::Buffer {
    wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("pelt simulation mesh collider fields"),
            contents: bytemuck::cast_slice(words),
            usage: wgpu::BufferUsages::STORAGE,
        },
    )
}

/// The fields of `meshes` (each once) as the fields buffer holds them, and where each begins.
pub(crate) fn field_words<'a>(
    meshes: impl Iterator<Item = &'a Arc<ColliderMesh>>,
) -> (Vec<f32>, Vec<(Arc<ColliderMesh>, u32)>) {
    let mut words = Vec::new();
    let mut fields: Vec<(Arc<ColliderMesh>, u32)> = Vec::new();
    for mesh in meshes {
        if fields.iter().any(|(m, _)| Arc::ptr_eq(m, mesh)) {
            continue;
        }
        let field = mesh.field();
        let offset = u32::try_from(words.len()).unwrap_or(u32::MAX);
        let dims = field.dims().map(|n| f32::from_bits(n as u32));
        words.extend(field.origin().to_array());
        words.push(field.cell());
        words.extend(dims);
        words.push(0.0);
        debug_assert_eq!(words.len() - offset as usize, FIELD_HEADER);
        words.extend_from_slice(field.values());
        fields.push((Arc::clone(mesh), offset));
    }
    (words, fields)
}

/// Whether `words` floats of fields fit one storage buffer binding of a device with `limits`.
pub(crate) fn fields_fit(words: usize, limits: &wgpu::Limits) -> Result<(), RenderError> {
    let bytes = 4 * words as u64;
    let limit = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
    if bytes > limit {
        return Err(RenderError::TooLarge { what: "mesh colliders' distance fields", bytes, limit });
    }
    Ok(())
}

/// The grasp's weights, after the slots' headers.
fn weights_first() -> usize {
    SKIN_FIRST
}

/// The skin's planes (`simulation_lone.wgsl`'s `planes_first`), after the weights; then the
/// cones and the triangle part, once the skin is found.
fn planes_first(v: usize) -> usize {
    weights_first() + v.div_ceil(4)
}

/// Where slot `slot`'s colliders begin after `prefix_words` vec4s (`Skin::prefix_words`), each
/// slot with room for `slot_colliders` (the slot's header tells the kernels).
fn colliders_first(prefix_words: usize, slot: usize, slot_colliders: usize) -> usize {
    prefix_words + slot * slot_colliders * COLLIDER_WORDS
}

/// The buffer's bytes: `prefix_words` vec4s, then every slot's room for `slot_colliders`.
fn buffer_bytes(prefix_words: usize, slot_colliders: usize) -> u64 {
    colliders_first(prefix_words, CONTACT_SLOTS, slot_colliders) as u64 * 16
}

// A strand's header packs its triangle count in 6 bits.
const _: () = assert!(pelt_core::sim::contact::surface::MAX_STRAND_TRIANGLES < 64);

/// The skin's planes and triangles of one fur of `v` strands, as the buffer packs them.
#[derive(Debug)]
pub(crate) struct Skin {
    v: usize,
    /// Every strand's planes, or none until the simulation has found them.
    planes: Vec<[glam::Vec4; SKIN_PLANES]>,
    surface: SkinSurface,
}

impl Skin {
    /// No planes and no triangles for `v` strands: what the buffer holds until the simulation
    /// has found its skin setup (a step with the skin off reads none of it, so none is kept).
    pub fn none(v: usize) -> Self {
        Self { v, planes: Vec::new(), surface: SkinSurface::default() }
    }

    /// The simulation's skin planes and triangles (`pelt_core::sim::contact`).
    pub fn of(strands: &ContactStrands<'_>) -> Self {
        Self { v: strands.skin.len(), planes: strands.skin.to_vec(), surface: strands.surface.clone() }
    }

    /// Each strand's cone (`skin_cone`), for the screen.
    fn cones(&self) -> impl Iterator<Item = glam::Vec4> + '_ {
        self.planes.iter().map(skin_cone)
    }

    /// Every strand's `SKIN_PLANES` planes, then every strand's cone.
    pub fn planes_and_cones(&self) -> impl Iterator<Item = [f32; 4]> + '_ {
        self.planes.iter().flat_map(|planes| planes.map(|p| p.to_array())).chain(self.cones().map(|c| c.to_array()))
    }

    /// The triangle part (`simulation_contact.wgsl`'s `surface_closest`) for strands rooted at
    /// `roots` at rest: a header per strand, the lists (each entry its triangle's first vec4,
    /// counted from the headers), the triangles.
    pub fn surface_words(&self, roots: &[glam::Vec3]) -> Vec<[f32; 4]> {
        let surface = &self.surface;
        let mut words: Vec<[f32; 4]> = surface
            .strands
            .iter()
            .zip(roots)
            .map(|([first, count], root)| root.extend(f32::from_bits((first << 6) | count)).to_array())
            .collect();
        let triangles_first = (roots.len() + surface.lists.len().div_ceil(4)) as u32;
        words.extend(surface.lists.chunks(4).map(|c| {
            let mut w = [0.0_f32; 4];
            for (slot, index) in w.iter_mut().zip(c) {
                *slot = f32::from_bits(triangles_first + index * SURFACE_WORDS as u32);
            }
            w
        }));
        words.extend(surface.triangles.iter().flat_map(|t| t.map(|w| w.to_array())));
        words
    }

    /// vec4s of the planes, cones and triangle part (what a pool holds once).
    pub fn shared_words(&self) -> usize {
        (SKIN_PLANES + 1) * self.planes.len() + self.words()
    }

    /// vec4s of the triangle part: a header per strand (rest root, `first << 6 | count`), the
    /// lists four indices a vec4, then the triangles.
    fn words(&self) -> usize {
        self.surface.strands.len() + self.surface.lists.len().div_ceil(4) + self.surface.triangles.len() * SURFACE_WORDS
    }

    /// vec4s of the buffer before the colliders: the slots' headers, the weights, then the
    /// planes, cones and triangle part.
    fn prefix_words(&self) -> usize {
        planes_first(self.v) + self.shared_words()
    }
}

impl GpuContact {
    /// The buffer's size in bytes for `skin`'s fur with room for `slot_colliders` colliders in
    /// each step slot.
    pub fn bytes(skin: &Skin, slot_colliders: usize) -> u64 {
        buffer_bytes(skin.prefix_words(), slot_colliders)
    }

    /// The longest strand's length (a little over), each slot's bound on a strand's reach.
    pub fn reach(&self) -> f32 {
        self.reach
    }

    /// Colliders each step slot has room for now.
    pub fn slot_colliders(&self) -> usize {
        self.slot_colliders
    }

    /// Bytes of the list of a fur of `v` strands: the header (`groups`, `count`), and a strand
    /// index and a segment per strand.
    pub fn work_bytes(v: usize) -> u64 {
        16 + 8 * v.max(1) as u64
    }

    /// The buffer with `skin` (planes and triangles) for `structure`'s strands and no collider
    /// or grasp (nor room for one).
    pub fn new(device: &wgpu::Device, structure: &FurStructure, skin: &Skin) -> Self {
        let v = structure.vertex_count();
        let buffer = skin_buffer(device, &structure.positions[..v], skin, 0);
        let fields_buffer = fields_buffer(device, &[0.0; 4]);
        let work = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt simulation contact list"),
            size: Self::work_bytes(v),
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let work_groups = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt simulation contact dispatch"),
            size: 16,
            usage: wgpu::BufferUsages::INDIRECT | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        Self {
            buffer,
            vertex_count: v,
            prefix_words: skin.prefix_words(),
            slot_colliders: 0,
            reach: reach(structure),
            weights: Vec::new(),
            fields_buffer,
            work,
            work_groups,
            fields: Vec::new(),
        }
    }

    /// The contact of a copy whose steps with contact read its pool's: the strands' reach alone,
    /// and buffers of a few bytes for the bind groups of its steps without contact (which read
    /// none of them).
    pub fn unused(device: &wgpu::Device, structure: &FurStructure) -> Self {
        // Room for a list's header and one entry, the least a list's binding holds.
        let tiny = |label, usage| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: Self::work_bytes(1),
                usage,
                mapped_at_creation: false,
            })
        };
        Self {
            buffer: tiny("pelt simulation contact (the pool's)", CONTACT_USAGE),
            vertex_count: structure.vertex_count(),
            prefix_words: 0,
            slot_colliders: 0,
            reach: reach(structure),
            weights: Vec::new(),
            fields_buffer: fields_buffer(device, &[0.0; 4]),
            work: tiny("pelt simulation contact list (the pool's)", wgpu::BufferUsages::STORAGE),
            work_groups: tiny("pelt simulation contact dispatch (the pool's)", wgpu::BufferUsages::INDIRECT),
            fields: Vec::new(),
        }
    }

    /// Puts `skin` in a new buffer (its size follows the triangles); the grasp's weights are
    /// written again at the next step, the slots are written every step. `roots`: the strands'
    /// rest roots.
    pub fn set_skin(&mut self, device: &wgpu::Device, roots: &[glam::Vec3], skin: &Skin) {
        self.prefix_words = skin.prefix_words();
        self.buffer = skin_buffer(device, roots, skin, self.slot_colliders);
        self.weights.clear();
    }

    /// Makes room for `steps`' colliders in every slot; true when the buffer was replaced (its
    /// bind groups with it). The new buffer takes the old one's skin and weights by a copy on
    /// the GPU (submitted here), so nothing of the skin is kept on the CPU.
    ///
    /// # Errors
    /// [`RenderError::TooLarge`] when the grown buffer would exceed the device's limits; nothing
    /// changes then.
    pub fn make_room(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        steps: &[ContactStep],
    ) -> Result<bool, RenderError> {
        let room = slot_room(steps);
        if room <= self.slot_colliders {
            return Ok(false);
        }
        let size = buffer_bytes(self.prefix_words, room);
        check_size(device, "simulation contact", size)?;
        let grown = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt simulation contact"),
            size,
            usage: CONTACT_USAGE,
            mapped_at_creation: false,
        });
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pelt contact room") });
        encoder.copy_buffer_to_buffer(&self.buffer, 0, &grown, 0, self.prefix_words as u64 * 16);
        queue.submit([encoder.finish()]);
        self.buffer = grown;
        self.slot_colliders = room;
        Ok(true)
    }

    /// Empties the list before a step's screen.
    pub fn clear_work(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.clear_buffer(&self.work, 0, Some(16));
    }

    /// The workgroups the screen counted, as the solve's dispatch arguments.
    pub fn copy_work_groups(&self, encoder: &mut wgpu::CommandEncoder) {
        encoder.copy_buffer_to_buffer(&self.work, 0, &self.work_groups, 0, 12);
    }

    /// Uploads the fields of the mesh colliders in `steps` not uploaded yet; true when the
    /// fields buffer was replaced (its bind groups with it). A new field rebuilds the buffer
    /// with the fields `steps` use, dropping the rest; a field already there is not written again.
    ///
    /// # Errors
    /// [`RenderError::TooLarge`] when the fields would exceed the device's storage buffer
    /// limits (a host's field baked finer than this GPU holds); nothing changes then.
    pub fn upload_fields(&mut self, device: &wgpu::Device, steps: &[ContactStep]) -> Result<bool, RenderError> {
        let used = || steps.iter().flat_map(|s| s.colliders.iter().filter_map(|c| c.mesh.as_ref()));
        if used().all(|m| self.offset(m).is_some()) {
            return Ok(false);
        }
        let (words, fields) = field_words(used());
        fields_fit(words.len(), &device.limits())?;
        self.fields = fields;
        self.fields_buffer = fields_buffer(device, &words);
        Ok(true)
    }

    /// Where `mesh`'s field begins in the fields buffer, if it is there.
    fn offset(&self, mesh: &Arc<ColliderMesh>) -> Option<u32> {
        self.fields.iter().find(|(m, _)| Arc::ptr_eq(m, mesh)).map(|(_, offset)| *offset)
    }

    /// Writes step slot `slot`'s header and colliders (as many as [`GpuContact::make_room`]
    /// made room for).
    pub fn write_slot(&self, queue: &wgpu::Queue, slot: usize, step: &ContactStep) {
        let count = step.colliders.len().min(self.slot_colliders);
        debug_assert_eq!(count, step.colliders.len().min(MAX_STEP_COLLIDERS), "make_room first");
        let first = colliders_first(self.prefix_words, slot, self.slot_colliders);
        let header = slot_header(step, count, self.reach, first);
        queue.write_buffer(&self.buffer, (2 * slot) as u64 * 16, bytemuck::cast_slice(&header));
        if count == 0 {
            return;
        }
        let words = collider_words(&step.colliders[..count], |m| self.offset(m));
        queue.write_buffer(&self.buffer, first as u64 * 16, bytemuck::cast_slice(&words));
    }

    /// Writes the grasp's weights when they changed.
    pub fn write_strands(&mut self, queue: &wgpu::Queue, strands: &ContactStrands<'_>) {
        let v = self.vertex_count;
        if strands.grasp_weights == self.weights.as_slice()
            || (strands.grasp_weights.is_empty() && self.weights.is_empty())
        {
            return;
        }
        let packed = packed_weights(v, strands.grasp_weights);
        if !packed.is_empty() {
            queue.write_buffer(&self.buffer, weights_first() as u64 * 16, bytemuck::cast_slice(&packed));
        }
        self.weights = strands.grasp_weights.to_vec();
    }
}

/// `colliders` as a slot holds them, 5 vec4s each; `field` says where a mesh's field begins.
pub(crate) fn collider_words(
    colliders: &[StepCollider],
    field: impl Fn(&Arc<ColliderMesh>) -> Option<u32>,
) -> Vec<[f32; 4]> {
    colliders
        .iter()
        .flat_map(|c| {
            [
                c.centre.extend(c.radius).to_array(),
                c.half_extents.extend(f32::from_bits(c.kind)).to_array(),
                c.rotation.to_array(),
                c.travel.extend(c.friction).to_array(),
                [
                    c.bound,
                    if c.grasp_hand { 1.0 } else { 0.0 },
                    // A mesh's field, uploaded first.
                    f32::from_bits(c.mesh.as_ref().and_then(&field).unwrap_or(0)),
                    0.0,
                ],
            ]
        })
        .collect()
}

/// A slot's header: (collider count, skin on, grip presence, `reach`), (grip, where its `count`
/// colliders begin).
pub(crate) fn slot_header(step: &ContactStep, count: usize, reach: f32, first: usize) -> [[f32; 4]; 2] {
    [
        [f32::from_bits(count as u32), if step.skin { 1.0 } else { 0.0 }, step.grip_presence, reach],
        step.grip.extend(f32::from_bits(first as u32)).to_array(),
    ]
}

/// The grasp's `weights` for `v` strands, four a vec4 (zero past the weights given).
pub(crate) fn packed_weights(v: usize, weights: &[f32]) -> Vec<f32> {
    let mut packed = vec![0.0_f32; v.div_ceil(4) * 4];
    let n = weights.len().min(v);
    packed[..n].copy_from_slice(&weights[..n]);
    packed
}

/// The longest strand of `structure` (a little over).
fn reach(structure: &FurStructure) -> f32 {
    let (v, layers) = (structure.vertex_count(), structure.layers as usize);
    let longest = (0..v)
        .map(|j| {
            (0..layers).map(|k| structure.positions[(k + 1) * v + j].distance(structure.positions[k * v + j])).sum()
        })
        .fold(0.0_f32, f32::max);
    longest * 1.001
}

/// Colliders a slot makes room for to hold the busiest of `steps`.
pub(crate) fn slot_room<'a>(steps: impl IntoIterator<Item = &'a ContactStep>) -> usize {
    room_for(steps.into_iter().map(|s| s.colliders.len()).max().unwrap_or(0))
}

/// Room for `most` colliders: none for none, else a power of two from `MIN_SLOT_COLLIDERS` to
/// `MAX_STEP_COLLIDERS` (so a coat whose colliders come one by one is not made again for each).
fn room_for(most: usize) -> usize {
    if most == 0 { 0 } else { most.next_power_of_two().clamp(MIN_SLOT_COLLIDERS, MAX_STEP_COLLIDERS) }
}

/// The contact buffer for `roots.len()` strands: the slots' headers (zero), `skin`'s planes and
/// cones, the weights (zero), the skin triangles, then room for `slot_colliders` colliders in
/// each slot.
fn skin_buffer(device: &wgpu::Device, roots: &[glam::Vec3], skin: &Skin, slot_colliders: usize) -> wgpu::Buffer {
    let v = roots.len();
    // The headers, and the grasp's weights, written by `write_strands`.
    let mut words = vec![[0.0_f32; 4]; planes_first(v)];
    words.extend(skin.planes_and_cones());
    words.extend(skin.surface_words(roots));
    debug_assert_eq!(words.len(), skin.prefix_words());
    words.resize(colliders_first(words.len(), CONTACT_SLOTS, slot_colliders), [0.0; 4]);
    wgpu::util::DeviceExt::create_buffer_init(
        device,
        &wgpu::util::BufferInitDescriptor {
            label: Some("pelt simulation contact"),
            contents: bytemuck::cast_slice(&words),
            usage: CONTACT_USAGE,
        },
    )
}

/// The contact buffer's uses: read by the kernels, written by the queue, copied when it grows.
const CONTACT_USAGE: wgpu::BufferUsages =
    wgpu::BufferUsages::STORAGE.union(wgpu::BufferUsages::COPY_DST).union(wgpu::BufferUsages::COPY_SRC);

#[cfg(test)]
mod tests {
    use super::*;

    /// A slot has no room for colliders until a step has one, then room for a power of two of
    /// them from 4, never more than a step can hold; the buffer grows by that room alone.
    #[test]
    fn slots_make_room_for_the_busiest_step() {
        let room: Vec<usize> = [0, 1, 3, 4, 5, 9, 100, 128, 129, 1000].into_iter().map(room_for).collect();
        assert_eq!(room, [0, 4, 4, 4, 8, 16, 128, 128, 128, 128]);
        let skin = Skin::none(10);
        let bare = GpuContact::bytes(&skin, 0);
        // Headers and a quarter of a weight vec4 per strand: no skin until it is found.
        assert_eq!(bare, (2 * 64 + 3) * 16);
        assert_eq!(GpuContact::bytes(&skin, 8) - bare, 64 * 8 * 5 * 16);
    }

    /// Fields past the device's storage binding (or buffer) limit are refused with both sizes.
    #[test]
    fn fields_past_the_binding_limit_are_a_clear_error() {
        let limits = wgpu::Limits { max_storage_buffer_binding_size: 1 << 20, ..wgpu::Limits::default() };
        assert!(fields_fit(1 << 18, &limits).is_ok());
        let error = fields_fit((1 << 18) + 1, &limits).expect_err("over the limit");
        let message = error.to_string();
        assert!(message.contains("1048580") && message.contains("1048576"), "{message}");
        let small_buffers = wgpu::Limits { max_buffer_size: 1 << 10, ..wgpu::Limits::default() };
        assert!(fields_fit(1 << 9, &small_buffers).is_err());
    }
}
