//! Triangle meshes: import, repair, normals and edge topology.
//!
//! Every loader produces a [`RawMesh`] (an indexed triangle list straight from the file) and
//! hands it to [`Mesh::from_raw`], which validates, welds, repairs and measures it. The result is
//! a clean, indexed, manifold-or-reported mesh plus a [`MeshReport`] the caller can print.
//!
//! By job: `error` ([`MeshError`]), the loaders (`obj`, `gltf`, [`builtin`]), `repair`
//! ([`Mesh::from_raw`], welding, orientation, [`smooth_normals`]), `topology` ([`Topology`],
//! the edge list) and `report` ([`MeshReport`]). A glTF file's rig is read in `anim`
//! ([`Mesh::load_animated`]) on top of this module's glTF parse, so meshes never need the rig.

pub mod builtin;
mod error;
pub(crate) mod gltf;
mod obj;
mod repair;
mod report;
mod topology;
mod tuck;
mod vertex_cache;
mod wedges;

use std::path::Path;

use glam::{Mat4, Vec2, Vec3, Vec4};

pub use error::MeshError;
pub use repair::smooth_normals;
pub use report::{MeshReport, NormalSource};
pub use topology::{NO_FACE, Topology};
pub use tuck::tuck_under;
pub use wedges::Wedges;

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

/// One vertex colour set: glTF's `COLOR_n` attribute, RGBA in `0..=1` (linear, as glTF stores it).
#[derive(Clone, Debug, PartialEq)]
pub struct ColourSet {
    /// `n` of `COLOR_n`.
    pub set: u32,
    /// One colour per vertex.
    pub colours: Vec<Vec4>,
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
    /// Reorder the triangles so neighbours follow each other (`vertex_cache.rs`): every shell
    /// draws them through an index buffer, and a vertex leaves the GPU's vertex cache (to be
    /// shaded again) unless its triangles come close together. Off keeps the file's order.
    pub vertex_cache_order: bool,
}

impl Default for ImportOptions {
    fn default() -> Self {
        Self { weld: true, weld_tolerance: 1e-6, orient: true, vertex_cache_order: true }
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
    /// Vertex colour sets read from the file (glTF `COLOR_n`), one colour per vertex each; a
    /// welded vertex has the mean of the colours welded into it. Grooms can read them.
    pub colour_sets: Vec<ColourSet>,
}

impl Mesh {
    /// Loads a mesh file (`.obj`, `.gltf`, `.glb`), chosen by extension.
    ///
    /// # Errors
    /// A [`MeshError`] naming the file for missing files, unknown formats, parse errors and
    /// unrepairable content.
    pub fn load(path: &Path, options: &ImportOptions) -> Result<(Self, MeshReport), MeshError> {
        let (raw, colour_sets) = Self::read_raw(path)?;
        Self::repair(raw, &colour_sets, path, options).map(|(mesh, report, _)| (mesh, report))
    }

    /// The first half of [`Mesh::load`]: the file parsed, not yet repaired, with its vertex
    /// colour sets (one colour per raw vertex each). [`Mesh::from_raw`] is the second half for
    /// a file without colour sets.
    ///
    /// # Errors
    /// As [`Mesh::load`], for the reading and parsing alone.
    pub fn read_raw(path: &Path) -> Result<(RawMesh, Vec<ColourSet>), MeshError> {
        let extension = path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).unwrap_or_default();
        if !path.exists() {
            return Err(MeshError::Io {
                file: path.to_path_buf(),
                error: std::io::Error::new(std::io::ErrorKind::NotFound, "no such file"),
            });
        }
        match extension.as_str() {
            "obj" => Ok((obj::load(path)?, Vec::new())),
            "gltf" | "glb" => gltf::load(path),
            _ => Err(MeshError::UnknownFormat { file: path.to_path_buf(), extension }),
        }
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
        let (raw, colour_sets) = gltf::parse(bytes, name, None)?;
        Self::repair(raw, &colour_sets, name, options).map(|(mesh, report, _)| (mesh, report))
    }

    /// The vertex colours of glTF's `COLOR_n` for `set = n`, one per vertex, if the file had them.
    #[must_use]
    pub fn colour_set(&self, set: u32) -> Option<&[Vec4]> {
        self.colour_sets.iter().find(|c| c.set == set).map(|c| c.colours.as_slice())
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

fn bounds(positions: &[Vec3]) -> (Vec3, Vec3) {
    positions
        .iter()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(*p), hi.max(*p)))
}
