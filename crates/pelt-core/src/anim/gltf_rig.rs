//! Reads a glTF document's nodes, skins, morph targets and animations into a [`Rig`], per raw
//! vertex first ([`RawRig`]) and then per base vertex of the repaired mesh ([`RawRig::finish`]).

use std::collections::HashMap;

use glam::{Mat3, Mat4, Quat, Vec3};
use gltf::animation::util::ReadOutputs;

use crate::mesh::gltf::Span;

use super::{
    Animation, Channel, Influences, Interpolation, MorphSet, PaletteJoint, Property, Rig, RigNode, Sampler,
    SkinSummary, Trs,
};

/// Morph targets of one primitive, dense over its raw vertices.
#[derive(Clone, Debug)]
struct RawMorphSet {
    node: usize,
    first_vertex: u32,
    /// Per target, position and normal deltas per vertex of the primitive.
    targets: Vec<(Vec<Vec3>, Vec<Vec3>)>,
}

/// A rig over the raw (unwelded) vertices.
#[derive(Clone, Debug)]
pub(super) struct RawRig {
    nodes: Vec<RigNode>,
    order: Vec<usize>,
    skins: Vec<SkinSummary>,
    palette: Vec<PaletteJoint>,
    influences: Vec<Influences>,
    morphs: Vec<RawMorphSet>,
    animations: Vec<Animation>,
    report: Vec<String>,
}

impl RawRig {
    /// Lines the rig up with the repaired mesh: `source[j]` is the raw vertex base vertex `j`
    /// was taken from.
    pub(super) fn finish(self, source: &[u32]) -> Rig {
        let influences = source.iter().map(|&i| self.influences[i as usize]).collect();
        let mut morphs = Vec::new();
        for set in self.morphs {
            let range = set.first_vertex..set.first_vertex + set.targets.first().map_or(0, |t| t.0.len() as u32);
            let targets = set
                .targets
                .iter()
                .map(|(dp, dn)| {
                    source
                        .iter()
                        .enumerate()
                        .filter(|(_, i)| range.contains(i))
                        .map(|(j, &i)| {
                            let k = (i - set.first_vertex) as usize;
                            (j as u32, dp[k], dn[k])
                        })
                        .filter(|(_, p, n)| *p != Vec3::ZERO || *n != Vec3::ZERO)
                        .collect()
                })
                .collect();
            morphs.push(MorphSet { node: set.node, targets });
        }
        Rig {
            nodes: self.nodes,
            order: self.order,
            skins: self.skins,
            palette: self.palette,
            influences,
            morphs,
            animations: self.animations,
            report: self.report,
        }
    }
}

/// Reads the rig of `document` for the raw mesh made of `spans` (`vertex_count` vertices).
/// `None` when nothing in the file moves (no skins, animations or morph targets).
///
/// # Errors
/// A message for accessors that cannot be read at all.
pub(super) fn read_rig(
    document: &gltf::Document,
    buffers: &[gltf::buffer::Data],
    spans: &[Span],
    vertex_count: usize,
) -> Result<Option<RawRig>, String> {
    let has_morphs = document.meshes().any(|m| m.primitives().any(|p| p.morph_targets().len() > 0));
    if document.skins().len() == 0 && document.animations().len() == 0 && !has_morphs {
        return Ok(None);
    }
    let get = |buffer: gltf::Buffer| buffers.get(buffer.index()).map(|data| &data.0[..]);
    let mut report = Vec::new();
    let (nodes, order) = read_nodes(document, &mut report);

    let mut palette = Vec::new();
    let mut skin_offsets: HashMap<usize, u32> = HashMap::new();
    let mut rigid_entries: HashMap<Option<usize>, u32> = HashMap::new();
    let mut influences = vec![Influences { joints: [0; 4], weights: [1.0, 0.0, 0.0, 0.0] }; vertex_count];
    let mut counts = InfluenceCounts::default();
    let mut morphs = Vec::new();
    for span in spans {
        let mesh = document.meshes().nth(span.mesh).ok_or("a span names a missing mesh")?;
        let primitive = mesh.primitives().nth(span.primitive).ok_or("a span names a missing primitive")?;
        let name = || format!("mesh {} ({:?}) primitive {}", span.mesh, mesh.name().unwrap_or(""), span.primitive);
        let reader = primitive.reader(get);
        let range = span.first_vertex as usize..(span.first_vertex + span.count) as usize;
        let skin = span.skin.and_then(|s| document.skins().nth(s));
        let joints0 = reader.read_joints(0).map(|j| j.into_u16().collect::<Vec<_>>());
        let weights0 = reader.read_weights(0).map(|w| w.into_f32().collect::<Vec<_>>());
        match (skin, joints0, weights0) {
            (Some(skin), Some(joints0), Some(weights0)) => {
                let offset = *skin_offsets.entry(skin.index()).or_insert_with(|| {
                    let offset = palette.len() as u32;
                    push_skin(&skin, buffers, &mut palette, &mut report);
                    offset
                });
                let joint_count = skin.joints().len();
                let sets = [
                    Some((joints0, weights0)),
                    reader
                        .read_joints(1)
                        .map(|j| j.into_u16().collect())
                        .zip(reader.read_weights(1).map(|w| w.into_f32().collect::<Vec<_>>())),
                ];
                for (k, v) in range.clone().enumerate() {
                    let pairs =
                        sets.iter().flatten().filter(|(j, w)| j.len() > k && w.len() > k).flat_map(|(j, w)| {
                            j[k].iter().zip(w[k]).map(|(&joint, weight)| (u32::from(joint), weight))
                        });
                    influences[v] = normalise(pairs, joint_count, offset, &mut counts);
                }
                if sets.iter().flatten().any(|(j, w)| j.len() < range.len() || w.len() < range.len()) {
                    report.push(format!(
                        "{}: JOINTS/WEIGHTS shorter than POSITION; missing vertices bound to joint 0",
                        name()
                    ));
                }
            }
            (Some(_), _, _) => {
                report.push(format!(
                    "{}: its node has a skin but it has no JOINTS_0/WEIGHTS_0; it keeps its bind pose",
                    name()
                ));
                let entry = rigid_entry(None, Mat4::IDENTITY, &mut rigid_entries, &mut palette);
                influences[range.clone()].fill(Influences { joints: [entry; 4], weights: [1.0, 0.0, 0.0, 0.0] });
            }
            (None, _, _) => {
                let entry = rigid_entry(span.node, span.world_from_local, &mut rigid_entries, &mut palette);
                influences[range.clone()].fill(Influences { joints: [entry; 4], weights: [1.0, 0.0, 0.0, 0.0] });
            }
        }
        if let (Some(node), true) = (span.node, primitive.morph_targets().len() > 0) {
            let linear = Mat3::from_mat4(span.world_from_local);
            let normal = linear.inverse().transpose();
            let count = span.count as usize;
            let targets = reader
                .read_morph_targets()
                .map(|(positions, normals, _)| {
                    let mut dp: Vec<Vec3> =
                        positions.map_or_else(Vec::new, |p| p.map(|d| linear * Vec3::from(d)).collect());
                    let mut dn: Vec<Vec3> =
                        normals.map_or_else(Vec::new, |n| n.map(|d| normal * Vec3::from(d)).collect());
                    for deltas in [&mut dp, &mut dn] {
                        if deltas.iter().any(|d| !d.is_finite()) {
                            counts.non_finite_morph_targets += 1;
                            deltas.clear();
                        }
                        deltas.resize(count, Vec3::ZERO);
                    }
                    (dp, dn)
                })
                .collect();
            morphs.push(RawMorphSet { node, first_vertex: span.first_vertex, targets });
        }
    }
    counts.report(&mut report);
    let skins =
        document.skins().map(|s| SkinSummary { name: s.name().map(str::to_owned), joints: s.joints().len() }).collect();
    let animations = read_animations(document, get, &nodes, &mut report);
    Ok(Some(RawRig { nodes, order, skins, palette, influences, morphs, animations, report }))
}

/// Every node with its parent and rest transform, and an order with parents first. A node in a
/// parent cycle (invalid glTF) becomes a root, reported.
fn read_nodes(document: &gltf::Document, report: &mut Vec<String>) -> (Vec<RigNode>, Vec<usize>) {
    let mut parent = vec![None; document.nodes().len()];
    for node in document.nodes() {
        for child in node.children() {
            parent[child.index()] = Some(node.index());
        }
    }
    let nodes: Vec<RigNode> = document
        .nodes()
        .map(|node| {
            let (t, r, s) = node.transform().decomposed();
            let morph_targets = node.mesh().and_then(|m| m.primitives().next()).map_or(0, |p| p.morph_targets().len());
            let mut rest_weights = node
                .weights()
                .or_else(|| node.mesh().and_then(|m| m.weights()))
                .map(<[f32]>::to_vec)
                .unwrap_or_default();
            rest_weights.resize(morph_targets, 0.0);
            RigNode {
                name: node.name().map(str::to_owned),
                parent: parent[node.index()],
                rest: Trs {
                    translation: Vec3::from(t),
                    rotation: unit_rotation(Quat::from_array(r)),
                    scale: Vec3::from(s),
                },
                rest_matrix: Some(Mat4::from_cols_array_2d(&node.transform().matrix())),
                rest_weights,
            }
        })
        .collect();
    let mut nodes = nodes;
    let mut order: Vec<usize> = (0..nodes.len()).filter(|&n| nodes[n].parent.is_none()).collect();
    let mut next = 0;
    let children: Vec<Vec<usize>> = document.nodes().map(|n| n.children().map(|c| c.index()).collect()).collect();
    let mut placed = vec![false; nodes.len()];
    for &n in &order {
        placed[n] = true;
    }
    while next < order.len() {
        let n = order[next];
        next += 1;
        for &c in &children[n] {
            if !placed[c] && nodes[c].parent == Some(n) {
                placed[c] = true;
                order.push(c);
            }
        }
    }
    for n in 0..nodes.len() {
        if !placed[n] {
            report.push(format!("node {n} is in a parent cycle (invalid glTF); it is treated as a root"));
            nodes[n].parent = None;
            placed[n] = true;
            order.push(n);
        }
    }
    (nodes, order)
}

/// `q` normalised; the identity for a zero or non-finite one.
fn unit_rotation(q: Quat) -> Quat {
    if q.is_finite() && q.length_squared() > 0.0 { q.normalize() } else { Quat::IDENTITY }
}

/// Adds a skin's joints to the palette; missing inverse bind matrices are the identity
/// (reported), as the spec says.
fn push_skin(
    skin: &gltf::Skin<'_>,
    buffers: &[gltf::buffer::Data],
    palette: &mut Vec<PaletteJoint>,
    report: &mut Vec<String>,
) {
    let get = |buffer: gltf::Buffer| buffers.get(buffer.index()).map(|data| &data.0[..]);
    let name = format!("skin {} ({:?})", skin.index(), skin.name().unwrap_or(""));
    let joints: Vec<usize> = skin.joints().map(|j| j.index()).collect();
    let matrices: Option<Vec<Mat4>> =
        skin.reader(get).read_inverse_bind_matrices().map(|m| m.map(|c| Mat4::from_cols_array_2d(&c)).collect());
    let matrices = match matrices {
        None => {
            report.push(format!("{name}: no inverse bind matrices; identity used"));
            vec![Mat4::IDENTITY; joints.len()]
        }
        Some(m) if m.len() < joints.len() || m.iter().any(|m| !m.is_finite()) => {
            report.push(format!(
                "{name}: {} inverse bind matrices for {} joints, or non-finite ones; identity used",
                m.len(),
                joints.len()
            ));
            vec![Mat4::IDENTITY; joints.len()]
        }
        Some(m) => m,
    };
    if joints.is_empty() {
        report.push(format!("{name}: no joints; its vertices keep their bind pose"));
        palette.push(PaletteJoint { node: None, inverse_bind: Mat4::IDENTITY });
    }
    palette.extend(
        joints.iter().zip(matrices).map(|(&node, inverse_bind)| PaletteJoint { node: Some(node), inverse_bind }),
    );
}

fn rigid_entry(
    node: Option<usize>,
    world_from_local: Mat4,
    entries: &mut HashMap<Option<usize>, u32>,
    palette: &mut Vec<PaletteJoint>,
) -> u32 {
    *entries.entry(node).or_insert_with(|| {
        palette.push(PaletteJoint {
            node,
            inverse_bind: if node.is_some() { world_from_local.inverse() } else { Mat4::IDENTITY },
        });
        palette.len() as u32 - 1
    })
}

/// What was repaired in the influences, for one report line each.
#[derive(Debug, Default)]
pub(super) struct InfluenceCounts {
    over_four: usize,
    zero_sum: usize,
    out_of_range: usize,
    bad_weights: usize,
    non_finite_morph_targets: usize,
}

impl InfluenceCounts {
    pub(super) fn report(&self, report: &mut Vec<String>) {
        if self.over_four > 0 {
            report.push(format!(
                "{} vertices have more than 4 influences: the 4 largest kept, renormalised",
                self.over_four
            ));
        }
        if self.out_of_range > 0 {
            report.push(format!("{} influences name a joint past the skin's joints: dropped", self.out_of_range));
        }
        if self.bad_weights > 0 {
            report.push(format!("{} weights are negative or not finite: dropped", self.bad_weights));
        }
        if self.zero_sum > 0 {
            report.push(format!(
                "{} vertices have weights that sum to 0: bound to the skin's first joint",
                self.zero_sum
            ));
        }
        if self.non_finite_morph_targets > 0 {
            report.push(format!(
                "{} morph target attributes have non-finite deltas: ignored",
                self.non_finite_morph_targets
            ));
        }
    }
}

/// The four largest valid influences, weights summing to 1, joints offset into the palette.
pub(super) fn normalise(
    pairs: impl Iterator<Item = (u32, f32)>,
    joint_count: usize,
    offset: u32,
    counts: &mut InfluenceCounts,
) -> Influences {
    let mut kept: Vec<(u32, f32)> = Vec::with_capacity(8);
    for (joint, weight) in pairs {
        if weight == 0.0 {
            continue;
        }
        if !(weight.is_finite() && weight > 0.0) {
            counts.bad_weights += 1;
        } else if joint as usize >= joint_count {
            counts.out_of_range += 1;
        } else if let Some(k) = kept.iter_mut().find(|(j, _)| *j == joint) {
            k.1 += weight;
        } else {
            kept.push((joint, weight));
        }
    }
    if kept.len() > 4 {
        counts.over_four += 1;
        kept.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
        kept.truncate(4);
    }
    let sum: f32 = kept.iter().map(|(_, w)| w).sum();
    let mut out = Influences { joints: [offset; 4], weights: [0.0; 4] };
    if !(sum > 0.0 && sum.is_finite()) {
        counts.zero_sum += 1;
        out.weights[0] = 1.0;
        return out;
    }
    for (k, (joint, weight)) in kept.into_iter().enumerate() {
        out.joints[k] = offset + joint;
        out.weights[k] = weight / sum;
    }
    out
}

fn read_animations<'a, 's, F>(
    document: &'a gltf::Document,
    get: F,
    nodes: &[RigNode],
    report: &mut Vec<String>,
) -> Vec<Animation>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let mut animations = Vec::new();
    for animation in document.animations() {
        let name = animation.name().map(str::to_owned);
        let mut channels = Vec::new();
        for channel in animation.channels() {
            let label = || {
                format!(
                    "animation {} ({:?}) channel {}",
                    animation.index(),
                    animation.name().unwrap_or(""),
                    channel.index()
                )
            };
            // gltf 1.4 does not check a channel's target node and panics on a missing one.
            let json = &document.as_json().animations[animation.index()].channels[channel.index()];
            let node = json.target.node.value();
            if node >= nodes.len() {
                report.push(format!("{}: it targets node {node}, which does not exist; channel dropped", label()));
                continue;
            }
            match read_channel(&channel, get.clone(), nodes) {
                Ok(c) => channels.push(c),
                Err(problem) => report.push(format!("{}: {problem}; channel dropped", label())),
            }
        }
        let start_secs = channels.iter().map(|c| c.sampler.time_range().0).fold(f32::INFINITY, f32::min);
        let end_secs = channels.iter().map(|c| c.sampler.time_range().1).fold(f32::NEG_INFINITY, f32::max);
        let (start_secs, end_secs) = if channels.is_empty() { (0.0, 0.0) } else { (start_secs, end_secs) };
        animations.push(Animation { name, channels, start_secs, end_secs });
    }
    animations
}

fn read_channel<'a, 's, F>(channel: &gltf::animation::Channel<'a>, get: F, nodes: &[RigNode]) -> Result<Channel, String>
where
    F: Clone + Fn(gltf::Buffer<'a>) -> Option<&'s [u8]>,
{
    let node = channel.target().node().index();
    if node >= nodes.len() {
        return Err(format!("it targets node {node}, which does not exist"));
    }
    let interpolation = match channel.sampler().interpolation() {
        gltf::animation::Interpolation::Linear => Interpolation::Linear,
        gltf::animation::Interpolation::Step => Interpolation::Step,
        gltf::animation::Interpolation::CubicSpline => Interpolation::CubicSpline,
    };
    let reader = channel.reader(get);
    let times: Vec<f32> = reader.read_inputs().ok_or("its key times cannot be read")?.collect();
    let outputs = reader.read_outputs().ok_or("its key values cannot be read")?;
    let (property, values, width): (Property, Vec<f32>, usize) = match outputs {
        ReadOutputs::Translations(t) => (Property::Translation, t.flatten().collect(), 3),
        ReadOutputs::Rotations(r) => (Property::Rotation, r.into_f32().flatten().collect(), 4),
        ReadOutputs::Scales(s) => (Property::Scale, s.flatten().collect(), 3),
        ReadOutputs::MorphTargetWeights(w) => {
            let targets = nodes[node].rest_weights.len();
            if targets == 0 {
                return Err(format!("it drives morph weights of node {node}, which has no morph targets"));
            }
            (Property::Weights, w.into_f32().collect(), targets)
        }
    };
    let sampler = Sampler { interpolation, times, values, width };
    sampler.validate()?;
    Ok(Channel { node, property, sampler })
}
