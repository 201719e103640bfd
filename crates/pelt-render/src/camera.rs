//! A perspective camera and automatic framing from a bounding sphere: a convenience that makes
//! [`ViewData`] for Pelt's own commands and examples. Hosts with a camera of their own build
//! [`ViewData`] from it instead.

use glam::{Mat4, Vec3};

use crate::view::{Light, ViewData};

/// A right-handed, Y-up perspective camera with conventional depth (0 at `near`, 1 at `far`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Where the camera is.
    pub eye: Vec3,
    /// The point it looks at.
    pub target: Vec3,
    /// The world direction that is up in the picture.
    pub up: Vec3,
    /// Vertical field of view.
    pub fov_y_rad: f32,
    /// Near plane distance.
    pub near: f32,
    /// Far plane distance.
    pub far: f32,
}

impl Camera {
    /// Default vertical field of view (35 degrees: little perspective distortion).
    pub const DEFAULT_FOV_Y_RAD: f32 = 35.0 * std::f32::consts::PI / 180.0;

    /// A camera on a sphere around `target`: `azimuth_deg` turns around +Y from +Z toward +X,
    /// `elevation_deg` lifts toward +Y.
    #[must_use]
    pub fn orbit(target: Vec3, azimuth_deg: f32, elevation_deg: f32, distance: f32) -> Self {
        // Stop short of the poles, where `up` and the view direction would coincide.
        let (azimuth, elevation) = (azimuth_deg.to_radians(), elevation_deg.clamp(-89.5, 89.5).to_radians());
        let direction = Vec3::new(azimuth.sin() * elevation.cos(), elevation.sin(), azimuth.cos() * elevation.cos());
        let distance = distance.max(1e-6);
        Self {
            eye: target + direction * distance,
            target,
            up: Vec3::Y,
            fov_y_rad: Self::DEFAULT_FOV_Y_RAD,
            near: distance * 0.01,
            far: distance * 10.0,
        }
    }

    /// The distance at which a sphere of `radius` fills the view of this field of view with a
    /// small margin, for any aspect ratio.
    #[must_use]
    pub fn framing_distance(radius: f32, fov_y_rad: f32, aspect_ratio: f32) -> f32 {
        let half_y = fov_y_rad * 0.5;
        let half_x = (half_y.tan() * aspect_ratio.max(1e-3)).atan();
        let half = half_y.min(half_x);
        radius.max(1e-6) * 1.08 / half.sin()
    }

    /// Frames the sphere `(centre, radius)` from the given angles.
    #[must_use]
    pub fn framing(centre: Vec3, radius: f32, azimuth_deg: f32, elevation_deg: f32, aspect_ratio: f32) -> Self {
        let distance = Self::framing_distance(radius, Self::DEFAULT_FOV_Y_RAD, aspect_ratio);
        Self::orbit(centre, azimuth_deg, elevation_deg, distance)
    }

    /// Frames `points` (e.g. mesh vertices) tightly from the given angles, looking at `target`,
    /// with `padding` world units around every point (e.g. the fur length) and a small margin.
    #[must_use]
    pub fn framing_points(
        target: Vec3,
        points: impl IntoIterator<Item = Vec3>,
        padding: f32,
        azimuth_deg: f32,
        elevation_deg: f32,
        aspect_ratio: f32,
    ) -> Self {
        let unit = Self::orbit(target, azimuth_deg, elevation_deg, 1.0);
        let backward = (unit.eye - target).normalize();
        let right = unit.up.cross(backward).normalize();
        let up = backward.cross(right);
        let tan_y = (Self::DEFAULT_FOV_Y_RAD * 0.5).tan();
        let tan_x = tan_y * aspect_ratio.max(1e-3);
        let margin = 1.06;
        let mut distance = 1e-6_f32;
        for point in points {
            let offset = point - target;
            let depth = offset.dot(backward);
            let needed_x = (offset.dot(right).abs() + padding) * margin / tan_x;
            let needed_y = (offset.dot(up).abs() + padding) * margin / tan_y;
            distance = distance.max(depth + padding + needed_x.max(needed_y));
        }
        Self::orbit(target, azimuth_deg, elevation_deg, distance)
    }

    /// View matrix.
    #[must_use]
    pub fn view_from_world(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye, self.target, self.up)
    }

    /// Projection (depth 0 at `near`, 1 at `far`) times view.
    #[must_use]
    pub fn clip_from_world(&self, aspect_ratio: f32) -> Mat4 {
        let clip_from_view =
            glam::camera::rh::proj::directx::perspective(self.fov_y_rad, aspect_ratio.max(1e-3), self.near, self.far);
        clip_from_view * self.view_from_world()
    }

    /// The view for a target of `aspect_ratio`, lit by `light`.
    #[must_use]
    pub fn view_data(&self, aspect_ratio: f32, light: &Light) -> ViewData {
        let world_from_view = self.view_from_world().inverse();
        ViewData {
            // The eye itself rather than the inverse's translation, which rounds.
            camera_position_world: self.eye,
            ..ViewData::new(self.clip_from_world(aspect_ratio), world_from_view, light)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn framed_sphere_fits_the_view() {
        let (centre, radius) = (Vec3::new(1.0, 2.0, -3.0), 2.5);
        for aspect in [0.5, 1.0, 16.0 / 9.0] {
            let camera = Camera::framing(centre, radius, 30.0, 20.0, aspect);
            let clip_from_world = camera.clip_from_world(aspect);
            let right = camera.view_from_world().inverse().transform_vector3(Vec3::X);
            let up = camera.view_from_world().inverse().transform_vector3(Vec3::Y);
            let mut widest = 0.0_f32;
            for offset in [right, -right, up, -up] {
                let clip = clip_from_world * (centre + offset * radius).extend(1.0);
                let ndc = clip.truncate() / clip.w;
                assert!(ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0, "{aspect}: {ndc}");
                assert!((0.0..1.0).contains(&ndc.z));
                widest = widest.max(ndc.x.abs()).max(ndc.y.abs());
            }
            assert!(widest > 0.8, "the sphere fills the view: {widest}");
        }
    }

    #[test]
    fn framed_points_fit_the_view_tightly() {
        let points = [Vec3::new(-3.0, -0.5, 0.2), Vec3::new(3.0, 0.5, -0.2), Vec3::new(0.0, 1.0, 1.0)];
        let aspect = 16.0 / 9.0;
        let camera = Camera::framing_points(Vec3::ZERO, points, 0.1, 20.0, 10.0, aspect);
        let clip_from_world = camera.clip_from_world(aspect);
        let mut widest = 0.0_f32;
        for point in points {
            let clip = clip_from_world * point.extend(1.0);
            let ndc = clip.truncate() / clip.w;
            assert!(ndc.x.abs() < 1.0 && ndc.y.abs() < 1.0 && (0.0..1.0).contains(&ndc.z), "{ndc}");
            widest = widest.max(ndc.x.abs()).max(ndc.y.abs());
        }
        assert!(widest > 0.8, "tight: {widest}");
    }

    #[test]
    fn orbit_angles_point_where_documented() {
        let camera = Camera::orbit(Vec3::ZERO, 90.0, 0.0, 2.0);
        assert!(camera.eye.distance(Vec3::new(2.0, 0.0, 0.0)) < 1e-5);
        let camera = Camera::orbit(Vec3::ZERO, 0.0, 90.0, 2.0);
        assert!((camera.eye.y - 2.0).abs() < 1e-3);
        assert!(camera.clip_from_world(1.0).is_finite());
    }
}
