//! The unified shell-and-fin structure (the paper's contribution) and the separated structure of
//! Lengyel et al. 2001 it is measured against.
//!
//! One shared vertex array `NV[i*V + j] = BV_j + G_j * (i / L) * length_j` (layer `i = 0..=L`,
//! base vertex `j`, growing vector `G_j`) serves both the shells (every layer repeats the base
//! triangles, offset by `i*V`) and the fins (the quad `(i,a) (i,b) (i+1,b) (i+1,a)` on every edge
//! `(a, b)` and every `i < L`). Nothing is replicated per layer: the GPU holds this array once,
//! plus the base triangles and the edge list.

mod footprint;

use glam::{Quat, Vec2, Vec3};

pub use footprint::{Footprint, SeparatedStructure};

use crate::groom::{Groom, TangentFrame, tangent_frames};
use crate::mesh::Mesh;
use crate::rng;

/// The largest layer count Pelt accepts (the paper uses 16 and 32).
pub const MAX_LAYERS: u32 = 128;

/// Bytes of one shared-vertex position on the GPU (three packed `f32`).
pub const POSITION_BYTES: u64 = 12;
/// Bytes of one full vertex of the separated structure: position, normal (3 x f32 each) and uv.
pub const SEPARATED_VERTEX_BYTES: u64 = 12 + 12 + 8;
/// Bytes of one index.
pub const INDEX_BYTES: u64 = 4;

/// Errors from building a fur structure.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FurError {
    /// A layer count outside `1..=MAX_LAYERS`.
    #[error("layers must be between 1 and {MAX_LAYERS}, got {0}")]
    Layers(u32),
    /// A negative or non-finite fur length.
    #[error("fur length must be finite and not negative, got {0}")]
    Length(f32),
    /// A per-vertex length map of the wrong size.
    #[error("the length map has {got} entries but the mesh has {expected} vertices")]
    LengthMapSize {
        /// Vertices of the mesh.
        expected: usize,
        /// Entries in the map.
        got: usize,
    },
    /// A groom that does not fit the mesh (wrong size, values out of range).
    #[error("the groom does not fit the mesh: {0}")]
    Groom(String),
}

/// How long the fur is.
#[derive(Clone, Debug, PartialEq)]
pub enum FurLength {
    /// The same length (world units) everywhere.
    Constant(f32),
    /// One length per base vertex (world units), e.g. painted or read from a map.
    PerVertex(Vec<f32>),
}

/// Which way the fur grows from each base vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GrowthDirection {
    /// Each direction is tilted away from the normal by up to this angle (radians), seeded.
    pub random_angle_rad: f32,
    /// Seed for the random tilt.
    pub seed: u64,
    /// A world-space combing direction; only its part along the surface matters.
    pub comb: Vec3,
    /// How far the fur leans into the comb: 0 = along the normal, 1 = flat along the surface.
    pub comb_blend: f32,
}

impl Default for GrowthDirection {
    fn default() -> Self {
        Self { random_angle_rad: 0.0, seed: 0, comb: Vec3::ZERO, comb_blend: 0.0 }
    }
}

impl GrowthDirection {
    /// The growing vector for a vertex with unit normal `normal` (always a unit vector on the
    /// outside of the surface).
    #[must_use]
    pub fn apply(&self, vertex: usize, normal: Vec3) -> Vec3 {
        let mut direction = normal;
        let along_surface = self.comb - normal * self.comb.dot(normal);
        if let Some(tangent) = along_surface.try_normalize() {
            // Keep a little of the normal so combed fur never lies exactly in the surface.
            let blend = self.comb_blend.clamp(0.0, 1.0) * 0.95;
            direction = (normal * (1.0 - blend) + tangent * blend).normalize();
        }
        if self.random_angle_rad > 0.0 {
            let bits = rng::hash(self.seed, vertex as u64, 0x6469_7265, 0);
            let turn = rng::unit_f32(bits) * std::f32::consts::TAU;
            let tilt = rng::unit_f32(rng::mix64(bits)) * self.random_angle_rad.min(1.4);
            let (u, v) = direction.any_orthonormal_pair();
            let axis = u * turn.cos() + v * turn.sin();
            direction = (Quat::from_axis_angle(axis, tilt) * direction).normalize();
        }
        // Never below the surface, whatever the tilt and comb add up to.
        let height = direction.dot(normal);
        if height < MIN_HEIGHT {
            let tangent = (direction - normal * height).normalize_or_zero();
            direction = normal * MIN_HEIGHT + tangent * (1.0 - MIN_HEIGHT * MIN_HEIGHT).sqrt();
        }
        direction
    }
}

impl GrowthDirection {
    /// The growing vector of a groomed vertex: combed along the groom's `flow` in its tangent
    /// `frame` (in place of [`GrowthDirection::comb`]), leaning by `comb_blend` times the flow's
    /// length (at most 1), then tilted as [`GrowthDirection::apply`] tilts.
    #[must_use]
    pub fn groomed(&self, vertex: usize, normal: Vec3, frame: TangentFrame, flow: Vec2) -> Vec3 {
        let comb = frame.to_surface(flow);
        let comb_blend = self.comb_blend * flow.length().min(1.0);
        GrowthDirection { comb, comb_blend, ..*self }.apply(vertex, normal)
    }
}

/// The least cosine between a growing vector and its normal: fur always leaves the surface.
const MIN_HEIGHT: f32 = 0.1;

/// Everything needed to grow the unified structure on a mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct FurParams {
    /// Number of shells `L` above the base (layer 0 is the base surface, layer `L` the tips).
    pub layers: u32,
    /// How long the strands are.
    pub length: FurLength,
    /// Which way the strands grow out of the surface.
    pub direction: GrowthDirection,
}

/// The unified shell-and-fin structure on one base mesh.
#[derive(Clone, Debug)]
pub struct FurStructure {
    /// The base surface (layer 0): triangles for the shells, edges for the fins.
    pub mesh: Mesh,
    /// `L`: the number of shells above the base.
    pub layers: u32,
    /// Unit growing vector per base vertex.
    pub directions: Vec<Vec3>,
    /// Fur length per base vertex (world units).
    pub lengths: Vec<f32>,
    /// The shared vertex array `NV`, `(L + 1) * V` entries, layer-major: `NV[i*V + j]`.
    pub positions: Vec<Vec3>,
    /// The groom it was grown with (`None`: uniform fur). Its lengths and directions are already
    /// in `lengths`, `directions` and `positions`; bald regions are what
    /// [`FurStructure::triangle_has_fur`] and [`FurStructure::edge_has_fins`] say; density,
    /// clump and tint are the renderer's to apply.
    pub groom: Option<Groom>,
}

impl FurStructure {
    /// Grows the rest pose on `mesh` (the paper's steps 1-6).
    ///
    /// # Errors
    /// [`FurError`] for a layer count outside `1..=MAX_LAYERS`, a negative or non-finite
    /// length, or a length map of the wrong size.
    pub fn new(mesh: Mesh, params: &FurParams) -> Result<Self, FurError> {
        Self::new_groomed(mesh, params, None)
    }

    /// Grows the rest pose on `mesh` with a groom (`None`: as [`FurStructure::new`], to the bit).
    ///
    /// Vertex `j` grows `params.length` times the groom's length factor. With a direction map,
    /// its comb is the groom's flow in the vertex's [`crate::groom::TangentFrame`] (in place of
    /// `params.direction.comb`), leaning by `comb_blend` times the flow's length (at most 1);
    /// the random tilt applies as before. The groom travels with the structure (`groom`).
    ///
    /// # Errors
    /// As [`FurStructure::new`], and [`FurError::Groom`] for a groom of the wrong size or with
    /// values out of range.
    pub fn new_groomed(mesh: Mesh, params: &FurParams, groom: Option<Groom>) -> Result<Self, FurError> {
        if params.layers == 0 || params.layers > MAX_LAYERS {
            return Err(FurError::Layers(params.layers));
        }
        let v = mesh.vertex_count();
        let mut lengths = match &params.length {
            FurLength::Constant(l) => vec![*l; v],
            FurLength::PerVertex(map) if map.len() == v => map.clone(),
            FurLength::PerVertex(map) => return Err(FurError::LengthMapSize { expected: v, got: map.len() }),
        };
        if let Some(bad) = lengths.iter().find(|l| !l.is_finite() || **l < 0.0) {
            return Err(FurError::Length(*bad));
        }
        let groom = groom.filter(|g| !g.is_uniform());
        if let Some(groom) = &groom {
            groom.validate(v, "the groom").map_err(|e| FurError::Groom(e.to_string()))?;
            if let Some(factors) = &groom.length {
                lengths.iter_mut().zip(factors).for_each(|(l, f)| *l *= f);
            }
            if let Some(bad) = lengths.iter().find(|l| !l.is_finite()) {
                return Err(FurError::Length(*bad));
            }
        }
        let directions: Vec<Vec3> = match groom.as_ref().and_then(|g| g.direction.as_ref()) {
            None => mesh.normals.iter().enumerate().map(|(j, n)| params.direction.apply(j, *n)).collect(),
            Some(flows) => {
                let frames = tangent_frames(&mesh);
                (mesh.normals.iter().zip(&frames).zip(flows).enumerate())
                    .map(|(j, ((n, frame), flow))| params.direction.groomed(j, *n, *frame, *flow))
                    .collect()
            }
        };
        let layers = params.layers;
        let mut positions = Vec::with_capacity((layers as usize + 1) * v);
        for i in 0..=layers {
            let fraction = i as f32 / layers as f32;
            positions.extend(
                mesh.positions.iter().zip(&directions).zip(&lengths).map(|((bv, g), l)| *bv + *g * (fraction * l)),
            );
        }
        Ok(Self { mesh, layers, directions, lengths, positions, groom })
    }

    /// The same fur with every strand `scale` times as long: each layer's node moved along its
    /// strand from the root, the roots, directions and topology kept (a herd member's
    /// `length_scale`; the shells, fins and textures stay shared).
    #[must_use]
    pub fn with_length_scale(&self, scale: f32) -> Self {
        let v = self.vertex_count();
        let mut scaled = self.clone();
        for (k, p) in scaled.positions.iter_mut().enumerate().skip(v) {
            let root = self.positions[k % v];
            *p = root + (*p - root) * scale;
        }
        for length in &mut scaled.lengths {
            *length *= scale;
        }
        scaled
    }

    /// Whether base triangle `t` gets shell faces: not when all three of its vertices are bald
    /// (so the fur tapers to nothing across the triangles around a bald patch). Always without
    /// a groom.
    #[must_use]
    pub fn triangle_has_fur(&self, t: usize) -> bool {
        self.groom.as_ref().is_none_or(|g| !self.mesh.triangles[t].iter().all(|&j| g.is_bald(j as usize)))
    }

    /// Whether edge `e` gets fin faces: not when both its ends are bald (the fin would have no
    /// height). Every edge with fins borders a triangle with fur.
    #[must_use]
    pub fn edge_has_fins(&self, e: usize) -> bool {
        self.groom.as_ref().is_none_or(|g| !self.mesh.edges[e].iter().all(|&j| g.is_bald(j as usize)))
    }

    /// The base triangles with fur ([`FurStructure::triangle_has_fur`]), in mesh order: the
    /// shells' index list.
    #[must_use]
    pub fn furred_triangles(&self) -> Vec<u32> {
        (0..self.mesh.triangles.len()).filter(|&t| self.triangle_has_fur(t)).map(|t| t as u32).collect()
    }

    /// The edges with fins ([`FurStructure::edge_has_fins`]), in mesh order.
    #[must_use]
    pub fn fin_edges(&self) -> Vec<u32> {
        (0..self.mesh.edges.len()).filter(|&e| self.edge_has_fins(e)).map(|e| e as u32).collect()
    }

    /// The base vertices whose strand differs between this structure and `other` (the same
    /// mesh regrown with another groom): length, growth direction, or whether it is bald, to
    /// the bit. What a groom edit hands [`crate::sim::Simulation::regroom`].
    #[must_use]
    pub fn changed_strands(&self, other: &FurStructure) -> Vec<u32> {
        let bald = |fur: &FurStructure, j: usize| fur.groom.as_ref().is_some_and(|g| g.is_bald(j));
        (0..self.vertex_count().min(other.vertex_count()))
            .filter(|&j| {
                self.lengths[j].to_bits() != other.lengths[j].to_bits()
                    || self.directions[j].to_array().map(f32::to_bits)
                        != other.directions[j].to_array().map(f32::to_bits)
                    || bald(self, j) != bald(other, j)
            })
            .map(|j| j as u32)
            .collect()
    }

    /// `V`, the base vertex count (the stride between layers).
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.mesh.vertex_count()
    }

    /// Index of `NV[layer * V + vertex]` in the shared array.
    #[must_use]
    #[inline]
    pub fn index(&self, layer: u32, vertex: u32) -> u32 {
        layer * self.vertex_count() as u32 + vertex
    }

    /// The shared-vertex indices of base triangle `t` in shell `layer`.
    #[must_use]
    pub fn shell_triangle(&self, layer: u32, t: usize) -> [u32; 3] {
        self.mesh.triangles[t].map(|j| self.index(layer, j))
    }

    /// The fin quad on `edge` between layers `layer` and `layer + 1`:
    /// `(i,a) (i,b) (i+1,b) (i+1,a)`.
    ///
    /// # Panics
    /// If `layer >= L`.
    #[must_use]
    pub fn fin_quad(&self, edge: usize, layer: u32) -> [u32; 4] {
        assert!(layer < self.layers, "fin quads join layer i to i + 1 < L + 1");
        let [a, b] = self.mesh.edges[edge];
        [self.index(layer, a), self.index(layer, b), self.index(layer + 1, b), self.index(layer + 1, a)]
    }

    /// Counts and GPU bytes of this unified structure (faces: those drawn, bald regions left out).
    #[must_use]
    pub fn footprint(&self) -> Footprint {
        Footprint::unified(self)
    }
}

#[cfg(test)]
mod tests {
    use proptest::prelude::*;

    use super::*;
    use crate::mesh::builtin::Builtin;

    fn grow(builtin: Builtin, layers: u32, direction: GrowthDirection) -> FurStructure {
        let (mesh, _) = builtin.mesh();
        FurStructure::new(mesh, &FurParams { layers, length: FurLength::Constant(0.3), direction }).unwrap()
    }

    #[test]
    fn box_matches_table_2() {
        let fur = grow(Builtin::Box, 16, GrowthDirection::default());
        assert_eq!(fur.positions.len(), 5_032);
        let two = SeparatedStructure { layers: 16, fin_faces: 2 }.footprint(&fur.mesh);
        let thirty = SeparatedStructure { layers: 16, fin_faces: 30 }.footprint(&fur.mesh);
        assert_eq!(fur.footprint().vertices, 5_032);
        assert_eq!(two.vertices, 6_796);
        assert_eq!(thirty.vertices, 31_492);
        let vertices = |f: &Footprint| f.vertices;
        let saved_vs_two = fur.footprint().savings_percent(&two, vertices);
        let saved_vs_thirty = fur.footprint().savings_percent(&thirty, vertices);
        assert!((saved_vs_two - 25.96).abs() < 0.01, "{saved_vs_two}");
        assert!((saved_vs_thirty - 84.02).abs() < 0.01, "{saved_vs_thirty}");
        // Unified fins: 2L triangles per edge.
        assert_eq!(fur.footprint().fin_faces, 2 * 16 * 882);
    }

    #[test]
    fn bad_params_are_errors() {
        let (mesh, _) = Builtin::Box.mesh();
        let params = |layers, length| FurParams { layers, length, direction: GrowthDirection::default() };
        assert_eq!(
            FurStructure::new(mesh.clone(), &params(0, FurLength::Constant(1.0))).unwrap_err(),
            FurError::Layers(0)
        );
        assert!(FurStructure::new(mesh.clone(), &params(4, FurLength::Constant(-1.0))).is_err());
        assert!(FurStructure::new(mesh.clone(), &params(4, FurLength::Constant(f32::NAN))).is_err());
        assert!(FurStructure::new(mesh, &params(4, FurLength::PerVertex(vec![1.0; 3]))).is_err());
    }

    #[test]
    fn fin_quads_join_neighbouring_layers_of_one_edge() {
        let fur = grow(Builtin::Torus, 5, GrowthDirection::default());
        let v = fur.vertex_count() as u32;
        for (e, &[a, b]) in fur.mesh.edges.iter().enumerate().step_by(37) {
            for i in 0..fur.layers {
                let q = fur.fin_quad(e, i);
                assert_eq!(q, [i * v + a, i * v + b, (i + 1) * v + b, (i + 1) * v + a]);
                assert!(q.iter().all(|&k| (k as usize) < fur.positions.len()));
            }
        }
    }

    proptest! {
        #[test]
        fn every_shared_vertex_lies_on_its_base_ray(
            layers in 1u32..40,
            random_deg in 0.0f32..60.0,
            comb_blend in 0.0f32..1.0,
            seed in any::<u64>(),
            which in 0usize..5,
        ) {
            let direction = GrowthDirection {
                random_angle_rad: random_deg.to_radians(),
                seed,
                comb: Vec3::new(0.3, -1.0, 0.2),
                comb_blend,
            };
            let fur = grow(Builtin::ALL[which], layers, direction);
            let v = fur.vertex_count();
            prop_assert_eq!(fur.positions.len(), v * (layers as usize + 1));
            for j in (0..v).step_by(7) {
                let g = fur.directions[j];
                prop_assert!((g.length() - 1.0).abs() < 1e-5);
                prop_assert!(g.dot(fur.mesh.normals[j]) > 0.0, "fur grows outward");
                for i in 0..=layers {
                    let expected = fur.mesh.positions[j] + g * (i as f32 / layers as f32 * fur.lengths[j]);
                    let got = fur.positions[fur.index(i, j as u32) as usize];
                    prop_assert!(got.distance(expected) < 1e-5);
                }
            }
        }
    }
}
