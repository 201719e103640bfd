//! The main world: the [`Fur`] component, building a fur from its mesh and preset, and the
//! simulation systems (gravity, [`FurWind`], [`FurTouch`], following the entity's transform with
//! inertia).
//!
//! pelt-core simulates in the mesh's own (model) space; the world's gravity, wind, touch ray and
//! the entity's acceleration are turned into model space each frame, and the renderer draws the
//! result through the entity's `GlobalTransform`.

use std::collections::HashSet;
use std::sync::Arc;

use bevy::asset::{AssetEvent, AssetId, Assets, Handle};
use bevy::ecs::prelude::*;
use bevy::log::error;
use bevy::math::{Affine3A, Vec3};
use bevy::mesh::{Mesh, Mesh3d};
use bevy::prelude::{GlobalTransform, Name, Time};
use bevy::shape::Ray3d;
use pelt_core::sim::WindParams;
use pelt_core::texture::FurTextures;
use pelt_core::{FurStructure, Simulation};

use crate::convert::{to_pelt, to_pelt_affine};
use crate::mesh::pelt_mesh;
use crate::preset::FurPreset;

/// Grows fur on this entity's [`Mesh3d`] from a [`FurPreset`].
///
/// The fur is built when both the mesh and the preset have loaded, and rebuilt when either
/// changes (a preset file edited on disk reloads with Bevy's `file_watcher` feature).
#[derive(Component, Clone, Debug)]
#[require(GlobalTransform)]
pub struct Fur {
    /// The preset to grow.
    pub preset: Handle<FurPreset>,
    /// Draw Pelt's opaque skin (layer 0, coloured like the roots) under the fur. Turn it off when
    /// the entity's own material draws the surface.
    pub skin: bool,
}

impl Fur {
    /// Fur from `preset`, with Pelt's skin under it.
    #[must_use]
    pub fn new(preset: Handle<FurPreset>) -> Self {
        Self { preset, skin: true }
    }

    /// The same fur over the entity's own material (no Pelt skin).
    #[must_use]
    pub fn without_skin(self) -> Self {
        Self { skin: false, ..self }
    }
}

/// The wind every fur feels, in world space (it replaces the presets' own `[simulation.wind]`).
#[derive(Resource, Clone, Debug, PartialEq)]
pub struct FurWind {
    /// Where the wind blows to (world space; any non-zero vector).
    pub direction: Vec3,
    /// Force of the wind in units of gravity strength; 0 is calm.
    pub strength: f32,
    /// How much gusts vary the strength (`0..=1`).
    pub gust_strength: f32,
}

impl Default for FurWind {
    fn default() -> Self {
        Self { direction: Vec3::X, strength: 0.0, gust_strength: 0.5 }
    }
}

/// Touching fur with a ray (e.g. from the cursor through the camera, or from a picking hit).
///
/// While `ray` is `Some`, the first frame picks the nearest furred base surface along it and
/// starts a touch there; later frames drag the touch along the ray at the same distance. Setting
/// `ray` back to `None` releases the fur, which springs back.
#[derive(Resource, Clone, Debug)]
pub struct FurTouch {
    /// The ray in world space, or `None` for no touch.
    pub ray: Option<Ray3d>,
    /// Radius of the touched area, as a fraction of the touched fur's bounding radius.
    pub radius: f32,
    active: Option<ActiveTouch>,
}

#[derive(Clone, Copy, Debug)]
struct ActiveTouch {
    entity: Entity,
    distance: f32,
}

impl Default for FurTouch {
    fn default() -> Self {
        Self { ray: None, radius: 0.3, active: None }
    }
}

impl FurTouch {
    /// The entity whose fur is being touched.
    #[must_use]
    pub fn touched(&self) -> Option<Entity> {
        self.active.map(|a| a.entity)
    }
}

/// A built fur: its structure, textures and simulation (added by [`crate::PeltPlugin`] next to
/// [`Fur`] once the mesh and preset have loaded).
#[derive(Component, Debug)]
pub struct FurState {
    pub(crate) structure: Arc<FurStructure>,
    pub(crate) textures: Arc<FurTextures>,
    simulation: Simulation,
    /// Changes whenever the structure or textures do, so the render world re-uploads.
    pub(crate) revision: u64,
    preset: AssetId<FurPreset>,
    mesh: AssetId<Mesh>,
    /// The positions to draw this frame (model space, layer-major).
    pub(crate) positions: Arc<Vec<glam::Vec3>>,
    motion: Option<Motion>,
    radius: f32,
}

/// Where the entity was, for its acceleration.
#[derive(Clone, Copy, Debug)]
struct Motion {
    translation: Vec3,
    velocity: Vec3,
    time_secs: f64,
}

impl FurState {
    /// The simulation (its parameters, touch, positions).
    #[must_use]
    pub fn simulation(&self) -> &Simulation {
        &self.simulation
    }

    /// The unified shell-and-fin structure at rest.
    #[must_use]
    pub fn structure(&self) -> &FurStructure {
        &self.structure
    }
}

/// Standard gravity: the entity's acceleration is felt in units of it.
const STANDARD_GRAVITY: f32 = 9.81;
/// Inertial forces are capped (units of gravity strength) so a teleport is a jolt, not a blow-up.
const MAX_INERTIA: f32 = 4.0;

/// Builds (or rebuilds) the fur of every [`Fur`] entity whose mesh and preset are loaded and new
/// or changed. Failures are logged once per change, naming the entity, and leave the entity bare.
pub(crate) fn build_furs(
    mut commands: Commands,
    mut preset_events: MessageReader<AssetEvent<FurPreset>>,
    mut mesh_events: MessageReader<AssetEvent<Mesh>>,
    presets: Res<Assets<FurPreset>>,
    meshes: Res<Assets<Mesh>>,
    furs: Query<(Entity, &Fur, &Mesh3d, Option<&FurState>, Option<&Name>)>,
    mut failed: Local<HashSet<(Entity, AssetId<FurPreset>, AssetId<Mesh>)>>,
    mut next_revision: Local<u64>,
) {
    let changed_presets: HashSet<AssetId<FurPreset>> = preset_events.read().filter_map(changed_id).collect();
    let changed_meshes: HashSet<AssetId<Mesh>> = mesh_events.read().filter_map(changed_id).collect();
    failed.retain(|(_, preset, mesh)| !changed_presets.contains(preset) && !changed_meshes.contains(mesh));
    for (entity, fur, mesh3d, state, name) in &furs {
        let (preset_id, mesh_id) = (fur.preset.id(), mesh3d.id());
        let stale = match state {
            None => true,
            Some(state) => {
                state.preset != preset_id
                    || state.mesh != mesh_id
                    || changed_presets.contains(&preset_id)
                    || changed_meshes.contains(&mesh_id)
            }
        };
        if !stale || failed.contains(&(entity, preset_id, mesh_id)) {
            continue;
        }
        let (Some(preset), Some(mesh)) = (presets.get(preset_id), meshes.get(mesh_id)) else { continue };
        let label = name.map_or_else(|| format!("entity {entity}"), |n| format!("{n} ({entity})"));
        *next_revision += 1;
        match build(&label, preset, mesh, preset_id, mesh_id, *next_revision) {
            Ok(state) => {
                commands.entity(entity).insert(state);
            }
            Err(problem) => {
                error!("cannot grow fur on {label}: {problem}");
                failed.insert((entity, preset_id, mesh_id));
            }
        }
    }
}

fn changed_id<A: bevy::asset::Asset>(event: &AssetEvent<A>) -> Option<AssetId<A>> {
    match event {
        AssetEvent::Modified { id } | AssetEvent::LoadedWithDependencies { id } | AssetEvent::Added { id } => Some(*id),
        _ => None,
    }
}

fn build(
    label: &str,
    preset: &FurPreset,
    mesh: &Mesh,
    preset_id: AssetId<FurPreset>,
    mesh_id: AssetId<Mesh>,
    revision: u64,
) -> Result<FurState, String> {
    let mesh = pelt_mesh(mesh, label).map_err(|e| e.to_string())?;
    let params = preset.preset.fur_params(&mesh);
    let radius = mesh.bounding_sphere().1;
    let structure = FurStructure::new(mesh, &params).map_err(|e| format!("{}: {e}", preset.preset.file().display()))?;
    let simulation = Simulation::new(&structure, &preset.preset.simulation)
        .map_err(|e| format!("{}: {e}", preset.preset.file().display()))?;
    let positions = Arc::new(simulation.positions().to_vec());
    Ok(FurState {
        structure: Arc::new(structure),
        textures: Arc::clone(&preset.textures),
        simulation,
        revision,
        preset: preset_id,
        mesh: mesh_id,
        positions,
        motion: None,
        radius,
    })
}

/// Steps every fur to the current time: gravity and wind turned into the fur's model space, the
/// entity's acceleration as an inertial force, and the touch ray.
pub(crate) fn simulate_furs(
    time: Res<Time>,
    wind: Res<FurWind>,
    presets: Res<Assets<FurPreset>>,
    mut touch: ResMut<FurTouch>,
    mut furs: Query<(Entity, &Fur, &GlobalTransform, &mut FurState)>,
) {
    let now = time.elapsed_secs_f64();
    update_touch(&mut touch, &mut furs);
    for (entity, fur, transform, mut state) in &mut furs {
        let state = &mut *state;
        let world_from_model = transform.affine();
        let model_from_world = world_from_model.inverse();
        let to_model = |v: Vec3| to_pelt(model_from_world.transform_vector3(v));
        let mut params = state.simulation.params().clone();
        // The preset's gravity direction is the world's (Bevy's +Y is up); the simulation needs
        // it in the mesh's space, which turns with the entity.
        if let Some(preset) = presets.get(fur.preset.id()) {
            let gravity = bevy::math::Vec3::from_array(preset.preset.simulation.gravity_direction.to_array());
            params.gravity_direction = to_model(gravity).normalize_or(glam::Vec3::NEG_Y);
        }
        params.wind = WindParams {
            direction: to_model(wind.direction).normalize_or(glam::Vec3::X),
            strength: wind.strength,
            gust_strength: wind.gust_strength,
            ..params.wind
        };
        if let Err(problem) = state.simulation.set_params(&params) {
            error!("fur on {entity}: {problem}");
        }
        let inertia = inertial_force(&mut state.motion, transform.translation(), now, params.gravity_strength);
        state.simulation.field_mut().fill(to_model(inertia));
        state.simulation.advance_to(now);
        state.positions = Arc::new(state.simulation.positions().to_vec());
    }
}

/// The force the fur feels from the entity's acceleration (world space, units of gravity
/// strength): `-a / g`, capped.
fn inertial_force(motion: &mut Option<Motion>, translation: Vec3, now: f64, gravity_strength: f32) -> Vec3 {
    let Some(last) = *motion else {
        *motion = Some(Motion { translation, velocity: Vec3::ZERO, time_secs: now });
        return Vec3::ZERO;
    };
    let dt = (now - last.time_secs) as f32;
    if dt <= 1e-5 {
        return Vec3::ZERO;
    }
    let velocity = (translation - last.translation) / dt;
    let acceleration = (velocity - last.velocity) / dt;
    *motion = Some(Motion { translation, velocity, time_secs: now });
    (-acceleration / STANDARD_GRAVITY * gravity_strength).clamp_length_max(MAX_INERTIA * gravity_strength.max(0.0))
}

fn update_touch(touch: &mut FurTouch, furs: &mut Query<(Entity, &Fur, &GlobalTransform, &mut FurState)>) {
    let radius_fraction = touch.radius;
    match (touch.ray, touch.active) {
        (None, None) => {}
        (None, Some(active)) => {
            if let Ok((_, _, _, mut state)) = furs.get_mut(active.entity) {
                state.simulation.touch_end();
            }
            touch.active = None;
        }
        (Some(ray), Some(active)) => {
            let point = ray.get_point(active.distance);
            if let Ok((_, _, transform, mut state)) = furs.get_mut(active.entity) {
                let model = to_pelt_affine(&transform.affine()).inverse().transform_point3(to_pelt(point));
                if let Err(problem) = state.simulation.touch_drag(model) {
                    error!("fur touch: {problem}");
                }
            } else {
                touch.active = None;
            }
        }
        (Some(ray), None) => {
            let nearest = furs
                .iter()
                .filter_map(|(entity, _, transform, state)| {
                    let world_from_model = transform.affine();
                    let hit = pick(state, &world_from_model, &ray)?;
                    Some((entity, hit))
                })
                .min_by(|a, b| a.1.1.total_cmp(&b.1.1));
            if let Some((entity, (model_point, distance))) = nearest
                && let Ok((_, _, _, mut state)) = furs.get_mut(entity)
            {
                let radius = (radius_fraction * state.radius).max(1e-6);
                match state.simulation.touch_begin(model_point, radius) {
                    Ok(()) => touch.active = Some(ActiveTouch { entity, distance }),
                    Err(problem) => error!("fur touch: {problem}"),
                }
            }
        }
    }
}

/// The model-space hit of a world ray with the fur's base surface and its world distance.
fn pick(state: &FurState, world_from_model: &Affine3A, ray: &Ray3d) -> Option<(glam::Vec3, f32)> {
    let model_from_world = to_pelt_affine(world_from_model).inverse();
    let origin = model_from_world.transform_point3(to_pelt(ray.origin));
    let direction = model_from_world.transform_vector3(to_pelt(*ray.direction));
    let hit = state.simulation.pick(&state.structure.mesh.triangles, origin, direction)?;
    let world_point = world_from_model.transform_point3(bevy::math::Vec3::from_array(hit.point.to_array()));
    Some((hit.point, world_point.distance(ray.origin)))
}
