//! Herds: many copies of one fur, each with its own place, heading, walking speed, clip and
//! phase: a scene script's `[[instance]]` tables, or [`scatter`] for `pelt render --herd N`.
//!
//! ```toml
//! [[instance]]
//! position = [0.0, 0.0, 0.0]       # where its model's origin stands at time 0 (world)
//! heading_deg = 90.0               # optional (default 0): turn about +Y; 0 keeps the model's +Z ahead
//! speed = 30.0                     # optional (default 0): world units a second, straight ahead
//! clip = "Walk"                    # optional: the animation it plays (default: the host's)
//! time_offset_secs = 0.4           # optional (default 0): how far into its clip it starts
//! tint = [1.0, 0.8, 0.6]           # optional (default white): multiplies its coat's colour
//! length_scale = 1.2               # optional (default 1): its strands this much longer
//! ```
//!
//! Each instance is simulated in the world with its own [`FurStepper`](super::FurStepper)
//! ([`FurStepper::set_placement`](super::FurStepper::set_placement)); a script's other keys (wind,
//! rain, colliders) reach every instance where they are in the world.

use glam::{Mat4, Quat, Vec3};

use crate::anim::Rig;
use crate::rng;

/// One member of a herd (`[[instance]]`).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct HerdInstance {
    /// Where the model's origin stands at time 0 (world units).
    pub position: Vec3,
    /// Turn about +Y in degrees; 0 keeps the model's +Z ahead.
    #[serde(default)]
    pub heading_deg: f32,
    /// World units a second along its heading.
    #[serde(default)]
    pub speed: f32,
    /// The clip it plays, by name or index; default the host's.
    #[serde(default)]
    pub clip: Option<String>,
    /// Seconds into its clip at time 0.
    #[serde(default)]
    pub time_offset_secs: f64,
    /// Multiplies its coat's colour (linear RGB; white keeps the textures').
    #[serde(default = "white")]
    pub tint: Vec3,
    /// Its strands' lengths over the fur's ([`FurStructure::with_length_scale`](crate::FurStructure::with_length_scale)).
    #[serde(default = "one")]
    pub length_scale: f32,
}

fn white() -> Vec3 {
    Vec3::ONE
}

fn one() -> f32 {
    1.0
}

/// The largest [`HerdInstance::length_scale`]: a coat grown ten times longer is another preset.
pub const MAX_LENGTH_SCALE: f32 = 10.0;

impl HerdInstance {
    /// Standing at `position`, heading along +Z, the host's clip from its start.
    #[must_use]
    pub fn at(position: Vec3) -> Self {
        Self {
            position,
            heading_deg: 0.0,
            speed: 0.0,
            clip: None,
            time_offset_secs: 0.0,
            tint: Vec3::ONE,
            length_scale: 1.0,
        }
    }

    /// Its model-to-world transform at `time_secs`: turned by its heading, carried ahead at its
    /// speed.
    #[must_use]
    pub fn world_from_model(&self, time_secs: f64) -> Mat4 {
        let turn = Quat::from_rotation_y(self.heading_deg.to_radians());
        let travelled = (turn * Vec3::Z) * (self.speed * time_secs as f32);
        Mat4::from_rotation_translation(turn, self.position + travelled)
    }

    /// Its clip's time at scene time `time_secs`.
    #[must_use]
    pub fn clip_time(&self, time_secs: f64) -> f64 {
        time_secs + self.time_offset_secs
    }

    /// Where it stands at `time_secs`.
    #[must_use]
    pub fn position_at(&self, time_secs: f64) -> Vec3 {
        self.world_from_model(time_secs).w_axis.truncate()
    }
}

/// Checks every instance: finite position, heading, speed and offset.
///
/// # Errors
/// `(key, problem)`, the key as `instance[i].field`.
pub fn validate(instances: &[HerdInstance]) -> Result<(), (String, String)> {
    for (i, instance) in instances.iter().enumerate() {
        let key = |field: &str| format!("instance[{i}].{field}");
        if !instance.position.is_finite() {
            return Err((key("position"), format!("must be finite, got {}", instance.position)));
        }
        if !(instance.heading_deg.is_finite() && instance.heading_deg.abs() <= 3600.0) {
            return Err((key("heading_deg"), format!("must be between -3600 and 3600, got {}", instance.heading_deg)));
        }
        if !instance.speed.is_finite() {
            return Err((key("speed"), format!("must be finite, got {}", instance.speed)));
        }
        if !(instance.time_offset_secs.is_finite() && instance.time_offset_secs >= 0.0) {
            return Err((
                key("time_offset_secs"),
                format!("must be finite and at least 0, got {}", instance.time_offset_secs),
            ));
        }
        if !(instance.tint.is_finite() && instance.tint.min_element() >= 0.0) {
            return Err((key("tint"), format!("must be three finite numbers of at least 0, got {}", instance.tint)));
        }
        if !(instance.length_scale.is_finite()
            && instance.length_scale > 0.0
            && instance.length_scale <= MAX_LENGTH_SCALE)
        {
            return Err((
                key("length_scale"),
                format!("must be above 0 and at most {MAX_LENGTH_SCALE}, got {}", instance.length_scale),
            ));
        }
        if instance.clip.as_deref() == Some("") {
            return Err((key("clip"), "must name a clip (or be left out for the host's)".into()));
        }
    }
    Ok(())
}

/// Each instance's clip in `rig`: its `clip` found by name or index, else `default`.
///
/// # Errors
/// `(key, problem)` for a clip the rig lacks (the problem lists the file's clips) or any clip
/// without a rig.
pub fn resolve_clips(
    instances: &[HerdInstance],
    rig: Option<&Rig>,
    default: Option<usize>,
) -> Result<Vec<Option<usize>>, (String, String)> {
    instances
        .iter()
        .enumerate()
        .map(|(i, instance)| match (&instance.clip, rig) {
            (None, _) => Ok(default),
            (Some(name), Some(rig)) => {
                rig.find_animation(name).map(Some).map_err(|e| (format!("instance[{i}].clip"), e))
            }
            (Some(name), None) => {
                Err((format!("instance[{i}].clip"), format!("no animation {name:?}: the mesh has no animations")))
            }
        })
        .collect()
}

/// The box `instances` of `fur` cover at the times `secs` (every member's mesh at each, with the
/// fur's longest strand about its sides and above; the ground under its feet); `None` for no
/// instances. Hosts fit a herd's shadow maps, ground and camera to it.
#[must_use]
pub fn extent(fur: &crate::FurStructure, instances: &[HerdInstance], secs: &[f64]) -> Option<(Vec3, Vec3)> {
    if instances.is_empty() {
        return None;
    }
    let (low, high) = fur.mesh.bounds();
    let length = Vec3::splat(fur.lengths.iter().copied().fold(0.0, f32::max));
    let corners = [low, high, Vec3::new(low.x, low.y, high.z), Vec3::new(high.x, high.y, low.z)];
    Some(instances.iter().flat_map(|i| secs.iter().map(|&t| i.world_from_model(t))).fold(
        (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
        |(lo, hi), world| {
            corners
                .iter()
                .map(|c| world.transform_point3(*c))
                .fold((lo, hi), |(lo, hi), p| (lo.min(p - length * Vec3::new(1.0, 0.0, 1.0)), hi.max(p + length)))
        },
    ))
}

/// Most instances [`scatter`] places.
pub const MAX_SCATTERED: usize = 100_000;

/// `count` instances on a square field, `spacing` apart on a jittered grid centred on the
/// origin (y = 0), all heading roughly the same way (+X, within 25 degrees), each at its own
/// phase in the first `phase_secs` of its clip; seeded, so the same call places them the same.
///
/// # Errors
/// A message for a count of 0 or above [`MAX_SCATTERED`], or a spacing that is not positive.
pub fn scatter(count: usize, spacing: f32, phase_secs: f64, seed: u64) -> Result<Vec<HerdInstance>, String> {
    if count == 0 {
        return Err("a herd needs at least one instance, got 0".into());
    }
    if count > MAX_SCATTERED {
        return Err(format!("at most {MAX_SCATTERED} instances, got {count}"));
    }
    if !(spacing.is_finite() && spacing > 0.0) {
        return Err(format!("the spacing must be positive, got {spacing}"));
    }
    let columns = (count as f64).sqrt().ceil() as usize;
    let rows = count.div_ceil(columns);
    let unit = |k: usize, channel: u64| rng::unit_f32(rng::hash(seed, k as u64, channel, 0x4e_7d));
    Ok((0..count)
        .map(|k| {
            let (row, column) = (k / columns, k % columns);
            let jitter = Vec3::new(unit(k, 0) - 0.5, 0.0, unit(k, 1) - 0.5) * (0.35 * spacing);
            let grid = Vec3::new(
                (column as f32 - 0.5 * (columns - 1) as f32) * spacing,
                0.0,
                (row as f32 - 0.5 * (rows - 1) as f32) * spacing,
            );
            HerdInstance {
                heading_deg: 90.0 + 50.0 * (unit(k, 2) - 0.5),
                time_offset_secs: f64::from(unit(k, 3)) * phase_secs.max(0.0),
                ..HerdInstance::at(grid + jitter)
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn an_instance_walks_along_its_heading() {
        let instance = HerdInstance { heading_deg: 90.0, speed: 2.0, ..HerdInstance::at(Vec3::new(1.0, 0.0, 0.0)) };
        // +Z turned a quarter about +Y is +X.
        assert!((instance.position_at(1.5) - Vec3::new(4.0, 0.0, 0.0)).length() < 1e-5);
        let ahead = instance.world_from_model(0.0).transform_vector3(Vec3::Z);
        assert!((ahead - Vec3::X).length() < 1e-6);
    }

    #[test]
    fn scatter_places_count_instances_apart_and_the_same_each_time() {
        let herd = scatter(10, 2.0, 1.0, 7).unwrap();
        assert_eq!(herd.len(), 10);
        assert_eq!(herd, scatter(10, 2.0, 1.0, 7).unwrap());
        for (a, instance) in herd.iter().enumerate() {
            for other in &herd[a + 1..] {
                // Grid cells 2 apart, each jittered by at most 0.35 * 2 / 2 per axis.
                assert!((instance.position - other.position).length() > 2.0 - 2.0 * 0.35 * 2.0f32.sqrt());
            }
            assert!((0.0..1.0).contains(&instance.time_offset_secs));
        }
        validate(&herd).unwrap();
    }

    #[test]
    fn bad_herds_are_refused() {
        assert!(scatter(0, 1.0, 1.0, 0).unwrap_err().contains("got 0"));
        assert!(scatter(3, 0.0, 1.0, 0).is_err());
        let nan = [HerdInstance::at(Vec3::ZERO), HerdInstance::at(Vec3::new(f32::NAN, 0.0, 0.0))];
        let (key, problem) = validate(&nan).unwrap_err();
        assert_eq!(key, "instance[1].position");
        assert!(problem.contains("finite"), "{problem}");
        let (key, problem) =
            resolve_clips(&[HerdInstance { clip: Some("Run".into()), ..HerdInstance::at(Vec3::ZERO) }], None, None)
                .unwrap_err();
        assert_eq!(key, "instance[0].clip");
        assert!(problem.contains("no animations"), "{problem}");
    }
}
