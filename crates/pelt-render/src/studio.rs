//! [`Studio`]: what surrounds a fur in Pelt's own pictures (the key light, the ambient, the
//! exposure and the background). Every Pelt host (`pelt render`, the viewer, the web page, the
//! examples) draws with [`Studio::default`], so a preset seen from one camera looks the same in each.

use glam::Vec3;
use pelt_core::light::{Environment, LightSource};

use crate::camera::Camera;
use crate::targets::DEFAULT_BACKGROUND;
use crate::view::{Light, LightSet, ViewData};

/// The light, exposure and background a fur is shown with. Colours are linear RGB: a host
/// resolves into an sRGB target (or an sRGB view of its canvas or swap chain) so that the
/// encoding happens once, on write.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Studio {
    /// The key light (following the camera by default) and the ambient term.
    pub light: Light,
    /// Scales all light, key and ambient alike (1: Pelt's picture).
    pub exposure: f32,
    /// The clear colour.
    pub background: Vec3,
    /// Lights in physical units replacing `light` (empty: `light` is the key light).
    pub lights: LightSet,
    /// The environment replacing `light`'s ambient (none: the ambient).
    pub environment: Option<Environment>,
}

impl Default for Studio {
    /// Pelt's look: [`Light::default`], exposure 1 and [`DEFAULT_BACKGROUND`].
    fn default() -> Self {
        Self {
            light: Light::default(),
            exposure: 1.0,
            background: DEFAULT_BACKGROUND,
            lights: LightSet::default(),
            environment: None,
        }
    }
}

impl Studio {
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
        let studio = Studio::default();
        let plain = studio.view_data(&camera, 1.5);
        assert_eq!(plain, camera.view_data(1.5, &Light::default()), "exposure 1 is the default light as it is");
        let doubled = Studio { exposure: 2.0, ..studio }.view_data(&camera, 1.5);
        assert_eq!(doubled.light_colour, 2.0 * plain.light_colour);
        assert_eq!(doubled.ambient, 2.0 * plain.ambient);
        assert_eq!(doubled.clip_from_world, plain.clip_from_world);
        assert_eq!(doubled.light_direction_world, plain.light_direction_world);
    }
}
