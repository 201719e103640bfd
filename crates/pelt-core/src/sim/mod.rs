//! Fur simulation (docs/paper-notes.md section 4): gravity, wind and touch bend every strand of the
//! shared vertex array by rotating its nodes about the node before them, root first.
//!
//! - [`bend`]: the rotation scheme of the paper's Equation 1, in O(L) per strand
//!   ([`bend_strand`]) and as the literal O(L^2) loop kept as the oracle ([`bend_strand_literal`]).
//! - [`wind`]: wind with gusts that travel with it and a small seeded jitter.
//! - [`field`]: the per-vertex [`ForceField`] and the touch (patting) overlay.
//! - [`mod@pick`]: ray picking of the base mesh, so a pointer or a script can touch the fur.
//! - [`simulation`]: [`Simulation`], fixed steps with linear interpolation between the last two.
//! - [`stepper`]: [`FurStepper`], one fur driven through time: its base posed, the script played.
//! - `inputs`: one step's inputs for any kernel, computed once: [`StepInputs`] (shared by every
//!   strand) and [`StrandInputs`] (per strand).
//! - [`scene`]: scripted wind and touch strokes ([`Scene`]), reproducible frame by frame.
//! - [`herd`]: many copies of one fur, each placed, heading and phased on its own ([`HerdInstance`]).
//! - [`motion`]: scripted rigid motion of the meshes (`[[motion]]` keys of a [`Scene`]).
//! - [`inertia`]: the force from the roots' acceleration on a moving body ([`Inertia`]).
//! - [`contact`]: the skin, colliders and the grasp, applied after the bend.
//! - `soak` (with the `lab` feature): many steps under extreme, changing inputs for any kernel.
//!
//! `Simulation` bends with a batched kernel (8 strands per AVX2 register, an exact closed form
//! for straight strands, the running quaternion for curved ones; AVX2 + FMA where the CPU has
//! them, a portable copy giving the same bytes elsewhere: [`CpuKernel`]).
//!
//! The model is quasi-static, as in the paper: a strand's pose is a function of the force on it,
//! with no velocity. So a state at time `t` depends on earlier states only through the inertial
//! force (a damped spring per strand, reset by a jump in time), which keeps every step
//! deterministic, parallel over strands, and cheap to jump to any time.

pub mod bend;
pub mod contact;
mod dispatch;
pub mod field;
pub mod herd;
pub mod inertia;
mod inputs;
mod kernel;
mod lanes;
pub mod motion;
pub mod pick;
pub mod scene;
mod shown;
pub mod simulation;
#[cfg(feature = "lab")]
pub mod soak;
pub mod stepper;
pub mod wind;

use glam::Vec3;

pub use crate::param::ParamError;

pub use bend::{BEND_GAIN, bend_strand, bend_strand_literal, bend_weight};
pub use contact::{
    Collider, ColliderKey, ColliderMesh, ContactParams, ContactStep, ContactStrands, Grasp, GraspParams, HAND_PARTS,
    Shape, StepCollider,
};
pub use dispatch::CpuKernel;
pub use field::{ForceField, Touch};
pub use herd::HerdInstance;
pub use inertia::{Inertia, InertiaStep, SpringStep};
pub use inputs::{InputVersions, StepInputs, StrandInputs};
pub use kernel::{KernelRest, kernel_rest};
pub use motion::{Ease, MotionKey};
pub use pick::{Hit, pick};
pub use scene::{Scene, SceneCamera, SceneCollider, SceneError, SceneGround, SceneShape, Stroke, WindKey};
pub use simulation::{SimError, Simulation};
#[cfg(feature = "lab")]
pub use soak::{SoakReport, SoakStep, SoakSubject, soak};
pub use stepper::FurStepper;
pub use wind::{WindParams, WindStep, value_noise3};

/// Simulation parameters; part of a fur preset (`[simulation]` table).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimParams {
    /// Stiffness: larger is stiffer (the paper's `stability`). Default 8. Under the default
    /// [`Equation::Pelt`] this is not the paper's number: see [`Equation`] for the conversion.
    pub stability: f32,
    /// Which form of the paper's Equation 1 bends the fur (`"pelt"`, the default, or
    /// `"paper"`).
    pub equation: Equation,
    /// Unit gravity direction. Default `-Y`.
    pub gravity_direction: Vec3,
    /// Gravity strength (0 turns gravity off). Default 1: with the default stability and 16
    /// layers a horizontal strand's tip turns about a third of the way down.
    pub gravity_strength: f32,
    /// Simulation steps per second. Default 30.
    pub rate_hz: f32,
    /// Draw `lerp(previous, current)` between steps; when false the simulation runs every frame.
    pub interpolate: bool,
    /// Wind (`[simulation.wind]`); off by default (strength 0).
    pub wind: WindParams,
    /// Touch (`[simulation.touch]`).
    pub touch: TouchParams,
    /// How strongly the fur lags behind the body's acceleration: the inertial force is
    /// `-inertia * acceleration / radius` (acceleration in bounding radii per second squared,
    /// force in gravity's units). 0 turns it off. Default 0.05.
    pub inertia: f32,
    /// Damping ratio of the fur's swing after the body's motion changes: below 1 it swings past
    /// and settles, 1 or more it settles without swinging. Default 0.3.
    pub damping: f32,
    /// Contact with the skin (`[simulation.contact]`); off by default.
    pub contact: ContactParams,
}

impl Default for SimParams {
    fn default() -> Self {
        Self {
            stability: 8.0,
            equation: Equation::Pelt,
            gravity_direction: Vec3::NEG_Y,
            gravity_strength: 1.0,
            rate_hz: 30.0,
            interpolate: true,
            wind: WindParams::default(),
            touch: TouchParams::default(),
            inertia: 0.05,
            damping: 0.3,
            contact: ContactParams::default(),
        }
    }
}

/// The form of the paper's Equation 1 (`equation` in `[simulation]`).
///
/// Root first, at node `k` of a strand of `L` segments, with `a_k` the angle between segment `k`
/// and the force `F` (the paper's `acos(V . V2)`, computed as `atan2`, so clamped by
/// construction) and `RN = L - k` the nodes not yet visited, the strand beyond node `k` turns
/// toward the force by `theta_k = a_k * min(1, |F| * gain * RN / stability)`:
///
/// | equation | gain | at gravity strength 1 |
/// |---|---|---|
/// | `pelt` | `BEND_GAIN / L^2` (`8 / L^2`) | `a_k * min(1, 8 RN / (L^2 stability))` |
/// | `paper` | `1` | `a_k * min(1, RN / stability)`: the paper's Equation 1 |
///
/// Both scale the angle by the force's magnitude (so wind and touch bend by their strength, as
/// the paper's section on forces asks; gravity of strength 1 is the paper's Equation 1 exactly)
/// and clamp the factor at 1 so no segment turns past the force. `pelt` divides by `L^2` so a
/// fur bends about as much at any layer count (the factors of one strand sum to about
/// `|F| * 4 / stability`), and its gain of 8 puts the default stability 8 at a visible droop.
/// The two agree exactly when `stability_paper = stability_pelt * L^2 / 8`: Pelt's default 8 is
/// the paper's 256 at `L = 16` and 1,024 at `L = 32`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Equation {
    /// `gain = 8 / L^2`: the bend hardly depends on the layer count. The default.
    #[default]
    Pelt,
    /// `gain = 1`: the paper's literal `acos(V . V2) * RN / stability`, for reproducing its
    /// figures.
    Paper,
}

impl Equation {
    /// The gain of this form for `layers` segments (see [`Equation`]).
    #[must_use]
    pub fn gain(self, layers: u32) -> f32 {
        match self {
            Self::Pelt => BEND_GAIN / (layers.max(1) as f32).powi(2),
            Self::Paper => 1.0,
        }
    }

    /// The stability that gives the same bend under [`Equation::Paper`] as `stability` does
    /// under [`Equation::Pelt`] at `layers` (`stability * L^2 / 8`).
    #[must_use]
    pub fn paper_stability_from_pelt(stability: f32, layers: u32) -> f32 {
        stability * (layers as f32).powi(2) / BEND_GAIN
    }
}

/// How a touch (patting) acts on the force field (`[simulation.touch]`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TouchParams {
    /// Force per radius of drag: dragging the pointer one touch radius away from the hit point
    /// pushes with this force at the centre. Default 4 (well above gravity's 1).
    pub strength: f32,
    /// After release the touch fades out linearly over this many seconds; 0 (the default)
    /// restores the field's original values at once. Either way the originals come back exactly.
    pub release_secs: f32,
}

impl Default for TouchParams {
    fn default() -> Self {
        Self { strength: 4.0, release_secs: 0.0 }
    }
}

/// The largest force magnitude (gravity, wind or touch) the simulation accepts as a parameter.
pub const MAX_FORCE: f32 = 1e9;

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
        if !(self.gravity_strength.is_finite() && (0.0..=MAX_FORCE).contains(&self.gravity_strength)) {
            return error("gravity_strength", format!("must be between 0 and 1e9, got {}", self.gravity_strength));
        }
        if !(self.rate_hz.is_finite() && (1.0..=1000.0).contains(&self.rate_hz)) {
            return error("rate_hz", format!("must be between 1 and 1000, got {}", self.rate_hz));
        }
        self.wind.validate().map_err(|e| ParamError { key: format!("simulation.{}", e.key), problem: e.problem })?;
        if !(self.touch.strength.is_finite() && (0.0..=MAX_FORCE).contains(&self.touch.strength)) {
            return error("touch.strength", format!("must be between 0 and 1e9, got {}", self.touch.strength));
        }
        if !(self.touch.release_secs.is_finite() && (0.0..=60.0).contains(&self.touch.release_secs)) {
            return error("touch.release_secs", format!("must be between 0 and 60, got {}", self.touch.release_secs));
        }
        if !(self.inertia.is_finite() && (0.0..=100.0).contains(&self.inertia)) {
            return error("inertia", format!("must be between 0 and 100, got {}", self.inertia));
        }
        if !(self.damping.is_finite() && (0.0..=100.0).contains(&self.damping)) {
            return error("damping", format!("must be between 0 and 100, got {}", self.damping));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid_and_round_trip_through_toml() {
        let params = SimParams::default();
        params.validate().unwrap();
        let text = toml::to_string(&params).unwrap();
        let back: SimParams = toml::from_str(&text).unwrap();
        assert_eq!(back, params);
    }

    #[test]
    fn bad_values_name_their_key() {
        let mut params = SimParams::default();
        params.wind.gust_scale = 0.0;
        assert_eq!(params.validate().unwrap_err().key, "simulation.wind.gust_scale");
        let mut params = SimParams::default();
        params.touch.release_secs = f32::NAN;
        assert_eq!(params.validate().unwrap_err().key, "simulation.touch.release_secs");
        let params = SimParams { stability: 0.0, ..SimParams::default() };
        assert_eq!(params.validate().unwrap_err().key, "simulation.stability");
        let params = SimParams { inertia: -1.0, ..SimParams::default() };
        assert_eq!(params.validate().unwrap_err().key, "simulation.inertia");
        let params = SimParams { damping: f32::INFINITY, ..SimParams::default() };
        assert_eq!(params.validate().unwrap_err().key, "simulation.damping");
        assert!(toml::from_str::<SimParams>("[wind]\nspeeed = 1.0").is_err());
    }
}
