//! The fur's vertex arrays as glTF wants them: one shell vertex per wedge (a base vertex with one
//! tile coordinate) shared by every exported layer but for its position, and fin strips with
//! their own vertices (each fin runs its own stretch of the fin texture).

use glam::{Vec2, Vec3};

use crate::fur::FurStructure;
use crate::mesh::Mesh;
use crate::reference::TileMapping;
use crate::texture::ImageRgba8;

/// The shells' wedges: per exported vertex, its base vertex and its tile coordinate.
#[derive(Clone, Debug, Default)]
pub(super) struct ShellWedges {
    /// Base vertex of each wedge.
    pub vertices: Vec<u32>,
    /// Tile coordinate (shell texture uv, repeating) of each wedge.
    pub tile_uvs: Vec<Vec2>,
    /// The mesh uv of each wedge (meshes with uvs): the surface colour's and the skin's.
    pub mesh_uvs: Option<Vec<Vec2>>,
    /// Triangles over the wedges.
    pub triangles: Vec<[u32; 3]>,
}

/// The renderer's tile coordinates: mesh uvs scaled, or without uvs the axis-aligned projection of
/// the root that the triangle faces most (the shader picks it per fragment from the interpolated
/// normal, so away from narrow bands it is the same). Only the triangles with fur (a groom's bald
/// ones have none, as in the renderer).
pub(super) fn shell_wedges(fur: &FurStructure, mapping: TileMapping) -> ShellWedges {
    let mesh = &fur.mesh;
    if let Some(wedges) = mesh.wedges() {
        return ShellWedges {
            vertices: wedges.vertices,
            tile_uvs: wedges.uvs.iter().map(|uv| *uv * mapping.tiles_per_uv).collect(),
            mesh_uvs: Some(wedges.uvs),
            triangles: wedges
                .corners
                .chunks_exact(3)
                .enumerate()
                .filter(|&(t, _)| fur.triangle_has_fur(t))
                .map(|(_, c)| [c[0], c[1], c[2]])
                .collect(),
        };
    }
    let mut numbered = std::collections::HashMap::with_capacity(2 * mesh.vertex_count());
    let mut out = ShellWedges::default();
    for (t, triangle) in mesh.triangles.iter().enumerate() {
        if !fur.triangle_has_fur(t) {
            continue;
        }
        let [a, b, c] = triangle.map(|j| mesh.positions[j as usize]);
        let axis = tile_axis((b - a).cross(c - a));
        out.triangles.push(triangle.map(|vertex| {
            let next = out.vertices.len() as u32;
            let wedge = *numbered.entry((vertex, axis)).or_insert(next);
            if wedge == next {
                let p = mesh.positions[vertex as usize] * mapping.tiles_per_world;
                out.vertices.push(vertex);
                out.tile_uvs.push(match axis {
                    0 => Vec2::new(p.y, p.z),
                    1 => Vec2::new(p.z, p.x),
                    _ => Vec2::new(p.x, p.y),
                });
            }
            wedge
        }));
    }
    out
}

/// The axis a surface with normal `n` faces most (0 = x, 1 = y, 2 = z), as `tile_axis` in
/// pelt-render's `shading.wgsl`.
fn tile_axis(n: Vec3) -> u8 {
    let a = n.abs();
    if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    }
}

/// The fins: every edge's strip from the roots to the tips through the exported layers.
#[derive(Clone, Debug, Default)]
pub(super) struct Fins {
    /// Base vertex of each fin vertex.
    pub vertices: Vec<u32>,
    /// Layer of each fin vertex.
    pub layers: Vec<u32>,
    /// Fin texture uv (u along the edge in tiles, repeating; v = 0 at the tips).
    pub uvs: Vec<Vec2>,
    /// The edge's normal (mean of its ends'), which the renderer lights fins with.
    pub normals: Vec<Vec3>,
    /// The mesh uv of each end (surface colour), from the first face beside the edge.
    pub mesh_uvs: Option<Vec<Vec2>>,
    /// Two triangles per edge and exported layer step.
    pub triangles: Vec<[u32; 3]>,
}

/// Fins on every edge with fins (a groom's bald edges have none) through `nodes` (layer 0, then
/// the exported layers, ascending).
pub(super) fn fins(fur: &FurStructure, nodes: &[u32], mapping: TileMapping) -> Fins {
    let mesh = &fur.mesh;
    let mut out = Fins { mesh_uvs: mesh.corner_uvs.as_ref().map(|_| Vec::new()), ..Fins::default() };
    let top = fur.layers as f32;
    for (edge, &[a, b]) in mesh.edges.iter().enumerate() {
        if !fur.edge_has_fins(edge) {
            continue;
        }
        let (pa, pb) = (mesh.positions[a as usize], mesh.positions[b as usize]);
        let offset = f32::from((hash(edge as u32) & 0xffff) as u16) / 65536.0;
        let along = pa.distance(pb) * mapping.tiles_per_world;
        let normal = (mesh.normals[a as usize] + mesh.normals[b as usize]).try_normalize().unwrap_or(Vec3::Y);
        let ends = [a, b].map(|vertex| end_uv(mesh, edge, vertex));
        let first = out.vertices.len() as u32;
        for &layer in nodes {
            for (side, &vertex) in [a, b].iter().enumerate() {
                out.vertices.push(vertex);
                out.layers.push(layer);
                out.uvs.push(Vec2::new(offset + side as f32 * along, 1.0 - layer as f32 / top));
                out.normals.push(normal);
                if let Some(uvs) = &mut out.mesh_uvs {
                    uvs.push(ends[side]);
                }
            }
        }
        for step in 0..nodes.len() as u32 - 1 {
            let (ia, ib) = (first + 2 * step, first + 2 * step + 1);
            let (ja, jb) = (ia + 2, ib + 2);
            out.triangles.push([ia, ib, jb]);
            out.triangles.push([ia, jb, ja]);
        }
    }
    out
}

/// The mesh uv of `vertex` in the first face beside `edge` (zero without uvs).
fn end_uv(mesh: &Mesh, edge: usize, vertex: u32) -> Vec2 {
    let Some(uvs) = &mesh.corner_uvs else { return Vec2::ZERO };
    let face = mesh.edge_faces[edge][0] as usize;
    mesh.triangles.get(face).and_then(|t| t.iter().position(|&v| v == vertex)).map_or(Vec2::ZERO, |k| uvs[face][k])
}

/// `hash` of pelt-render's `unified.wgsl`: each fin starts at its own place in the fin texture.
fn hash(x: u32) -> u32 {
    let mut h = x.wrapping_mul(0x9e37_79b9);
    h = (h ^ (h >> 16)).wrapping_mul(0x85eb_ca6b);
    h = (h ^ (h >> 13)).wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// The surface image's linear colour at each mesh uv (surface colour mode's tint), as the
/// renderer samples it (v = 0 at the top row).
pub(super) fn surface_colours(surface: &ImageRgba8, uvs: &[Vec2]) -> Vec<Vec3> {
    uvs.iter()
        .map(|uv| {
            let texel = surface.sample_wrapped(uv.x, uv.y);
            Vec3::new(srgb_to_linear(texel.x), srgb_to_linear(texel.y), srgb_to_linear(texel.z))
        })
        .collect()
}

pub(super) fn srgb_to_linear(value: f32) -> f32 {
    if value <= 0.04045 { value / 12.92 } else { ((value + 0.055) / 1.055).powf(2.4) }
}

pub(super) fn linear_to_srgb(value: f32) -> f32 {
    let v = value.clamp(0.0, 1.0);
    if v <= 0.003_130_8 { v * 12.92 } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 }
}
