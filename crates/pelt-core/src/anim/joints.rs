//! Skinning with joint matrices a host computes each frame (a game engine's own skeleton and
//! animation player): the linear blend skinning [`Rig::pose`](super::Rig::pose) does, fed with
//! one `world(joint) * inverse_bind` matrix per joint instead of sampling a glTF animation.

use glam::Mat4;

use super::gltf_rig::{InfluenceCounts, normalise};
use super::{Influences, Pose, skin};
use crate::mesh::Mesh;

/// Why a [`Skin`] cannot be built or posed.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SkinError {
    /// An array has the wrong length.
    #[error("{what}: expected {expected}, got {got}")]
    Size {
        /// What was wrong.
        what: &'static str,
        /// The length it needs.
        expected: usize,
        /// The length it has.
        got: usize,
    },
    /// A base vertex names a raw vertex the joint arrays do not have.
    #[error("base vertex {vertex} comes from raw vertex {source_vertex}, but the skin has {raw_vertices} raw vertices")]
    Source {
        /// The base vertex.
        vertex: usize,
        /// The raw vertex it names.
        source_vertex: u32,
        /// Raw vertices in the joint arrays.
        raw_vertices: usize,
    },
    /// A skin needs at least one joint.
    #[error("a skin needs at least one joint")]
    NoJoints,
    /// A joint matrix has a NaN or infinite entry.
    #[error("joint matrix {joint} is not finite")]
    NonFinite {
        /// The joint.
        joint: usize,
    },
}

/// Which joints move each base vertex and by how much, for joint matrices the host supplies.
///
/// Built from per-raw-vertex joints and weights (as a game engine keeps them beside its mesh)
/// and the raw vertex each base vertex came from ([`Mesh::from_raw_traced`]), so the weights
/// follow welding and repair. Weights are repaired as the glTF reader repairs them: negative or
/// non-finite weights and joints past the last are dropped, the four largest kept and
/// renormalised, and a vertex with no weight left is bound to joint 0 ([`Skin::report`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Skin {
    influences: Vec<Influences>,
    joint_count: usize,
    report: Vec<String>,
}

impl Skin {
    /// A skin for the base vertices `source` lists (`source[j]` is the raw vertex base vertex `j`
    /// was taken from), with `joints[i]` and `weights[i]` the influences of raw vertex `i` over
    /// `joint_count` joints.
    ///
    /// # Errors
    /// [`SkinError::Size`] when `joints` and `weights` differ in length, [`SkinError::Source`]
    /// for a raw vertex past them, [`SkinError::NoJoints`] for `joint_count == 0`.
    pub fn new(
        joints: &[[u32; 4]],
        weights: &[[f32; 4]],
        source: &[u32],
        joint_count: usize,
    ) -> Result<Self, SkinError> {
        if weights.len() != joints.len() {
            return Err(SkinError::Size { what: "the joint weights", expected: joints.len(), got: weights.len() });
        }
        if joint_count == 0 {
            return Err(SkinError::NoJoints);
        }
        let mut counts = InfluenceCounts::default();
        let mut influences = Vec::with_capacity(source.len());
        for (vertex, &raw) in source.iter().enumerate() {
            let (Some(j), Some(w)) = (joints.get(raw as usize), weights.get(raw as usize)) else {
                return Err(SkinError::Source { vertex, source_vertex: raw, raw_vertices: joints.len() });
            };
            influences.push(normalise(j.iter().copied().zip(w.iter().copied()), joint_count, 0, &mut counts));
        }
        let mut report = Vec::new();
        counts.report(&mut report);
        Ok(Self { influences, joint_count, report })
    }

    /// Base vertices the skin was built for.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.influences.len()
    }

    /// Joints the skin expects one matrix for.
    #[must_use]
    pub fn joint_count(&self) -> usize {
        self.joint_count
    }

    /// What was repaired in the weights, one line each.
    #[must_use]
    pub fn report(&self) -> &[String] {
        &self.report
    }

    /// Poses `mesh` (the mesh the skin was built for, in its bind pose) with one matrix per
    /// joint, `world(joint) * inverse_bind`, into `pose`: positions and normals where the
    /// matrices put them, and each vertex's rotation for
    /// [`Simulation::set_base_rotations`](crate::sim::Simulation::set_base_rotations).
    ///
    /// # Errors
    /// [`SkinError::Size`] for a mesh or a matrix list of another size, [`SkinError::NonFinite`]
    /// for a matrix with NaN or infinite entries; `pose` is unchanged then.
    pub fn pose(&self, mesh: &Mesh, joint_matrices: &[Mat4], pose: &mut Pose) -> Result<(), SkinError> {
        if mesh.vertex_count() != self.influences.len() {
            return Err(SkinError::Size {
                what: "the mesh's vertices",
                expected: self.influences.len(),
                got: mesh.vertex_count(),
            });
        }
        if joint_matrices.len() != self.joint_count {
            return Err(SkinError::Size {
                what: "the joint matrices",
                expected: self.joint_count,
                got: joint_matrices.len(),
            });
        }
        if let Some(joint) = joint_matrices.iter().position(|m| !m.is_finite()) {
            return Err(SkinError::NonFinite { joint });
        }
        let joints: Vec<skin::JointTransform> = joint_matrices.iter().map(|&m| skin::JointTransform::new(m)).collect();
        let mut morphed = std::mem::take(&mut pose.morphed);
        morphed.clear();
        morphed.extend(mesh.positions.iter().copied().zip(mesh.normals.iter().copied()));
        skin::blend(&joints, &self.influences, &morphed, &mesh.normals, pose);
        pose.morphed = morphed;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;
    use crate::ImportOptions;
    use crate::mesh::RawMesh;

    /// A strip of two quads along +X, split at x = 1 into two raw copies (a uv seam), so welding
    /// has something to follow.
    fn strip() -> (Mesh, Vec<u32>) {
        let positions = vec![
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            // The second quad repeats the seam's two vertices.
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(2.0, 1.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
        ];
        let triangles = vec![[0, 1, 2], [0, 2, 3], [4, 5, 6], [4, 6, 7]];
        let raw = RawMesh { positions, normals: None, uvs: None, triangles };
        let (mesh, _, source) = Mesh::from_raw_traced(raw, std::path::Path::new("strip"), &ImportOptions::default())
            .expect("a valid strip");
        (mesh, source)
    }

    #[test]
    fn half_weights_land_halfway_between_the_two_joints() {
        let (mesh, source) = strip();
        assert_eq!(mesh.vertex_count(), 6, "the seam's copies are welded");
        // Raw vertices at x = 0 follow joint 0, at x = 2 joint 1, the seam half each.
        let joints = vec![[0, 1, 0, 0]; 8];
        let weights: Vec<[f32; 4]> = (0..8)
            .map(|i| match i {
                0 | 3 => [1.0, 0.0, 0.0, 0.0],
                5 | 6 => [0.0, 1.0, 0.0, 0.0],
                _ => [0.5, 0.5, 0.0, 0.0],
            })
            .collect();
        let skin = Skin::new(&joints, &weights, &source, 2).unwrap();
        assert!(skin.report().is_empty(), "{:?}", skin.report());
        let lift = Mat4::from_translation(Vec3::new(0.0, 0.0, 4.0));
        let mut pose = Pose::default();
        skin.pose(&mesh, &[Mat4::IDENTITY, lift], &mut pose).unwrap();
        for (j, (rest, posed)) in mesh.positions.iter().zip(&pose.positions).enumerate() {
            let expected_z = 2.0 * rest.x;
            assert!((posed.z - expected_z).abs() < 1e-5 && posed.x == rest.x, "vertex {j}: {rest} -> {posed}");
        }
    }

    #[test]
    fn a_turned_joint_turns_positions_normals_and_frames() {
        let (mesh, source) = strip();
        let skin = Skin::new(&[[0; 4]; 8], &[[1.0, 0.0, 0.0, 0.0]; 8], &source, 1).unwrap();
        let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
        let mut pose = Pose::default();
        skin.pose(&mesh, &[Mat4::from_quat(turn)], &mut pose).unwrap();
        for j in 0..mesh.vertex_count() {
            assert!(pose.positions[j].distance(turn * mesh.positions[j]) < 1e-5);
            assert!(pose.normals[j].distance(turn * mesh.normals[j]) < 1e-5);
            assert!(pose.rotations[j].angle_between(turn) < 1e-3);
        }
    }

    #[test]
    fn bad_weights_and_matrices_are_errors_or_repairs() {
        let (mesh, source) = strip();
        let mut weights = vec![[1.0, 0.0, 0.0, 0.0]; 8];
        weights[0] = [0.0; 4];
        weights[1] = [f32::NAN, 1.0, 0.0, 0.0];
        let joints = vec![[0, 0, 0, 0]; 8];
        let skin = Skin::new(&joints, &weights, &source, 1).unwrap();
        assert_eq!(skin.report().len(), 2, "{:?}", skin.report());
        assert_eq!(
            Skin::new(&joints, &weights[..7], &source, 1).unwrap_err(),
            SkinError::Size { what: "the joint weights", expected: 8, got: 7 }
        );
        assert_eq!(Skin::new(&joints, &weights, &source, 0).unwrap_err(), SkinError::NoJoints);
        assert!(matches!(Skin::new(&joints[..4], &weights[..4], &source, 1), Err(SkinError::Source { .. })));

        let mut pose = Pose::default();
        let broken = Mat4::from_translation(Vec3::new(f32::INFINITY, 0.0, 0.0));
        assert_eq!(skin.pose(&mesh, &[broken], &mut pose).unwrap_err(), SkinError::NonFinite { joint: 0 });
        assert!(matches!(skin.pose(&mesh, &[Mat4::IDENTITY; 2], &mut pose), Err(SkinError::Size { .. })));
        assert!(pose.positions.is_empty(), "a failed pose leaves the pose alone");
        skin.pose(&mesh, &[Mat4::IDENTITY], &mut pose).unwrap();
        assert_eq!(pose.positions, mesh.positions, "identity joints give the bind pose");
        assert!(pose.positions.iter().chain(&pose.normals).all(|p| p.is_finite()));
    }
}
