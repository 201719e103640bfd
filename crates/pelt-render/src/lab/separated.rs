//! The separated structure of Lengyel et al. 2001, drawn on the same API as the unified one for
//! side-by-side comparisons: shells as `(L + 1) * V` full vertices (position, normal, uv;
//! 32 bytes each) reused by one index buffer with a base-vertex offset per layer, and fins as
//! geometry of their own, `N` faces per fin, built once on the CPU (they do not bend).
//!
//! Each fin is a strip of `N / 2` quads up the rest strands with vertices of its own (they carry
//! the fin's plane normal for Lengyel's fade and uvs along the fin), stored as a plain triangle
//! list: 6 vertices a quad, the first two the roots of the edge's ends. The same buffer is bound
//! as storage too, so every vertex of a fin decides the fade for the whole fin and fins that do
//! not show are culled, as the unified fins are. (The paper counts `N` vertices a fin, sharing strip vertices; the
//! drawn cost is the same.) Layer 0 of the shell vertices is the opaque skin; it carries the base
//! normal where the shells carry the growing vector, so the skin is lit as the unified one.
//!
//! Views, textures, the object uniform, the shading and pipeline creation are the unified
//! renderer's; only the vertex input and the draws differ.

use glam::{Vec2, Vec3};
use pelt_core::FurStructure;
use pelt_core::fur::{POSITION_BYTES, SEPARATED_VERTEX_BYTES};
use pelt_core::texture::FurTextures;
use wgpu::util::DeviceExt as _;

use crate::RenderError;
use crate::lod::PreparedLevel;
use crate::object::{FurFrame, GpuBytes, ObjectShape, uniform_buffer};
use crate::renderer::{FurDrawSettings, FurRenderer, PassKind, PipelineSource, Transparency, create_pipeline};
use crate::requirements::{ErrorScope, check_size};
use crate::shaders::separated_shader_source;
use crate::targets::FurTarget;
use crate::textures::GpuTextures;
use crate::view::FurView;

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    position: Vec3,
    normal: Vec3,
    uv: Vec2,
}
const _: () = assert!(size_of::<Vertex>() as u64 == SEPARATED_VERTEX_BYTES, "Footprint counts 32-byte vertices");

/// [`Vertex`] as `VertexIn` in `separated.wgsl` reads it.
const VERTEX_ATTRIBUTES: [wgpu::VertexAttribute; 3] =
    wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2];

/// The separated structure's pipelines for the target of a [`FurRenderer`], sharing its views
/// and layouts.
#[derive(Debug)]
pub struct SeparatedRenderer {
    target: FurTarget,
    skin: wgpu::RenderPipeline,
    /// Ungroomed furs, groomed ones (with the groom's varyings): shells and fins.
    coats: [SeparatedCoat; 2],
}

/// One coat's separated pipelines.
#[derive(Debug)]
struct SeparatedCoat {
    /// Meshes without uvs, with uvs; each blended, alpha-to-coverage.
    shells: [[wgpu::RenderPipeline; 2]; 2],
    /// Blended, alpha-to-coverage.
    fins: [wgpu::RenderPipeline; 2],
}

impl SeparatedRenderer {
    /// Builds the separated pipelines for `renderer`'s target.
    ///
    /// # Errors
    /// [`RenderError::Gpu`] when the device rejects the pipelines.
    pub fn new(device: &wgpu::Device, renderer: &FurRenderer) -> Result<Self, RenderError> {
        let target = renderer.target();
        let layouts = renderer.layouts();
        let scope = ErrorScope::push(device);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pelt separated"),
            source: wgpu::ShaderSource::Wgsl(separated_shader_source().into()),
        });
        let layout = layouts.pipeline_layout(device, "pelt separated", &layouts.separated_object, true);
        let vertex_layout = [Some(wgpu::VertexBufferLayout {
            array_stride: SEPARATED_VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &VERTEX_ATTRIBUTES,
        })];
        let build_for = |label: &str, (vertex_entry, fragment_entry): (&str, &str), kind, mesh_uvs| {
            let source = PipelineSource {
                mesh_uvs,
                coat: None,
                layout: &layout,
                module: &module,
                vertex_entry,
                fragment_entry,
                buffers: &vertex_layout,
            };
            create_pipeline(device, &target, label, &source, kind)
        };
        let build = |label: &str, entries: (&str, &str), kind| build_for(label, entries, kind, None);
        let skin = build("pelt separated skin", ("vs_separated_skin", "fs_skin"), PassKind::Opaque);
        // Without uvs, with uvs: each passes on only what its fragments read; the groomed coat
        // adds the groom's terms, and the object's flags say whether they are read (`GROOM` 0).
        let coat = |suffix: &str| {
            let entry = |name: &str| format!("{name}{suffix}");
            let shells = ["tiles", "uvs"].map(|walk| {
                let entries = (entry(&format!("vs_separated_shell_{walk}")), entry(&format!("fs_shell_{walk}")));
                Transparency::BOTH.map(|t| {
                    let kind = PassKind::Shells(t);
                    build_for(
                        "pelt separated shells",
                        (entries.0.as_str(), entries.1.as_str()),
                        kind,
                        Some(walk == "uvs"),
                    )
                })
            });
            let fin_entries = (entry("vs_separated_fin"), entry("fs_separated_fin"));
            let fins = Transparency::BOTH.map(|t| {
                build("pelt separated fins", (fin_entries.0.as_str(), fin_entries.1.as_str()), PassKind::Fins(t))
            });
            SeparatedCoat { shells, fins }
        };
        let coats = [coat(""), coat("_groomed")];
        scope.pop("building the separated pipelines")?;
        Ok(Self { target, skin, coats })
    }

    /// The target description the pipelines were built for.
    #[must_use]
    pub fn target(&self) -> FurTarget {
        self.target
    }

    /// Records `fur` as seen from `view`, as [`FurRenderer::draw`] does for the unified structure.
    pub fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        view: &FurView,
        fur: &SeparatedFur,
        settings: &FurDrawSettings,
    ) {
        let which = Transparency::index(settings.alpha_to_coverage);
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, &fur.bind_group, &[]);
        pass.set_bind_group(2, fur.textures.bind_group(), &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        pass.set_vertex_buffer(0, fur.shell_vertices.slice(..));
        pass.set_index_buffer(fur.shell_indices.slice(..), wgpu::IndexFormat::Uint32);
        if settings.skin {
            pass.set_pipeline(&self.skin);
            pass.draw_indexed(0..fur.index_count, 0, 0..1);
        }
        let coat = &self.coats[usize::from(fur.shape.groom_shading)];
        if settings.shells {
            pass.set_pipeline(&coat.shells[usize::from(fur.shape.has_uvs)][which]);
            let furred = 3 * fur.shape.furred_triangle_count;
            for layer in fur.level.shell_layers(fur.shape.layers) {
                pass.draw_indexed(0..furred, (layer * fur.shape.vertex_count) as i32, layer..layer + 1);
            }
        }
        if settings.fins {
            pass.set_pipeline(&coat.fins[which]);
            pass.set_vertex_buffer(0, fur.fin_vertices.slice(..));
            pass.draw(0..fur.fin_vertex_count, 0..1);
        }
    }
}

/// One fur in the separated structure on the GPU (the rest pose; its fins do not follow a
/// simulation).
#[derive(Debug)]
pub struct SeparatedFur {
    shape: ObjectShape,
    uniform: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    textures: GpuTextures,
    shell_vertices: wgpu::Buffer,
    shell_indices: wgpu::Buffer,
    fin_vertices: wgpu::Buffer,
    fin_vertex_count: u32,
    index_count: u32,
    bytes: GpuBytes,
    /// The level of detail of the last `prepare` (shells only: these fins are fixed geometry).
    level: PreparedLevel,
}

impl SeparatedFur {
    /// Builds the separated buffers for the rest pose of `structure`, with `fin_faces` faces per
    /// fin (2 as Lengyel, or `N`; rounded up to even).
    ///
    /// # Errors
    /// As [`crate::GpuFur::new`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        structure: &FurStructure,
        textures: &FurTextures,
        fin_faces: u32,
    ) -> Result<Self, RenderError> {
        // A groom's bald triangles get no shells and its bald edges no fins, as in the unified
        // structure: the index buffer holds the furred triangles first (the shells draw those),
        // then the bald ones (the skin draws them all).
        let fin_edges = structure.fin_edges();
        let (shell, fin) = separated_vertices(structure, &fin_edges, fin_faces);
        check_size(device, "separated shells", shell.len() as u64 * SEPARATED_VERTEX_BYTES)?;
        check_size(device, "separated fins", fin.len() as u64 * SEPARATED_VERTEX_BYTES)?;
        let furred = structure.furred_triangles();
        let mut is_furred = vec![false; structure.mesh.triangles.len()];
        furred.iter().for_each(|&t| is_furred[t as usize] = true);
        let order = furred.iter().copied().chain((0..is_furred.len() as u32).filter(|&t| !is_furred[t as usize]));
        let indices: Vec<u32> = order.flat_map(|t| structure.mesh.triangles[t as usize]).collect();
        let groom = structure.groom.as_ref();
        let attributes = groom
            .map_or_else(|| vec![[0.0; 8]], |g| crate::geometry::groom_attributes(g, structure.mesh.vertex_count()));
        let mut ends: Vec<u32> = fin_edges.iter().flat_map(|&e| structure.mesh.edges[e as usize]).collect();
        if ends.is_empty() {
            ends = vec![0, 0];
        }
        let scope = ErrorScope::push(device);
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let shell_vertices = buffer("pelt separated shells", bytemuck::cast_slice(&shell), wgpu::BufferUsages::VERTEX);
        let shell_indices = buffer("pelt separated indices", bytemuck::cast_slice(&indices), wgpu::BufferUsages::INDEX);
        // Never empty: a storage binding needs at least one word (a mesh without edges has no fins).
        let fin_bytes: &[u8] =
            if fin.is_empty() { &[0; SEPARATED_VERTEX_BYTES as usize] } else { bytemuck::cast_slice(&fin) };
        let fin_usage = wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::STORAGE;
        let fin_vertices = buffer("pelt separated fins", fin_bytes, fin_usage);
        let uniform = uniform_buffer(device);
        let layouts = renderer.layouts();
        let groom_buffer =
            buffer("pelt separated groom attributes", bytemuck::cast_slice(&attributes), wgpu::BufferUsages::STORAGE);
        let ends_buffer = buffer("pelt separated fin ends", bytemuck::cast_slice(&ends), wgpu::BufferUsages::STORAGE);
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt separated object"),
            layout: &layouts.separated_object,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: fin_vertices.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: groom_buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: ends_buffer.as_entire_binding() },
            ],
        });
        let textures = GpuTextures::new(device, queue, layouts, textures, groom.is_some());
        scope.pop("uploading the separated structure")?;
        let textures = textures?;
        let vertices = (shell.len() + fin.len()) as u64;
        let bytes = GpuBytes {
            positions: vertices * POSITION_BYTES,
            attributes: vertices * (SEPARATED_VERTEX_BYTES - POSITION_BYTES),
            indices: indices.len() as u64 * 4,
            textures: textures.bytes,
        };
        let mut shape = ObjectShape::new(&structure.mesh, structure.layers);
        // The fin fade finds a fin's vertices from the fins' count.
        shape.edge_count = fin_edges.len() as u32;
        shape.furred_triangle_count = furred.len() as u32;
        shape.fin_edge_count = fin_edges.len() as u32;
        shape.groomed = groom.is_some();
        shape.groom_shading = groom.is_some_and(crate::geometry::shades);
        Ok(Self {
            shape,
            uniform,
            bind_group,
            textures,
            shell_vertices,
            shell_indices,
            fin_vertices,
            fin_vertex_count: fin.len() as u32,
            index_count: indices.len() as u32,
            bytes,
            level: PreparedLevel::new(),
        })
    }

    /// Writes this frame's model transform and look; the interpolation is unused (the separated
    /// structure is static).
    pub fn prepare(&self, queue: &wgpu::Queue, frame: &FurFrame) {
        let uniform = self.shape.uniform(frame, self.textures.root_colour, self.textures.shape);
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        self.level.set(frame.level, self.shape.layers);
    }

    /// Bytes of the separated structure on the GPU (shell and fin vertices, shell indices) and
    /// its textures.
    #[must_use]
    pub fn gpu_bytes(&self) -> GpuBytes {
        self.bytes
    }
}

/// The shell vertices (`(L + 1) * V`, layer 0 the skin) and the fins of `fin_edges`.
fn separated_vertices(fur: &FurStructure, fin_edges: &[u32], fin_faces: u32) -> (Vec<Vertex>, Vec<Vertex>) {
    let mesh = &fur.mesh;
    let v = mesh.vertex_count();
    let world_per_uv = crate::object::world_per_uv(mesh);
    // One uv per vertex (the first corner that uses it): the separated structure has no
    // per-corner data, so uv seams stretch here and only here.
    let mut vertex_uvs = vec![Vec2::ZERO; v];
    if let Some(uvs) = &mesh.corner_uvs {
        for (triangle, corner_uvs) in mesh.triangles.iter().zip(uvs).rev() {
            for (&j, uv) in triangle.iter().zip(corner_uvs) {
                vertex_uvs[j as usize] = *uv * world_per_uv;
            }
        }
    }
    let mut shell = Vec::with_capacity(fur.positions.len());
    for layer in 0..=fur.layers {
        let start = fur.index(layer, 0) as usize;
        let normals = if layer == 0 { &mesh.normals } else { &fur.directions };
        for ((position, normal), uv) in fur.positions[start..start + v].iter().zip(normals).zip(&vertex_uvs) {
            shell.push(Vertex { position: *position, normal: *normal, uv: *uv });
        }
    }
    let quads_per_fin = fin_faces.max(2).div_ceil(2);
    let mut fin = Vec::with_capacity(fin_edges.len() * 6 * quads_per_fin as usize);
    for &[a, b] in fin_edges.iter().map(|&e| &mesh.edges[e as usize]) {
        let (a, b) = (a as usize, b as usize);
        let root = |j: usize| fur.positions[j];
        let tip = |j: usize| fur.positions[fur.index(fur.layers, j as u32) as usize];
        let along = root(b) - root(a);
        let up = (tip(a) - root(a) + tip(b) - root(b)) * 0.5;
        let normal = along.cross(up).normalize_or(fur.directions[a]);
        let u_b = along.length();
        let point = |side: usize, t: f32| {
            let j = if side == 0 { a } else { b };
            let position = root(j).lerp(tip(j), t);
            Vertex { position, normal, uv: Vec2::new(if side == 0 { 0.0 } else { u_b }, t) }
        };
        for q in 0..quads_per_fin {
            let (t0, t1) = (q as f32 / quads_per_fin as f32, (q + 1) as f32 / quads_per_fin as f32);
            fin.extend([point(0, t0), point(1, t0), point(1, t1), point(0, t0), point(1, t1), point(0, t1)]);
        }
    }
    (shell, fin)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shaders::{assert_vertex_mirrors, rust_layout};

    #[test]
    fn vertex_mirrors_vertex_in() {
        let rust = rust_layout!(Vertex { position, normal, uv });
        assert_vertex_mirrors(&separated_shader_source(), "VertexIn", &rust, &VERTEX_ATTRIBUTES);
    }
}
