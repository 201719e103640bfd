//! A skinned body as capsules, one per bone, for the fur to collide with.
//!
//! Each capsule is fitted once, in the bind pose, to the vertices its joint moves most, and
//! posed every frame by that joint's skinning matrix: two points transformed per bone, so the
//! colliders follow the skinned body exactly where it moves rigidly with a bone, at no cost per
//! body vertex. A signed distance field ([`super::MeshSdf`]) would have to be rebaked (or
//! deformed) every frame for a skinned body; it serves plain, rigid meshes instead.

use glam::{Mat4, Vec3};

use crate::anim::{Pose, Rig};
use crate::mesh::Mesh;

/// Fewest vertices a joint needs for a capsule of its own.
const MIN_VERTICES: usize = 8;

/// One capsule: the points within `radius` of the segment `a`-`b`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Capsule {
    /// One end of the segment.
    pub a: Vec3,
    /// The other end.
    pub b: Vec3,
    /// Radius.
    pub radius: f32,
}

impl Capsule {
    /// Signed distance from `p` to the capsule's surface (negative inside).
    #[must_use]
    pub fn distance(&self, p: Vec3) -> f32 {
        let ab = self.b - self.a;
        let length_squared = ab.length_squared();
        let t = if length_squared > 0.0 { ((p - self.a).dot(ab) / length_squared).clamp(0.0, 1.0) } else { 0.0 };
        p.distance(self.a + ab * t) - self.radius
    }
}

/// One bone's capsule in the bind pose and the joint that moves it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BoneCapsule {
    /// The rig's palette joint ([`Rig::joint_matrices`]).
    pub joint: usize,
    /// The capsule in the bind pose.
    pub rest: Capsule,
    /// Vertices it was fitted to.
    pub vertices: usize,
    /// The largest gap between a fitted vertex and the capsule's surface, either side.
    pub fit_error: f32,
}

/// A skinned body's capsules, posed with its rig.
#[derive(Clone, Debug, PartialEq)]
pub struct BodyCapsules {
    /// One per joint that moves at least a few vertices most, in joint order.
    pub bones: Vec<BoneCapsule>,
}

impl BodyCapsules {
    /// Fits a capsule per joint to the bind-pose vertices whose heaviest weight is that joint's
    /// (at least 0.5): the segment runs along the vertices' principal axis, the radius is the
    /// median distance from it, and the segment is shortened by the radius at both ends so the
    /// caps end where the vertices do.
    #[must_use]
    pub fn fit(body: &Mesh, rig: &Rig) -> Self {
        let influences = rig.influences();
        let mut groups: Vec<Vec<Vec3>> = vec![Vec::new(); rig.joint_count()];
        for (p, inf) in body.positions.iter().zip(influences) {
            let k = (0..4).max_by(|&i, &j| inf.weights[i].total_cmp(&inf.weights[j]).then(j.cmp(&i))).unwrap_or(0);
            if inf.weights[k] >= 0.5
                && let Some(group) = groups.get_mut(inf.joints[k] as usize)
            {
                group.push(*p);
            }
        }
        let bones = groups
            .iter()
            .enumerate()
            .filter(|(_, points)| points.len() >= MIN_VERTICES)
            .map(|(joint, points)| fit_one(joint, points))
            .collect();
        Self { bones }
    }

    /// Shrinks every capsule that holds one of `points` (bind pose) until none lies within
    /// `margin` of it, and returns how many shrank. A capsule's radius is the median of its
    /// vertices' distances, so it bulges out of the body where the body is thinner; a garment
    /// on the body (the try-on's skirt) would have fur rooted inside it, which no collision
    /// response can free.
    pub fn clear_of(&mut self, points: &[Vec3], margin: f32) -> usize {
        let mut shrunk = 0;
        for bone in &mut self.bones {
            let rest = bone.rest;
            let axis = rest.b - rest.a;
            let nearest = points
                .iter()
                .map(|&p| {
                    let t = if axis.length_squared() > 0.0 {
                        ((p - rest.a).dot(axis) / axis.length_squared()).clamp(0.0, 1.0)
                    } else {
                        0.0
                    };
                    p.distance(rest.a + axis * t)
                })
                .fold(f32::INFINITY, f32::min);
            let radius = (nearest - margin).max(f32::MIN_POSITIVE);
            if radius < rest.radius {
                bone.rest.radius = radius;
                shrunk += 1;
            }
        }
        shrunk
    }

    /// The capsules in `pose` (which [`Rig::pose`] filled for the body), in the space the pose
    /// is in; `world_from_model` places them (the script's motion) and must be rigid.
    #[must_use]
    pub fn posed(&self, rig: &Rig, pose: &Pose, world_from_model: Mat4) -> Vec<Capsule> {
        let matrices = rig.joint_matrices(pose);
        self.bones
            .iter()
            .map(|bone| {
                let m = world_from_model * matrices[bone.joint];
                // A skinning matrix with scale scales the capsule's radius by its mean.
                let scale =
                    (m.x_axis.truncate().length() + m.y_axis.truncate().length() + m.z_axis.truncate().length()) / 3.0;
                Capsule {
                    a: m.transform_point3(bone.rest.a),
                    b: m.transform_point3(bone.rest.b),
                    radius: bone.rest.radius * scale,
                }
            })
            .collect()
    }
}

fn fit_one(joint: usize, points: &[Vec3]) -> BoneCapsule {
    let n = points.len() as f32;
    let centre = points.iter().copied().sum::<Vec3>() / n;
    // The covariance's principal axis by power iteration, from a fixed start: deterministic.
    let mut covariance = [[0.0_f32; 3]; 3];
    for p in points {
        let d = (*p - centre).to_array();
        for (row, &di) in covariance.iter_mut().zip(&d) {
            for (c, &dj) in row.iter_mut().zip(&d) {
                *c += di * dj;
            }
        }
    }
    let m = glam::Mat3::from_cols_array_2d(&covariance);
    let mut axis = Vec3::new(0.577, 0.578, 0.579);
    for _ in 0..64 {
        axis = (m * axis).try_normalize().unwrap_or(Vec3::Y);
    }
    let along = |p: Vec3| (p - centre).dot(axis);
    let (lo, hi) =
        points.iter().fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &p| (lo.min(along(p)), hi.max(along(p))));
    let mut radial: Vec<f32> = points.iter().map(|&p| (p - centre - axis * along(p)).length()).collect();
    radial.sort_by(f32::total_cmp);
    let radius = radial[radial.len() / 2].max(f32::MIN_POSITIVE);
    let (a, b) = if hi - lo > 2.0 * radius {
        (centre + axis * (lo + radius), centre + axis * (hi - radius))
    } else {
        let middle = centre + axis * (0.5 * (lo + hi));
        (middle, middle)
    };
    let rest = Capsule { a, b, radius };
    let fit_error = points.iter().map(|&p| rest.distance(p).abs()).fold(0.0, f32::max);
    BoneCapsule { joint, rest, vertices: points.len(), fit_error }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::walking_try_on;
    use crate::mesh::ImportOptions;

    #[test]
    fn capsules_follow_the_bones_exactly_as_skinning_moves_rigid_vertices() {
        let scene = walking_try_on(&ImportOptions::default()).unwrap();
        let (body, rig, capsules) = (&scene.body, &scene.body_rig, &scene.capsules);
        assert!(capsules.bones.len() >= 15, "{} capsules", capsules.bones.len());
        let world = Mat4::from_rotation_y(0.7) * Mat4::from_translation(Vec3::new(1.0, 0.0, -2.0));
        let mut pose = Pose::default();
        let mut checked = 0;
        for k in 0..6 {
            let t = 0.3 * f64::from(k);
            rig.pose(body, Some(0), t, &mut pose);
            let posed = capsules.posed(rig, &pose, world);
            for (bone, capsule) in capsules.bones.iter().zip(&posed) {
                // Vertices the joint alone moves keep their distance to its capsule in every pose:
                // the oracle is the skinned vertex itself, not the capsule's transform.
                for (v, inf) in rig.influences().iter().enumerate() {
                    if inf.joints[0] as usize == bone.joint && inf.weights[0] == 1.0 {
                        let rest = bone.rest.distance(body.positions[v]);
                        let now = capsule.distance(world.transform_point3(pose.positions[v]));
                        assert!((rest - now).abs() < 1e-4, "joint {} vertex {v} at {t} s: {rest} vs {now}", bone.joint);
                        checked += 1;
                    }
                }
            }
        }
        assert!(checked > 100, "{checked} rigid vertices checked");
    }

    #[test]
    fn each_capsule_hugs_the_vertices_it_was_fitted_to() {
        let scene = walking_try_on(&ImportOptions::default()).unwrap();
        let (body, rig) = (&scene.body, &scene.body_rig);
        for bone in &scene.capsules.bones {
            let mut gaps: Vec<f32> = rig
                .influences()
                .iter()
                .enumerate()
                .filter(|(_, inf)| inf.joints[0] as usize == bone.joint && inf.weights[0] >= 0.9)
                .map(|(v, _)| bone.rest.distance(body.positions[v]).abs())
                .collect();
            if gaps.len() < 8 {
                continue;
            }
            gaps.sort_by(f32::total_cmp);
            let median = gaps[gaps.len() / 2];
            assert!(
                median <= 0.5 * bone.rest.radius,
                "joint {}: median gap {median}, radius {}",
                bone.joint,
                bone.rest.radius
            );
            assert!(bone.rest.radius.is_finite() && bone.rest.radius > 0.0 && bone.fit_error.is_finite());
        }
    }
}
