//! A hand grasping the fur: the strands rooted within the grip's radius are gathered toward the
//! grip point and follow it (within their length; roots stay on the skin); on release they
//! spring back and settle with damping.

use glam::Vec3;

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
    /// Radius of the hand's ball about the grip, which pushes the strands it does not hold (0:
    /// none).
    pub hand_radius: f32,
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
    /// of `radius`, falling smoothly to 0 at `radius`.
    #[must_use]
    pub fn new(
        point: Vec3,
        radius: f32,
        hand_radius: f32,
        time_secs: f64,
        params: GraspParams,
        roots: &[Vec3],
    ) -> Self {
        let weights = roots
            .iter()
            .map(|root| {
                let t = ((root.distance(point) / radius - 0.7) / 0.3).clamp(0.0, 1.0);
                1.0 - t * t * (3.0 - 2.0 * t)
            })
            .collect();
        Self {
            point,
            radius,
            grip: point,
            hand_radius,
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

    /// Whether the grasp was released and has settled (it acts no more).
    #[must_use]
    pub fn settled(&self, time_secs: f64) -> bool {
        self.released_at_secs.is_some() && self.presence(time_secs) == 0.0
    }
}
