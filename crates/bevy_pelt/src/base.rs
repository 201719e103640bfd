//! Where a fur's base surface is each frame: moved rigidly by the entity's `GlobalTransform`, or
//! skinned by pelt-core with the joint matrices of Bevy's own skeleton (`SkinnedMesh`, driven by
//! Bevy's animation).
//!
//! The simulation runs in the world's frame divided by one uniform scale `s` (the transform's or
//! the skin's): strands keep their length relative to the body at any scale, the roots move and
//! accelerate there as they do in the world (so pelt-core's inertia sees the body's motion), and
//! gravity, wind and rays keep their world directions. The renderer draws it with
//! `world_from_simulation = scale(s)`.

use glam::{Affine3A, Mat4, Quat, Vec3};
use pelt_core::anim::{Pose, Skin, SkinError};

/// The posed base this frame, in simulation space.
#[derive(Debug, Default)]
pub(crate) struct Base {
    pub positions: Vec<Vec3>,
    /// Unit normals (simulation and world space turn alike), for the renderer's lighting.
    pub normals: Vec<Vec3>,
    pub rotations: Vec<Quat>,
    /// The uniform scale `s`: world = s * simulation.
    pub scale: f32,
    pose: Pose,
}

impl Base {
    /// The base (`rest` positions and `rest_normals`) moved rigidly by `world_from_model`.
    pub fn rigid(&mut self, rest: &[Vec3], rest_normals: &[Vec3], world_from_model: &Affine3A) {
        let (_, rotation, _) = world_from_model.to_scale_rotation_translation();
        let rotation = if rotation.is_finite() { rotation.normalize() } else { Quat::IDENTITY };
        let scale = uniform_scale(world_from_model.matrix3.determinant());
        self.scale = scale;
        self.positions.clear();
        self.positions.extend(rest.iter().map(|&p| world_from_model.transform_point3(p) / scale));
        let normal_from_model = world_from_model.matrix3.inverse().transpose();
        let normal_from_model = if normal_from_model.is_finite() { normal_from_model } else { glam::Mat3A::IDENTITY };
        self.normals.clear();
        self.normals.extend(rest_normals.iter().map(|&n| (normal_from_model * n).normalize_or(n)));
        self.rotations.clear();
        self.rotations.resize(rest.len(), rotation);
    }

    /// The base skinned by `skin` with `joint_matrices` (`world(joint) * inverse_bind` each, so
    /// the skinned positions are in world space, as Bevy draws skinned meshes).
    pub fn skinned(&mut self, skin: &Skin, mesh: &pelt_core::Mesh, joint_matrices: &[Mat4]) -> Result<(), SkinError> {
        skin.pose(mesh, joint_matrices, &mut self.pose)?;
        // The skeleton's scale: joints scaled with their parents (a scene root scaled to fit the
        // world) scale the whole body.
        let determinants: f32 = joint_matrices.iter().map(|m| uniform_scale(Mat4::determinant(m))).sum::<f32>()
            / joint_matrices.len() as f32;
        let scale = if determinants.is_finite() && determinants > 0.0 { determinants } else { 1.0 };
        self.scale = scale;
        self.positions.clear();
        self.positions.extend(self.pose.positions.iter().map(|&p| p / scale));
        self.normals.clone_from(&self.pose.normals);
        self.rotations.clone_from(&self.pose.rotations);
        Ok(())
    }

    /// Simulation space to world space.
    pub fn world_from_simulation(&self) -> Mat4 {
        Mat4::from_scale(Vec3::splat(self.scale))
    }
}

/// The uniform scale of a linear map with determinant `determinant`: its cube root, 1 for a
/// singular or broken one.
fn uniform_scale(determinant: f32) -> f32 {
    let scale = determinant.abs().cbrt();
    if scale.is_finite() && scale > 1e-12 { scale } else { 1.0 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scaled_turned_moved_body_is_its_world_pose_divided_by_the_scale() {
        let rest = [Vec3::ZERO, Vec3::X, Vec3::Y];
        let turn = Quat::from_rotation_z(0.5);
        let world_from_model =
            Affine3A::from_scale_rotation_translation(Vec3::splat(3.0), turn, Vec3::new(6.0, 0.0, 0.0));
        let mut base = Base::default();
        base.rigid(&rest, &[Vec3::X; 3], &world_from_model);
        assert!(base.normals.iter().all(|n| n.distance(turn * Vec3::X) < 1e-5), "{:?}", base.normals);
        assert!((base.scale - 3.0).abs() < 1e-5);
        for (p, q) in rest.iter().zip(&base.positions) {
            let world = world_from_model.transform_point3(*p);
            assert!(base.world_from_simulation().transform_point3(*q).distance(world) < 1e-5);
        }
        assert!(base.rotations.iter().all(|r| r.angle_between(turn) < 1e-4));
        // Strands keep their length relative to the body: one model unit is one simulation unit.
        assert!((base.positions[1].distance(base.positions[0]) - 1.0).abs() < 1e-5);
    }

    #[test]
    fn a_singular_transform_does_not_make_nan() {
        let mut base = Base::default();
        base.rigid(&[Vec3::ONE], &[Vec3::Y], &Affine3A::from_scale(Vec3::ZERO));
        assert!(base.scale == 1.0 && base.positions[0].is_finite() && base.rotations[0].is_finite());
        assert!(base.normals[0].is_finite());
    }
}
