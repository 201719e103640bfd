//! Lights and the environment as data, with no GPU: what a scene script's `[[light]]` and
//! `[environment]` tables, `pelt render --light` and an embedder give, in physical units, and
//! what the renderer takes from them ([`LightSource`], [`Environment`]).
//!
//! Units: a directional light's illuminance in lux; a point or spot light's intensity in candela
//! (lumens accepted and converted over the light's solid angle); world units are metres, so a
//! point light of `I` candela gives `I / d^2` lux at `d`. An environment's colours are radiance
//! in the same scale (a uniform environment of radiance `L` gives `pi * L` lux). Pelt's exposure
//! 1 shows 1 lux on a white Lambertian surface as white.

mod environment;
mod sh;

pub use environment::{CubeContent, Environment, EnvironmentError, EnvironmentSpec};
pub use sh::{SH_BANDS, Sh9, sh9_basis};

use glam::Vec3;

/// The most lights one view holds (the renderer's array; a script with more is an error).
pub const MAX_LIGHTS: usize = 8;

/// What kind of light.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LightKind {
    /// A sun: parallel rays from a direction, illuminance in lux.
    #[default]
    Directional,
    /// A bulb: from a position in every direction, intensity in candela, falling off with the
    /// square of the distance.
    Point,
    /// A point light within a cone about its axis, fading from the inner cone to the outer.
    Spot,
}

/// One light as given (a `[[light]]` table, a flag, an embedder): physical units, validated by
/// [`LightSpec::validate`] and resolved to world space by [`LightSpec::source`].
///
/// ```toml
/// [[light]]
/// name = "key"             # optional: tables with one name are keys of one light over time
/// time_secs = 0.0          # optional (default 0): when this key applies
/// kind = "directional"     # "directional" | "point" | "spot"
/// azimuth_deg = 30.0       # directional: where it comes from, around +Y from +Z toward +X
/// elevation_deg = 40.0     # directional: above the horizon
/// lux = 1.0                # directional: illuminance (default 1)
/// colour = [1.0, 0.95, 0.9]  # linear RGB, scaled by the intensity (default white)
/// shadows = true           # whether it casts shadows (default true)
/// # point and spot: position = [x, y, z]; candela = 10.0 or lumens = 125.0
/// # spot: target = [x, y, z] (default the origin), cone_deg = 45 (full outer angle, 0 < c <= 180),
/// # inner_cone_deg = 36 (default 0.8 of the cone)
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct LightSpec {
    /// Keys of one light share a name; unnamed tables are lights of their own.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
    /// When this key applies (seconds of scene time).
    #[serde(default)]
    pub time_secs: f64,
    /// The kind of light.
    #[serde(default)]
    pub kind: LightKind,
    /// Directional: turn of the direction toward the light around +Y from +Z toward +X, degrees.
    #[serde(default)]
    pub azimuth_deg: f32,
    /// Directional: lift of the direction toward the light above the horizon, degrees.
    #[serde(default = "default_elevation")]
    pub elevation_deg: f32,
    /// Point and spot: where the light is (world units).
    #[serde(default)]
    pub position: Vec3,
    /// Spot: the point the cone's axis aims at.
    #[serde(default)]
    pub target: Vec3,
    /// Directional: illuminance in lux.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lux: Option<f32>,
    /// Point and spot: intensity in candela.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub candela: Option<f32>,
    /// Point and spot: luminous flux in lumens (instead of candela).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub lumens: Option<f32>,
    /// Linear RGB, scaled by the intensity.
    #[serde(default = "white")]
    pub colour: Vec3,
    /// Spot: the outer cone's full angle, degrees, `0 < cone <= 180`.
    #[serde(default = "default_cone")]
    pub cone_deg: f32,
    /// Spot: the inner cone's full angle (full intensity inside), degrees; default 0.8 of the cone.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub inner_cone_deg: Option<f32>,
    /// Whether the light casts shadows.
    #[serde(default = "yes")]
    pub shadows: bool,
}

fn default_elevation() -> f32 {
    45.0
}

fn white() -> Vec3 {
    Vec3::ONE
}

fn default_cone() -> f32 {
    45.0
}

fn yes() -> bool {
    true
}

impl Default for LightSpec {
    fn default() -> Self {
        Self {
            name: None,
            time_secs: 0.0,
            kind: LightKind::Directional,
            azimuth_deg: 0.0,
            elevation_deg: default_elevation(),
            position: Vec3::ZERO,
            target: Vec3::ZERO,
            lux: None,
            candela: None,
            lumens: None,
            colour: Vec3::ONE,
            cone_deg: default_cone(),
            inner_cone_deg: None,
            shadows: true,
        }
    }
}

/// One light resolved for the renderer: world space, intensity as lux (directional) or candela
/// (point, spot) times the colour.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSource {
    /// The kind of light.
    pub kind: LightKind,
    /// Point and spot: the light's position, world space.
    pub position: Vec3,
    /// Directional: unit vector toward the light. Spot: unit vector along the cone's axis, away
    /// from the light. Point: unused (zero).
    pub direction: Vec3,
    /// Linear RGB times lux (directional) or candela (point, spot).
    pub intensity: Vec3,
    /// Spot: cosine of the inner cone's half angle (full intensity inside).
    pub cos_inner: f32,
    /// Spot: cosine of the outer cone's half angle (dark outside).
    pub cos_outer: f32,
    /// Whether the light casts shadows.
    pub casts_shadows: bool,
}

impl LightSource {
    /// A directional light of `lux` toward `toward_light` (normalised; +Y if zero).
    #[must_use]
    pub fn directional(toward_light: Vec3, colour: Vec3, lux: f32) -> Self {
        Self {
            kind: LightKind::Directional,
            position: Vec3::ZERO,
            direction: toward_light.normalize_or(Vec3::Y),
            intensity: colour * lux,
            cos_inner: -1.0,
            cos_outer: -1.0,
            casts_shadows: true,
        }
    }
}

/// The unit vector toward a light at `azimuth_deg` around +Y (from +Z toward +X) and
/// `elevation_deg` above the horizon: the camera's convention (`Camera::orbit`).
#[must_use]
pub fn direction_from_angles(azimuth_deg: f32, elevation_deg: f32) -> Vec3 {
    let (azimuth, elevation) = (azimuth_deg.to_radians(), elevation_deg.to_radians());
    Vec3::new(elevation.cos() * azimuth.sin(), elevation.sin(), elevation.cos() * azimuth.cos())
}

/// The solid angle of a cone of full angle `cone_deg`, steradians.
#[must_use]
pub fn cone_solid_angle(cone_deg: f32) -> f32 {
    std::f32::consts::TAU * (1.0 - (0.5 * cone_deg.to_radians()).cos())
}

impl LightSpec {
    /// Checks every value; errors are `(key, problem)` with keys relative to the table.
    ///
    /// # Errors
    /// NaN or negative intensities and colours, a spot cone of 0 or over 180 degrees, an inner
    /// cone wider than the outer, the wrong intensity key for the kind, non-finite positions.
    pub fn validate(&self) -> Result<(), (String, String)> {
        if !self.time_secs.is_finite() || self.time_secs < 0.0 {
            return Err(("time_secs".into(), format!("must be finite and at least 0, got {}", self.time_secs)));
        }
        let non_negative = |key: &str, value: f32| {
            if value.is_finite() && value >= 0.0 {
                Ok(())
            } else {
                Err((key.to_owned(), format!("must be a finite number at least 0, got {value}")))
            }
        };
        for (key, value) in [("lux", self.lux), ("candela", self.candela), ("lumens", self.lumens)] {
            if let Some(value) = value {
                non_negative(key, value)?;
            }
        }
        for (c, value) in self.colour.to_array().into_iter().enumerate() {
            non_negative(&format!("colour[{c}]"), value)?;
        }
        for (key, value) in [("azimuth_deg", self.azimuth_deg), ("elevation_deg", self.elevation_deg)] {
            if !value.is_finite() {
                return Err((key.to_owned(), format!("must be finite, got {value}")));
            }
        }
        if !(-90.0..=90.0).contains(&self.elevation_deg) {
            return Err(("elevation_deg".into(), format!("must be between -90 and 90, got {}", self.elevation_deg)));
        }
        for (key, value) in [("position", self.position), ("target", self.target)] {
            if !value.is_finite() {
                return Err((key.to_owned(), format!("must be finite, got {value}")));
            }
        }
        match self.kind {
            LightKind::Directional => {
                if self.candela.is_some() || self.lumens.is_some() {
                    return Err(("lux".into(), "a directional light's intensity is lux, not candela or lumens".into()));
                }
            }
            LightKind::Point | LightKind::Spot => {
                if self.lux.is_some() {
                    return Err((
                        "candela".into(),
                        "a point or spot light's intensity is candela or lumens, not lux".into(),
                    ));
                }
                if self.candela.is_some() && self.lumens.is_some() {
                    return Err(("lumens".into(), "give candela or lumens, not both".into()));
                }
            }
        }
        if self.kind == LightKind::Spot {
            let cone = |key: &str, value: f32| {
                if value.is_finite() && value > 0.0 && value <= 180.0 {
                    Ok(())
                } else {
                    Err((key.to_owned(), format!("must be more than 0 and at most 180 degrees, got {value}")))
                }
            };
            cone("cone_deg", self.cone_deg)?;
            if let Some(inner) = self.inner_cone_deg {
                cone("inner_cone_deg", inner)?;
                if inner > self.cone_deg {
                    return Err((
                        "inner_cone_deg".into(),
                        format!("must be at most cone_deg ({}), got {inner}", self.cone_deg),
                    ));
                }
            }
            if (self.target - self.position).length_squared() == 0.0 {
                return Err(("target".into(), "must differ from position".into()));
            }
        }
        Ok(())
    }

    /// The intensity in the kind's own unit: lux, or candela (lumens converted over the light's
    /// solid angle: the sphere for a point light, the outer cone for a spot).
    #[must_use]
    pub fn intensity(&self) -> f32 {
        match self.kind {
            LightKind::Directional => self.lux.unwrap_or(1.0),
            LightKind::Point | LightKind::Spot => match (self.candela, self.lumens) {
                (Some(candela), _) => candela,
                (None, Some(lumens)) => {
                    let solid_angle = if self.kind == LightKind::Point {
                        4.0 * std::f32::consts::PI
                    } else {
                        cone_solid_angle(self.cone_deg)
                    };
                    lumens / solid_angle.max(1e-6)
                }
                (None, None) => 1.0,
            },
        }
    }

    /// The light in world space.
    #[must_use]
    pub fn source(&self) -> LightSource {
        let inner = self.inner_cone_deg.unwrap_or(0.8 * self.cone_deg);
        let half_cos = |deg: f32| (0.5 * deg.to_radians()).cos();
        let (direction, cos_inner, cos_outer) = match self.kind {
            LightKind::Directional => (direction_from_angles(self.azimuth_deg, self.elevation_deg), -1.0, -1.0),
            LightKind::Point => (Vec3::ZERO, -1.0, -1.0),
            LightKind::Spot => {
                let outer = half_cos(self.cone_deg);
                // A hair apart, so the shader's fade never divides by zero.
                ((self.target - self.position).normalize_or(Vec3::NEG_Y), half_cos(inner).max(outer + 1e-4), outer)
            }
        };
        LightSource {
            kind: self.kind,
            position: self.position,
            direction,
            intensity: self.colour * self.intensity(),
            cos_inner,
            cos_outer,
            casts_shadows: self.shadows,
        }
    }

    /// This key blended toward `next` by `t` (0..1): angles, positions, colour, intensity and cones
    /// linearly; the kind and shadows are this key's.
    #[must_use]
    pub fn lerp(&self, next: &Self, t: f32) -> Self {
        let mix = |a: f32, b: f32| a + (b - a) * t;
        let intensity = mix(self.intensity(), next.intensity());
        let (lux, candela) =
            if self.kind == LightKind::Directional { (Some(intensity), None) } else { (None, Some(intensity)) };
        Self {
            name: self.name.clone(),
            time_secs: self.time_secs + (next.time_secs - self.time_secs) * f64::from(t),
            kind: self.kind,
            azimuth_deg: mix(self.azimuth_deg, next.azimuth_deg),
            elevation_deg: mix(self.elevation_deg, next.elevation_deg),
            position: self.position.lerp(next.position, t),
            target: self.target.lerp(next.target, t),
            lux,
            candela,
            lumens: None,
            colour: self.colour.lerp(next.colour, t),
            cone_deg: mix(self.cone_deg, next.cone_deg),
            inner_cone_deg: Some(mix(
                self.inner_cone_deg.unwrap_or(0.8 * self.cone_deg),
                next.inner_cone_deg.unwrap_or(0.8 * next.cone_deg),
            )),
            shadows: self.shadows,
        }
    }
}

/// Checks a list of `[[light]]` keys: each valid, keys of one name sorted by time and of one
/// kind, at most [`MAX_LIGHTS`] lights. Keys in errors are `light[i].key`.
///
/// # Errors
/// `(key, problem)` for the first bad value.
pub fn validate_keys(keys: &[LightSpec]) -> Result<(), (String, String)> {
    for (i, key) in keys.iter().enumerate() {
        key.validate().map_err(|(k, problem)| (format!("light[{i}].{k}"), problem))?;
        let Some(name) = &key.name else { continue };
        if let Some(j) = keys[..i].iter().rposition(|k| k.name.as_ref() == Some(name)) {
            if key.time_secs < keys[j].time_secs {
                return Err((
                    format!("light[{i}].time_secs"),
                    format!("keys of light {name:?} must be sorted by time"),
                ));
            }
            if key.kind != keys[j].kind {
                return Err((format!("light[{i}].kind"), format!("every key of light {name:?} must be of one kind")));
            }
        }
    }
    let count = light_groups(keys).len();
    if count > MAX_LIGHTS {
        return Err(("light".into(), format!("at most {MAX_LIGHTS} lights, got {count}")));
    }
    Ok(())
}

/// The keys of each light, in the order the lights first appear: each unnamed table alone, each
/// name's tables together.
fn light_groups(keys: &[LightSpec]) -> Vec<Vec<&LightSpec>> {
    let mut groups: Vec<Vec<&LightSpec>> = Vec::new();
    for key in keys {
        match key.name.as_ref().and_then(|name| groups.iter_mut().find(|g| g[0].name.as_ref() == Some(name))) {
            Some(group) => group.push(key),
            None => groups.push(vec![key]),
        }
    }
    groups
}

/// Every light at `time_secs`: each light's keys blended linearly between the two around it
/// (held before the first and after the last).
#[must_use]
pub fn lights_at(keys: &[LightSpec], time_secs: f64) -> Vec<LightSource> {
    light_groups(keys)
        .into_iter()
        .map(|group| {
            let after = group.iter().position(|k| k.time_secs > time_secs);
            match after {
                None => group[group.len() - 1].source(),
                Some(0) => group[0].source(),
                Some(i) => {
                    let (a, b) = (group[i - 1], group[i]);
                    let span = b.time_secs - a.time_secs;
                    let t = if span > 0.0 { ((time_secs - a.time_secs) / span) as f32 } else { 1.0 };
                    a.lerp(b, t).source()
                }
            }
        })
        .collect()
}
