//! The lights' shadows: [`ShadowMap`], three views of the same renderer from each light view.
//!
//! 1. Everything opaque (the furs' skin, plain meshes, colliders, a ground) draws depth only: the
//!    opaque shadow map, sampled with a few filtered taps.
//! 2. The furs' outermost shells draw depth only: the fur's first surface from the light (z0).
//! 3. The shells and fins draw their opacity, added into four cumulative layers by depth past z0
//!    (a deep opacity map, Yuksel & Keyser 2008), tested against the opaque map.
//!
//! A directional or spot light takes one light view, a point light inside the scene six (a cube);
//! each is a layer of the maps' array textures. A view lit with the map
//! ([`FurView::set_shadows`]) reads a point's visibility from each shadowing light as the opaque
//! taps times the fur's transmittance `exp(-extinction * opacity)` at its depth (`shadows.wgsl`).

use glam::{Mat4, Vec3, Vec4};
use pelt_core::light::{LightKind, LightSource, MAX_LIGHTS};

use crate::RenderError;
use crate::renderer::FurRenderer;
use crate::shaders::{
    SHADOW_DEPTH_FORMAT as DEPTH_FORMAT, SHADOW_OPACITY_FORMAT as OPACITY_FORMAT, SHADOW_VIEWS, ShadowUniform,
    ShadowViewUniform, array_view, shadow_texture,
};
use crate::view::{FurView, ShadowLookups, ShadowPass, ViewData};

/// The most light views one [`ShadowMap`] holds: a point light takes six, a directional or spot
/// light one. Shadowing lights past them cast no shadow.
pub const MAX_SHADOW_VIEWS: u32 = SHADOW_VIEWS as u32;

/// How a light casts its shadows ([`ShadowCaster::for_light`] picks a light's).
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
    /// A point light at `position` among the casters: six perspective views, a cube about it.
    Point {
        /// World space.
        position: Vec3,
    },
}

/// The cube's faces in the order `shadows.wgsl` picks them: +x, -x, +y, -y, +z, -z.
const CUBE_FACES: [Vec3; 6] = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];

impl ShadowCaster {
    /// How `light` casts for a scene within `radius` of `centre`. A sun casts along its
    /// direction. A spot or point light outside that sphere casts one perspective view aimed at
    /// its centre, just wide enough to hold it (a point light's shadows then all fall away from
    /// it, as a spot's do); inside it, a spot keeps its own cone and a point light casts a cube.
    #[must_use]
    pub fn for_light(light: &LightSource, (centre, radius): (Vec3, f32)) -> Self {
        if light.kind == LightKind::Directional {
            return Self::Directional { toward_light: light.direction };
        }
        let to_centre = centre - light.position;
        let distance = to_centre.length();
        if distance > radius * 1.01 {
            // A hair wider than the sphere, so its rim stays inside the map.
            let cone_rad = ((radius / distance).asin() * 1.05).min(1.5);
            return Self::Spot { position: light.position, direction: to_centre / distance, cone_rad };
        }
        match light.kind {
            LightKind::Spot => Self::Spot {
                position: light.position,
                direction: light.direction,
                cone_rad: light.cos_outer.clamp(-1.0, 1.0).acos().clamp(0.01, 1.5),
            },
            _ => Self::Point { position: light.position },
        }
    }

    /// The caster of `view`'s key light (light 0, else the view's own light direction, a sun).
    #[must_use]
    pub fn for_key_light(view: &ViewData, bounds: (Vec3, f32)) -> Self {
        view.lights
            .as_slice()
            .first()
            .map_or(Self::Directional { toward_light: view.light_direction_world }, |key| Self::for_light(key, bounds))
    }

    /// Every shadowing light of `view` by its index and how it casts: the lights that cast
    /// shadows, or the view's own key light where it has no lights (light 0, a sun).
    #[must_use]
    pub fn for_view(view: &ViewData, bounds: (Vec3, f32)) -> Vec<(usize, Self)> {
        let lights = view.lights.as_slice();
        if lights.is_empty() {
            return vec![(0, Self::Directional { toward_light: view.light_direction_world })];
        }
        lights
            .iter()
            .enumerate()
            .filter(|(_, light)| light.casts_shadows)
            .map(|(index, light)| (index, Self::for_light(light, bounds)))
            .collect()
    }

    /// How many light views it takes: six for a point light's cube, else one.
    #[must_use]
    pub fn view_count(&self) -> u32 {
        if matches!(self, Self::Point { .. }) { 6 } else { 1 }
    }

    /// Light view `face` (`0..view_count()`) of a map `size` texels a side aimed at the scene
    /// within `radius` of `centre`: its uniform, its view data for the passes, and whether it sees
    /// any of the scene (a cube face that does not is cleared and not drawn).
    fn light_view(&self, face: usize, (centre, radius): (Vec3, f32), size: f32) -> (ShadowViewUniform, ViewData, bool) {
        let (eye, forward, projection, near, far, texel_world, light, seen) = match *self {
            ShadowCaster::Directional { toward_light } => {
                let toward = toward_light.normalize_or(Vec3::Y);
                let eye = centre + toward * (2.0 * radius);
                let (near, far) = (radius, 3.0 * radius);
                let projection =
                    glam::camera::rh::proj::directx::orthographic(-radius, radius, -radius, radius, near, far);
                (eye, -toward, projection, near, far, 2.0 * radius / size, toward.extend(0.0), true)
            }
            ShadowCaster::Spot { position, direction, cone_rad } => {
                let forward = direction.normalize_or(-Vec3::Y);
                let cone = cone_rad.clamp(0.01, 1.5);
                let distance = (centre - position).length().max(1e-3);
                let far = distance + radius;
                let near = (distance - radius).max(far * 1e-3);
                let projection = glam::camera::rh::proj::directx::perspective(2.0 * cone, 1.0, near, far);
                let texel_world = 2.0 * distance * cone.tan() / size;
                (position, forward, projection, near, far, texel_world, position.extend(1.0), true)
            }
            ShadowCaster::Point { position } => {
                let forward = CUBE_FACES[face.min(5)];
                // Four texels wider than a quarter turn, so the taps at a face's edge stay in it.
                let half_tan = 1.0 + 4.0 / size;
                let to_centre = centre - position;
                let distance = to_centre.length();
                let far = distance + radius;
                let near = (distance - radius).max(far * 1e-3);
                let projection = glam::camera::rh::proj::directx::perspective(2.0 * half_tan.atan(), 1.0, near, far);
                // The face's frustum lies within a cone of half-angle atan(sqrt(2) * half_tan).
                let seen = distance <= radius
                    || forward.angle_between(to_centre)
                        <= (std::f32::consts::SQRT_2 * half_tan).atan() + (radius / distance).min(1.0).asin();
                let texel_world = 2.0 * distance.max(radius) * half_tan / size;
                (position, forward, projection, near, far, texel_world, position.extend(1.0), seen)
            }
        };
        let perspective = if matches!(self, Self::Directional { .. }) { 0.0 } else { 1.0 };
        let up = if forward.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
        let light_clip_from_world: Mat4 = projection * glam::camera::rh::view::look_to_mat4(eye, forward, up);
        let uniform = ShadowViewUniform {
            light_clip_from_world,
            light,
            texel_world,
            bias_world: texel_world,
            perspective,
            near,
            far,
            texel: 1.0 / size,
            _padding_0: 0.0,
            _padding_1: 0.0,
        };
        let data = ViewData {
            clip_from_world: light_clip_from_world,
            camera_position_world: eye,
            light_direction_world: -forward,
            light_colour: Vec3::ONE,
            ambient: 0.0,
            lights: crate::view::LightSet::default(),
            environment: pelt_core::light::Environment::default(),
        };
        (uniform, data, seen)
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

/// The lights' shadow maps: per light view an opaque depth map, the fur's first surface and its
/// opacity layers (the first `size` squared, the fur's half that), each a layer of an array
/// texture. Make one per renderer; each frame [`ShadowMap::prepare`] it with the shadowing lights,
/// [`ShadowMap::record`] it before the picture's pass, and draw the picture through a view lit with
/// it ([`FurView::set_shadows`]).
#[derive(Debug)]
pub struct ShadowMap {
    settings: ShadowSettings,
    /// What the picture's views read (`shadows.wgsl`'s `Shadow`).
    uniform: wgpu::Buffer,
    /// One per light view the maps hold.
    slots: Vec<LightView>,
    receiver: wgpu::BindGroup,
    /// The light views this frame's lights use, and which of them see the scene.
    used: Vec<bool>,
    /// This frame's only light view is light 0's (the lookups read it at fixed offsets).
    key_only: bool,
}

/// One light view's layers and the three passes' views into them.
#[derive(Debug)]
struct LightView {
    depth: wgpu::TextureView,
    fur_depth: wgpu::TextureView,
    opacity: wgpu::TextureView,
    /// The opacity pass's copy of the uniform, naming this view (`pass_view`).
    caster_uniform: wgpu::Buffer,
    /// The three passes' views (`ShadowPass` order).
    views: [FurView; 3],
}

impl ShadowMap {
    /// The maps for drawing with `renderer`, with room for one light view (a sun or a spot).
    ///
    /// # Errors
    /// As [`ShadowMap::with_views`].
    pub fn new(device: &wgpu::Device, renderer: &FurRenderer, settings: ShadowSettings) -> Result<Self, RenderError> {
        Self::with_views(device, renderer, settings, 1)
    }

    /// The maps with room for `views` light views (a point light takes six; at most
    /// [`MAX_SHADOW_VIEWS`]).
    ///
    /// # Errors
    /// [`RenderError::Target`] for a size of 0 or past the device's texture limit, no views or
    /// more than [`MAX_SHADOW_VIEWS`], or a fur depth or extinction that is not a positive (or
    /// zero extinction) finite number.
    pub fn with_views(
        device: &wgpu::Device,
        renderer: &FurRenderer,
        settings: ShadowSettings,
        views: u32,
    ) -> Result<Self, RenderError> {
        let max = device.limits().max_texture_dimension_2d;
        if settings.size == 0 || settings.size > max {
            return Err(RenderError::Target(format!("a shadow map of {} texels a side (1 to {max})", settings.size)));
        }
        let max_layers = device.limits().max_texture_array_layers.min(MAX_SHADOW_VIEWS);
        if views == 0 || views > max_layers {
            return Err(RenderError::Target(format!("a shadow map of {views} light views (1 to {max_layers})")));
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
        let uniform_buffer = |label| {
            device.create_buffer(&wgpu::BufferDescriptor {
                label: Some(label),
                size: size_of::<ShadowUniform>() as u64,
                usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            })
        };
        let uniform = uniform_buffer("pelt shadow");
        let size = settings.size;
        let depth = shadow_texture(device, DEPTH_FORMAT, (size, views), true);
        // The fur's maps at half the size: light through fur varies smoothly, and the opacity
        // pass's fragments were most of a small picture's shadow cost.
        let fur_size = size.div_ceil(2);
        let fur_depth = shadow_texture(device, DEPTH_FORMAT, (fur_size, views), true);
        let opacity = shadow_texture(device, OPACITY_FORMAT, (fur_size, views), true);
        // The opacity pass reads z0; what it draws into stands in as 1x1 textures.
        let stand_in_depth = array_view(&shadow_texture(device, DEPTH_FORMAT, (1, 1), false));
        let stand_in_opacity = array_view(&shadow_texture(device, OPACITY_FORMAT, (1, 1), false));
        let fur_depth_array = array_view(&fur_depth);
        let layer = |texture: &wgpu::Texture, index| {
            texture.create_view(&wgpu::TextureViewDescriptor {
                dimension: Some(wgpu::TextureViewDimension::D2),
                base_array_layer: index,
                array_layer_count: Some(1),
                ..wgpu::TextureViewDescriptor::default()
            })
        };
        let slots = (0..views)
            .map(|index| {
                let caster_uniform = uniform_buffer("pelt shadow caster");
                let caster = layouts.shadow_group(
                    device,
                    &caster_uniform,
                    (&stand_in_depth, &fur_depth_array, &stand_in_opacity),
                );
                LightView {
                    depth: layer(&depth, index),
                    fur_depth: layer(&fur_depth, index),
                    opacity: layer(&opacity, index),
                    caster_uniform,
                    views: [
                        FurView::shadow_pass(device, layouts, ShadowPass::Opaque, layouts.no_shadows.clone()),
                        FurView::shadow_pass(device, layouts, ShadowPass::FurDepth, layouts.no_shadows.clone()),
                        FurView::shadow_pass(device, layouts, ShadowPass::Opacity, caster),
                    ],
                }
            })
            .collect();
        let receiver =
            layouts.shadow_group(device, &uniform, (&array_view(&depth), &fur_depth_array, &array_view(&opacity)));
        Ok(Self { settings, uniform, slots, receiver, used: Vec::new(), key_only: false })
    }

    /// The settings the maps were made with.
    #[must_use]
    pub fn settings(&self) -> ShadowSettings {
        self.settings
    }

    /// How many light views the maps hold.
    #[must_use]
    pub fn view_capacity(&self) -> u32 {
        self.slots.len() as u32
    }

    /// Aims the maps at `casters` (each a light's index in the picture's view and how it
    /// casts, as [`ShadowCaster::for_view`] lists them): everything that casts lies within
    /// `radius` of `centre` (world space). Receivers further from a light than that compare as at
    /// the far edge, so a ground below the casters takes their shadow without being inside.
    /// `light_count` is how many lights the picture's view has. Returns how many of `casters`
    /// have maps: those past the room the maps have (or past light 7) cast no shadow.
    pub fn prepare(
        &mut self,
        queue: &wgpu::Queue,
        (casters, light_count): (&[(usize, ShadowCaster)], usize),
        (centre, radius): (Vec3, f32),
    ) -> usize {
        let radius = if radius.is_finite() && radius > 0.0 { radius } else { 1.0 };
        let size = self.settings.size as f32;
        let d = self.settings.fur_depth;
        let mut uniform = ShadowUniform {
            extinction: self.settings.extinction,
            pass_view: 0,
            layers: self.slots.len() as u32,
            _padding_1: 0,
            layer_ends: Vec4::new(0.2 * d, 0.5 * d, 1.0 * d, 2.0 * d),
            light_views: [[0; 4]; MAX_LIGHTS],
            views: [ShadowViewUniform::default(); SHADOW_VIEWS],
        };
        self.used.clear();
        let mut cast = 0;
        let mut lights = Vec::new();
        for &(light, caster) in casters {
            let first = self.used.len();
            let count = caster.view_count() as usize;
            if light >= MAX_LIGHTS || first + count > self.slots.len() {
                continue;
            }
            uniform.light_views[light] = [first as u32, count as u32, 0, 0];
            for face in 0..count {
                let (view_uniform, data, seen) = caster.light_view(face, (centre, radius), size);
                uniform.views[first + face] = view_uniform;
                for view in &self.slots[first + face].views {
                    view.prepare(queue, &data);
                }
                self.used.push(seen);
            }
            lights.push(light);
            cast += 1;
        }
        // One light, casting one view: the studio's key light, read at fixed offsets.
        self.key_only = light_count <= 1 && lights == [0] && self.used.len() == 1;
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        for (index, slot) in self.slots.iter().enumerate().take(self.used.len()) {
            uniform.pass_view = index as u32;
            queue.write_buffer(&slot.caster_uniform, 0, bytemuck::bytes_of(&uniform));
        }
        cast
    }

    /// Records the three passes of every light view in use into `encoder`; `draw` records the
    /// scene into each through the view it is given, with the same [`FurRenderer::draw`] and
    /// [`FurRenderer::draw_plain`] calls as the picture (each draws what that pass needs). A cube
    /// face that sees none of the scene is cleared only.
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
        for (slot, &seen) in self.slots.iter().zip(&self.used) {
            for (label, depth, view) in [
                ("pelt shadow opaque", &slot.depth, &slot.views[0]),
                ("pelt shadow fur depth", &slot.fur_depth, &slot.views[1]),
            ] {
                let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                    label: Some(label),
                    color_attachments: &[],
                    depth_stencil_attachment: Some(clear_depth(depth)),
                    timestamp_writes: None,
                    occlusion_query_set: None,
                    multiview_mask: None,
                });
                if seen {
                    draw(&mut pass, view);
                }
            }
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("pelt shadow opacity"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &slot.opacity,
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
            if seen {
                draw(&mut pass, &slot.views[2]);
            }
        }
    }

    /// Group 3 of the views lit with these maps, and how their draws read them.
    pub(crate) fn receiver(&self) -> (&wgpu::BindGroup, ShadowLookups) {
        (&self.receiver, if self.key_only { ShadowLookups::Key } else { ShadowLookups::Every })
    }
}

impl FurView {
    /// Lights the draws through this view with `shadows` (the lights' shadow maps, recorded
    /// with [`ShadowMap::record`] before this view's pass), or without shadows (`None`).
    pub fn set_shadows(&mut self, shadows: Option<&ShadowMap>) {
        self.set_shadow_group(shadows.map(ShadowMap::receiver));
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
    fn every_shadowing_light_casts_and_a_point_light_among_the_casters_takes_a_cube() {
        let point = LightSource {
            kind: LightKind::Point,
            position: Vec3::new(0.2, 0.5, 0.0),
            ..LightSource::directional(Vec3::Y, Vec3::ONE, 1.0)
        };
        let sun = LightSource::directional(Vec3::new(1.0, 1.0, 0.0), Vec3::ONE, 1.0);
        let unshadowed = LightSource { casts_shadows: false, ..sun };
        let camera = crate::Camera::orbit(Vec3::ZERO, 0.0, 20.0, 4.0);
        let view = camera.view_data(1.0, &crate::Light::default()).with_lights(&[sun, unshadowed, point], None);
        let casters = ShadowCaster::for_view(&view, (Vec3::ZERO, 1.5));
        assert_eq!(
            casters,
            vec![
                (0, ShadowCaster::Directional { toward_light: sun.direction }),
                (2, ShadowCaster::Point { position: point.position }),
            ]
        );
        assert_eq!(casters.iter().map(|(_, c)| c.view_count()).sum::<u32>(), 7);
        // Without lights, the view's own key light casts as a sun.
        let paper = camera.view_data(1.0, &crate::Light::default());
        let key = ShadowCaster::for_view(&paper, (Vec3::ZERO, 1.5));
        assert!(
            matches!(key[..], [(0, ShadowCaster::Directional { toward_light })]
                if toward_light.distance(paper.light_direction_world) < 1e-6),
            "{key:?}"
        );
    }

    #[test]
    fn a_cube_face_projects_what_lies_toward_it_and_skips_a_scene_behind_it() {
        let position = Vec3::new(0.0, 3.0, 0.0);
        let cube = ShadowCaster::Point { position };
        let bounds = (Vec3::ZERO, 1.0);
        for (face, axis) in CUBE_FACES.iter().enumerate() {
            let (uniform, data, _) = cube.light_view(face, bounds, 256.0);
            // A point as far along the face's axis as the scene's centre lands at the middle of
            // its map, within its depth range.
            let clip = uniform.light_clip_from_world * (position + *axis * 3.0).extend(1.0);
            let ndc = clip.truncate() / clip.w;
            assert!(ndc.truncate().length() < 1e-5 && (0.0..=1.0).contains(&ndc.z), "face {face}: {ndc}");
            assert_eq!(data.camera_position_world, position);
        }
        // The scene lies below the light, within 20 degrees of straight down: only the face
        // looking down sees it. From inside the scene every face does.
        let seen = |cube: ShadowCaster| (0..6).map(|face| cube.light_view(face, bounds, 256.0).2).collect::<Vec<_>>();
        assert_eq!(seen(cube), [false, false, false, true, false, false]);
        assert_eq!(seen(ShadowCaster::Point { position: Vec3::new(0.0, 0.5, 0.0) }), [true; 6]);
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
