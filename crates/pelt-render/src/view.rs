//! Per-view data supplied by the host: the camera's transform and position, the key light, and
//! the lights and environment the fur model loops over. Each view has its own uniform buffers
//! ([`FurView`]), so several views drawn in one submission do not overwrite each other.

use glam::{Mat4, Vec3};
use pelt_core::light::{Environment, LightKind, LightSource, MAX_LIGHTS};

use crate::shaders::{GpuLight, Layouts, LightsUniform, ViewUniform};

/// Where the key light comes from.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum LightDirection {
    /// Unit vector toward the light in world space (a sun).
    World(Vec3),
    /// Unit vector toward the light in view space (x right, y up, z toward the viewer), so the
    /// light follows the camera.
    View(Vec3),
}

/// The key light and the ambient term.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Light {
    /// Toward the light.
    pub direction: LightDirection,
    /// Linear RGB.
    pub colour: Vec3,
    /// Light everywhere, as a fraction of the surface colour.
    pub ambient: f32,
}

impl Light {
    /// Pelt's default: from the upper left, following the camera.
    pub const DEFAULT_FROM_VIEW: Vec3 = Vec3::new(-0.45, 0.65, 0.6);
}

impl Default for Light {
    fn default() -> Self {
        Self { direction: LightDirection::View(Self::DEFAULT_FROM_VIEW.normalize()), colour: Vec3::ONE, ambient: 0.25 }
    }
}

/// Up to [`MAX_LIGHTS`] lights, in a fixed array so a view stays `Copy`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSet {
    lights: [LightSource; MAX_LIGHTS],
    count: usize,
}

impl Default for LightSet {
    fn default() -> Self {
        Self { lights: [LightSource::directional(Vec3::Y, Vec3::ZERO, 0.0); MAX_LIGHTS], count: 0 }
    }
}

impl LightSet {
    /// The first [`MAX_LIGHTS`] of `lights`.
    #[must_use]
    pub fn new(lights: &[LightSource]) -> Self {
        let mut set = Self { count: lights.len().min(MAX_LIGHTS), ..Self::default() };
        set.lights[..set.count].copy_from_slice(&lights[..set.count]);
        set
    }

    /// The lights.
    #[must_use]
    pub fn as_slice(&self) -> &[LightSource] {
        &self.lights[..self.count]
    }

    /// Whether there are none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Every light's intensity times `scale`.
    #[must_use]
    pub fn scaled(&self, scale: f32) -> Self {
        let mut set = *self;
        for light in &mut set.lights[..set.count] {
            light.intensity *= scale;
        }
        set
    }
}

/// One view as the shaders see it; build it from the host's camera with [`ViewData::new`] or
/// fill the fields directly.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ViewData {
    /// Projection times view, with the host's depth convention (reverse-Z or not).
    pub clip_from_world: Mat4,
    /// The camera's position in world space (shell and fin fading, highlights).
    pub camera_position_world: Vec3,
    /// Unit vector toward the key light, world space.
    pub light_direction_world: Vec3,
    /// Linear RGB.
    pub light_colour: Vec3,
    /// Light everywhere, as a fraction of the surface colour.
    pub ambient: f32,
    /// The lights the fur model loops over (light 0 is the key light).
    pub lights: LightSet,
    /// The fur model's environment.
    pub environment: Environment,
}

impl ViewData {
    /// Whether any of the sphere (`centre`, `radius`, world space) can be in this view: it is
    /// not wholly outside one of the frustum's planes (either depth convention). Hosts skip the
    /// furs it rules out (a herd's members off screen); a sphere near a corner may pass without
    /// showing.
    #[must_use]
    pub fn sees_sphere(&self, centre: Vec3, radius: f32) -> bool {
        let m = self.clip_from_world;
        let rows = [m.row(0), m.row(1), m.row(2), m.row(3)];
        let p = centre.extend(1.0);
        // -w <= x, y <= w and 0 <= z <= w, as planes (a, b, c, d) . p >= 0.
        let planes =
            [rows[3] + rows[0], rows[3] - rows[0], rows[3] + rows[1], rows[3] - rows[1], rows[2], rows[3] - rows[2]];
        planes.iter().all(|plane| {
            let length = plane.truncate().length();
            // A degenerate plane (an infinite far plane's) rules nothing out.
            length <= f32::EPSILON || plane.dot(p) / length >= -radius
        })
    }

    /// A view from the host's camera: `clip_from_world` and the camera's transform
    /// `world_from_view` (its position is the translation), with `light` resolved to world space.
    #[must_use]
    pub fn new(clip_from_world: Mat4, world_from_view: Mat4, light: &Light) -> Self {
        let light_direction_world = match light.direction {
            LightDirection::World(direction) => direction,
            LightDirection::View(direction) => world_from_view.transform_vector3(direction),
        };
        let light_direction_world = light_direction_world.normalize_or(Vec3::Y);
        // The key light as the fur model's light 0 and the ambient as a uniform environment: a
        // colour of 1 is pi lux, which shows a white Lambertian surface as white.
        let key = LightSource::directional(light_direction_world, light.colour, std::f32::consts::PI);
        Self {
            clip_from_world,
            camera_position_world: world_from_view.w_axis.truncate(),
            light_direction_world,
            light_colour: light.colour,
            ambient: light.ambient,
            lights: LightSet::new(&[key]),
            environment: Environment::uniform(Vec3::splat(light.ambient)),
        }
    }

    /// This view lit by `lights` and `environment` (none: no environment light) instead: the
    /// fur model takes them all; Kajiya-Kay takes light 0 as its key light (a point or spot
    /// light by its direction from the world origin) and the environment's mean as its ambient.
    #[must_use]
    pub fn with_lights(self, lights: &[LightSource], environment: Option<Environment>) -> Self {
        let environment = environment.unwrap_or_default();
        let (light_direction_world, light_colour) = match lights.first() {
            None => (self.light_direction_world, Vec3::ZERO),
            Some(key) => {
                let direction = match key.kind {
                    LightKind::Directional => key.direction,
                    LightKind::Point | LightKind::Spot => key.position.normalize_or(Vec3::Y),
                };
                (direction, key.intensity / std::f32::consts::PI)
            }
        };
        Self {
            light_direction_world,
            light_colour,
            ambient: luminance(environment.sh.mean()),
            lights: LightSet::new(lights),
            environment,
            ..self
        }
    }

    /// The lights' uniform (`Lights` in `fur_bsdf.wgsl`).
    pub(crate) fn lights_uniform(&self) -> LightsUniform {
        let lights = self.lights.as_slice();
        let mut light = [GpuLight::default(); MAX_LIGHTS];
        for (gpu, l) in light.iter_mut().zip(lights) {
            let (position_or_direction, cos_outer, cos_inner) = match l.kind {
                LightKind::Directional => (l.direction.extend(0.0), -2.0, -1.0),
                LightKind::Point => (l.position.extend(1.0), -2.0, -1.0),
                LightKind::Spot => (l.position.extend(1.0), l.cos_outer, l.cos_inner),
            };
            let kind = match l.kind {
                LightKind::Directional => 0,
                LightKind::Point => 1,
                LightKind::Spot => 2,
            };
            *gpu = GpuLight {
                position_or_direction,
                spot_axis_cos_outer: l.direction.extend(cos_outer),
                intensity_cos_inner: l.intensity.extend(cos_inner),
                flags: [u32::from(l.casts_shadows), kind, 0, 0],
            };
        }
        let environment_tint = tint(self.environment.sh.mean());
        let light_sum = lights.iter().fold(Vec3::ZERO, |sum, l| sum + l.intensity);
        let light_tint = if luminance(light_sum) > 0.0 { tint(light_sum) } else { environment_tint };
        LightsUniform {
            count: lights.len() as u32,
            padding_0: 0,
            padding_1: 0,
            padding_2: 0,
            light_tint: light_tint.extend(1.0),
            environment_tint: environment_tint.extend(1.0),
            environment_sh: self.environment.sh.coefficients.map(|c| c.extend(luminance(c))),
            light,
        }
    }
}

fn luminance(c: Vec3) -> f32 {
    c.dot(Vec3::new(0.2126, 0.7152, 0.0722))
}

/// `c` scaled to luminance 1 (white where it has none).
fn tint(c: Vec3) -> Vec3 {
    let l = luminance(c);
    if l > 1e-12 && c.is_finite() { c / l } else { Vec3::ONE }
}

/// One view's uniform buffer and bind group (group 0 of every Pelt pipeline). Make one per
/// camera (or per eye, per shadow view...) and [`FurView::prepare`] it each frame before
/// submitting the passes that draw with it.
#[derive(Debug)]
pub struct FurView {
    buffer: wgpu::Buffer,
    lights: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    /// Group 3: the shadow maps this view's draws read (or stand-ins).
    shadow_group: wgpu::BindGroup,
    /// Kept to drop the shadow maps again.
    no_shadows: wgpu::BindGroup,
    role: ViewRole,
}

/// What draws through a view record.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ViewRole {
    /// The host's picture, lit with the shadow maps or without.
    Camera { shadowed: bool },
    /// One pass of a shadow map, seen from the light.
    Shadow(ShadowPass),
}

/// The passes of a [`ShadowMap`](crate::ShadowMap), in order.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum ShadowPass {
    /// Everything opaque (skin, plain meshes, colliders, ground), depth only.
    Opaque,
    /// The fur's first surface (its outermost shell), depth only.
    FurDepth,
    /// The shells and fins' opacity, added into the layers beyond the first surface.
    Opacity,
}

impl FurView {
    /// [`FurView::new`] with the renderer's layouts.
    pub(crate) fn create(device: &wgpu::Device, layouts: &Layouts) -> Self {
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt view"),
            size: size_of::<ViewUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let lights = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt lights"),
            size: size_of::<LightsUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt view"),
            layout: &layouts.view,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: buffer.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: lights.as_entire_binding() },
            ],
        });
        let no_shadows = layouts.no_shadows.clone();
        Self {
            buffer,
            lights,
            bind_group,
            shadow_group: no_shadows.clone(),
            no_shadows,
            role: ViewRole::Camera { shadowed: false },
        }
    }

    /// A view of one of a shadow map's passes, reading `shadow_group`.
    pub(crate) fn shadow_pass(
        device: &wgpu::Device,
        layouts: &Layouts,
        pass: ShadowPass,
        shadow_group: wgpu::BindGroup,
    ) -> Self {
        Self { shadow_group, role: ViewRole::Shadow(pass), ..Self::create(device, layouts) }
    }

    /// Binds a shadow map's receiver group (`None`: the stand-ins, no shadows); hosts call
    /// `FurView::set_shadows` (`shadows.rs`).
    pub(crate) fn set_shadow_group(&mut self, group: Option<&wgpu::BindGroup>) {
        self.shadow_group = group.map_or_else(|| self.no_shadows.clone(), Clone::clone);
        self.role = ViewRole::Camera { shadowed: group.is_some() };
    }

    /// This view drawing without shadows: the same uniforms (prepared with it), for objects
    /// that receive no shadows (Bevy's `NotShadowReceiver`).
    #[must_use]
    pub fn unshadowed(&self) -> Self {
        Self {
            buffer: self.buffer.clone(),
            lights: self.lights.clone(),
            bind_group: self.bind_group.clone(),
            shadow_group: self.no_shadows.clone(),
            no_shadows: self.no_shadows.clone(),
            role: match self.role {
                ViewRole::Camera { .. } => ViewRole::Camera { shadowed: false },
                role @ ViewRole::Shadow(_) => role,
            },
        }
    }

    /// Whether draws through this view read a shadow map.
    #[must_use]
    pub fn has_shadows(&self) -> bool {
        self.role == ViewRole::Camera { shadowed: true }
    }

    pub(crate) fn role(&self) -> ViewRole {
        self.role
    }

    pub(crate) fn shadow_group(&self) -> &wgpu::BindGroup {
        &self.shadow_group
    }

    /// Writes this frame's view (takes effect at the next submission).
    pub fn prepare(&self, queue: &wgpu::Queue, data: &ViewData) {
        let uniform = ViewUniform {
            clip_from_world: data.clip_from_world,
            camera_position: data.camera_position_world,
            ambient: data.ambient,
            light_direction: data.light_direction_world,
            _padding_0: 0.0,
            light_colour: data.light_colour,
            _padding_1: 0.0,
        };
        queue.write_buffer(&self.buffer, 0, bytemuck::bytes_of(&uniform));
        queue.write_buffer(&self.lights, 0, bytemuck::bytes_of(&data.lights_uniform()));
    }

    pub(crate) fn bind_group(&self) -> &wgpu::BindGroup {
        &self.bind_group
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_sphere_is_seen_unless_wholly_outside_a_plane() {
        // From +Z 10 units out, looking at the origin, 35 degrees high, square.
        let fov = 35.0_f32.to_radians();
        let eye = Vec3::new(0.0, 0.0, 10.0);
        let world_from_view = glam::camera::rh::view::look_at_mat4(eye, Vec3::ZERO, Vec3::Y).inverse();
        let clip_from_view = glam::camera::rh::proj::directx::perspective(fov, 1.0, 0.1, 100.0);
        let clip_from_world = clip_from_view * world_from_view.inverse();
        let view = ViewData::new(clip_from_world, world_from_view, &Light::default());
        assert!(view.sees_sphere(Vec3::ZERO, 0.1));
        // Behind the camera, far to the side of the view, and past the far plane.
        assert!(!view.sees_sphere(Vec3::new(0.0, 0.0, 20.0), 1.0));
        assert!(!view.sees_sphere(Vec3::new(50.0, 0.0, 0.0), 1.0));
        assert!(!view.sees_sphere(Vec3::new(0.0, 0.0, -150.0), 1.0));
        // Just outside the left edge, and the same sphere grown to reach in.
        let half_width = 10.0 * (0.5 * fov).tan();
        let outside = Vec3::new(-(half_width + 0.6), 0.0, 0.0);
        assert!(!view.sees_sphere(outside, 0.4));
        assert!(view.sees_sphere(outside, 0.8));
    }

    #[test]
    fn view_space_light_turns_with_the_camera() {
        let world_from_view = Mat4::from_rotation_translation(
            glam::Quat::from_rotation_y(std::f32::consts::FRAC_PI_2),
            Vec3::new(1.0, 2.0, 3.0),
        );
        let light = Light { direction: LightDirection::View(Vec3::Z), ..Light::default() };
        let view = ViewData::new(Mat4::IDENTITY, world_from_view, &light);
        assert!(view.camera_position_world.distance(Vec3::new(1.0, 2.0, 3.0)) < 1e-6);
        assert!(view.light_direction_world.distance(Vec3::X) < 1e-6, "{}", view.light_direction_world);
        let sun = Light { direction: LightDirection::World(Vec3::new(0.0, 2.0, 0.0)), ..light };
        assert!(ViewData::new(Mat4::IDENTITY, world_from_view, &sun).light_direction_world.distance(Vec3::Y) < 1e-6);
    }
}
