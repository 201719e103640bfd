//! Keyframe samplers: glTF's LINEAR, STEP and CUBICSPLINE interpolation of translations,
//! rotations, scales and morph weights.

use glam::{Quat, Vec4};

/// How a sampler interpolates between its keys (glTF `animation.sampler.interpolation`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "SCREAMING_SNAKE_CASE")]
pub enum Interpolation {
    /// Linear; rotations by spherical linear interpolation (the shorter arc).
    Linear,
    /// The value of the key at or before the time.
    Step,
    /// Cubic Hermite spline with an in-tangent, a value and an out-tangent per key; rotations
    /// are normalised after interpolation.
    CubicSpline,
}

/// What a sampler's values mean: a rotation is interpolated as a quaternion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ValueKind {
    /// Components interpolated independently (translation, scale, morph weights).
    Vector,
    /// A unit quaternion `[x, y, z, w]`.
    Rotation,
}

/// One animation sampler: key times and `width` values per key (three times that for
/// CUBICSPLINE: in-tangent, value, out-tangent).
#[derive(Clone, Debug, PartialEq)]
pub struct Sampler {
    /// The interpolation.
    pub interpolation: Interpolation,
    /// Key times in seconds, non-decreasing, finite.
    pub times: Vec<f32>,
    /// Key values, flattened (`width` floats per value).
    pub values: Vec<f32>,
    /// Floats per value: 3 for translation and scale, 4 for rotation, the morph target count for
    /// weights.
    pub width: usize,
}

impl Sampler {
    /// Checks the key counts and that every key is finite and the times never decrease.
    ///
    /// # Errors
    /// What is wrong, in words.
    pub fn validate(&self) -> Result<(), String> {
        if self.times.is_empty() {
            return Err("the sampler has no keys".to_owned());
        }
        if self.width == 0 {
            return Err("the sampler's values are empty".to_owned());
        }
        let per_key = if self.interpolation == Interpolation::CubicSpline { 3 } else { 1 };
        let expected = self.times.len() * self.width * per_key;
        if self.values.len() != expected {
            return Err(format!(
                "{} keys need {expected} output values, the sampler has {}",
                self.times.len(),
                self.values.len()
            ));
        }
        if let Some(t) = self.times.iter().find(|t| !t.is_finite()) {
            return Err(format!("non-finite key time {t}"));
        }
        if let Some(v) = self.values.iter().find(|v| !v.is_finite()) {
            return Err(format!("non-finite key value {v}"));
        }
        if let Some(k) = self.times.windows(2).position(|w| w[1] < w[0]) {
            return Err(format!("key times decrease at key {} ({} after {})", k + 1, self.times[k + 1], self.times[k]));
        }
        Ok(())
    }

    /// The first and last key times.
    #[must_use]
    pub fn time_range(&self) -> (f32, f32) {
        (self.times.first().copied().unwrap_or(0.0), self.times.last().copied().unwrap_or(0.0))
    }

    /// Samples at `time` (clamped to the keys) into `out` (`width` floats). Assumes a sampler
    /// that passed [`Sampler::validate`].
    pub(crate) fn sample(&self, kind: ValueKind, time: f32, out: &mut [f32]) {
        let w = self.width;
        let cubic = self.interpolation == Interpolation::CubicSpline;
        // The value of key k (the middle of the three entries for a cubic spline).
        let value = |k: usize| {
            let start = if cubic { (3 * k + 1) * w } else { k * w };
            &self.values[start..start + w]
        };
        let last = self.times.len() - 1;
        // The key at or before `time` (the first key before the first time).
        let k = self.times.partition_point(|&t| t <= time).saturating_sub(1);
        if time <= self.times[0] || k >= last {
            let key = if time <= self.times[0] { 0 } else { last };
            out.copy_from_slice(value(key));
            normalise_rotation(kind, out);
            return;
        }
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        let span = t1 - t0;
        let u = if span > 0.0 { ((time - t0) / span).clamp(0.0, 1.0) } else { 1.0 };
        match self.interpolation {
            Interpolation::Step => out.copy_from_slice(value(k)),
            Interpolation::Linear => match kind {
                ValueKind::Vector => {
                    for ((o, a), b) in out.iter_mut().zip(value(k)).zip(value(k + 1)) {
                        *o = a + (b - a) * u;
                    }
                }
                ValueKind::Rotation => {
                    let a = Quat::from_slice(value(k)).normalize();
                    let b = Quat::from_slice(value(k + 1)).normalize();
                    out.copy_from_slice(&a.slerp(b, u).to_array());
                }
            },
            Interpolation::CubicSpline => {
                // glTF 2.0 Appendix C: p(u) = (2u^3 - 3u^2 + 1) v_k + span (u^3 - 2u^2 + u) b_k
                //   + (-2u^3 + 3u^2) v_k+1 + span (u^3 - u^2) a_k+1
                let (u2, u3) = (u * u, u * u * u);
                let out_tangent = &self.values[(3 * k + 2) * w..(3 * k + 3) * w];
                let in_tangent = &self.values[3 * (k + 1) * w..(3 * (k + 1) + 1) * w];
                let (v0, v1) = (value(k), value(k + 1));
                for c in 0..w {
                    out[c] = (2.0 * u3 - 3.0 * u2 + 1.0) * v0[c]
                        + span * (u3 - 2.0 * u2 + u) * out_tangent[c]
                        + (-2.0 * u3 + 3.0 * u2) * v1[c]
                        + span * (u3 - u2) * in_tangent[c];
                }
                normalise_rotation(kind, out);
            }
        }
    }
}

fn normalise_rotation(kind: ValueKind, out: &mut [f32]) {
    if kind == ValueKind::Rotation {
        let q = Vec4::from_slice(out).try_normalize().unwrap_or(Vec4::W);
        out.copy_from_slice(&q.to_array());
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sampler(interpolation: Interpolation, times: &[f32], values: &[f32], width: usize) -> Sampler {
        let s = Sampler { interpolation, times: times.to_vec(), values: values.to_vec(), width };
        s.validate().unwrap();
        s
    }

    fn at(s: &Sampler, kind: ValueKind, time: f32) -> Vec<f32> {
        let mut out = vec![0.0; s.width];
        s.sample(kind, time, &mut out);
        out
    }

    #[test]
    fn linear_and_step_match_hand_computed_values() {
        let s = sampler(Interpolation::Linear, &[0.0, 1.0, 3.0], &[0.0, 0.0, 0.0, 2.0, 4.0, 6.0, 4.0, 4.0, 4.0], 3);
        assert_eq!(at(&s, ValueKind::Vector, 0.25), [0.5, 1.0, 1.5]);
        // Halfway between key 1 (2, 4, 6) and key 2 (4, 4, 4).
        assert_eq!(at(&s, ValueKind::Vector, 2.0), [3.0, 4.0, 5.0]);
        assert_eq!(at(&s, ValueKind::Vector, -1.0), [0.0, 0.0, 0.0], "clamped before the first key");
        assert_eq!(at(&s, ValueKind::Vector, 9.0), [4.0, 4.0, 4.0], "clamped after the last key");
        let s = Sampler { interpolation: Interpolation::Step, ..s };
        assert_eq!(at(&s, ValueKind::Vector, 0.99), [0.0, 0.0, 0.0]);
        assert_eq!(at(&s, ValueKind::Vector, 1.0), [2.0, 4.0, 6.0]);
        assert_eq!(at(&s, ValueKind::Vector, 2.9), [2.0, 4.0, 6.0]);
    }

    #[test]
    fn rotations_slerp_along_the_shorter_arc() {
        // Identity to 90 degrees about Z; a quarter of the way is 22.5 degrees.
        let half = std::f32::consts::FRAC_1_SQRT_2;
        let s = sampler(Interpolation::Linear, &[0.0, 1.0], &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, half, half], 4);
        let q = at(&s, ValueKind::Rotation, 0.25);
        let angle = 22.5_f32.to_radians();
        let expected = [0.0, 0.0, (angle / 2.0).sin(), (angle / 2.0).cos()];
        for (a, b) in q.iter().zip(expected) {
            assert!((a - b).abs() < 1e-6, "{q:?} vs {expected:?}");
        }
        // The same end rotation written as -q: slerp still takes the 90-degree arc, not 270.
        let s = sampler(Interpolation::Linear, &[0.0, 1.0], &[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -half, -half], 4);
        let q = Quat::from_slice(&at(&s, ValueKind::Rotation, 0.5));
        assert!((q.angle_between(Quat::IDENTITY) - 45_f32.to_radians()).abs() < 1e-5);
    }

    #[test]
    fn cubic_spline_matches_the_hermite_formula() {
        // One component; keys (t=0, v=1, out-tangent 2) and (t=2, in-tangent -1, v=3).
        // u = 0.5, span 2: h00 = 0.5, h10 = 0.125, h01 = 0.5, h11 = -0.125
        // p = 0.5 * 1 + 2 * 0.125 * 2 + 0.5 * 3 + 2 * (-0.125) * (-1) = 0.5 + 0.5 + 1.5 + 0.25
        let s = sampler(Interpolation::CubicSpline, &[0.0, 2.0], &[9.0, 1.0, 2.0, -1.0, 3.0, 9.0], 1);
        assert!((at(&s, ValueKind::Vector, 1.0)[0] - 2.75).abs() < 1e-6);
        assert_eq!(at(&s, ValueKind::Vector, 0.0), [1.0]);
        assert_eq!(at(&s, ValueKind::Vector, 2.0), [3.0]);
        // Rotations come back unit length.
        let r = sampler(
            Interpolation::CubicSpline,
            &[0.0, 1.0],
            &[
                0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0,
                0.0, 0.0, 0.0, 0.0,
            ],
            4,
        );
        let q = Vec4::from_slice(&at(&r, ValueKind::Rotation, 0.3));
        assert!((q.length() - 1.0).abs() < 1e-6);
    }

    #[test]
    fn broken_samplers_say_what_is_wrong() {
        let bad = |times: &[f32], values: &[f32]| {
            Sampler { interpolation: Interpolation::Linear, times: times.to_vec(), values: values.to_vec(), width: 1 }
                .validate()
                .unwrap_err()
        };
        assert!(bad(&[], &[]).contains("no keys"));
        assert!(bad(&[0.0, f32::NAN], &[0.0, 1.0]).contains("non-finite key time"));
        assert!(bad(&[0.0, 1.0], &[0.0, f32::INFINITY]).contains("non-finite key value"));
        assert!(bad(&[1.0, 0.0], &[0.0, 1.0]).contains("decrease"));
        assert!(bad(&[0.0, 1.0], &[0.0]).contains("need 2"));
    }
}
