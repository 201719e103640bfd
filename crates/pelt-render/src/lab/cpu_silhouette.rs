//! Silhouette fins decided on the CPU: the same decision as the compute pass (`fin_fade` in
//! `unified.wgsl`), for hosts that keep the base mesh's positions on the CPU anyway (a CPU
//! simulation, a skinned mesh posed on the CPU). It writes the fins' instance list and indirect
//! draw with the queue, so the frame records no compute pass; see BENCHMARKS.md for when each
//! path is the cheaper one.

use glam::{Mat3, Vec3};
use pelt_core::mesh::NO_FACE;
use pelt_core::{FurStructure, Mesh};

use crate::RenderError;
use crate::fur::GpuFur;
use crate::object::FurFrame;

/// One fur's topology kept on the CPU for [`GpuFur::prepare_fins_on_cpu`], and the list
/// it last wrote. Make it once per mesh (its triangles, edges and the faces beside each edge).
#[derive(Clone, Debug)]
pub struct CpuSilhouette {
    vertex_count: usize,
    triangles: Vec<[u32; 3]>,
    edges: Vec<[u32; 2]>,
    edge_faces: Vec<[u32; 2]>,
    /// World-space unit face normals of the last decision (zero for degenerate faces).
    face_normals: Vec<Vec3>,
    /// `(edge, fade as f32 bits)` of the fins the last decision kept, in edge order.
    fins: Vec<[u32; 2]>,
}

impl CpuSilhouette {
    /// The topology of `mesh`, the base mesh of the fur it will decide for.
    #[must_use]
    pub fn new(mesh: &Mesh) -> Self {
        Self {
            vertex_count: mesh.vertex_count(),
            triangles: mesh.triangles.clone(),
            edges: mesh.edges.clone(),
            edge_faces: mesh.edge_faces.clone(),
            face_normals: Vec::with_capacity(mesh.triangles.len()),
            fins: Vec::with_capacity(mesh.edges.len()),
        }
    }

    /// The topology of `structure`'s base mesh with only the edges that grow fins, in the order
    /// the GPU keeps them: what a groomed fur needs (as [`CpuSilhouette::new`] without a groom).
    #[must_use]
    pub fn of(structure: &FurStructure) -> Self {
        let mut silhouette = Self::new(&structure.mesh);
        if structure.groom.is_some() {
            let fins = structure.fin_edges();
            silhouette.edges = fins.iter().map(|&e| structure.mesh.edges[e as usize]).collect();
            silhouette.edge_faces = fins.iter().map(|&e| structure.mesh.edge_faces[e as usize]).collect();
        }
        silhouette
    }

    /// The edges it decides for (one possible fin each).
    #[must_use]
    pub fn edge_count(&self) -> usize {
        self.edges.len()
    }

    /// Decides which fins show for a fur whose base vertices (layer 0 of the shared array, model
    /// space) are the first `V` of `positions`, drawn with `frame`'s transform and look and seen
    /// from `camera_position_world`. Returns `(edge, fade bits)` for every fin with a fade above
    /// 0, in edge order: the instances of the fins' indirect draw.
    ///
    /// # Errors
    /// [`RenderError::Count`] when `positions` holds fewer than `V` positions.
    pub fn decide(
        &mut self,
        positions: &[Vec3],
        frame: &FurFrame,
        camera_position_world: Vec3,
    ) -> Result<&[[u32; 2]], RenderError> {
        if positions.len() < self.vertex_count {
            return Err(RenderError::Count {
                what: "base positions for the CPU silhouette",
                expected: self.vertex_count,
                got: positions.len(),
                rule: "V (layer 0 of the shared array)",
            });
        }
        let world_from_model = frame.world_from_model;
        let linear = Mat3::from_mat4(world_from_model);
        // Normals through the inverse transpose, as the shaders take them (any affine transform);
        // a singular transform keeps the plain 3x3.
        let normal_from_model = if linear.determinant().abs() > 1e-30 { linear.inverse().transpose() } else { linear };
        let fade_cos = frame.look.fin_fade_cos.max(1e-3);
        self.face_normals.clear();
        self.face_normals.extend(self.triangles.iter().map(|&[a, b, c]| {
            let (a, b, c) = (positions[a as usize], positions[b as usize], positions[c as usize]);
            unit_or(normal_from_model * (b - a).cross(c - a), Vec3::ZERO)
        }));
        self.fins.clear();
        for (edge, (&[a, b], &[face_a, face_b])) in self.edges.iter().zip(&self.edge_faces).enumerate() {
            let middle = world_from_model.transform_point3(0.5 * (positions[a as usize] + positions[b as usize]));
            let to_camera = unit_or(camera_position_world - middle, Vec3::Z);
            let facing_a = self.face_normals[face_a as usize].dot(to_camera);
            let mut edge_on = facing_a.abs();
            if face_b != NO_FACE {
                let facing_b = self.face_normals[face_b as usize].dot(to_camera);
                edge_on = edge_on.min(facing_b.abs());
                if facing_a * facing_b <= 0.0 {
                    // One face toward the camera, one away: a true silhouette edge.
                    edge_on = 0.0;
                }
            }
            let t = (edge_on / fade_cos).clamp(0.0, 1.0);
            let fade = 1.0 - t * t * (3.0 - 2.0 * t);
            if fade > 0.0 {
                self.fins.push([edge as u32, fade.to_bits()]);
            }
        }
        Ok(&self.fins)
    }
}

impl GpuFur {
    /// The silhouette decision made on the CPU instead of by the compute pass of
    /// [`FurRenderer::prepare_fins`](crate::FurRenderer::prepare_fins): decides which fins show
    /// for the base vertices `positions` (the first `V` are used: layer 0 of the shared array as
    /// drawn, model space), `frame` (the one given to [`GpuFur::prepare`]) and the camera at
    /// `camera_position_world`, and writes the fins' list and indirect draw with `queue`. Draw
    /// with [`crate::FurDrawSettings::silhouette_fins`] as after the compute pass; record no
    /// compute pass for this fur and view. Returns the number of fins kept (0 for a fur without
    /// fins).
    ///
    /// # Errors
    /// [`RenderError::Count`] when `silhouette` was made for a fur with another count of edges
    /// with fins, or
    /// `positions` holds fewer than `V` positions.
    pub fn prepare_fins_on_cpu(
        &self,
        queue: &wgpu::Queue,
        silhouette: &mut CpuSilhouette,
        positions: &[Vec3],
        frame: &FurFrame,
        camera_position_world: Vec3,
    ) -> Result<u32, RenderError> {
        let expected = self.geometry().shape.fin_edge_count as usize;
        if silhouette.edge_count() != expected {
            return Err(RenderError::Count {
                what: "CPU silhouette edges",
                expected,
                got: silhouette.edge_count(),
                rule: "the fur's edges with fins (CpuSilhouette::of)",
            });
        }
        let Some(list) = self.fin_list() else {
            return Ok(0);
        };
        let fins = silhouette.decide(positions, frame, camera_position_world)?;
        list.write(queue, self.slot(), fins, frame.level.shells(self.layers()));
        Ok(fins.len() as u32)
    }
}

/// `v` at unit length, or `fallback` when it is (nearly) zero.
fn unit_or(v: Vec3, fallback: Vec3) -> Vec3 {
    let length_squared = v.length_squared();
    if length_squared > 1e-20 { v / length_squared.sqrt() } else { fallback }
}
