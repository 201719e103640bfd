//! The render world: furs extracted each frame, uploaded with pelt-render on Bevy's own device
//! and queue, and drawn into Bevy's 3D main pass (after the opaque phase, before the
//! transparent one) with Bevy's camera, depth buffer (reverse-Z), MSAA and colour target.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use bevy::camera::{Camera3d, CompositingSpace, Exposure};
use bevy::ecs::prelude::*;
use bevy::light::{
    AmbientLight, DirectionalLight, GlobalAmbientLight, NotShadowCaster, NotShadowReceiver, PointLight, SpotLight,
};
use bevy::log::error;
use bevy::prelude::{Color, GlobalTransform, InheritedVisibility};
use bevy::render::Extract;
use bevy::render::camera::{ExtractedCamera, TemporalJitter};
use bevy::render::renderer::{RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::view::{ExtractedView, Msaa, ResolvedCompositingSpace, ViewDepthStencilTexture, ViewTarget};
use pelt_core::FurStructure;
use pelt_core::light::{Environment, LightKind, LightSource, MAX_LIGHTS};
use pelt_core::sim::SimParams;
use pelt_core::texture::FurTextures;
use pelt_core::wet::WetParams;
use pelt_render::{
    FurAsset, FurDrawSettings, FurDriver, FurLook, FurRenderer, FurShading, FurTarget, FurView, KernelChoice, Light,
    LightDirection, ViewData,
};

use crate::convert::{to_pelt, to_pelt_mat4};
use crate::environment::FurEnvironments;
use crate::fur::{Fur, FurState};

/// The light Pelt shades fur with (Kajiya-Kay strands) when the scene has no
/// `DirectionalLight`, and the ambient where the render world has no Bevy ambient light. Pelt's
/// default follows the camera from the upper left.
///
/// With a directional light in the scene (the first one by entity, among the visible), the fur
/// takes its direction and its colour times `illuminance * exposure / pi`, the camera's exposure
/// (Bevy's `Exposure`) included: the brightness Bevy gives a white diffuse surface facing the
/// light, so fur and Bevy's materials agree. Every other visible light (point and spot lights,
/// more directional lights; up to 8 in all) reaches a coat shaded with the fur model
/// (`[shading] model = "fur"`), in the same units; Kajiya-Kay takes the first. Bevy's ambient light
/// (the camera's `AmbientLight`, else the `GlobalAmbientLight`) is the fur's too: colour times
/// brightness times exposure, the radiance a white diffuse surface shows under it in Bevy. A
/// camera's `EnvironmentMapLight` adds to it, as in Bevy: its diffuse map (a cube map in
/// `Rgba16Float`, `Rgba32Float` or `Rgb9e5Ufloat`) reduced to spherical harmonics once per image,
/// turned by its `rotation`, times its `intensity` and the exposure; the fur model takes it by
/// direction and colour, Kajiya-Kay its mean. The map's data must be on the CPU when it is read:
/// kept in the main world (`RenderAssetUsages::default()`, as Bevy's KTX2 maps are), or, for an
/// image kept for the render world only (Bevy's `EnvironmentMapLight::solid_color` and
/// `hemispherical_gradient`), used by a camera in the frame it is added or changed. A map that
/// cannot be read (handed over before, another format) is reported once and left out.
#[derive(Resource, Clone, Copy, Debug, Default, PartialEq)]
pub struct FurLight(pub Light);

/// The depth format of Bevy's 3D views.
pub(crate) const DEPTH_FORMAT: wgpu::TextureFormat = bevy::core_pipeline::core_3d::CORE_3D_DEPTH_FORMAT;

/// This frame's furs, copied out of the main world.
#[derive(Resource, Default)]
pub(crate) struct ExtractedFurs {
    furs: Vec<ExtractedFur>,
    light: Light,
    sun: Option<Sun>,
    /// The scene's other lights (point, spot, more directional), world space, before exposure.
    others: Vec<pelt_core::light::LightSource>,
    /// The main world's entity of each of the fur's lights, in the order the fur takes them:
    /// the sun (if any), then the others.
    light_entities: Vec<Entity>,
}

/// The scene's first directional light.
#[derive(Clone, Copy, Debug)]
struct Sun {
    /// Unit vector toward the light, world space.
    toward_light: glam::Vec3,
    /// Linear colour times illuminance (lux).
    colour_lux: glam::Vec3,
}

impl Sun {
    /// Pelt's light for a camera with `exposure` (Bevy's `Exposure::exposure()`).
    fn light(&self, exposure: f32, ambient: f32) -> Light {
        Light {
            direction: LightDirection::World(self.toward_light),
            colour: self.colour_lux * (exposure / std::f32::consts::PI),
            ambient,
        }
    }

    /// The sun as one of the fur model's lights (before exposure).
    fn source(&self) -> LightSource {
        LightSource::directional(self.toward_light, self.colour_lux, 1.0)
    }
}

/// Limits `pass` to the camera's viewport, if it has one.
pub(crate) fn set_camera_viewport(pass: &mut wgpu::RenderPass<'_>, camera: &ExtractedCamera) {
    if let Some(viewport) = &camera.viewport {
        let (position, size) = (viewport.physical_position.as_vec2(), viewport.physical_size.as_vec2());
        pass.set_viewport(position.x, position.y, size.x, size.y, viewport.depth.start, viewport.depth.end);
    }
}

/// A Bevy colour as linear RGB.
fn linear(colour: Color) -> glam::Vec3 {
    let c = colour.to_linear();
    glam::Vec3::new(c.red, c.green, c.blue)
}

pub(crate) struct ExtractedFur {
    pub(crate) entity: Entity,
    pub(crate) revision: u64,
    structure: Arc<FurStructure>,
    textures: Arc<FurTextures>,
    positions: Arc<Vec<glam::Vec3>>,
    normals: Arc<Vec<glam::Vec3>>,
    pub(crate) world_from_simulation: glam::Mat4,
    centre_world: glam::Vec3,
    /// About `centre_world`, the fur at its longest (views that cannot see it skip it).
    radius_world: f32,
    pub(crate) skin: bool,
    /// Drawn into Bevy's shadow maps (no `NotShadowCaster`).
    pub(crate) casts_shadows: bool,
    /// Shaded with Bevy's shadow maps (no `NotShadowReceiver`).
    receives_shadows: bool,
    wetness: Option<Arc<Vec<f32>>>,
    wet: WetParams,
    shading: FurShading,
    tint: glam::Vec3,
}

pub(crate) fn extract_furs(
    mut extracted: ResMut<ExtractedFurs>,
    light: Extract<Res<FurLight>>,
    furs: Extract<
        Query<(Entity, &Fur, &FurState, Option<&InheritedVisibility>, Has<NotShadowCaster>, Has<NotShadowReceiver>)>,
    >,
    suns: Extract<Query<(Entity, &DirectionalLight, &GlobalTransform, Option<&InheritedVisibility>)>>,
    bulbs: Extract<Query<(Entity, &PointLight, &GlobalTransform, Option<&InheritedVisibility>)>>,
    spots: Extract<Query<(Entity, &SpotLight, &GlobalTransform, Option<&InheritedVisibility>)>>,
) {
    extracted.light = light.0;
    let visible = |visibility: Option<&InheritedVisibility>| visibility.is_none_or(|v| v.get());
    let mut suns: Vec<_> = suns.iter().filter(|(.., v)| visible(*v)).collect();
    suns.sort_by_key(|(entity, ..)| *entity);
    let sun = |(_, sun, transform, _): &(Entity, &DirectionalLight, &GlobalTransform, _)| {
        // A directional light shines along its forward (-Z) axis.
        let toward_light = to_pelt(transform.back().as_vec3()).try_normalize()?;
        let colour_lux = linear(sun.color) * sun.illuminance;
        colour_lux.is_finite().then_some(Sun { toward_light, colour_lux })
    };
    extracted.sun = suns.first().and_then(sun);
    let mut others: Vec<(Entity, LightSource)> =
        suns.iter().skip(1).filter_map(|s| Some((s.0, sun(s)?.source()))).collect();
    // Bevy gives point and spot lights in lumens over the whole sphere (a spot is a point light
    // masked by its cone): candela = lumens / 4 pi.
    let candela = |lumens: f32| lumens / (4.0 * std::f32::consts::PI);
    let mut bulbs: Vec<_> = bulbs.iter().filter(|(.., v)| visible(*v)).collect();
    bulbs.sort_by_key(|(entity, ..)| *entity);
    for (entity, bulb, transform, _) in bulbs {
        others.push((
            entity,
            LightSource {
                kind: LightKind::Point,
                position: to_pelt(transform.translation()),
                direction: glam::Vec3::ZERO,
                intensity: linear(bulb.color) * candela(bulb.intensity),
                cos_inner: -1.0,
                cos_outer: -1.0,
                casts_shadows: false,
            },
        ));
    }
    let mut spots: Vec<_> = spots.iter().filter(|(.., v)| visible(*v)).collect();
    spots.sort_by_key(|(entity, ..)| *entity);
    for (entity, spot, transform, _) in spots {
        others.push((
            entity,
            LightSource {
                kind: LightKind::Spot,
                position: to_pelt(transform.translation()),
                direction: to_pelt(transform.forward().as_vec3()).normalize_or(glam::Vec3::NEG_Y),
                intensity: linear(spot.color) * candela(spot.intensity),
                // Bevy's angles are half angles.
                cos_inner: spot.inner_angle.cos(),
                cos_outer: spot.outer_angle.cos(),
                casts_shadows: false,
            },
        ));
    }
    others.retain(|(_, l)| l.intensity.is_finite() && l.position.is_finite() && l.direction.is_finite());
    others.truncate(MAX_LIGHTS - 1);
    let sun_entity = extracted.sun.and(suns.first().map(|(entity, ..)| *entity));
    extracted.light_entities = sun_entity.into_iter().chain(others.iter().map(|(entity, _)| *entity)).collect();
    extracted.others = others.into_iter().map(|(_, light)| light).collect();
    extracted.furs.clear();
    for (entity, fur, state, visibility, not_caster, not_receiver) in &furs {
        if visibility.is_some_and(|v| !v.get()) {
            continue;
        }
        extracted.furs.push(ExtractedFur {
            entity,
            revision: state.revision,
            structure: Arc::clone(&state.structure),
            textures: Arc::clone(&state.textures),
            positions: Arc::clone(&state.positions),
            normals: Arc::clone(&state.normals),
            world_from_simulation: state.world_from_simulation,
            centre_world: state.centre_world,
            radius_world: state.radius_world,
            skin: fur.skin,
            casts_shadows: !not_caster,
            receives_shadows: !not_receiver,
            wetness: state.wetness.clone(),
            wet: state.wet.clone(),
            shading: FurShading::from_params(&state.shading),
            tint: glam::Vec3::from_array(fur.tint.to_array()),
        });
    }
}

impl ExtractedFur {
    /// A sphere about the fur at its longest, world space.
    pub(crate) fn bounds(&self) -> (glam::Vec3, f32) {
        (self.centre_world, self.radius_world)
    }

    /// Its longest strand (model units).
    pub(crate) fn longest_strand(&self) -> f32 {
        self.structure.lengths.iter().copied().fold(0.0, f32::max)
    }
}

impl ExtractedFurs {
    pub(crate) fn furs(&self) -> &[ExtractedFur] {
        &self.furs
    }

    /// The index among the fur's lights of the light `entity` (main world), if it is one.
    pub(crate) fn light_index(&self, entity: Entity) -> Option<usize> {
        self.light_entities.iter().position(|&e| e == entity)
    }
}

/// A view's projection times view, as Bevy's shaders see it without the TAA jitter.
pub(crate) fn clip_from_world(view: &ExtractedView) -> glam::Mat4 {
    match view.clip_from_world {
        Some(clip_from_world) => to_pelt_mat4(&clip_from_world),
        None => to_pelt_mat4(&view.clip_from_view) * to_pelt_mat4(&view.world_from_view.to_matrix()).inverse(),
    }
}

/// The projection Bevy draws a camera's geometry with: jittered under TAA, so the fur's samples
/// move with the rest of the picture's.
fn jittered_clip_from_world(view: &ExtractedView, jitter: Option<&TemporalJitter>) -> glam::Mat4 {
    let Some(jitter) = jitter.filter(|_| view.clip_from_world.is_none()) else { return clip_from_world(view) };
    let mut clip_from_view = view.clip_from_view;
    jitter.jitter_projection(&mut clip_from_view, bevy::math::UVec2::new(view.viewport.z, view.viewport.w).as_vec2());
    to_pelt_mat4(&clip_from_view) * to_pelt_mat4(&view.world_from_view.to_matrix()).inverse()
}

impl ViewEntry {
    /// Whether any of `fur` can be in this view (a fur whose bounds are unknown is).
    pub(crate) fn sees(&self, fur: &ExtractedFur) -> bool {
        self.data.as_ref().is_none_or(|data| data.sees_sphere(fur.centre_world, fur.radius_world))
    }

    pub(crate) fn target(&self) -> FurTarget {
        self.target
    }

    pub(crate) fn fur_view(&self) -> &FurView {
        &self.view
    }

    pub(crate) fn fur_view_mut(&mut self) -> &mut FurView {
        &mut self.view
    }
}

/// Pelt's GPU objects on Bevy's device.
#[derive(Resource, Default)]
pub(crate) struct FurGpu {
    renderers: HashMap<FurTarget, FurRenderer>,
    failed_targets: HashSet<FurTarget>,
    /// One per fur and target description (a fur seen by cameras with different targets is
    /// uploaded once for each).
    furs: HashMap<(Entity, FurTarget), GpuFurEntry>,
    /// One per 3D view (render-world view entity).
    views: HashMap<Entity, ViewEntry>,
    failed_furs: HashSet<(Entity, u64)>,
    /// What the furs of one structure and textures share on the GPU, once per target: a
    /// hundred entities of one mesh and preset upload their topology and textures once.
    assets: HashMap<AssetKey, SharedAsset>,
}

/// A structure and its textures (by address: the main world shares one `Arc` among the furs
/// of one mesh and preset) and a target.
type AssetKey = (usize, usize, FurTarget);

struct SharedAsset {
    asset: FurAsset,
    /// Held so the addresses in the key stay theirs while the asset lives.
    _sources: (Arc<FurStructure>, Arc<FurTextures>),
}

/// How many furs the render world holds and draws, and how many GPU assets they share (the
/// furs of one mesh and preset share one), as of the last frame. A render-world resource.
#[derive(Resource, Debug, Default)]
pub struct FurGpuStats {
    /// Furs uploaded (one per fur and camera target description).
    pub furs: usize,
    /// Shared assets: topology, uvs, fin strip and textures, each uploaded once.
    pub assets: usize,
    /// Furs drawn into the cameras' main passes, summed over the cameras: a fur no camera can
    /// see (its bounds outside every view) is not drawn.
    pub drawn: std::sync::atomic::AtomicUsize,
}

struct GpuFurEntry {
    /// Draws the states the main world's `FurStepper` simulates (the CPU kernel).
    fur: FurDriver,
    revision: u64,
    /// The positions and model transform drawn this frame and the last (motion vectors).
    current: Option<(Arc<Vec<glam::Vec3>>, glam::Mat4)>,
    previous: Option<(Arc<Vec<glam::Vec3>>, glam::Mat4)>,
}

pub(crate) struct ViewEntry {
    target: FurTarget,
    view: FurView,
    /// Draw through an sRGB view of Bevy's `Rgba8Unorm` target, which holds sRGB-encoded colour
    /// (Bevy's default compositing space); Pelt's shaders output linear colour.
    srgb_view: bool,
    camera_position: glam::Vec3,
    /// What the view sees (without the TAA jitter), to skip the furs it cannot.
    data: Option<ViewData>,
}

/// The colour format Pelt's pipelines write for a view, and whether that is an sRGB view of a
/// non-sRGB target.
fn colour_format(target_format: wgpu::TextureFormat, space: Option<CompositingSpace>) -> (wgpu::TextureFormat, bool) {
    use wgpu::TextureFormat as F;
    match (target_format, space) {
        (F::Rgba8Unorm, Some(CompositingSpace::Srgb)) => (F::Rgba8UnormSrgb, true),
        (F::Bgra8Unorm, Some(CompositingSpace::Srgb)) => (F::Bgra8UnormSrgb, true),
        (format, _) => (format, false),
    }
}

impl FurGpu {
    pub(crate) fn view(&self, entity: Entity) -> Option<&ViewEntry> {
        self.views.get(&entity)
    }

    pub(crate) fn view_mut(&mut self, entity: Entity) -> Option<&mut ViewEntry> {
        self.views.get_mut(&entity)
    }

    /// The renderer of a target some view has.
    pub(crate) fn renderer(&self, target: FurTarget) -> &FurRenderer {
        &self.renderers[&target]
    }

    /// A target some view draws into, the same every frame while the views stay.
    pub(crate) fn first_target(&self) -> Option<FurTarget> {
        self.views.values().map(|view| view.target).min_by_key(|target| format!("{target:?}"))
    }

    pub(crate) fn fur(&self, entity: Entity, target: FurTarget) -> Option<&FurDriver> {
        self.furs.get(&(entity, target)).map(|entry| &entry.fur)
    }

    /// Last frame's positions and model transform of a fur (none on its first frame).
    pub(crate) fn previous(&self, entity: Entity, target: FurTarget) -> Option<(&[glam::Vec3], glam::Mat4)> {
        let (positions, transform) = self.furs.get(&(entity, target))?.previous.as_ref()?;
        Some((&positions[..], *transform))
    }
}

/// Pipelines per target, a view uniform per camera, and each fur's upload and transform.
pub(crate) fn prepare_furs(
    device: Res<RenderDevice>,
    queue: Res<RenderQueue>,
    extracted: Res<ExtractedFurs>,
    mut gpu: ResMut<FurGpu>,
    mut stats: ResMut<FurGpuStats>,
    views: Query<
        (
            Entity,
            &ExtractedView,
            &Msaa,
            Option<&ResolvedCompositingSpace>,
            Option<&ExtractedCamera>,
            Option<&TemporalJitter>,
            Option<&AmbientLight>,
        ),
        (With<ViewTarget>, With<Camera3d>),
    >,
    global_ambient: Option<Res<GlobalAmbientLight>>,
    environments: Res<FurEnvironments>,
) {
    let device = device.wgpu_device();
    let queue: &wgpu::Queue = &queue;
    let gpu = &mut *gpu;
    let mut seen_views = HashSet::new();
    let mut targets = HashSet::new();
    for (entity, view, msaa, space, camera, jitter, camera_ambient) in &views {
        let (colour, srgb_view) = colour_format(view.target_format, ResolvedCompositingSpace::space(space));
        let target = FurTarget::new(colour)
            .with_depth(DEPTH_FORMAT, wgpu::CompareFunction::GreaterEqual)
            .with_sample_count(msaa.samples());
        if !gpu.renderers.contains_key(&target) {
            if gpu.failed_targets.contains(&target) {
                continue;
            }
            match FurRenderer::new(device, target) {
                Ok(renderer) => {
                    gpu.renderers.insert(target, renderer);
                }
                Err(problem) => {
                    error!("Pelt cannot draw fur into {target:?}: {problem}");
                    gpu.failed_targets.insert(target);
                    continue;
                }
            }
        }
        let renderer = &gpu.renderers[&target];
        let entry = match gpu.views.get_mut(&entity) {
            Some(entry) if entry.target == target => entry,
            _ => {
                let view = FurView::new(device, renderer);
                let camera_position = glam::Vec3::ZERO;
                gpu.views.insert(entity, ViewEntry { target, view, srgb_view, camera_position, data: None });
                gpu.views.get_mut(&entity).expect("just inserted")
            }
        };
        entry.srgb_view = srgb_view;
        let world_from_view = to_pelt_mat4(&view.world_from_view.to_matrix());
        let clip_from_world = jittered_clip_from_world(view, jitter);
        entry.camera_position = world_from_view.w_axis.truncate();
        let exposure = camera.map_or_else(|| Exposure::default().exposure(), |camera| camera.exposure);
        // Bevy's ambient as a radiance (before exposure, like the lights), else `FurLight`'s.
        let bevy_ambient = camera_ambient
            .map(|a| (a.color, a.brightness))
            .or_else(|| global_ambient.as_deref().map(|a| (a.color, a.brightness)))
            .map(|(colour, brightness)| linear(colour) * brightness)
            .filter(|radiance| radiance.is_finite());
        let ambient = bevy_ambient.map_or(glam::Vec3::splat(extracted.light.ambient), |radiance| radiance * exposure);
        // Bevy adds the camera's environment map light to its ambient light.
        let environment_map = environments.camera(entity).map(|map| map.sh.scaled(exposure));
        let environment = match environment_map {
            Some(map) => {
                let uniform = Environment::uniform(ambient).sh;
                let mut sh = map;
                sh.coefficients.iter_mut().zip(uniform.coefficients).for_each(|(c, u)| *c += u);
                Environment { sh }
            }
            None => Environment::uniform(ambient),
        };
        // Kajiya-Kay's ambient is one level: the environment's mean radiance's luminance.
        let ambient_level = environment.sh.mean().dot(glam::Vec3::new(0.2126, 0.7152, 0.0722));
        let light = extracted
            .sun
            .map_or(Light { ambient: ambient_level, ..extracted.light }, |sun| sun.light(exposure, ambient_level));
        let mut data = ViewData::new(clip_from_world, world_from_view, &light);
        // The fur model sums the lights it is given; Kajiya-Kay alone needs only the key light
        // and the ambient level.
        if !extracted.others.is_empty() || extracted.furs.iter().any(|f| f.shading.fur_model) {
            // The sun (if any) first: Kajiya-Kay keeps it as its key light.
            let sun = extracted.sun.as_ref().map(Sun::source);
            let lights: Vec<LightSource> = sun
                .into_iter()
                .chain(extracted.others.iter().copied())
                .map(|l| LightSource { intensity: l.intensity * exposure, ..l })
                .collect();
            data = data.with_lights(&lights, Some(environment));
        }
        entry.view.prepare(queue, &data);
        entry.data = Some(ViewData::new(self::clip_from_world(view), world_from_view, &light));
        seen_views.insert(entity);
        targets.insert(target);
    }
    gpu.views.retain(|entity, _| seen_views.contains(entity));

    let mut seen_furs = HashSet::new();
    let mut seen_assets = HashSet::new();
    for fur in &extracted.furs {
        if gpu.failed_furs.contains(&(fur.entity, fur.revision)) {
            continue;
        }
        for &target in &targets {
            let key = (fur.entity, target);
            let renderer = &gpu.renderers[&target];
            let asset_key = (Arc::as_ptr(&fur.structure) as usize, Arc::as_ptr(&fur.textures) as usize, target);
            seen_assets.insert(asset_key);
            let stale = gpu.furs.get(&key).is_none_or(|entry| entry.revision != fur.revision);
            if stale {
                let params = SimParams::default();
                let asset = match gpu.assets.get(&asset_key) {
                    Some(shared) => Ok(shared.asset.clone()),
                    None => FurAsset::new(device, queue, renderer, &fur.structure, &fur.textures).inspect(|asset| {
                        let sources = (Arc::clone(&fur.structure), Arc::clone(&fur.textures));
                        gpu.assets.insert(asset_key, SharedAsset { asset: asset.clone(), _sources: sources });
                    }),
                };
                let renderer = &gpu.renderers[&target];
                let driver = asset.and_then(|asset| {
                    FurDriver::with_asset(device, queue, renderer, &asset, &fur.structure, &params, KernelChoice::Cpu)
                });
                match driver {
                    Ok(gpu_fur) => {
                        gpu.furs.insert(
                            key,
                            GpuFurEntry { fur: gpu_fur, revision: fur.revision, current: None, previous: None },
                        );
                    }
                    Err(problem) => {
                        error!("Pelt cannot upload the fur of {}: {problem}", fur.entity);
                        gpu.failed_furs.insert((fur.entity, fur.revision));
                        gpu.furs.remove(&key);
                        continue;
                    }
                }
            }
            let Some(entry) = gpu.furs.get_mut(&key) else { continue };
            entry.fur.set_world_from_model(fur.world_from_simulation);
            entry.fur.set_look(FurLook { shading: fur.shading, tint: fur.tint, ..FurLook::default() });
            if let Err(problem) = entry.fur.show_wet(queue, fur.wetness.as_deref().map(Vec::as_slice), &fur.wet) {
                error!("Pelt cannot show the wetness of {}: {problem}", fur.entity);
            }
            // Before the first simulated frame the normals are the rest ones the fur starts with.
            let normals = (!fur.normals.is_empty()).then_some(&fur.normals[..]);
            if let Err(problem) = entry.fur.show_state(queue, &fur.positions, normals) {
                error!("Pelt cannot update the fur of {}: {problem}", fur.entity);
                continue;
            }
            let now = (Arc::clone(&fur.positions), fur.world_from_simulation);
            entry.previous = entry.current.replace(now);
            seen_furs.insert(key);
        }
    }
    gpu.furs.retain(|key, _| seen_furs.contains(key));
    gpu.assets.retain(|key, _| seen_assets.contains(key));
    *stats = FurGpuStats { furs: gpu.furs.len(), assets: gpu.assets.len(), drawn: 0.into() };
}

/// Draws every fur into one 3D view's main pass: the view's colour target (through an sRGB view
/// where Bevy stores sRGB) and its depth buffer, so fur and Bevy's geometry occlude each other.
pub(crate) fn draw_furs(
    view: ViewQuery<(&ExtractedCamera, &ViewTarget, &ViewDepthStencilTexture)>,
    gpu: Res<FurGpu>,
    extracted: Res<ExtractedFurs>,
    stats: Res<FurGpuStats>,
    mut ctx: RenderContext,
) {
    let view_entity = view.entity();
    let (camera, target, depth) = view.into_inner();
    let Some(entry) = gpu.views.get(&view_entity) else { return };
    let Some(renderer) = gpu.renderers.get(&entry.target) else { return };
    // Farthest first: shells and fins blend over what is behind them.
    let mut furs: Vec<(&ExtractedFur, &FurDriver)> = extracted
        .furs
        .iter()
        .filter(|fur| entry.sees(fur))
        .filter_map(|fur| gpu.furs.get(&(fur.entity, entry.target)).map(|e| (fur, &e.fur)))
        .collect();
    stats.drawn.fetch_add(furs.len(), std::sync::atomic::Ordering::Relaxed);
    if furs.is_empty() {
        return;
    }
    furs.sort_by(|a, b| {
        let distance = |fur: &ExtractedFur| fur.centre_world.distance_squared(entry.camera_position);
        distance(b.0).total_cmp(&distance(a.0))
    });

    let format = entry.srgb_view.then_some(entry.target.colour_format);
    let view_of = |texture: &wgpu::Texture| {
        texture.create_view(&wgpu::TextureViewDescriptor { format, ..wgpu::TextureViewDescriptor::default() })
    };
    let main = view_of(target.main_texture());
    let multisampled = target.sampled_main_texture().map(|texture| view_of(texture));
    let (colour_view, resolve_target) = match &multisampled {
        Some(multisampled) => (multisampled, Some(&main)),
        None => (&main, None),
    };
    let colour = wgpu::RenderPassColorAttachment {
        view: colour_view,
        depth_slice: None,
        resolve_target,
        ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
    };
    let mut pass = ctx.command_encoder().begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("pelt fur"),
        color_attachments: &[Some(colour)],
        depth_stencil_attachment: Some(depth.get_attachment(wgpu::StoreOp::Store)),
        timestamp_writes: None,
        occlusion_query_set: None,
        multiview_mask: None,
    });
    set_camera_viewport(&mut pass, camera);
    let unshadowed = entry.view.unshadowed();
    for (fur, driver) in furs {
        let settings = FurDrawSettings { skin: fur.skin, ..FurDrawSettings::ALL };
        let view = if fur.receives_shadows { &entry.view } else { &unshadowed };
        driver.draw(&mut pass, renderer, view, &settings);
    }
}
