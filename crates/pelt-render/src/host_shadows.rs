//! Shadows a host draws itself ([`HostShadows`]): an engine's shadow maps (Bevy's directional
//! cascades, spot lights and point lights' cube faces), each copied into a layer of Pelt's maps
//! with the view that drew it,
//! so the fur receives what the engine's meshes cast through the same lookups as its own maps
//! (`shadows.wgsl`). The fur has no deep opacity map here: what it casts into the engine's maps
//! shades the engine's meshes, and its own strands lie within the depth bias (the fur's length).

use glam::{Mat4, Vec3, Vec4};
use pelt_core::light::MAX_LIGHTS;

use crate::RenderError;
use crate::renderer::FurRenderer;
use crate::shaders::{
    SHADOW_DEPTH_FORMAT, SHADOW_OPACITY_FORMAT, SHADOW_VIEWS, ShadowUniform, ShadowViewUniform, array_view,
    shadow_copy_shader_source, shadow_texture,
};
use crate::view::{FurView, ShadowLookups};

/// One of a host's shadow views: what drew it, and how its depth reads.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostShadowView {
    /// The index of the light it shadows among the picture's lights (`ViewData::lights`).
    pub light_index: usize,
    /// The light's projection times view: world space to the map's clip space.
    pub clip_from_world: Mat4,
    /// Whether the map's depth is reverse-Z (near = 1), as Bevy's are.
    pub reverse_z: bool,
    /// World units a texel of the map spans at the fur (the normal offset).
    pub texel_world: f32,
    /// The light: its position (point and spot), or the unit vector toward it (directional).
    pub light: HostLight,
}

/// Where a host's shadowing light is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum HostLight {
    /// A sun: the unit vector toward it.
    Directional(Vec3),
    /// A point or spot light at this position, one view.
    Positional(Vec3),
    /// One face of a point light's cube at `position`: `face` 0 to 5 is the view of the points
    /// whose offset from the light is largest along +X, -X, +Y, -Y, +Z or -Z (world space). A
    /// light's six faces take six layers in that order.
    CubeFace {
        /// The light's position.
        position: Vec3,
        /// Which face.
        face: usize,
    },
}

/// A host's shadow maps copied into Pelt's: make one per camera and renderer, each frame
/// [`HostShadows::prepare`] it with the views the host drew, [`HostShadows::record_copy`] their
/// depth after the host's shadow passes and before the picture, and light the picture's view
/// with it ([`FurView::set_host_shadows`]).
#[derive(Debug)]
pub struct HostShadows {
    size: u32,
    layers: u32,
    fur_depth: f32,
    uniform: wgpu::Buffer,
    layer_views: Vec<wgpu::TextureView>,
    receiver: wgpu::BindGroup,
    copy: wgpu::RenderPipeline,
    copy_layout: wgpu::BindGroupLayout,
    /// This frame's sources, one a layer in use (none: a cube face not given, cleared).
    copies: Vec<Option<wgpu::BindGroup>>,
}

impl HostShadows {
    /// Room for `layers` of the host's views, each `size` texels a side (the largest host map's),
    /// for fur at most `fur_depth` long.
    ///
    /// # Errors
    /// [`RenderError::Target`] for a size of 0 or past the device's limit, no layers or more
    /// than `MAX_SHADOW_VIEWS`, or a fur depth that is not a positive finite number.
    pub fn new(
        device: &wgpu::Device,
        renderer: &FurRenderer,
        (size, layers): (u32, u32),
        fur_depth: f32,
    ) -> Result<Self, RenderError> {
        let max = device.limits().max_texture_dimension_2d;
        if size == 0 || size > max {
            return Err(RenderError::Target(format!("a host shadow map of {size} texels a side (1 to {max})")));
        }
        let max_layers = device.limits().max_texture_array_layers.min(SHADOW_VIEWS as u32);
        if layers == 0 || layers > max_layers {
            return Err(RenderError::Target(format!("{layers} host shadow views (1 to {max_layers})")));
        }
        if !(fur_depth.is_finite() && fur_depth > 0.0) {
            return Err(RenderError::Target(format!("a shadow fur depth of {fur_depth} (a positive length)")));
        }
        let layouts = renderer.layouts();
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt host shadows"),
            size: size_of::<ShadowUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let depth = shadow_texture(device, SHADOW_DEPTH_FORMAT, (size, layers), true);
        let layer_views = (0..layers)
            .map(|layer| {
                depth.create_view(&wgpu::TextureViewDescriptor {
                    dimension: Some(wgpu::TextureViewDimension::D2),
                    base_array_layer: layer,
                    array_layer_count: Some(1),
                    ..wgpu::TextureViewDescriptor::default()
                })
            })
            .collect();
        // No fur maps: one cleared texel a layer (a zero opacity: full transmittance).
        let fur_depth_maps = array_view(&shadow_texture(device, SHADOW_DEPTH_FORMAT, (1, layers), false));
        let opacity = array_view(&shadow_texture(device, SHADOW_OPACITY_FORMAT, (1, layers), false));
        let receiver = layouts.shadow_group(device, &uniform, (&array_view(&depth), &fur_depth_maps, &opacity));
        let copy_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt host shadow copy"),
            entries: &[wgpu::BindGroupLayoutEntry {
                binding: 0,
                visibility: wgpu::ShaderStages::FRAGMENT,
                ty: wgpu::BindingType::Texture {
                    sample_type: wgpu::TextureSampleType::Depth,
                    view_dimension: wgpu::TextureViewDimension::D2,
                    multisampled: false,
                },
                count: None,
            }],
        });
        let copy = copy_pipeline(device, &copy_layout);
        Ok(Self { size, layers, fur_depth, uniform, layer_views, receiver, copy, copy_layout, copies: Vec::new() })
    }

    /// The size and layers it was made with.
    #[must_use]
    pub fn size_and_layers(&self) -> (u32, u32) {
        (self.size, self.layers)
    }

    /// Aims the layers at `views`, each with the host's depth map that view drew (`sources`:
    /// one layer of depth, square, reverse-Z or not as its view says; one smaller than the
    /// layers is read at its nearest texel). Each view takes a layer, a point light's faces six
    /// in face order (the first face met reserves them; a face not given is unshadowed); views
    /// past the layers, or of a light past the 8th, cast nothing. Returns how many layers are used.
    pub fn prepare(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        views: &[HostShadowView],
        sources: &[&wgpu::TextureView],
    ) -> usize {
        let d = self.fur_depth;
        let mut uniform = ShadowUniform {
            extinction: 0.0,
            pass_view: 0,
            layers: self.layers,
            _padding_1: 0,
            layer_ends: Vec4::new(0.2 * d, 0.5 * d, 1.0 * d, 2.0 * d),
            light_views: [[0; 4]; MAX_LIGHTS],
            views: [ShadowViewUniform::default(); SHADOW_VIEWS],
        };
        // Clip z to `w - z`: a reverse-Z depth read as Pelt's forward one (`shadow_copy.wgsl`).
        let flip = Mat4::from_cols(Vec4::X, Vec4::Y, Vec4::new(0.0, 0.0, -1.0, 0.0), Vec4::new(0.0, 0.0, 1.0, 1.0));
        let (assigned, light_views, used) = assign_layers(views, (self.layers as usize).min(SHADOW_VIEWS));
        uniform.light_views = light_views;
        let mut layers: Vec<Option<wgpu::BindGroup>> = vec![None; used];
        for ((view, source), layer) in views.iter().zip(sources).zip(assigned) {
            let Some(layer) = layer else { continue };
            let light = match view.light {
                HostLight::Directional(toward) => toward.normalize_or(Vec3::Y).extend(0.0),
                HostLight::Positional(position) | HostLight::CubeFace { position, .. } => position.extend(1.0),
            };
            if let HostLight::CubeFace { face, .. } = view.light {
                // Every face knows the light, given or not: the lookups pick the face from it.
                for index in layer - face..layer - face + 6 {
                    uniform.views[index].light = light;
                }
            }
            uniform.views[layer] = ShadowViewUniform {
                light_clip_from_world: if view.reverse_z { flip * view.clip_from_world } else { view.clip_from_world },
                light,
                texel_world: view.texel_world,
                // The fur's own strands lie within this of the map's surface: they do not
                // shadow themselves through it.
                bias_world: view.texel_world + self.fur_depth,
                perspective: 0.0,
                near: 0.0,
                far: 1.0,
                texel: 1.0 / self.size as f32,
                _padding_0: 0.0,
                _padding_1: 0.0,
            };
            layers[layer] = Some(device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pelt host shadow copy"),
                layout: &self.copy_layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(source) }],
            }));
        }
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        self.copies = layers;
        self.copies.len()
    }

    /// Copies the host's maps [`HostShadows::prepare`] was given into Pelt's layers: record it
    /// after the host's shadow passes, before the picture's.
    pub fn record_copy(&self, encoder: &mut wgpu::CommandEncoder) {
        for (group, target) in self.copies.iter().zip(&self.layer_views) {
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("pelt host shadow copy"),
                color_attachments: &[],
                depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
                    view: target,
                    depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Store }),
                    stencil_ops: None,
                }),
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            // A face not given keeps the clear: the far plane, unshadowed.
            if let Some(group) = group {
                pass.set_pipeline(&self.copy);
                pass.set_bind_group(0, group, &[]);
                pass.draw(0..3, 0..1);
            }
        }
    }

    pub(crate) fn receiver(&self) -> (&wgpu::BindGroup, ShadowLookups) {
        (&self.receiver, ShadowLookups::Every)
    }
}

/// The copy's pipeline: a triangle over the layer writing the host's depth, turned forward.
fn copy_pipeline(device: &wgpu::Device, layout: &wgpu::BindGroupLayout) -> wgpu::RenderPipeline {
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("pelt host shadow copy"),
        source: wgpu::ShaderSource::Wgsl(shadow_copy_shader_source().into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("pelt host shadow copy"),
        bind_group_layouts: &[Some(layout)],
        immediate_size: 0,
    });
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some("pelt host shadow copy"),
        layout: Some(&pipeline_layout),
        vertex: wgpu::VertexState {
            module: &module,
            entry_point: Some("vs_copy"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            buffers: &[],
        },
        primitive: wgpu::PrimitiveState::default(),
        depth_stencil: Some(wgpu::DepthStencilState {
            format: SHADOW_DEPTH_FORMAT,
            depth_write_enabled: Some(true),
            depth_compare: Some(wgpu::CompareFunction::Always),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: Some(wgpu::FragmentState {
            module: &module,
            entry_point: Some("fs_copy"),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            targets: &[],
        }),
        multiview_mask: None,
        cache: None,
    })
}

/// Where each of `views` goes among `capacity` layers: its layer (none: it casts nothing), each
/// light's first layer and count (`Shadow::light_views`), and the layers used. A light's first
/// view takes the next layer, or, a cube face, the next six (face `f` at the first plus `f`);
/// more views of a one-view light take layers the lookups do not read.
fn assign_layers(views: &[HostShadowView], capacity: usize) -> (Vec<Option<usize>>, [[u32; 4]; MAX_LIGHTS], usize) {
    let mut light_views = [[0u32; 4]; MAX_LIGHTS];
    let mut used = 0;
    let assigned = views
        .iter()
        .map(|view| {
            let slot = light_views.get_mut(view.light_index)?;
            match view.light {
                HostLight::CubeFace { face, .. } if face >= 6 => None,
                HostLight::CubeFace { face, .. } => {
                    if slot[1] == 0 && used + 6 <= capacity {
                        *slot = [used as u32, 6, 0, 0];
                        used += 6;
                    }
                    (slot[1] == 6).then_some(slot[0] as usize + face)
                }
                HostLight::Directional(_) | HostLight::Positional(_) => {
                    if used >= capacity || slot[1] == 6 {
                        return None;
                    }
                    if slot[1] == 0 {
                        *slot = [used as u32, 1, 0, 0];
                    }
                    used += 1;
                    Some(used - 1)
                }
            }
        })
        .collect();
    (assigned, light_views, used)
}

impl FurView {
    /// Lights the draws through this view with a host's shadow maps ([`HostShadows`], copied
    /// with [`HostShadows::record_copy`] before this view's pass), or without shadows (`None`).
    pub fn set_host_shadows(&mut self, shadows: Option<&HostShadows>) {
        self.set_shadow_group(shadows.map(HostShadows::receiver));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn view(light_index: usize, light: HostLight) -> HostShadowView {
        HostShadowView { light_index, clip_from_world: Mat4::IDENTITY, reverse_z: true, texel_world: 0.01, light }
    }

    #[test]
    fn a_point_lights_faces_take_six_layers_in_face_order() {
        let sun = HostLight::Directional(Vec3::Y);
        let face = |face| HostLight::CubeFace { position: Vec3::ONE, face };
        // Two cascades of the sun, a cube's faces out of order, a spot light.
        let mut views = vec![view(0, sun), view(0, sun)];
        views.extend([5, 0, 3, 1, 2, 4].map(|f| view(1, face(f))));
        views.push(view(2, HostLight::Positional(Vec3::Y)));
        let (assigned, light_views, used) = assign_layers(&views, 12);
        assert_eq!(assigned, [0, 1, 7, 2, 5, 3, 4, 6, 8].map(Some));
        assert_eq!(&light_views[..3], &[[0, 1, 0, 0], [2, 6, 0, 0], [8, 1, 0, 0]]);
        assert_eq!(used, 9);
        // Too few layers for the cube: its faces cast nothing, the spot light still does.
        let (assigned, light_views, used) = assign_layers(&views, 4);
        assert_eq!(assigned, [Some(0), Some(1), None, None, None, None, None, None, Some(2)]);
        assert_eq!(light_views[1], [0; 4]);
        assert_eq!(used, 3);
        // A face past the sixth, a light past the eighth: nothing.
        let odd = [view(0, face(6)), view(MAX_LIGHTS, sun)];
        assert_eq!(assign_layers(&odd, 12), (vec![None, None], [[0; 4]; MAX_LIGHTS], 0));
    }
}
