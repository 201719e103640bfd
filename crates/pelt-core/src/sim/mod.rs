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
