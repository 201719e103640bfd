//! The page's key light and shadows: Pelt's studio (its key light fixed in the world, the
//! `sky-ground` environment, shadows on), as `pelt render` draws it. A drag turns the light; it
//! can follow the camera instead, as the paper's does. Shadows and a ground under the meshes are
//! switches.

use glam::{Vec2, Vec3};
use pelt_core::light::direction_from_angles;
use pelt_render::{Camera, KEY_LIGHT_ANGLES, Light, LightDirection, Studio};

/// Degrees the light turns per CSS pixel dragged (the orbit's rate).
const LIGHT_DEG_PER_PX: f32 = 0.4;

/// The lowest and highest elevation a drag reaches: a light at the horizon or overhead casts
/// no shadow a viewer can read.
const ELEVATION_RANGE_DEG: (f32, f32) = (2.0, 89.0);

/// The key light and what it casts.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PageLight {
    /// Azimuth and elevation in degrees, fixed in the world; `None` follows the camera.
    angles: Option<(f32, f32)>,
    /// The key light casts shadows (the fur's own included).
    pub shadows: bool,
    /// A ground plane under the meshes, taking their shadow.
    pub ground: bool,
}

impl Default for PageLight {
    /// Pelt's studio: the key light at [`KEY_LIGHT_ANGLES`], casting shadows; no ground.
    fn default() -> Self {
        Self { angles: Some(KEY_LIGHT_ANGLES), shadows: true, ground: false }
    }
}

impl PageLight {
    /// Where the light is fixed (azimuth, elevation in degrees), or `None` while it follows the
    /// camera.
    #[must_use]
    pub fn angles(&self) -> Option<(f32, f32)> {
        self.angles
    }

    /// Fixes the light in the world at `azimuth_deg` (about +Y from +Z toward +X) and
    /// `elevation_deg` (above the horizon, -90 to 90).
    ///
    /// # Errors
    /// A message for a non-finite angle or an elevation outside -90 to 90; the light stays.
    pub fn set(&mut self, azimuth_deg: f32, elevation_deg: f32) -> Result<(), String> {
        if !(azimuth_deg.is_finite() && elevation_deg.is_finite() && (-90.0..=90.0).contains(&elevation_deg)) {
            return Err(format!(
                "a light at azimuth {azimuth_deg} and elevation {elevation_deg} (degrees; elevation -90 to 90)"
            ));
        }
        self.angles = Some((azimuth_deg.rem_euclid(360.0), elevation_deg));
        Ok(())
    }

    /// Lets the light follow the camera again.
    pub fn follow_camera(&mut self) {
        self.angles = None;
    }

    /// Turns the light by a drag of `drag_css_px` (x right, y down): right turns it with the
    /// camera's azimuth, up raises it. A light that followed `camera` starts where it was.
    pub fn drag(&mut self, drag_css_px: Vec2, camera: &Camera) {
        let (azimuth, elevation) = self.angles.unwrap_or_else(|| following_angles(camera));
        let (low, high) = ELEVATION_RANGE_DEG;
        let elevation = (elevation - drag_css_px.y * LIGHT_DEG_PER_PX).clamp(low, high);
        self.angles = Some(((azimuth + drag_css_px.x * LIGHT_DEG_PER_PX).rem_euclid(360.0), elevation));
    }

    /// The key light's direction.
    #[must_use]
    pub fn direction(&self) -> LightDirection {
        match self.angles {
            Some((azimuth, elevation)) => LightDirection::World(direction_from_angles(azimuth, elevation)),
            None => Light::default().direction,
        }
    }

    /// The studio this light makes: [`Studio::default`] with the key light where it is, or the
    /// paper's studio ([`Studio::following_camera`]) while it follows the camera.
    #[must_use]
    pub fn studio(&self) -> Studio {
        match self.angles {
            Some((azimuth, elevation)) => {
                Studio::default().with_lights(&[Studio::sun_at(azimuth, elevation)], Some(Studio::sky_ground()))
            }
            None => Studio::following_camera(),
        }
    }
}

/// The angles of the default light that follows `camera`, in the world.
fn following_angles(camera: &Camera) -> (f32, f32) {
    let toward = camera.view_data(1.0, &Light::default()).light_direction_world.normalize_or(Vec3::Y);
    (toward.x.atan2(toward.z).to_degrees().rem_euclid(360.0), toward.y.clamp(-1.0, 1.0).asin().to_degrees())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_page_starts_in_pelts_studio() {
        let light = PageLight::default();
        assert_eq!(light.studio(), Studio::default());
        assert!(light.shadows && !light.ground);
        let mut following = light;
        following.follow_camera();
        assert_eq!(following.studio(), Studio::following_camera());
    }

    #[test]
    fn a_drag_starts_from_where_the_following_light_was() {
        let camera = Camera::orbit(Vec3::ZERO, 35.0, 15.0, 2.0);
        let following = camera.view_data(1.0, &Light::default()).light_direction_world;
        let mut light = PageLight::default();
        light.follow_camera();
        light.drag(Vec2::ZERO, &camera);
        let LightDirection::World(fixed) = light.direction() else { panic!("a dragged light is fixed in the world") };
        assert!(fixed.distance(following) < 1e-4, "{fixed} against {following}");
    }

    #[test]
    fn dragging_right_turns_and_up_raises_within_bounds() {
        let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 2.0);
        let mut light = PageLight::default();
        light.set(10.0, 30.0).unwrap();
        light.drag(Vec2::new(25.0, -25.0), &camera);
        assert_eq!(light.angles(), Some((20.0, 40.0)));
        light.drag(Vec2::new(0.0, -1000.0), &camera);
        assert_eq!(light.angles().unwrap().1, ELEVATION_RANGE_DEG.1);
        light.follow_camera();
        assert_eq!(light.direction(), Light::default().direction);
    }

    #[test]
    fn bad_angles_are_refused_and_the_light_stays() {
        let mut light = PageLight::default();
        light.set(40.0, 35.0).unwrap();
        for (azimuth, elevation) in [(f32::NAN, 10.0), (10.0, 95.0), (f32::INFINITY, 0.0)] {
            assert!(light.set(azimuth, elevation).is_err());
        }
        assert_eq!(light.angles(), Some((40.0, 35.0)));
    }
}
