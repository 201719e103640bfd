//! Morph targets on the fur: the source's own (each strand carried by its root's displacement),
//! or a simulated loop of wind (one target per sampled frame, crossfaded in turn by a weights
//! animation), so the fur moves in players that cannot skin or simulate it.

use glam::Vec3;
use serde_json::{Value, json};

use super::ExportError;
use super::document::Document;

/// Morph targets written on every fur primitive, and what drives their weights.
#[derive(Clone, Debug)]
pub struct FurMorphs {
    /// Per target, a position delta for every node of the shared array (`(L + 1) * V`), in the
    /// space of [`super::ExportInput::positions`].
    pub targets: Vec<Vec<Vec3>>,
    /// The fur mesh's default weights (none: all zero).
    pub weights: Vec<f32>,
    /// What drives the weights.
    pub animation: MorphAnimation,
}

/// What drives the fur's morph weights.
#[derive(Clone, Debug, PartialEq)]
pub enum MorphAnimation {
    /// The source's animations: every channel driving the weights of this node of the source
    /// drives the fur's too (the fur's targets are that node's, in order).
    FollowNode(usize),
    /// A new looping animation: target `k` at `k * period / n`, crossfading linearly into the
    /// next, the last back into the first at `period_secs`.
    Loop {
        /// The animation's name.
        name: String,
        /// Its length in seconds.
        period_secs: f32,
    },
}

/// Per-base-vertex deltas (a root's displacement) carried up every node of its strand: the
/// shared-array target of a fur whose strands ride rigidly on their roots.
#[must_use]
pub fn carried_up(deltas: &[Vec3], layers: u32) -> Vec<Vec3> {
    let mut out = Vec::with_capacity(deltas.len() * (layers as usize + 1));
    for _ in 0..=layers {
        out.extend_from_slice(deltas);
    }
    out
}

impl FurMorphs {
    /// Checks the targets against the shared array's size and the animation's values.
    pub(super) fn check(&self, nodes: usize) -> Result<(), ExportError> {
        let bad = |problem: String| Err(ExportError::Input(problem));
        if self.targets.is_empty() {
            return bad("morph targets: none given".to_owned());
        }
        if let Some(target) = self.targets.iter().find(|t| t.len() != nodes) {
            return bad(format!("a morph target of {} deltas for {nodes} nodes", target.len()));
        }
        if self.targets.iter().flatten().any(|d| !d.is_finite()) {
            return bad("a morph target with a non-finite delta".to_owned());
        }
        if !self.weights.is_empty() && self.weights.len() != self.targets.len() {
            return bad(format!("{} morph weights for {} targets", self.weights.len(), self.targets.len()));
        }
        if let MorphAnimation::Loop { period_secs, .. } = self.animation
            && !(period_secs.is_finite() && period_secs > 0.0 && self.targets.len() >= 2)
        {
            return bad(format!(
                "a morph loop needs a positive length and two targets, got {period_secs} s and {}",
                self.targets.len()
            ));
        }
        Ok(())
    }

    /// A primitive's `targets`: per target, the deltas of its vertices (`node` gives each
    /// vertex's index in the shared array).
    pub(super) fn primitive_targets(&self, document: &mut Document, nodes: &[usize]) -> Value {
        let targets: Vec<Value> = self
            .targets
            .iter()
            .map(|target| {
                let deltas: Vec<Vec3> = nodes.iter().map(|&k| target[k]).collect();
                json!({ "POSITION": document.vec3(&deltas, true) })
            })
            .collect();
        Value::Array(targets)
    }

    /// The animation channels driving the fur node `fur_node`'s weights.
    pub(super) fn animate(&self, document: &mut Document, fur_node: usize) {
        match &self.animation {
            MorphAnimation::FollowNode(node) => {
                let animations = document.root.get_mut("animations").and_then(Value::as_array_mut);
                for animation in animations.into_iter().flatten() {
                    let Some(channels) = animation.get_mut("channels").and_then(Value::as_array_mut) else { continue };
                    let followed: Vec<Value> = channels
                        .iter()
                        .filter(|c| {
                            c["target"]["node"].as_u64() == Some(*node as u64) && c["target"]["path"] == "weights"
                        })
                        .map(|c| json!({ "sampler": c["sampler"], "target": { "node": fur_node, "path": "weights" } }))
                        .collect();
                    channels.extend(followed);
                }
            }
            MorphAnimation::Loop { name, period_secs } => {
                let n = self.targets.len();
                let times: Vec<f32> = (0..=n).map(|k| k as f32 * period_secs / n as f32).collect();
                let weights: Vec<f32> =
                    (0..=n).flat_map(|k| (0..n).map(move |t| if t == k % n { 1.0 } else { 0.0 })).collect();
                let input = document.animation_floats(&times, true);
                let output = document.animation_floats(&weights, false);
                document.push(
                    "animations",
                    json!({
                        "name": name,
                        "samplers": [{ "input": input, "output": output, "interpolation": "LINEAR" }],
                        "channels": [{ "sampler": 0, "target": { "node": fur_node, "path": "weights" } }],
                    }),
                );
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn carried_up_repeats_the_roots() {
        let deltas = [Vec3::X, Vec3::Y];
        assert_eq!(carried_up(&deltas, 2), [Vec3::X, Vec3::Y, Vec3::X, Vec3::Y, Vec3::X, Vec3::Y]);
    }

    #[test]
    fn a_loop_needs_two_targets_and_a_length() {
        let morphs = |n: usize, period_secs: f32| FurMorphs {
            targets: vec![vec![Vec3::ZERO; 4]; n],
            weights: Vec::new(),
            animation: MorphAnimation::Loop { name: "m".to_owned(), period_secs },
        };
        assert!(morphs(2, 1.0).check(4).is_ok());
        assert!(morphs(1, 1.0).check(4).is_err());
        assert!(morphs(2, 0.0).check(4).is_err());
        assert!(morphs(2, f32::NAN).check(4).is_err());
        assert!(morphs(2, 1.0).check(5).is_err());
    }
}
