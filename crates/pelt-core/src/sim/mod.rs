//! Fur simulation (PAPER-NOTES section 4).
//!
//! INTERFACE (fixed so presets and the renderer can build against it; the simulation issue
//! fills the rest).

use glam::Vec3;

/// Simulation parameters; part of a fur preset (`[simulation]` table).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimParams {
    /// Stiffness: larger is stiffer (the paper's `stability`).
    pub stability: f32,
    /// Unit gravity direction.
    pub gravity_direction: Vec3,
    /// Gravity strength (0 turns gravity off).
    pub gravity_strength: f32,
    /// Simulation steps per second.
    pub rate_hz: f32,
    /// Draw `lerp(previous, current)` between steps; when false the simulation runs every frame.
    pub interpolate: bool,
}

impl Default for SimParams {
    fn default() -> Self {
        Self { stability: 8.0, gravity_direction: Vec3::NEG_Y, gravity_strength: 1.0, rate_hz: 30.0, interpolate: true }
    }
}

/// A parameter outside its allowed range: its preset key and what is allowed.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
#[error("{key}: {problem}")]
pub struct ParamError {
    /// The key as written in a preset, e.g. `simulation.stability`.
    pub key: String,
    /// What is wrong and the allowed range.
    pub problem: String,
}

impl SimParams {
    /// Checks every field against its documented range.
    ///
    /// # Errors
    /// The first [`ParamError`] found.
    pub fn validate(&self) -> Result<(), ParamError> {
        let error = |key: &str, problem: String| Err(ParamError { key: format!("simulation.{key}"), problem });
        if !(self.stability.is_finite() && self.stability >= 1e-6 && self.stability <= 1e9) {
            return error("stability", format!("must be between 1e-6 and 1e9, got {}", self.stability));
        }
        if !self.gravity_direction.is_finite() || self.gravity_direction.length_squared() == 0.0 {
            return error(
                "gravity_direction",
                format!("must be a finite non-zero vector, got {}", self.gravity_direction),
            );
        }
        if !(self.gravity_strength.is_finite() && self.gravity_strength >= 0.0) {
            return error("gravity_strength", format!("must be finite and at least 0, got {}", self.gravity_strength));
        }
        if !(self.rate_hz.is_finite() && (1.0..=1000.0).contains(&self.rate_hz)) {
            return error("rate_hz", format!("must be between 1 and 1000, got {}", self.rate_hz));
        }
        Ok(())
    }
}
