//! Moving characters: glTF node hierarchies, skins, morph targets and animations, sampled at any
//! time into a posed base mesh (positions, normals and each vertex's rotation) that the
//! simulation takes through [`Simulation::set_base_rotations`](crate::sim::Simulation::set_base_rotations).
//!
//! - [`sampler`]: LINEAR, STEP and CUBICSPLINE keys.
//! - [`Rig`]: what a glTF file says about how its mesh moves, per base vertex of the repaired
//!   [`Mesh`] (welding and repair are followed, so the rig lines up with the fur's vertices).
//! - [`Pose`]: one posed base, reused frame after frame.
//! - [`Skin`]: the same skinning with joint matrices a host computes (a game engine's skeleton).
//!
//! Per frame: each node's local transform is its rest TRS with the animation's channels over it
//! (time looped over the clip); world transforms parent first; every joint's matrix is
//! `world(joint) * inverse_bind`. Morph targets are added in the mesh's space first, then linear
//! blend skinning moves positions and normals (rayon over vertices). A mesh without a skin that
//! hangs under an animated node is skinned to that node with weight 1, so it moves rigidly; its
//! "inverse bind" is the inverse of the node's rest world transform, as the static import bakes
//! that transform in. So the rest pose reproduces the static mesh.

mod gltf_rig;
mod joints;
mod load;
pub mod sampler;
mod skin;

use glam::{Mat3, Mat4, Quat, Vec3};

pub use joints::{Skin, SkinError};
pub use sampler::{Interpolation, Sampler};

use crate::mesh::Mesh;
use sampler::ValueKind;

/// A node's rest transform: translation, rotation, scale (glTF's TRS).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trs {
    /// Translation.
    pub translation: Vec3,
    /// Unit rotation.
    pub rotation: Quat,
    /// Scale.
    pub scale: Vec3,
}

impl Trs {
    /// `T * R * S`.
    #[must_use]
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

/// One node of the glTF hierarchy.
#[derive(Clone, Debug, PartialEq)]
pub struct RigNode {
    /// Its name in the file.
    pub name: Option<String>,
    /// Its parent, if any.
    pub parent: Option<usize>,
    /// Its rest transform.
    pub rest: Trs,
    /// The rest matrix exactly as written, for a node given as a matrix (glTF animates only
    /// TRS nodes; using the matrix keeps the rest pose bit-identical to the static import).
    pub rest_matrix: Option<Mat4>,
    /// Rest morph target weights of the mesh on this node (empty without morph targets).
    pub rest_weights: Vec<f32>,
}

/// One skin, for reports.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinSummary {
    /// Its name in the file.
    pub name: Option<String>,
    /// Its joint count.
    pub joints: usize,
}

/// What an animation channel drives.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Property {
    /// The node's translation.
    Translation,
    /// The node's rotation.
    Rotation,
    /// The node's scale.
    Scale,
    /// The morph target weights of the node's mesh.
    Weights,
}

/// One animation channel: a sampler driving one property of one node.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// The node.
    pub node: usize,
    /// What it drives.
    pub property: Property,
    /// The keys.
    pub sampler: Sampler,
}

/// One animation clip.
#[derive(Clone, Debug, PartialEq)]
pub struct Animation {
    /// Its name in the file.
    pub name: Option<String>,
    /// Its channels (the valid ones: broken channels are dropped and reported).
    pub channels: Vec<Channel>,
    /// The earliest key time.
    pub start_secs: f32,
    /// The latest key time.
    pub end_secs: f32,
}

impl Animation {
    /// The clip's length in seconds (from its earliest to its latest key).
    #[must_use]
    pub fn duration_secs(&self) -> f32 {
        self.end_secs - self.start_secs
    }

    /// The clip time for `time_secs` since the clip began, looping.
    #[must_use]
    pub fn clip_time(&self, time_secs: f64) -> f32 {
        let duration = f64::from(self.duration_secs());
        if duration > 0.0 && time_secs.is_finite() {
            self.start_secs + time_secs.rem_euclid(duration) as f32
        } else {
            self.start_secs
        }
    }
}

/// A joint of the skinning palette: a node (none for the identity) and its inverse bind matrix.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct PaletteJoint {
    pub node: Option<usize>,
    pub inverse_bind: Mat4,
}

/// Up to four `(palette joint, weight)` pairs per vertex; weights sum to 1.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct Influences {
    pub joints: [u32; 4],
    pub weights: [f32; 4],
}

/// Morph targets of one mesh instance (a node with a mesh), in base-vertex indices.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct MorphSet {
    /// The node whose weights drive it.
    pub node: usize,
    /// Per target, `(base vertex, position delta, normal delta)` where either is non-zero.
    pub targets: Vec<Vec<(u32, Vec3, Vec3)>>,
}

/// How a glTF file's mesh moves: nodes, skins, morph targets and animations, lined up with the
/// base vertices of the repaired [`Mesh`].
#[derive(Clone, Debug, PartialEq)]
pub struct Rig {
    nodes: Vec<RigNode>,
    /// Node indices, every parent before its children.
    order: Vec<usize>,
    skins: Vec<SkinSummary>,
    palette: Vec<PaletteJoint>,
    influences: Vec<Influences>,
    morphs: Vec<MorphSet>,
    animations: Vec<Animation>,
    report: Vec<String>,
}

/// One posed base: positions, unit normals and the rotation of each vertex's frame from rest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Pose {
    /// Posed positions, one per base vertex.
    pub positions: Vec<Vec3>,
    /// Posed unit normals.
    pub normals: Vec<Vec3>,
    /// Per vertex, the rotation taking its rest normal (and the fur's rest frame) to the pose.
    pub rotations: Vec<Quat>,
    /// Scratch: morphed rest positions and normals.
    morphed: Vec<(Vec3, Vec3)>,
    local: Vec<Trs>,
    weights: Vec<Vec<f32>>,
    world: Vec<Mat4>,
}

impl Pose {
    /// The morph target weights of `node`'s mesh in this pose (empty for a node without them).
    #[must_use]
    pub fn morph_weights(&self, node: usize) -> &[f32] {
        self.weights.get(node).map_or(&[], Vec::as_slice)
    }
}

impl Rig {
    /// The nodes of the hierarchy.
    #[must_use]
    pub fn nodes(&self) -> &[RigNode] {
        &self.nodes
    }

    /// The skins.
    #[must_use]
    pub fn skins(&self) -> &[SkinSummary] {
        &self.skins
    }

    /// The animation clips.
    #[must_use]
    pub fn animations(&self) -> &[Animation] {
        &self.animations
    }

    /// Morph target count over every mesh instance.
    #[must_use]
    pub fn morph_target_count(&self) -> usize {
        self.morphs.iter().map(|m| m.targets.len()).sum()
    }

    /// The morph targets as whole-mesh position deltas (in the mesh's space, per target one per
    /// base vertex) and the node whose weights drive them; `None` without morph targets, or when
    /// they hang on more than one node or their primitives disagree on the target count (a single
    /// set of weights cannot drive them).
    #[must_use]
    pub fn morph_position_deltas(&self) -> Option<(usize, Vec<Vec<Vec3>>)> {
        let first = self.morphs.first()?;
        if self.morphs.iter().any(|m| m.node != first.node || m.targets.len() != first.targets.len()) {
            return None;
        }
        let mut targets = vec![vec![Vec3::ZERO; self.influences.len()]; first.targets.len()];
        for set in &self.morphs {
            for (deltas, target) in targets.iter_mut().zip(&set.targets) {
                for &(v, dp, _) in target {
                    if let Some(d) = deltas.get_mut(v as usize) {
                        *d += dp;
                    }
                }
            }
        }
        Some((first.node, targets))
    }

    /// What was wrong with the file's skins and animations and how it was handled, one line each.
    #[must_use]
    pub fn report(&self) -> &[String] {
        &self.report
    }

    /// Base vertices the rig was built for.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.influences.len()
    }

    /// Finds an animation by name, or by index written as a number.
    ///
    /// # Errors
    /// A message listing the animations there are.
    pub fn find_animation(&self, name_or_index: &str) -> Result<usize, String> {
        if let Some(k) = self.animations.iter().position(|a| a.name.as_deref() == Some(name_or_index)) {
            return Ok(k);
        }
        if let Ok(k) = name_or_index.parse::<usize>()
            && k < self.animations.len()
        {
            return Ok(k);
        }
        let names: Vec<String> = self
            .animations
            .iter()
            .enumerate()
            .map(|(k, a)| format!("{k}: {}", a.name.as_deref().unwrap_or("(unnamed)")))
            .collect();
        Err(if names.is_empty() {
            format!("no animation {name_or_index:?}: the file has no animations")
        } else {
            format!("no animation {name_or_index:?}; the file has {}", names.join(", "))
        })
    }

    /// Poses `mesh` (the repaired mesh this rig was read with) with `animation` at `time_secs`
    /// since the clip began (looping), or in the rest pose for `None`, into `pose`.
    ///
    /// # Panics
    /// If `mesh` has another vertex count than the rig, or `animation` is out of range.
    pub fn pose(&self, mesh: &Mesh, animation: Option<usize>, time_secs: f64, pose: &mut Pose) {
        assert_eq!(mesh.vertex_count(), self.influences.len(), "the rig belongs to another mesh");
        self.pose_joints(animation, time_secs, pose);
        let joints: Vec<skin::JointTransform> = self
            .palette
            .iter()
            .map(|joint| {
                skin::JointTransform::new(joint.node.map_or(Mat4::IDENTITY, |n| pose.world[n]) * joint.inverse_bind)
            })
            .collect();

        pose.morphed.clear();
        pose.morphed.extend(mesh.positions.iter().copied().zip(mesh.normals.iter().copied()));
        for set in &self.morphs {
            for (target, &weight) in set.targets.iter().zip(&pose.weights[set.node]) {
                if weight != 0.0 {
                    for &(v, dp, dn) in target {
                        let (p, n) = &mut pose.morphed[v as usize];
                        *p += dp * weight;
                        *n += dn * weight;
                    }
                }
            }
        }
        let morphed = std::mem::take(&mut pose.morphed);
        skin::blend(&joints, &self.influences, &morphed, &mesh.normals, pose);
        pose.morphed = morphed;
    }

    /// The part of [`Rig::pose`] before the vertices: `animation` sampled at `time_secs` and
    /// every node's world transform, so [`Rig::joint_matrices`] reads `pose`; its vertices are
    /// left as they were (for a GPU to skin, `pelt_render::GpuSkin`).
    ///
    /// # Panics
    /// If `animation` is out of range.
    pub fn pose_joints(&self, animation: Option<usize>, time_secs: f64, pose: &mut Pose) {
        pose.local.clear();
        pose.local.extend(self.nodes.iter().map(|n| n.rest));
        pose.weights.resize(self.nodes.len(), Vec::new());
        for (weights, node) in pose.weights.iter_mut().zip(&self.nodes) {
            weights.clone_from(&node.rest_weights);
        }
        let mut animated = vec![false; self.nodes.len()];
        if let Some(clip) = animation.map(|k| &self.animations[k]) {
            let t = clip.clip_time(time_secs);
            let mut value = Vec::new();
            for channel in &clip.channels {
                let kind = if channel.property == Property::Rotation { ValueKind::Rotation } else { ValueKind::Vector };
                value.resize(channel.sampler.width, 0.0);
                channel.sampler.sample(kind, t, &mut value);
                let local = &mut pose.local[channel.node];
                animated[channel.node] = true;
                match channel.property {
                    Property::Translation => local.translation = Vec3::from_slice(&value),
                    Property::Rotation => local.rotation = Quat::from_slice(&value),
                    Property::Scale => local.scale = Vec3::from_slice(&value),
                    Property::Weights => {
                        let weights = &mut pose.weights[channel.node];
                        weights.resize(value.len(), 0.0);
                        weights.copy_from_slice(&value);
                    }
                }
            }
        }
        pose.world.resize(self.nodes.len(), Mat4::IDENTITY);
        for &n in &self.order {
            let node = &self.nodes[n];
            let local = match node.rest_matrix {
                Some(matrix) if !animated[n] => matrix,
                _ => pose.local[n].matrix(),
            };
            pose.world[n] = node.parent.map_or(local, |p| pose.world[p] * local);
        }
    }
}

impl Rig {
    /// Each base vertex's influences as indices into a glTF skin whose joints are the nodes
    /// `skin_joints` (what an exported mesh bound to that skin carries as JOINTS_0/WEIGHTS_0).
    /// `None` when a vertex is moved by a node outside that skin (another skin, or a mesh
    /// hanging rigidly under an animated node).
    #[must_use]
    pub fn influences_in_skin(&self, skin_joints: &[usize]) -> Option<Vec<([u16; 4], [f32; 4])>> {
        let slot: Vec<Option<u16>> = self
            .palette
            .iter()
            .map(|joint| {
                let node = joint.node?;
                skin_joints.iter().position(|&n| n == node).and_then(|k| u16::try_from(k).ok())
            })
            .collect();
        self.influences
            .iter()
            .map(|inf| {
                let mut joints = [0_u16; 4];
                let mut weights = [0.0_f32; 4];
                for k in 0..4 {
                    if inf.weights[k] > 0.0 {
                        joints[k] = slot[inf.joints[k] as usize]?;
                        weights[k] = inf.weights[k];
                    }
                }
                Some((joints, weights))
            })
            .collect()
    }

    /// The linear blend skinning matrix of every base vertex in `pose`, which [`Rig::pose`]
    /// filled (morph targets not included): what takes a point riding on the vertex from the
    /// bind pose to the pose.
    #[must_use]
    pub fn vertex_matrices(&self, pose: &Pose) -> Vec<Mat4> {
        let joints: Vec<Mat4> = self
            .palette
            .iter()
            .map(|joint| {
                joint.node.and_then(|n| pose.world.get(n).copied()).unwrap_or(Mat4::IDENTITY) * joint.inverse_bind
            })
            .collect();
        self.influences
            .iter()
            .map(|inf| {
                inf.joints
                    .iter()
                    .zip(&inf.weights)
                    .filter(|(_, w)| **w != 0.0)
                    .fold(Mat4::ZERO, |sum, (&j, &w)| sum + joints[j as usize] * w)
            })
            .collect()
    }
}

impl Rig {
    /// Palette joints: the matrices [`Rig::joint_matrices`] returns, one per joint.
    #[must_use]
    pub fn joint_count(&self) -> usize {
        self.palette.len()
    }

    /// Each base vertex's four palette joints and their weights (unused slots weigh 0), as
    /// [`Rig::pose`] blends them: what a GPU skins the base with ([`Rig::joint_matrices`] per pose).
    #[must_use]
    pub fn vertex_influences(&self) -> Vec<([u32; 4], [f32; 4])> {
        self.influences.iter().map(|inf| (inf.joints, inf.weights)).collect()
    }

    /// The node a palette joint follows (`None` for a joint fixed at the identity).
    #[must_use]
    pub fn joint_node(&self, joint: usize) -> Option<usize> {
        self.palette.get(joint).and_then(|j| j.node)
    }

    /// Every palette joint's skinning matrix `world(joint) * inverse_bind` in `pose`, which
    /// [`Rig::pose`] filled: what takes a point that follows the joint from the bind pose to the pose.
    #[must_use]
    pub fn joint_matrices(&self, pose: &Pose) -> Vec<Mat4> {
        self.palette
            .iter()
            .map(|joint| {
                joint.node.and_then(|n| pose.world.get(n).copied()).unwrap_or(Mat4::IDENTITY) * joint.inverse_bind
            })
            .collect()
    }

    /// Turns the rig's whole world by `turn` (over every root node) and rebinds `mesh` (the
    /// mesh this rig was read with) to the turned rest pose: its positions and normals become
    /// that pose and every inverse bind matrix follows, so poses come out as before, turned, and
    /// the rest pose is the mesh itself. Exact when every joint's rest skinning matrix is the
    /// same (a bind pose that is the rest pose up to one transform, as a Z-up export's).
    pub(crate) fn rebind_at_rest(&mut self, mesh: &mut Mesh, turn: Mat4) {
        let mut pose = Pose::default();
        self.pose(mesh, None, 0.0, &mut pose);
        let rest = self.joint_matrices(&pose).first().copied().unwrap_or(Mat4::IDENTITY);
        for node in self.nodes.iter_mut().filter(|n| n.parent.is_none()) {
            let turned = turn * node.rest_matrix.unwrap_or_else(|| node.rest.matrix());
            let (scale, rotation, translation) = turned.to_scale_rotation_translation();
            node.rest = Trs { translation, rotation, scale };
            node.rest_matrix = node.rest_matrix.map(|_| turned);
        }
        let bind_from_old = turn * rest;
        mesh.transform(bind_from_old);
        let old_from_bind = bind_from_old.inverse();
        for joint in &mut self.palette {
            joint.inverse_bind *= old_from_bind;
        }
    }

    /// Each base vertex's joints and weights (palette indices; up to four, summing to 1).
    pub(crate) fn influences(&self) -> &[Influences] {
        &self.influences
    }

    /// This rig's skeleton and clips driving another mesh, whose vertices take `influences`
    /// (one per vertex). Morph targets belong to the old mesh's vertices and are left out.
    pub(crate) fn with_influences(&self, influences: Vec<Influences>) -> Self {
        Self { influences, morphs: Vec::new(), ..self.clone() }
    }
}

/// The normal matrix of `m`: the inverse transpose of its upper 3x3 (zero for a singular one).
fn normal_matrix(m: Mat4) -> Mat3 {
    let linear = Mat3::from_mat4(m);
    if linear.determinant().abs() > f32::MIN_POSITIVE { linear.inverse().transpose() } else { Mat3::ZERO }
}
