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

mod herd;
mod herd_view;
mod objects;
mod pipeline;
mod prepass;
mod shadow;

pub use herd_view::HerdDraws;
pub(crate) use pipeline::{PassKind, PipelineSource, Transparency, create_pipeline};
pub use prepass::{FurMotion, FurPrepass, MotionData, PrepassTarget};

use std::sync::OnceLock;

use crate::RenderError;
use crate::fur::{Coat, GpuFur};
use crate::listing::{DRAW_ARGS_BYTES, FIN_INSTANCE_LAYOUT, FinList, ListingPasses, ShellList};
use crate::plain::PlainMesh;
use crate::pool::{LIST_FINS, LIST_SHELLS};
use crate::requirements::{ErrorScope, check_features_and_limits};
use crate::shaders::{Layouts, unified_shader_source};
use crate::sim_pipelines::SimPipelines;
use crate::targets::FurTarget;
use crate::view::{FurView, ShadowLookups, ViewRole};

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

/// The two ways of walking the base triangles (see `unified.wgsl`), as entry point suffixes:
/// meshes with uvs by the corners' wedges, meshes without by the base triangles.
const WALKS: [(&str, bool); 2] = [("wedges", true), ("indexed", false)];

/// The coat-independent pipelines for one way of walking the base triangles (see
/// `unified.wgsl`).
#[derive(Debug)]
struct SurfacePipelines {
    plain: wgpu::RenderPipeline,
    skin: wgpu::RenderPipeline,
}

/// One coat's shell and fin pipelines, each blended and alpha-to-coverage.
#[derive(Debug)]
struct CoatPipelines {
    /// Meshes with uvs (by the corners' wedges), then meshes without (by the base triangles).
    shells: [[wgpu::RenderPipeline; 2]; 2],
    /// The same over the view-angle pass's list.
    listed_shells: [[wgpu::RenderPipeline; 2]; 2],
    /// Every edge.
    fins: [wgpu::RenderPipeline; 2],
    /// The silhouette pass's edges.
    silhouette_fins: [wgpu::RenderPipeline; 2],
}

/// What building a coat's pipelines takes, kept so the groomed and wet coats are built the
/// first time a fur draws with one (a dry, ungroomed scene never compiles them).
#[derive(Debug)]
struct CoatBuilder {
    device: wgpu::Device,
    module: wgpu::ShaderModule,
    layout: wgpu::PipelineLayout,
    /// Plain meshes' (no fur textures).
    plain_layout: wgpu::PipelineLayout,
}

impl CoatBuilder {
    /// The plain and skin pipelines of one walk, seen with shadows or without.
    fn surface(&self, target: &FurTarget, mesh_uvs: bool, shadowed: ShadowLookups) -> SurfacePipelines {
        let skin = format!("vs_skin_{}", if mesh_uvs { "wedges" } else { "indexed" });
        let build = |label, layout, fragment_entry| {
            let source = PipelineSource {
                mesh_uvs: Some(mesh_uvs),
                coat: Some(Coat::PLAIN.shadowed(shadowed)),
                layout,
                module: &self.module,
                vertex_entry: &skin,
                fragment_entry,
                buffers: &[],
            };
            create_pipeline(&self.device, target, label, &source, PassKind::Opaque)
        };
        SurfacePipelines {
            plain: build("pelt plain", &self.plain_layout, "fs_plain"),
            skin: build("pelt skin", &self.layout, "fs_skin"),
        }
    }

    fn build(&self, target: &FurTarget, coat: Coat) -> CoatPipelines {
        let build = |label: &str, vertex: &str, fragment: &str, kind: PassKind, (buffers, mesh_uvs)| {
            let (vertex_entry, fragment_entry) = (coat.entry(vertex), coat.entry(fragment));
            let source = PipelineSource {
                mesh_uvs,
                coat: Some(coat),
                layout: &self.layout,
                module: &self.module,
                vertex_entry: &vertex_entry,
                fragment_entry: &fragment_entry,
                buffers,
            };
            create_pipeline(&self.device, target, label, &source, kind)
        };
        // Meshes with uvs walk wedges, meshes without base vertices: each walk's pipelines know
        // which, and drop the other's work.
        let shells = |listed: &str| {
            WALKS.map(|(walk, mesh_uvs)| {
                let vertex = format!("vs_shell_{walk}{listed}");
                let fragment = if mesh_uvs { "fs_shell_uvs" } else { "fs_shell_tiles" };
                Transparency::BOTH
                    .map(|t| build("pelt shells", &vertex, fragment, PassKind::Shells(t), (&[][..], Some(mesh_uvs))))
            })
        };
        let instances = [Some(FIN_INSTANCE_LAYOUT)];
        CoatPipelines {
            shells: shells(""),
            listed_shells: shells("_listed"),
            fins: Transparency::BOTH.map(|t| build("pelt fins", "vs_fin", "fs_fin", PassKind::Fins(t), (&[], None))),
            silhouette_fins: Transparency::BOTH.map(|t| {
                build("pelt silhouette fins", "vs_fin_silhouette", "fs_fin", PassKind::Fins(t), (&instances, None))
            }),
        }
    }
}

/// The unified structure's pipelines for one [`FurTarget`], shared by every [`GpuFur`],
/// [`PlainMesh`] and [`FurView`] made with it. Create it once per target description.
///
/// Nothing here blocks, and it keeps no per-frame state: `draw` only records into the host's
/// pass what `prepare` calls wrote before. The pipelines of a groomed or wet coat are built the
/// first time a fur draws with one.
#[derive(Debug)]
pub struct FurRenderer {
    target: FurTarget,
    layouts: Layouts,
    /// The skin and plain meshes, without shadows and with them: meshes with uvs (indexed by
    /// the corners' wedges), then meshes without (by the base triangles). Those without shadows
    /// are built with the rest.
    surfaces: [[OnceLock<SurfacePipelines>; 2]; 3],
    /// Shells and fins per [`Coat`] (by [`Coat::index`]); the plain coat's built with the rest.
    coats: [OnceLock<CoatPipelines>; Coat::COUNT],
    coat_builder: CoatBuilder,
    /// The shadow maps' pipelines, built when one first draws.
    shadows: shadow::ShadowSet,
    /// The silhouette and view-angle passes.
    listing: ListingPasses,
    /// The GPU simulation's kernels, compiled when a fur first simulates on the GPU.
    simulation: OnceLock<SimPipelines>,
    /// Whether [`FurRenderer::draw_herd`] pools a herd's shadow casters.
    pooled_casting: bool,
    /// Whether a herd's GPU simulations made after this step each pool in one dispatch.
    pooled_stepping: bool,
    /// Whether [`HerdDraws`] pools the camera's draws of a herd.
    pooled_drawing: bool,
    /// Whether the device takes an indirect draw's first instance, so [`HerdDraws`] can gather
    /// thinned shells and fins ([`crate::optional_features`]).
    first_instance: bool,
    /// Whether hosts pose a GPU-kernel herd's bases on the GPU (`HerdPosing`).
    herd_posing: bool,
    /// The camera's pooled pipelines (`HerdDraws`), built when a herd first draws with one.
    pool_camera: herd_view::PoolCameraPipelines,
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
        let coat_builder = CoatBuilder { device: device.clone(), module, layout: fur_layout, plain_layout };
        let surfaces = [(); 3].map(|()| [(); 2].map(|()| OnceLock::new()));
        for (walk, mesh_uvs) in [true, false].into_iter().enumerate() {
            let _ = surfaces[0][walk].set(coat_builder.surface(&target, mesh_uvs, ShadowLookups::Off));
        }
        let coats = [(); Coat::COUNT].map(|()| OnceLock::new());
        let _ = coats[Coat::PLAIN.index()].set(coat_builder.build(&target, Coat::PLAIN));
        let listing = ListingPasses::new(device, &layouts);
        scope.pop("building the fur pipelines")?;
        // Pooling pays on a GPU; on a CPU rasteriser every lane reads its copy's data from
        // storage, and a dispatch a copy was as fast.
        let gpu = matches!(
            device.adapter_info().device_type,
            wgpu::DeviceType::DiscreteGpu | wgpu::DeviceType::IntegratedGpu
        );
        Ok(Self {
            target,
            layouts,
            surfaces,
            coats,
            coat_builder,
            shadows: shadow::ShadowSet::default(),
            listing,
            simulation: OnceLock::new(),
            pooled_casting: gpu,
            pooled_stepping: gpu,
            pooled_drawing: gpu,
            first_instance: device.features().contains(wgpu::Features::INDIRECT_FIRST_INSTANCE),
            herd_posing: gpu,
            pool_camera: herd_view::PoolCameraPipelines::default(),
        })
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
    ///
    /// Through one of a [`crate::ShadowMap`]'s views (its `record`), the fur draws itself into
    /// that shadow pass instead: its skin as an opaque caster, its shells and fins as opacity.
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, view: &FurView, fur: &GpuFur, settings: &FurDrawSettings) {
        self.draw_counted(pass, view, fur, settings);
    }

    /// [`FurRenderer::draw`], returning the draws recorded.
    fn draw_counted(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        view: &FurView,
        fur: &GpuFur,
        settings: &FurDrawSettings,
    ) -> usize {
        let shadowed = match view.role() {
            ViewRole::Camera { shadows } => shadows,
            ViewRole::Shadow(shadow_pass) => return self.draw_shadow(pass, (view, shadow_pass), fur, settings),
        };
        let geometry = fur.geometry();
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, geometry.bind_group(), &[]);
        pass.set_bind_group(2, fur.textures_bind_group(), &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        let mut draws = 0;
        if settings.skin {
            pass.set_pipeline(&self.surface(geometry.shape.has_uvs, shadowed).skin);
            geometry.draw_skin(pass);
            draws += 1;
        }
        let layers = geometry.shape.layers;
        if layers == 0 || !(settings.shells || settings.fins) || !fur.prepared_level().coat_shown() {
            return draws;
        }
        if settings.shells {
            draws += self.draw_shells_of(pass, fur, shadowed, settings);
        }
        // Fins after the shells: at the silhouette, where fins matter, they stand outside the
        // shells and must not be covered by the faded outer layers.
        if settings.fins && fur.prepared_level().fins_shown() {
            draws += self.draw_fins_of(pass, fur, shadowed, settings);
        }
        draws
    }

    /// A shown coat's shells (its object bound in group 1), those the view angle thins over its
    /// list where its listing pass was recorded; returns the draws recorded.
    fn draw_shells_of(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        fur: &GpuFur,
        shadowed: ShadowLookups,
        settings: &FurDrawSettings,
    ) -> usize {
        let coat = self.coat(fur.coat().shadowed(shadowed));
        let walk = usize::from(!fur.geometry().shape.has_uvs);
        let which = Transparency::index(settings.alpha_to_coverage);
        let shells = &coat.shells[walk][which];
        match fur.shell_list() {
            Some(list) if list.recorded(fur.slot()) && fur.prepared_level().by_view() => {
                draw_thinned_shells(pass, fur, (shells, &coat.listed_shells[walk][which]), list);
                fur.drawn_shells() as usize
            }
            _ => {
                pass.set_pipeline(shells);
                fur.geometry().draw_shells(pass, 0..fur.drawn_shells());
                1
            }
        }
    }

    /// A shown coat's fins (its object bound in group 1); returns the draws recorded.
    fn draw_fins_of(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        fur: &GpuFur,
        shadowed: ShadowLookups,
        settings: &FurDrawSettings,
    ) -> usize {
        let coat = self.coat(fur.coat().shadowed(shadowed));
        let which = Transparency::index(settings.alpha_to_coverage);
        let geometry = fur.geometry();
        match fur.fin_list() {
            Some(list) if settings.silhouette_fins => {
                pass.set_pipeline(&coat.silhouette_fins[which]);
                let slot = fur.slot();
                geometry.draw_fin_list(pass, list.instances_of(slot), (&list.draws, FinList::draw_offset(slot)));
            }
            _ => {
                pass.set_pipeline(&coat.fins[which]);
                geometry.draw_fins(pass, fur.drawn_shells());
            }
        }
        1
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
        self.prepare_fins_of(encoder, view, [fur]);
    }

    /// [`FurRenderer::prepare_fins`] for every fur of `furs` (a herd), in one compute pass: the
    /// copies made together (`FurDriver::herd_with_asset`, `GpuFur::herd_from_asset`) share a
    /// pool, and each listing dispatch lists every copy of a pool that lists this frame (as its
    /// last [`GpuFur::prepare`] said), so a herd lists in a few dispatches, not a few a fur. No
    /// pass when none of them lists. Returns the dispatches recorded.
    pub fn prepare_fins_of<'a>(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        view: &FurView,
        furs: impl IntoIterator<Item = &'a GpuFur>,
    ) -> usize {
        // Per pool (in the order first met): whether any of its copies lists fins, and the slots
        // whose shells are thinned.
        let mut pools: Vec<(&GpuFur, bool, Vec<u32>)> = Vec::new();
        for fur in furs {
            let lists = fur.lists();
            let (fins, shells) = (lists & LIST_FINS != 0, lists & LIST_SHELLS != 0);
            if lists == 0 {
                continue;
            }
            let index = match pools.iter().position(|(first, ..)| std::sync::Arc::ptr_eq(first.pool(), fur.pool())) {
                Some(index) => index,
                None => {
                    pools.push((fur, false, Vec::new()));
                    pools.len() - 1
                }
            };
            pools[index].1 |= fins;
            if shells {
                pools[index].2.push(fur.slot());
            }
        }
        if pools.is_empty() {
            return 0;
        }
        for (fur, _, thinned) in &pools {
            if let Some(list) = fur.pool().shells().filter(|_| !thinned.is_empty()) {
                list.fill_head(encoder);
            }
        }
        let mut pass = encoder
            .begin_compute_pass(&wgpu::ComputePassDescriptor { label: Some("pelt listing"), timestamp_writes: None });
        let mut dispatches = 0;
        for (fur, fins, thinned) in pools {
            let pool = fur.pool();
            let objects = pool.listing_group();
            if let Some(list) = pool.fins().filter(|_| fins) {
                list.record(&mut pass, &self.listing.silhouette, view.bind_group(), objects);
                dispatches += 2;
            }
            if let Some(list) = pool.shells().filter(|_| !thinned.is_empty()) {
                list.record(&mut pass, &self.listing.view_lod, (view.bind_group(), objects), thinned);
                dispatches += 3;
            }
        }
        dispatches
    }

    /// Records a plain mesh as seen from `view` (opaque: draw it before the furs). Call
    /// [`PlainMesh::prepare`] before submitting.
    pub fn draw_plain(&self, pass: &mut wgpu::RenderPass<'_>, view: &FurView, mesh: &PlainMesh) {
        let shadowed = match view.role() {
            ViewRole::Camera { shadows } => shadows,
            ViewRole::Shadow(shadow_pass) => return self.draw_plain_shadow(pass, (view, shadow_pass), mesh),
        };
        let geometry = mesh.geometry();
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, geometry.bind_group(), &[]);
        pass.set_bind_group(2, &self.layouts.empty_group, &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        pass.set_pipeline(&self.surface(geometry.shape.has_uvs, shadowed).plain);
        geometry.draw_skin(pass);
    }

    fn surface(&self, has_uvs: bool, shadowed: ShadowLookups) -> &SurfacePipelines {
        let walk = usize::from(!has_uvs);
        self.surfaces[shadowed as usize][walk]
            .get_or_init(|| self.coat_builder.surface(&self.target, has_uvs, shadowed))
    }

    /// `coat`'s shell and fin pipelines, built on first use.
    fn coat(&self, coat: Coat) -> &CoatPipelines {
        self.coats[coat.index()].get_or_init(|| self.coat_builder.build(&self.target, coat))
    }

    pub(crate) fn layouts(&self) -> &Layouts {
        &self.layouts
    }

    /// The GPU simulation's kernels for every fur simulated through this renderer, compiled once.
    pub(crate) fn simulation_pipelines(&self) -> Result<&SimPipelines, RenderError> {
        if let Some(pipelines) = self.simulation.get() {
            return Ok(pipelines);
        }
        let built = SimPipelines::new(&self.coat_builder.device)?;
        Ok(self.simulation.get_or_init(|| built))
    }
}

/// The shells one at a time from the innermost out (blending needs the order): those the view
/// angle thins over the pass's list of triangles, the others over every triangle.
fn draw_thinned_shells(
    pass: &mut wgpu::RenderPass<'_>,
    fur: &GpuFur,
    (shells, listed_shells): (&wgpu::RenderPipeline, &wgpu::RenderPipeline),
    list: &ShellList,
) {
    let geometry = fur.geometry();
    let layers = geometry.shape.layers;
    for shell in 0..fur.drawn_shells() {
        if fur.prepared_level().dropped_shell(layers, shell) {
            pass.set_pipeline(listed_shells);
            // The draws start at the fur's own indices (`first_index`).
            pass.set_index_buffer(list.indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed_indirect(&list.draws, list.draws_offset(fur.slot()) + u64::from(shell) * DRAW_ARGS_BYTES);
        } else {
            pass.set_pipeline(shells);
            geometry.draw_shells(pass, shell..shell + 1);
        }
    }
}
