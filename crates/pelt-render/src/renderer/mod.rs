//! The unified renderer: pipelines for one [`FurTarget`], drawing [`GpuFur`]s and
//! [`PlainMesh`]es into the host's render pass.
//!
//! A fur draws, in order:
//! 1. the opaque skin (layer 0, coloured like the roots);
//! 2. shells, instanced per layer from the innermost out, over the same `3F` indexed corners,
//!    alpha-blended with depth test on and depth writes off (or alpha-to-coverage), faded where
//!    the surface turns edge-on;
//! 3. fins, instanced per edge over one shared strip of `6L` indices, faded in near the silhouette:
//!    with [`FurDrawSettings::silhouette_fins`] only the edges the silhouette pass
//!    ([`FurRenderer::prepare_fins`]) kept, through an indirect draw; else every edge.

mod objects;
mod pipeline;

pub(crate) use pipeline::{PassKind, PipelineSource, Transparency, create_pipeline};

use crate::RenderError;
use crate::fur::GpuFur;
use crate::listing::{DRAW_ARGS_BYTES, FIN_INSTANCE_LAYOUT, ListingPasses, ShellList};
use crate::plain::PlainMesh;
use crate::requirements::{ErrorScope, check_features_and_limits};
use crate::shaders::{Layouts, unified_shader_source};
use crate::targets::FurTarget;
use crate::view::FurView;

/// Which parts of a fur a draw records; everything here can change every draw.
///
/// Hosts with separate opaque and transparent phases draw each fur twice: the skin alone in the
/// opaque phase (`FurDrawSettings::SKIN`), shells and fins in the transparent phase
/// (`FurDrawSettings::FUR`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct FurDrawSettings {
    /// Draw the opaque skin under the fur.
    pub skin: bool,
    /// Draw the shells.
    pub shells: bool,
    /// Draw the fins.
    pub fins: bool,
    /// Shells and fins with alpha-to-coverage (order independent, writes depth) instead of
    /// blending. Needs a target with MSAA.
    pub alpha_to_coverage: bool,
    /// Draw only the fins the silhouette pass kept: the host records
    /// [`FurRenderer::prepare_fins`] for this fur and view before the render pass, every frame.
    /// Without it every edge's fin is drawn and each vertex tests its own edge (no compute pass,
    /// several times the vertex work).
    pub silhouette_fins: bool,
}

impl FurDrawSettings {
    /// Skin, shells and fins, blended; fins on every edge (no silhouette pass needed).
    pub const ALL: Self =
        Self { skin: true, shells: true, fins: true, alpha_to_coverage: false, silhouette_fins: false };
    /// The opaque skin only.
    pub const SKIN: Self =
        Self { skin: true, shells: false, fins: false, alpha_to_coverage: false, silhouette_fins: false };
    /// Shells and fins only (blended; fins on every edge).
    pub const FUR: Self =
        Self { skin: false, shells: true, fins: true, alpha_to_coverage: false, silhouette_fins: false };
    /// [`FurDrawSettings::ALL`] with silhouette fins: what Pelt's own commands draw (record
    /// [`FurRenderer::prepare_fins`] first).
    pub const SILHOUETTE: Self = Self { silhouette_fins: true, ..Self::ALL };
}

impl Default for FurDrawSettings {
    fn default() -> Self {
        Self::ALL
    }
}

/// Pipelines for one way of walking the base triangles (see `unified.wgsl`).
#[derive(Debug)]
struct SurfacePipelines {
    plain: wgpu::RenderPipeline,
    skin: wgpu::RenderPipeline,
    /// Blended, alpha-to-coverage.
    shells: [wgpu::RenderPipeline; 2],
    /// Blended, alpha-to-coverage: shells over the view-angle pass's list.
    listed_shells: [wgpu::RenderPipeline; 2],
}

/// The unified structure's pipelines for one [`FurTarget`], shared by every [`GpuFur`],
/// [`PlainMesh`] and [`FurView`] made with it. Create it once per target description.
///
/// Nothing here blocks, and it keeps no per-frame state: `draw` only records into the host's
/// pass what `prepare` calls wrote before.
#[derive(Debug)]
pub struct FurRenderer {
    target: FurTarget,
    layouts: Layouts,
    /// Meshes with uvs: indexed by the corners' wedges (base vertex and uv).
    wedges: SurfacePipelines,
    /// Meshes without uvs: indexed by the base triangles.
    indexed: SurfacePipelines,
    /// Blended, alpha-to-coverage: every edge.
    fins: [wgpu::RenderPipeline; 2],
    /// Blended, alpha-to-coverage: the silhouette pass's edges.
    silhouette_fins: [wgpu::RenderPipeline; 2],
    /// The silhouette and view-angle passes.
    listing: ListingPasses,
}

impl FurRenderer {
    /// Builds the pipelines for `target` on `device`.
    ///
    /// # Errors
    /// [`RenderError::Target`] for a malformed target; [`RenderError::MissingFeatures`] or
    /// [`RenderError::Limit`] when the device was created without [`crate::required_features`] or
    /// [`crate::required_limits`]; [`RenderError::Gpu`] when the device rejects the pipelines
    /// (e.g. an adapter without [`crate::required_downlevel_flags`]: check it with
    /// [`crate::check_adapter`] first for a clearer message).
    pub fn new(device: &wgpu::Device, target: FurTarget) -> Result<Self, RenderError> {
        target.validate()?;
        check_features_and_limits(device.features(), &device.limits())?;
        let scope = ErrorScope::push(device);
        let layouts = Layouts::new(device);
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pelt unified"),
            source: wgpu::ShaderSource::Wgsl(unified_shader_source().into()),
        });
        let fur_layout = layouts.pipeline_layout(device, "pelt unified", &layouts.unified_object, true);
        let plain_layout = layouts.pipeline_layout(device, "pelt plain", &layouts.unified_object, false);
        let build_with =
            |label: &str,
             layout: &wgpu::PipelineLayout,
             (vertex_entry, fragment_entry): (&str, &str),
             kind: PassKind,
             (buffers, mesh_uvs): (&[Option<wgpu::VertexBufferLayout<'_>>], Option<bool>)| {
                let source =
                    PipelineSource { mesh_uvs, layout, module: &module, vertex_entry, fragment_entry, buffers };
                create_pipeline(device, &target, label, &source, kind)
            };
        let build = |label: &str, layout: &wgpu::PipelineLayout, entries: (&str, &str), kind: PassKind| {
            build_with(label, layout, entries, kind, (&[], None))
        };
        // Meshes with uvs walk wedges, meshes without base vertices: each walk's pipelines know
        // which, and drop the other's work.
        let surface = |walk: &str, mesh_uvs: bool| {
            let skin = format!("vs_skin_{walk}");
            let shell = format!("vs_shell_{walk}");
            let listed = format!("vs_shell_{walk}_listed");
            let shell_fragment = if mesh_uvs { "fs_shell_uvs" } else { "fs_shell_tiles" };
            let surface =
                |label, layout, entries, kind| build_with(label, layout, entries, kind, (&[], Some(mesh_uvs)));
            SurfacePipelines {
                plain: surface("pelt plain", &plain_layout, (&skin, "fs_plain"), PassKind::Opaque),
                skin: surface("pelt skin", &fur_layout, (&skin, "fs_skin"), PassKind::Opaque),
                shells: Transparency::BOTH
                    .map(|t| surface("pelt shells", &fur_layout, (&shell, shell_fragment), PassKind::Shells(t))),
                listed_shells: Transparency::BOTH.map(|t| {
                    surface("pelt listed shells", &fur_layout, (&listed, shell_fragment), PassKind::Shells(t))
                }),
            }
        };
        let wedges = surface("wedges", true);
        let indexed = surface("indexed", false);
        let fins = Transparency::BOTH.map(|t| build("pelt fins", &fur_layout, ("vs_fin", "fs_fin"), PassKind::Fins(t)));
        let instances = [Some(FIN_INSTANCE_LAYOUT)];
        let silhouette_fins = Transparency::BOTH.map(|t| {
            let entries = ("vs_fin_silhouette", "fs_fin");
            build_with("pelt silhouette fins", &fur_layout, entries, PassKind::Fins(t), (&instances, None))
        });
        let listing = ListingPasses::new(device, &layouts);
        scope.pop("building the fur pipelines")?;
        Ok(Self { target, layouts, wedges, indexed, fins, silhouette_fins, listing })
    }

    /// The target description the pipelines were built for.
    #[must_use]
    pub fn target(&self) -> FurTarget {
        self.target
    }

    /// Records `fur` as seen from `view` into `pass` (a pass on attachments of this renderer's
    /// target). Call [`FurView::prepare`] and [`GpuFur::prepare`] before submitting.
    ///
    /// With blending, draw opaque geometry first and furs after it, farthest first.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, view: &FurView, fur: &GpuFur, settings: &FurDrawSettings) {
        let geometry = fur.geometry();
        let surface = self.surface(geometry.shape.has_uvs);
        let which = Transparency::index(settings.alpha_to_coverage);
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, geometry.bind_group(), &[]);
        pass.set_bind_group(2, fur.textures_bind_group(), &[]);
        if settings.skin {
            pass.set_pipeline(&surface.skin);
            geometry.draw_skin(pass);
        }
        let layers = geometry.shape.layers;
        if settings.shells && layers > 0 {
            match fur.shell_list() {
                Some(list) if list.recorded() && fur.prepared_level().by_view() => {
                    draw_thinned_shells(pass, fur, surface, which, list);
                }
                _ => {
                    pass.set_pipeline(&surface.shells[which]);
                    geometry.draw_shells(pass, 0..fur.drawn_shells());
                }
            }
        }
        // Fins after the shells: at the silhouette, where fins matter, they stand outside the
        // shells and must not be covered by the faded outer layers.
        if settings.fins && layers > 0 {
            match fur.fin_list() {
                Some(list) if settings.silhouette_fins => {
                    pass.set_pipeline(&self.silhouette_fins[which]);
                    geometry.draw_fin_list(pass, &list.instances, &list.draw);
                }
                _ => {
                    pass.set_pipeline(&self.fins[which]);
                    geometry.draw_fins(pass, fur.drawn_shells());
                }
            }
        }
    }

    /// Records the silhouette pass of `fur` seen from `view` into `encoder` (a compute pass): it
    /// decides once per edge which fins show, for a [`FurRenderer::draw`] with
    /// [`FurDrawSettings::silhouette_fins`] in a render pass recorded after it. Call it every
    /// frame, after [`FurView::prepare`] and [`GpuFur::prepare`] (it reads both uniforms), once per
    /// view that draws the fur, each before that view's pass. Nothing blocks or is read back.
    ///
    /// When the level thins shells by view angle ([`crate::FurLevel::facing`]) it also records
    /// the pass that lists the triangles the thinned shells still need, and the next draws of
    /// `fur` (until its next [`GpuFur::prepare`]) draw those shells over that list only.
    pub fn prepare_fins(&self, encoder: &mut wgpu::CommandEncoder, view: &FurView, fur: &GpuFur) {
        if let Some(list) = fur.fin_list() {
            list.record(encoder, &self.listing.silhouette, view.bind_group(), fur.geometry().bind_group());
        }
        if let Some(list) = fur.shell_list()
            && fur.prepared_level().by_view()
        {
            list.record(encoder, &self.listing.view_lod, view.bind_group(), fur.geometry().bind_group());
        }
    }

    /// Records a plain mesh as seen from `view` (opaque: draw it before the furs). Call
    /// [`PlainMesh::prepare`] before submitting.
    pub fn draw_plain(&self, pass: &mut wgpu::RenderPass<'_>, view: &FurView, mesh: &PlainMesh) {
        let geometry = mesh.geometry();
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, geometry.bind_group(), &[]);
        pass.set_pipeline(&self.surface(geometry.shape.has_uvs).plain);
        geometry.draw_skin(pass);
    }

    fn surface(&self, has_uvs: bool) -> &SurfacePipelines {
        if has_uvs { &self.wedges } else { &self.indexed }
    }

    pub(crate) fn layouts(&self) -> &Layouts {
        &self.layouts
    }
}

/// The shells one at a time from the innermost out (blending needs the order): those the view
/// angle thins over the pass's list of triangles, the others over every triangle.
fn draw_thinned_shells(
    pass: &mut wgpu::RenderPass<'_>,
    fur: &GpuFur,
    surface: &SurfacePipelines,
    which: usize,
    list: &ShellList,
) {
    let geometry = fur.geometry();
    let layers = geometry.shape.layers;
    for shell in 0..fur.drawn_shells() {
        if fur.prepared_level().dropped_shell(layers, shell) {
            pass.set_pipeline(&surface.listed_shells[which]);
            pass.set_index_buffer(list.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed_indirect(&list.draws, u64::from(shell) * DRAW_ARGS_BYTES);
        } else {
            pass.set_pipeline(&surface.shells[which]);
            geometry.draw_shells(pass, shell..shell + 1);
        }
    }
}
