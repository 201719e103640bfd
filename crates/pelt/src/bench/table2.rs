//! The paper's Table 2: counts and GPU bytes of the unified structure against the separated
//! structure with 2-face and 30-face fins.

use pelt_core::fur::FurLength;
use pelt_core::fur::{Footprint, INDEX_BYTES, SEPARATED_VERTEX_BYTES};
use pelt_core::{FurParams, FurStructure, GrowthDirection, Mesh, SeparatedStructure};

use super::models::Model;

/// Faces per fin of the paper's second baseline.
pub const MANY_FIN_FACES: u32 = 30;

/// What the paper claims the unified structure saves (vertices), for the report to sit beside.
pub const PAPER_SAVINGS_VS_2_PERCENT: f64 = 25.0;
pub const PAPER_SAVINGS_VS_30_PERCENT: f64 = 85.0;

/// One model at one layer count.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Table2Row {
    /// Base vertices of every mesh drawn (the body included), as the paper counts them.
    pub vertices: u64,
    /// Base triangles of every mesh drawn.
    pub faces: u64,
    /// Edges of the furred mesh (each carries a fin).
    pub fur_edges: u64,
    /// Base vertices of the furred mesh.
    pub fur_vertices: u64,
    pub unified: Footprint,
    pub separated2: Footprint,
    pub separated30: Footprint,
    /// What an un-furred body adds to every structure: its vertices, triangles and GPU bytes.
    pub body_vertices: u64,
    pub body_faces: u64,
    pub body_bytes: u64,
}

impl Table2Row {
    /// # Errors
    /// A layer count the fur structure refuses.
    pub fn compute(model: &Model, layers: u32) -> anyhow::Result<Self> {
        let fur = &model.fur;
        let (body_vertices, body_faces, body_bytes) = model.body.as_ref().map_or((0, 0, 0), plain_mesh);
        Ok(Self {
            vertices: fur.vertex_count() as u64 + body_vertices,
            faces: fur.triangles.len() as u64 + body_faces,
            fur_edges: fur.edges.len() as u64,
            fur_vertices: fur.vertex_count() as u64,
            unified: unified_footprint(fur, layers)?,
            separated2: SeparatedStructure { layers, fin_faces: 2 }.footprint(fur),
            separated30: SeparatedStructure { layers, fin_faces: MANY_FIN_FACES }.footprint(fur),
            body_vertices,
            body_faces,
            body_bytes,
        })
    }

    /// Vertices of the whole scene drawn with the unified structure (`V(L+1)`, plus a body).
    pub fn unified_vertices(&self) -> u64 {
        self.unified.vertices + self.body_vertices
    }
    pub fn separated2_vertices(&self) -> u64 {
        self.separated2.vertices + self.body_vertices
    }
    pub fn separated30_vertices(&self) -> u64 {
        self.separated30.vertices + self.body_vertices
    }
    pub fn unified_bytes(&self) -> u64 {
        self.unified.total_bytes() + self.body_bytes
    }
    pub fn separated2_bytes(&self) -> u64 {
        self.separated2.total_bytes() + self.body_bytes
    }
    pub fn separated30_bytes(&self) -> u64 {
        self.separated30.total_bytes() + self.body_bytes
    }
}

/// The unified footprint, as the structure itself reports it (growing it is cheap next to loading).
fn unified_footprint(mesh: &Mesh, layers: u32) -> anyhow::Result<Footprint> {
    let params = FurParams { layers, length: FurLength::Constant(0.0), direction: GrowthDirection::default() };
    Ok(FurStructure::new(mesh.clone(), &params)?.footprint())
}

/// `100 * (theirs - ours) / theirs`.
pub fn savings_percent(ours: u64, theirs: u64) -> f64 {
    if theirs == 0 { 0.0 } else { 100.0 * (theirs as f64 - ours as f64) / theirs as f64 }
}

/// Vertices, triangles and GPU bytes of a mesh drawn plainly (full vertices, one index buffer).
fn plain_mesh(mesh: &Mesh) -> (u64, u64, u64) {
    let vertices = mesh.vertex_count() as u64;
    let faces = mesh.triangles.len() as u64;
    (vertices, faces, vertices * SEPARATED_VERTEX_BYTES + 3 * faces * INDEX_BYTES)
}

#[cfg(test)]
mod tests {
    use pelt_core::Builtin;

    use super::super::models::{MODELS, MeshSource};
    use super::*;

    fn model(fur: Builtin, body: Option<Builtin>) -> Model {
        let spec = MODELS[0];
        Model { spec, fur: fur.mesh().0, body: body.map(|b| b.mesh().0), rig: None }
    }

    #[test]
    fn box_reproduces_the_papers_row() {
        let row = Table2Row::compute(&model(Builtin::Box, None), 16).unwrap();
        assert_eq!((row.vertices, row.faces, row.fur_edges), (296, 588, 882));
        assert_eq!(row.unified_vertices(), 5_032);
        assert_eq!(row.separated2_vertices(), 6_796);
        assert_eq!(row.separated30_vertices(), 31_492);
        let saved = savings_percent(row.unified_vertices(), row.separated2_vertices());
        assert!((saved - 25.96).abs() < 0.01, "{saved}");
        assert!(row.unified_bytes() < row.separated2_bytes());
    }

    #[test]
    fn a_body_counts_once_in_every_structure() {
        let alone = Table2Row::compute(&model(Builtin::Plane, None), 16).unwrap();
        let dressed = Table2Row::compute(&model(Builtin::Plane, Some(Builtin::Sphere)), 16).unwrap();
        let (sphere, _) = Builtin::Sphere.mesh();
        let v = sphere.vertex_count() as u64;
        assert_eq!(dressed.vertices, alone.vertices + v);
        assert_eq!(dressed.unified_vertices(), alone.unified_vertices() + v);
        assert_eq!(dressed.separated2_vertices(), alone.separated2_vertices() + v);
        assert_eq!(dressed.separated30_vertices(), alone.separated30_vertices() + v);
        let body_bytes = dressed.unified_bytes() - alone.unified_bytes();
        assert_eq!(body_bytes, v * 32 + sphere.triangles.len() as u64 * 12);
        assert_eq!(dressed.separated30_bytes() - alone.separated30_bytes(), body_bytes);
        // The body dilutes the savings, as in the paper's Women row.
        let saved = |r: &Table2Row| savings_percent(r.unified_vertices(), r.separated2_vertices());
        assert!(saved(&dressed) < saved(&alone));
        assert!(matches!(MODELS[4].body, Some(MeshSource::Asset(_))));
    }
}
