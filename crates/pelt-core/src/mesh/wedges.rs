//! Wedges: the distinct (base vertex, uv) pairs a mesh's triangle corners use. A vertex on a uv
//! seam has one wedge per side. The unified renderer draws the shells of a mesh with uvs indexed
//! by wedge, so that each is shaded once a layer (walking the `3F` corners shaded every corner:
//! 17,568 a layer on Spot, against 3,225 wedges); the footprint counts their bytes.

use glam::Vec2;

use super::Mesh;

/// A mesh's wedges, numbered in the order the corners first use them (so the triangles'
/// vertex-cache order carries over), and each corner's wedge.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Wedges {
    /// The base vertex of each wedge.
    pub vertices: Vec<u32>,
    /// The uv of each wedge.
    pub uvs: Vec<Vec2>,
    /// The wedge of each triangle corner (`3F`, triangle-major).
    pub corners: Vec<u32>,
}

impl Mesh {
    /// The wedges of a mesh with uvs; `None` without uvs.
    #[must_use]
    pub fn wedges(&self) -> Option<Wedges> {
        let corner_uvs = self.corner_uvs.as_ref()?;
        let mut numbered = std::collections::HashMap::with_capacity(2 * self.vertex_count());
        let mut wedges = Wedges { corners: Vec::with_capacity(3 * corner_uvs.len()), ..Wedges::default() };
        for (triangle, uvs) in self.triangles.iter().zip(corner_uvs) {
            for (&vertex, &uv) in triangle.iter().zip(uvs) {
                let next = wedges.vertices.len() as u32;
                let wedge = *numbered.entry((vertex, uv.to_array().map(f32::to_bits))).or_insert(next);
                if wedge == next {
                    wedges.vertices.push(vertex);
                    wedges.uvs.push(uv);
                }
                wedges.corners.push(wedge);
            }
        }
        Some(wedges)
    }
}
