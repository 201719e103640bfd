//! Contact between fur and the scene: [`FurCollider`]s (sphere, capsule, box, plane, closed mesh) on entities,
//! so a Bevy body, physics-driven or animated, pushes fur; and [`FurGrasp`], a hand a host opens
//! and closes. Both take their pose from the entity's `GlobalTransform` every frame.
//!
//! Every fur feels every collider. pelt-core joins a collider's poses from frame to frame by its
//! id (the entity), so one that moves fast sweeps the fur along its whole path within a step,
//! and one that appears inside the fur grows in over a quarter of a second instead of flinging
//! it.

use std::sync::Arc;

use bevy::ecs::prelude::*;
use bevy::math::Vec3;
use bevy::prelude::GlobalTransform;
use pelt_core::Mesh;
use pelt_core::body::SdfError;
use pelt_core::sim::contact::{Collider, GraspParams, Shape};
use pelt_core::sim::{ColliderMesh, SimError, Simulation};

use crate::convert::to_pelt;

/// A collider shape in the entity's own frame, before its `GlobalTransform`'s scale.
#[derive(Clone, Debug, PartialEq)]
pub enum FurShape {
    /// A ball about the entity's origin.
    Sphere {
        /// Radius, world units before scale.
        radius: f32,
    },
    /// A segment along the local Y axis from `-half_length` to `half_length`, swept by a ball
    /// (Bevy's `Capsule3d` of `half_length`).
    Capsule {
        /// Radius.
        radius: f32,
        /// Half the segment's length.
        half_length: f32,
    },
    /// A box (Bevy's `Cuboid` of `half_size * 2`).
    Cuboid {
        /// Half its size along the local axes.
        half_size: Vec3,
    },
    /// The half-space below the plane through the origin with local `+Y` as its normal.
    Plane,
    /// A closed mesh (pelt's axes and units, about the entity's origin) as its baked distance
    /// field, shared by every fur (see [`FurCollider::mesh`]).
    Mesh(Arc<ColliderMesh>),
}

/// Pushes fur out of a shape that follows this entity's `GlobalTransform` (a ball thrown through
/// a coat, a hand, a wall). The transform's scale scales the shape (a ball takes its largest axis,
/// a capsule its largest across X and Z for the radius and Y for the length, a mesh its largest
/// axis).
#[derive(Component, Clone, Debug, PartialEq)]
#[require(GlobalTransform)]
pub struct FurCollider {
    /// The shape.
    pub shape: FurShape,
    /// How much of the collider's motion along its surface touching fur follows, `0..=1`.
    pub friction: f32,
}

impl FurCollider {
    /// A ball of `radius`.
    #[must_use]
    pub fn sphere(radius: f32) -> Self {
        Self { shape: FurShape::Sphere { radius }, friction: 0.3 }
    }

    /// A capsule along local Y.
    #[must_use]
    pub fn capsule(radius: f32, half_length: f32) -> Self {
        Self { shape: FurShape::Capsule { radius, half_length }, friction: 0.3 }
    }

    /// A box of `half_size`.
    #[must_use]
    pub fn cuboid(half_size: Vec3) -> Self {
        Self { shape: FurShape::Cuboid { half_size }, friction: 0.3 }
    }

    /// The half-space below local `+Y`.
    #[must_use]
    pub fn plane() -> Self {
        Self { shape: FurShape::Plane, friction: 0.3 }
    }

    /// A closed `mesh` (in the entity's frame, pelt's axes), baked once into a distance field
    /// of `resolution` cells along its longest side (32 resolves a hand-sized prop).
    ///
    /// # Errors
    /// [`SdfError::NotClosed`] for a mesh with holes, and the other [`SdfError`]s of baking.
    pub fn mesh(mesh: Mesh, resolution: usize) -> Result<Self, SdfError> {
        Ok(Self { shape: FurShape::Mesh(Arc::new(ColliderMesh::new(mesh, resolution)?)), friction: 0.3 })
    }

    /// This collider with `friction`.
    #[must_use]
    pub fn with_friction(self, friction: f32) -> Self {
        Self { friction, ..self }
    }

    /// pelt-core's collider for this frame at `time_secs`, in a fur's simulation space (world
    /// divided by `simulation_scale`).
    fn at(&self, entity: Entity, transform: &GlobalTransform, simulation_scale: f32, time_secs: f64) -> Collider {
        let (scale, rotation, translation) = transform.to_scale_rotation_translation();
        let scale = scale.abs() / simulation_scale;
        let shape = match self.shape {
            FurShape::Sphere { radius } => Shape::Sphere { radius: radius * scale.max_element() },
            FurShape::Capsule { radius, half_length } => {
                Shape::Capsule { radius: radius * scale.x.max(scale.z), half_length: half_length * scale.y }
            }
            FurShape::Cuboid { half_size } => Shape::Box { half_extents: to_pelt(half_size * scale) },
            FurShape::Plane => Shape::Plane,
            FurShape::Mesh(ref mesh) => Shape::Mesh { mesh: Arc::clone(mesh), scale: scale.max_element() },
        };
        let rotation = glam::Quat::from_array(rotation.to_array());
        let position = to_pelt(translation) / simulation_scale;
        let mut collider = Collider::at(entity.index_u32(), shape, time_secs, position, rotation);
        collider.friction = self.friction;
        collider
    }
}

/// A hand that grasps fur at this entity's position: while `closed`, the strands rooted within
/// `radius` of where it closed are gathered toward the entity and follow it (within their
/// length); opening it lets them spring back. A host drives it (a VR controller, a cursor, a
/// script) by moving the entity and setting `closed`.
///
/// A grasp closes on every fur with a root within `radius` of the entity; one fur follows one
/// grasp at a time (the lowest entity among those closing on it).
#[derive(Component, Clone, Copy, Debug, PartialEq)]
#[require(GlobalTransform)]
pub struct FurGrasp {
    /// Whether the hand is closed.
    pub closed: bool,
    /// Strands rooted within this distance (world units) of the closing point are held.
    pub radius: f32,
    /// Size of the hand (world units; fingers, thumb and palm about the grip, see
    /// `pelt_core::sim::Grasp::hand`), which pushes the strands it does not hold; 0 for none.
    pub hand_radius: f32,
    /// How fast it closes and how the fur springs back.
    pub params: GraspParams,
}

impl FurGrasp {
    /// An open hand gathering within `radius`, with no fingers that push.
    #[must_use]
    pub fn new(radius: f32) -> Self {
        Self { closed: false, radius, hand_radius: 0.0, params: GraspParams::default() }
    }
}

/// The grasps of this frame: entity, component, world position, sorted by entity.
pub(crate) type Grasps = Vec<(Entity, FurGrasp, Vec3)>;

/// Hands one fur the colliders of this frame (`simulation_scale`: world = scale * simulation).
pub(crate) fn apply_colliders(
    simulation: &mut Simulation,
    colliders: &[(Entity, FurCollider, GlobalTransform)],
    simulation_scale: f32,
    time_secs: f64,
) -> Result<(), SimError> {
    if colliders.is_empty() && simulation.colliders().is_empty() {
        return Ok(());
    }
    let colliders: Vec<Collider> = colliders
        .iter()
        .map(|(entity, collider, transform)| collider.at(*entity, transform, simulation_scale, time_secs))
        .collect();
    simulation.set_colliders(&colliders)
}

/// Begins, moves or ends one fur's grasp from the [`FurGrasp`]s; `holding` is the grasp entity
/// the fur follows.
pub(crate) fn apply_grasp(
    simulation: &mut Simulation,
    holding: &mut Option<Entity>,
    grasps: &Grasps,
    simulation_scale: f32,
    time_secs: f64,
) -> Result<(), SimError> {
    let to_simulation = |world: Vec3| to_pelt(world) / simulation_scale;
    if let Some(entity) = *holding {
        match grasps.iter().find(|(e, grasp, _)| *e == entity && grasp.closed) {
            Some((_, _, position)) => return simulation.grasp_move(to_simulation(*position)),
            None => {
                simulation.grasp_end(time_secs);
                *holding = None;
            }
        }
    }
    let reaches = |grasp: &FurGrasp, point: glam::Vec3| {
        let radius = grasp.radius / simulation_scale;
        simulation.roots().iter().any(|root| root.distance(point) <= radius)
    };
    let closing = grasps.iter().find(|(_, grasp, position)| grasp.closed && reaches(grasp, to_simulation(*position)));
    if let Some((entity, grasp, position)) = closing {
        simulation.grasp_begin(
            to_simulation(*position),
            grasp.radius / simulation_scale,
            grasp.hand_radius / simulation_scale,
            grasp.params,
            time_secs,
        )?;
        *holding = Some(*entity);
    }
    Ok(())
}
