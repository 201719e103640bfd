//! The light flags `pelt render`, `pelt fidelity` and `pelt bench` share: one key light fixed in
//! the world, an environment, and how they combine with a script's `[[light]]` and
//! `[environment]` and the preset's `[shading]`.

use std::path::Path;

use anyhow::Context as _;
use pelt_core::light::{Environment, LightSource};
use pelt_core::preset::Preset;
use pelt_core::sim::Scene;
use pelt_render::{FurLook, FurShading, Studio};

/// `--light` and `--environment`.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct LightArgs {
    /// The key light. AZIMUTH,ELEVATION (degrees, like --camera: around +Y from +Z toward +X,
    /// above the horizon) fixes a sun of pi lux in the world (a white Lambertian surface facing it
    /// shows white), replacing a script's [[light]]s; `camera` makes it follow the camera with a
    /// uniform ambient, as the paper lights its fur. Default: a script's lights, else Pelt's key
    /// light at 40,35.
    #[arg(long, value_name = "AZIMUTH,ELEVATION|camera", value_parser = parse_key_light, allow_hyphen_values = true)]
    pub light: Option<KeyLight>,
    /// Light from every direction: an equirectangular PNG, HDR or EXR image, `sky-ground` (a pale
    /// sky over a dark ground) or `ambient` (uniform, as the paper's). Replaces a script's
    /// [environment]. Default: the script's, else sky-ground.
    #[arg(long, value_name = "FILE|sky-ground|ambient")]
    pub environment: Option<String>,
}

/// `--light`'s value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum KeyLight {
    /// A sun at azimuth, elevation (degrees), fixed in the world.
    Fixed(f32, f32),
    /// The paper's key light, following the camera.
    Camera,
}

fn parse_key_light(text: &str) -> Result<KeyLight, String> {
    if text.trim() == "camera" {
        return Ok(KeyLight::Camera);
    }
    let values: Vec<f32> = text
        .split(',')
        .map(|v| v.trim().parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|e| format!("{text:?}: {e} (expected AZIMUTH,ELEVATION in degrees, or `camera`)"))?;
    match values[..] {
        [azimuth, elevation] if azimuth.is_finite() && (-90.0..=90.0).contains(&elevation) => {
            Ok(KeyLight::Fixed(azimuth, elevation))
        }
        _ => Err(format!("expected AZIMUTH,ELEVATION in degrees (elevation -90 to 90) or `camera`, got {text:?}")),
    }
}

impl LightArgs {
    /// The environment the flag names, else the script's, else `sky-ground` (none with the key
    /// light following the camera, whose ambient is uniform).
    ///
    /// # Errors
    /// An image that cannot be read or is not one, named; an environment given with the key light
    /// following the camera.
    pub fn environment(&self, scene: Option<&Scene>) -> anyhow::Result<Option<Environment>> {
        match (self.environment.as_deref(), self.light) {
            (Some("ambient"), _) => Ok(None),
            (Some(_), Some(KeyLight::Camera)) => {
                anyhow::bail!(
                    "--environment: the key light that follows the camera has a uniform ambient; fix the light with --light AZIMUTH,ELEVATION"
                )
            }
            (Some("sky-ground"), _) => Ok(Some(Studio::sky_ground())),
            (Some(file), _) => Environment::load_image(Path::new(file)).map(Some).context("--environment"),
            (None, Some(KeyLight::Camera)) => Ok(None),
            (None, _) => Ok(Some(scene.and_then(|s| s.environment_light).unwrap_or_else(Studio::sky_ground))),
        }
    }

    /// The lights at `time_secs`: `--light`, else the script's, else Pelt's key light.
    #[must_use]
    pub fn lights_at(&self, scene: Option<&Scene>, time_secs: f64) -> Vec<LightSource> {
        match self.light {
            Some(KeyLight::Fixed(azimuth, elevation)) => vec![Studio::sun_at(azimuth, elevation)],
            Some(KeyLight::Camera) => Vec::new(),
            None => {
                let script = scene.map(|s| s.lights_at(time_secs)).unwrap_or_default();
                if script.is_empty() { vec![Studio::key_light()] } else { script }
            }
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
