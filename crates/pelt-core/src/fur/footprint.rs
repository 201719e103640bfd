//! What a structure costs: vertex and face counts and GPU bytes of the unified structure and of
//! the separated structure of Lengyel et al. it is measured against, both honouring a groom's
//! bald regions.

use super::{FurStructure, INDEX_BYTES, POSITION_BYTES, SEPARATED_VERTEX_BYTES};
use crate::mesh::Mesh;

/// The separated structure of Lengyel et al.: shells plus fins as geometry of their own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct SeparatedStructure {
    /// Number of shells `L` above the base.
    pub layers: u32,
    /// Faces per fin: 2 (one quad, Lengyel) or `N` (the paper compares `N = 30`).
    pub fin_faces: u32,
}

impl SeparatedStructure {
    /// Counts and GPU bytes of this structure on `mesh`, furred all over.
    #[must_use]
    pub fn footprint(&self, mesh: &Mesh) -> Footprint {
        Footprint::separated(mesh, self.layers, self.fin_faces, Drawn::all(mesh))
    }

    /// Counts and GPU bytes of this structure grown with `fur`'s groom: as in the unified
    /// structure, bald triangles get no shells and edges with both ends bald no fins, so the two
    /// are compared on the same fur. Without a groom, as [`SeparatedStructure::footprint`].
    #[must_use]
    pub fn footprint_of(&self, fur: &FurStructure) -> Footprint {
        Footprint::separated(&fur.mesh, self.layers, self.fin_faces, Drawn::of(fur))
    }
}

/// The base triangles that get shells and the edges that get fins.
#[derive(Clone, Copy)]
struct Drawn {
    triangles: u64,
    edges: u64,
}

impl Drawn {
    fn all(mesh: &Mesh) -> Self {
        Self { triangles: mesh.triangles.len() as u64, edges: mesh.edges.len() as u64 }
    }

    fn of(fur: &FurStructure) -> Self {
        if fur.groom.is_none() {
            return Self::all(&fur.mesh);
        }
        let triangles = (0..fur.mesh.triangles.len()).filter(|&t| fur.triangle_has_fur(t)).count() as u64;
        let edges = (0..fur.mesh.edges.len()).filter(|&e| fur.edge_has_fins(e)).count() as u64;
        Self { triangles, edges }
    }
}

/// Vertex and face counts and GPU bytes of one structure on one mesh.
///
/// Faces count what is drawn: with a groom, bald triangles have no shell faces and edges with
/// both ends bald no fin faces ([`FurStructure::triangle_has_fur`]). The vertex counts follow the paper's Table 2: unified `V(L+1)`; separated `V(L+1) + N*E` with
/// `N` faces per fin. GPU bytes follow the layouts Pelt draws:
/// - unified: positions `12 * V(L+1)`; attributes the base normals `12V` plus, when the mesh has
///   uvs, `8` per wedge (each distinct (vertex, uv) pair, [`crate::mesh::Wedges`]); indices the
///   base triangles `3F` and the edges `2E` plus each edge's two faces `2E` (for the silhouette
///   test), and with uvs each wedge's vertex `W` and each corner's wedge `3F`, 4 bytes each;
/// - separated: every vertex a full vertex (position, normal, uv: 32 bytes), split here into
///   positions (12) and attributes (20); indices one shell index buffer `3F` reused per layer
///   with a base-vertex offset, and `3N` per fin.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct Footprint {
    /// Vertices stored (the paper's counting).
    pub vertices: u64,
    /// Shell faces (`F * L`, the base is drawn once more as the opaque skin) plus fin faces.
    pub faces: u64,
    /// Shell faces, `F * L`.
    pub shell_faces: u64,
    /// Fin faces: `2LE` unified, `NE` separated.
    pub fin_faces: u64,
    /// GPU bytes of vertex positions.
    pub position_bytes: u64,
    /// GPU bytes of other vertex data (normals, uvs).
    pub attribute_bytes: u64,
    /// GPU bytes of indices and topology.
    pub index_bytes: u64,
}

impl Footprint {
    /// The unified structure on `fur`'s mesh.
    pub(super) fn unified(fur: &FurStructure) -> Self {
        let (mesh, drawn) = (&fur.mesh, Drawn::of(fur));
        let (v, f, e, l) = counts(mesh, fur.layers);
        let vertices = v * (l + 1);
        // Meshes with uvs: the wedges' uvs, their vertices and each corner's wedge.
        let (uv_bytes, wedge_indices) = match mesh.wedges() {
            Some(wedges) => (8 * wedges.vertices.len() as u64, wedges.vertices.len() as u64 + 3 * f),
            None => (0, 0),
        };
        let shell_faces = drawn.triangles * l;
        let fin_faces = 2 * l * drawn.edges;
        Self {
            vertices,
            faces: shell_faces + fin_faces,
            shell_faces,
            fin_faces,
            position_bytes: vertices * POSITION_BYTES,
            attribute_bytes: v * 12 + uv_bytes,
            index_bytes: (3 * f + 2 * e + 2 * e + wedge_indices) * INDEX_BYTES,
        }
    }

    fn separated(mesh: &Mesh, layers: u32, faces_per_fin: u32, drawn: Drawn) -> Self {
        let (v, _, _, l) = counts(mesh, layers);
        let (f, e) = (drawn.triangles, drawn.edges);
        let n = u64::from(faces_per_fin);
        let vertices = v * (l + 1) + n * e;
        let shell_faces = f * l;
        let fin_faces = n * e;
        Self {
            vertices,
            faces: shell_faces + fin_faces,
            shell_faces,
            fin_faces,
            position_bytes: vertices * POSITION_BYTES,
            attribute_bytes: vertices * (SEPARATED_VERTEX_BYTES - POSITION_BYTES),
            index_bytes: (3 * f + 3 * n * e) * INDEX_BYTES,
        }
    }

    /// All GPU bytes of the structure.
    #[must_use]
    pub fn total_bytes(&self) -> u64 {
        self.position_bytes + self.attribute_bytes + self.index_bytes
    }

    /// How much `self` saves against `other`, in percent of `other` (`key` picks the measure).
    #[must_use]
    pub fn savings_percent(&self, other: &Self, key: impl Fn(&Self) -> u64) -> f64 {
        let theirs = key(other) as f64;
        if theirs == 0.0 { 0.0 } else { 100.0 * (theirs - key(self) as f64) / theirs }
    }
}

fn counts(mesh: &Mesh, layers: u32) -> (u64, u64, u64, u64) {
    (mesh.vertex_count() as u64, mesh.triangles.len() as u64, mesh.edges.len() as u64, u64::from(layers))
}
