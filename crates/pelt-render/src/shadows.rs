//! The key light's shadows: [`ShadowMap`], three views of the same renderer from the light.
//!
//! 1. Everything opaque (the furs' skin, plain meshes, colliders, a ground) draws depth only: the
//!    opaque shadow map, sampled with a few filtered taps.
//! 2. The furs' outermost shells draw depth only: the fur's first surface from the light (z0).
//! 3. The shells and fins draw their opacity, added into four cumulative layers by depth past z0
//!    (a deep opacity map, Yuksel & Keyser 2008), tested against the opaque map.
//!
//! A view lit with the map ([`FurView::set_shadows`]) reads a point's visibility as the opaque
//! taps times the fur's transmittance `exp(-extinction * opacity)` at its depth (`shadows.wgsl`).

use glam::{Vec3, Vec4};
use pelt_core::light::LightKind;

use crate::RenderError;
use crate::renderer::FurRenderer;
use crate::shaders::{
    SHADOW_DEPTH_FORMAT as DEPTH_FORMAT, SHADOW_OPACITY_FORMAT as OPACITY_FORMAT, ShadowUniform, shadow_texture,
};
use crate::view::{FurView, ShadowPass, ViewData};

/// The light that casts the shadows ([`ShadowCaster::for_key_light`] picks a view's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ShadowCaster {
    /// A sun toward `toward_light` (world space): an orthographic view fitted to the scene.
    Directional {
        /// Toward the light.
        toward_light: Vec3,
    },
    /// A spot light at `position` shining along `direction` in a cone of half-angle `cone_rad`:
    /// a perspective view.
    Spot {
        /// World space.
        position: Vec3,
        /// Where the light points.
        direction: Vec3,
        /// Half the cone's opening, radians (`0 < cone_rad < pi / 2`).
        cone_rad: f32,
    },
}

impl ShadowCaster {
    /// The caster of `view`'s key light (light 0, else its sun) for a scene within `radius` of
    /// `centre`. A sun casts along its direction. A spot or point light outside that sphere casts
    /// a perspective view aimed at its centre, just wide enough to hold it (a point light's
    /// shadows fall away from it, as a spot's do); inside it, a spot keeps its own cone and a
    /// point light casts as a sun from where it stands (its shadows in every direction would take
    /// six views).
    #[must_use]
    pub fn for_key_light(view: &ViewData, (centre, radius): (Vec3, f32)) -> Self {
        let Some(key) = view.lights.as_slice().first().filter(|l| l.kind != LightKind::Directional) else {
            return Self::Directional { toward_light: view.light_direction_world };
        };
        let to_centre = centre - key.position;
        let distance = to_centre.length();
        if distance > radius * 1.01 {
            // A hair wider than the sphere, so its rim stays inside the map.
            let cone_rad = ((radius / distance).asin() * 1.05).min(1.5);
            return Self::Spot { position: key.position, direction: to_centre / distance, cone_rad };
        }
        match key.kind {
            LightKind::Spot => Self::Spot {
                position: key.position,
                direction: key.direction,
                cone_rad: key.cos_outer.clamp(-1.0, 1.0).acos().clamp(0.01, 1.5),
            },
            _ => Self::Directional { toward_light: (key.position - centre).normalize_or(Vec3::Y) },
        }
    }
}

/// A shadow map's resolution and how the fur takes light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShadowSettings {
    /// Texels along each side of the opaque map (the fur's maps have half as many).
    pub size: u32,
    /// How deep (world units) below the fur's first surface the opacity layers reach: about
    /// the fur's length.
    pub fur_depth: f32,
    /// How fast light dies in fur: the transmittance is `exp(-extinction * opacity)`, the
    /// opacity the sum of the strands' alpha in front.
    pub extinction: f32,
}

impl ShadowSettings {
    /// Pelt's default map (512 texels a side) for fur `fur_length` long.
    #[must_use]
    pub fn for_fur(fur_length: f32) -> Self {
        Self { size: MAX_FITTED_SIZE, fur_depth: fur_length, extinction: 0.6 }
    }

    /// [`ShadowSettings::for_fur`] with the map fitted to a `width` x `height` picture
    /// ([`fitted_shadow_size`]).
    #[must_use]
    pub fn for_frame(fur_length: f32, (width, height): (u32, u32)) -> Self {
        Self { size: fitted_shadow_size(width, height), ..Self::for_fur(fur_length) }
    }
}

/// The largest map [`fitted_shadow_size`] gives, and [`ShadowSettings::for_fur`]'s.
pub const MAX_FITTED_SIZE: u32 = 512;

/// The opaque map's side for a `width` x `height` picture: the picture's longer side rounded up
/// to a power of two, 256 to [`MAX_FITTED_SIZE`]. Both frame the scene's bounds, so a shadow
/// texel stays about a pixel, and a small picture does not pay for a large map's depth and
/// opacity passes (most of a 256x256 frame's shadow cost on a software rasteriser).
#[must_use]
pub fn fitted_shadow_size(width: u32, height: u32) -> u32 {
    width.max(height).max(1).next_power_of_two().clamp(256, MAX_FITTED_SIZE)
}

/// The key light's shadow maps: an opaque depth map, the fur's first surface and its opacity
/// layers (the first `size` squared, the fur's half that). Make one per light and renderer; each frame
/// [`ShadowMap::prepare`] it, [`ShadowMap::record`] it before the picture's pass, and draw the
/// picture through a view lit with it ([`FurView::set_shadows`]).
#[derive(Debug)]
pub struct ShadowMap {
    settings: ShadowSettings,
    uniform: wgpu::Buffer,
    depth: wgpu::TextureView,
    fur_depth: wgpu::TextureView,
    opacity: wgpu::TextureView,
    /// The three passes' views (`ShadowPass` order).
    views: [FurView; 3],
    receiver: wgpu::BindGroup,
}

impl ShadowMap {
    /// The maps for drawing with `renderer`.
    ///
    /// # Errors
    /// [`RenderError::Target`] for a size of 0 or past the device's texture limit, or a fur depth
    /// or extinction that is not a positive (or zero extinction) finite number.
    pub fn new(device: &wgpu::Device, renderer: &FurRenderer, settings: ShadowSettings) -> Result<Self, RenderError> {
        let max = device.limits().max_texture_dimension_2d;
        if settings.size == 0 || settings.size > max {
            return Err(RenderError::Target(format!("a shadow map of {} texels a side (1 to {max})", settings.size)));
        }
        if !(settings.fur_depth.is_finite() && settings.fur_depth > 0.0) {
            return Err(RenderError::Target(format!(
                "a shadow fur depth of {} (a positive length)",
                settings.fur_depth
            )));
        }
        if !(settings.extinction.is_finite() && settings.extinction >= 0.0) {
            return Err(RenderError::Target(format!("a shadow extinction of {} (0 or more)", settings.extinction)));
        }
        let layouts = renderer.layouts();
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt shadow"),
            size: size_of::<ShadowUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let size = settings.size;
        let depth = shadow_texture(device, DEPTH_FORMAT, size, true);
        // The fur's maps at half the size: light through fur varies smoothly, and the opacity
        // pass's fragments were most of a small picture's shadow cost.
        let fur_size = size.div_ceil(2);
        let fur_depth = shadow_texture(device, DEPTH_FORMAT, fur_size, true);
        let opacity = shadow_texture(device, OPACITY_FORMAT, fur_size, true);
        // The opacity pass reads z0; what it draws into stands in as 1x1 textures.
        let stand_in_depth = shadow_texture(device, DEPTH_FORMAT, 1, false);
        let stand_in_opacity = shadow_texture(device, OPACITY_FORMAT, 1, false);
        let caster = layouts.shadow_group(device, &uniform, (&stand_in_depth, &fur_depth, &stand_in_opacity));
        let receiver = layouts.shadow_group(device, &uniform, (&depth, &fur_depth, &opacity));
        let views = [
            FurView::shadow_pass(device, layouts, ShadowPass::Opaque, layouts.no_shadows.clone()),
            FurView::shadow_pass(device, layouts, ShadowPass::FurDepth, layouts.no_shadows.clone()),
            FurView::shadow_pass(device, layouts, ShadowPass::Opacity, caster),
        ];
        Ok(Self { settings, uniform, depth, fur_depth, opacity, views, receiver })
    }

    /// The settings the maps were made with.
    #[must_use]
    pub fn settings(&self) -> ShadowSettings {
        self.settings
    }

    /// Aims the light's views at the scene: everything that casts lies within `radius` of
    /// `centre` (world space). Receivers further from the light than that compare as at the far
    /// edge, so a ground below the casters takes their shadow without being inside.
    pub fn prepare(&self, queue: &wgpu::Queue, caster: &ShadowCaster, (centre, radius): (Vec3, f32)) {
        let radius = if radius.is_finite() && radius > 0.0 { radius } else { 1.0 };
        let size = self.settings.size as f32;
        let (eye, forward, projection, near, far, texel_world, perspective) = match *caster {
            ShadowCaster::Directional { toward_light } => {
                let toward = toward_light.normalize_or(Vec3::Y);
                let eye = centre + toward * (2.0 * radius);
                let (near, far) = (radius, 3.0 * radius);
                let projection =
                    glam::camera::rh::proj::directx::orthographic(-radius, radius, -radius, radius, near, far);
                (eye, -toward, projection, near, far, 2.0 * radius / size, 0.0)
            }
            ShadowCaster::Spot { position, direction, cone_rad } => {
                let forward = direction.normalize_or(-Vec3::Y);
                let cone = cone_rad.clamp(0.01, 1.5);
                let distance = (centre - position).length().max(1e-3);
                let far = distance + radius;
                let near = (distance - radius).max(far * 1e-3);
                let projection = glam::camera::rh::proj::directx::perspective(2.0 * cone, 1.0, near, far);
                (position, forward, projection, near, far, 2.0 * distance * cone.tan() / size, 1.0)
            }
        };
        let up = if forward.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
        let light_clip_from_world = projection * glam::camera::rh::view::look_to_mat4(eye, forward, up);
        let d = self.settings.fur_depth;
        let uniform = ShadowUniform {
            light_clip_from_world,
            texel_world,
            bias_world: texel_world,
            extinction: self.settings.extinction,
            perspective,
            near,
            far,
            texel: 1.0 / size,
            _padding: 0.0,
            layer_ends: Vec4::new(0.2 * d, 0.5 * d, 1.0 * d, 2.0 * d),
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        let data = ViewData {
            clip_from_world: light_clip_from_world,
            camera_position_world: eye,
            light_direction_world: -forward,
            light_colour: Vec3::ONE,
            ambient: 0.0,
            lights: crate::view::LightSet::default(),
            environment: pelt_core::light::Environment::default(),
        };
        for view in &self.views {
            view.prepare(queue, &data);
        }
    }

    /// Records the three passes into `encoder`; `draw` records the scene into each through the
    /// view it is given, with the same [`FurRenderer::draw`] and
    /// [`FurRenderer::draw_plain`] calls as the picture (each draws what that pass needs).
    pub fn record(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        mut draw: impl FnMut(&mut wgpu::RenderPass<'_>, &FurView),
    ) {
        let clear_depth = |view| wgpu::RenderPassDepthStencilAttachment {
            view,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
            stencil_ops: None,
        };
        for (label, depth, view) in [
            ("pelt shadow opaque", &self.depth, &self.views[0]),
            ("pelt shadow fur depth", &self.fur_depth, &self.views[1]),
        ] {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some(label),
                color_attachments: &[],
                depth_stencil_attachment: Some(clear_depth(depth)),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            draw(&mut pass, view);
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("pelt shadow opacity"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: &self.opacity,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations {
                    load: wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
                    store: wgpu::StoreOp::Store,
                },
            })],
            // No depth test against the opaque map (another size): fur behind the opaque
            // casters adds opacity only past their own shadow.
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        draw(&mut pass, &self.views[2]);
    }

    /// Group 3 of the views lit with these maps.
    pub(crate) fn receiver_group(&self) -> &wgpu::BindGroup {
        &self.receiver
    }
}

impl FurView {
    /// Lights the draws through this view with `shadows` (the key light's shadow map, recorded
    /// with [`ShadowMap::record`] before this view's pass), or without shadows (`None`).
    pub fn set_shadows(&mut self, shadows: Option<&ShadowMap>) {
        self.set_shadow_group(shadows.map(ShadowMap::receiver_group));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use pelt_core::light::LightSource;

    fn view_with(light: LightSource) -> ViewData {
        let camera = crate::Camera::orbit(Vec3::ZERO, 0.0, 20.0, 4.0);
        camera.view_data(1.0, &crate::Light::default()).with_lights(&[light], None)
    }

    #[test]
    fn a_point_or_spot_key_light_outside_the_scene_casts_a_view_aimed_at_it() {
        let point = LightSource {
            kind: LightKind::Point,
            position: Vec3::new(0.0, 3.0, 0.0),
            ..LightSource::directional(Vec3::Y, Vec3::ONE, 1.0)
        };
        let ShadowCaster::Spot { position, direction, cone_rad } =
            ShadowCaster::for_key_light(&view_with(point), (Vec3::ZERO, 1.5))
        else {
            panic!("a point light above the scene casts a perspective view");
        };
        assert_eq!(position, point.position);
        assert!(direction.distance(Vec3::NEG_Y) < 1e-6, "{direction}");
        // Just wider than the sphere's silhouette from the light: asin(1.5 / 3) = 30 degrees.
        assert!(cone_rad > 30f32.to_radians() && cone_rad < 33f32.to_radians(), "{cone_rad}");
        let sun = LightSource::directional(Vec3::new(1.0, 1.0, 0.0), Vec3::ONE, 1.0);
        assert_eq!(
            ShadowCaster::for_key_light(&view_with(sun), (Vec3::ZERO, 1.5)),
            ShadowCaster::Directional { toward_light: sun.direction }
        );
    }

    #[test]
    fn the_fitted_map_follows_the_pictures_longer_side_within_256_to_512() {
        let cases = [((64, 64), 256), ((256, 256), 256), ((257, 100), 512), ((300, 480), 512), ((1280, 720), 512)];
        for ((width, height), size) in cases {
            assert_eq!(fitted_shadow_size(width, height), size, "{width}x{height}");
        }
        assert_eq!(fitted_shadow_size(0, 0), 256);
        assert_eq!(ShadowSettings::for_frame(0.1, (1920, 1080)), ShadowSettings::for_fur(0.1));
    }
}
