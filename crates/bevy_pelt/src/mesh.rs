//! Bevy meshes into pelt-core meshes (welded, repaired, with adjacency for the fins).

use std::path::Path;

use bevy::mesh::{Indices, Mesh, PrimitiveTopology, VertexAttributeValues};
use pelt_core::anim::Skin;
use pelt_core::mesh::RawMesh;
use pelt_core::{ImportOptions, MeshError};

/// Converts a triangle-list Bevy mesh (positions, optional normals and first uv set, optional
/// indices) into a pelt-core mesh, with the Bevy vertex each base vertex was taken from (for the
/// skin weights). `name` names it in errors.
///
/// Vertices Bevy splits at uv or normal seams are welded back together, so the fur's strands and
/// fins run across the seams; pelt-core keeps the uvs per triangle corner.
pub(crate) fn pelt_mesh(mesh: &Mesh, name: &str) -> Result<(pelt_core::Mesh, Vec<u32>), MeshError> {
    let file = Path::new(name);
    let invalid = |message: String| MeshError::Parse { file: file.to_path_buf(), line: None, message };
    if mesh.primitive_topology() != PrimitiveTopology::TriangleList {
        return Err(invalid(format!("fur needs a triangle list, this mesh is a {:?}", mesh.primitive_topology())));
    }
    // A mesh whose data went to the render world only (`RenderAssetUsages::RENDER_WORLD`) has
    // nothing left to grow fur from.
    let attribute = |id: bevy::mesh::MeshVertexAttributeId| {
        mesh.try_attribute_option(id)
            .map_err(|e| invalid(format!("{e}; fur needs the mesh in the main world (RenderAssetUsages::MAIN_WORLD)")))
    };
    let positions: Vec<glam::Vec3> = match attribute(Mesh::ATTRIBUTE_POSITION.id)? {
        Some(VertexAttributeValues::Float32x3(values)) => values.iter().map(|&p| glam::Vec3::from_array(p)).collect(),
        Some(_) => return Err(invalid("positions are not three 32-bit floats".to_owned())),
        None => return Err(invalid("the mesh has no positions".to_owned())),
    };
    let normals = match attribute(Mesh::ATTRIBUTE_NORMAL.id)? {
        Some(VertexAttributeValues::Float32x3(values)) => {
            Some(values.iter().map(|&n| glam::Vec3::from_array(n)).collect())
        }
        _ => None,
    };
    let uvs = match attribute(Mesh::ATTRIBUTE_UV_0.id)? {
        Some(VertexAttributeValues::Float32x2(values)) => {
            Some(values.iter().map(|&uv| glam::Vec2::from_array(uv)).collect())
        }
        _ => None,
    };
    let indices: Vec<u32> = match mesh.try_indices_option().map_err(|e| invalid(e.to_string()))? {
        Some(Indices::U16(indices)) => indices.iter().map(|&i| u32::from(i)).collect(),
        Some(Indices::U32(indices)) => indices.clone(),
        None => (0..positions.len() as u32).collect(),
    };
    if !indices.len().is_multiple_of(3) {
        return Err(invalid(format!("{} indices is not a whole number of triangles", indices.len())));
    }
    let triangles = indices.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect();
    let raw = RawMesh { positions, normals, uvs, triangles };
    pelt_core::Mesh::from_raw_traced(raw, file, &ImportOptions::default()).map(|(mesh, _report, source)| (mesh, source))
}

/// The skin of a Bevy mesh (its joint indices and weights) over `joint_count` joints, for the
/// base vertices `source` names (from [`pelt_mesh`]).
pub(crate) fn pelt_skin(mesh: &Mesh, source: &[u32], joint_count: usize) -> Result<Skin, String> {
    let joints: Vec<[u32; 4]> = match mesh.try_attribute_option(Mesh::ATTRIBUTE_JOINT_INDEX.id) {
        Ok(Some(VertexAttributeValues::Uint16x4(values))) => values.iter().map(|j| j.map(u32::from)).collect(),
        Ok(Some(VertexAttributeValues::Uint8x4(values))) => values.iter().map(|j| j.map(u32::from)).collect(),
        Ok(Some(_)) => return Err("its joint indices are not four 8- or 16-bit integers".to_owned()),
        Ok(None) => return Err("it has a SkinnedMesh but no joint indices".to_owned()),
        Err(e) => return Err(e.to_string()),
    };
    let weights: Vec<[f32; 4]> = match mesh.try_attribute_option(Mesh::ATTRIBUTE_JOINT_WEIGHT.id) {
        Ok(Some(VertexAttributeValues::Float32x4(values))) => values.clone(),
        Ok(Some(VertexAttributeValues::Unorm16x4(values))) => {
            values.iter().map(|w| w.map(|w| f32::from(w) / f32::from(u16::MAX))).collect()
        }
        Ok(Some(VertexAttributeValues::Unorm8x4(values))) => {
            values.iter().map(|w| w.map(|w| f32::from(w) / f32::from(u8::MAX))).collect()
        }
        Ok(Some(_)) => return Err("its joint weights are not four floats or unorms".to_owned()),
        Ok(None) => return Err("it has a SkinnedMesh but no joint weights".to_owned()),
        Err(e) => return Err(e.to_string()),
    };
    Skin::new(&joints, &weights, source, joint_count).map_err(|e| format!("its skin: {e}"))
}

#[cfg(test)]
mod tests {
    use bevy::asset::RenderAssetUsages;
    use bevy::shape::Cuboid;

    use super::*;

    #[test]
    fn a_cube_welds_to_eight_corners_with_twelve_edges_of_fins() {
        let cube = Mesh::from(Cuboid::new(1.0, 1.0, 1.0));
        let (mesh, source) = pelt_mesh(&cube, "cube").unwrap();
        assert_eq!(cube.count_vertices(), 24, "Bevy splits the corners per face");
        assert_eq!(mesh.vertex_count(), 8);
        assert_eq!(mesh.triangles.len(), 12);
        assert_eq!(mesh.edges.len(), 18, "12 cube edges and 6 face diagonals");
        assert!(mesh.corner_uvs.is_some());
        assert_eq!(source.len(), 8);
        for (j, &raw) in source.iter().enumerate() {
            let VertexAttributeValues::Float32x3(positions) = cube.attribute(Mesh::ATTRIBUTE_POSITION).unwrap() else {
                unreachable!("a cuboid has float positions")
            };
            assert_eq!(mesh.positions[j].to_array(), positions[raw as usize], "base vertex {j} comes from its source");
        }
    }

    #[test]
    fn a_skinned_cube_poses_with_its_weights() {
        // The top face follows joint 1, the bottom joint 0.
        let mut cube = Mesh::from(Cuboid::new(1.0, 1.0, 1.0));
        let VertexAttributeValues::Float32x3(positions) = cube.attribute(Mesh::ATTRIBUTE_POSITION).unwrap().clone()
        else {
            unreachable!("a cuboid has float positions")
        };
        cube.insert_attribute(Mesh::ATTRIBUTE_JOINT_INDEX, VertexAttributeValues::Uint16x4(vec![[0, 1, 0, 0]; 24]));
        let weights: Vec<[f32; 4]> =
            positions.iter().map(|p| if p[1] > 0.0 { [0.0, 1.0, 0.0, 0.0] } else { [1.0, 0.0, 0.0, 0.0] }).collect();
        cube.insert_attribute(Mesh::ATTRIBUTE_JOINT_WEIGHT, weights);
        let (mesh, source) = pelt_mesh(&cube, "cube").unwrap();
        let skin = pelt_skin(&cube, &source, 2).unwrap();
        let mut pose = pelt_core::anim::Pose::default();
        let up = glam::Mat4::from_translation(glam::Vec3::Y);
        skin.pose(&mesh, &[glam::Mat4::IDENTITY, up], &mut pose).unwrap();
        for (rest, posed) in mesh.positions.iter().zip(&pose.positions) {
            let lift = if rest.y > 0.0 { 1.0 } else { 0.0 };
            assert_eq!(*posed, *rest + glam::Vec3::Y * lift);
        }
        let bare = Mesh::from(Cuboid::new(1.0, 1.0, 1.0));
        let error = pelt_skin(&bare, &source, 2).unwrap_err();
        assert!(error.contains("joint indices"), "{error}");
    }

    #[test]
    fn lines_are_an_error_naming_the_mesh() {
        let lines = Mesh::new(PrimitiveTopology::LineList, RenderAssetUsages::default());
        let error = pelt_mesh(&lines, "wire").unwrap_err().to_string();
        assert!(error.contains("wire") && error.contains("triangle list"), "{error}");
    }
}
