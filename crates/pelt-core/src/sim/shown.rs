//! What a host draws of the colliders: each one once, where and as large as it is at a time.

use super::contact::{Collider, StepCollider};
use super::simulation::Simulation;

impl Simulation {
    /// The colliders as they stand at `time_secs`, one each, for drawing: the grasp's hand first
    /// (its fingers, thumb and palm while it holds and opens), then every collider present then
    /// at the pose and the size it has grown to ([`StepCollider::grasp_hand`] tells the hand
    /// apart). These are the shapes the fur is
    /// pushed out of (the step's own pose, without the samples along its path).
    #[must_use]
    pub fn shown_colliders(&self, time_secs: f64) -> Vec<StepCollider> {
        self.shown_colliders_where(time_secs, |_| true)
    }

    /// [`Self::shown_colliders`], of the colliders `keep` takes (the grasp's hand always).
    #[must_use]
    pub fn shown_colliders_where(&self, time_secs: f64, keep: impl Fn(&Collider) -> bool) -> Vec<StepCollider> {
        let step_secs = 1.0 / f64::from(self.params().rate_hz);
        let mut shown = Vec::new();
        if let Some(grasp) = self.grasp() {
            shown.extend(grasp.hand(time_secs));
        }
        let mut samples = Vec::new();
        for collider in self.colliders().iter().filter(|c| keep(c)) {
            samples.clear();
            collider.push_step(time_secs, step_secs, self.bounding_radius(), &mut samples);
            // The step's own pose comes last, after the samples along the way.
            if let Some(last) = samples.pop() {
                shown.push(last);
            }
        }
        shown
    }
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use crate::fur::FurLength;
    use crate::sim::contact::{Collider, ColliderKey, Shape};
    use crate::{Builtin, FurParams, FurStructure};

    use super::*;

    fn simulation() -> Simulation {
        let (mesh, _) = Builtin::Sphere.mesh();
        let structure = FurStructure::new(
            mesh,
            &FurParams { layers: 4, length: FurLength::Constant(0.2), direction: Default::default() },
        )
        .expect("a sphere grows fur");
        Simulation::new(&structure, &crate::sim::SimParams::default()).expect("default parameters")
    }

    #[test]
    fn colliders_show_at_their_pose_once_grown() {
        let mut sim = simulation();
        let mut ball = Collider::at(7, Shape::Sphere { radius: 0.5 }, 1.0, Vec3::new(0.0, 2.0, 0.0), Quat::IDENTITY);
        ball.keys.push(ColliderKey { time_secs: 3.0, position: Vec3::new(0.0, 4.0, 0.0), rotation: Quat::IDENTITY });
        sim.set_colliders(&[ball]).expect("a valid ball");
        assert!(sim.shown_colliders(0.5).is_empty(), "absent before its first key");
        let growing = sim.shown_colliders(1.1);
        assert_eq!(growing.len(), 1);
        assert!(growing[0].radius > 0.0 && growing[0].radius < 0.5, "grows in: {}", growing[0].radius);
        let later = sim.shown_colliders(2.0);
        assert_eq!(later.len(), 1, "one pose however far it moved in the step");
        assert!((later[0].radius - 0.5).abs() < 1e-6);
        assert!(later[0].centre.distance(Vec3::new(0.0, 3.0, 0.0)) < 1e-5, "{}", later[0].centre);
        assert!(!later[0].grasp_hand);
    }

    #[test]
    fn the_holding_hand_shows_first() {
        let mut sim = simulation();
        let point = Vec3::new(0.0, 1.0, 0.0);
        sim.grasp_begin(point, 0.4, 0.2, crate::sim::contact::GraspParams::default(), 0.0).expect("a valid grasp");
        let grip = Vec3::new(0.0, 1.5, 0.0);
        sim.grasp_move(grip).expect("a finite point");
        let ball = Collider::at(7, Shape::Sphere { radius: 0.5 }, 0.0, Vec3::new(3.0, 0.0, 0.0), Quat::IDENTITY);
        sim.set_colliders(&[ball]).expect("a valid ball");
        let shown = sim.shown_colliders(0.5);
        assert_eq!(shown.len(), crate::sim::contact::HAND_PARTS + 1);
        let (hand, rest) = shown.split_at(crate::sim::contact::HAND_PARTS);
        assert!(hand.iter().all(|c| c.grasp_hand) && !rest[0].grasp_hand, "the hand first, then the ball");
        assert_eq!(hand.iter().filter(|c| c.kind == StepCollider::CAPSULE).count(), 5, "four fingers and a thumb");
        for part in hand {
            assert!(part.centre.distance(grip) + part.bound <= 3.0 * 0.2, "the hand lies about the grip: {part:?}");
        }
        sim.grasp_end(0.6);
        let opening = sim.shown_colliders(0.7);
        assert_eq!(opening.len(), crate::sim::contact::HAND_PARTS + 1, "the hand opens after letting go");
        let height = |parts: &[StepCollider]| parts.iter().map(|c| c.centre.y).sum::<f32>();
        assert!(height(&opening[..6]) > height(hand), "and withdraws");
        assert_eq!(sim.shown_colliders(0.95).len(), 1, "the hand is gone once open");
    }
}
