//! Pipeline plumbing shared by the unified and the separated renderer: one function that builds
//! every fur pipeline for a [`FurTarget`].

use crate::fur::Coat;
use crate::targets::FurTarget;

/// How the fur's transparency is resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Transparency {
    /// Premultiplied alpha blending, depth writes off (drawn in order, inner to outer).
    Blend,
    /// Alpha-to-coverage with depth writes on (order independent).
    Coverage,
}

impl Transparency {
    /// The blended variant and the alpha-to-coverage one, in the order pipelines are kept.
    pub const BOTH: [Self; 2] = [Self::Blend, Self::Coverage];

    pub fn index(alpha_to_coverage: bool) -> usize {
        usize::from(alpha_to_coverage)
    }
}

/// What a pipeline draws, which sets its blending, depth writes and culling.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PassKind {
    Opaque,
    Shells(Transparency),
    Fins(Transparency),
}

/// One pipeline's shader and vertex input.
#[derive(Clone, Copy)]
pub(crate) struct PipelineSource<'a> {
    /// Whether every mesh the pipeline draws has uvs, where that is known (the unified
    /// renderer walks meshes with and without them through separate pipelines): the shaders
    /// then drop the other case's varyings and fetches (`MESH_UVS` in `shading.wgsl`).
    pub mesh_uvs: Option<bool>,
    /// The coat the pipeline draws, where it is fixed (the unified renderer's shells and fins);
    /// `None` reads the object's flags.
    pub coat: Option<Coat>,
    pub layout: &'a wgpu::PipelineLayout,
    pub module: &'a wgpu::ShaderModule,
    pub vertex_entry: &'a str,
    pub fragment_entry: &'a str,
    pub buffers: &'a [Option<wgpu::VertexBufferLayout<'a>>],
}

impl PipelineSource<'_> {
    /// The shaders' override constants for this source (`shading.wgsl`, `unified.wgsl`,
    /// `shadows.wgsl`); `coverage` sets `ALPHA_TO_COVERAGE`.
    pub(crate) fn constants(&self, coverage: bool) -> [(&'static str, f64); 7] {
        let mesh_uvs = match self.mesh_uvs {
            None => 0.0,
            Some(true) => 1.0,
            Some(false) => 2.0,
        };
        // 0 reads the object's flag, 1 is off, 2 on.
        let switch = |on: Option<bool>| match on {
            None => 0.0,
            Some(false) => 1.0,
            Some(true) => 2.0,
        };
        [
            ("ALPHA_TO_COVERAGE", if coverage { 1.0 } else { 0.0 }),
            ("MESH_UVS", mesh_uvs),
            ("GROOM", switch(self.coat.map(|c| c.groomed))),
            ("WET", switch(self.coat.map(|c| c.wet))),
            ("SHADOWS", if self.coat.is_some_and(|c| c.shadowed) { 1.0 } else { 0.0 }),
            ("SHADOW_KEY_ONLY", if self.coat.is_some_and(|c| c.shadowed && c.key_shadows) { 1.0 } else { 0.0 }),
            ("SHADING", switch(self.coat.map(|c| c.fur_model))),
        ]
    }
}

/// Builds one Pelt pipeline for `target`.
pub(crate) fn create_pipeline(
    device: &wgpu::Device,
    target: &FurTarget,
    label: &str,
    source: &PipelineSource<'_>,
    kind: PassKind,
) -> wgpu::RenderPipeline {
    let transparency = match kind {
        PassKind::Opaque => None,
        PassKind::Shells(t) | PassKind::Fins(t) => Some(t),
    };
    let coverage = transparency == Some(Transparency::Coverage);
    let blend = (transparency == Some(Transparency::Blend)).then_some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING);
    let depth_write = transparency != Some(Transparency::Blend);
    // Shells facing away lie behind the skin; fins are seen from both sides.
    let cull_mode = match kind {
        PassKind::Fins(_) => None,
        PassKind::Opaque | PassKind::Shells(_) => Some(wgpu::Face::Back),
    };
    let constants = source.constants(coverage);
    let compilation_options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(source.layout),
        vertex: wgpu::VertexState {
            module: source.module,
            entry_point: Some(source.vertex_entry),
            compilation_options: compilation_options.clone(),
            buffers: source.buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            front_face: wgpu::FrontFace::Ccw,
            cull_mode,
            ..wgpu::PrimitiveState::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: target.depth_format,
            depth_write_enabled: Some(depth_write),
            depth_compare: Some(target.depth_compare),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: target.sample_count,
            mask: !0,
            alpha_to_coverage_enabled: coverage && target.sample_count > 1,
        },
        fragment: Some(wgpu::FragmentState {
            module: source.module,
            entry_point: Some(source.fragment_entry),
            compilation_options,
            targets: &[Some(wgpu::ColorTargetState {
                format: target.colour_format,
                blend,
                // Coverage already says how much of a pixel a strand covers; writing its alpha
                // too would leave the target (and a PNG read from it) translucent.
                write_mask: if coverage { wgpu::ColorWrites::COLOR } else { wgpu::ColorWrites::ALL },
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}
