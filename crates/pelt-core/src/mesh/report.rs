//! What import found and repaired, for the caller to print.

use std::fmt;

/// Where the vertex normals came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NormalSource {
    /// From the file (averaged where welding merged vertices).
    File,
    /// Computed as angle-weighted smooth normals because the file had none (or broken ones).
    Computed,
}

/// What [`Mesh::from_raw`](super::Mesh::from_raw) found and repaired.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MeshReport {
    /// The file or built-in this mesh came from.
    pub source: String,
    /// Vertices in the file.
    pub input_vertices: usize,
    /// Triangles in the file.
    pub input_triangles: usize,
    /// Vertices merged into another one by welding.
    pub welded_vertices: usize,
    /// Triangles dropped for having no area.
    pub dropped_zero_area_triangles: usize,
    /// Triangles dropped for using one vertex twice.
    pub dropped_repeated_index_triangles: usize,
    /// Triangles over the same three vertices as an earlier one, either winding (double-sided
    /// or doubled geometry would make every edge non-manifold and draw its fins twice).
    pub dropped_duplicate_triangles: usize,
    /// Vertices dropped because no triangle uses them.
    pub dropped_unreferenced_vertices: usize,
    /// Triangles flipped to agree with their neighbours (or to turn a closed part outward).
    pub reoriented_triangles: usize,
    /// Where the normals came from.
    pub normals: NormalSource,
    /// Whether the mesh has texture coordinates (none are generated when the file has none).
    pub has_uvs: bool,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Connected chains of boundary edges: the holes and open rims (0 on a closed mesh).
    pub boundary_loops: usize,
    /// Edges with more than two faces.
    pub non_manifold_edges: usize,
    /// Edges whose two faces traverse them in the same direction (flipped winding).
    pub inconsistent_winding_edges: usize,
    /// Vertices after repair.
    pub vertices: usize,
    /// Triangles after repair.
    pub triangles: usize,
    /// Undirected edges after repair.
    pub edges: usize,
}

impl MeshReport {
    /// Whether every edge has exactly two consistently wound faces.
    #[must_use]
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0 && self.non_manifold_edges == 0 && self.inconsistent_winding_edges == 0
    }
}

impl fmt::Display for MeshReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "mesh {}", self.source)?;
        writeln!(
            f,
            "  read {} vertices, {} triangles; kept {} vertices, {} triangles, {} edges",
            self.input_vertices, self.input_triangles, self.vertices, self.triangles, self.edges
        )?;
        writeln!(f, "  welded {} duplicate vertices", self.welded_vertices)?;
        writeln!(
            f,
            "  dropped {} zero-area, {} repeated-index and {} duplicate triangles, {} unreferenced vertices",
            self.dropped_zero_area_triangles,
            self.dropped_repeated_index_triangles,
            self.dropped_duplicate_triangles,
            self.dropped_unreferenced_vertices
        )?;
        writeln!(f, "  flipped {} triangles to a consistent, outward winding", self.reoriented_triangles)?;
        let normals = match self.normals {
            NormalSource::File => "from the file",
            NormalSource::Computed => "computed (smooth)",
        };
        let uvs = if self.has_uvs { "from the file" } else { "none in the file (none generated)" };
        writeln!(f, "  normals {normals}; uvs {uvs}")?;
        write!(
            f,
            "  {} boundary edges in {} loops, {} non-manifold edges, {} edges with inconsistent winding",
            self.boundary_edges, self.boundary_loops, self.non_manifold_edges, self.inconsistent_winding_edges
        )
    }
}
