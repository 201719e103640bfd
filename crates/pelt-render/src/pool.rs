//! A pool: the copies of one fur made together (a herd's members) keep their own state in shared
//! buffers, slot by slot: the shared array's states, the base normals, the object uniforms, and
//! the silhouette and view-angle passes' lists. A draw binds one copy's ranges, so it draws
//! exactly as a lone fur does; a listing pass binds the whole pool and lists every copy in one
//! dispatch (`object_pool.wgsl`: workgroup z is the slot). A lone fur is a pool of one.

use std::sync::Mutex;

use glam::Vec3;
use pelt_core::fur::POSITION_BYTES;

use crate::RenderError;
use crate::listing::{FinList, ShellList};
use crate::object::ObjectShape;
use crate::requirements::check_size;
use crate::shaders::{Layouts, OBJECT_SLOT_BYTES, OBJECT_UNIFORM_BYTES};

/// Every copy's ranges start on this many bytes: the largest storage and uniform offset
/// alignment WebGPU lets a device ask for, so any device binds them.
const RANGE_ALIGNMENT: u64 = 256;

/// Usage of the shared-array buffers: read by the vertex shaders, written by the queue or by a
/// host's compute pass, and bindable as vertex buffers or copied by hosts that want to.
pub const POSITIONS_USAGE: wgpu::BufferUsages = wgpu::BufferUsages::STORAGE
    .union(wgpu::BufferUsages::VERTEX)
    .union(wgpu::BufferUsages::COPY_DST)
    .union(wgpu::BufferUsages::COPY_SRC);

/// What the listing passes list of a copy this frame (`LIST_FINS`, `LIST_SHELLS` in
/// `object_pool.wgsl`).
pub(crate) const LIST_FINS: u32 = 1;
pub(crate) const LIST_SHELLS: u32 = 2;
/// A slot's gathered place when it has none (`NOT_GATHERED` in `object_pool.wgsl`).
pub(crate) const NOT_GATHERED: u32 = u32::MAX;

/// What every copy of a pool shares and its draws read: the mesh's shape, topology, wedge uvs
/// and groom attributes.
pub(crate) struct PoolMesh<'a> {
    pub shape: ObjectShape,
    pub topology: &'a wgpu::Buffer,
    pub uvs: &'a wgpu::Buffer,
    pub groom: &'a wgpu::Buffer,
}

/// The shared buffers of `slots` copies of one fur.
#[derive(Debug)]
pub(crate) struct MemberPool {
    /// Slot `s`'s state `k` at `(s * state_count + k) * state_stride`.
    states: wgpu::Buffer,
    /// Slot `s`'s base normals at `s * normals_stride`.
    normals: wgpu::Buffer,
    /// Slot `s`'s object uniform at `s * OBJECT_SLOT_BYTES` (uniform for its draws, storage for
    /// the listing passes).
    objects: wgpu::Buffer,
    state_count: usize,
    state_bytes: u64,
    state_stride: u64,
    normals_bytes: u64,
    normals_stride: u64,
    fins: Option<FinList>,
    shells: Option<ShellList>,
    /// Each slot's `gather` words as last written (`ObjectSlot` in `object_pool.wgsl`), and the
    /// plan (`crate::HerdDraws`) that wrote them.
    gather: Mutex<(u64, Vec<[u32; 2]>)>,
    /// The listing passes' group 1: the objects, the states (twice), the normals, the topology.
    listing_group: wgpu::BindGroup,
    /// The pooled shadow casters' group 1 (`Layouts::pool_draws`): the listing's and the wedge
    /// uvs, the groom attributes and a stand-in for the wetness (a wet copy casts alone).
    draw_group: wgpu::BindGroup,
}

impl MemberPool {
    /// The most copies of `shared` with `state_count` states one pool holds on `device`: each of
    /// its buffers within one storage binding.
    pub fn most_slots(device: &wgpu::Device, shape: ObjectShape, state_count: usize) -> u32 {
        let limits = device.limits();
        let limit = limits.max_storage_buffer_binding_size.min(limits.max_buffer_size);
        let positions = (u64::from(shape.layers) + 1) * u64::from(shape.vertex_count) * POSITION_BYTES;
        let state = positions.next_multiple_of(RANGE_ALIGNMENT) * state_count.max(1) as u64;
        let fins = u64::from(shape.fin_edge_count) * 8;
        let shells = u64::from(shape.furred_triangle_count) * 12;
        let per_slot = state.max(fins).max(shells).max(OBJECT_SLOT_BYTES).max(1);
        let most = (limit / per_slot).min(u64::from(limits.max_compute_workgroups_per_dimension));
        u32::try_from(most).unwrap_or(u32::MAX).max(1)
    }

    /// A pool of `slots` copies of `mesh`, each starting from `positions` (`(L + 1) * V`) in each
    /// of its `state_count` states and `normals` (`V`).
    pub fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        mesh: &PoolMesh<'_>,
        (positions, normals): (&[Vec3], &[Vec3]),
        (state_count, slots): (usize, u32),
    ) -> Result<Self, RenderError> {
        let state_count = state_count.clamp(1, 2);
        let state_bytes = positions.len() as u64 * POSITION_BYTES;
        let state_stride = state_bytes.max(4).next_multiple_of(RANGE_ALIGNMENT);
        let normals_bytes = normals.len() as u64 * POSITION_BYTES;
        let normals_stride = normals_bytes.max(4).next_multiple_of(RANGE_ALIGNMENT);
        let slot_count = u64::from(slots.max(1));
        let states_size = state_stride * state_count as u64 * slot_count;
        check_size(device, "shared vertex array", states_size)?;
        check_size(device, "base normals", normals_stride * slot_count)?;
        // Every slot starts as the rest pose, written once while mapped.
        let filled = |label, stride: u64, copies: u64, contents: &[u8], usage| {
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: stride * copies,
                usage,
                mapped_at_creation: true,
            });
            for copy in 0..copies {
                let at = copy * stride;
                // A buffer mapped at creation maps whole; only a lost device fails here, and
                // its buffers are never read.
                if let Ok(mut view) = buffer.slice(at..at + contents.len() as u64).get_mapped_range_mut() {
                    view.copy_from_slice(contents);
                }
            }
            buffer.unmap();
            buffer
        };
        let states = filled(
            "pelt shared vertices",
            state_stride,
            state_count as u64 * slot_count,
            bytemuck::cast_slice(positions),
            POSITIONS_USAGE,
        );
        let normals = filled(
            "pelt base normals",
            normals_stride,
            slot_count,
            bytemuck::cast_slice(normals),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::COPY_SRC,
        );
        // Every slot gathers nowhere until a plan says (`MemberPool::gather`).
        let objects = filled(
            "pelt objects",
            OBJECT_SLOT_BYTES,
            slot_count,
            &[0; OBJECT_UNIFORM_BYTES as usize]
                .into_iter()
                .chain(bytemuck::cast::<[u32; 2], [u8; 8]>([NOT_GATHERED; 2]))
                .collect::<Vec<u8>>(),
            wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let (shape, topology) = (mesh.shape, mesh.topology);
        let layers = shape.layers;
        let fins = FinList::new(device, layouts, (shape.fin_edge_count, layers), slots)?;
        let per_shell = shape.vertices_per_shell();
        let head = (topology, shape.surface_indices_first());
        let shells = ShellList::new(device, layouts, (shape.furred_triangle_count, per_shell, layers), (slots, head))?;
        let listing_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt pool objects"),
            layout: &layouts.pool_objects,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: objects.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: states.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: states.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: normals.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: topology.as_entire_binding() },
            ],
        });
        // Read by no pipeline that binds it: the pooled casters are built dry.
        let no_wetness = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt pool wetness stand-in"),
            size: 16,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        });
        let draw_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt pool draws"),
            layout: &layouts.pool_draws,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: objects.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: states.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: states.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: normals.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: mesh.uvs.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 5, resource: topology.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 6, resource: mesh.groom.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 7, resource: no_wetness.as_entire_binding() },
            ],
        });
        Ok(Self {
            states,
            normals,
            objects,
            state_count,
            state_bytes,
            state_stride,
            normals_bytes,
            normals_stride,
            fins,
            shells,
            gather: Mutex::new((0, vec![[NOT_GATHERED; 2]; slots.max(1) as usize])),
            listing_group,
            draw_group,
        })
    }

    /// Makes `plan` the pool's gathering plan: each slot of `places` (slot, its fin draw's and
    /// its shell draws' gathered places, or [`NOT_GATHERED`]) gathers there from the next listing
    /// pass on, every other slot nowhere. Writes only the slots that change.
    pub fn gather(&self, queue: &wgpu::Queue, plan: u64, places: &[(u32, [u32; 2])]) {
        let Ok(mut gather) = self.gather.lock() else { return };
        let mut wanted = vec![[NOT_GATHERED; 2]; gather.1.len()];
        for &(slot, place) in places {
            if let Some(slot) = wanted.get_mut(slot as usize) {
                *slot = place;
            }
        }
        gather.0 = plan;
        for (slot, (old, new)) in gather.1.iter_mut().zip(wanted).enumerate() {
            if *old != new {
                *old = new;
                let at = slot as u64 * OBJECT_SLOT_BYTES + OBJECT_UNIFORM_BYTES;
                queue.write_buffer(&self.objects, at, bytemuck::cast_slice(&new));
            }
        }
    }

    /// The plan whose places the pool's listing passes gather to (0: none yet).
    pub fn gathering_plan(&self) -> u64 {
        self.gather.lock().map_or(0, |gather| gather.0)
    }

    /// States per copy (1 or 2).
    pub fn state_count(&self) -> usize {
        self.state_count
    }

    /// Slot `slot`'s state `k`.
    pub fn state(&self, slot: u32, k: usize) -> wgpu::BufferSlice<'_> {
        let at = (u64::from(slot) * self.state_count as u64 + k as u64) * self.state_stride;
        self.states.slice(at..at + self.state_bytes)
    }

    /// Slot `slot`'s base normals.
    pub fn normals(&self, slot: u32) -> wgpu::BufferSlice<'_> {
        let at = u64::from(slot) * self.normals_stride;
        self.normals.slice(at..at + self.normals_bytes)
    }

    /// Slot `slot`'s object uniform.
    pub fn object(&self, slot: u32) -> wgpu::BufferSlice<'_> {
        let at = u64::from(slot) * OBJECT_SLOT_BYTES;
        self.objects.slice(at..at + crate::shaders::OBJECT_UNIFORM_BYTES)
    }

    /// The bytes one copy's lists hold.
    pub fn slot_list_bytes(&self) -> u64 {
        self.fins.as_ref().map_or(0, FinList::slot_bytes) + self.shells.as_ref().map_or(0, ShellList::slot_bytes)
    }

    /// The bytes the pool's copies' lists share (the gathered draws' head of indices).
    pub fn shared_list_bytes(&self) -> u64 {
        self.shells.as_ref().map_or(0, ShellList::head_bytes)
    }

    pub fn fins(&self) -> Option<&FinList> {
        self.fins.as_ref()
    }

    pub fn shells(&self) -> Option<&ShellList> {
        self.shells.as_ref()
    }

    pub fn listing_group(&self) -> &wgpu::BindGroup {
        &self.listing_group
    }

    pub fn draw_group(&self) -> &wgpu::BindGroup {
        &self.draw_group
    }

    /// Slot `slot`'s `pool` field of its object (`Object::pool` in `shading.wgsl`): where its
    /// `current` and `previous` states and its normals start in the pool's buffers, in `u32`s,
    /// and `lists` ([`LIST_FINS`], [`LIST_SHELLS`]).
    pub fn object_pool_field(&self, slot: u32, (current, previous): (usize, usize), lists: u32) -> [u32; 4] {
        let words = |slice: wgpu::BufferSlice<'_>| u32::try_from(slice.offset() / 4).unwrap_or(u32::MAX);
        [words(self.state(slot, current)), words(self.state(slot, previous)), words(self.normals(slot)), lists]
    }
}

/// A binding of `slice` (a range of one buffer).
pub(crate) fn binding(slice: wgpu::BufferSlice<'_>) -> wgpu::BindingResource<'_> {
    wgpu::BindingResource::Buffer(wgpu::BufferBinding {
        buffer: slice.buffer(),
        offset: slice.offset(),
        size: wgpu::BufferSize::new(slice.size()),
    })
}
