//! Grooms: fur that differs over the body. Per-vertex maps over the fur mesh's surface, each
//! optional, each relative to the preset (an absent map is the preset's uniform value):
//!
//! - **length**: a factor on the preset's length, `0..=MAX_LENGTH_FACTOR`; 0 = bald;
//! - **density**: a factor on the strand density, `0..=1` (the shader thins the strands);
//! - **direction**: a flow in the surface, in the vertex's [`TangentFrame`] (`x` along the
//!   tangent, `y` along `up`), each component `-1..=1`: the fur is combed along it, as far as the
//!   preset's `direction.comb_blend` times the flow's length (at most 1) says;
//! - **clump**: how strongly strands gather into clumps, `0..=1`;
//! - **tint**: a linear RGB factor on the strand colour, each `0..=1`.
//!
//! Sources are named in the preset's `[groom]` table ([`GroomParams`], `source`): images through
//! the mesh's UVs, glTF vertex colour sets, or a per-vertex groom file (`file`, its format in
//! `file.rs`), or a strand groom of USD curves baked per vertex (`strands.rs`, [`bake_strands`]).
//! [`crate::fur::FurStructure::new_groomed`] grows the structure a groom describes.
//! [`GroomEditor`] paints a groom with [`Brush`]es (`brush.rs`, `edit.rs`).

mod brush;
mod edit;
mod file;
mod frame;
mod source;
mod sparse;
mod strands;
mod strokes;
mod surface_grid;

use std::path::PathBuf;

use glam::{Vec2, Vec3};

use crate::mesh::Mesh;

pub use brush::{Axis, Brush, BrushKind, Falloff, LENGTH_STEP};
pub use edit::{DAB_SPACING, GroomEditor, UNDO_DEPTH, rest_point};
pub use file::{FILE_MAGIC, FILE_VERSION};
pub use frame::{TangentFrame, tangent_frames};
pub use source::GroomParams;
pub use strands::{StrandBakeParams, StrandBakeReport, bake_strands};
pub use strokes::StrokeList;

/// The largest length factor a groom may hold (images reach 1; groom files may go beyond).
pub const MAX_LENGTH_FACTOR: f32 = 16.0;

/// One of a groom's maps.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GroomMap {
    /// Length factor.
    Length,
    /// Density factor.
    Density,
    /// Tangent-space flow.
    Direction,
    /// Clump strength.
    Clump,
    /// Colour tint.
    Tint,
}

impl GroomMap {
    /// Every map, in the groom file's order.
    pub const ALL: [Self; 5] = [Self::Length, Self::Density, Self::Direction, Self::Clump, Self::Tint];

    /// The map's key in the preset's `[groom]` table.
    #[must_use]
    pub fn key(self) -> &'static str {
        match self {
            Self::Length => "length",
            Self::Density => "density",
            Self::Direction => "direction",
            Self::Clump => "clump",
            Self::Tint => "tint",
        }
    }

    /// Floats per vertex.
    #[must_use]
    pub fn components(self) -> usize {
        match self {
            Self::Direction => 2,
            Self::Tint => 3,
            _ => 1,
        }
    }

    /// The range each component must lie in.
    fn range(self) -> (f32, f32) {
        match self {
            Self::Length => (0.0, MAX_LENGTH_FACTOR),
            Self::Direction => (-1.0, 1.0),
            _ => (0.0, 1.0),
        }
    }
}

/// Why a groom could not be read, written or used. Each message names the file (image, groom file
/// or mesh) and, for a preset's source, the `groom.*` key.
#[derive(Debug, thiserror::Error)]
pub enum GroomError {
    // The cause is part of the message (not a `source`) so it is printed exactly once.
    /// A groom file could not be read or written.
    #[error("{}: cannot read or write the groom file: {error}", file.display())]
    Io {
        /// The groom file.
        file: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// A stroke list that cannot be used.
    #[error("{}: {problem}", file.display())]
    Strokes {
        /// The stroke list file.
        file: PathBuf,
        /// What is wrong (the stroke and key).
        problem: String,
    },
    /// A groom file is malformed (magic, version, size, checksum).
    #[error("{}: not a valid groom file: {problem}", file.display())]
    Format {
        /// The groom file.
        file: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// A groom file made for another mesh.
    #[error(
        "{}: the groom was made for a mesh of {file_vertices} vertices (positions hash {file_hash:016x}), \
         but {mesh} has {mesh_vertices} vertices (positions hash {mesh_hash:016x})",
        file.display()
    )]
    WrongMesh {
        /// The groom file.
        file: PathBuf,
        /// Vertices recorded in the file.
        file_vertices: usize,
        /// Positions hash recorded in the file.
        file_hash: u64,
        /// The mesh it was loaded onto.
        mesh: String,
        /// That mesh's vertices.
        mesh_vertices: usize,
        /// That mesh's positions hash ([`mesh_hash`]).
        mesh_hash: u64,
    },
    /// An image map could not be loaded or has the wrong pixel format.
    #[error("groom.{key}: {}: {problem}", image.display())]
    Image {
        /// The `[groom]` key.
        key: String,
        /// The image file.
        image: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// An image map for a mesh without UVs.
    #[error(
        "groom.{key}: {}: {mesh} has no UVs, so images cannot be mapped onto it; \
         use a groom file or a glTF vertex colour set (COLOR_n)",
        image.display()
    )]
    NoUvs {
        /// The `[groom]` key.
        key: String,
        /// The image file.
        image: PathBuf,
        /// The mesh.
        mesh: String,
    },
    /// A vertex colour set the mesh does not have.
    #[error("groom.{key}: {mesh} has no vertex colour set COLOR_{set} ({available})")]
    NoColourSet {
        /// The `[groom]` key.
        key: String,
        /// `n` of `COLOR_n`.
        set: u32,
        /// The mesh.
        mesh: String,
        /// The sets it has.
        available: String,
    },
    /// A map with the wrong number of values.
    #[error("{origin}: groom.{key}: {got} values, but the mesh has {expected} vertices")]
    Size {
        /// Where the map came from.
        origin: String,
        /// The map's key.
        key: &'static str,
        /// Vertices of the mesh.
        expected: usize,
        /// Values in the map.
        got: usize,
    },
    /// A strand groom's file could not be read as USD (the message names it).
    #[error("groom.strands: {0}")]
    Usd(String),
    /// A strand groom (USD curves) that cannot be baked.
    #[error("{}: {problem}", file.display())]
    Strands {
        /// The curve file.
        file: PathBuf,
        /// What is wrong.
        problem: String,
    },
    /// A value that is not finite or out of its range.
    #[error("{origin}: groom.{key}: vertex {vertex}: {problem}")]
    Value {
        /// Where the map came from.
        origin: String,
        /// The map's key.
        key: &'static str,
        /// The vertex.
        vertex: usize,
        /// What is wrong.
        problem: String,
    },
}

/// Per-vertex maps over one mesh; `None` is the preset's uniform value. See the module docs.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Groom {
    /// Length factor per vertex (0 = bald, 1 = the preset's length).
    pub length: Option<Vec<f32>>,
    /// Density factor per vertex (`0..=1`).
    pub density: Option<Vec<f32>>,
    /// Flow per vertex in its [`TangentFrame`] (components `-1..=1`).
    pub direction: Option<Vec<Vec2>>,
    /// Clump strength per vertex (`0..=1`).
    pub clump: Option<Vec<f32>>,
    /// Linear RGB tint per vertex (each `0..=1`).
    pub tint: Option<Vec<Vec3>>,
}

impl Groom {
    /// Whether no map is set (the uniform fur).
    #[must_use]
    pub fn is_uniform(&self) -> bool {
        GroomMap::ALL.iter().all(|&map| !self.has(map))
    }

    /// Whether `map` is set.
    #[must_use]
    pub fn has(&self, map: GroomMap) -> bool {
        self.values(map).is_some()
    }

    /// The length factor of `vertex` (1 without a length map).
    #[must_use]
    pub fn length_factor(&self, vertex: usize) -> f32 {
        self.length.as_ref().map_or(1.0, |l| l[vertex])
    }

    /// Whether `vertex` grows no fur (its length factor is 0).
    #[must_use]
    pub fn is_bald(&self, vertex: usize) -> bool {
        self.length_factor(vertex) == 0.0
    }

    /// `map`'s values as flat floats (`components()` per vertex), if set.
    #[must_use]
    pub fn values(&self, map: GroomMap) -> Option<Vec<f32>> {
        match map {
            GroomMap::Length => self.length.clone(),
            GroomMap::Density => self.density.clone(),
            GroomMap::Direction => self.direction.as_ref().map(|d| d.iter().flat_map(|v| v.to_array()).collect()),
            GroomMap::Clump => self.clump.clone(),
            GroomMap::Tint => self.tint.as_ref().map(|t| t.iter().flat_map(|v| v.to_array()).collect()),
        }
    }

    /// Sets `map` from flat floats (`components()` per vertex; a trailing partial vertex is dropped).
    pub fn set_values(&mut self, map: GroomMap, values: Vec<f32>) {
        match map {
            GroomMap::Length => self.length = Some(values),
            GroomMap::Density => self.density = Some(values),
            GroomMap::Direction => {
                self.direction = Some(values.chunks_exact(2).map(|c| Vec2::new(c[0], c[1])).collect());
            }
            GroomMap::Clump => self.clump = Some(values),
            GroomMap::Tint => self.tint = Some(values.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()),
        }
    }

    /// Removes `map` (back to the preset's uniform value).
    pub fn clear(&mut self, map: GroomMap) {
        match map {
            GroomMap::Length => self.length = None,
            GroomMap::Density => self.density = None,
            GroomMap::Direction => self.direction = None,
            GroomMap::Clump => self.clump = None,
            GroomMap::Tint => self.tint = None,
        }
    }

    /// Number of vertices of `map`, if set.
    fn len_of(&self, map: GroomMap) -> Option<usize> {
        match map {
            GroomMap::Length => self.length.as_ref().map(Vec::len),
            GroomMap::Density => self.density.as_ref().map(Vec::len),
            GroomMap::Direction => self.direction.as_ref().map(Vec::len),
            GroomMap::Clump => self.clump.as_ref().map(Vec::len),
            GroomMap::Tint => self.tint.as_ref().map(Vec::len),
        }
    }

    /// Checks every set map: one entry per vertex of a `vertex_count` mesh, finite, in range.
    /// `origin` names where the groom came from in messages.
    ///
    /// # Errors
    /// [`GroomError::Size`] or [`GroomError::Value`] for the first problem.
    pub fn validate(&self, vertex_count: usize, origin: &str) -> Result<(), GroomError> {
        for map in GroomMap::ALL {
            let Some(got) = self.len_of(map) else { continue };
            if got != vertex_count {
                return Err(GroomError::Size {
                    origin: origin.to_owned(),
                    key: map.key(),
                    expected: vertex_count,
                    got,
                });
            }
            let values = self.values(map).unwrap_or_default();
            let (low, high) = map.range();
            let components = map.components();
            if let Some(at) = values.iter().position(|x| !(x.is_finite() && (low..=high).contains(x))) {
                let value = values[at];
                let problem = if value.is_finite() {
                    format!("{value} is outside {low}..={high}")
                } else {
                    format!("{value} is not a finite number")
                };
                return Err(GroomError::Value {
                    origin: origin.to_owned(),
                    key: map.key(),
                    vertex: at / components,
                    problem,
                });
            }
        }
        Ok(())
    }

    /// GPU-free bytes the groom's maps hold (4 per float).
    #[must_use]
    pub fn bytes(&self) -> u64 {
        GroomMap::ALL.iter().filter_map(|&map| self.len_of(map).map(|n| (n * map.components() * 4) as u64)).sum()
    }
}

/// A hash of a mesh's vertex count and welded positions (64-bit FNV-1a over the count and each
/// coordinate's `f32` bits, little-endian): what a groom file records of the mesh it belongs to.
#[must_use]
pub fn mesh_hash(mesh: &Mesh) -> u64 {
    let mut hash = Fnv::new();
    hash.write(&(mesh.vertex_count() as u64).to_le_bytes());
    for p in &mesh.positions {
        for c in p.to_array() {
            hash.write(&c.to_bits().to_le_bytes());
        }
    }
    hash.finish()
}

/// 64-bit FNV-1a.
struct Fnv(u64);

impl Fnv {
    fn new() -> Self {
        Self(0xcbf2_9ce4_8422_2325)
    }

    fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    fn finish(&self) -> u64 {
        self.0
    }
}
