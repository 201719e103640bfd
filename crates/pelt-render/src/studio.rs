//! [`Studio`]: what surrounds a fur in Pelt's own pictures (the lights, the environment, the
//! exposure and the background). Every Pelt host (`pelt render`, the viewer, the web page, the
//! examples) draws with [`Studio::default`], so a preset seen from one camera looks the same in each.

use glam::Vec3;
use pelt_core::light::{Environment, LightSource, direction_from_angles};

use crate::camera::Camera;
use crate::targets::DEFAULT_BACKGROUND;
use crate::view::{Light, LightSet, ViewData};

/// The light, exposure and background a fur is shown with. Colours are linear RGB: a host
/// resolves into an sRGB target (or an sRGB view of its canvas or swap chain) so that the
/// encoding happens once, on write.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Studio {
    /// The key light following the camera and the ambient term, used where `lights` is empty.
    pub light: Light,
    /// Scales all light, key and ambient alike (1: Pelt's picture).
    pub exposure: f32,
    /// The clear colour.
    pub background: Vec3,
    /// Lights in physical units replacing `light` (empty: `light` is the key light; by default
    /// [`Studio::key_light`]).
    pub lights: LightSet,
    /// The environment replacing `light`'s ambient (none: the ambient; by default `sky-ground`).
    pub environment: Option<Environment>,
}

/// Where Pelt's key light stands, fixed in the world: azimuth and elevation in degrees (about +Y
/// from +Z toward +X, above the horizon). Beside the default camera (azimuth 30, elevation 15) and
/// above it, so the coat is lit from the front and its shadow falls behind and below it.
pub const KEY_LIGHT_ANGLES: (f32, f32) = (40.0, 35.0);
/// The `sky-ground` environment's radiance above the horizon (linear RGB): a pale blue fill.
pub const SKY_RADIANCE: Vec3 = Vec3::new(0.34, 0.38, 0.44);
/// The `sky-ground` environment's radiance below the horizon: a dark warm bounce.
pub const GROUND_RADIANCE: Vec3 = Vec3::new(0.12, 0.1, 0.08);

impl Default for Studio {
    /// Pelt's look: the key light ([`Studio::key_light`]) fixed in the world, the `sky-ground`
    /// environment ([`SKY_RADIANCE`] over [`GROUND_RADIANCE`]) as the fill, exposure 1 and [`DEFAULT_BACKGROUND`].
    /// Hosts add the key light's shadows ([`crate::Surroundings`]).
    fn default() -> Self {
        Self::following_camera().with_lights(&[Self::key_light()], Some(Self::sky_ground()))
    }
}

impl Studio {
    /// Pelt's key light: a white sun of pi lux (a white Lambertian surface facing it shows white)
    /// at [`KEY_LIGHT_ANGLES`], casting shadows.
    #[must_use]
    pub fn key_light() -> LightSource {
        let (azimuth, elevation) = KEY_LIGHT_ANGLES;
        Self::sun_at(azimuth, elevation)
    }

    /// A white sun of pi lux at `azimuth_deg`, `elevation_deg` (as [`KEY_LIGHT_ANGLES`]), fixed
    /// in the world and casting shadows: what `--light` and a dragged key light place.
    #[must_use]
    pub fn sun_at(azimuth_deg: f32, elevation_deg: f32) -> LightSource {
        LightSource::directional(direction_from_angles(azimuth_deg, elevation_deg), Vec3::ONE, std::f32::consts::PI)
    }

    /// The `sky-ground` environment: [`SKY_RADIANCE`] over [`GROUND_RADIANCE`].
    #[must_use]
    pub fn sky_ground() -> Environment {
        Environment::sky_ground(SKY_RADIANCE, GROUND_RADIANCE)
    }

    /// The paper's studio: one key light that follows the camera ([`Light::default`]) and a
    /// uniform ambient, exposure 1 and [`DEFAULT_BACKGROUND`].
    #[must_use]
    pub fn following_camera() -> Self {
        Self {
            light: Light::default(),
            exposure: 1.0,
            background: DEFAULT_BACKGROUND,
            lights: LightSet::default(),
            environment: None,
        }
    }

    /// The view uniform for `camera` on a target of `aspect_ratio`, lit by this studio.
    #[must_use]
    pub fn view_data(&self, camera: &Camera, aspect_ratio: f32) -> ViewData {
        let light = Light {
            colour: self.light.colour * self.exposure,
            ambient: self.light.ambient * self.exposure,
            ..self.light
        };
        let view = camera.view_data(aspect_ratio, &light);
        if self.lights.is_empty() && self.environment.is_none() {
            return view;
        }
        let environment = self.environment.unwrap_or_else(|| Environment::uniform(Vec3::splat(self.light.ambient)));
        let environment = Environment { sh: environment.sh.scaled(self.exposure) };
        view.with_lights(self.lights.scaled(self.exposure).as_slice(), Some(environment))
    }

    /// This studio with `lights` (at most [`pelt_core::light::MAX_LIGHTS`]) and `environment`.
    #[must_use]
    pub fn with_lights(self, lights: &[LightSource], environment: Option<Environment>) -> Self {
        Self { lights: LightSet::new(lights), environment, ..self }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exposure_scales_the_key_light_and_the_ambient_only() {
        let camera = Camera::orbit(Vec3::ZERO, 30.0, 15.0, 2.0);
        let studio = Studio::following_camera();
        let plain = studio.view_data(&camera, 1.5);
        assert_eq!(plain, camera.view_data(1.5, &Light::default()), "exposure 1 is the default light as it is");
        let doubled = Studio { exposure: 2.0, ..studio }.view_data(&camera, 1.5);
        assert_eq!(doubled.light_colour, 2.0 * plain.light_colour);
        assert_eq!(doubled.ambient, 2.0 * plain.ambient);
        assert_eq!(doubled.clip_from_world, plain.clip_from_world);
        assert_eq!(doubled.light_direction_world, plain.light_direction_world);
    }

    #[test]
    fn the_default_key_light_stays_put_when_the_camera_turns() {
        let studio = Studio::default();
        assert_eq!(studio.lights.as_slice(), &[Studio::key_light()]);
        assert!(studio.lights.as_slice()[0].casts_shadows);
        assert!(studio.environment.is_some());
        let (azimuth, elevation) = KEY_LIGHT_ANGLES;
        let fixed = direction_from_angles(azimuth, elevation);
        for camera_azimuth in [30.0, 150.0, 270.0] {
            let view = studio.view_data(&Camera::orbit(Vec3::ZERO, camera_azimuth, 15.0, 2.0), 1.5);
            let toward = view.light_direction_world;
            assert!(
                toward.distance(fixed) < 1e-5,
                "camera at {camera_azimuth}: key light toward {toward}, not {fixed}"
            );
        }
    }
}
