//! The colliders a simulation pushes its fur out of, drawn as shaded plain meshes (spheres,
//! capsules, boxes, planes, mesh colliders' own meshes and the grasp's hand), posed each frame
//! and depth-tested with the fur.

use std::f32::consts::{PI, TAU};
use std::path::Path;
use std::sync::Arc;

use glam::{Mat4, Vec3};
use pelt_core::Mesh;
use pelt_core::mesh::{ImportOptions, RawMesh};
use pelt_core::sim::{ColliderMesh, StepCollider};

use crate::RenderError;
use crate::plain::PlainMesh;
use crate::renderer::FurRenderer;
use crate::view::FurView;

/// Linear RGB of a collider: a cool grey that reads against fur and skin.
pub const COLLIDER_COLOUR: Vec3 = Vec3::new(0.42, 0.5, 0.62);

/// Linear RGB of the grasp's hand: a skin tone.
pub const HAND_COLOUR: Vec3 = Vec3::new(0.8, 0.52, 0.4);

/// Segments around a sphere's or capsule's axis.
const SEGMENTS: u32 = 40;

/// The shape of one mesh in its own frame: everything a collider's mesh depends on besides the
/// pose and a uniform scale.
#[derive(Clone, Debug, PartialEq)]
enum MeshShape {
    /// A unit ball.
    Sphere,
    /// A capsule of unit radius whose segment runs from `-half_length` to `half_length` on Y.
    Capsule { half_length: f32 },
    /// A cube from -1 to 1 (scaled by the half extents).
    Box,
    /// A square from -1 to 1 in XZ, normal +Y.
    Plane,
    /// A mesh collider's own mesh (the same `Arc`: the same mesh).
    Mesh(Arc<ColliderMesh>),
}

/// The mesh, the colour and the transform from mesh to simulation space of one collider.
/// `plane_half_size` is how far a plane is drawn about its point (it has no edge).
fn placement(collider: &StepCollider, plane_half_size: f32) -> (MeshShape, Vec3, Mat4) {
    let colour = if collider.grasp_hand { HAND_COLOUR } else { COLLIDER_COLOUR };
    let posed = |scale: Vec3| Mat4::from_scale_rotation_translation(scale, collider.rotation, collider.centre);
    match collider.kind {
        StepCollider::SPHERE => (MeshShape::Sphere, colour, posed(Vec3::splat(collider.radius))),
        StepCollider::CAPSULE => {
            // Growing scales radius and length alike, so the unit mesh keeps its proportion.
            let half_length = collider.half_extents.y / collider.radius.max(f32::MIN_POSITIVE);
            (MeshShape::Capsule { half_length }, colour, posed(Vec3::splat(collider.radius)))
        }
        StepCollider::BOX => (MeshShape::Box, colour, posed(collider.half_extents)),
        StepCollider::MESH if let Some(mesh) = &collider.mesh => {
            (MeshShape::Mesh(Arc::clone(mesh)), colour, posed(Vec3::splat(collider.radius)))
        }
        _ => (MeshShape::Plane, colour, posed(Vec3::splat(plane_half_size))),
    }
}

/// A ground: the square from -1 to 1 in x and z at y = 0, facing +y (place and scale it with
/// [`PlainMesh::prepare`]).
#[must_use]
pub fn ground_mesh() -> Mesh {
    shape_mesh(&MeshShape::Plane)
}

/// A triangle mesh of `shape` (counter-clockwise from outside, unit normals).
fn shape_mesh(shape: &MeshShape) -> Mesh {
    let raw = match shape {
        MeshShape::Mesh(mesh) => return mesh.mesh().clone(),
        MeshShape::Sphere => capsule(0.0),
        MeshShape::Capsule { half_length } => capsule(*half_length),
        MeshShape::Box => cube(),
        MeshShape::Plane => square(),
    };
    // Unwelded, so the box keeps its flat faces; the generators' winding is already outward.
    let options = ImportOptions { weld: false, orient: false, vertex_cache_order: false, ..ImportOptions::default() };
    let (mesh, _) = Mesh::from_raw(raw, Path::new("builtin:collider"), &options)
        .expect("generated collider meshes are finite and have triangles");
    mesh
}

/// A unit-radius ball swept along Y from `-half_length` to `half_length` (a sphere at 0): rings
/// from the south pole to the north, the lower hemisphere's rings moved down, the upper's up.
fn capsule(half_length: f32) -> RawMesh {
    let rings_per_half = SEGMENTS / 4;
    let mut raw = RawMesh { normals: Some(Vec::new()), ..RawMesh::default() };
    let mut rows = 0;
    for half in [-1.0f32, 1.0] {
        for ring in 0..=rings_per_half {
            // Latitude from -90 to 0 degrees for the lower half, 0 to 90 for the upper.
            let latitude = if half < 0.0 {
                -0.5 * PI + 0.5 * PI * ring as f32 / rings_per_half as f32
            } else {
                0.5 * PI * ring as f32 / rings_per_half as f32
            };
            for segment in 0..=SEGMENTS {
                let azimuth = TAU * segment as f32 / SEGMENTS as f32;
                let normal = Vec3::new(latitude.cos() * azimuth.cos(), latitude.sin(), -latitude.cos() * azimuth.sin());
                raw.positions.push(normal + Vec3::Y * (half * half_length));
                raw.normals.as_mut().expect("made with normals").push(normal);
            }
            rows += 1;
        }
    }
    let columns = SEGMENTS + 1;
    for row in 0..rows - 1 {
        for col in 0..SEGMENTS {
            let i = row * columns + col;
            let (right, up) = (i + 1, i + columns);
            // Skip the triangles that collapse at the poles.
            if row > 0 {
                raw.triangles.push([i, right, up + 1]);
            }
            if row + 1 < rows - 1 {
                raw.triangles.push([i, up + 1, up]);
            }
        }
    }
    raw
}

/// The cube from -1 to 1, four vertices and a flat normal per face.
fn cube() -> RawMesh {
    let mut raw = RawMesh { normals: Some(Vec::new()), ..RawMesh::default() };
    for (normal, u, v) in pelt_core::mesh::builtin::CUBE_FACES {
        let base = raw.positions.len() as u32;
        for (a, b) in [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)] {
            raw.positions.push(normal + u * a + v * b);
            raw.normals.as_mut().expect("made with normals").push(normal);
        }
        raw.triangles.extend([[base, base + 1, base + 2], [base, base + 2, base + 3]]);
    }
    raw
}

/// The square from -1 to 1 in XZ facing +Y.
fn square() -> RawMesh {
    RawMesh {
        positions: vec![
            Vec3::new(-1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, 1.0),
            Vec3::new(1.0, 0.0, -1.0),
            Vec3::new(-1.0, 0.0, -1.0),
        ],
        normals: Some(vec![Vec3::Y; 4]),
        uvs: None,
        triangles: vec![[0, 1, 2], [0, 2, 3]],
    }
}

/// One drawn collider: its mesh and the shape it was made for.
#[derive(Debug)]
struct Slot {
    shape: MeshShape,
    colour: Vec3,
    mesh: PlainMesh,
}

/// The colliders of one simulation on the GPU, drawn as plain meshes.
///
/// Each frame [`ColliderMeshes::update`] takes the colliders as they stand
/// (`Simulation::shown_colliders`); meshes are made when a collider of a new shape appears and
/// reused while the shapes stay, only their transforms rewritten. [`ColliderMeshes::draw`] draws
/// them with [`FurRenderer::draw_plain`], before the fur so the fur is depth-tested against them.
/// With no colliders nothing is drawn, and the picture is the one without this object.
#[derive(Debug, Default)]
pub struct ColliderMeshes {
    slots: Vec<Slot>,
    shown: usize,
}

impl ColliderMeshes {
    /// No colliders yet.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Poses a mesh for each of `colliders` (in simulation space, placed in the world by
    /// `world_from_model`: identity where the simulation runs in the world, as a
    /// `FurStepper`'s does, the fur's own transform where a host draws it under one). A plane is drawn as a square of
    /// `plane_half_size` about its point (the fur's bounding radius or so).
    ///
    /// # Errors
    /// A [`RenderError`] when a new mesh cannot be uploaded.
    pub fn update(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        colliders: &[StepCollider],
        world_from_model: Mat4,
        plane_half_size: f32,
    ) -> Result<(), RenderError> {
        self.shown = 0;
        for collider in colliders {
            let (shape, colour, model_from_mesh) = placement(collider, plane_half_size);
            if !model_from_mesh.is_finite() {
                continue;
            }
            let index = self.shown;
            let stale = self.slots.get(index).is_none_or(|slot| slot.shape != shape || slot.colour != colour);
            if stale {
                let mesh = PlainMesh::new(device, renderer, &shape_mesh(&shape), colour)?;
                let slot = Slot { shape, colour, mesh };
                if index < self.slots.len() {
                    self.slots[index] = slot;
                } else {
                    self.slots.push(slot);
                }
            }
            self.slots[index].mesh.prepare(queue, world_from_model * model_from_mesh);
            self.shown += 1;
        }
        Ok(())
    }

    /// How many colliders the next [`ColliderMeshes::draw`] draws.
    #[must_use]
    pub fn len(&self) -> usize {
        self.shown
    }

    /// Whether the next [`ColliderMeshes::draw`] draws nothing.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.shown == 0
    }

    /// Draws the colliders of the last update into the host's pass (before the fur).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, renderer: &FurRenderer, view: &FurView) {
        for slot in &self.slots[..self.shown] {
            renderer.draw_plain(pass, view, &slot.mesh);
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Quat;

    use super::*;

    /// Every generated vertex lies on the collider's surface (by the simulation's own distance)
    /// and its normal points out of it; the triangles wind outward.
    #[test]
    fn meshes_lie_on_the_colliders_they_draw() {
        let rotation = Quat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1);
        let centre = Vec3::new(0.5, -1.0, 2.0);
        let colliders = [
            StepCollider::ball(centre, 0.7),
            StepCollider {
                kind: StepCollider::CAPSULE,
                rotation,
                half_extents: Vec3::new(0.0, 1.3, 0.0),
                bound: 2.0,
                ..StepCollider::ball(centre, 0.4)
            },
            StepCollider {
                kind: StepCollider::BOX,
                rotation,
                radius: 0.0,
                half_extents: Vec3::new(0.3, 0.8, 1.5),
                bound: 2.0,
                ..StepCollider::ball(centre, 0.0)
            },
            StepCollider {
                kind: StepCollider::PLANE,
                rotation,
                bound: f32::INFINITY,
                ..StepCollider::ball(centre, 0.0)
            },
        ];
        for collider in colliders {
            let (shape, _, model_from_mesh) = placement(&collider, 3.0);
            let mesh = shape_mesh(&shape);
            let normal_from_mesh = glam::Mat3::from_mat4(model_from_mesh).inverse().transpose();
            for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
                let x = model_from_mesh.transform_point3(*p);
                let (_, outward, distance) = collider.closest(x);
                assert!(distance.abs() < 1e-4, "kind {}: {x} is {distance} off the surface", collider.kind);
                let n = (normal_from_mesh * *n).normalize();
                // A box's corner has three faces' normals; the distance picks one of them.
                let least = if collider.kind == StepCollider::BOX { -1e-5 } else { 0.999 };
                assert!(n.dot(outward) > least, "kind {}: normal {n} against {outward}", collider.kind);
            }
            for t in &mesh.triangles {
                let [a, b, c] = t.map(|i| model_from_mesh.transform_point3(mesh.positions[i as usize]));
                let face = (b - a).cross(c - a);
                let outward = collider.closest((a + b + c) / 3.0).1;
                if face.length() > 1e-9 {
                    assert!(face.dot(outward) >= 0.0, "kind {}: a triangle faces inward", collider.kind);
                }
            }
        }
    }

    #[test]
    fn the_hand_is_told_apart() {
        let mut hand = StepCollider::ball(Vec3::ZERO, 0.2);
        assert_eq!(placement(&hand, 1.0).1, COLLIDER_COLOUR);
        hand.grasp_hand = true;
        assert_eq!(placement(&hand, 1.0).1, HAND_COLOUR);
    }
}
