//! Colliders a host or a script places: sphere, capsule, oriented box, plane and closed mesh,
//! each on a keyframed pose, validated, and resolved into the flat [`StepCollider`]s one step
//! reads.

use std::sync::Arc;

use glam::{Quat, Vec3};

use crate::body::{MeshSdf, SdfError};
use crate::mesh::Mesh;

/// A closed mesh as a collider's shape: the mesh (what hosts draw) and its signed distance
/// field, baked once (what contact reads).
///
/// A [`Shape::Mesh`] holds it behind an [`Arc`] rather than an id into a table the
/// simulation keeps: every step's [`StepCollider`]s then carry the field itself (a pointer
/// copy per sample), `StepCollider::closest` needs no table beside it, and the GPU side keys
/// its one upload per field on the `Arc`'s identity.
#[derive(Clone, Debug)]
pub struct ColliderMesh {
    mesh: Mesh,
    field: MeshSdf,
    half_extents: Vec3,
    reach: f32,
}

impl ColliderMesh {
    /// Bakes `mesh` (in the collider's own frame: the pose moves its origin) with `resolution`
    /// cells along its longest side.
    ///
    /// # Errors
    /// The [`SdfError`] of [`MeshSdf::bake`]: [`SdfError::NotClosed`] for a mesh with holes.
    pub fn new(mesh: Mesh, resolution: usize) -> Result<Self, SdfError> {
        let field = MeshSdf::bake(&mesh, resolution)?;
        let (lo, hi) = mesh.bounds();
        let reach = mesh.positions.iter().map(|p| p.length()).fold(0.0, f32::max);
        Ok(Self { half_extents: (hi - lo) * 0.5, reach, mesh, field })
    }

    /// The mesh, in the collider's frame.
    #[must_use]
    pub fn mesh(&self) -> &Mesh {
        &self.mesh
    }

    /// Its signed distance field (its own transform unused: the collider's pose places it).
    #[must_use]
    pub fn field(&self) -> &MeshSdf {
        &self.field
    }
}

impl PartialEq for ColliderMesh {
    /// The same mesh at once (hosts compare colliders every frame), else by content.
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self, other)
            || (self.mesh == other.mesh && self.field == other.field && self.half_extents == other.half_extents)
    }
}

/// The shape of a [`Collider`] in its own frame (the pose moves and turns it).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", deny_unknown_fields)]
pub enum Shape {
    /// A ball of `radius` about the pose's position.
    Sphere {
        /// World units, finite and positive.
        radius: f32,
    },
    /// A segment along the local Y axis from `-half_length` to `half_length`, swept by a ball.
    Capsule {
        /// World units, finite and positive.
        radius: f32,
        /// Half the segment's length (0 makes a sphere).
        half_length: f32,
    },
    /// An oriented box.
    Box {
        /// Half its size along the local axes, each finite and positive.
        half_extents: Vec3,
    },
    /// The half-space below the plane through the pose's position with local `+Y` as normal.
    Plane,
    /// A closed mesh about the pose's position, scaled by `scale` (scripts name its file; see
    /// `sim::scene`).
    #[serde(skip)]
    Mesh {
        /// The mesh and its field.
        mesh: Arc<ColliderMesh>,
        /// Uniform scale, finite and positive.
        scale: f32,
    },
}

impl Shape {
    /// The smallest size across the shape (the unit of the sweep's spacing); infinite for a
    /// plane. A mesh's is its bounding box's smallest half extent: a sample spacing that can
    /// still step over a thin part of a mesh that is thinner than its box.
    fn thickness(&self) -> f32 {
        match self {
            Self::Sphere { radius } | Self::Capsule { radius, .. } => *radius,
            Self::Box { half_extents } => half_extents.min_element(),
            Self::Plane => f32::INFINITY,
            Self::Mesh { mesh, scale } => mesh.half_extents.min_element() * scale,
        }
    }
}

/// One pose of a collider at a time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ColliderKey {
    /// When the collider is here (simulation seconds).
    pub time_secs: f64,
    /// The shape's centre (a plane's point), world units.
    pub position: Vec3,
    /// The shape's turn from its own frame.
    pub rotation: Quat,
}

/// A collider: a shape moving through keyframed poses (linear between keys, held after the
/// last). It is absent before its first key and grows in over [`Collider::appear_secs`] after
/// it, so one that appears inside the fur pushes it out over a few steps instead of at once.
#[derive(Clone, Debug, PartialEq)]
pub struct Collider {
    /// The host's name for it: [`Simulation::set_colliders`](crate::sim::Simulation::set_colliders)
    /// matches colliders by id from call to call to know how each moved.
    pub id: u32,
    /// Its shape.
    pub shape: Shape,
    /// Poses sorted by time (at least one).
    pub keys: Vec<ColliderKey>,
    /// How much of the collider's motion along its surface the touching fur follows, 0..=1.
    pub friction: f32,
    /// Seconds over which it grows to full size after it appears (0: at once).
    pub appear_secs: f32,
    /// When it appeared, where that is not its first key (a host's collider whose earlier poses
    /// were dropped); `None`: at its first key.
    pub appeared_secs: Option<f64>,
}

/// The largest speed, in the collider's radii (a box's, or a mesh's box's, smallest half extent) per step, at which
/// a collider's whole path within a step is swept: faster, it jumps (no fur is pushed between).
pub const SWEEP_RADII_PER_STEP: f32 = 8.0;

/// A collider as one step reads it: its pose at the step's time (or one of the poses sampled
/// along its path within the step), at the size it has grown to. Shared by every kernel.
#[derive(Clone, Debug, PartialEq)]
pub struct StepCollider {
    /// 0 sphere, 1 capsule, 2 box, 3 plane, 4 mesh.
    pub kind: u32,
    /// Centre (a plane's point).
    pub centre: Vec3,
    /// Turn from the shape's frame.
    pub rotation: Quat,
    /// Sphere and capsule radius, a mesh's scale (0 for a box or plane).
    pub radius: f32,
    /// A box's half extents; a capsule's `(0, half_length, 0)`.
    pub half_extents: Vec3,
    /// How far its centre moved over the step (friction drags touching fur by this).
    pub travel: Vec3,
    /// [`Collider::friction`].
    pub friction: f32,
    /// Whether it is the hand of the grasp: strands the grasp holds pass through it.
    pub grasp_hand: bool,
    /// Radius of a ball about `centre` holding the shape (infinite for a plane).
    pub bound: f32,
    /// A mesh's shape (`None` for the others).
    pub mesh: Option<Arc<ColliderMesh>>,
}

impl StepCollider {
    /// Kind code of a sphere.
    pub const SPHERE: u32 = 0;
    /// Kind code of a capsule.
    pub const CAPSULE: u32 = 1;
    /// Kind code of a box.
    pub const BOX: u32 = 2;
    /// Kind code of a plane.
    pub const PLANE: u32 = 3;
    /// Kind code of a mesh.
    pub const MESH: u32 = 4;

    /// A ball (the grasp's hand).
    #[must_use]
    pub fn ball(centre: Vec3, radius: f32) -> Self {
        Self {
            kind: Self::SPHERE,
            centre,
            rotation: Quat::IDENTITY,
            radius,
            half_extents: Vec3::ZERO,
            travel: Vec3::ZERO,
            friction: 0.0,
            grasp_hand: false,
            bound: radius,
            mesh: None,
        }
    }

    /// The closest point of the surface to `x`, the outward normal there and the signed distance
    /// of `x` (negative inside).
    #[must_use]
    pub fn closest(&self, x: Vec3) -> (Vec3, Vec3, f32) {
        let around_ball = |core: Vec3, radius: f32| {
            let d = x - core;
            let length = d.length();
            let normal = if length > 0.0 { d / length } else { self.rotation * Vec3::Y };
            (core + normal * radius, normal, length - radius)
        };
        match self.kind {
            Self::SPHERE => around_ball(self.centre, self.radius),
            Self::CAPSULE => {
                let axis = self.rotation * Vec3::Y;
                let h = self.half_extents.y;
                let t = axis.dot(x - self.centre).clamp(-h, h);
                around_ball(self.centre + axis * t, self.radius)
            }
            Self::BOX => {
                let local = self.rotation.inverse() * (x - self.centre);
                let h = self.half_extents;
                let q = local.abs() - h;
                if q.max_element() > 0.0 {
                    let clamped = local.clamp(-h, h);
                    let out = local - clamped;
                    let length = out.length();
                    (self.centre + self.rotation * clamped, self.rotation * (out / length), length)
                } else {
                    let axis = if q.x >= q.y && q.x >= q.z {
                        0
                    } else if q.y >= q.z {
                        1
                    } else {
                        2
                    };
                    let sign = if local[axis] < 0.0 { -1.0 } else { 1.0 };
                    let mut surface = local;
                    surface[axis] = sign * h[axis];
                    let mut normal = Vec3::ZERO;
                    normal[axis] = sign;
                    (self.centre + self.rotation * surface, self.rotation * normal, q[axis])
                }
            }
            Self::MESH if let Some(mesh) = &self.mesh => {
                // The field's distance in the mesh's frame, scaled; the surface point one
                // distance back along the normal (the field's gradient).
                let scale = self.radius;
                let local = (self.rotation.inverse() * (x - self.centre)) / scale;
                let (distance, gradient) = mesh.field.local_distance_gradient(local);
                let normal = (self.rotation * gradient).try_normalize().unwrap_or(self.rotation * Vec3::Y);
                let distance = distance * scale;
                (x - normal * distance, normal, distance)
            }
            _ => {
                let normal = self.rotation * Vec3::Y;
                let distance = normal.dot(x - self.centre);
                (x - normal * distance, normal, distance)
            }
        }
    }
}

impl Collider {
    /// A collider standing still at `position`, present from `time_secs` (a host's pose for one
    /// frame; [`Simulation::set_colliders`](crate::sim::Simulation::set_colliders) joins successive
    /// poses of one id into its motion).
    #[must_use]
    pub fn at(id: u32, shape: Shape, time_secs: f64, position: Vec3, rotation: Quat) -> Self {
        Self {
            id,
            shape,
            keys: vec![ColliderKey { time_secs, position, rotation }],
            friction: 0.3,
            appear_secs: 0.25,
            appeared_secs: None,
        }
    }

    /// Checks the shape, the keys and the parameters; the error names the key (`radius`,
    /// `keys[2].position`, ...) and the problem.
    ///
    /// # Errors
    /// `(key, problem)` for the first bad value.
    pub fn validate(&self) -> Result<(), (String, String)> {
        let positive = |key: &str, value: f32| {
            if value.is_finite() && value > 0.0 {
                Ok(())
            } else {
                Err((key.to_owned(), format!("must be finite and positive, got {value}")))
            }
        };
        match &self.shape {
            Shape::Sphere { radius } => positive("radius", *radius)?,
            Shape::Capsule { radius, half_length } => {
                positive("radius", *radius)?;
                if !(half_length.is_finite() && *half_length >= 0.0) {
                    return Err(("half_length".into(), format!("must be finite and at least 0, got {half_length}")));
                }
            }
            Shape::Box { half_extents } => {
                for (axis, value) in ["x", "y", "z"].iter().zip(half_extents.to_array()) {
                    positive(&format!("half_extents.{axis}"), value)?;
                }
            }
            Shape::Plane => {}
            Shape::Mesh { scale, .. } => positive("scale", *scale)?,
        }
        if !(self.friction.is_finite() && (0.0..=1.0).contains(&self.friction)) {
            return Err(("friction".into(), format!("must be between 0 and 1, got {}", self.friction)));
        }
        if !(self.appear_secs.is_finite() && (0.0..=60.0).contains(&self.appear_secs)) {
            return Err(("appear_secs".into(), format!("must be between 0 and 60, got {}", self.appear_secs)));
        }
        if self.keys.is_empty() {
            return Err(("keys".into(), "needs at least one pose".into()));
        }
        for (i, key) in self.keys.iter().enumerate() {
            if !key.time_secs.is_finite() {
                return Err((format!("keys[{i}].time_secs"), format!("must be finite, got {}", key.time_secs)));
            }
            if i > 0 && key.time_secs < self.keys[i - 1].time_secs {
                return Err((format!("keys[{i}].time_secs"), "keys must be sorted by time".into()));
            }
            if !key.position.is_finite() {
                return Err((format!("keys[{i}].position"), format!("must be finite, got {}", key.position)));
            }
            if !key.rotation.is_finite() || key.rotation.length_squared() == 0.0 {
                return Err((
                    format!("keys[{i}].rotation"),
                    format!("must be a finite non-zero quaternion, got {}", key.rotation),
                ));
            }
        }
        Ok(())
    }

    /// The pose at `time_secs` (held before the first key and after the last).
    #[must_use]
    pub fn pose_at(&self, time_secs: f64) -> (Vec3, Quat) {
        let after = self.keys.iter().position(|k| k.time_secs > time_secs);
        let key = |k: &ColliderKey| (k.position, k.rotation.normalize());
        match after {
            None => key(self.keys.last().expect("validated: one key at least")),
            Some(0) => key(&self.keys[0]),
            Some(i) => {
                let (a, b) = (&self.keys[i - 1], &self.keys[i]);
                let t = ((time_secs - a.time_secs) / (b.time_secs - a.time_secs)) as f32;
                (a.position.lerp(b.position, t), a.rotation.normalize().slerp(b.rotation.normalize(), t))
            }
        }
    }

    /// When the collider (last) appeared at or before `time_secs`: its first key, or the end of
    /// the last step between keys faster than [`SWEEP_RADII_PER_STEP`] (a jump, after which it
    /// grows in again). `None` before the first key.
    pub(crate) fn appeared_at(&self, time_secs: f64, step_secs: f64) -> Option<f64> {
        let first = self.appeared_secs.unwrap_or(self.keys[0].time_secs);
        if time_secs < first {
            return None;
        }
        let limit = SWEEP_RADII_PER_STEP * self.shape.thickness();
        let mut appeared = first;
        for pair in self.keys.windows(2) {
            if pair[1].time_secs > time_secs {
                break;
            }
            let steps = ((pair[1].time_secs - pair[0].time_secs) / step_secs).max(1.0) as f32;
            if pair[0].position.distance(pair[1].position) / steps > limit {
                appeared = pair[1].time_secs;
            }
        }
        Some(appeared)
    }

    /// Appends this collider as the step at `time_secs` (of `step_secs`) reads it: absent before
    /// its first key; grown by the time since it appeared; its path over the step sampled at
    /// most one thickness apart (up to [`SWEEP_RADII_PER_STEP`] thicknesses), so a thin fast
    /// collider pushes every strand it passes. `fur_radius` sizes a plane's approach.
    pub(crate) fn push_step(&self, time_secs: f64, step_secs: f64, fur_radius: f32, out: &mut Vec<StepCollider>) {
        let Some(appeared) = self.appeared_at(time_secs, step_secs) else { return };
        let grown = if self.appear_secs > 0.0 {
            let t = (((time_secs - appeared) / f64::from(self.appear_secs)) as f32).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        } else {
            1.0
        };
        if grown <= 0.0 {
            return;
        }
        let (position, rotation) = self.pose_at(time_secs);
        let before = (time_secs - step_secs).max(appeared);
        let (earlier, earlier_rotation) = self.pose_at(before);
        let travel = position - earlier;
        let thickness = self.shape.thickness() * grown;
        let samples = if thickness.is_finite() && travel.length() <= SWEEP_RADII_PER_STEP * thickness {
            (travel.length() / thickness).ceil().clamp(1.0, SWEEP_RADII_PER_STEP) as usize
        } else {
            1
        };
        for s in 0..samples {
            // The step's own pose last, after the poses along the way, newest first toward it.
            let t = (s + 1) as f32 / samples as f32;
            let (centre, turn) = if samples == 1 {
                (position, rotation)
            } else {
                (earlier.lerp(position, t), earlier_rotation.slerp(rotation, t))
            };
            let mut collider = StepCollider {
                kind: 0,
                centre,
                rotation: turn,
                radius: 0.0,
                half_extents: Vec3::ZERO,
                travel,
                friction: self.friction,
                grasp_hand: false,
                bound: 0.0,
                mesh: None,
            };
            match &self.shape {
                Shape::Sphere { radius } => {
                    collider.radius = radius * grown;
                    collider.bound = collider.radius;
                }
                Shape::Capsule { radius, half_length } => {
                    collider.kind = StepCollider::CAPSULE;
                    collider.radius = radius * grown;
                    collider.half_extents = Vec3::new(0.0, half_length * grown, 0.0);
                    collider.bound = collider.radius + collider.half_extents.y;
                }
                Shape::Box { half_extents } => {
                    collider.kind = StepCollider::BOX;
                    collider.half_extents = half_extents * grown;
                    collider.bound = collider.half_extents.length();
                }
                Shape::Plane => {
                    collider.kind = StepCollider::PLANE;
                    // Rises from one fur radius below to its place as it grows.
                    collider.centre -= (turn * Vec3::Y) * (2.0 * fur_radius * (1.0 - grown));
                    collider.bound = f32::INFINITY;
                }
                Shape::Mesh { mesh, scale } => {
                    // Grows about the mesh's origin, as the others grow about their centres.
                    collider.kind = StepCollider::MESH;
                    collider.radius = scale * grown;
                    collider.bound = mesh.reach * collider.radius;
                    collider.mesh = Some(Arc::clone(mesh));
                }
            }
            out.push(collider);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_colliders_name_their_key() {
        let mut c = Collider::at(1, Shape::Sphere { radius: 0.0 }, 0.0, Vec3::ZERO, Quat::IDENTITY);
        assert_eq!(c.validate().unwrap_err().0, "radius");
        c.shape = Shape::Capsule { radius: -1.0, half_length: 1.0 };
        assert_eq!(c.validate().unwrap_err().0, "radius");
        c.shape = Shape::Box { half_extents: Vec3::new(1.0, f32::NAN, 1.0) };
        assert_eq!(c.validate().unwrap_err().0, "half_extents.y");
        c.shape = Shape::Plane;
        c.keys[0].position.x = f32::NAN;
        assert_eq!(c.validate().unwrap_err().0, "keys[0].position");
        c.keys[0].position.x = 0.0;
        c.keys.push(ColliderKey { time_secs: -1.0, position: Vec3::ZERO, rotation: Quat::IDENTITY });
        assert_eq!(c.validate().unwrap_err().0, "keys[1].time_secs");
    }

    #[test]
    fn closest_points_lie_on_the_surface() {
        let rotation = Quat::from_rotation_z(0.4);
        for (kind, radius, half) in [
            (StepCollider::SPHERE, 0.5, Vec3::ZERO),
            (StepCollider::CAPSULE, 0.3, Vec3::new(0.0, 0.7, 0.0)),
            (StepCollider::BOX, 0.0, Vec3::new(0.4, 0.2, 0.6)),
        ] {
            let c = StepCollider { kind, radius, half_extents: half, rotation, ..StepCollider::ball(Vec3::X, radius) };
            for x in [Vec3::new(1.1, 0.1, 0.0), Vec3::new(2.0, 1.0, -1.0), Vec3::new(0.8, -0.3, 0.2)] {
                let (s, n, d) = c.closest(x);
                assert!((x - s).dot(n) - d < 1e-5 && (s + n * d).distance(x) < 1e-5, "{kind} {x}");
                assert!(c.closest(s).2.abs() < 1e-5, "{kind}: the closest point is on the surface");
            }
        }
    }
}
