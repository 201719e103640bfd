//! Scripted rigid motion of the furred mesh (and the plain meshes with it): keyframed
//! translation and rotation with easing, the `[[motion]]` keys of a scene script.
//!
//! ```toml
//! [[motion]]
//! time_secs = 0.0
//! translation = [0.0, 0.0, 0.0]    # optional, default 0
//! rotation_deg = [0.0, 90.0, 0.0]  # optional: turns about X, Y, Z in degrees (applied Y, X, Z)
//! ease = "in_out"                  # toward the next key: linear (default), in_out, in, out, step
//! ```
//!
//! The transform is `translate(translation) * rotate(rotation)`: rotations turn the meshes
//! about the world origin of their files, then they move. Between keys the translation is
//! interpolated and the rotation slerped, at the eased fraction of the time between them.

use glam::{EulerRot, Mat4, Quat, Vec3};

/// How the fraction of time between two keys is shaped.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Ease {
    /// Constant speed.
    #[default]
    Linear,
    /// Starts and ends at rest (smoothstep).
    InOut,
    /// Starts at rest.
    In,
    /// Ends at rest.
    Out,
    /// Holds this key until the next.
    Step,
}

impl Ease {
    /// The eased fraction for `t` in `0..=1`.
    #[must_use]
    pub fn apply(self, t: f32) -> f32 {
        let t = t.clamp(0.0, 1.0);
        match self {
            Self::Linear => t,
            Self::InOut => t * t * (3.0 - 2.0 * t),
            Self::In => t * t,
            Self::Out => t * (2.0 - t),
            Self::Step => 0.0,
        }
    }
}

/// One keyframe of the meshes' rigid motion.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct MotionKey {
    /// When this key applies (seconds of scene time).
    pub time_secs: f64,
    /// Where the meshes are moved to.
    #[serde(default)]
    pub translation: Vec3,
    /// Turns about X, Y and Z in degrees (applied in the order Y, X, Z).
    #[serde(default)]
    pub rotation_deg: Vec3,
    /// Easing toward the next key.
    #[serde(default)]
    pub ease: Ease,
}

impl MotionKey {
    /// This key's rotation.
    #[must_use]
    pub fn rotation(&self) -> Quat {
        let r = self.rotation_deg * (std::f32::consts::PI / 180.0);
        Quat::from_euler(EulerRot::YXZ, r.y, r.x, r.z)
    }
}

/// The meshes' transform at `time_secs` from sorted `keys` (held before the first and after
/// the last); `None` without keys.
#[must_use]
pub fn motion_at(keys: &[MotionKey], time_secs: f64) -> Option<Mat4> {
    let after = keys.iter().position(|k| k.time_secs > time_secs);
    let (translation, rotation) = match after {
        None => keys.last().map(|k| (k.translation, k.rotation()))?,
        Some(0) => (keys[0].translation, keys[0].rotation()),
        Some(i) => {
            let (a, b) = (&keys[i - 1], &keys[i]);
            let t = a.ease.apply(((time_secs - a.time_secs) / (b.time_secs - a.time_secs)) as f32);
            (a.translation.lerp(b.translation, t), a.rotation().slerp(b.rotation(), t))
        }
    };
    Some(Mat4::from_rotation_translation(rotation, translation))
}

/// Checks keys: finite, sorted, times at least 0. Returns the bad key and what is wrong.
pub(super) fn validate(keys: &[MotionKey]) -> Result<(), (String, String)> {
    for (i, key) in keys.iter().enumerate() {
        if !(key.time_secs.is_finite() && key.time_secs >= 0.0) {
            return Err((
                format!("motion[{i}].time_secs"),
                format!("must be finite and at least 0, got {}", key.time_secs),
            ));
        }
        if i > 0 && key.time_secs < keys[i - 1].time_secs {
            return Err((format!("motion[{i}].time_secs"), "keyframes must be sorted by time".into()));
        }
        if !key.translation.is_finite() {
            return Err((format!("motion[{i}].translation"), format!("must be finite, got {}", key.translation)));
        }
        if !key.rotation_deg.is_finite() {
            return Err((format!("motion[{i}].rotation_deg"), format!("must be finite, got {}", key.rotation_deg)));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn key(time_secs: f64, x: f32, yaw: f32, ease: Ease) -> MotionKey {
        MotionKey { time_secs, translation: Vec3::new(x, 0.0, 0.0), rotation_deg: Vec3::new(0.0, yaw, 0.0), ease }
    }

    #[test]
    fn keys_interpolate_with_their_easing() {
        assert!(motion_at(&[], 1.0).is_none());
        let keys = [key(1.0, 0.0, 0.0, Ease::Linear), key(3.0, 4.0, 90.0, Ease::Linear)];
        let at = |t: f64| motion_at(&keys, t).unwrap();
        assert_eq!(at(0.0).transform_point3(Vec3::ZERO), Vec3::ZERO, "held before the first key");
        assert!(at(2.0).transform_point3(Vec3::ZERO).distance(Vec3::new(2.0, 0.0, 0.0)) < 1e-6);
        // Half of a 90-degree turn about Y takes +X to (cos 45, 0, -sin 45), then moves by 2.
        let p = at(2.0).transform_point3(Vec3::X);
        let h = std::f32::consts::FRAC_1_SQRT_2;
        assert!(p.distance(Vec3::new(2.0 + h, 0.0, -h)) < 1e-5, "{p}");
        assert!(at(9.0).transform_point3(Vec3::ZERO).distance(Vec3::new(4.0, 0.0, 0.0)) < 1e-6, "held after");

        let eased = [key(0.0, 0.0, 0.0, Ease::InOut), key(1.0, 1.0, 0.0, Ease::Linear)];
        let x = |t: f64| motion_at(&eased, t).unwrap().transform_point3(Vec3::ZERO).x;
        assert!((x(0.25) - 0.15625).abs() < 1e-6, "smoothstep(0.25) = 0.15625, got {}", x(0.25));
        assert!((x(0.5) - 0.5).abs() < 1e-6);
        let held = [key(0.0, 0.0, 0.0, Ease::Step), key(1.0, 1.0, 0.0, Ease::Linear)];
        assert_eq!(motion_at(&held, 0.99).unwrap().transform_point3(Vec3::ZERO).x, 0.0);
        assert_eq!(Ease::In.apply(0.5), 0.25);
        assert_eq!(Ease::Out.apply(0.5), 0.75);
    }

    #[test]
    fn bad_keys_name_themselves() {
        let mut keys = vec![key(1.0, 0.0, 0.0, Ease::Linear), key(0.5, 0.0, 0.0, Ease::Linear)];
        assert_eq!(validate(&keys).unwrap_err().0, "motion[1].time_secs");
        keys[1].time_secs = 2.0;
        keys[1].rotation_deg.y = f32::NAN;
        assert_eq!(validate(&keys).unwrap_err().0, "motion[1].rotation_deg");
    }
}
