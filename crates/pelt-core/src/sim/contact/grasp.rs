//! A hand grasping the fur: the strands rooted within the grip's radius are gathered toward the
//! grip point and follow it (within their length; roots stay on the skin); on release they
//! spring back and settle with damping. The hand is four finger capsules, a thumb and a palm
//! about the grip ([`Grasp::hand`]): it closes as the grasp does, opens and withdraws on release,
//! and pushes the strands it does not hold.

use glam::{Quat, Vec3};

use super::collider::StepCollider;

/// How a grasp closes and lets go.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GraspParams {
    /// Seconds the hand takes to close (the gathered strands turn toward the grip). Default 0.3.
    pub close_secs: f32,
    /// Frequency of the spring back after release, Hz. Default 2.
    pub spring_hz: f32,
    /// Damping ratio of the spring back (below 1 it swings past rest once or more). Default 0.35.
    pub damping: f32,
}

impl Default for GraspParams {
    fn default() -> Self {
        Self { close_secs: 0.3, spring_hz: 2.0, damping: 0.35 }
    }
}

impl GraspParams {
    /// Checks the ranges; `(key, problem)` for the first bad value.
    ///
    /// # Errors
    /// The key and the problem.
    pub fn validate(&self) -> Result<(), (String, String)> {
        for (key, value, low, high) in [
            ("close_secs", self.close_secs, 0.0, 60.0),
            ("spring_hz", self.spring_hz, 0.01, 100.0),
            ("damping", self.damping, 0.01, 100.0),
        ] {
            if !(value.is_finite() && (low..=high).contains(&value)) {
                return Err((key.into(), format!("must be between {low} and {high}, got {value}")));
            }
        }
        Ok(())
    }
}

impl GraspParams {
    /// Seconds after release until the swing has settled (below a thousandth of the hold).
    #[must_use]
    pub fn settle_secs(&self) -> f32 {
        (1.0 / SETTLED).ln() / (self.damping * std::f32::consts::TAU * self.spring_hz)
    }
}

/// The parts of [`Grasp::hand`]: four fingers, a thumb and a palm.
pub const HAND_PARTS: usize = 6;

/// A finger's bend from its knuckle, radians below the outward direction: spread open, and
/// curled in under the grip when closed.
const FINGER_OPEN: f32 = 0.35;
const FINGER_CLOSED: f32 = 1.92;

/// The remaining swing below which a released grasp counts as settled and is dropped.
const SETTLED: f32 = 1e-3;

/// A grasp in progress (or springing back after release).
#[derive(Clone, Debug, PartialEq)]
pub struct Grasp {
    /// Where the hand closed.
    pub point: Vec3,
    /// Strands rooted within this distance of `point` are gathered.
    pub radius: f32,
    /// Where the grip is now.
    pub grip: Vec3,
    /// Size of the hand about the grip (its knuckles lie this far from the grip's axis; its
    /// fingers, thumb and palm push the strands it does not hold); 0: no hand.
    pub hand_radius: f32,
    /// The hand's up: the mean normal of the skin it closed on (the fingers reach down along it).
    pub axis: Vec3,
    /// When it closed and when it let go.
    pub closed_at_secs: f64,
    /// When it let go, if it has.
    pub released_at_secs: Option<f64>,
    /// Closing and spring-back.
    pub params: GraspParams,
    /// Gathered strands' weights, one per strand (0: not held).
    weights: Vec<f32>,
}

impl Grasp {
    /// Closes at `point` at `time_secs` over the strands rooted at `roots`: weight 1 within 70%
    /// of `radius`, falling smoothly to 0 at `radius`. `normals` (one per root, or empty) give
    /// the hand's [`Grasp::axis`]: their mean over the held strands, else `+Y`.
    #[must_use]
    pub fn new(
        point: Vec3,
        radius: f32,
        hand_radius: f32,
        time_secs: f64,
        params: GraspParams,
        roots: &[Vec3],
        normals: &[Vec3],
    ) -> Self {
        let weights: Vec<f32> = roots
            .iter()
            .map(|root| {
                let t = ((root.distance(point) / radius - 0.7) / 0.3).clamp(0.0, 1.0);
                1.0 - t * t * (3.0 - 2.0 * t)
            })
            .collect();
        let axis = weights
            .iter()
            .zip(normals)
            .filter(|(_, n)| n.is_finite())
            .fold(Vec3::ZERO, |sum, (w, n)| sum + *n * *w)
            .try_normalize()
            .unwrap_or(Vec3::Y);
        Self {
            point,
            radius,
            grip: point,
            hand_radius,
            axis,
            closed_at_secs: time_secs,
            released_at_secs: None,
            params,
            weights,
        }
    }

    /// How far each strand is held, one per strand in `[0, 1]`.
    #[must_use]
    pub fn weights(&self) -> &[f32] {
        &self.weights
    }

    /// How much the gathered strands turn toward the grip at `time_secs`: rising to 1 over
    /// `close_secs`, then after release a damped oscillation from 1 through 0 (negative values
    /// swing past rest), exactly 0 once settled.
    #[must_use]
    pub fn presence(&self, time_secs: f64) -> f32 {
        let closing = (time_secs - self.closed_at_secs) as f32;
        let closed = if self.params.close_secs > 0.0 {
            let t = (closing / self.params.close_secs).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        } else if closing >= 0.0 {
            1.0
        } else {
            0.0
        };
        let Some(released) = self.released_at_secs else { return closed };
        let after = ((time_secs - released) as f32).max(0.0);
        let omega = std::f32::consts::TAU * self.params.spring_hz;
        let zeta = self.params.damping;
        let envelope = (-zeta * omega * after).exp();
        if envelope < SETTLED {
            return 0.0;
        }
        let swing = if zeta < 1.0 {
            let omega_d = omega * (1.0 - zeta * zeta).sqrt();
            // The under-damped spring released from rest at 1.
            envelope * ((omega_d * after).cos() + zeta * omega / omega_d * (omega_d * after).sin())
        } else {
            envelope * (1.0 + omega * after)
        };
        closed * swing
    }

    /// How far the hand is closed at `time_secs`, and how far it has opened and withdrawn since
    /// release (0 while it holds, 1 once gone): each in `[0, 1]`.
    fn closure(&self, time_secs: f64) -> (f32, f32) {
        let smooth = |t: f32| t * t * (3.0 - 2.0 * t);
        let closing = |at: f64| {
            if self.params.close_secs > 0.0 {
                smooth((((at - self.closed_at_secs) as f32) / self.params.close_secs).clamp(0.0, 1.0))
            } else if at >= self.closed_at_secs {
                1.0
            } else {
                0.0
            }
        };
        match self.released_at_secs {
            None => (closing(time_secs), 0.0),
            Some(released) => {
                let after = (time_secs - released) as f32;
                let opened = if self.params.close_secs > 0.0 {
                    smooth((after / self.params.close_secs).clamp(0.0, 1.0))
                } else {
                    1.0
                };
                (closing(released) * (1.0 - opened), opened)
            }
        }
    }

    /// The hand at `time_secs` as colliders the step reads (each marked
    /// [`StepCollider::grasp_hand`], so the strands it holds pass through): four finger capsules
    /// and a thumb curling from open to closed about the grip as the hand closes, and a palm
    /// ball above it, all grown in with the closing so the hand appears without a jolt; on
    /// release the fingers open and the hand withdraws along [`Grasp::axis`] over `close_secs`,
    /// then is gone. Empty without a hand (`hand_radius` 0) and once it is gone.
    #[must_use]
    pub fn hand(&self, time_secs: f64) -> Vec<StepCollider> {
        let (closed, opened) = self.closure(time_secs);
        let h = self.hand_radius;
        let grown = if self.released_at_secs.is_some() { 1.0 } else { (2.0 * closed).min(1.0) };
        if h <= 0.0 || grown <= 0.0 || opened >= 1.0 {
            return Vec::new();
        }
        let size = h * grown;
        let up = self.axis;
        // Across the hand: world X laid flat on the skin, so the hand's heading does not depend
        // on the last bits of the axis.
        let across = (Vec3::X - up * up.dot(Vec3::X)).try_normalize().unwrap_or_else(|| up.any_orthonormal_vector());
        let base = self.grip + up * (2.0 * h * opened);
        let bend = FINGER_OPEN + (FINGER_CLOSED - FINGER_OPEN) * closed;
        let digit = |heading_deg: f32, knuckle_out: f32, knuckle_up: f32, length: f32, radius: f32| {
            let outward = Quat::from_axis_angle(up, heading_deg.to_radians()) * across;
            let knuckle = base + (outward * knuckle_out + up * knuckle_up) * size;
            let along = outward * bend.cos() - up * bend.sin();
            let centre = knuckle + along * (0.5 * length * size);
            let mut finger = StepCollider::ball(centre, radius * size);
            finger.kind = StepCollider::CAPSULE;
            finger.rotation = Quat::from_rotation_arc(Vec3::Y, along);
            finger.half_extents = Vec3::new(0.0, 0.5 * length * size, 0.0);
            finger.bound = finger.radius + finger.half_extents.y;
            finger.grasp_hand = true;
            finger
        };
        let mut parts = Vec::with_capacity(HAND_PARTS);
        for heading in [-54.0, -18.0, 18.0, 54.0] {
            parts.push(digit(heading, 0.8, 0.9, 1.1, 0.2));
        }
        parts.push(digit(180.0, 0.7, 0.6, 0.85, 0.24));
        let mut palm = StepCollider::ball(base + up * (1.05 * size), 0.75 * size);
        palm.grasp_hand = true;
        parts.push(palm);
        parts
    }

    /// Whether the grasp was released and has settled (it acts no more).
    #[must_use]
    pub fn settled(&self, time_secs: f64) -> bool {
        self.released_at_secs.is_some() && self.presence(time_secs) == 0.0
    }
}
