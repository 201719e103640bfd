//! The camera's draws of a plan ([`HerdDraws`]): its pooled pipelines, built the first time a
//! herd draws with each, and the steps recorded into the host's pass.

use std::ops::Range;
use std::sync::OnceLock;

use super::{ENTRY_BYTES, ENTRY_LAYOUT, HerdDraws, Step, coat_shells};
use crate::fur::{Coat, GpuFur};
use crate::listing::FIN_INSTANCE_LAYOUT;
use crate::renderer::pipeline::{PassKind, PipelineSource, Transparency, create_pipeline};
use crate::renderer::{CoatBuilder, FurDrawSettings, FurRenderer, WALKS};
use crate::view::{FurView, ShadowLookups, ViewRole};

/// The camera's pooled pipelines, each built the first time a herd draws with it.
#[derive(Debug, Default)]
pub(in crate::renderer) struct PoolCameraPipelines {
    /// By shadow lookups, then walk.
    skins: [OnceLock<[wgpu::RenderPipeline; 2]>; 3],
    /// By coat, then walk and transparency.
    shells: [OnceLock<[[wgpu::RenderPipeline; 2]; 2]>; Coat::COUNT],
    /// The gathered thinned shells, by coat, then walk and transparency.
    listed_shells: [OnceLock<[[wgpu::RenderPipeline; 2]; 2]>; Coat::COUNT],
    /// The gathered fins, by coat, then transparency.
    fins: [OnceLock<[wgpu::RenderPipeline; 2]>; Coat::COUNT],
}

impl CoatBuilder {
    fn pool_camera(
        &self,
        (module, layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
        target: &crate::targets::FurTarget,
        (vertex, fragment, buffer): (&str, &str, Option<wgpu::VertexBufferLayout<'static>>),
        (mesh_uvs, coat, kind): (Option<bool>, Coat, PassKind),
    ) -> wgpu::RenderPipeline {
        let buffers = [buffer];
        let source = PipelineSource {
            mesh_uvs,
            coat: Some(coat),
            layout,
            module,
            vertex_entry: vertex,
            fragment_entry: fragment,
            buffers: if buffers[0].is_some() { &buffers } else { &[] },
        };
        create_pipeline(&self.device, target, "pelt pool camera", &source, kind)
    }
}

impl FurRenderer {
    /// Whether [`HerdDraws`] pools the camera's draws of a herd's copies: by default on a
    /// discrete or integrated GPU, as [`FurRenderer::pooled_casting`] (a CPU rasteriser reads
    /// each vertex's object from storage, which costs it more than the draws save).
    #[must_use]
    pub fn pooled_drawing(&self) -> bool {
        self.pooled_drawing
    }

    /// Sets [`FurRenderer::pooled_drawing`] for the plans made after; the pictures are the same
    /// either way.
    pub fn set_pooled_drawing(&mut self, pooled: bool) {
        self.pooled_drawing = pooled;
    }

    /// Draws the members `furs` of a [`HerdDraws::prepare`] (the same furs in the same order)
    /// through `view` as its plan says; through a shadow map's view as
    /// [`FurRenderer::draw_herd`]. Furs that are not the plan's draw each alone, in order.
    /// Returns the draws recorded.
    pub fn draw_herd_planned(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        view: &FurView,
        plan: &HerdDraws,
        furs: &[&GpuFur],
        settings: &FurDrawSettings,
    ) -> usize {
        let shadowed = match view.role() {
            ViewRole::Camera { shadows } if furs.len() == plan.members => shadows,
            _ => return self.draw_herd(pass, view, furs.iter().copied(), settings),
        };
        let mut draws = 0;
        for step in &plan.steps {
            draws += match step {
                Step::Alone(member) => self.draw_counted(pass, view, furs[*member], settings),
                Step::Pooled { members, thinned, skins, shells, shell_places, fin_places } => {
                    let run: Vec<&GpuFur> = plan.pooled[members.clone()].iter().map(|&k| furs[k]).collect();
                    let Some(buffer) = &plan.buffer else { continue };
                    let places = Gathered {
                        valid: run[0].pool().gathering_plan() == plan.id,
                        thinned: thinned - members.start,
                        shells: shell_places.clone(),
                        fins: fin_places.clone(),
                    };
                    let ranges = (skins.clone(), shells.clone());
                    self.draw_pooled(pass, (view, shadowed), (&run, buffer), ranges, &places, settings)
                }
            };
        }
        draws
    }

    /// One pooled step: the run's skins, shells and fins.
    fn draw_pooled(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        (view, shadowed): (&FurView, ShadowLookups),
        (run, buffer): (&[&GpuFur], &wgpu::Buffer),
        (skins, shells): (Range<u32>, Range<u32>),
        gathered: &Gathered,
        settings: &FurDrawSettings,
    ) -> usize {
        let first = run[0];
        let geometry = first.geometry();
        let walk = usize::from(!geometry.shape.has_uvs);
        let mut draws = 0;
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, first.pool().draw_group(), &[]);
        pass.set_bind_group(2, first.textures_bind_group(), &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        // Each draw's entries bound from their first and its instances counted from 0, so no
        // backend needs a first instance for instance-rate attributes.
        let entries =
            |range: &Range<u32>| buffer.slice(ENTRY_BYTES * u64::from(range.start)..ENTRY_BYTES * u64::from(range.end));
        if settings.skin {
            pass.set_pipeline(&self.pool_camera_skins(shadowed)[walk]);
            pass.set_vertex_buffer(0, entries(&skins));
            geometry.draw_skins(pass, 0..skins.len() as u32);
            draws += 1;
        }
        let which = Transparency::index(settings.alpha_to_coverage);
        let coat = first.coat().shadowed(shadowed);
        if settings.shells && !shells.is_empty() {
            pass.set_pipeline(&self.pool_camera_shells(coat)[walk][which]);
            pass.set_vertex_buffer(0, entries(&shells));
            geometry.draw_shells(pass, 0..shells.len() as u32);
            draws += 1;
        }
        let thinned = &run[gathered.thinned..];
        if settings.shells && !thinned.is_empty() {
            let list = first.shell_list().filter(|list| {
                gathered.valid && thinned.iter().all(|fur| list.recorded(fur.slot()) && coat_shells(fur) > 0)
            });
            if let Some(list) = list {
                pass.set_pipeline(&self.pool_camera_listed_shells(coat)[walk][which]);
                pass.set_index_buffer(list.indices.slice(..), wgpu::IndexFormat::Uint32);
                let layers = geometry.shape.layers;
                let (at, count) = (list.gathered_offset(gathered.shells.start), gathered.shells.len() as u32 * layers);
                pass.multi_draw_indexed_indirect(&list.draws, at, count);
                draws += 1;
            } else {
                // Each as a lone fur (its own object in group 1).
                for fur in thinned.iter().filter(|fur| coat_shells(fur) > 0) {
                    pass.set_bind_group(1, fur.geometry().bind_group(), &[]);
                    draws += self.draw_shells_of(pass, fur, shadowed, settings);
                }
                pass.set_bind_group(1, first.pool().draw_group(), &[]);
            }
        }
        // Fins after the shells, as a lone fur draws them.
        let shown: Vec<&GpuFur> =
            run.iter().copied().filter(|fur| coat_shells(fur) > 0 && fur.prepared_level().fins_shown()).collect();
        if settings.fins && !shown.is_empty() {
            let list = first.fin_list().filter(|_| settings.silhouette_fins && gathered.valid);
            let strip = geometry.fin_strip();
            match (list, strip) {
                (Some(list), Some(strip)) if !gathered.fins.is_empty() => {
                    pass.set_pipeline(&self.pool_camera_fins(coat)[which]);
                    pass.set_index_buffer(strip.slice(..), wgpu::IndexFormat::Uint32);
                    pass.set_vertex_buffer(0, list.instances.slice(..));
                    let at = list.gathered_offset(gathered.fins.start);
                    pass.multi_draw_indexed_indirect(&list.draws, at, gathered.fins.len() as u32);
                    draws += 1;
                }
                _ => {
                    // Each its own (its object in group 1).
                    for fur in shown {
                        pass.set_bind_group(1, fur.geometry().bind_group(), &[]);
                        draws += self.draw_fins_of(pass, fur, shadowed, settings);
                    }
                }
            }
        }
        draws
    }

    fn pool_camera_skins(&self, shadowed: ShadowLookups) -> &[wgpu::RenderPipeline; 2] {
        self.pool_camera.skins[shadowed as usize].get_or_init(|| {
            let casters = self.pool_casters();
            let coat = Coat::PLAIN.shadowed(shadowed);
            WALKS.map(|(walk, uvs)| {
                self.coat_builder.pool_camera(
                    (&casters.module, &casters.layout),
                    &self.target,
                    (&format!("vs_pool_camera_skin_{walk}"), "fs_pool_skin", Some(ENTRY_LAYOUT)),
                    (Some(uvs), coat, PassKind::Opaque),
                )
            })
        })
    }

    fn pool_camera_shells(&self, coat: Coat) -> &[[wgpu::RenderPipeline; 2]; 2] {
        self.pool_camera.shells[coat.index()].get_or_init(|| {
            // The gathered ones with them: a herd that first thins or shows fins a few frames
            // in would otherwise stall that frame compiling them.
            if self.first_instance {
                self.pool_camera_listed_shells(coat);
                self.pool_camera_fins(coat);
            }
            self.pool_camera_shells_for(coat, "")
        })
    }

    fn pool_camera_listed_shells(&self, coat: Coat) -> &[[wgpu::RenderPipeline; 2]; 2] {
        self.pool_camera.listed_shells[coat.index()].get_or_init(|| self.pool_camera_shells_for(coat, "_listed"))
    }

    /// The shells' pipelines: from the plan's instance buffer, or `_listed` from the gathered
    /// draws (the first instance names the copy).
    fn pool_camera_shells_for(&self, coat: Coat, listed: &str) -> [[wgpu::RenderPipeline; 2]; 2] {
        let casters = self.pool_casters();
        let buffer = listed.is_empty().then_some(ENTRY_LAYOUT);
        WALKS.map(|(walk, uvs)| {
            let fragment = coat.entry(if uvs { "fs_pool_shell_uvs" } else { "fs_pool_shell_tiles" });
            let vertex = coat.entry(&format!("vs_pool_shell_{walk}{listed}"));
            Transparency::BOTH.map(|t| {
                self.coat_builder.pool_camera(
                    (&casters.module, &casters.layout),
                    &self.target,
                    (&vertex, &fragment, buffer.clone()),
                    (Some(uvs), coat, PassKind::Shells(t)),
                )
            })
        })
    }

    fn pool_camera_fins(&self, coat: Coat) -> &[wgpu::RenderPipeline; 2] {
        self.pool_camera.fins[coat.index()].get_or_init(|| {
            let casters = self.pool_casters();
            let (vertex, fragment) = (coat.entry("vs_pool_fin_silhouette"), coat.entry("fs_pool_fin"));
            Transparency::BOTH.map(|t| {
                self.coat_builder.pool_camera(
                    (&casters.module, &casters.layout),
                    &self.target,
                    (&vertex, &fragment, Some(FIN_INSTANCE_LAYOUT)),
                    (None, coat, PassKind::Fins(t)),
                )
            })
        })
    }
}

/// A pooled step's gathered draws: whether the pool gathers for this plan, where the thinned
/// copies start in the run, and their shells' and the run's fins' places.
struct Gathered {
    valid: bool,
    thinned: usize,
    shells: Range<u32>,
    fins: Range<u32>,
}
