//! A fur's depth-only and motion-vector draws, for a host's depth prepass, motion-vector prepass
//! (TAA, motion blur) and shadow maps: the skin opaque, shells and fins alpha-tested against
//! their textures (`prepass.wgsl`).
//!
//! One [`FurPrepass`] per attachment description ([`PrepassTarget`]), one [`FurMotion`] per fur
//! and view it draws into.

use glam::{Mat4, Vec3};

use crate::RenderError;
use crate::fur::GpuFur;
use crate::renderer::FurRenderer;
use crate::requirements::ErrorScope;
use crate::shaders::prepass_shader_source;
use crate::view::FurView;

/// The attachments of a prepass or shadow pass: a depth buffer, and with `motion_format` a
/// motion-vector target (two channels: this frame's screen position minus last frame's, in uv
/// units, y down).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PrepassTarget {
    /// The depth attachment's format.
    pub depth_format: wgpu::TextureFormat,
    /// `GreaterEqual` for reverse-Z (Bevy's views and shadow maps), `LessEqual` otherwise.
    pub depth_compare: wgpu::CompareFunction,
    /// The motion-vector attachment's format (two channels), if any.
    pub motion_format: Option<wgpu::TextureFormat>,
    /// Samples per pixel of the attachments.
    pub sample_count: u32,
}

impl PrepassTarget {
    /// Depth only (a shadow map, or a depth prepass): single-sampled.
    #[must_use]
    pub fn depth(depth_format: wgpu::TextureFormat, depth_compare: wgpu::CompareFunction) -> Self {
        Self { depth_format, depth_compare, motion_format: None, sample_count: 1 }
    }

    /// With a motion-vector target.
    #[must_use]
    pub fn with_motion(self, motion_format: wgpu::TextureFormat) -> Self {
        Self { motion_format: Some(motion_format), ..self }
    }

    /// With `sample_count` samples per pixel.
    #[must_use]
    pub fn with_sample_count(self, sample_count: u32) -> Self {
        Self { sample_count, ..self }
    }
}

/// One view's matrices for [`FurMotion::prepare`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MotionData {
    /// This frame's projection times view without a TAA jitter.
    pub unjittered_clip_from_world: Mat4,
    /// Last frame's, likewise.
    pub previous_clip_from_world: Mat4,
    /// The fur's model transform last frame.
    pub previous_world_from_model: Mat4,
    /// Clamp depth to the near plane instead of clipping: directional shadow cascades, whose
    /// casters may lie in front of the cascade's near plane.
    pub clamp_depth: bool,
}

impl MotionData {
    /// A view that needs no motion vectors (a shadow map or a depth prepass).
    #[must_use]
    pub fn still(clamp_depth: bool) -> Self {
        Self {
            unjittered_clip_from_world: Mat4::IDENTITY,
            previous_clip_from_world: Mat4::IDENTITY,
            previous_world_from_model: Mat4::IDENTITY,
            clamp_depth,
        }
    }
}

/// `Motion` of `prepass.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct MotionUniform {
    unjittered_clip_from_world: Mat4,
    previous_clip_from_model: Mat4,
    clamp_depth: u32,
    padding: [u32; 3],
}

/// The depth-only and motion-vector pipelines of one [`PrepassTarget`], for furs uploaded with
/// one [`FurRenderer`] (they share its bind group layouts).
#[derive(Debug)]
pub struct FurPrepass {
    target: PrepassTarget,
    motion_layout: wgpu::BindGroupLayout,
    /// Skin, shells and fins; by walk (meshes with uvs, then without) where it matters.
    skin: [wgpu::RenderPipeline; 2],
    shells: [wgpu::RenderPipeline; 2],
    fins: wgpu::RenderPipeline,
}

impl FurPrepass {
    /// Builds the pipelines for `target`, drawing furs uploaded with `renderer`.
    ///
    /// # Errors
    /// [`RenderError::Gpu`] when the device rejects them.
    pub fn new(device: &wgpu::Device, renderer: &FurRenderer, target: PrepassTarget) -> Result<Self, RenderError> {
        let scope = ErrorScope::push(device);
        let layouts = renderer.layouts();
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let uniform = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Uniform,
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let motion_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt motion"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::VERTEX,
                    ty: uniform,
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::VERTEX,
                    ty: storage,
                    count: None,
                },
            ],
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pelt prepass"),
            bind_group_layouts: &[
                Some(&layouts.view),
                Some(&layouts.unified_object),
                Some(&layouts.textures),
                Some(&motion_layout),
            ],
            immediate_size: 0,
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pelt prepass"),
            source: wgpu::ShaderSource::Wgsl(prepass_shader_source().into()),
        });
        let motion = target.motion_format.is_some();
        let build = |label: &str, vertex: &str, part: &str, cull_mode, mesh_uvs: f64| {
            let constants = [("MESH_UVS", mesh_uvs)];
            let options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
            let fragment_entry = match (part, motion) {
                ("skin", false) => None,
                (part, false) => Some(format!("fs_prepass_{part}_depth")),
                (part, true) => Some(format!("fs_prepass_{part}_motion")),
            };
            let targets = [target.motion_format.map(|format| wgpu::ColorTargetState {
                format,
                blend: None,
                write_mask: wgpu::ColorWrites::ALL,
            })];
            let targets = if motion { &targets[..] } else { &[] };
            device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
                label: Some(label),
                layout: Some(&layout),
                vertex: wgpu::VertexState {
                    module: &module,
                    entry_point: Some(vertex),
                    compilation_options: options.clone(),
                    buffers: &[],
                },
                primitive: wgpu::PrimitiveState {
                    topology: wgpu::PrimitiveTopology::TriangleList,
                    front_face: wgpu::FrontFace::Ccw,
                    cull_mode,
                    ..wgpu::PrimitiveState::default()
                },
                // No bias here: like Bevy's own shadow casters, the receiver offsets its lookup.
                depth_stencil: Some(wgpu::DepthStencilState {
                    format: target.depth_format,
                    depth_write_enabled: Some(true),
                    depth_compare: Some(target.depth_compare),
                    stencil: wgpu::StencilState::default(),
                    bias: wgpu::DepthBiasState::default(),
                }),
                multisample: wgpu::MultisampleState {
                    count: target.sample_count,
                    mask: !0,
                    alpha_to_coverage_enabled: false,
                },
                fragment: fragment_entry.as_deref().map(|entry| wgpu::FragmentState {
                    module: &module,
                    entry_point: Some(entry),
                    compilation_options: options.clone(),
                    targets,
                }),
                multiview_mask: None,
                cache: None,
            })
        };
        let back = Some(wgpu::Face::Back);
        let walks = [("wedges", 1.0), ("indexed", 2.0)];
        let skin =
            walks.map(|(walk, uvs)| build("pelt prepass skin", &format!("vs_prepass_skin_{walk}"), "skin", back, uvs));
        let shells = walks
            .map(|(walk, uvs)| build("pelt prepass shells", &format!("vs_prepass_shell_{walk}"), "shell", back, uvs));
        let fins = build("pelt prepass fins", "vs_prepass_fin", "fin", None, 0.0);
        scope.pop("building the fur prepass pipelines")?;
        Ok(Self { target, motion_layout, skin, shells, fins })
    }

    /// The attachments the pipelines were built for.
    #[must_use]
    pub fn target(&self) -> PrepassTarget {
        self.target
    }

    /// Records `fur` (uploaded with this prepass's renderer) as seen from `view` into `pass`, a
    /// pass on attachments of this prepass's target. `skin` draws the opaque skin too. Call
    /// [`FurView::prepare`], [`GpuFur::prepare`] and [`FurMotion::prepare`] before submitting.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, view: &FurView, fur: &GpuFur, motion: &FurMotion, skin: bool) {
        let geometry = fur.geometry();
        let walk = usize::from(!geometry.shape.has_uvs);
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, geometry.bind_group(), &[]);
        pass.set_bind_group(2, fur.textures_bind_group(), &[]);
        pass.set_bind_group(3, &motion.bind_group, &[]);
        if skin {
            pass.set_pipeline(&self.skin[walk]);
            geometry.draw_skin(pass);
        }
        if geometry.shape.layers == 0 {
            return;
        }
        pass.set_pipeline(&self.shells[walk]);
        geometry.draw_shells(pass, 0..fur.drawn_shells());
        if fur.prepared_level().fins_shown() {
            pass.set_pipeline(&self.fins);
            geometry.draw_fins(pass, fur.drawn_shells());
        }
    }
}

/// One fur as one prepass or shadow view sees it: the view's matrices this frame and last, the
/// fur's transform last frame and, for motion vectors, its positions last frame.
#[derive(Debug)]
pub struct FurMotion {
    uniform: wgpu::Buffer,
    /// Last frame's positions (none for a view without motion vectors: the current ones stand in).
    previous: Option<wgpu::Buffer>,
    bind_group: wgpu::BindGroup,
}

impl FurMotion {
    /// For a view with motion vectors: keeps a copy of the fur's positions, written with
    /// [`FurMotion::set_previous_positions`] (they start as the fur's current ones).
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, prepass: &FurPrepass, fur: &GpuFur) -> Self {
        let size = fur.current_positions().size();
        let previous = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt previous positions"),
            size,
            usage: wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pelt motion") });
        let current = fur.current_positions();
        encoder.copy_buffer_to_buffer(current.buffer(), current.offset(), &previous, 0, size);
        queue.submit([encoder.finish()]);
        Self::with_previous(device, prepass, Some(previous), fur)
    }

    /// For a view without motion vectors (a shadow map, a depth prepass).
    pub fn depth_only(device: &wgpu::Device, prepass: &FurPrepass, fur: &GpuFur) -> Self {
        Self::with_previous(device, prepass, None, fur)
    }

    fn with_previous(
        device: &wgpu::Device,
        prepass: &FurPrepass,
        previous: Option<wgpu::Buffer>,
        fur: &GpuFur,
    ) -> Self {
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt motion"),
            size: size_of::<MotionUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let positions = previous.as_ref().map_or(fur.current_positions(), |previous| previous.slice(..));
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt motion"),
            layout: &prepass.motion_layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: crate::pool::binding(positions) },
            ],
        });
        Self { uniform, previous, bind_group }
    }

    /// Writes this frame's matrices (takes effect at the next submission).
    pub fn prepare(&self, queue: &wgpu::Queue, data: &MotionData) {
        let uniform = MotionUniform {
            unjittered_clip_from_world: data.unjittered_clip_from_world,
            previous_clip_from_model: data.previous_clip_from_world * data.previous_world_from_model,
            clamp_depth: u32::from(data.clamp_depth),
            padding: [0; 3],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }

    /// Writes the positions the fur was drawn with last frame (`(L + 1) * V`, model space).
    ///
    /// # Errors
    /// [`RenderError::Count`] for another count; [`RenderError::Target`] for a depth-only motion.
    pub fn set_previous_positions(&self, queue: &wgpu::Queue, positions: &[Vec3]) -> Result<(), RenderError> {
        let Some(previous) = &self.previous else {
            return Err(RenderError::Target("a depth-only FurMotion keeps no previous positions".to_owned()));
        };
        let expected = previous.size() / 12;
        if positions.len() as u64 != expected {
            return Err(RenderError::Count {
                what: "previous positions",
                expected: expected as usize,
                got: positions.len(),
                rule: "(L + 1) * V",
            });
        }
        queue.write_buffer(previous, 0, bytemuck::cast_slice(positions));
        Ok(())
    }
}
