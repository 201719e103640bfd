//! A mesh in the unified layout on the GPU, shared by [`crate::GpuFur`] (`L` layers) and
//! [`crate::PlainMesh`] (layer 0 only): the shared vertex array (one or two states), base
//! normals, wedge uvs and topology as storage buffers, and the object uniform.
//!
//! A groomed fur keeps its triangles and edges in the draw order of [`Furred`]: those with fur
//! (fins) first, so the shells and fins draw a prefix of the topology, the skin all of it, and
//! the topology keeps its size (`pelt_core::fur::Footprint` counts it).

use std::sync::Arc;

use glam::{Vec2, Vec3};
use pelt_core::groom::Groom;
use pelt_core::mesh::NO_FACE;
use pelt_core::{FurStructure, Mesh};
use wgpu::util::DeviceExt as _;

use crate::RenderError;
use crate::object::{GpuBytes, ObjectShape};
use crate::pool::{MemberPool, PoolMesh, binding};
use crate::requirements::check_size;
use crate::shaders::{Layouts, ObjectUniform};

pub use crate::pool::POSITIONS_USAGE;

/// Which base triangles get shells and which edges get fins, each list in mesh order
/// (`FurStructure::furred_triangles`, `FurStructure::fin_edges`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub(crate) struct Furred {
    pub triangles: Vec<u32>,
    pub edges: Vec<u32>,
}

impl Furred {
    /// What `structure`'s groom leaves furred; `None` (everything, in mesh order) without one.
    pub fn of(structure: &FurStructure) -> Option<Self> {
        structure.groom.as_ref()?;
        Some(Self { triangles: structure.furred_triangles(), edges: structure.fin_edges() })
    }
}

/// `first` (ascending, below `count`), then the rest of `0..count` in order: the GPU's order of
/// a groomed fur's triangles or edges.
fn furred_first(count: usize, first: &[u32]) -> Vec<u32> {
    let mut listed = vec![false; count];
    first.iter().for_each(|&k| listed[k as usize] = true);
    first.iter().copied().chain((0..count as u32).filter(|&k| !listed[k as usize])).collect()
}

/// The topology buffer's contents (see `topology` in `unified.wgsl`) with triangles and edges in
/// the order of `furred` (mesh order without), and the wedges' uvs.
fn topology(mesh: &Mesh, furred: Option<&Furred>) -> (Vec<u32>, Option<Vec<Vec2>>, u32) {
    let wedges = mesh.wedges();
    let Some(furred) = furred else {
        let mut topology: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        topology.extend(mesh.edges.iter().flatten());
        topology.extend(mesh.edge_faces.iter().flatten());
        let Some(wedges) = wedges else { return (topology, None, 0) };
        let count = wedges.vertices.len() as u32;
        topology.extend(wedges.vertices);
        topology.extend(wedges.corners);
        return (topology, Some(wedges.uvs), count);
    };
    let triangles = furred_first(mesh.triangles.len(), &furred.triangles);
    let edges = furred_first(mesh.edges.len(), &furred.edges);
    let mut slot_of_triangle = vec![0; triangles.len()];
    for (slot, &t) in triangles.iter().enumerate() {
        slot_of_triangle[t as usize] = slot as u32;
    }
    let mut topology: Vec<u32> = triangles.iter().flat_map(|&t| mesh.triangles[t as usize]).collect();
    topology.extend(edges.iter().flat_map(|&e| mesh.edges[e as usize]));
    topology.extend(edges.iter().flat_map(|&e| {
        mesh.edge_faces[e as usize].map(|face| if face == NO_FACE { NO_FACE } else { slot_of_triangle[face as usize] })
    }));
    let Some(wedges) = wedges else { return (topology, None, 0) };
    let count = wedges.vertices.len() as u32;
    topology.extend(wedges.vertices);
    let corners = &wedges.corners;
    topology.extend(triangles.iter().flat_map(|&t| corners[3 * t as usize..3 * t as usize + 3].iter().copied()));
    (topology, Some(wedges.uvs), count)
}

/// The groom attributes of every vertex of a `vertex_count` mesh (`GroomAttributes` in
/// `shading.wgsl`); absent maps give the uniform values (tint 1, density 1, clump 0).
pub(crate) fn groom_attributes(groom: &Groom, vertex_count: usize) -> Vec<[f32; 8]> {
    (0..vertex_count)
        .map(|j| {
            let tint = groom.tint.as_ref().map_or(Vec3::ONE, |t| t[j]);
            let density = groom.density.as_ref().map_or(1.0, |d| d[j]);
            let clump = groom.clump.as_ref().map_or(0.0, |c| c[j]);
            [tint.x, tint.y, tint.z, density, clump, 0.0, 0.0, 0.0]
        })
        .collect()
}

/// Whether `groom` changes the shading (density, clump or tint).
pub(crate) fn shades(groom: &Groom) -> bool {
    groom.density.is_some() || groom.clump.is_some() || groom.tint.is_some()
}

/// What every copy of one mesh shares on the GPU: the topology, the wedges' uvs, the fin strip
/// and the groom's attributes. Cloning it clones handles, not buffers.
#[derive(Clone, Debug)]
pub(crate) struct SharedGeometry {
    pub shape: ObjectShape,
    /// Triangles (3F), edges (2E), edge faces (2E), and for meshes with uvs the wedges' base
    /// vertices (W) and the corners' wedges (3F); also the index buffer of the base triangles (by
    /// vertex, or by wedge with uvs).
    topology: wgpu::Buffer,
    uvs: wgpu::Buffer,
    /// The fin strip of one edge (`6L` indices into `2(L + 1)` strip vertices), shared by all
    /// edges: indexed, each strip vertex is shaded once however many triangles use it.
    fin_indices: Option<wgpu::Buffer>,
    /// Each vertex's groom attributes (`V` entries for a groomed fur, else one unused entry).
    groom: wgpu::Buffer,
    /// The uvs (attributes) and the topology and strip (indices).
    bytes: GpuBytes,
}

impl SharedGeometry {
    /// Uploads what `L = layers` layers over `mesh` share; shells and fins draw only what
    /// `furred` lists (`None`: everything) and shade with `groom`.
    pub fn new(
        device: &wgpu::Device,
        (mesh, furred, groom): (&Mesh, Option<&Furred>, Option<&Groom>),
        layers: u32,
    ) -> Result<Self, RenderError> {
        let mut shape = ObjectShape::new(mesh, layers);
        if let Some(furred) = furred {
            shape.furred_triangle_count = furred.triangles.len() as u32;
            shape.fin_edge_count = furred.edges.len() as u32;
        }
        let (topology, wedge_uvs, wedge_count) = topology(mesh, furred);
        shape.wedge_count = wedge_count;
        let wedge_uvs = wedge_uvs.unwrap_or_else(|| vec![Vec2::ZERO]);
        check_size(device, "mesh topology", topology.len() as u64 * 4)?;
        check_size(device, "mesh uvs", wedge_uvs.len() as u64 * 8)?;
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let uvs = buffer("pelt wedge uvs", bytemuck::cast_slice(&wedge_uvs), wgpu::BufferUsages::STORAGE);
        let topology = buffer(
            "pelt topology",
            bytemuck::cast_slice(&topology),
            // Copied from by a pool's shell lists (`ShellList::fill_head`).
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::INDEX | wgpu::BufferUsages::COPY_SRC,
        );
        let strip: Vec<u32> = (0..layers)
            .flat_map(|i| {
                let (a, b, a_up, b_up) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
                [a, b, b_up, a, b_up, a_up]
            })
            .collect();
        let fin_indices =
            (layers > 0).then(|| buffer("pelt fin strip", bytemuck::cast_slice(&strip), wgpu::BufferUsages::INDEX));
        let attributes = match groom {
            Some(groom) => groom_attributes(groom, mesh.vertex_count()),
            None => vec![[0.0; 8]],
        };
        shape.groomed = groom.is_some();
        shape.groom_shading = groom.is_some_and(shades);
        let groom = buffer(
            "pelt groom attributes",
            bytemuck::cast_slice(&attributes),
            wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
        );
        let bytes = GpuBytes {
            attributes: uvs.size(),
            indices: topology.size() + fin_indices.as_ref().map_or(0, wgpu::Buffer::size),
            ..GpuBytes::default()
        };
        Ok(Self { shape, topology, uvs, fin_indices, groom, bytes })
    }

    /// The buffers' bytes (the groom's attributes not counted: [`UnifiedGeometry::groom_bytes`]).
    pub fn bytes(&self) -> GpuBytes {
        self.bytes
    }
}

/// One copy of a mesh on the GPU: its own shared-array states, base normals and object uniform
/// (a slot of a [`MemberPool`]) and wetness over a [`SharedGeometry`].
#[derive(Debug)]
pub(crate) struct UnifiedGeometry {
    pub shape: ObjectShape,
    shared: SharedGeometry,
    pool: Arc<MemberPool>,
    slot: u32,
    /// `current` is the newer of the slot's states.
    current: usize,
    /// A wetness per base vertex (`V` `f32`, zero until set): per-frame state like the
    /// silhouette list, so not counted in [`GpuBytes`].
    wetness: wgpu::Buffer,
    /// `bind_groups[c]` reads state `c` as current and the other state as previous.
    bind_groups: Vec<wgpu::BindGroup>,
    /// This copy's own bytes: the states and the normals.
    own_bytes: GpuBytes,
}

impl UnifiedGeometry {
    /// Uploads `mesh` with `positions` (`(L + 1) * V`, layer-major) into every state; shells
    /// and fins draw only what `furred` lists (`None`: everything) and shade with `groom`.
    pub fn new(
        device: &wgpu::Device,
        layouts: &Layouts,
        (mesh, furred, groom): (&Mesh, Option<&Furred>, Option<&Groom>),
        layers: u32,
        positions: &[Vec3],
        state_count: usize,
    ) -> Result<Self, RenderError> {
        let shared = SharedGeometry::new(device, (mesh, furred, groom), layers)?;
        Self::instance(device, layouts, &shared, (positions, &mesh.normals), state_count)
    }

    /// A copy of `shared` of its own (a pool of one): `positions` (`(L + 1) * V`, layer-major)
    /// in every state, `normals` (`V`) as its base normals.
    pub fn instance(
        device: &wgpu::Device,
        layouts: &Layouts,
        shared: &SharedGeometry,
        (positions, normals): (&[Vec3], &[Vec3]),
        state_count: usize,
    ) -> Result<Self, RenderError> {
        let pool = Self::pool(device, layouts, shared, (positions, normals), (state_count, 1))?;
        Ok(Self::in_pool(device, layouts, shared, &pool, 0))
    }

    /// A pool of `slots` copies of `shared`, each starting from `positions` and `normals`.
    pub fn pool(
        device: &wgpu::Device,
        layouts: &Layouts,
        shared: &SharedGeometry,
        (positions, normals): (&[Vec3], &[Vec3]),
        (state_count, slots): (usize, u32),
    ) -> Result<Arc<MemberPool>, RenderError> {
        let shape = shared.shape;
        let expected = (shape.layers as usize + 1) * shape.vertex_count as usize;
        if positions.len() != expected {
            return Err(RenderError::Count {
                what: "shared vertex positions",
                expected,
                got: positions.len(),
                rule: "(L + 1) * V",
            });
        }
        if normals.len() != shape.vertex_count as usize {
            let expected = shape.vertex_count as usize;
            return Err(RenderError::Count { what: "base normals", expected, got: normals.len(), rule: "V" });
        }
        let mesh = PoolMesh { shape, topology: &shared.topology, uvs: &shared.uvs, groom: &shared.groom };
        Ok(Arc::new(MemberPool::new(device, layouts, &mesh, (positions, normals), (state_count, slots))?))
    }

    /// The copy in slot `slot` of `pool` (made over `shared`).
    pub fn in_pool(
        device: &wgpu::Device,
        layouts: &Layouts,
        shared: &SharedGeometry,
        pool: &Arc<MemberPool>,
        slot: u32,
    ) -> Self {
        let shape = shared.shape;
        let wetness = wgpu::util::DeviceExt::create_buffer_init(
            device,
            &wgpu::util::BufferInitDescriptor {
                label: Some("pelt wetness"),
                contents: bytemuck::cast_slice(&vec![0.0_f32; (shape.vertex_count as usize).max(1)]),
                usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            },
        );
        let states = pool.state_count();
        let bind_groups = (0..states)
            .map(|current| {
                let previous = (current + 1) % states;
                device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("pelt unified object"),
                    layout: &layouts.unified_object,
                    entries: &[
                        wgpu::BindGroupEntry { binding: 0, resource: binding(pool.object(slot)) },
                        wgpu::BindGroupEntry { binding: 1, resource: binding(pool.state(slot, previous)) },
                        wgpu::BindGroupEntry { binding: 2, resource: binding(pool.state(slot, current)) },
                        wgpu::BindGroupEntry { binding: 3, resource: binding(pool.normals(slot)) },
                        wgpu::BindGroupEntry { binding: 4, resource: shared.uvs.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 5, resource: shared.topology.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 6, resource: shared.groom.as_entire_binding() },
                        wgpu::BindGroupEntry { binding: 7, resource: wetness.as_entire_binding() },
                    ],
                })
            })
            .collect();
        // The data's bytes, as `Footprint` counts them (a range's padding, under 256 bytes, is
        // the allocator's kind of overhead).
        let own_bytes = GpuBytes {
            positions: pool.state(slot, 0).size() * states as u64,
            attributes: pool.normals(slot).size(),
            ..GpuBytes::default()
        };
        Self {
            shape,
            shared: shared.clone(),
            pool: Arc::clone(pool),
            slot,
            current: 0,
            wetness,
            bind_groups,
            own_bytes,
        }
    }

    /// Bytes of the groom attributes (0 without a groom).
    pub fn groom_bytes(&self) -> u64 {
        if self.shape.groomed { self.shared.groom.size() } else { 0 }
    }

    /// Rewrites the groom attributes from `groom` (density, clump, tint; lengths and directions
    /// live in the shared array). No allocation on the GPU: the buffer was made for the groom.
    pub fn set_groom(&mut self, queue: &wgpu::Queue, groom: &Groom) -> Result<(), RenderError> {
        let vertices = self.shape.vertex_count as usize;
        if !self.shape.groomed {
            return Err(RenderError::Groom(
                "the fur was uploaded without a groom; grow it with one (set_structure) first".to_owned(),
            ));
        }
        groom.validate(vertices, "the groom").map_err(|e| RenderError::Groom(e.to_string()))?;
        queue.write_buffer(&self.shared.groom, 0, bytemuck::cast_slice(&groom_attributes(groom, vertices)));
        self.shape.groom_shading = shades(groom);
        Ok(())
    }

    /// Every byte it draws with: its own and the shared ones.
    pub fn bytes(&self) -> GpuBytes {
        let (own, shared) = (self.own_bytes, self.shared.bytes);
        GpuBytes {
            positions: own.positions + shared.positions,
            attributes: own.attributes + shared.attributes,
            indices: own.indices + shared.indices,
            textures: own.textures + shared.textures,
        }
    }

    /// This copy's own bytes: the states of the shared array and the base normals.
    pub fn own_bytes(&self) -> GpuBytes {
        self.own_bytes
    }

    pub fn state_count(&self) -> usize {
        self.pool.state_count()
    }

    /// Writes the object uniform, with where the listing passes find this copy in its pool and
    /// what they list of it this frame (`lists`: `pool::LIST_FINS`, `pool::LIST_SHELLS`).
    pub fn write_uniform(&self, queue: &wgpu::Queue, uniform: &ObjectUniform, lists: u32) {
        let states = (self.current, (self.current + 1) % self.state_count());
        let uniform = ObjectUniform { pool: self.pool.object_pool_field(self.slot, states, lists), ..*uniform };
        let object = self.pool.object(self.slot);
        queue.write_buffer(object.buffer(), object.offset(), bytemuck::bytes_of(&uniform));
    }

    /// The pool this copy's state lives in, and its slot there.
    pub fn slot(&self) -> (&Arc<MemberPool>, u32) {
        (&self.pool, self.slot)
    }

    fn check_positions(&self, positions: &[Vec3]) -> Result<(), RenderError> {
        let expected = (self.shape.layers as usize + 1) * self.shape.vertex_count as usize;
        if positions.len() == expected {
            Ok(())
        } else {
            Err(RenderError::Count {
                what: "shared vertex positions",
                expected,
                got: positions.len(),
                rule: "(L + 1) * V",
            })
        }
    }

    /// Writes `positions` into every state.
    pub fn set_positions(&self, queue: &wgpu::Queue, positions: &[Vec3]) -> Result<(), RenderError> {
        self.check_positions(positions)?;
        for k in 0..self.state_count() {
            let state = self.pool.state(self.slot, k);
            queue.write_buffer(state.buffer(), state.offset(), bytemuck::cast_slice(positions));
        }
        Ok(())
    }

    pub fn set_states(&self, queue: &wgpu::Queue, previous: &[Vec3], current: &[Vec3]) -> Result<(), RenderError> {
        self.check_positions(previous)?;
        self.check_positions(current)?;
        let (old, new) = (self.previous(), self.current());
        queue.write_buffer(old.buffer(), old.offset(), bytemuck::cast_slice(previous));
        queue.write_buffer(new.buffer(), new.offset(), bytemuck::cast_slice(current));
        Ok(())
    }

    /// The newer state becomes the older one; the buffer that held the older is now current.
    pub fn swap_states(&mut self) {
        self.current = (self.current + 1) % self.state_count();
    }

    pub fn push_state(&mut self, queue: &wgpu::Queue, positions: &[Vec3]) -> Result<(), RenderError> {
        self.check_positions(positions)?;
        self.swap_states();
        let state = self.current();
        queue.write_buffer(state.buffer(), state.offset(), bytemuck::cast_slice(positions));
        Ok(())
    }

    pub fn current(&self) -> wgpu::BufferSlice<'_> {
        self.pool.state(self.slot, self.current)
    }

    pub fn previous(&self) -> wgpu::BufferSlice<'_> {
        self.pool.state(self.slot, (self.current + 1) % self.state_count())
    }

    pub fn normals(&self) -> wgpu::BufferSlice<'_> {
        self.pool.normals(self.slot)
    }

    pub fn set_normals(&self, queue: &wgpu::Queue, normals: &[Vec3]) -> Result<(), RenderError> {
        let expected = self.shape.vertex_count as usize;
        if normals.len() != expected {
            return Err(RenderError::Count { what: "base normals", expected, got: normals.len(), rule: "V" });
        }
        let slice = self.normals();
        queue.write_buffer(slice.buffer(), slice.offset(), bytemuck::cast_slice(normals));
        Ok(())
    }

    pub fn set_wetness(&self, queue: &wgpu::Queue, wetness: &[f32]) -> Result<(), RenderError> {
        let expected = self.shape.vertex_count as usize;
        if wetness.len() != expected {
            return Err(RenderError::Count { what: "wetness values", expected, got: wetness.len(), rule: "V" });
        }
        queue.write_buffer(&self.wetness, 0, bytemuck::cast_slice(wetness));
        Ok(())
    }

    pub fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_groups[self.current]
    }

    /// Draws every base triangle once: the skin, or a plain mesh.
    pub fn draw_skin(&self, pass: &mut wgpu::RenderPass<'_>) {
        self.draw_surface(pass, 0..1, self.shape.triangle_count);
    }

    /// Draws every base triangle once an instance: a pool's skins (`instances` = slots).
    pub fn draw_skins(&self, pass: &mut wgpu::RenderPass<'_>, instances: std::ops::Range<u32>) {
        self.draw_surface(pass, instances, self.shape.triangle_count);
    }

    /// Draws the furred base triangles in the shells `instances`.
    pub fn draw_shells(&self, pass: &mut wgpu::RenderPass<'_>, instances: std::ops::Range<u32>) {
        self.draw_surface(pass, instances, self.shape.furred_triangle_count);
    }

    /// Draws the first `drawn` base triangles (`instances` = layers), indexed: by wedge with uvs,
    /// else by base vertex.
    fn draw_surface(&self, pass: &mut wgpu::RenderPass<'_>, instances: std::ops::Range<u32>, drawn: u32) {
        let first = self.shape.surface_indices_first();
        if drawn == 0 {
            return;
        }
        let indices = self.shared.topology.slice(4 * first..4 * (first + 3 * u64::from(drawn)));
        pass.set_index_buffer(indices, wgpu::IndexFormat::Uint32);
        pass.draw_indexed(0..3 * drawn, 0, instances);
    }

    /// Draws the fins listed in `instances` (the silhouette pass's edges) through the indirect
    /// draw at `offset` in `draws`.
    pub fn draw_fin_list(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        instances: wgpu::BufferSlice<'_>,
        (draws, offset): (&wgpu::Buffer, u64),
    ) {
        if let Some(strip) = &self.shared.fin_indices {
            pass.set_index_buffer(strip.slice(..), wgpu::IndexFormat::Uint32);
            pass.set_vertex_buffer(0, instances);
            pass.draw_indexed_indirect(draws, offset);
        }
    }

    /// The fin strip's indices (`None` without layers).
    pub fn fin_strip(&self) -> Option<&wgpu::Buffer> {
        self.shared.fin_indices.as_ref()
    }

    /// Draws every fin (instance = edge) with `segments` segments (the level of detail's).
    pub fn draw_fins(&self, pass: &mut wgpu::RenderPass<'_>, segments: u32) {
        if let Some(strip) = &self.shared.fin_indices {
            pass.set_index_buffer(strip.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..6 * segments.min(self.shape.layers), 0, 0..self.shape.fin_edge_count);
        }
    }
}
