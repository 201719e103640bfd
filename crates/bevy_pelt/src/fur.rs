//! The main world: the [`Fur`] component, building a fur from its mesh and preset (groomed by
//! its `[groom]` table), and the simulation systems (gravity, [`FurWind`], [`FurTouch`], the
//! base following the entity's transform or Bevy's skeleton, with pelt-core's inertia; the
//! colliders, grasps and sponges of [`crate::contact`] and [`crate::wet`]).
//!
//! pelt-core simulates the base where it is in the world (divided by one uniform scale, see
//! [`crate::base`]), so the roots' acceleration is the body's and pelt-core's `Inertia` makes the
//! fur lag, swing and settle; gravity, wind and the touch ray keep their world directions.

use std::collections::{HashMap, HashSet};
use std::sync::Arc;

use bevy::asset::{AssetEvent, AssetId, Assets, Handle};
use bevy::ecs::prelude::*;
use bevy::log::error;
use bevy::math::Vec3;
use bevy::mesh::skinning::{SkinnedMesh, SkinnedMeshInverseBindposes};
use bevy::mesh::{Mesh, Mesh3d};
use bevy::prelude::{GlobalTransform, Name, Time};
use bevy::shape::Ray3d;
use pelt_core::anim::Skin;
use pelt_core::sim::{FurStepper, WindParams};
use pelt_core::texture::FurTextures;
use pelt_core::wet::WetParams;
use pelt_core::{FurStructure, Simulation};

use crate::base::Base;
use crate::contact::{FurCollider, FurGrasp, Grasps, apply_colliders, apply_grasp};
use crate::convert::{to_pelt, to_pelt_affine, to_pelt_mat4};
use crate::mesh::{pelt_mesh, pelt_skin};
use crate::preset::FurPreset;
use crate::wet::{FurSponge, apply_sponges};

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
    /// Multiplies this entity's coat colour (linear RGB; white keeps the preset's): one animal of
    /// a herd in its own colour, its structure and textures still shared.
    pub tint: Vec3,
}

impl Fur {
    /// Fur from `preset`, with Pelt's skin under it.
    #[must_use]
    pub fn new(preset: Handle<FurPreset>) -> Self {
        Self { preset, skin: true, tint: Vec3::ONE }
    }

    /// The same fur with its colour multiplied by `tint`.
    #[must_use]
    pub fn with_tint(self, tint: Vec3) -> Self {
        Self { tint, ..self }
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
    /// The simulation, its base posed from the entity's transform or skeleton each frame.
    stepper: FurStepper,
    /// Changes whenever the structure or textures do, so the render world re-uploads.
    pub(crate) revision: u64,
    preset: AssetId<FurPreset>,
    mesh: AssetId<Mesh>,
    /// The positions to draw this frame (simulation space, layer-major).
    pub(crate) positions: Arc<Vec<glam::Vec3>>,
    /// The base's normals this frame (world directions), for lighting.
    pub(crate) normals: Arc<Vec<glam::Vec3>>,
    /// Simulation space to world space (a uniform scale; see [`crate::base`]).
    pub(crate) world_from_simulation: glam::Mat4,
    /// The base's bounding-box centre in world space, to draw far furs first.
    pub(crate) centre_world: glam::Vec3,
    /// A world radius about `centre_world` holding the fur at its longest, so views that cannot
    /// see it skip it.
    pub(crate) radius_world: f32,
    /// The skin when the entity has a `SkinnedMesh`: the base follows Bevy's joints.
    skin: Option<Skin>,
    base: Base,
    radius: f32,
    /// The [`FurGrasp`] entity this fur follows.
    holding: Option<Entity>,
    /// The wetness per base vertex this frame, `None` while dry.
    pub(crate) wetness: Option<Arc<Vec<f32>>>,
    /// The preset's `[wet]`: what wetness does to the look.
    pub(crate) wet: WetParams,
    /// The preset's `[shading]`: Kajiya-Kay or the fur model.
    pub(crate) shading: pelt_core::preset::ShadingParams,
}

impl FurState {
    /// The simulation (its parameters, touch, positions).
    #[must_use]
    pub fn simulation(&self) -> &Simulation {
        self.stepper.simulation()
    }

    /// Takes the simulation's positions to world space: the simulation runs where the fur is in
    /// the world, divided by one uniform scale (the entity's or its skeleton's), so strands keep
    /// their length relative to the body.
    #[must_use]
    pub fn world_from_simulation(&self) -> glam::Mat4 {
        self.world_from_simulation
    }

    /// Whether this fur and `other` share one grown structure (and so one GPU asset): furs of
    /// one mesh, preset and skeleton do, however many there are.
    #[must_use]
    pub fn shares_structure_with(&self, other: &FurState) -> bool {
        Arc::ptr_eq(&self.structure, &other.structure)
    }

    /// The unified shell-and-fin structure at rest (its `groom`, when the preset has one).
    #[must_use]
    pub fn structure(&self) -> &FurStructure {
        &self.structure
    }

    /// Each base vertex's wetness in `0..=1`, as the last step left it.
    #[must_use]
    pub fn wetness(&self) -> &[f32] {
        self.stepper.wetness().values()
    }
}

/// Builds (or rebuilds) the fur of every [`Fur`] entity whose mesh and preset are loaded and new
/// or changed. Failures are logged once per change, naming the entity, and leave the entity bare.
pub(crate) fn build_furs(
    mut commands: Commands,
    mut preset_events: MessageReader<AssetEvent<FurPreset>>,
    mut mesh_events: MessageReader<AssetEvent<Mesh>>,
    presets: Res<Assets<FurPreset>>,
    meshes: Res<Assets<Mesh>>,
    furs: Query<(Entity, &Fur, &Mesh3d, Option<&SkinnedMesh>, Option<&FurState>, Option<&Name>)>,
    mut failed: Local<HashSet<(Entity, AssetId<FurPreset>, AssetId<Mesh>)>>,
    mut next_revision: Local<u64>,
    mut built: Local<SharedStructures>,
) {
    let changed_presets: HashSet<AssetId<FurPreset>> = preset_events.read().filter_map(changed_id).collect();
    let changed_meshes: HashSet<AssetId<Mesh>> = mesh_events.read().filter_map(changed_id).collect();
    failed.retain(|(_, preset, mesh)| !changed_presets.contains(preset) && !changed_meshes.contains(mesh));
    // A changed mesh or preset grows anew; what no fur holds any more is let go.
    built.0.retain(|(preset, mesh, _), (structure, _)| {
        !changed_presets.contains(preset) && !changed_meshes.contains(mesh) && structure.strong_count() > 0
    });
    for (entity, fur, mesh3d, skinned, state, name) in &furs {
        let (preset_id, mesh_id) = (fur.preset.id(), mesh3d.id());
        let stale = match state {
            None => true,
            Some(state) => {
                state.preset != preset_id
                    || state.mesh != mesh_id
                    || state.skin.as_ref().map(Skin::joint_count) != skinned.map(|s| s.joints.len())
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
        let joint_count = skinned.map(|s| s.joints.len());
        let key = (preset_id, mesh_id, joint_count);
        let shared = built.0.get(&key).and_then(|(structure, skin)| Some((structure.upgrade()?, skin.clone())));
        match build(&label, preset, (mesh, shared), joint_count, (preset_id, mesh_id), *next_revision) {
            Ok(state) => {
                built.0.insert(key, (Arc::downgrade(&state.structure), state.skin.clone()));
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

/// Structures already grown, by preset, mesh and joint count, with their skins: the entities of
/// one mesh and preset (a herd) share one structure, and the render world one GPU asset.
#[derive(Default)]
pub(crate) struct SharedStructures(HashMap<SharedKey, (std::sync::Weak<FurStructure>, Option<Skin>)>);

type SharedKey = (AssetId<FurPreset>, AssetId<Mesh>, Option<usize>);

fn build(
    label: &str,
    preset: &FurPreset,
    (bevy_mesh, shared): (&Mesh, Option<(Arc<FurStructure>, Option<Skin>)>),
    joint_count: Option<usize>,
    (preset_id, mesh_id): (AssetId<FurPreset>, AssetId<Mesh>),
    revision: u64,
) -> Result<FurState, String> {
    let (structure, skin) = match shared {
        Some(shared) => shared,
        None => grow(label, preset, bevy_mesh, joint_count)?,
    };
    let radius = structure.mesh.bounding_sphere().1;
    let file = preset.preset.file().display();
    let mut stepper = FurStepper::new(&structure, &preset.preset.simulation).map_err(|e| format!("{file}: {e}"))?;
    stepper.set_wet(&preset.preset.wet).map_err(|e| format!("{file}: {e}"))?;
    let positions = Arc::new(stepper.simulation().positions().to_vec());
    Ok(FurState {
        structure,
        textures: Arc::clone(&preset.textures),
        stepper,
        revision,
        preset: preset_id,
        mesh: mesh_id,
        positions,
        normals: Arc::new(Vec::new()),
        world_from_simulation: glam::Mat4::IDENTITY,
        centre_world: glam::Vec3::ZERO,
        radius_world: f32::INFINITY,
        skin,
        base: Base::default(),
        radius,
        holding: None,
        wetness: None,
        wet: preset.preset.wet.clone(),
        shading: preset.preset.shading.clone(),
    })
}

/// Grows the fur of `preset` on `bevy_mesh` (skinned by `joint_count` joints).
fn grow(
    label: &str,
    preset: &FurPreset,
    bevy_mesh: &Mesh,
    joint_count: Option<usize>,
) -> Result<(Arc<FurStructure>, Option<Skin>), String> {
    let (mesh, source) = pelt_mesh(bevy_mesh, label).map_err(|e| e.to_string())?;
    let skin = joint_count.map(|joints| pelt_skin(bevy_mesh, &source, joints)).transpose()?;
    if let Some(skin) = &skin {
        for line in skin.report() {
            bevy::log::warn!("{label}: {line}");
        }
    }
    let params = preset.preset.fur_params(&mesh);
    let groom = preset.groom(&mesh, label).map_err(|e| e.to_string())?;
    let file = preset.preset.file().display();
    let structure = FurStructure::new_groomed(mesh, &params, groom).map_err(|e| format!("{file}: {e}"))?;
    Ok((Arc::new(structure), skin))
}

/// Steps every fur to the current time: the base posed from the entity's transform or Bevy's
/// joints, the preset's gravity and the [`FurWind`] in world directions, and the touch ray.
pub(crate) fn simulate_furs(
    time: Res<Time>,
    wind: Res<FurWind>,
    presets: Res<Assets<FurPreset>>,
    bindposes: Res<Assets<SkinnedMeshInverseBindposes>>,
    joints: Query<&GlobalTransform>,
    colliders: Query<(Entity, &FurCollider, &GlobalTransform)>,
    grasps: Query<(Entity, &FurGrasp, &GlobalTransform)>,
    sponges: Query<(&FurSponge, &GlobalTransform)>,
    mut touch: ResMut<FurTouch>,
    mut furs: FurQuery,
) {
    let now = time.elapsed_secs_f64();
    update_touch(&mut touch, &mut furs);
    let mut colliders: Vec<(Entity, FurCollider, GlobalTransform)> =
        colliders.iter().map(|(entity, collider, transform)| (entity, collider.clone(), *transform)).collect();
    colliders.sort_by_key(|(entity, ..)| *entity);
    let mut grasps: Grasps =
        grasps.iter().map(|(entity, grasp, transform)| (entity, *grasp, transform.translation())).collect();
    grasps.sort_by_key(|(entity, ..)| *entity);
    let sponges: Vec<_> = sponges.iter().map(|(sponge, transform)| (transform.translation(), *sponge)).collect();
    let mut joint_matrices = Vec::new();
    for (entity, fur, transform, skinned, mut state) in &mut furs {
        let state = &mut *state;
        match pose_base(state, transform, skinned, &bindposes, &joints, &mut joint_matrices) {
            Ok(true) => {}
            Ok(false) => continue,
            Err(problem) => {
                error!("fur on {entity}: {problem}");
                continue;
            }
        }
        let base = &state.base;
        // The first pose restarts the simulation there, at rest, rather than swinging in from
        // the rest pose.
        if let Err(problem) = state.stepper.set_pose(&base.positions, &base.normals, &base.rotations) {
            error!("fur on {entity}: {problem}");
            continue;
        }
        let scale = base.scale;
        let simulation = state.stepper.simulation_mut();
        if let Err(problem) = apply_colliders(simulation, &colliders, scale, now) {
            error!("fur on {entity}: {problem}");
        }
        if let Err(problem) = apply_grasp(simulation, &mut state.holding, &grasps, scale, now) {
            error!("fur on {entity}: {problem}");
        }
        apply_sponges(&mut state.stepper, &sponges, scale);
        state.world_from_simulation = base.world_from_simulation();
        state.centre_world = state.world_from_simulation.transform_point3(box_centre(&base.positions));
        let reach = box_radius(&base.positions) + state.structure.lengths.iter().copied().fold(0.0, f32::max);
        let w = state.world_from_simulation;
        let scale = w.x_axis.truncate().length().max(w.y_axis.truncate().length()).max(w.z_axis.truncate().length());
        state.radius_world = reach * scale;
        let mut params = state.stepper.simulation().params().clone();
        // The preset's gravity direction is the world's (Bevy's +Y is up), and so is the
        // simulation's frame.
        if let Some(preset) = presets.get(fur.preset.id()) {
            params.gravity_direction = preset.preset.simulation.gravity_direction;
        }
        params.wind = WindParams {
            direction: to_pelt(wind.direction).normalize_or(glam::Vec3::X),
            strength: wind.strength,
            gust_strength: wind.gust_strength,
            ..params.wind
        };
        if let Err(problem) = state.stepper.simulation_mut().set_params(&params) {
            error!("fur on {entity}: {problem}");
        }
        if let Err(problem) = state.stepper.advance_to(now) {
            error!("fur on {entity}: {problem}");
            continue;
        }
        state.positions = Arc::new(state.stepper.simulation().positions().to_vec());
        state.normals = Arc::new(state.base.normals.clone());
        let wetness = state.stepper.wetness();
        state.wetness = (!wetness.is_dry()).then(|| Arc::new(wetness.values().to_vec()));
    }
}

/// Poses the fur's base for this frame: Bevy's joints through the skin, or the entity's
/// transform. False (and no pose) while a skin's inverse bind matrices are not loaded.
fn pose_base(
    state: &mut FurState,
    transform: &GlobalTransform,
    skinned: Option<&SkinnedMesh>,
    bindposes: &Assets<SkinnedMeshInverseBindposes>,
    joints: &Query<&GlobalTransform>,
    joint_matrices: &mut Vec<glam::Mat4>,
) -> Result<bool, String> {
    let (Some(skin), Some(skinned)) = (&state.skin, skinned) else {
        let mesh = &state.structure.mesh;
        state.base.rigid(&mesh.positions, &mesh.normals, &to_pelt_affine(&transform.affine()));
        return Ok(true);
    };
    let Some(inverse_binds) = bindposes.get(&skinned.inverse_bindposes) else { return Ok(false) };
    joint_matrices.clear();
    for (joint, inverse_bind) in skinned.joints.iter().zip(inverse_binds.iter()) {
        let world = joints.get(*joint).map_err(|_| format!("its joint {joint} has no transform"))?;
        joint_matrices.push(to_pelt_mat4(&(world.to_matrix() * *inverse_bind)));
    }
    state.base.skinned(skin, &state.structure.mesh, joint_matrices).map_err(|e| e.to_string())?;
    Ok(true)
}

/// Half the diagonal of the points' bounding box.
fn box_radius(points: &[glam::Vec3]) -> f32 {
    let (min, max) = points
        .iter()
        .fold((glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    if points.is_empty() { 0.0 } else { 0.5 * (max - min).length() }
}

fn box_centre(points: &[glam::Vec3]) -> glam::Vec3 {
    let (min, max) = points
        .iter()
        .fold((glam::Vec3::splat(f32::MAX), glam::Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    if points.is_empty() { glam::Vec3::ZERO } else { (min + max) * 0.5 }
}

type FurQuery<'w, 's> = Query<
    'w,
    's,
    (Entity, &'static Fur, &'static GlobalTransform, Option<&'static SkinnedMesh>, &'static mut FurState),
>;

fn update_touch(touch: &mut FurTouch, furs: &mut FurQuery) {
    let radius_fraction = touch.radius;
    match (touch.ray, touch.active) {
        (None, None) => {}
        (None, Some(active)) => {
            if let Ok((.., mut state)) = furs.get_mut(active.entity) {
                state.stepper.simulation_mut().touch_end();
            }
            touch.active = None;
        }
        (Some(ray), Some(active)) => {
            let point = ray.get_point(active.distance);
            if let Ok((.., mut state)) = furs.get_mut(active.entity) {
                let point = state.world_from_simulation.inverse().transform_point3(to_pelt(point));
                if let Err(problem) = state.stepper.simulation_mut().touch_drag(point) {
                    error!("fur touch: {problem}");
                }
            } else {
                touch.active = None;
            }
        }
        (Some(ray), None) => {
            let nearest = furs
                .iter()
                .filter_map(|(entity, .., state)| Some((entity, pick(state, &ray)?)))
                .min_by(|a, b| a.1.1.total_cmp(&b.1.1));
            if let Some((entity, (point, distance))) = nearest
                && let Ok((.., mut state)) = furs.get_mut(entity)
            {
                let radius = (radius_fraction * state.radius).max(1e-6);
                match state.stepper.simulation_mut().touch_begin(point, radius) {
                    Ok(()) => touch.active = Some(ActiveTouch { entity, distance }),
                    Err(problem) => error!("fur touch: {problem}"),
                }
            }
        }
    }
}

/// The simulation-space hit of a world ray with the fur's base surface, and its world distance.
fn pick(state: &FurState, ray: &Ray3d) -> Option<(glam::Vec3, f32)> {
    let simulation_from_world = state.world_from_simulation.inverse();
    let origin = simulation_from_world.transform_point3(to_pelt(ray.origin));
    let direction = simulation_from_world.transform_vector3(to_pelt(*ray.direction));
    let hit = state.simulation().pick(&state.structure.mesh.triangles, origin, direction)?;
    let world_point = state.world_from_simulation.transform_point3(hit.point);
    Some((hit.point, world_point.distance(to_pelt(ray.origin))))
}
