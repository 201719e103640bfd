//! The shadow views' pipelines: the same vertex shaders as the picture's, drawn from the light
//! into a [`ShadowMap`](crate::ShadowMap)'s depth and opacity maps (`shadows.wgsl`).

use std::sync::OnceLock;

use super::{CoatBuilder, FurRenderer, PipelineSource, WALKS};
use crate::fur::{Coat, GpuFur};
use crate::plain::PlainMesh;
use crate::renderer::FurDrawSettings;
use crate::shaders::{
    Layouts, SHADOW_DEPTH_FORMAT as DEPTH_FORMAT, SHADOW_OPACITY_FORMAT as OPACITY_FORMAT, pool_draw_shader_source,
};
use crate::view::{FurView, ShadowLookups, ShadowPass};

/// What a shadow pipeline writes.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum ShadowKind {
    /// Depth only, biased against acne (the opaque map).
    Opaque,
    /// Depth only (the fur's first surface).
    FurDepth,
    /// Opacity added into the layers, tested against the opaque map.
    Opacity,
}

/// The depth-only pipelines every fur shares: walk by walk (wedges, then indexed).
#[derive(Debug)]
pub(super) struct ShadowPipelines {
    plain: [wgpu::RenderPipeline; 2],
    skin: [wgpu::RenderPipeline; 2],
    fur_depth: [wgpu::RenderPipeline; 2],
}

/// One coat's opacity pipelines (shells only: seen from the light, a coat's fins stand edge-on
/// where its shells do not, and would cost more than every shell together).
#[derive(Debug)]
pub(super) struct OpacityPipelines {
    shells: [wgpu::RenderPipeline; 2],
}

/// The opacity pass draws at most this many shells (`OPACITY_SHELLS` in `unified.wgsl`): one
/// for each of the map's opacity layers.
pub(super) const OPACITY_SHELLS: u32 = 4;

/// The opacity shells a coat of `shells` drawn shells casts: each the middle of a run of
/// `shells / OPACITY_SHELLS` (rounded up), as `opacity_shell` in `unified.wgsl` picks them; none
/// for a coat without shells.
pub(super) fn opacity_shells(shells: u32) -> u32 {
    shells.div_ceil(shells.div_ceil(OPACITY_SHELLS).max(1))
}

/// The shadow pipelines, each built the first time a shadow map draws with it.
#[derive(Debug, Default)]
pub(super) struct ShadowSet {
    depth: OnceLock<ShadowPipelines>,
    /// By the coat's index without shadows or the fur model (groomed, wet): opacity needs
    /// neither.
    opacity: [OnceLock<OpacityPipelines>; 4],
    /// A pool's casters (`pool_draws.wgsl`), built the first time a herd casts.
    pub(super) pool: OnceLock<PoolCasters>,
}

/// A pool's shadow pipelines, each drawing every copy of a run of slots at once: their own
/// module (the shading over a pool) and layout (`Layouts::pool_draws`).
#[derive(Debug)]
pub(super) struct PoolCasters {
    pub module: wgpu::ShaderModule,
    pub layout: wgpu::PipelineLayout,
    pub skin: [wgpu::RenderPipeline; 2],
    pub fur_depth: [wgpu::RenderPipeline; 2],
    /// By whether the groom reaches the shading (a wet copy casts alone).
    opacity: [OnceLock<[wgpu::RenderPipeline; 2]>; 2],
}

impl CoatBuilder {
    fn shadow_pipeline(
        &self,
        label: &str,
        (vertex, fragment): (&str, Option<&str>),
        (layout, mesh_uvs, coat): (&wgpu::PipelineLayout, Option<bool>, Coat),
        kind: ShadowKind,
    ) -> wgpu::RenderPipeline {
        self.shadow_pipeline_in(&self.module, label, (vertex, fragment), (layout, mesh_uvs, coat), kind)
    }

    fn shadow_pipeline_in(
        &self,
        module: &wgpu::ShaderModule,
        label: &str,
        (vertex, fragment): (&str, Option<&str>),
        (layout, mesh_uvs, coat): (&wgpu::PipelineLayout, Option<bool>, Coat),
        kind: ShadowKind,
    ) -> wgpu::RenderPipeline {
        let source = PipelineSource {
            mesh_uvs,
            coat: Some(coat),
            layout,
            module,
            vertex_entry: vertex,
            fragment_entry: "",
            buffers: &[],
        };
        create_shadow_pipeline(&self.device, label, &source, fragment, kind)
    }

    fn shadow_depth(&self) -> ShadowPipelines {
        let depth = |label, vertex: &str, layout, mesh_uvs, kind| {
            self.shadow_pipeline(label, (vertex, None), (layout, Some(mesh_uvs), Coat::PLAIN), kind)
        };
        ShadowPipelines {
            plain: WALKS.map(|(walk, uvs)| {
                depth("pelt shadow plain", &format!("vs_skin_{walk}"), &self.plain_layout, uvs, ShadowKind::Opaque)
            }),
            skin: WALKS.map(|(walk, uvs)| {
                depth("pelt shadow skin", &format!("vs_skin_{walk}"), &self.layout, uvs, ShadowKind::Opaque)
            }),
            fur_depth: WALKS.map(|(walk, uvs)| {
                depth("pelt shadow fur depth", &format!("vs_shell_{walk}"), &self.layout, uvs, ShadowKind::FurDepth)
            }),
        }
    }

    fn opacity(&self, coat: Coat) -> OpacityPipelines {
        OpacityPipelines {
            shells: WALKS.map(|(walk, uvs)| {
                let fragment = coat.entry(if uvs { "fs_opacity_uvs" } else { "fs_opacity_tiles" });
                self.shadow_pipeline(
                    "pelt shadow shells",
                    (&coat.entry(&format!("vs_opacity_shell_{walk}")), Some(&fragment)),
                    (&self.layout, Some(uvs), coat),
                    ShadowKind::Opacity,
                )
            }),
        }
    }
}

impl CoatBuilder {
    fn pool_casters(&self, layouts: &Layouts) -> PoolCasters {
        let module = self.device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pelt pool draws"),
            source: wgpu::ShaderSource::Wgsl(pool_draw_shader_source().into()),
        });
        let layout = layouts.pipeline_layout(&self.device, "pelt pool draws", &layouts.pool_draws, true);
        let depth = |label, vertex: &str, kind| {
            WALKS.map(|(walk, uvs)| {
                let entry = format!("{vertex}_{walk}");
                self.shadow_pipeline_in(&module, label, (&entry, None), (&layout, Some(uvs), Coat::PLAIN), kind)
            })
        };
        PoolCasters {
            skin: depth("pelt pool shadow skin", "vs_pool_skin", ShadowKind::Opaque),
            fur_depth: depth("pelt pool shadow fur depth", "vs_pool_fur_depth", ShadowKind::FurDepth),
            opacity: [OnceLock::new(), OnceLock::new()],
            module,
            layout,
        }
    }

    fn pool_opacity(&self, casters: &PoolCasters, coat: Coat) -> [wgpu::RenderPipeline; 2] {
        WALKS.map(|(walk, uvs)| {
            let fragment = coat.entry(if uvs { "fs_pool_opacity_uvs" } else { "fs_pool_opacity_tiles" });
            self.shadow_pipeline_in(
                &casters.module,
                "pelt pool shadow shells",
                (&coat.entry(&format!("vs_pool_opacity_shell_{walk}")), Some(&fragment)),
                (&casters.layout, Some(uvs), coat),
                ShadowKind::Opacity,
            )
        })
    }
}

impl FurRenderer {
    pub(super) fn pool_casters(&self) -> &PoolCasters {
        self.shadows.pool.get_or_init(|| self.coat_builder.pool_casters(&self.layouts))
    }

    /// A pool's opacity pipelines for dry copies with `coat`'s groom.
    pub(super) fn pool_opacity(&self, coat: Coat) -> &[wgpu::RenderPipeline; 2] {
        let casters = self.pool_casters();
        let coat = Coat { groomed: coat.groomed, ..Coat::PLAIN };
        casters.opacity[usize::from(coat.groomed)].get_or_init(|| self.coat_builder.pool_opacity(casters, coat))
    }

    fn shadow_depth(&self) -> &ShadowPipelines {
        self.shadows.depth.get_or_init(|| self.coat_builder.shadow_depth())
    }

    fn opacity(&self, coat: Coat) -> &OpacityPipelines {
        // The lighting the vertex stage computes is not read, so the cheaper model's.
        let coat = Coat { shadowed: false, key_shadows: false, fur_model: false, ..coat };
        self.shadows.opacity[coat.index()].get_or_init(|| self.coat_builder.opacity(coat))
    }

    /// `fur` in one pass of a shadow map; returns the draws recorded.
    pub(super) fn draw_shadow(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        (view, shadow_pass): (&FurView, ShadowPass),
        fur: &GpuFur,
        settings: &FurDrawSettings,
    ) -> usize {
        let geometry = fur.geometry();
        let walk = usize::from(!geometry.shape.has_uvs);
        let shells = fur.drawn_shells();
        let furred = geometry.shape.layers > 0
            && shells > 0
            && (settings.shells || settings.fins)
            && fur.prepared_level().coat_shown();
        // Nothing to draw, nothing bound (a far herd's faded coats draw nothing into the fur's
        // maps).
        let draws = match shadow_pass {
            ShadowPass::Opaque => settings.skin,
            ShadowPass::FurDepth | ShadowPass::Opacity => furred,
        };
        if !draws {
            return 0;
        }
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, geometry.bind_group(), &[]);
        pass.set_bind_group(2, fur.textures_bind_group(), &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        match shadow_pass {
            ShadowPass::Opaque if settings.skin => {
                pass.set_pipeline(&self.shadow_depth().skin[walk]);
                geometry.draw_skin(pass);
            }
            ShadowPass::FurDepth if furred => {
                // The outermost shell is the fur's first surface wherever it grows.
                pass.set_pipeline(&self.shadow_depth().fur_depth[walk]);
                geometry.draw_shells(pass, shells - 1..shells);
            }
            ShadowPass::Opacity if furred => {
                pass.set_pipeline(&self.opacity(fur.coat()).shells[walk]);
                geometry.draw_shells(pass, 0..opacity_shells(shells));
            }
            _ => {}
        }
        1
    }

    /// A plain mesh in one pass of a shadow map: it casts in the opaque one only.
    pub(super) fn draw_plain_shadow(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        (view, shadow_pass): (&FurView, ShadowPass),
        mesh: &PlainMesh,
    ) {
        if shadow_pass != ShadowPass::Opaque {
            return;
        }
        let geometry = mesh.geometry();
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, geometry.bind_group(), &[]);
        pass.set_bind_group(2, &self.layouts.empty_group, &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        pass.set_pipeline(&self.shadow_depth().plain[usize::from(!geometry.shape.has_uvs)]);
        geometry.draw_skin(pass);
    }
}

fn create_shadow_pipeline(
    device: &wgpu::Device,
    label: &str,
    source: &PipelineSource<'_>,
    fragment_entry: Option<&str>,
    kind: ShadowKind,
) -> wgpu::RenderPipeline {
    // The shadow views draw a coat's own shapes without reading shadows themselves.
    let coat = source.coat.unwrap_or(Coat::PLAIN).shadowed(ShadowLookups::Off);
    let constants = PipelineSource { coat: Some(coat), ..*source }.constants(false);
    let compilation_options = wgpu::PipelineCompilationOptions { constants: &constants, ..Default::default() };
    let (depth_write, bias, cull_mode) = match kind {
        // A texel's worth of slope keeps lit surfaces off their own shadow.
        ShadowKind::Opaque => (true, wgpu::DepthBiasState { constant: 2, slope_scale: 2.0, clamp: 0.0 }, None),
        ShadowKind::FurDepth => (true, wgpu::DepthBiasState::default(), None),
        ShadowKind::Opacity => (false, wgpu::DepthBiasState::default(), Some(wgpu::Face::Back)),
    };
    let additive = wgpu::BlendComponent {
        src_factor: wgpu::BlendFactor::One,
        dst_factor: wgpu::BlendFactor::One,
        operation: wgpu::BlendOperation::Add,
    };
    let targets = [Some(wgpu::ColorTargetState {
        format: OPACITY_FORMAT,
        blend: Some(wgpu::BlendState { color: additive, alpha: additive }),
        write_mask: wgpu::ColorWrites::ALL,
    })];
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
        depth_stencil: (kind != ShadowKind::Opacity).then_some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(depth_write),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: wgpu::StencilState::default(),
            bias,
        }),
        multisample: wgpu::MultisampleState::default(),
        fragment: fragment_entry.map(|entry| wgpu::FragmentState {
            module: source.module,
            entry_point: Some(entry),
            compilation_options,
            targets: &targets,
        }),
        multiview_mask: None,
        cache: None,
    })
}
