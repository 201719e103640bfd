//! The page's orbit camera: angles and distance about a target, turned and zoomed by the
//! pointers, and the ray through a pixel.

use glam::{Vec2, Vec3};
use pelt_render::Camera;

/// Degrees turned per CSS pixel dragged.
const ORBIT_DEG_PER_PX: f32 = 0.4;

/// An orbit about a target; angles in degrees as `Camera::orbit` takes them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    /// The point looked at.
    pub target: Vec3,
    /// Turn about +Y, from +Z toward +X.
    pub azimuth_deg: f32,
    /// Lift toward +Y.
    pub elevation_deg: f32,
    /// Eye to target.
    pub distance: f32,
}

impl Orbit {
    /// The camera of this orbit.
    #[must_use]
    pub fn camera(&self) -> Camera {
        Camera::orbit(self.target, self.azimuth_deg, self.elevation_deg, self.distance)
    }

    /// Turns by a drag of `drag_css_px` (x right, y down).
    pub fn rotate(&mut self, drag_css_px: Vec2) {
        self.azimuth_deg -= drag_css_px.x * ORBIT_DEG_PER_PX;
        self.elevation_deg = (self.elevation_deg + drag_css_px.y * ORBIT_DEG_PER_PX).clamp(-85.0, 85.0);
    }

    /// Moves toward the target for `factor < 1` and away for `factor > 1`, within sane bounds.
    pub fn zoom(&mut self, factor: f32, framed_distance: f32) {
        if factor.is_finite() && factor > 0.0 {
            self.distance = (self.distance * factor).clamp(framed_distance * 0.15, framed_distance * 6.0);
        }
    }

    /// The world-space ray `(origin, unit direction)` through `pixel` of a view of `size`
    /// (same units, from the top-left corner).
    #[must_use]
    pub fn ray(&self, pixel: Vec2, size: Vec2) -> (Vec3, Vec3) {
        let size = size.max(Vec2::ONE);
        let camera = self.camera();
        let ndc = Vec2::new(pixel.x / size.x * 2.0 - 1.0, 1.0 - pixel.y / size.y * 2.0);
        let world_from_clip = camera.clip_from_world(size.x / size.y).inverse();
        let near = world_from_clip.project_point3(ndc.extend(0.0));
        let far = world_from_clip.project_point3(ndc.extend(1.0));
        (camera.eye, (far - near).normalize_or((self.target - camera.eye).normalize_or(Vec3::NEG_Z)))
    }
}
