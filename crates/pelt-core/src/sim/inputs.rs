//! The inputs of one simulation step, computed in one place for every kernel that bends the
//! strands: [`StepInputs`] (what every strand shares: gravity, the wind's step, the touch,
//! Equation 1's gain) and [`StrandInputs`] (one entry per strand: posed roots and frames,
//! stability, the user field, the touch's weights, the inertial force, wetness). The CPU kernel reads them
//! here; a GPU kernel packs them into its buffers as they are.

use glam::{Quat, Vec3};

use super::SimParams;
use super::field::Touch;
use super::wind::WindStep;
#[cfg(doc)]
use crate::wet::WetParams;

/// What every strand shares in the step at [`StepInputs::time_secs`], from
/// [`Simulation::step_inputs`](super::Simulation::step_inputs).
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct StepInputs {
    /// The step's simulation time.
    pub time_secs: f64,
    /// Gravity: its unit direction times its strength.
    pub gravity: Vec3,
    /// The wind at this step.
    pub wind: WindStep,
    /// The touch's force, `interaction / radius * strength`; zero without a touch.
    pub touch_force: Vec3,
    /// How much of the touch acts, in `[0, 1]` (it fades out after release); 0 without a touch.
    /// A strand's field is blended towards `touch_force` by its touch weight times this.
    pub touch_presence: f32,
    /// Equation 1's gain ([`Equation::gain`](super::Equation::gain) for the fur's layers).
    pub gain: f32,
}

impl StepInputs {
    pub(super) fn new(params: &SimParams, layers: u32, radius: f32, touch: Option<&Touch>, time_secs: f64) -> Self {
        let (touch_force, touch_presence) = touch.map_or((Vec3::ZERO, 0.0), |touch| {
            let presence = touch.presence(time_secs, params.touch.release_secs);
            (touch.force(params.touch.strength), presence.max(0.0))
        });
        Self {
            time_secs,
            gravity: params.gravity_direction.normalize_or_zero() * params.gravity_strength,
            wind: WindStep::new(&params.wind, time_secs, radius),
            touch_force,
            touch_presence,
            gain: params.equation.gain(layers),
        }
    }
}

/// One entry per strand (base vertex) of the simulation's inputs as they are now, from
/// [`Simulation::strand_inputs`](super::Simulation::strand_inputs). Every slice has one entry
/// per strand.
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct StrandInputs<'a> {
    /// The posed root positions.
    pub roots: &'a [Vec3],
    /// Each strand's rotation from its rest frame into the posed base frame.
    pub frames: &'a [Quat],
    /// The stability where no map is set ([`SimParams::stability`]).
    pub stability: f32,
    /// The per-strand stability map, if one is set.
    pub stability_map: Option<&'a [f32]>,
    /// The user force field.
    pub field: &'a [Vec3],
    /// The strands the touch reaches, with their falloff weights in `(0, 1]`; empty without a
    /// touch.
    pub touch_weights: &'a [(u32, f32)],
    /// The inertial force from the roots' acceleration at the newest step.
    pub inertial: &'a [Vec3],
    /// Each strand's wetness in `[0, 1]`, if any strand is wet.
    pub wetness: Option<&'a [f32]>,
    /// Gravity's factor per unit of wetness ([`WetParams::added_weight`]).
    pub wet_weight: f32,
    /// Stability's loss per unit of wetness ([`WetParams::softening`]).
    pub wet_softening: f32,
}

impl StrandInputs<'_> {
    /// Strand `strand`'s stability: the map's entry, or [`StrandInputs::stability`], times
    /// `1 - softening * wetness` when wet.
    ///
    /// # Panics
    /// If `strand` is not a strand of the simulation and a map is set.
    #[must_use]
    pub fn stability_of(&self, strand: usize) -> f32 {
        let stability = self.stability_map.map_or(self.stability, |map| map[strand]);
        match self.wetness {
            Some(wetness) => stability * (1.0 - self.wet_softening * wetness[strand]),
            None => stability,
        }
    }

    /// Gravity's factor on strand `strand`: `1 + added_weight * wetness` (exactly 1 when dry).
    ///
    /// # Panics
    /// If `strand` is not a strand of the simulation and wetness is set.
    #[must_use]
    pub fn gravity_scale_of(&self, strand: usize) -> f32 {
        self.wetness.map_or(1.0, |wetness| 1.0 + self.wet_weight * wetness[strand])
    }
}

/// Counters of the per-strand inputs' changes, from [`Simulation::input_versions`](super::Simulation::input_versions)
/// (super::Simulation::input_versions): a kernel that keeps the inputs resident uploads one only
/// when its counter moved. Two simulations never share an `id`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[non_exhaustive]
pub struct InputVersions {
    /// Which simulation these count.
    pub id: u64,
    /// The posed roots and frames (`set_base`, `set_base_rotations`).
    pub base: u64,
    /// The stability map and the stability where none is set.
    pub stability: u64,
    /// The user field (every `field_mut`).
    pub field: u64,
    /// The touch (every `touch_begin`): its weights are fixed when it begins.
    pub touch: u64,
}
