//! The orbit camera: orbit about a target, pan in the view plane, zoom toward the target, and
//! frame a bounding sphere so the whole fur is in view.

use glam::{Mat4, Vec2, Vec3};

/// Radians turned per pixel dragged.
const ORBIT_RAD_PER_PX: f32 = 0.008;
/// Distance scale per wheel step (one notch).
const ZOOM_PER_STEP: f32 = 0.88;
/// Keeps the camera off the poles, where `look_at` has no up vector.
const MAX_PITCH_RAD: f32 = 1.55;
/// Room left around a framed object, as a factor of its bounding radius.
const FRAME_MARGIN: f32 = 1.2;

/// A perspective camera orbiting `target`, Y up.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OrbitCamera {
    pub target: Vec3,
    /// Turn about +Y; 0 looks down -Z (the eye sits on +Z).
    pub yaw_rad: f32,
    /// Elevation of the eye above the target's horizon.
    pub pitch_rad: f32,
    pub distance: f32,
    pub fov_y_rad: f32,
}

impl Default for OrbitCamera {
    fn default() -> Self {
        Self { target: Vec3::ZERO, yaw_rad: 0.6, pitch_rad: 0.35, distance: 4.0, fov_y_rad: 40f32.to_radians() }
    }
}

/// A ray in world space.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: Vec3,
    /// Unit length.
    pub direction: Vec3,
}

impl OrbitCamera {
    /// Unit vector from the target to the eye.
    fn backward(&self) -> Vec3 {
        let (sin_yaw, cos_yaw) = self.yaw_rad.sin_cos();
        let (sin_pitch, cos_pitch) = self.pitch_rad.sin_cos();
        Vec3::new(cos_pitch * sin_yaw, sin_pitch, cos_pitch * cos_yaw)
    }

    pub fn eye(&self) -> Vec3 {
        self.target + self.backward() * self.distance
    }

    pub fn view_from_world(&self) -> Mat4 {
        glam::camera::rh::view::look_at_mat4(self.eye(), self.target, Vec3::Y)
    }

    /// Near and far planes that keep anything within `distance` of the target visible.
    pub fn near_far(&self) -> (f32, f32) {
        (self.distance * 0.01, self.distance * 4.0 + 10.0)
    }

    /// The renderer's camera of this orbit.
    pub fn camera(&self) -> pelt_render::Camera {
        let (near, far) = self.near_far();
        pelt_render::Camera { eye: self.eye(), target: self.target, up: Vec3::Y, fov_y_rad: self.fov_y_rad, near, far }
    }

    /// wgpu clip space (depth 0..1).
    pub fn clip_from_view(&self, aspect: f32) -> Mat4 {
        let (near, far) = self.near_far();
        glam::camera::rh::proj::directx::perspective(self.fov_y_rad, aspect.max(1e-3), near, far)
    }

    pub fn clip_from_world(&self, aspect: f32) -> Mat4 {
        self.clip_from_view(aspect) * self.view_from_world()
    }

    /// Turns the camera about the target by a pointer drag in pixels.
    pub fn orbit(&mut self, drag_px: Vec2) {
        self.yaw_rad -= drag_px.x * ORBIT_RAD_PER_PX;
        self.pitch_rad = (self.pitch_rad + drag_px.y * ORBIT_RAD_PER_PX).clamp(-MAX_PITCH_RAD, MAX_PITCH_RAD);
    }

    /// Moves the target in the view plane so the point under the pointer follows it.
    pub fn pan(&mut self, drag_px: Vec2, viewport_height_px: f32) {
        let world_per_px = self.world_per_px_at_target(viewport_height_px);
        let view = self.view_from_world().inverse();
        let right = view.x_axis.truncate();
        let up = view.y_axis.truncate();
        self.target += (-right * drag_px.x + up * drag_px.y) * world_per_px;
    }

    /// Moves toward (positive `steps`) or away from the target; one step is one wheel notch.
    pub fn zoom(&mut self, steps: f32) {
        self.distance = (self.distance * ZOOM_PER_STEP.powf(steps)).clamp(1e-3, 1e6);
    }

    /// World units per pixel in the plane through the target.
    pub fn world_per_px_at_target(&self, viewport_height_px: f32) -> f32 {
        2.0 * self.distance * (self.fov_y_rad * 0.5).tan() / viewport_height_px.max(1.0)
    }

    /// Pixels that `world_length` covers at `point` (for the brush circle).
    pub fn px_per_world_at(&self, point: Vec3, viewport_height_px: f32) -> f32 {
        let depth = (point - self.eye()).dot(-self.backward()).max(1e-4);
        viewport_height_px / (2.0 * depth * (self.fov_y_rad * 0.5).tan())
    }

    /// Keeps the view direction and looks at the sphere so all of it fits the viewport.
    pub fn frame(&mut self, center: Vec3, radius: f32, aspect: f32) {
        let half_fov_y = self.fov_y_rad * 0.5;
        let half_fov_x = (half_fov_y.tan() * aspect.max(1e-3)).atan();
        let half_fov = half_fov_y.min(half_fov_x);
        self.target = center;
        self.distance = radius.max(1e-3) * FRAME_MARGIN / half_fov.sin();
    }

    /// The ray through a pixel (`pixel` from the viewport's top-left, in the same units as
    /// `viewport_size`).
    pub fn ray(&self, pixel: Vec2, viewport_size: Vec2) -> Ray {
        let size = viewport_size.max(Vec2::ONE);
        let ndc = Vec2::new(pixel.x / size.x * 2.0 - 1.0, 1.0 - pixel.y / size.y * 2.0);
        let world_from_clip = self.clip_from_world(size.x / size.y).inverse();
        let near = world_from_clip.project_point3(ndc.extend(0.0));
        let far = world_from_clip.project_point3(ndc.extend(1.0));
        let origin = self.eye();
        Ray { origin, direction: (far - near).normalize_or(-self.backward()) }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corners(center: Vec3, half: f32) -> Vec<Vec3> {
        (0..8)
            .map(|i| {
                let sign = |bit: i32| if i & bit == 0 { -1.0 } else { 1.0 };
                center + Vec3::new(sign(1), sign(2), sign(4)) * half
            })
            .collect()
    }

    #[test]
    fn framing_puts_every_point_inside_the_view_for_wide_and_tall_windows() {
        let points = corners(Vec3::new(3.0, -1.0, 2.0), 0.7);
        let center = Vec3::new(3.0, -1.0, 2.0);
        let radius = 0.7 * 3f32.sqrt();
        for aspect in [0.4, 1.0, 2.5] {
            for yaw_rad in [0.0, 1.0, 2.5] {
                let mut camera = OrbitCamera { yaw_rad, distance: 100.0, ..OrbitCamera::default() };
                camera.frame(center, radius, aspect);
                let clip_from_world = camera.clip_from_world(aspect);
                let mut largest = 0.0f32;
                for p in &points {
                    let ndc = clip_from_world.project_point3(*p);
                    largest = largest.max(ndc.x.abs()).max(ndc.y.abs());
                    assert!((0.0..1.0).contains(&ndc.z), "{p} clipped by depth: {ndc}");
                }
                assert!(largest < 1.0, "aspect {aspect}: a corner leaves the view ({largest})");
                // Framing is tight too: the object fills a good part of the narrower side.
                assert!(largest > 0.4, "aspect {aspect}: framed too loosely ({largest})");
            }
        }
    }

    #[test]
    fn the_centre_pixel_ray_hits_the_target_and_the_corner_rays_project_back() {
        let camera = OrbitCamera { target: Vec3::new(1.0, 2.0, 3.0), distance: 5.0, ..OrbitCamera::default() };
        let size = Vec2::new(800.0, 500.0);
        let ray = camera.ray(size * 0.5, size);
        assert!(ray.origin.distance(camera.eye()) < 1e-4);
        let closest = ray.origin + ray.direction * (camera.target - ray.origin).dot(ray.direction);
        assert!(closest.distance(camera.target) < 1e-3, "{closest}");

        let pixel = Vec2::new(700.0, 100.0);
        let ray = camera.ray(pixel, size);
        let ndc = camera.clip_from_world(size.x / size.y).project_point3(ray.origin + ray.direction * 3.0);
        let back = Vec2::new((ndc.x + 1.0) * 0.5 * size.x, (1.0 - ndc.y) * 0.5 * size.y);
        assert!(back.distance(pixel) < 0.05, "{back} vs {pixel}");
    }

    #[test]
    fn orbit_keeps_distance_and_clamps_pitch_pan_follows_the_pointer_zoom_is_monotonic() {
        let mut camera = OrbitCamera::default();
        let before = camera.eye().distance(camera.target);
        camera.orbit(Vec2::new(123.0, 10_000.0));
        assert!((camera.eye().distance(camera.target) - before).abs() < 1e-4);
        assert!(camera.pitch_rad <= MAX_PITCH_RAD);

        // Dragging right by 100 px moves the target left by 100 px' worth of world.
        let mut camera = OrbitCamera::default();
        let height_px = 600.0;
        let start = camera.target;
        camera.pan(Vec2::new(100.0, 0.0), height_px);
        let moved = camera.target - start;
        let right = camera.view_from_world().inverse().x_axis.truncate();
        let expected = 100.0 * camera.world_per_px_at_target(height_px);
        assert!((moved.dot(-right) - expected).abs() < 1e-4, "{moved}");

        let mut camera = OrbitCamera::default();
        let far = camera.distance;
        camera.zoom(1.0);
        assert!(camera.distance < far);
        camera.zoom(-2.0);
        assert!(camera.distance > far);
    }

    #[test]
    fn brush_scale_matches_the_projection() {
        let camera = OrbitCamera::default();
        let height_px = 700.0;
        let px = camera.px_per_world_at(camera.target, height_px);
        assert!((px * camera.world_per_px_at_target(height_px) - 1.0).abs() < 1e-4);
    }
}
