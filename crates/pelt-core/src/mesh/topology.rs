//! Undirected edges of a triangle list, their faces, and what is wrong with them.

use std::collections::HashMap;

/// Marks a missing face in [`Mesh::edge_faces`](super::Mesh::edge_faces) (a boundary edge has only one).
pub const NO_FACE: u32 = u32::MAX;

/// Undirected edges of a triangle list and what is wrong with them.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Topology {
    /// Undirected edges, each `[low, high]`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// The faces beside each edge (`NO_FACE` for a missing second one).
    pub edge_faces: Vec<[u32; 2]>,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Edges with more than two faces.
    pub non_manifold_edges: usize,
    /// Edges whose two faces traverse them in the same direction.
    pub inconsistent_winding_edges: usize,
}

impl Topology {
    /// Builds the sorted undirected edge list of `triangles`.
    #[must_use]
    pub fn build(triangles: &[[u32; 3]]) -> Self {
        let half_edges = sorted_half_edges(triangles);
        let mut topology = Self::default();
        let mut start = 0;
        while start < half_edges.len() {
            let (a, b, _, _) = half_edges[start];
            let mut end = start + 1;
            while end < half_edges.len() && half_edges[end].0 == a && half_edges[end].1 == b {
                end += 1;
            }
            let uses = &half_edges[start..end];
            topology.edges.push([a, b]);
            topology.edge_faces.push([uses[0].2, uses.get(1).map_or(NO_FACE, |u| u.2)]);
            match uses.len() {
                1 => topology.boundary_edges += 1,
                2 => {
                    if uses[0].3 == uses[1].3 {
                        topology.inconsistent_winding_edges += 1;
                    }
                }
                _ => topology.non_manifold_edges += 1,
            }
            start = end;
        }
        topology
    }
}

impl Topology {
    /// Connected components of the boundary edges (a hole or an open rim is one loop).
    #[must_use]
    pub fn boundary_loops(&self) -> usize {
        fn root(parent: &mut HashMap<u32, u32>, mut v: u32) -> u32 {
            while let Some(&p) = parent.get(&v).filter(|&&p| p != v) {
                // Path halving keeps the chains short.
                let grandparent = parent.get(&p).copied().unwrap_or(p);
                parent.insert(v, grandparent);
                v = grandparent;
            }
            v
        }
        let mut parent: HashMap<u32, u32> = HashMap::new();
        let boundary = self.edges.iter().zip(&self.edge_faces).filter(|(_, faces)| faces[1] == NO_FACE);
        for ([a, b], _) in boundary {
            parent.entry(*a).or_insert(*a);
            parent.entry(*b).or_insert(*b);
            let (ra, rb) = (root(&mut parent, *a), root(&mut parent, *b));
            if ra != rb {
                parent.insert(ra.max(rb), ra.min(rb));
            }
        }
        let vertices: Vec<u32> = parent.keys().copied().collect();
        vertices.into_iter().filter(|&v| root(&mut parent, v) == v).count()
    }
}

/// `(low, high, face, forward)` for every half-edge, sorted so each edge's uses are adjacent.
pub(super) fn sorted_half_edges(triangles: &[[u32; 3]]) -> Vec<(u32, u32, u32, bool)> {
    let mut half_edges = Vec::with_capacity(triangles.len() * 3);
    for (face, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            half_edges.push((a.min(b), a.max(b), face as u32, a < b));
        }
    }
    half_edges.sort_unstable();
    half_edges
}
