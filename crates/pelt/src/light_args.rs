//! The light flags `pelt render`, `pelt fidelity` and `pelt bench` share: one key light fixed in
//! the world, an environment, and how they combine with a script's `[[light]]` and
//! `[environment]` and the preset's `[shading]`.

use std::path::Path;

use anyhow::Context as _;
use glam::Vec3;
use pelt_core::light::{Environment, LightSource, direction_from_angles};
use pelt_core::preset::Preset;
use pelt_core::sim::Scene;
use pelt_render::{FurLook, FurShading, Studio};

/// `--light` and `--environment`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct LightArgs {
    /// One key light fixed in the world, from azimuth,elevation (degrees, like --camera: around
    /// +Y from +Z toward +X, above the horizon), of pi lux (a white Lambertian surface shows
    /// white). Replaces a script's [[light]]s. Default: the key light follows the camera.
    #[arg(long, value_name = "AZIMUTH,ELEVATION", value_parser = parse_angles, allow_hyphen_values = true)]
    pub light: Option<(f32, f32)>,
    /// Light from every direction: an equirectangular PNG, HDR or EXR image, or `sky-ground`
    /// (a pale sky over a dark ground). Replaces a script's [environment]. Default: the ambient.
    #[arg(long, value_name = "FILE|sky-ground")]
    pub environment: Option<String>,
}

/// The `sky-ground` environment's radiance above and below the horizon.
pub const SKY: Vec3 = Vec3::new(0.34, 0.38, 0.44);
pub const GROUND: Vec3 = Vec3::new(0.12, 0.1, 0.08);

fn parse_angles(text: &str) -> Result<(f32, f32), String> {
    let values: Vec<f32> = text
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{text:?}: {e}"))?;
    match values[..] {
        [azimuth, elevation] if azimuth.is_finite() && (-90.0..=90.0).contains(&elevation) => Ok((azimuth, elevation)),
        _ => Err(format!("expected AZIMUTH,ELEVATION in degrees (elevation -90 to 90), got {text:?}")),
    }
}

impl LightArgs {
    /// The environment the flag names, else the script's.
    ///
    /// # Errors
    /// An image that cannot be read or is not one, named.
    pub fn environment(&self, scene: Option<&Scene>) -> anyhow::Result<Option<Environment>> {
        match self.environment.as_deref() {
            Some("sky-ground") => Ok(Some(Environment::sky_ground(SKY, GROUND))),
            Some(file) => Environment::load_image(Path::new(file)).map(Some).context("--environment"),
            None => Ok(scene.and_then(|s| s.environment_light)),
        }
    }

    /// The lights at `time_secs`: `--light`, else the script's.
    #[must_use]
    pub fn lights_at(&self, scene: Option<&Scene>, time_secs: f64) -> Vec<LightSource> {
        match self.light {
            Some((azimuth, elevation)) => {
                vec![LightSource::directional(
                    direction_from_angles(azimuth, elevation),
                    Vec3::ONE,
                    std::f32::consts::PI,
                )]
            }
            None => scene.map(|s| s.lights_at(time_secs)).unwrap_or_default(),
        }
    }

    /// Pelt's studio with these lights at `time_secs` and `environment`.
    #[must_use]
    pub fn studio(&self, scene: Option<&Scene>, environment: Option<Environment>, time_secs: f64) -> Studio {
        Studio::default().with_lights(&self.lights_at(scene, time_secs), environment)
    }
}

/// The default look with the preset's `[shading]`.
#[must_use]
pub fn preset_look(preset: &Preset) -> FurLook {
    FurLook { shading: FurShading::from_params(&preset.shading), ..FurLook::default() }
}
