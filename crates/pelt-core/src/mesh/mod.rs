//! Triangle meshes: import, repair, normals and edge topology.
//!
//! Every loader produces a [`RawMesh`] (an indexed triangle list straight from the file) and
//! hands it to [`Mesh::from_raw`], which validates, welds, repairs and measures it. The result is
//! a clean, indexed, manifold-or-reported mesh plus a [`MeshReport`] the caller can print.

pub mod builtin;
mod gltf;
mod obj;

use std::collections::HashMap;
use std::fmt;
use std::path::{Path, PathBuf};

use glam::{Mat4, Vec2, Vec3};

/// Marks a missing face in [`Mesh::edge_faces`] (a boundary edge has only one).
pub const NO_FACE: u32 = u32::MAX;

/// Errors from reading or validating a mesh. Each names the file (or built-in) it came from.
#[derive(Debug, thiserror::Error)]
pub enum MeshError {
    // The cause is part of the message (not a `source`) so it is printed exactly once.
    /// The file could not be read.
    #[error("{}: cannot read the file: {error}", file.display())]
    Io {
        /// The file.
        file: PathBuf,
        /// Why it could not be read.
        error: std::io::Error,
    },
    /// The file's extension is no mesh format Pelt reads.
    #[error("{}: unknown mesh format {extension:?} (Pelt reads .obj, .gltf and .glb)", file.display())]
    UnknownFormat {
        /// The file.
        file: PathBuf,
        /// Its extension.
        extension: String,
    },
    /// The file is malformed.
    #[error("{}{}: {message}", file.display(), line.map(|l| format!(":{l}")).unwrap_or_default())]
    Parse {
        /// The file.
        file: PathBuf,
        /// The line, where the format has lines.
        line: Option<usize>,
        /// What is wrong.
        message: String,
    },
    /// No usable triangle is left.
    #[error("{}: the mesh has no triangles{detail}", file.display())]
    NoTriangles {
        /// The file.
        file: PathBuf,
        /// What was dropped, if anything.
        detail: String,
    },
    /// A triangle refers to a vertex that does not exist.
    #[error("{}: triangle {triangle} uses vertex index {index}, but the mesh has only {vertex_count} vertices", file.display())]
    IndexOutOfRange {
        /// The file.
        file: PathBuf,
        /// The triangle.
        triangle: usize,
        /// The vertex index it uses.
        index: u32,
        /// Vertices in the mesh.
        vertex_count: usize,
    },
    /// A vertex has a NaN or infinite coordinate.
    #[error("{}: vertex {vertex} has a non-finite coordinate {position:?} (NaN or infinity)", file.display())]
    NonFinite {
        /// The file.
        file: PathBuf,
        /// The vertex.
        vertex: usize,
        /// Its coordinates.
        position: [f32; 3],
    },
}

/// An indexed triangle list as read from a file, before any repair.
///
/// `normals` and `uvs`, when present, have one entry per position.
#[derive(Clone, Debug, Default)]
pub struct RawMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals, when the file has them.
    pub normals: Option<Vec<Vec3>>,
    /// Texture coordinates, when the file has them.
    pub uvs: Option<Vec<Vec2>>,
    /// Triangles as indices into `positions`.
    pub triangles: Vec<[u32; 3]>,
}

/// How [`Mesh::from_raw`] treats its input.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImportOptions {
    /// Merge vertices at the same position so adjacency (and fins) exist on triangle soups.
    pub weld: bool,
    /// Welding distance relative to the bounding-box diagonal.
    pub weld_tolerance: f32,
    /// Flip triangles so neighbours agree on winding and closed parts face outward (fur grows
    /// along normals computed from the winding, and fins need consistent neighbours).
    pub orient: bool,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self { weld: true, weld_tolerance: 1e-6, orient: true }
    }
}

/// Where the vertex normals came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum NormalSource {
    /// From the file (averaged where welding merged vertices).
    File,
    /// Computed as angle-weighted smooth normals because the file had none (or broken ones).
    Computed,
}

/// What [`Mesh::from_raw`] found and repaired.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct MeshReport {
    /// The file or built-in this mesh came from.
    pub source: String,
    /// Vertices in the file.
    pub input_vertices: usize,
    /// Triangles in the file.
    pub input_triangles: usize,
    /// Vertices merged into another one by welding.
    pub welded_vertices: usize,
    /// Triangles dropped for having no area.
    pub dropped_zero_area_triangles: usize,
    /// Triangles dropped for using one vertex twice.
    pub dropped_repeated_index_triangles: usize,
    /// Triangles over the same three vertices as an earlier one, either winding (double-sided
    /// or doubled geometry would make every edge non-manifold and draw its fins twice).
    pub dropped_duplicate_triangles: usize,
    /// Vertices dropped because no triangle uses them.
    pub dropped_unreferenced_vertices: usize,
    /// Triangles flipped to agree with their neighbours (or to turn a closed part outward).
    pub reoriented_triangles: usize,
    /// Where the normals came from.
    pub normals: NormalSource,
    /// Whether the mesh has texture coordinates (none are generated when the file has none).
    pub has_uvs: bool,
    /// Edges with one face.
    pub boundary_edges: usize,
    /// Connected chains of boundary edges: the holes and open rims (0 on a closed mesh).
    pub boundary_loops: usize,
    /// Edges with more than two faces.
    pub non_manifold_edges: usize,
    /// Edges whose two faces traverse them in the same direction (flipped winding).
    pub inconsistent_winding_edges: usize,
    /// Vertices after repair.
    pub vertices: usize,
    /// Triangles after repair.
    pub triangles: usize,
    /// Undirected edges after repair.
    pub edges: usize,
}

impl MeshReport {
    /// Whether every edge has exactly two consistently wound faces.
    #[must_use]
    pub fn is_closed_manifold(&self) -> bool {
        self.boundary_edges == 0 && self.non_manifold_edges == 0 && self.inconsistent_winding_edges == 0
    }
}

impl fmt::Display for MeshReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "mesh {}", self.source)?;
        writeln!(
            f,
            "  read {} vertices, {} triangles; kept {} vertices, {} triangles, {} edges",
            self.input_vertices, self.input_triangles, self.vertices, self.triangles, self.edges
        )?;
        writeln!(f, "  welded {} duplicate vertices", self.welded_vertices)?;
        writeln!(
            f,
            "  dropped {} zero-area, {} repeated-index and {} duplicate triangles, {} unreferenced vertices",
            self.dropped_zero_area_triangles,
            self.dropped_repeated_index_triangles,
            self.dropped_duplicate_triangles,
            self.dropped_unreferenced_vertices
        )?;
        writeln!(f, "  flipped {} triangles to a consistent, outward winding", self.reoriented_triangles)?;
        let normals = match self.normals {
            NormalSource::File => "from the file",
            NormalSource::Computed => "computed (smooth)",
        };
        let uvs = if self.has_uvs { "from the file" } else { "none in the file (none generated)" };
        writeln!(f, "  normals {normals}; uvs {uvs}")?;
        write!(
            f,
            "  {} boundary edges in {} loops, {} non-manifold edges, {} edges with inconsistent winding",
            self.boundary_edges, self.boundary_loops, self.non_manifold_edges, self.inconsistent_winding_edges
        )
    }
}

/// A clean triangle mesh: the base surface the fur grows from.
#[derive(Clone, Debug, PartialEq)]
pub struct Mesh {
    /// Vertex positions `BV_j`.
    pub positions: Vec<Vec3>,
    /// Unit vertex normals `BN_j`.
    pub normals: Vec<Vec3>,
    /// Texture coordinates per triangle corner (kept per corner so UV seams survive welding).
    pub corner_uvs: Option<Vec<[Vec2; 3]>>,
    /// Triangles, counter-clockwise seen from outside.
    pub triangles: Vec<[u32; 3]>,
    /// Undirected edges `(a, b)` with `a < b`, sorted.
    pub edges: Vec<[u32; 2]>,
    /// The (up to) two triangles next to each edge; [`NO_FACE`] where there is none.
    pub edge_faces: Vec<[u32; 2]>,
}

impl Mesh {
    /// Loads a mesh file (`.obj`, `.gltf`, `.glb`), chosen by extension.
    ///
    /// # Errors
    /// A [`MeshError`] naming the file for missing files, unknown formats, parse errors and
    /// unrepairable content.
    pub fn load(path: &Path, options: &ImportOptions) -> Result<(Self, MeshReport), MeshError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
        if !path.exists() {
            return Err(MeshError::Io {
                file: path.to_path_buf(),
                error: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
            });
        }
        let raw = match extension.as_str() {
            "obj" => obj::load(path)?,
            "gltf" | "glb" => gltf::load(path)?,
            _ => return Err(MeshError::UnknownFormat { file: path.to_path_buf(), extension }),
        };
        Self::from_raw(raw, path, options)
    }

    /// Parses OBJ text held in memory (used for embedded meshes and tests).
    ///
    /// # Errors
    /// As [`Mesh::load`]; `name` stands in for the file name in messages.
    pub fn from_obj_str(text: &str, name: &Path, options: &ImportOptions) -> Result<(Self, MeshReport), MeshError> {
        let raw = obj::parse(text, name)?;
        Self::from_raw(raw, name, options)
    }

    /// Parses glTF 2.0 held in memory (`.gltf` JSON with embedded `data:` buffers, or `.glb`).
    ///
    /// # Errors
    /// As [`Mesh::load`]; `name` stands in for the file name in messages. Buffers in external
    /// files cannot be read this way.
    pub fn from_gltf_slice(
        bytes: &[u8],
        name: &Path,
        options: &ImportOptions,
    ) -> Result<(Self, MeshReport), MeshError> {
        let raw = gltf::parse(bytes, name, None)?;
        Self::from_raw(raw, name, options)
    }

    /// Validates, welds and repairs a raw mesh.
    ///
    /// # Errors
    /// [`MeshError::IndexOutOfRange`], [`MeshError::NonFinite`] or [`MeshError::NoTriangles`]
    /// (also when every triangle was degenerate).
    pub fn from_raw(raw: RawMesh, file: &Path, options: &ImportOptions) -> Result<(Self, MeshReport), MeshError> {
        let file_buf = || file.to_path_buf();
        let input_vertices = raw.positions.len();
        let input_triangles = raw.triangles.len();
        if raw.triangles.is_empty() {
            return Err(MeshError::NoTriangles { file: file_buf(), detail: String::new() });
        }
        for (triangle, corners) in raw.triangles.iter().enumerate() {
            if let Some(&index) = corners.iter().find(|&&i| i as usize >= input_vertices) {
                return Err(MeshError::IndexOutOfRange {
                    file: file_buf(),
                    triangle,
                    index,
                    vertex_count: input_vertices,
                });
            }
        }
        if let Some((vertex, p)) = raw.positions.iter().enumerate().find(|(_, p)| !p.is_finite()) {
            return Err(MeshError::NonFinite { file: file_buf(), vertex, position: p.to_array() });
        }
        let raw_normals = raw.normals.filter(|n| n.len() == input_vertices && n.iter().all(|v| v.is_finite()));
        let raw_uvs = raw.uvs.filter(|uv| uv.len() == input_vertices && uv.iter().all(|v| v.is_finite()));

        let (min, max) = bounds(&raw.positions);
        let diagonal = (max - min).length().max(f32::MIN_POSITIVE);

        // Weld: map every input vertex to a canonical one.
        let canonical: Vec<u32> = if options.weld {
            weld_map(&raw.positions, options.weld_tolerance * diagonal)
        } else {
            (0..input_vertices as u32).collect()
        };
        let welded_vertices = canonical.iter().enumerate().filter(|&(i, &c)| c as usize != i).count();

        // Drop degenerate triangles.
        let area_epsilon = (diagonal * 1e-7).powi(2);
        let mut dropped_repeated = 0;
        let mut dropped_zero_area = 0;
        let mut dropped_duplicate = 0;
        let mut seen = std::collections::HashSet::with_capacity(raw.triangles.len());
        let mut kept: Vec<([u32; 3], usize)> = Vec::with_capacity(raw.triangles.len());
        for (t, tri) in raw.triangles.iter().enumerate() {
            let w = tri.map(|i| canonical[i as usize]);
            if w[0] == w[1] || w[1] == w[2] || w[0] == w[2] {
                dropped_repeated += 1;
                continue;
            }
            let [a, b, c] = w.map(|i| raw.positions[i as usize]);
            if (b - a).cross(c - a).length_squared() * 0.25 <= area_epsilon {
                dropped_zero_area += 1;
                continue;
            }
            let mut corners = w;
            corners.sort_unstable();
            if !seen.insert(corners) {
                dropped_duplicate += 1;
                continue;
            }
            kept.push((w, t));
        }
        if kept.is_empty() {
            return Err(MeshError::NoTriangles {
                file: file_buf(),
                detail: format!(" left after repair (all {input_triangles} were degenerate)"),
            });
        }

        // Compact: keep referenced canonical vertices only, in input order.
        let mut new_index = vec![u32::MAX; input_vertices];
        let mut referenced = vec![false; input_vertices];
        for (tri, _) in &kept {
            for &i in tri {
                referenced[i as usize] = true;
            }
        }
        let mut positions = Vec::new();
        for (i, &is_used) in referenced.iter().enumerate() {
            if is_used {
                new_index[i] = positions.len() as u32;
                positions.push(raw.positions[i]);
            }
        }
        let canonical_count = canonical.iter().enumerate().filter(|&(i, &c)| c as usize == i).count();
        let dropped_unreferenced = canonical_count - positions.len();
        let mut triangles: Vec<[u32; 3]> = kept.iter().map(|(tri, _)| tri.map(|i| new_index[i as usize])).collect();
        let mut corner_uvs = raw_uvs
            .as_ref()
            .map(|uvs| kept.iter().map(|&(_, t)| raw.triangles[t].map(|i| uvs[i as usize])).collect::<Vec<_>>());
        let flips = if options.orient { orientation_flips(&positions, &triangles) } else { Vec::new() };
        for (t, _) in flips.iter().enumerate().filter(|&(_, &flip)| flip) {
            triangles[t].swap(1, 2);
            if let Some(uvs) = &mut corner_uvs {
                uvs[t].swap(1, 2);
            }
        }
        let reoriented_triangles = flips.iter().filter(|&&flip| flip).count();

        let computed = smooth_normals(&positions, &triangles);
        let (normals, normal_source) = match &raw_normals {
            Some(file_normals) => {
                let mut sum = vec![Vec3::ZERO; positions.len()];
                for (i, n) in file_normals.iter().enumerate() {
                    let target = new_index[canonical[i] as usize];
                    if target != u32::MAX {
                        sum[target as usize] += *n;
                    }
                }
                let normals = sum.iter().zip(&computed).map(|(s, c)| s.try_normalize().unwrap_or(*c)).collect();
                (normals, NormalSource::File)
            }
            None => (computed, NormalSource::Computed),
        };

        let topology = Topology::build(&triangles);
        let boundary_loops = topology.boundary_loops();
        let mesh =
            Mesh { positions, normals, corner_uvs, triangles, edges: topology.edges, edge_faces: topology.edge_faces };
        let report = MeshReport {
            source: file.display().to_string(),
            input_vertices,
            input_triangles,
            welded_vertices,
            dropped_zero_area_triangles: dropped_zero_area,
            dropped_repeated_index_triangles: dropped_repeated,
            dropped_duplicate_triangles: dropped_duplicate,
            dropped_unreferenced_vertices: dropped_unreferenced,
            reoriented_triangles,
            normals: normal_source,
            has_uvs: mesh.corner_uvs.is_some(),
            boundary_edges: topology.boundary_edges,
            boundary_loops,
            non_manifold_edges: topology.non_manifold_edges,
            inconsistent_winding_edges: topology.inconsistent_winding_edges,
            vertices: mesh.positions.len(),
            triangles: mesh.triangles.len(),
            edges: mesh.edges.len(),
        };
        Ok((mesh, report))
    }

    /// Number of vertices `V`.
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.positions.len()
    }

    /// Axis-aligned bounds `(min, max)`.
    #[must_use]
    pub fn bounds(&self) -> (Vec3, Vec3) {
        bounds(&self.positions)
    }

    /// A bounding sphere `(centre, radius)`: the box centre and the farthest vertex from it.
    #[must_use]
    pub fn bounding_sphere(&self) -> (Vec3, f32) {
        let (min, max) = self.bounds();
        let centre = (min + max) * 0.5;
        let radius = self.positions.iter().map(|p| p.distance(centre)).fold(0.0, f32::max);
        (centre, radius)
    }

    /// Unit normal of triangle `t` (zero for a degenerate one).
    #[must_use]
    pub fn face_normal(&self, t: usize) -> Vec3 {
        let [a, b, c] = self.triangles[t].map(|i| self.positions[i as usize]);
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Total surface area.
    #[must_use]
    pub fn surface_area(&self) -> f32 {
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.positions[i as usize]);
                (b - a).cross(c - a).length() * 0.5
            })
            .sum()
    }

    /// Mean edge length, a natural unit for fur length on an unknown mesh.
    #[must_use]
    pub fn mean_edge_length(&self) -> f32 {
        if self.edges.is_empty() {
            return 0.0;
        }
        let total: f32 =
            self.edges.iter().map(|[a, b]| self.positions[*a as usize].distance(self.positions[*b as usize])).sum();
        total / self.edges.len() as f32
    }

    /// Applies `world_from_local` to positions and normals in place.
    pub fn transform(&mut self, world_from_local: Mat4) {
        let normal_from_local = world_from_local.inverse().transpose();
        for p in &mut self.positions {
            *p = world_from_local.transform_point3(*p);
        }
        for n in &mut self.normals {
            *n = normal_from_local.transform_vector3(*n).normalize_or(*n);
        }
    }
}

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

/// Which triangles to flip so that every manifold edge is traversed in opposite directions by
/// its two faces. Each connected part (through manifold edges) is oriented from its first
/// triangle, then as a whole: a closed part to enclose positive volume (outward), an open part
/// to flip as few triangles as possible. A non-orientable part (a Moebius strip) keeps the
/// conflicts it cannot avoid; they stay counted as inconsistent winding.
fn orientation_flips(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<bool> {
    let half_edges = sorted_half_edges(triangles);
    // (neighbour, whether the two traverse the edge the same way, i.e. one must flip).
    let mut neighbours: Vec<Vec<(u32, bool)>> = vec![Vec::new(); triangles.len()];
    let mut is_open = vec![false; triangles.len()];
    for group in half_edges.chunk_by(|x, y| (x.0, x.1) == (y.0, y.1)) {
        if let [first, second] = group {
            let same_way = first.3 == second.3;
            neighbours[first.2 as usize].push((second.2, same_way));
            neighbours[second.2 as usize].push((first.2, same_way));
        } else {
            for use_ in group {
                is_open[use_.2 as usize] = true;
            }
        }
    }

    let mut flip = vec![false; triangles.len()];
    let mut visited = vec![false; triangles.len()];
    let mut part = Vec::new();
    for seed in 0..triangles.len() {
        if visited[seed] {
            continue;
        }
        visited[seed] = true;
        part.clear();
        part.push(seed as u32);
        let mut next = 0;
        while next < part.len() {
            let face = part[next] as usize;
            next += 1;
            for &(other, same_way) in &neighbours[face] {
                if !visited[other as usize] {
                    visited[other as usize] = true;
                    flip[other as usize] = flip[face] ^ same_way;
                    part.push(other);
                }
            }
        }
        let is_closed = part.iter().all(|&f| !is_open[f as usize]);
        let turn_around = if is_closed {
            let volume: f64 = part
                .iter()
                .map(|&f| {
                    let [a, b, c] = triangles[f as usize].map(|i| positions[i as usize].as_dvec3());
                    let v = a.dot(b.cross(c));
                    if flip[f as usize] { -v } else { v }
                })
                .sum();
            volume < 0.0
        } else {
            2 * part.iter().filter(|&&f| flip[f as usize]).count() > part.len()
        };
        if turn_around {
            for &f in &part {
                flip[f as usize] = !flip[f as usize];
            }
        }
    }
    flip
}

/// `(low, high, face, forward)` for every half-edge, sorted so each edge's uses are adjacent.
fn sorted_half_edges(triangles: &[[u32; 3]]) -> Vec<(u32, u32, u32, bool)> {
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

fn bounds(positions: &[Vec3]) -> (Vec3, Vec3) {
    positions
        .iter()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}

/// Maps each vertex to the first vertex within `tolerance` of it (a uniform grid, so near-linear).
fn weld_map(positions: &[Vec3], tolerance: f32) -> Vec<u32> {
    let cell = tolerance.max(f32::MIN_POSITIVE) * 2.0;
    let key = |p: Vec3| {
        let q = (p / cell).floor();
        (q.x as i64, q.y as i64, q.z as i64)
    };
    let mut grid: HashMap<(i64, i64, i64), Vec<u32>> = HashMap::with_capacity(positions.len());
    let mut canonical = Vec::with_capacity(positions.len());
    for (i, &p) in positions.iter().enumerate() {
        let (x, y, z) = key(p);
        let mut found = None;
        'search: for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(bucket) = grid.get(&(x + dx, y + dy, z + dz))
                        && let Some(&j) = bucket.iter().find(|&&j| positions[j as usize].distance(p) <= tolerance)
                    {
                        found = Some(j);
                        break 'search;
                    }
                }
            }
        }
        match found {
            Some(j) => canonical.push(j),
            None => {
                grid.entry((x, y, z)).or_default().push(i as u32);
                canonical.push(i as u32);
            }
        }
    }
    canonical
}

/// Angle-weighted smooth vertex normals. A vertex whose faces cancel out gets its first face's
/// normal, and an isolated one +Y, so every normal is a unit vector.
#[must_use]
pub fn smooth_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sum = vec![Vec3::ZERO; positions.len()];
    let mut first_face = vec![Vec3::ZERO; positions.len()];
    for tri in triangles {
        let p = tri.map(|i| positions[i as usize]);
        let face = (p[1] - p[0]).cross(p[2] - p[0]).normalize_or_zero();
        for k in 0..3 {
            let e1 = (p[(k + 1) % 3] - p[k]).normalize_or_zero();
            let e2 = (p[(k + 2) % 3] - p[k]).normalize_or_zero();
            let angle = e1.dot(e2).clamp(-1.0, 1.0).acos();
            let v = tri[k] as usize;
            sum[v] += face * angle;
            if first_face[v] == Vec3::ZERO {
                first_face[v] = face;
            }
        }
    }
    sum.iter()
        .zip(&first_face)
        .map(|(s, f)| s.try_normalize().or_else(|| f.try_normalize()).unwrap_or(Vec3::Y))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn raw(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> RawMesh {
        RawMesh {
            positions: positions.iter().map(|p| Vec3::from_array(*p)).collect(),
            triangles: triangles.to_vec(),
            ..RawMesh::default()
        }
    }

    fn tetrahedron() -> RawMesh {
        raw(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]],
            &[[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    }

    #[test]
    fn tetrahedron_is_closed_manifold() {
        let (mesh, report) = Mesh::from_raw(tetrahedron(), Path::new("tet"), &ImportOptions::default()).unwrap();
        assert_eq!(mesh.edges.len(), 6);
        assert_eq!(mesh.edges.len() * 2, mesh.triangles.len() * 3);
        assert!(report.is_closed_manifold(), "{report}");
        assert_eq!(report.normals, NormalSource::Computed);
        for n in &mesh.normals {
            assert!((n.length() - 1.0).abs() < 1e-5);
        }
    }

    #[test]
    fn welding_joins_a_triangle_soup() {
        let mut soup = RawMesh::default();
        let tet = tetrahedron();
        for tri in &tet.triangles {
            let base = soup.positions.len() as u32;
            soup.positions.extend(tri.map(|i| tet.positions[i as usize]));
            soup.triangles.push([base, base + 1, base + 2]);
        }
        let (mesh, report) = Mesh::from_raw(soup.clone(), Path::new("soup"), &ImportOptions::default()).unwrap();
        assert_eq!(mesh.vertex_count(), 4);
        assert_eq!(report.welded_vertices, 8);
        assert!(report.is_closed_manifold());
        let unwelded = ImportOptions { weld: false, ..ImportOptions::default() };
        let (mesh, report) = Mesh::from_raw(soup, Path::new("soup"), &unwelded).unwrap();
        assert_eq!(mesh.vertex_count(), 12);
        assert_eq!(report.boundary_edges, 12);
    }

    #[test]
    fn degenerate_triangles_and_unused_vertices_are_dropped_and_counted() {
        let mut m = tetrahedron();
        m.positions.push(Vec3::new(5.0, 5.0, 5.0)); // unreferenced
        m.positions.push(Vec3::new(0.5, 0.0, 0.0)); // on edge 0-1: zero-area triangle below
        m.triangles.push([0, 0, 1]);
        m.triangles.push([0, 1, 5]);
        let (mesh, report) = Mesh::from_raw(m, Path::new("t"), &ImportOptions::default()).unwrap();
        assert_eq!(report.dropped_repeated_index_triangles, 1);
        assert_eq!(report.dropped_zero_area_triangles, 1);
        assert_eq!(report.dropped_unreferenced_vertices, 2);
        assert_eq!(mesh.vertex_count(), 4);
        assert_eq!(mesh.triangles.len(), 4);
    }

    #[test]
    fn bad_input_is_an_error_not_a_panic() {
        let file = Path::new("bad.obj");
        let mut m = tetrahedron();
        m.triangles.push([0, 1, 9]);
        let err = Mesh::from_raw(m, file, &ImportOptions::default()).unwrap_err();
        assert!(matches!(err, MeshError::IndexOutOfRange { index: 9, .. }), "{err}");
        assert!(err.to_string().contains("bad.obj"));

        let mut m = tetrahedron();
        m.positions[2].y = f32::NAN;
        let err = Mesh::from_raw(m, file, &ImportOptions::default()).unwrap_err();
        assert!(matches!(err, MeshError::NonFinite { vertex: 2, .. }), "{err}");

        let err = Mesh::from_raw(raw(&[[0.0; 3]], &[]), file, &ImportOptions::default()).unwrap_err();
        assert!(matches!(err, MeshError::NoTriangles { .. }));

        let all_degenerate = raw(&[[0.0; 3], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]], &[[0, 1, 2]]);
        let err = Mesh::from_raw(all_degenerate, file, &ImportOptions::default()).unwrap_err();
        assert!(err.to_string().contains("degenerate"), "{err}");
    }

    #[test]
    fn flipped_and_non_manifold_edges_are_reported() {
        let mut m = tetrahedron();
        m.triangles[3] = [1, 3, 2]; // flip one face
        let as_read = ImportOptions { orient: false, ..ImportOptions::default() };
        let (_, report) = Mesh::from_raw(m, Path::new("t"), &as_read).unwrap();
        assert_eq!(report.inconsistent_winding_edges, 3);
        assert_eq!(report.reoriented_triangles, 0);

        // Three triangles sharing edge 0-1.
        let fan = raw(
            &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]],
            &[[0, 1, 2], [1, 0, 3], [0, 1, 4]],
        );
        let (mesh, report) = Mesh::from_raw(fan, Path::new("fan"), &ImportOptions::default()).unwrap();
        assert_eq!(report.non_manifold_edges, 1);
        assert_eq!(report.boundary_edges, 6);
        assert_eq!(report.boundary_loops, 1, "the fan's rim is one chain through vertices 0 and 1");
        assert_eq!(mesh.edges.len(), 7, "fins are still built for every edge");
    }

    fn volume(mesh: &Mesh) -> f32 {
        mesh.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                a.dot(b.cross(c)) / 6.0
            })
            .sum()
    }

    #[test]
    fn flipped_faces_are_turned_back_and_uvs_follow_their_corners() {
        let mut m = tetrahedron();
        m.triangles[3] = [1, 3, 2];
        m.uvs = Some(m.positions.iter().map(|p| p.truncate()).collect());
        let (mesh, report) = Mesh::from_raw(m, Path::new("t"), &ImportOptions::default()).unwrap();
        assert_eq!(report.reoriented_triangles, 1);
        assert!(report.is_closed_manifold(), "{report}");
        assert!((volume(&mesh) - 1.0 / 6.0).abs() < 1e-6);
        let uvs = mesh.corner_uvs.as_ref().unwrap();
        for (tri, corners) in mesh.triangles.iter().zip(uvs) {
            for k in 0..3 {
                assert_eq!(corners[k], mesh.positions[tri[k] as usize].truncate(), "uv stays with its vertex");
            }
        }
    }

    #[test]
    fn a_closed_mesh_inside_out_is_turned_outward() {
        let mut m = tetrahedron();
        for t in &mut m.triangles {
            t.swap(0, 1);
        }
        let (mesh, report) = Mesh::from_raw(m, Path::new("t"), &ImportOptions::default()).unwrap();
        assert_eq!(report.reoriented_triangles, 4);
        assert!(volume(&mesh) > 0.0);
        let centre = Vec3::splat(0.25);
        assert!(mesh.positions.iter().zip(&mesh.normals).all(|(p, n)| n.dot(*p - centre) > 0.0));
    }

    #[test]
    fn an_open_mesh_keeps_its_majority_winding() {
        // A 4 x 4 grid of quads facing -Z as read; three triangles flipped.
        let mut grid = RawMesh::default();
        for row in 0..5 {
            for col in 0..5 {
                grid.positions.push(Vec3::new(col as f32, row as f32, 0.0));
            }
        }
        for row in 0..4 {
            for col in 0..4 {
                let i = row * 5 + col;
                grid.triangles.push([i, i + 6, i + 1]);
                grid.triangles.push([i, i + 5, i + 6]);
            }
        }
        for t in [3, 10, 17] {
            grid.triangles[t].swap(0, 1);
        }
        let (mesh, report) = Mesh::from_raw(grid, Path::new("grid"), &ImportOptions::default()).unwrap();
        assert_eq!(report.reoriented_triangles, 3);
        assert_eq!(report.inconsistent_winding_edges, 0);
        assert!((0..mesh.triangles.len()).all(|t| mesh.face_normal(t).z < -0.99), "the majority (-Z) wins");
    }

    #[test]
    fn a_moebius_strip_keeps_the_conflict_it_cannot_avoid() {
        let segments = 12;
        let mut strip = RawMesh::default();
        for k in 0..segments {
            let angle = std::f32::consts::TAU * k as f32 / segments as f32;
            let twist = angle / 2.0;
            let centre = Vec3::new(angle.cos(), angle.sin(), 0.0) * 2.0;
            let across = Vec3::new(angle.cos() * twist.cos(), angle.sin() * twist.cos(), twist.sin()) * 0.5;
            strip.positions.push(centre - across);
            strip.positions.push(centre + across);
        }
        for k in 0..segments {
            let (a, b) = (2 * k, 2 * k + 1);
            // The last segment joins the first one upside down.
            let (c, d) = if k + 1 == segments { (1, 0) } else { (2 * k + 2, 2 * k + 3) };
            strip.triangles.push([a, c, d]);
            strip.triangles.push([a, d, b]);
        }
        let (mesh, report) = Mesh::from_raw(strip, Path::new("moebius"), &ImportOptions::default()).unwrap();
        assert_eq!(mesh.triangles.len(), 2 * segments as usize);
        assert_eq!(report.inconsistent_winding_edges, 1, "{report}");
        assert_eq!(report.boundary_loops, 1, "a Moebius strip has a single rim");
    }

    #[test]
    fn duplicate_and_double_sided_triangles_are_dropped() {
        let mut m = tetrahedron();
        m.triangles.push([2, 1, 0]); // the back side of triangle 0
        m.triangles.push([1, 3, 0]); // triangle 1 again, rotated
        let (mesh, report) = Mesh::from_raw(m, Path::new("t"), &ImportOptions::default()).unwrap();
        assert_eq!(report.dropped_duplicate_triangles, 2);
        assert_eq!(mesh.triangles.len(), 4);
        assert!(report.is_closed_manifold(), "{report}");
    }
}
