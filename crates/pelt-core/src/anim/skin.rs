//! Linear blend skinning of positions, normals and the fur's frames, in parallel over vertices.

use glam::{Affine3A, Mat3, Mat4, Quat, Vec3};
use rayon::prelude::*;

use super::{Influences, Pose, normal_matrix};

/// Vertices per parallel task: enough to pay for the task.
const VERTICES_PER_TASK: usize = 512;

/// One palette joint's transform this frame: `world(joint) * inverse_bind`, its normal matrix
/// and its rotation.
#[derive(Clone, Copy, Debug)]
pub(super) struct JointTransform {
    matrix: Affine3A,
    normal: Mat3,
    rotation: Quat,
}

impl JointTransform {
    pub(super) fn new(matrix: Mat4) -> Self {
        let (scale, rotation, _) = matrix.to_scale_rotation_translation();
        let rotation = if scale.abs().min_element() > f32::MIN_POSITIVE && rotation.is_finite() {
            rotation.normalize()
        } else {
            Quat::IDENTITY
        };
        Self { matrix: Affine3A::from_mat4(matrix), normal: normal_matrix(matrix), rotation }
    }
}

/// Skins `morphed` (rest positions and normals with morph targets added) into `pose`;
/// `rest_normals` are the fur's rest normals, which the per-vertex rotations start from.
pub(super) fn blend(
    joints: &[JointTransform],
    influences: &[Influences],
    morphed: &[(Vec3, Vec3)],
    rest_normals: &[Vec3],
    pose: &mut Pose,
) {
    let v = influences.len();
    pose.positions.resize(v, Vec3::ZERO);
    pose.normals.resize(v, Vec3::ZERO);
    pose.rotations.resize(v, Quat::IDENTITY);
    pose.positions
        .par_iter_mut()
        .zip(pose.normals.par_iter_mut())
        .zip(pose.rotations.par_iter_mut())
        .enumerate()
        .with_min_len(VERTICES_PER_TASK)
        .for_each(|(j, ((position, normal), rotation))| {
            let (p, n) = morphed[j];
            let inf = &influences[j];
            let mut blended_p = Vec3::ZERO;
            let mut blended_n = Vec3::ZERO;
            let mut blended_q = glam::Vec4::ZERO;
            let first = joints[inf.joints[0] as usize].rotation;
            for (&joint, &weight) in inf.joints.iter().zip(&inf.weights) {
                if weight == 0.0 {
                    continue;
                }
                let joint = &joints[joint as usize];
                blended_p += joint.matrix.transform_point3(p) * weight;
                blended_n += joint.normal * n * weight;
                // Quaternions q and -q are one rotation: blend on the first joint's side.
                let q = glam::Vec4::from(joint.rotation);
                let sign = if q.dot(glam::Vec4::from(first)) < 0.0 { -1.0 } else { 1.0 };
                blended_q += q * (weight * sign);
            }
            let q = blended_q.try_normalize().map_or(Quat::IDENTITY, Quat::from_vec4);
            let turned_rest = q * rest_normals[j];
            let n = blended_n.try_normalize().unwrap_or(turned_rest);
            *position = blended_p;
            *normal = n;
            // The blended rotation, corrected so it takes the rest normal exactly onto the posed
            // normal (morph targets and blending bend normals a little away from it).
            *rotation = match turned_rest.try_normalize() {
                Some(turned) => (Quat::from_rotation_arc(turned, n) * q).normalize(),
                None => q,
            };
        });
}
