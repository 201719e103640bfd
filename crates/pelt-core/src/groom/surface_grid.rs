//! Closest points on a mesh's surface within a tolerance, through a grid of its triangles.

use std::collections::HashMap;

use glam::Vec3;

use crate::body::closest_on_triangle;
use crate::mesh::Mesh;

/// The mesh's triangles bucketed in cubic cells, each triangle in every cell its box (grown by
/// the tolerance) touches, so a root's cell lists every triangle within the tolerance of it.
pub(super) struct TriangleGrid {
    cell: f32,
    tolerance: f32,
    cells: HashMap<[i32; 3], Vec<u32>>,
}

impl TriangleGrid {
    pub(super) fn new(mesh: &Mesh, tolerance: f32) -> Self {
        let cell = (mesh.mean_edge_length() * 2.0).max(tolerance * 2.0).max(1e-6);
        let mut cells: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        let key = |p: Vec3| (p / cell).floor().as_ivec3().to_array();
        for (t, corners) in mesh.triangles.iter().enumerate() {
            let [a, b, c] = corners.map(|j| mesh.positions[j as usize]);
            let low = key(a.min(b).min(c) - tolerance);
            let high = key(a.max(b).max(c) + tolerance);
            for x in low[0]..=high[0] {
                for y in low[1]..=high[1] {
                    for z in low[2]..=high[2] {
                        cells.entry([x, y, z]).or_default().push(t as u32);
                    }
                }
            }
        }
        Self { cell, tolerance, cells }
    }

    /// The closest point within the tolerance: triangle, barycentric weights, distance.
    pub(super) fn closest(&self, mesh: &Mesh, p: Vec3) -> Option<(usize, [f32; 3], f32)> {
        let key = (p / self.cell).floor().as_ivec3().to_array();
        let mut best: Option<(usize, [f32; 3], f32)> = None;
        for &t in self.cells.get(&key)? {
            let [a, b, c] = mesh.triangles[t as usize].map(|j| mesh.positions[j as usize]);
            let w = closest_on_triangle(p, a, b, c);
            let distance = (a * w[0] + b * w[1] + c * w[2]).distance(p);
            if distance <= self.tolerance && best.is_none_or(|(_, _, d)| distance < d) {
                best = Some((t as usize, w, distance));
            }
        }
        best
    }

    /// The distance to the surface by brute force (for reporting how far off a root lies).
    pub(super) fn any_distance(&self, mesh: &Mesh, p: Vec3) -> f32 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|j| mesh.positions[j as usize]);
                let w = closest_on_triangle(p, a, b, c);
                (a * w[0] + b * w[1] + c * w[2]).distance(p)
            })
            .fold(f32::INFINITY, f32::min)
    }
}
