//! Wet fur: a wetness per base vertex (0 dry to 1 soaked) that rain, a water level and a sponge
//! raise and drying lowers, and the preset's `[wet]` table saying what wetness does.
//!
//! ```toml
//! [wet]
//! wetness = 0.0          # the coat's wetness at time 0, 0..=1
//! clump_size = 12.0      # clump cells, in shell texels
//! clump_strength = 0.8   # how strongly a soaked coat clumps, 0..=1
//! darkening = 0.5        # albedo times 1 - darkening * wetness
//! shine = 0.6            # highlight strength times 1 + shine * wetness (exponent 1 + 2 shine w)
//! added_weight = 1.0     # gravity on a strand times 1 + added_weight * wetness
//! softening = 0.3        # stability times 1 - softening * wetness
//! drying_per_sec = 0.05  # wetness lost per second
//! wicking = 0.15         # band above a water level that water climbs, fraction of the radius
//! ```
//!
//! Wetness advances in fixed ticks at the simulation's rate from the scene's start, so a frame's
//! wetness depends on its time only (a jump back replays from time 0, as a scene restarts). A
//! strand dries as one: tips do not dry before roots.

use glam::Vec3;

use crate::param::ParamError;

/// The `[wet]` table of a preset.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WetParams {
    /// The whole coat's wetness at time 0 (`pelt render --wetness` sets it), `0..=1`. Default 0.
    pub wetness: f32,
    /// Clump cells, in shell texels (a groom's clump map uses the same cells), `2..=128`.
    /// Default 12.
    pub clump_size: f32,
    /// How strongly a soaked coat clumps, `0..=1`: the clump amount a soaked strand adds to its
    /// groom's. Default 0.8.
    pub clump_strength: f32,
    /// Albedo times `1 - darkening * wetness`, `0..=1`. Default 0.5.
    pub darkening: f32,
    /// Highlight strength times `1 + shine * wetness`, its exponent times `1 + 2 * shine * wetness`,
    /// `0..=8`. Default 0.6.
    pub shine: f32,
    /// Gravity on a strand times `1 + added_weight * wetness`, `0..=10`. Default 1.
    pub added_weight: f32,
    /// Stability times `1 - softening * wetness`, `0..=0.9`. Default 0.3.
    pub softening: f32,
    /// Wetness lost per second, `0..=10`. Default 0.05 (a soaked coat dries in 20 s).
    pub drying_per_sec: f32,
    /// Height of the band above a water level that water wicks up, as a fraction of the mesh's
    /// bounding radius, `0..=2`. Default 0.15.
    pub wicking: f32,
}

impl Default for WetParams {
    fn default() -> Self {
        Self {
            wetness: 0.0,
            clump_size: 12.0,
            clump_strength: 0.8,
            darkening: 0.5,
            shine: 0.6,
            added_weight: 1.0,
            softening: 0.3,
            drying_per_sec: 0.05,
            wicking: 0.15,
        }
    }
}

impl WetParams {
    /// Whether every field is at its default.
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks every field against its documented range; keys are `wet.<field>`.
    ///
    /// # Errors
    /// The first [`ParamError`] found.
    pub fn validate(&self) -> Result<(), ParamError> {
        let checks = [
            ("wetness", self.wetness, 0.0, 1.0),
            ("clump_size", self.clump_size, 2.0, 128.0),
            ("clump_strength", self.clump_strength, 0.0, 1.0),
            ("darkening", self.darkening, 0.0, 1.0),
            ("shine", self.shine, 0.0, 8.0),
            ("added_weight", self.added_weight, 0.0, 10.0),
            ("softening", self.softening, 0.0, 0.9),
            ("drying_per_sec", self.drying_per_sec, 0.0, 10.0),
            ("wicking", self.wicking, 0.0, 2.0),
        ];
        for (key, value, low, high) in checks {
            if !(value.is_finite() && (low..=high).contains(&value)) {
                return Err(ParamError {
                    key: format!("wet.{key}"),
                    problem: format!("must be between {low} and {high}, got {value}"),
                });
            }
        }
        Ok(())
    }

    /// Gravity's factor on a strand of wetness `w`: `1 + added_weight * w`.
    #[must_use]
    pub fn gravity_scale(&self, w: f32) -> f32 {
        1.0 + self.added_weight * w
    }

    /// Stability's factor on a strand of wetness `w`: `1 - softening * w`.
    #[must_use]
    pub fn stability_scale(&self, w: f32) -> f32 {
        1.0 - self.softening * w
    }
}

/// A shower (`[[rain]]` in a scene): from `start_secs` to `end_secs` rain falls along
/// `direction`, wetting a surface at `rate` per second times how squarely it faces the rain.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RainKey {
    /// When the rain starts (seconds of scene time).
    pub start_secs: f64,
    /// When it stops.
    pub end_secs: f64,
    /// The direction the rain falls toward (any non-zero vector). Default straight down.
    #[serde(default = "down")]
    pub direction: Vec3,
    /// Wetness per second on a surface facing the rain squarely, `0..=100`.
    pub rate: f32,
}

fn down() -> Vec3 {
    Vec3::NEG_Y
}

/// A water level keyframe (`[[water]]` in a scene): the plane through `point` with `normal`
/// pointing out of the water. Keys are blended linearly in time (the normals normalised), held
/// before the first and after the last; below the plane the fur is soaked.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct WaterKey {
    /// When this key applies (seconds of scene time).
    pub time_secs: f64,
    /// A point on the water's surface (world units).
    pub point: Vec3,
    /// The surface's normal, out of the water (any non-zero vector). Default up.
    #[serde(default = "up")]
    pub normal: Vec3,
}

fn up() -> Vec3 {
    Vec3::Y
}

/// Checks rain and water keys; errors are `(key, problem)` as a scene reports them.
pub(crate) fn validate(rain: &[RainKey], water: &[WaterKey]) -> Result<(), (String, String)> {
    for (i, key) in rain.iter().enumerate() {
        if !(key.start_secs.is_finite() && key.start_secs >= 0.0) {
            return Err((
                format!("rain[{i}].start_secs"),
                format!("must be finite and at least 0, got {}", key.start_secs),
            ));
        }
        if !(key.end_secs.is_finite() && key.end_secs > key.start_secs) {
            return Err((
                format!("rain[{i}].end_secs"),
                format!("must be finite and later than start_secs, got {}", key.end_secs),
            ));
        }
        if !key.direction.is_finite() || key.direction.length_squared() == 0.0 {
            return Err((
                format!("rain[{i}].direction"),
                format!("must be a finite non-zero vector, got {}", key.direction),
            ));
        }
        if !(key.rate.is_finite() && (0.0..=100.0).contains(&key.rate)) {
            return Err((format!("rain[{i}].rate"), format!("must be between 0 and 100, got {}", key.rate)));
        }
    }
    for (i, key) in water.iter().enumerate() {
        if !(key.time_secs.is_finite() && key.time_secs >= 0.0) {
            return Err((
                format!("water[{i}].time_secs"),
                format!("must be finite and at least 0, got {}", key.time_secs),
            ));
        }
        if i > 0 && key.time_secs < water[i - 1].time_secs {
            return Err((format!("water[{i}].time_secs"), "keyframes must be sorted by time".into()));
        }
        if !key.point.is_finite() {
            return Err((format!("water[{i}].point"), format!("must be finite, got {}", key.point)));
        }
        if !key.normal.is_finite() || key.normal.length_squared() == 0.0 {
            return Err((
                format!("water[{i}].normal"),
                format!("must be a finite non-zero vector, got {}", key.normal),
            ));
        }
    }
    Ok(())
}

/// The water plane at `time_secs` as `(point, unit normal)`, or `None` without keys.
#[must_use]
pub fn water_at(keys: &[WaterKey], time_secs: f64) -> Option<(Vec3, Vec3)> {
    let after = keys.iter().position(|k| k.time_secs > time_secs);
    let (a, b, t) = match after {
        None => (keys.last()?, keys.last()?, 0.0),
        Some(0) => (&keys[0], &keys[0], 0.0),
        Some(i) => {
            let (a, b) = (&keys[i - 1], &keys[i]);
            (a, b, ((time_secs - a.time_secs) / (b.time_secs - a.time_secs)) as f32)
        }
    };
    let normal =
        (a.normal.normalize() * (1.0 - t) + b.normal.normalize() * t).try_normalize().unwrap_or(a.normal.normalize());
    Some((a.point * (1.0 - t) + b.point * t, normal))
}

/// What wets the fur over time: a scene's rain and water keys.
#[derive(Clone, Copy, Debug, Default)]
pub struct WetSources<'a> {
    /// Showers.
    pub rain: &'a [RainKey],
    /// Water level keys.
    pub water: &'a [WaterKey],
}

impl WetSources<'_> {
    /// Whether nothing wets the fur.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.rain.is_empty() && self.water.is_empty()
    }
}

/// The posed base the wetness is advanced on, in the scene's (world) space.
#[derive(Clone, Copy, Debug)]
pub struct WetSurface<'a> {
    /// Base vertex positions.
    pub positions: &'a [Vec3],
    /// Unit base normals.
    pub normals: &'a [Vec3],
    /// The base's bounding radius (the unit of the wicking band).
    pub radius: f32,
}

/// The most ticks a jump replays; a longer jump starts this many ticks before its target.
const MAX_REPLAY_TICKS: i64 = 36_000;

/// A wetness per base vertex, advanced in fixed ticks.
#[derive(Clone, Debug)]
pub struct Wetness {
    values: Vec<f32>,
    /// The tick the values are at (`None`: at the initial wetness, before tick 0).
    tick: Option<i64>,
    initial: f32,
}

impl Wetness {
    /// `vertices` base vertices at `initial` wetness (clamped to `0..=1`).
    #[must_use]
    pub fn new(vertices: usize, initial: f32) -> Self {
        let initial = if initial.is_finite() { initial.clamp(0.0, 1.0) } else { 0.0 };
        Self { values: vec![initial; vertices], tick: None, initial }
    }

    /// One value per base vertex.
    #[must_use]
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// Whether every vertex is dry (exactly 0).
    #[must_use]
    pub fn is_dry(&self) -> bool {
        self.values.iter().all(|&w| w == 0.0)
    }

    /// Sets every vertex (and the wetness a replay starts from) to `wetness`, clamped to `0..=1`.
    pub fn set_uniform(&mut self, wetness: f32) {
        *self = Self::new(self.values.len(), wetness);
    }

    /// Sets the wetness a replay starts from (time 0 and every jump back), clamped to `0..=1`;
    /// the values change only when nothing has been advanced yet.
    pub fn set_initial(&mut self, wetness: f32) {
        self.initial = if wetness.is_finite() { wetness.clamp(0.0, 1.0) } else { 0.0 };
        if self.tick.is_none() {
            self.values.fill(self.initial);
        }
    }

    /// A sponge pressed at `centre` (world units, the space of `positions`): within `radius`,
    /// each vertex's wetness moves toward `amount` (0 dries, 1 soaks) by a smooth falloff
    /// (full at the centre). Non-finite or non-positive input changes nothing.
    pub fn sponge(&mut self, positions: &[Vec3], centre: Vec3, radius: f32, amount: f32) {
        if !(centre.is_finite() && radius.is_finite() && radius > 0.0 && amount.is_finite()) {
            return;
        }
        let amount = amount.clamp(0.0, 1.0);
        for (w, p) in self.values.iter_mut().zip(positions) {
            let d = p.distance(centre) / radius;
            if d < 1.0 {
                let falloff = 1.0 - d * d * (3.0 - 2.0 * d);
                *w = (*w + (amount - *w) * falloff).clamp(0.0, 1.0);
            }
        }
    }

    /// Advances to `time_secs` in ticks of `1 / rate_hz` seconds: every tick, drying, then each
    /// active shower (`rate * max(0, n . -direction)`), then the water (1 below the plane, down
    /// to 0 over the wicking band above it, never lowering), on `surface`.
    pub fn advance_to(
        &mut self,
        time_secs: f64,
        rate_hz: f32,
        sources: WetSources<'_>,
        params: &WetParams,
        surface: WetSurface<'_>,
    ) {
        let WetSurface { positions, normals, radius } = surface;
        if !time_secs.is_finite() {
            return;
        }
        let rate = f64::from(rate_hz.max(1.0));
        let target = (time_secs * rate).floor() as i64;
        let mut next = match self.tick {
            Some(tick) if tick <= target => tick + 1,
            // A jump back: the scene starts over.
            _ => {
                self.values.fill(self.initial);
                0
            }
        };
        next = next.max(target - MAX_REPLAY_TICKS);
        if sources.is_empty() && (params.drying_per_sec == 0.0 || self.is_dry()) {
            self.tick = Some(target.max(next - 1));
            return;
        }
        let dt = (1.0 / rate) as f32;
        let band = params.wicking * radius;
        for tick in next..=target {
            let t = tick as f64 / rate;
            let rain: Vec<(Vec3, f32)> = sources
                .rain
                .iter()
                .filter(|r| (r.start_secs..r.end_secs).contains(&t))
                .map(|r| (-r.direction.normalize(), r.rate * dt))
                .collect();
            let water = water_at(sources.water, t);
            for ((w, p), n) in self.values.iter_mut().zip(positions).zip(normals) {
                let mut value = (*w - params.drying_per_sec * dt).max(0.0);
                for (toward_sky, amount) in &rain {
                    value += amount * n.dot(*toward_sky).max(0.0);
                }
                if let Some((point, normal)) = water {
                    let height = normal.dot(*p - point);
                    let soak = if height <= 0.0 {
                        1.0
                    } else if band > 0.0 {
                        (1.0 - height / band).max(0.0)
                    } else {
                        0.0
                    };
                    value = value.max(soak);
                }
                *w = value.clamp(0.0, 1.0);
            }
        }
        self.tick = Some(target);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn surface<'a>(positions: &'a [Vec3], normals: &'a [Vec3]) -> WetSurface<'a> {
        WetSurface { positions, normals, radius: 1.0 }
    }

    #[test]
    fn rain_wets_what_faces_it_and_drying_returns_to_exactly_zero() {
        let rain = [RainKey { start_secs: 0.0, end_secs: 1.0, direction: Vec3::NEG_Y, rate: 0.5 }];
        let params = WetParams { drying_per_sec: 0.1, ..WetParams::default() };
        let positions = [Vec3::ZERO, Vec3::ZERO, Vec3::ZERO];
        let normals = [Vec3::Y, Vec3::NEG_Y, Vec3::X];
        let mut wet = Wetness::new(3, 0.0);
        let sources = WetSources { rain: &rain, water: &[] };
        wet.advance_to(1.0, 30.0, sources, &params, surface(&positions, &normals));
        let w = wet.values();
        assert!(w[0] > 0.35 && w[0] < 0.45, "facing the rain: {}", w[0]);
        assert_eq!(w[1], 0.0, "facing away stays dry");
        assert_eq!(w[2], 0.0, "side-on stays dry");
        wet.advance_to(10.0, 30.0, sources, &params, surface(&positions, &normals));
        assert!(wet.is_dry(), "dried back to exactly 0: {:?}", wet.values());
    }

    #[test]
    fn water_soaks_below_and_wicks_above() {
        let water = [WaterKey { time_secs: 0.0, point: Vec3::ZERO, normal: Vec3::Y }];
        let params = WetParams { wicking: 0.5, ..WetParams::default() };
        let positions = [Vec3::new(0.0, -1.0, 0.0), Vec3::new(0.0, 0.25, 0.0), Vec3::new(0.0, 2.0, 0.0)];
        let mut wet = Wetness::new(3, 0.0);
        wet.advance_to(0.0, 30.0, WetSources { rain: &[], water: &water }, &params, surface(&positions, &[Vec3::Y; 3]));
        assert_eq!(wet.values(), &[1.0, 0.5, 0.0]);
    }

    #[test]
    fn a_jump_back_replays_to_the_same_values() {
        let water = [
            WaterKey { time_secs: 0.0, point: Vec3::new(0.0, -2.0, 0.0), normal: Vec3::Y },
            WaterKey { time_secs: 2.0, point: Vec3::new(0.0, 1.0, 0.0), normal: Vec3::Y },
        ];
        let positions: Vec<Vec3> = (0..8).map(|i| Vec3::new(0.0, i as f32 * 0.3 - 1.0, 0.0)).collect();
        let normals = vec![Vec3::Y; 8];
        let sources = WetSources { rain: &[], water: &water };
        let params = WetParams::default();
        let mut stepped = Wetness::new(8, 0.0);
        for frame in 0..=90 {
            stepped.advance_to(f64::from(frame) / 24.0, 30.0, sources, &params, surface(&positions, &normals));
        }
        let mut jumped = Wetness::new(8, 0.0);
        jumped.advance_to(1.0, 30.0, sources, &params, surface(&positions, &normals));
        jumped.advance_to(90.0 / 24.0, 30.0, sources, &params, surface(&positions, &normals));
        assert_eq!(stepped.values(), jumped.values());
    }

    #[test]
    fn bad_keys_are_named() {
        let nan_rain =
            [RainKey { start_secs: 0.0, end_secs: 1.0, direction: Vec3::new(f32::NAN, -1.0, 0.0), rate: 1.0 }];
        assert_eq!(validate(&nan_rain, &[]).unwrap_err().0, "rain[0].direction");
        let flat = [WaterKey { time_secs: 0.0, point: Vec3::ZERO, normal: Vec3::ZERO }];
        assert_eq!(validate(&[], &flat).unwrap_err().0, "water[0].normal");
        let params = WetParams { wetness: 1.5, ..WetParams::default() };
        assert_eq!(params.validate().unwrap_err().key, "wet.wetness");
    }
}
