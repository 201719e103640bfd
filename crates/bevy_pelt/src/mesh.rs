//! Bevy meshes into pelt-core meshes (welded, repaired, with adjacency for the fins).

use std::path::Path;

use bevy::mesh::{Indices, Mesh, PrimitiveTopology, VertexAttributeValues};
use pelt_core::mesh::RawMesh;
use pelt_core::{ImportOptions, MeshError};

/// Converts a triangle-list Bevy mesh (positions, optional normals and first uv set, optional
/// indices) into a pelt-core mesh. `name` names it in errors.
///
/// Vertices Bevy splits at uv or normal seams are welded back together, so the fur's strands and
/// fins run across the seams; pelt-core keeps the uvs per triangle corner.
pub(crate) fn pelt_mesh(mesh: &Mesh, name: &str) -> Result<pelt_core::Mesh, MeshError> {
    let file = Path::new(name);
    let invalid = |message: String| MeshError::Parse { file: file.to_path_buf(), line: None, message };
    if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
        return Err(invalid(format!("fur needs a triangle list, this mesh is a {:?}", mesh.primitive_topology())));
    }
    let positions = match mesh.attribute(Mesh::ATTRIBUTE_POSITION) {
        Some(VertexAttributeValues::Float32x3(values)) => values.iter().map(|&p| glam::Vec3::from_array(p)).collect(),
        Some(_) => return Err(invalid("positions are not three 32-bit floats".to_owned())),
        None => return Err(invalid("the mesh has no positions".to_owned())),
    };
    let normals = match mesh.attribute(Mesh::ATTRIBUTE_NORMAL) {
        Some(VertexAttributeValues::Float32x3(values)) => {
            Some(values.iter().map(|&n| glam::Vec3::from_array(n)).collect())
        }
        _ => None,
    };
    let uvs = match mesh.attribute(Mesh::ATTRIBUTE_UV_0) {
        Some(VertexAttributeValues::Float32x2(values)) => {
            Some(values.iter().map(|&uv| glam::Vec2::from_array(uv)).collect())
        }
        _ => None,
    };
    let indices: Vec<u32> = match mesh.indices() {
        Some(Indices::U16(indices)) => indices.iter().map(|&i| u32::from(i)).collect(),
        Some(Indices::U32(indices)) => indices.clone(),
        None => (0..mesh.count_vertices() as u32).collect(),
    };
    if !indices.len().is_multiple_of(3) {
        return Err(invalid(format!("{} indices is not a whole number of triangles", indices.len())));
    }
    let triangles = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let raw = RawMesh { positions, normals, uvs, triangles };
    pelt_core::Mesh::from_raw(raw, file, &ImportOptions::default()).map(|(mesh, _report)| mesh)
}

#[cfg(test)]
mod tests {
    use bevy::asset::RenderAssetUsages;
    use bevy::shape::Cuboid;

    use super::*;

    #[test]
    fn a_cube_welds_to_eight_corners_with_twelve_edges_of_fins() {
        let cube = Mesh::from(Cuboid::new(1.0, 1.0, 1.0));
        let mesh = pelt_mesh(&cube, "cube").unwrap();
        assert_eq!(cube.count_vertices(), 24, "Bevy splits the corners per face");
        assert_eq!(mesh.vertex_count(), 8);
        assert_eq!(mesh.triangles.len(), 12);
        assert_eq!(mesh.edges.len(), 18, "12 cube edges and 6 face diagonals");
        assert!(mesh.corner_uvs.is_some());
    }

    #[test]
    fn lines_are_an_error_naming_the_mesh() {
        let lines = Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::default());
        let error = pelt_mesh(&lines, "wire").unwrap_err().to_string();
        assert!(error.contains("wire") && error.contains("triangle list"), "{error}");
    }
}
