//! Wind: a direction and strength, gusts that travel across the fur with the wind, and a small
//! seeded jitter so the fur shakes.
//!
//! The gusts are coherent value noise frozen in space and carried along the wind direction
//! (Taylor's frozen turbulence): a strong patch of wind moves over the surface instead of
//! flickering in place. Everything is a pure function of seed, position, vertex and time, so the
//! field at a time never depends on earlier steps or on the thread count.

use glam::{DVec3, Vec3};

use super::{MAX_FORCE, ParamError};
use crate::rng;

/// Wind parameters (`[simulation.wind]` of a preset). Sizes and speeds are relative to the
/// base mesh's bounding-sphere radius, so one preset suits a mesh of any scale.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WindParams {
    /// Where the wind blows to (any finite non-zero vector). Default `+X`.
    pub direction: Vec3,
    /// Force of the wind, in the units of gravity strength. Default 0 (no wind).
    pub strength: f32,
    /// How much gusts vary the strength: it moves within `strength * (1 +- gust_strength)`.
    /// `0..=1`, default 0.5.
    pub gust_strength: f32,
    /// Size of a gust, in bounding radii. Default 0.5.
    pub gust_scale: f32,
    /// How fast gusts travel along the wind, in bounding radii per second. Default 1.
    pub gust_speed: f32,
    /// Random shake per vertex, as a fraction of `strength`. `0..=1`, default 0.1.
    pub jitter: f32,
    /// How often the shake changes direction (it blends smoothly in between). Default 6 Hz.
    pub jitter_hz: f32,
    /// Seed of gusts and jitter.
    pub seed: u64,
}

impl Default for WindParams {
    fn default() -> Self {
        Self {
            direction: Vec3::X,
            strength: 0.0,
            gust_strength: 0.5,
            gust_scale: 0.5,
            gust_speed: 1.0,
            jitter: 0.1,
            jitter_hz: 6.0,
            seed: 0,
        }
    }
}

impl WindParams {
    /// Checks every field; keys are relative to `simulation` (e.g. `wind.strength`).
    ///
    /// # Errors
    /// The first [`ParamError`] found.
    pub fn validate(&self) -> Result<(), ParamError> {
        let error = |key: &str, problem: String| Err(ParamError { key: format!("wind.{key}"), problem });
        if !self.direction.is_finite() || self.direction.length_squared() == 0.0 {
            return error("direction", format!("must be a finite non-zero vector, got {}", self.direction));
        }
        let checks: [(&str, f32, f32, f32); 6] = [
            ("strength", self.strength, 0.0, MAX_FORCE),
            ("gust_strength", self.gust_strength, 0.0, 1.0),
            ("gust_scale", self.gust_scale, 1e-4, 1e4),
            ("gust_speed", self.gust_speed, 0.0, 1e4),
            ("jitter", self.jitter, 0.0, 1.0),
            ("jitter_hz", self.jitter_hz, 0.0, 1000.0),
        ];
        for (key, value, low, high) in checks {
            if !(value.is_finite() && (low..=high).contains(&value)) {
                return error(key, format!("must be between {low} and {high}, got {value}"));
            }
        }
        Ok(())
    }

    /// The wind force on `vertex` at `position` and `time_secs`; `radius` is the base mesh's
    /// bounding radius (the unit of `gust_scale` and `gust_speed`).
    #[must_use]
    pub fn sample(&self, vertex: usize, position: Vec3, time_secs: f64, radius: f32) -> Vec3 {
        let Some(direction) = self.direction.try_normalize() else { return Vec3::ZERO };
        if self.strength == 0.0 {
            return Vec3::ZERO;
        }
        let gust_size = f64::from(self.gust_scale) * f64::from(radius.max(f32::MIN_POSITIVE));
        let travelled = direction.as_dvec3() * (f64::from(self.gust_speed) / f64::from(self.gust_scale) * time_secs);
        let gust = value_noise3(self.seed, position.as_dvec3() / gust_size - travelled);
        let mut force = direction * (self.strength * (1.0 + self.gust_strength * gust));
        if self.jitter > 0.0 {
            let t = time_secs * f64::from(self.jitter_hz);
            let tick = t.floor();
            let blend = smoothstep((t - tick) as f32);
            let tick = tick as i64 as u64;
            let a = random_vector(self.seed, vertex as u64, tick);
            let b = random_vector(self.seed, vertex as u64, tick.wrapping_add(1));
            force += (a * (1.0 - blend) + b * blend) * (self.strength * self.jitter);
        }
        force
    }
}

/// A seeded random vector in `[-1, 1]^3` for one vertex and tick (21 random bits per axis from
/// one hash: plenty for a shake, and a third of the hashing).
fn random_vector(seed: u64, vertex: u64, tick: u64) -> Vec3 {
    let bits = rng::hash(seed ^ 0x6A69_7474_6572, vertex, tick, 0);
    let axis = |shift: u32| ((bits >> shift) & 0x1F_FFFF) as f32 * (2.0 / 2_097_152.0) - 1.0;
    Vec3::new(axis(0), axis(21), axis(42))
}

/// One `mix64` per lattice corner: the coordinates are spread by odd constants first, which is
/// enough for value noise and a quarter of the cost of [`rng::hash`] (the wind is evaluated for
/// every vertex every step).
#[inline]
fn corner_bits(seed: u64, x: i64, y: i64, z: i64) -> u64 {
    rng::mix64(
        seed ^ (x as u64).wrapping_mul(0x9E37_79B9_7F4A_7C15)
            ^ (y as u64).wrapping_mul(0xC2B2_AE3D_27D4_EB4F)
            ^ (z as u64).wrapping_mul(0x1656_67B1_9E37_79F9),
    )
}

fn smoothstep(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

/// Seeded 3D value noise in `[-1, 1]`, smooth (C1) between integer lattice points.
///
/// Computed in `f64` so positions far from the origin (long runs advect far) keep their detail.
#[must_use]
pub fn value_noise3(seed: u64, point: DVec3) -> f32 {
    let cell = point.floor();
    let fraction = (point - cell).as_vec3();
    let [x, y, z] = [cell.x as i64, cell.y as i64, cell.z as i64];
    let seed = rng::mix64(seed);
    let corner = |dx: i64, dy: i64, dz: i64| {
        let bits = corner_bits(seed, x.wrapping_add(dx), y.wrapping_add(dy), z.wrapping_add(dz));
        rng::unit_f32(bits) * 2.0 - 1.0
    };
    let (u, v, w) = (smoothstep(fraction.x), smoothstep(fraction.y), smoothstep(fraction.z));
    let lerp = |a: f32, b: f32, t: f32| a + (b - a) * t;
    let x00 = lerp(corner(0, 0, 0), corner(1, 0, 0), u);
    let x10 = lerp(corner(0, 1, 0), corner(1, 1, 0), u);
    let x01 = lerp(corner(0, 0, 1), corner(1, 0, 1), u);
    let x11 = lerp(corner(0, 1, 1), corner(1, 1, 1), u);
    lerp(lerp(x00, x10, v), lerp(x01, x11, v), w)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn noise_is_bounded_continuous_and_seeded() {
        let mut previous = value_noise3(3, DVec3::ZERO);
        for i in 1..2000 {
            let p = DVec3::new(f64::from(i) * 0.01, f64::from(i) * 0.007, -f64::from(i) * 0.003);
            let n = value_noise3(3, p);
            assert!((-1.0..=1.0).contains(&n));
            assert!((n - previous).abs() < 0.1, "jump at {p}");
            previous = n;
        }
        let p = DVec3::new(0.5, 1.5, 2.5);
        assert_ne!(value_noise3(3, p), value_noise3(4, p));
    }

    #[test]
    fn gusts_travel_with_the_wind() {
        let wind = WindParams { strength: 1.0, jitter: 0.0, gust_speed: 2.0, ..WindParams::default() };
        // What blows at x at time 0 reaches x + speed * t (in radii) at time t.
        for i in 0..50 {
            let x = i as f32 * 0.13;
            let here = wind.sample(0, Vec3::new(x, 0.3, 0.1), 0.0, 1.0);
            let later = wind.sample(0, Vec3::new(x + 2.0 * 0.75, 0.3, 0.1), 0.75, 1.0);
            assert!(here.distance(later) < 1e-4, "{here} vs {later}");
        }
    }

    #[test]
    fn no_strength_no_wind_and_strength_bounds_the_force() {
        let calm = WindParams::default();
        assert_eq!(calm.sample(7, Vec3::ONE, 3.0, 1.0), Vec3::ZERO);
        let wind = WindParams { strength: 2.0, ..WindParams::default() };
        for i in 0..500 {
            let f = wind.sample(i, Vec3::splat(i as f32 * 0.1), f64::from(i as u32) * 0.05, 1.0);
            let bound = 2.0 * (1.0 + wind.gust_strength) + 2.0 * wind.jitter * 3f32.sqrt();
            assert!(f.length() <= bound + 1e-4 && f.x > 0.0, "{f}");
        }
    }
}
