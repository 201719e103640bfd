//! Wet fur: [`FurSponge`], a sponge at an entity's position that wets (or dries) the fur it
//! touches. The preset's `[wet]` table says what wetness does (heavier, softer, darker, shinier,
//! clumped strands) and how fast the fur dries; the wetness reaches the simulation and the
//! renderer.

use bevy::ecs::prelude::*;
use bevy::math::Vec3;
use bevy::prelude::GlobalTransform;
use pelt_core::sim::FurStepper;

use crate::convert::to_pelt;

/// A sponge pressed on fur at this entity's position: every frame it is `pressing`, the wetness
/// of the fur rooted within `radius` moves toward `amount` (1 soaks, 0 dries), most at the
/// centre, fading to nothing at `radius`. Every fur within reach takes it.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(GlobalTransform)]
pub struct FurSponge {
    /// Whether it presses this frame.
    pub pressing: bool,
    /// Radius of the wetted area, world units.
    pub radius: f32,
    /// The wetness it brings the fur toward, `0..=1`.
    pub amount: f32,
}

impl FurSponge {
    /// A pressing sponge of `radius` that soaks.
    #[must_use]
    pub fn new(radius: f32) -> Self {
        Self { pressing: true, radius, amount: 1.0 }
    }
}

/// Presses this frame's sponges (entity position, sponge) on one fur (world = scale * simulation).
pub(crate) fn apply_sponges(stepper: &mut FurStepper, sponges: &[(Vec3, FurSponge)], simulation_scale: f32) {
    for (position, sponge) in sponges.iter().filter(|(_, s)| s.pressing) {
        let centre = to_pelt(*position) / simulation_scale;
        stepper.sponge(centre, sponge.radius / simulation_scale, sponge.amount);
    }
}
