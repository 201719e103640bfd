//! Brushes: what one dab does to a groom's maps. A dab at a point of the rest surface changes
//! only the vertices closer than its radius, each by `strength * falloff(distance / radius)`;
//! [`super::GroomEditor`] turns dabs into strokes with undo and redo.

use glam::{Vec2, Vec3};

use super::GroomMap;

/// How much one full-weight dab of [`BrushKind::Grow`] or [`BrushKind::Shorten`] adds to or takes
/// from the length factor (a quarter of the preset's length, so a stroke builds up gradually).
pub const LENGTH_STEP: f32 = 0.25;

/// What a brush does. With `w` = the dab's weight at a vertex (`0..=1`):
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BrushKind {
    /// Length `+= w * LENGTH_STEP` (up to [`super::MAX_LENGTH_FACTOR`]).
    Grow,
    /// Length `-= w * LENGTH_STEP` (down to 0, bald).
    Shorten,
    /// Length `*= 1 - w`: a full-strength dab leaves its centre bald.
    Cut,
    /// Density toward [`Brush::value`] by `w`.
    Density,
    /// Direction toward the stroke's direction in the vertex's tangent frame (a unit flow) by `w`.
    Comb,
    /// Clump toward [`Brush::value`] by `w`.
    Clump,
    /// Tint toward [`Brush::colour`] by `w`.
    Tint,
    /// [`Brush::map`] toward the mean of each vertex's neighbours (before the dab) by `w`.
    Smooth,
    /// [`Brush::map`] toward the preset's value ([`super::GroomEditor::neutral`]) by `w`.
    Erase,
}

impl BrushKind {
    /// Every brush, in the panel's order.
    pub const ALL: [Self; 9] = [
        Self::Grow,
        Self::Shorten,
        Self::Cut,
        Self::Density,
        Self::Comb,
        Self::Clump,
        Self::Tint,
        Self::Smooth,
        Self::Erase,
    ];

    /// The brush's name (in stroke lists and the panel).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Grow => "grow",
            Self::Shorten => "shorten",
            Self::Cut => "cut",
            Self::Density => "density",
            Self::Comb => "comb",
            Self::Clump => "clump",
            Self::Tint => "tint",
            Self::Smooth => "smooth",
            Self::Erase => "erase",
        }
    }

    /// The brush named `name`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|k| k.name() == name)
    }

    /// The map a dab of this brush changes (`map` for smooth and erase).
    #[must_use]
    pub fn target(self, map: GroomMap) -> GroomMap {
        match self {
            Self::Grow | Self::Shorten | Self::Cut => GroomMap::Length,
            Self::Density => GroomMap::Density,
            Self::Comb => GroomMap::Direction,
            Self::Clump => GroomMap::Clump,
            Self::Tint => GroomMap::Tint,
            Self::Smooth | Self::Erase => map,
        }
    }
}

/// How a dab's weight falls from its centre (`t = 0`) to its rim (`t = 1`, not reached: only
/// vertices closer than the radius change).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Falloff {
    /// 1 everywhere inside.
    Constant,
    /// `1 - t`.
    Linear,
    /// `1 - t^2 (3 - 2t)` (smoothstep from the rim).
    #[default]
    Smooth,
}

impl Falloff {
    /// Every falloff, in the panel's order.
    pub const ALL: [Self; 3] = [Self::Constant, Self::Linear, Self::Smooth];

    /// The falloff's name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Constant => "constant",
            Self::Linear => "linear",
            Self::Smooth => "smooth",
        }
    }

    /// The falloff named `name`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|f| f.name() == name)
    }

    /// The weight at `t = distance / radius`, `0 <= t < 1`.
    #[must_use]
    pub fn at(self, t: f32) -> f32 {
        match self {
            Self::Constant => 1.0,
            Self::Linear => 1.0 - t,
            Self::Smooth => 1.0 - t * t * (3.0 - 2.0 * t),
        }
    }
}

/// A model axis: mirroring across it reflects through the model's plane where that coordinate
/// is 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Axis {
    /// Across the plane `x = 0` (left and right of a model facing +Z or -Z).
    X,
    /// Across `y = 0`.
    Y,
    /// Across `z = 0`.
    Z,
}

impl Axis {
    /// Every axis.
    pub const ALL: [Self; 3] = [Self::X, Self::Y, Self::Z];

    /// `"x"`, `"y"` or `"z"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::X => "x",
            Self::Y => "y",
            Self::Z => "z",
        }
    }

    /// The axis named `name`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|a| a.name() == name)
    }

    /// `v` reflected across the axis's plane.
    #[must_use]
    pub fn reflect(self, v: Vec3) -> Vec3 {
        match self {
            Self::X => Vec3::new(-v.x, v.y, v.z),
            Self::Y => Vec3::new(v.x, -v.y, v.z),
            Self::Z => Vec3::new(v.x, v.y, -v.z),
        }
    }

    /// `v`'s coordinate along the axis.
    #[must_use]
    pub fn of(self, v: Vec3) -> f32 {
        match self {
            Self::X => v.x,
            Self::Y => v.y,
            Self::Z => v.z,
        }
    }
}

/// One brush's settings. Out-of-range numbers are clamped when dabbing (a non-finite one makes
/// the dab change nothing), so no setting can put NaN or out-of-range values into a groom.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Brush {
    /// What it does.
    pub kind: BrushKind,
    /// Radius in model units (the rest mesh's).
    pub radius: f32,
    /// Weight at the centre, `0..=1`.
    pub strength: f32,
    /// How the weight falls toward the rim.
    pub falloff: Falloff,
    /// Repeat each dab reflected across this axis's plane.
    pub mirror: Option<Axis>,
    /// The value density and clump brushes paint toward, `0..=1`.
    pub value: f32,
    /// The linear RGB the tint brush paints toward, each `0..=1`.
    pub colour: Vec3,
    /// The map smooth and erase work on.
    pub map: GroomMap,
}

impl Default for Brush {
    fn default() -> Self {
        Self {
            kind: BrushKind::Grow,
            radius: 0.1,
            strength: 0.5,
            falloff: Falloff::Smooth,
            mirror: None,
            value: 0.5,
            colour: Vec3::ONE,
            map: GroomMap::Length,
        }
    }
}

impl Brush {
    /// The weight of a vertex at `distance` from the dab's centre: `strength * falloff(d / r)`
    /// for `d < r`, `None` outside (or for a radius that is not a positive finite number).
    #[must_use]
    pub fn weight(&self, distance: f32) -> Option<f32> {
        let strength = if self.strength.is_finite() { self.strength.clamp(0.0, 1.0) } else { 0.0 };
        let usable = self.radius.is_finite() && self.radius > 0.0 && distance.is_finite();
        (usable && distance < self.radius).then(|| strength * self.falloff.at(distance / self.radius))
    }

    /// `value` clamped to `0..=1` (0 if not finite).
    pub(super) fn target_value(&self) -> f32 {
        if self.value.is_finite() { self.value.clamp(0.0, 1.0) } else { 0.0 }
    }

    /// `colour` clamped to `0..=1` per channel (0 where not finite).
    pub(super) fn target_colour(&self) -> Vec3 {
        let c = |x: f32| if x.is_finite() { x.clamp(0.0, 1.0) } else { 0.0 };
        Vec3::new(c(self.colour.x), c(self.colour.y), c(self.colour.z))
    }
}

/// `a + (b - a) * w` per component, exact at `w = 0` and `w = 1`.
pub(super) fn mix(a: f32, b: f32, w: f32) -> f32 {
    if w >= 1.0 { b } else { a + (b - a) * w }
}

/// The unit flow of a world direction `d` in a frame `(tangent, up)`, `None` when `d` has no part
/// along the surface.
pub(super) fn flow_of(d: Vec3, tangent: Vec3, up: Vec3) -> Option<Vec2> {
    let flow = Vec2::new(d.dot(tangent), d.dot(up));
    flow.try_normalize().map(|f| f.clamp(Vec2::NEG_ONE, Vec2::ONE))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for kind in BrushKind::ALL {
            assert_eq!(BrushKind::from_name(kind.name()), Some(kind));
        }
        for falloff in Falloff::ALL {
            assert_eq!(Falloff::from_name(falloff.name()), Some(falloff));
        }
        for axis in Axis::ALL {
            assert_eq!(Axis::from_name(axis.name()), Some(axis));
        }
    }

    #[test]
    fn weights_stay_inside_the_radius_and_bad_settings_change_nothing() {
        let brush = Brush { radius: 2.0, strength: 0.5, falloff: Falloff::Linear, ..Brush::default() };
        assert_eq!(brush.weight(0.0), Some(0.5));
        assert_eq!(brush.weight(1.0), Some(0.25));
        assert_eq!(brush.weight(2.0), None);
        for radius in [0.0, -1.0, f32::NAN, f32::INFINITY] {
            assert_eq!(Brush { radius, ..brush }.weight(0.0), None);
        }
        assert_eq!(Brush { strength: f32::NAN, ..brush }.weight(0.0), Some(0.0));
        assert_eq!(Brush { strength: 7.0, ..brush }.weight(0.0), Some(1.0));
    }
}
