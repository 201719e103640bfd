//! The fur in Bevy's depth passes: its depth and motion vectors in each camera's prepass (so TAA
//! and motion blur see it move) and its depth in every shadow map Bevy draws (directional
//! cascades, point and spot lights), the skin opaque and shells and fins alpha-tested.
//!
//! Both draw after Bevy's own phases into Bevy's attachments: the prepass into the prepass depth
//! texture (the copy later passes read, so the main pass's blended shells are not occluded by
//! their own depth) and motion-vector texture; shadows into each shadow view's depth attachment.
//! Like Bevy's casters they draw with reverse-Z and no depth bias (receivers offset their
//! lookups), and directional cascades clamp depth instead of clipping at the near plane.

use std::collections::{HashMap, HashSet};

use bevy::core_pipeline::prepass::{DepthPrepass, MotionVectorPrepass, ViewPrepassTextures};
use bevy::ecs::prelude::*;
use bevy::log::error;
use bevy::pbr::{LightEntity, ShadowView, ViewLightEntities};
use bevy::render::camera::ExtractedCamera;
use bevy::render::renderer::{RenderContext, ViewQuery};
use bevy::render::view::{ExtractedView, Msaa};
use pelt_render::{
    FurMotion, FurPrepass, FurRenderer, FurTarget, FurView, GpuFur, MotionData, PrepassTarget, ViewData,
};

use crate::convert::to_pelt_mat4;
use crate::render::{DEPTH_FORMAT, ExtractedFurs, FurGpu, clip_from_world, set_camera_viewport};

/// Bevy's motion-vector format (`MOTION_VECTOR_PREPASS_FORMAT`).
const MOTION_FORMAT: wgpu::TextureFormat = bevy::core_pipeline::prepass::MOTION_VECTOR_PREPASS_FORMAT;

/// The prepass and shadow objects: pipelines per attachment description, a view uniform per
/// shadow view, one [`FurMotion`] per view and fur.
#[derive(Resource, Default)]
pub(crate) struct FurPasses {
    prepasses: HashMap<(FurTarget, PrepassTarget), FurPrepass>,
    failed: HashSet<(FurTarget, PrepassTarget)>,
    /// Shadow views: their uniform and the target whose furs they draw.
    shadow_views: HashMap<Entity, (FurTarget, FurView)>,
    /// Per (view, fur entity): the fur's revision when made, and the motion.
    motions: HashMap<(Entity, Entity), (u64, FurMotion)>,
    /// Per camera: its prepass target and last frame's unjittered projection.
    cameras: HashMap<Entity, CameraPrepass>,
}

struct CameraPrepass {
    target: (FurTarget, PrepassTarget),
    previous_clip_from_world: glam::Mat4,
}

/// Bevy's shadow maps: their own depth format, reverse-Z like its views.
fn shadow_target() -> PrepassTarget {
    PrepassTarget::depth(bevy::pbr::CORE_3D_SHADOW_MAP_FORMAT, wgpu::CompareFunction::GreaterEqual)
}

fn prepass<'a>(
    prepasses: &'a mut HashMap<(FurTarget, PrepassTarget), FurPrepass>,
    failed: &mut HashSet<(FurTarget, PrepassTarget)>,
    device: &wgpu::Device,
    renderer: &FurRenderer,
    target: PrepassTarget,
) -> Option<&'a FurPrepass> {
    let key = (renderer.target(), target);
    if failed.contains(&key) {
        return None;
    }
    if let std::collections::hash_map::Entry::Vacant(entry) = prepasses.entry(key) {
        match FurPrepass::new(device, renderer, target) {
            Ok(prepass) => {
                entry.insert(prepass);
            }
            Err(problem) => {
                error!("Pelt cannot draw fur into {target:?}: {problem}");
                failed.insert(key);
                return None;
            }
        }
    }
    prepasses.get(&key)
}

/// Prepares the prepass and shadow draws of this frame: runs after `prepare_furs`.
pub(crate) fn prepare_fur_passes(
    device: Res<bevy::render::renderer::RenderDevice>,
    queue: Res<bevy::render::renderer::RenderQueue>,
    extracted: Res<ExtractedFurs>,
    gpu: Res<FurGpu>,
    mut passes: ResMut<FurPasses>,
    cameras: Query<(Entity, &ExtractedView, &Msaa, Has<DepthPrepass>, Has<MotionVectorPrepass>), With<ExtractedCamera>>,
    shadow_views: Query<(Entity, &ExtractedView, &LightEntity), With<ShadowView>>,
) {
    let device = device.wgpu_device();
    let queue: &wgpu::Queue = &queue;
    let passes = &mut *passes;
    let mut seen = HashSet::new();

    for (entity, view, msaa, depth_prepass, motion_prepass) in &cameras {
        let Some(entry) = gpu.view(entity) else { continue };
        if !depth_prepass {
            continue;
        }
        let renderer = gpu.renderer(entry.target());
        let mut target =
            PrepassTarget::depth(DEPTH_FORMAT, wgpu::CompareFunction::GreaterEqual).with_sample_count(msaa.samples());
        if motion_prepass {
            target = target.with_motion(MOTION_FORMAT);
        }
        let Some(prepass) = prepass(&mut passes.prepasses, &mut passes.failed, device, renderer, target) else {
            continue;
        };
        let unjittered = clip_from_world(view);
        let camera = passes
            .cameras
            .entry(entity)
            .or_insert(CameraPrepass { target: (entry.target(), target), previous_clip_from_world: unjittered });
        camera.target = (entry.target(), target);
        for fur in extracted.furs() {
            let Some(driver) = gpu.fur(fur.entity, entry.target()) else { continue };
            let key = (entity, fur.entity);
            let stale = passes.motions.get(&key).is_none_or(|(revision, _)| *revision != fur.revision);
            if stale {
                let motion = if motion_prepass {
                    FurMotion::new(device, queue, prepass, driver.fur())
                } else {
                    FurMotion::depth_only(device, prepass, driver.fur())
                };
                passes.motions.insert(key, (fur.revision, motion));
            }
            let motion = &passes.motions[&key].1;
            let previous = gpu.previous(fur.entity, entry.target());
            if motion_prepass
                && let Some((positions, _)) = previous
                && let Err(problem) = motion.set_previous_positions(queue, positions)
            {
                error!("Pelt cannot keep the last frame of {}: {problem}", fur.entity);
            }
            motion.prepare(
                queue,
                &MotionData {
                    unjittered_clip_from_world: unjittered,
                    previous_clip_from_world: camera.previous_clip_from_world,
                    previous_world_from_model: previous.map_or(fur.world_from_simulation, |(_, transform)| transform),
                    clamp_depth: false,
                },
            );
            seen.insert(key);
        }
        camera.previous_clip_from_world = unjittered;
    }

    // Shadow maps: drawn with the furs of the first camera target (any holds the same upload).
    if let Some(target) = gpu.first_target() {
        let renderer = gpu.renderer(target);
        if let Some(prepass) = prepass(&mut passes.prepasses, &mut passes.failed, device, renderer, shadow_target()) {
            for (entity, view, light) in &shadow_views {
                let clamp_depth = matches!(light, LightEntity::Directional { .. });
                let mut world_from_view = to_pelt_mat4(&view.world_from_view.to_matrix());
                if clamp_depth {
                    // A directional light sees along parallel rays: fade shells and fins as seen
                    // from far up its beam, not from the cascade's origin.
                    let back = world_from_view.z_axis.truncate().normalize_or_zero();
                    world_from_view.w_axis += (back * 1.0e4).extend(0.0);
                }
                let shadow_view =
                    passes.shadow_views.entry(entity).or_insert_with(|| (target, FurView::new(device, renderer)));
                if shadow_view.0 != target {
                    *shadow_view = (target, FurView::new(device, renderer));
                }
                let data = ViewData::new(clip_from_world(view), world_from_view, &pelt_render::Light::default());
                shadow_view.1.prepare(queue, &data);
                for fur in extracted.furs().iter().filter(|fur| fur.casts_shadows) {
                    let Some(driver) = gpu.fur(fur.entity, target) else { continue };
                    let key = (entity, fur.entity);
                    let stale = passes.motions.get(&key).is_none_or(|(revision, _)| *revision != fur.revision);
                    if stale {
                        passes
                            .motions
                            .insert(key, (fur.revision, FurMotion::depth_only(device, prepass, driver.fur())));
                    }
                    passes.motions[&key].1.prepare(queue, &MotionData::still(clamp_depth));
                    seen.insert(key);
                }
            }
            passes.shadow_views.retain(|entity, _| shadow_views.contains(*entity));
        }
    }
    passes.motions.retain(|key, _| seen.contains(key));
    passes.cameras.retain(|entity, _| cameras.contains(*entity));
}

/// Draws every fur into one camera's prepass targets, after Bevy's prepass phases: the prepass
/// depth texture and, with `MotionVectorPrepass`, the motion vectors.
pub(crate) fn draw_fur_prepass(
    view: ViewQuery<(&ExtractedCamera, &ViewPrepassTextures)>,
    gpu: Res<FurGpu>,
    passes: Res<FurPasses>,
    extracted: Res<ExtractedFurs>,
    mut ctx: RenderContext,
) {
    let view_entity = view.entity();
    let (camera, textures) = view.into_inner();
    let Some(camera_prepass) = passes.cameras.get(&view_entity) else { return };
    let Some(entry) = gpu.view(view_entity) else { return };
    let Some(prepass) = passes.prepasses.get(&camera_prepass.target) else { return };
    let Some(depth) = textures.depth_only_view() else { return };
    let furs = draws(&extracted, &gpu, &passes, view_entity, camera_prepass.target.0, false);
    if furs.is_empty() {
        return;
    }
    let motion_attachment = prepass.target().motion_format.and(textures.motion_vectors.as_ref());
    if prepass.target().motion_format.is_some() && motion_attachment.is_none() {
        return;
    }
    let colour = motion_attachment.map(|attachment| attachment.get_attachment());
    let colours = [colour];
    let mut pass = ctx.command_encoder().begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("pelt fur prepass"),
        color_attachments: if colours[0].is_some() { &colours[..] } else { &[] },
        depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
            view: depth,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
            stencil_ops: None,
        }),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    set_camera_viewport(&mut pass, camera);
    for (fur, motion, skin) in furs {
        prepass.draw(&mut pass, entry.fur_view(), fur, motion, skin);
    }
}

/// The furs one view draws with their motions: (GPU fur, motion, whether the skin is drawn).
fn draws<'a>(
    extracted: &'a ExtractedFurs,
    gpu: &'a FurGpu,
    passes: &'a FurPasses,
    view: Entity,
    target: FurTarget,
    shadow: bool,
) -> Vec<(&'a GpuFur, &'a FurMotion, bool)> {
    extracted
        .furs()
        .iter()
        .filter(|fur| !shadow || fur.casts_shadows)
        .filter_map(|fur| {
            let driver = gpu.fur(fur.entity, target)?;
            let (_, motion) = passes.motions.get(&(view, fur.entity))?;
            Some((driver.fur(), motion, fur.skin))
        })
        .collect()
}

/// Draws every shadow-casting fur into one shadow view's depth, after Bevy's casters.
fn draw_shadow_view(
    (view_light, shadow_view): (Entity, &ShadowView),
    (gpu, passes, extracted): (&FurGpu, &FurPasses, &ExtractedFurs),
    ctx: &mut RenderContext<'_, '_>,
) {
    let Some((target, fur_view)) = passes.shadow_views.get(&view_light) else { return };
    let Some(prepass) = passes.prepasses.get(&(*target, shadow_target())) else { return };
    let furs = draws(extracted, gpu, passes, view_light, *target, true);
    if furs.is_empty() {
        return;
    }
    let mut pass = ctx.command_encoder().begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("pelt fur shadow"),
        color_attachments: &[],
        depth_stencil_attachment: Some(shadow_view.depth_attachment.get_attachment(wgpu::StoreOp::Store)),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    for (fur, motion, skin) in furs {
        prepass.draw(&mut pass, fur_view, fur, motion, skin);
    }
}

/// The fur into the directional cascades of one camera.
pub(crate) fn draw_fur_cascades(
    view: ViewQuery<&ViewLightEntities>,
    shadow_views: Query<&ShadowView>,
    gpu: Res<FurGpu>,
    passes: Res<FurPasses>,
    extracted: Res<ExtractedFurs>,
    mut ctx: RenderContext,
) {
    for &light in &view.into_inner().lights {
        if let Ok(shadow_view) = shadow_views.get(light) {
            draw_shadow_view((light, shadow_view), (&gpu, &passes, &extracted), &mut ctx);
        }
    }
}

/// The fur into one point or spot light's shadow map (a view of its own).
pub(crate) fn draw_fur_shared_shadows(
    view: ViewQuery<&ShadowView>,
    gpu: Res<FurGpu>,
    passes: Res<FurPasses>,
    extracted: Res<ExtractedFurs>,
    mut ctx: RenderContext,
) {
    let entity = view.entity();
    draw_shadow_view((entity, view.into_inner()), (&gpu, &passes, &extracted), &mut ctx);
}
