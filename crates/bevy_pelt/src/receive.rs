//! The fur receives Bevy's shadows: each camera's directional cascades, spot lights' maps and
//! point lights' cube faces, drawn by Bevy's shadow passes (the fur's own depth among them),
//! copied into pelt-render's `HostShadows` after those passes and read by the fur's lights in the
//! main pass.

use std::collections::{HashMap, HashSet};

use bevy::ecs::prelude::*;
use bevy::log::{error, warn};
use bevy::pbr::{LightEntity, ShadowView, ViewLightEntities};
use bevy::render::camera::ExtractedCamera;
use bevy::render::renderer::{RenderContext, ViewQuery};
use bevy::render::sync_world::MainEntity;
use bevy::render::texture::DepthStencilViews;
use bevy::render::view::ExtractedView;
use pelt_render::{HostLight, HostShadowView, HostShadows, MAX_SHADOW_VIEWS};

use crate::convert::to_pelt_mat4;
use crate::render::{ExtractedFurs, FurGpu, clip_from_world};

/// One camera's copies of Bevy's maps.
#[derive(Resource, Default)]
pub(crate) struct FurReceivers {
    cameras: HashMap<Entity, HostShadows>,
    /// Cameras whose copies could not be made (reported once).
    failed: HashSet<Entity>,
    /// Cameras whose lights want more views than the copies hold (reported once).
    overflowing: HashSet<Entity>,
}

/// A shadow view of Bevy's that a fur's light reads: the light's index, the view, its depth.
struct Candidate {
    light_index: usize,
    cascade: usize,
    view: HostShadowView,
    source: wgpu::TextureView,
    size: u32,
}

/// Aims each camera's copies at the shadow views Bevy drew for it and lights the camera's fur
/// view with them: runs after `prepare_furs`.
pub(crate) fn prepare_fur_receivers(
    device: Res<bevy::render::renderer::RenderDevice>,
    queue: Res<bevy::render::renderer::RenderQueue>,
    extracted: Res<ExtractedFurs>,
    mut gpu: ResMut<FurGpu>,
    mut receivers: ResMut<FurReceivers>,
    cameras: Query<(Entity, &ViewLightEntities), With<ExtractedCamera>>,
    shadow_views: Query<(&ShadowView, &ExtractedView, &LightEntity)>,
    main_entities: Query<&MainEntity>,
) {
    let device = device.wgpu_device();
    let queue: &wgpu::Queue = &queue;
    let receivers = &mut *receivers;
    let furs = extracted.furs();
    let fur_depth = furs.iter().map(|fur| fur.longest_strand()).fold(0.0, f32::max).max(1e-3);
    let mut seen = HashSet::new();
    for (camera, lights) in &cameras {
        let Some(entry) = gpu.view(camera) else { continue };
        let target = entry.target();
        let mut candidates: Vec<Candidate> = Vec::new();
        // The camera's own cascades, and the spot and point lights' maps every camera shares.
        let shared = shadow_views.iter().filter(|(.., light)| !matches!(light, LightEntity::Directional { .. }));
        let own = lights.lights.iter().filter_map(|&light_view| shadow_views.get(light_view).ok());
        for (shadow_view, view, light) in
            own.filter(|(.., l)| matches!(l, LightEntity::Directional { .. })).chain(shared)
        {
            let (light_entity, cascade) = match *light {
                LightEntity::Directional { light_entity, cascade_index } => (light_entity, cascade_index),
                LightEntity::Spot { light_entity } => (light_entity, 0),
                LightEntity::Point { light_entity, face_index } => (light_entity, face_index),
            };
            let Some(light_index) =
                main_entities.get(light_entity).ok().and_then(|main| extracted.light_index(main.id()))
            else {
                continue;
            };
            let DepthStencilViews::DepthOnly { depth_view } = &shadow_view.depth_attachment.depth_stencil_views else {
                continue;
            };
            let clip_from_world = clip_from_world(view);
            let size = view.viewport.z.max(1);
            let world_from_view = to_pelt_mat4(&view.world_from_view.to_matrix());
            let directional = matches!(light, LightEntity::Directional { .. });
            let clip_from_view = to_pelt_mat4(&view.clip_from_view);
            let position = world_from_view.w_axis.truncate();
            let (host_light, texel_world) = if directional {
                // Orthographic: the view's width over its texels.
                let width = 2.0 / clip_from_view.x_axis.x.abs().max(1e-12);
                (HostLight::Directional(world_from_view.z_axis.truncate()), width / size as f32)
            } else {
                // Perspective: a texel's span at the furs' distance from the light.
                let distance = furs.first().map_or(1.0, |fur| fur.bounds().0.distance(position));
                let span = 2.0 * distance / clip_from_view.y_axis.y.abs().max(1e-12);
                let host_light = match light {
                    // The face is the axis the view looks along (Bevy's cube faces are
                    // left-handed: its "+z" face looks along -Z).
                    LightEntity::Point { .. } => {
                        HostLight::CubeFace { position, face: axis_face(-world_from_view.z_axis.truncate()) }
                    }
                    _ => HostLight::Positional(position),
                };
                (host_light, span / size as f32)
            };
            candidates.push(Candidate {
                light_index,
                cascade,
                view: HostShadowView { light_index, clip_from_world, reverse_z: true, texel_world, light: host_light },
                source: (**depth_view).clone(),
                size,
            });
        }
        // One view a light: the nearest cascade that holds every fur, else the farthest.
        candidates.sort_by_key(|c| (c.light_index, c.cascade));
        let holds_every_fur = |c: &Candidate| {
            furs.iter().all(|fur| {
                let (centre, radius) = fur.bounds();
                [-1.0, 1.0].iter().all(|&s| {
                    let p = c.view.clip_from_world * (centre + glam::Vec3::splat(s * radius)).extend(1.0);
                    p.w > 0.0 && (p.truncate().truncate() / p.w).abs().max_element() <= 1.0
                })
            })
        };
        let mut chosen: Vec<Candidate> = Vec::new();
        for candidate in candidates {
            let cube_face = matches!(candidate.view.light, HostLight::CubeFace { .. });
            match chosen.last_mut() {
                Some(last) if last.light_index == candidate.light_index && !cube_face => {
                    if !holds_every_fur(last) {
                        *last = candidate;
                    }
                }
                _ => chosen.push(candidate),
            }
        }
        // Layers as large as the largest map (a point light's beside a sun's, of other sizes).
        let Some(size) = chosen.iter().map(|c| c.size).max() else {
            if let Some(entry) = gpu.view_mut(camera) {
                entry.fur_view_mut().set_host_shadows(None);
            }
            continue;
        };
        let layers = (chosen.len() as u32).min(MAX_SHADOW_VIEWS);
        if chosen.len() > MAX_SHADOW_VIEWS as usize && receivers.overflowing.insert(camera) {
            warn!(
                "Pelt's fur receives at most {MAX_SHADOW_VIEWS} of Bevy's shadow views (a point light takes six); \
                 {camera}'s lights have {}: the lights past them cast no shadow on the fur",
                chosen.len()
            );
        }
        let stale = receivers.cameras.get(&camera).is_none_or(|r| {
            let (made_size, made_layers) = r.size_and_layers();
            made_size != size || made_layers < layers
        });
        if stale {
            match HostShadows::new(device, gpu.renderer(target), (size, layers), fur_depth) {
                Ok(made) => {
                    receivers.cameras.insert(camera, made);
                }
                Err(problem) => {
                    if receivers.failed.insert(camera) {
                        error!("Pelt's fur cannot receive the shadows of {camera}: {problem}");
                    }
                    continue;
                }
            }
        }
        let receiver = receivers.cameras.get_mut(&camera).expect("made above");
        let views: Vec<HostShadowView> = chosen.iter().map(|c| c.view).collect();
        let sources: Vec<&wgpu::TextureView> = chosen.iter().map(|c| &c.source).collect();
        receiver.prepare((device, queue), &views, &sources);
        if let Some(entry) = gpu.view_mut(camera) {
            entry.fur_view_mut().set_host_shadows(Some(receiver));
        }
        seen.insert(camera);
    }
    receivers.cameras.retain(|camera, _| seen.contains(camera));
}

/// The cube face (0 to 5: +X, -X, +Y, -Y, +Z, -Z) whose axis `d` lies closest to.
fn axis_face(d: glam::Vec3) -> usize {
    let a = d.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    2 * axis + usize::from(d[axis] < 0.0)
}

/// Copies one camera's shadow maps after Bevy's shadow passes (and the fur's draws into them).
pub(crate) fn copy_fur_receivers(view: ViewQuery<Entity>, receivers: Res<FurReceivers>, mut ctx: RenderContext) {
    if let Some(receiver) = receivers.cameras.get(&view.into_inner()) {
        receiver.record_copy(ctx.command_encoder());
    }
}
