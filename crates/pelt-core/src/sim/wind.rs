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
    /// bounding radius (the unit of `gust_scale` and `gust_speed`). For many vertices at one
    /// time, make the [`WindStep`] once and ask it for each.
    #[must_use]
    pub fn sample(&self, vertex: usize, position: Vec3, time_secs: f64, radius: f32) -> Vec3 {
        WindStep::new(self, time_secs, radius).force(vertex, position)
    }
}

/// The wind of one step: everything [`WindParams`] and the time give every vertex alike,
/// computed once per step. [`WindStep::force`] is the force on one vertex. A kernel without f64
/// (a GPU's) takes the gust travel as whole cells plus a fraction, so its f32 arithmetic stays
/// as precise far from the start as near it, and the seeds and jitter ticks as 64-bit integers.
#[derive(Clone, Copy, Debug, PartialEq)]
#[non_exhaustive]
pub struct WindStep {
    /// The unit direction the wind blows to; zero without wind.
    pub direction: Vec3,
    /// The wind's strength; 0 without wind (no strength or no usable direction), and then the
    /// force is zero everywhere.
    pub strength: f32,
    /// How much gusts vary the strength ([`WindParams::gust_strength`]).
    pub gust_strength: f32,
    /// World units per gust-noise cell: the gust scale times the bounding radius.
    pub gust_size: f64,
    /// How far the gusts have travelled along the wind by this step, in noise cells: the noise
    /// is read at `position / gust_size - gust_travel`.
    pub gust_travel: DVec3,
    /// The whole cells of `gust_travel`: its floor per axis (saturated to `i64`).
    pub gust_travel_cells: [i64; 3],
    /// The rest of `gust_travel`, `gust_travel - floor(gust_travel)`, each axis in `[0, 1]`.
    pub gust_travel_fraction: Vec3,
    /// The gust noise's seed, mixed once as [`value_noise3`] mixes its seed.
    pub noise_seed: u64,
    /// The seed of the jitter's random vectors (the wind's seed, salted).
    pub jitter_seed: u64,
    /// The two jitter ticks this step blends between: `floor(time_secs * jitter_hz)` and the
    /// next.
    pub jitter_ticks: [u64; 2],
    /// The second tick's weight in the blend (smoothstepped).
    pub jitter_blend: f32,
    /// The jitter's scale, strength times [`WindParams::jitter`]; `None` without jitter.
    pub jitter_force: Option<f32>,
}

impl WindStep {
    /// The wind of `wind` at `time_secs`; `radius` is the base mesh's bounding radius (the unit
    /// of `gust_scale` and `gust_speed`).
    #[must_use]
    pub fn new(wind: &WindParams, time_secs: f64, radius: f32) -> Self {
        let (direction, strength) = match wind.direction.try_normalize() {
            Some(direction) if wind.strength != 0.0 => (direction, wind.strength),
            _ => (Vec3::ZERO, 0.0),
        };
        let gust_size = f64::from(wind.gust_scale) * f64::from(radius.max(f32::MIN_POSITIVE));
        let gust_travel = direction.as_dvec3() * (f64::from(wind.gust_speed) / f64::from(wind.gust_scale) * time_secs);
        let whole = gust_travel.floor();
        let ticks = time_secs * f64::from(wind.jitter_hz);
        let tick = ticks.floor();
        let jitter_blend = smoothstep((ticks - tick) as f32);
        let tick = tick as i64 as u64;
        Self {
            direction,
            strength,
            gust_strength: wind.gust_strength,
            gust_size,
            gust_travel,
            gust_travel_cells: [whole.x as i64, whole.y as i64, whole.z as i64],
            gust_travel_fraction: (gust_travel - whole).as_vec3(),
            noise_seed: rng::mix64(wind.seed),
            jitter_seed: wind.seed ^ JITTER_SALT,
            jitter_ticks: [tick, tick.wrapping_add(1)],
            jitter_blend,
            jitter_force: (wind.jitter > 0.0).then_some(strength * wind.jitter),
        }
    }

    /// The wind force on `vertex` at `position`.
    #[must_use]
    pub fn force(&self, vertex: usize, position: Vec3) -> Vec3 {
        if self.strength == 0.0 {
            return Vec3::ZERO;
        }
        let gust = value_noise3_mixed(self.noise_seed, position.as_dvec3() / self.gust_size - self.gust_travel);
        let mut force = self.direction * (self.strength * (1.0 + self.gust_strength * gust));
        if let Some(jitter_force) = self.jitter_force {
            let blend = self.jitter_blend;
            let a = random_vector(self.jitter_seed, vertex as u64, self.jitter_ticks[0]);
            let b = random_vector(self.jitter_seed, vertex as u64, self.jitter_ticks[1]);
            force += (a * (1.0 - blend) + b * blend) * jitter_force;
        }
        force
    }
}

/// What the jitter's seed is salted with, so its vectors differ from the gusts' noise.
const JITTER_SALT: u64 = 0x6A69_7474_6572;

/// A seeded random vector in `[-1, 1]^3` for one vertex and tick (21 random bits per axis from
/// one hash: plenty for a shake, and a third of the hashing); `seed` is already salted.
fn random_vector(seed: u64, vertex: u64, tick: u64) -> Vec3 {
    let bits = rng::hash(seed, vertex, tick, 0);
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
    value_noise3_mixed(rng::mix64(seed), point)
}

/// [`value_noise3`] with its seed already mixed.
fn value_noise3_mixed(seed: u64, point: DVec3) -> f32 {
    let cell = point.floor();
    let fraction = (point - cell).as_vec3();
    let [x, y, z] = [cell.x as i64, cell.y as i64, cell.z as i64];
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
    fn a_step_splits_the_gust_travel_into_whole_cells_and_a_fraction() {
        let wind = WindParams {
            strength: 1.0,
            gust_speed: 3.0,
            direction: Vec3::new(-1.0, 0.5, 2.0),
            ..WindParams::default()
        };
        for time_secs in [0.0, 0.37, 1e3, 1e7, -2.5] {
            let step = WindStep::new(&wind, time_secs, 0.8);
            for axis in 0..3 {
                let fraction = step.gust_travel_fraction[axis];
                assert!((0.0..=1.0).contains(&fraction), "{fraction}");
                let rebuilt = step.gust_travel_cells[axis] as f64 + f64::from(fraction);
                assert!((rebuilt - step.gust_travel[axis]).abs() < 1e-6, "{rebuilt} vs {}", step.gust_travel[axis]);
            }
            assert_eq!(step.jitter_ticks[1], step.jitter_ticks[0].wrapping_add(1));
            assert_eq!(step.force(3, Vec3::ONE), wind.sample(3, Vec3::ONE, time_secs, 0.8));
        }
        let calm = WindStep::new(&WindParams { jitter: 0.0, ..wind.clone() }, 1.0, 1.0);
        assert_eq!(calm.jitter_force, None);
        let still = WindStep::new(&WindParams { strength: 0.0, ..wind }, 1.0, 1.0);
        assert_eq!((still.direction, still.strength, still.gust_travel), (Vec3::ZERO, 0.0, DVec3::ZERO));
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
