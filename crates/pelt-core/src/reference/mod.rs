//! The explicit strand reference: every strand of the seeded field that the shell textures encode
//! ([`StrandField`]), placed on the mesh where its texels land, as geometry a renderer can draw
//! strand by strand. It is the ground truth that shells and fins approximate.
//!
//! Placement follows the shell renderer's tile mapping exactly:
//! - a mesh with uvs: tile coordinates are the corner uvs times [`TileMapping::tiles_per_uv`]; the
//!   tile repeats, so a triangle holds every strand whose root (shifted by whole tiles) lies in
//!   its uv triangle;
//! - a mesh without uvs: the triplanar projection of the model-space roots times
//!   [`TileMapping::tiles_per_world`]; each triangle takes the projection of its face normal's
//!   dominant axis (the shader blends three with sharp weights, so away from narrow bands this is
//!   the one it shows).
//!
//! A strand's cross-section at height `t` sits at texel `centre(t)` (lean, clumping, curl); the
//! shell at layer `i` shows it where the triangle's tile coordinates reach that texel. So node `t`
//! of a placed strand is the barycentric combination, at that point of the triangle (extrapolated
//! past its edges), of the triangle's three columns of the shared array, each read at height `t`
//! (between layers `floor(t L)` and the next, and along the last segment past the tips). The
//! strands therefore follow the simulated fur exactly as the shells do.
//!
//! A wet coat ([`StrandReference::wet`]) gathers each strand into the shells' clumps
//! ([`WetClumps`], the `clumps` module) before it is placed, so wet strands are clumped geometry.

mod clumps;
pub mod shadow;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use crate::fur::FurStructure;
use crate::mesh::Mesh;
use crate::texture::{Strand, StrandField};

pub use clumps::{CLUMP_PARTING, WetClumps, gather_amount, gathered, nearest_centre};

/// How tile coordinates are laid on a mesh (the shell renderer's mapping).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TileMapping {
    /// Meshes with uvs: tiles per uv unit.
    pub tiles_per_uv: f32,
    /// Meshes without uvs: tiles per model unit (triplanar projection).
    pub tiles_per_world: f32,
}

/// Shell texture tiles across a mesh's bounding radius in Pelt's standard look
/// (`pelt_render::FurLook::default()`'s `tiles_per_radius`).
pub const STANDARD_TILES_PER_RADIUS: f32 = 0.4;

impl TileMapping {
    /// The mapping the standard look lays on `mesh` (what `pelt_render::tile_mapping` gives for
    /// the default look): `STANDARD_TILES_PER_RADIUS` tiles per bounding radius, and on a mesh
    /// with uvs as many tiles per uv unit as keep the same tiles per area.
    #[must_use]
    pub fn standard(mesh: &Mesh) -> Self {
        let tiles_per_world = STANDARD_TILES_PER_RADIUS / mesh.bounding_sphere().1.max(1e-6);
        let world_per_uv = match &mesh.corner_uvs {
            Some(uvs) => {
                let uv_area: f32 = uvs.iter().map(|[a, b, c]| (*b - *a).perp_dot(*c - *a).abs() * 0.5).sum();
                if uv_area > 1e-12 { (mesh.surface_area() / uv_area).sqrt() } else { 1.0 }
            }
            None => 1.0,
        };
        Self { tiles_per_uv: tiles_per_world * world_per_uv, tiles_per_world }
    }

    /// Strands a field of `strands_per_tile` places on each triangle of `mesh` through this
    /// mapping (its uv area in tiles, or its triplanar projection's area in tiles, times the
    /// strands a tile holds).
    #[must_use]
    pub fn expected_strands(&self, mesh: &Mesh, strands_per_tile: usize) -> Vec<f32> {
        let n = strands_per_tile as f32;
        (0..mesh.triangles.len())
            .map(|t| match &mesh.corner_uvs {
                Some(uvs) => {
                    let [a, b, c] = uvs[t];
                    (b - a).perp_dot(c - a).abs() * 0.5 * self.tiles_per_uv * self.tiles_per_uv * n
                }
                None => {
                    let [a, b, c] = mesh.triangles[t].map(|j| mesh.positions[j as usize]);
                    let cross = (b - a).cross(c - a);
                    cross.abs().max_element() * 0.5 * self.tiles_per_world * self.tiles_per_world * n
                }
            })
            .collect()
    }
}

/// One strand placed on a triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PlacedStrand {
    /// Index into [`StrandField::strands`].
    pub field_index: u32,
    /// The base triangle it roots on.
    pub triangle: u32,
    /// The mesh uv at the root (for the surface colour mode), when the mesh has uvs.
    pub surface_uv: Option<Vec2>,
    /// First node in [`StrandReference::nodes`].
    pub first_node: u32,
    /// Nodes from the root (height 0) to the end (height = the length factor).
    pub node_count: u32,
    /// Cross-section radius at the root, model units.
    pub root_radius: f32,
    /// Model units per texel on this strand's triangle: `sqrt(surface area / tile area)` of the
    /// triangle, so a strand is as wide as the shell texels that draw it there (a stretched uv
    /// triangle or a tilted triplanar projection widens them).
    pub world_per_texel: f32,
    /// The coat's wetness at the root (0 for a dry reference): the ribbons darken and shine
    /// with it as `wet.wgsl` does.
    pub wetness: f32,
}

/// Where one node of a placed strand is, relative to its triangle.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StrandNode {
    /// Weights of the triangle's three columns (they sum to 1; outside `0..=1` past an edge).
    pub barycentric: Vec3,
    /// Height as a fraction of the fur length: 0 at the root.
    pub height: f32,
    /// The farthest (model units) this node may stand sideways from the root's own column: twice
    /// its lean at the tile's usual scale. Where the columns of a triangle splay apart, weights
    /// far outside it would otherwise amplify the splay.
    pub reach: f32,
}

/// Why a reference could not be made or evaluated.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum ReferenceError {
    /// A shared array of the wrong size.
    #[error("the shared array has {got} positions, expected (L + 1) * V = {expected}")]
    Positions {
        /// `(L + 1) * V`.
        expected: usize,
        /// What was given.
        got: usize,
    },
    /// A mapping that is zero, negative or not finite.
    #[error("tile mapping must be finite and positive, got {0}")]
    Mapping(String),
    /// Wet clumps that do not fit the fur.
    #[error("wet reference: {0}")]
    Wet(String),
}

/// Every strand of a field placed on one fur structure.
#[derive(Clone, Debug)]
pub struct StrandReference {
    /// The strands' field (shape, colour).
    pub field: StrandField,
    /// Placed strands, by triangle and then field order.
    pub strands: Vec<PlacedStrand>,
    /// Every strand's nodes, strand after strand.
    pub nodes: Vec<StrandNode>,
    /// Model units per texel at the tile's usual scale (each strand's own scale, which sets its
    /// width, is [`PlacedStrand::world_per_texel`]).
    pub world_per_texel: f32,
    triangles: Vec<[u32; 3]>,
    vertex_count: usize,
    layers: u32,
}

/// Side of the square cells strands are bucketed in by root, texels.
const CELL_TEXELS: f32 = 8.0;

impl StrandReference {
    /// Places every strand of `field` on `fur`'s base mesh through `mapping`.
    ///
    /// # Errors
    /// [`ReferenceError::Mapping`] for a mapping that is not finite and positive.
    pub fn new(fur: &FurStructure, field: StrandField, mapping: TileMapping) -> Result<Self, ReferenceError> {
        Self::build(fur, field, mapping, None)
    }

    /// Places every strand of `field` on `fur`'s base mesh through `mapping`, each gathered into
    /// the clumps a coat wet by `wet` shows on the shells.
    ///
    /// # Errors
    /// [`ReferenceError::Mapping`] for a mapping that is not finite and positive,
    /// [`ReferenceError::Wet`] for a wetness or groom clump map not one value per base vertex,
    /// or a clump size that is not finite and positive.
    pub fn wet(
        fur: &FurStructure,
        field: StrandField,
        mapping: TileMapping,
        wet: &WetClumps,
    ) -> Result<Self, ReferenceError> {
        let vertices = fur.mesh.vertex_count();
        if wet.wetness.len() != vertices || wet.groom_clump.as_ref().is_some_and(|c| c.len() != vertices) {
            return Err(ReferenceError::Wet(format!("wetness and clump maps need {vertices} values, one per vertex")));
        }
        if !(wet.clump_size.is_finite() && wet.clump_size > 0.0) {
            return Err(ReferenceError::Wet(format!("clump size must be finite and positive, got {}", wet.clump_size)));
        }
        Self::build(fur, field, mapping, Some(wet))
    }

    fn build(
        fur: &FurStructure,
        field: StrandField,
        mapping: TileMapping,
        wet: Option<&WetClumps>,
    ) -> Result<Self, ReferenceError> {
        let scale = [mapping.tiles_per_uv, mapping.tiles_per_world];
        if !scale.iter().all(|s| s.is_finite() && *s > 0.0) {
            return Err(ReferenceError::Mapping(format!("{mapping:?}")));
        }
        let size = field.params.size as f32;
        let buckets = Buckets::new(&field.strands, size);
        let mesh = &fur.mesh;
        let layers = fur.layers;
        let per_triangle: Vec<Vec<(PlacedStrand, Vec<StrandNode>)>> = (0..mesh.triangles.len())
            .into_par_iter()
            .map(|t| {
                let corners = mesh.triangles[t].map(|j| mesh.positions[j as usize]);
                let (params, uvs) = match &mesh.corner_uvs {
                    Some(uvs) => (uvs[t].map(|uv| uv * mapping.tiles_per_uv * size), Some(uvs[t])),
                    None => (triplanar(corners, mapping.tiles_per_world * size), None),
                };
                let Some(triangle) = Param::new(params) else { return Vec::new() };
                let surface_area = (corners[1] - corners[0]).cross(corners[2] - corners[0]).length();
                let local_world_per_texel = (surface_area * triangle.inverse_area.abs()).sqrt();
                let mut placed = Vec::new();
                buckets.visit(triangle.low, triangle.high, |index, shift| {
                    let strand = &field.strands[index as usize];
                    let root = strand.root() + shift;
                    let weights = triangle.barycentric(root);
                    if weights.min_element() < 0.0 {
                        return;
                    }
                    let texels_per_world = mapping.tiles_per_world * size;
                    let corner = mesh.triangles[t].map(|j| j as usize);
                    let at_root = |value: &dyn Fn(usize) -> f32| {
                        value(corner[0]) * weights.x + value(corner[1]) * weights.y + value(corner[2]) * weights.z
                    };
                    let (wetness, clump) = wet.map_or((0.0, 0.0), |wet| {
                        (at_root(&|j| wet.wetness[j].clamp(0.0, 1.0)), at_root(&|j| wet.vertex_clump(j)))
                    });
                    let cell_texels = wet.map_or(1.0, |wet| wet.clump_size);
                    let nodes = node_heights(strand.length_factor(), layers)
                        .map(|height| {
                            let lean = strand.centre(height) - strand.root();
                            // A wet strand's cross-section gathered into its clump (dry: as is).
                            let amount = gather_amount(clump, height);
                            let shift = if amount > 0.0 {
                                gathered(root, root + lean, amount, cell_texels) - root
                            } else {
                                lean
                            };
                            let mut barycentric = triangle.barycentric(root + shift);
                            // Where the tile is stretched thin over the surface (a squeezed uv
                            // triangle), a few texels of lean would reach far across the mesh:
                            // keep the lean within twice its length at the tile's usual scale.
                            let offset = barycentric - weights;
                            let reach =
                                (corners[0] * offset.x + corners[1] * offset.y + corners[2] * offset.z).length();
                            let limit = 2.0 * shift.length() / texels_per_world;
                            if reach > limit {
                                barycentric = weights + offset * (limit / reach);
                            }
                            StrandNode { barycentric, height, reach: limit }
                        })
                        .collect::<Vec<_>>();
                    let surface_uv = uvs.map(|[a, b, c]| a * weights.x + b * weights.y + c * weights.z);
                    let strand = PlacedStrand {
                        field_index: index,
                        triangle: t as u32,
                        surface_uv,
                        first_node: 0,
                        node_count: nodes.len() as u32,
                        root_radius: 0.0,
                        world_per_texel: local_world_per_texel,
                        wetness,
                    };
                    placed.push((strand, nodes));
                });
                // Buckets are visited in cell order: sort so the order is the field's.
                placed.sort_by_key(|(s, _)| s.field_index);
                placed
            })
            .collect();
        let world_per_texel = 1.0 / (mapping.tiles_per_world * size);
        let mut strands = Vec::new();
        let mut nodes = Vec::new();
        for (mut strand, strand_nodes) in per_triangle.into_iter().flatten() {
            strand.first_node = nodes.len() as u32;
            strand.root_radius =
                field.strands[strand.field_index as usize].radius_at(0.0, 0.0) * strand.world_per_texel;
            strands.push(strand);
            nodes.extend(strand_nodes);
        }
        Ok(Self {
            field,
            strands,
            nodes,
            world_per_texel,
            triangles: mesh.triangles.clone(),
            vertex_count: mesh.vertex_count(),
            layers,
        })
    }

    /// The field's strand behind a placed one.
    #[must_use]
    pub fn field_strand(&self, strand: &PlacedStrand) -> &Strand {
        &self.field.strands[strand.field_index as usize]
    }

    /// The nodes of one placed strand.
    #[must_use]
    pub fn strand_nodes(&self, strand: &PlacedStrand) -> &[StrandNode] {
        let first = strand.first_node as usize;
        &self.nodes[first..first + strand.node_count as usize]
    }

    /// Every node's cross-section radius (model units), in the order of [`Self::nodes`]: the
    /// strand's radius tapered at the node's height ([`Strand::radius_at`]) times its
    /// triangle's [`PlacedStrand::world_per_texel`]. The ribbons are this wide either side and
    /// the strands' shadow ([`shadow`]) blocks light this far from each.
    #[must_use]
    pub fn node_radii(&self) -> Vec<f32> {
        let taper = self.field.params.taper;
        let mut radii = Vec::with_capacity(self.nodes.len());
        for placed in &self.strands {
            let strand = self.field_strand(placed);
            radii.extend(
                self.strand_nodes(placed)
                    .iter()
                    .map(|node| strand.radius_at(node.height, taper) * placed.world_per_texel),
            );
        }
        radii
    }

    /// Each strand's nodes in [`Self::nodes`] (and in [`Self::node_positions`]' output).
    #[must_use]
    pub fn node_ranges(&self) -> Vec<std::ops::Range<usize>> {
        self.strands.iter().map(|s| s.first_node as usize..(s.first_node + s.node_count) as usize).collect()
    }

    /// Every node's model-space position for one state of the shared array (`(L + 1) * V`
    /// positions: the rest pose or a simulation's), in the order of [`Self::nodes`].
    ///
    /// # Errors
    /// [`ReferenceError::Positions`] for an array of another size.
    pub fn node_positions(&self, positions: &[Vec3]) -> Result<Vec<Vec3>, ReferenceError> {
        Ok(self.evaluate(positions, false)?.0)
    }

    /// Every node's model-space position, as [`Self::node_positions`], and what the shell
    /// texture adds to it: its offset from the strand's straight column at its height (the
    /// blend of the triangle's columns at the root's weights), the texture's lean, clumps and
    /// curl (and a wet coat's gathering). A position less its offset lies on the column, which
    /// the groom alone shapes.
    ///
    /// # Errors
    /// [`ReferenceError::Positions`] for an array of another size.
    pub fn node_positions_and_offsets(&self, positions: &[Vec3]) -> Result<(Vec<Vec3>, Vec<Vec3>), ReferenceError> {
        self.evaluate(positions, true)
    }

    /// Node positions, and their texture offsets when `offsets` (else an empty second list).
    fn evaluate(&self, positions: &[Vec3], offsets: bool) -> Result<(Vec<Vec3>, Vec<Vec3>), ReferenceError> {
        let expected = (self.layers as usize + 1) * self.vertex_count;
        if positions.len() != expected {
            return Err(ReferenceError::Positions { expected, got: positions.len() });
        }
        let columns = Columns { positions, vertex_count: self.vertex_count, layers: self.layers };
        let mut out = vec![Vec3::ZERO; self.nodes.len()];
        let mut out_offsets = vec![Vec3::ZERO; if offsets { self.nodes.len() } else { 0 }];
        type Chunk<'a> = (&'a PlacedStrand, &'a mut [Vec3], Option<&'a mut [Vec3]>);
        let chunks: Vec<Chunk<'_>> = {
            let mut rest = out.as_mut_slice();
            let mut rest_offsets = out_offsets.as_mut_slice();
            let mut chunks = Vec::with_capacity(self.strands.len());
            for strand in &self.strands {
                let n = strand.node_count as usize;
                let (head, tail) = rest.split_at_mut(n);
                rest = tail;
                let offsets_head = if offsets {
                    let (head, tail) = std::mem::take(&mut rest_offsets).split_at_mut(n);
                    rest_offsets = tail;
                    Some(head)
                } else {
                    None
                };
                chunks.push((strand, head, offsets_head));
            }
            chunks
        };
        chunks.into_par_iter().for_each(|(strand, out, mut offsets)| {
            let triangle = self.triangles[strand.triangle as usize];
            let nodes = self.strand_nodes(strand);
            // The root node has no lean: its weights are the root's.
            let root_weights = nodes[0].barycentric;
            for (k, (node, position)) in nodes.iter().zip(out.iter_mut()).enumerate() {
                let at = |b: Vec3| {
                    columns.at(triangle[0], node.height) * b.x
                        + columns.at(triangle[1], node.height) * b.y
                        + columns.at(triangle[2], node.height) * b.z
                };
                let column = at(root_weights);
                let sideways = at(node.barycentric) - column;
                let length = sideways.length();
                let offset = if length > node.reach { sideways * (node.reach / length) } else { sideways };
                *position = column + offset;
                if let Some(offsets) = offsets.as_deref_mut() {
                    offsets[k] = offset;
                }
            }
        });
        Ok((out, out_offsets))
    }
}

/// Heights of a strand's nodes: every layer below its end, then the end itself.
fn node_heights(length_factor: f32, layers: u32) -> impl Iterator<Item = f32> {
    let steps = (length_factor * layers as f32).ceil().max(1.0) as u32;
    (0..=steps).map(move |i| (i as f32 / layers as f32).min(length_factor))
}

/// The shared array read as columns: vertex `j` at height `t` (fraction of the fur length).
struct Columns<'a> {
    positions: &'a [Vec3],
    vertex_count: usize,
    layers: u32,
}

impl Columns<'_> {
    fn at(&self, vertex: u32, t: f32) -> Vec3 {
        let x = t * self.layers as f32;
        // Past the tips the last segment extends: strands longer than the fur reach beyond it.
        let i = (x.floor() as u32).min(self.layers - 1);
        let f = x - i as f32;
        let node = |layer: u32| self.positions[layer as usize * self.vertex_count + vertex as usize];
        node(i) * (1.0 - f) + node(i + 1) * f
    }
}

/// The triplanar projection of a triangle (the face normal's dominant axis), in texels.
fn triplanar(corners: [Vec3; 3], texels_per_world: f32) -> [Vec2; 3] {
    let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]).abs();
    // The shader's projections: x -> (y, z), y -> (z, x), z -> (x, y).
    let project = |p: Vec3| {
        if normal.x >= normal.y && normal.x >= normal.z {
            Vec2::new(p.y, p.z)
        } else if normal.y >= normal.z {
            Vec2::new(p.z, p.x)
        } else {
            Vec2::new(p.x, p.y)
        }
    };
    corners.map(|p| project(p) * texels_per_world)
}

/// A triangle in tile coordinates (texels).
struct Param {
    origin: Vec2,
    edge_1: Vec2,
    edge_2: Vec2,
    inverse_area: f32,
    low: Vec2,
    high: Vec2,
}

impl Param {
    fn new([a, b, c]: [Vec2; 3]) -> Option<Self> {
        let (edge_1, edge_2) = (b - a, c - a);
        let area = edge_1.perp_dot(edge_2);
        // A triangle with no extent in the tile (a degenerate uv triangle) shows no strands.
        if area.is_nan() || area.abs() <= 1e-9 {
            return None;
        }
        Some(Self { origin: a, edge_1, edge_2, inverse_area: 1.0 / area, low: a.min(b).min(c), high: a.max(b).max(c) })
    }

    fn barycentric(&self, q: Vec2) -> Vec3 {
        let d = q - self.origin;
        let u = d.perp_dot(self.edge_2) * self.inverse_area;
        let v = self.edge_1.perp_dot(d) * self.inverse_area;
        Vec3::new(1.0 - u - v, u, v)
    }
}

/// The field's strands bucketed by root cell, to find those in a triangle's box quickly.
struct Buckets {
    cells: i64,
    size: f32,
    strands: Vec<Vec<u32>>,
}

impl Buckets {
    fn new(strands: &[Strand], size: f32) -> Self {
        let cells = ((size / CELL_TEXELS) as i64).max(1);
        let mut buckets = vec![Vec::new(); (cells * cells) as usize];
        for (i, strand) in strands.iter().enumerate() {
            let cell = (strand.root() / size * cells as f32).floor();
            let (x, y) = ((cell.x as i64).clamp(0, cells - 1), (cell.y as i64).clamp(0, cells - 1));
            buckets[(y * cells + x) as usize].push(i as u32);
        }
        Self { cells, size, strands: buckets }
    }

    /// Calls `visit(strand, shift)` for every strand whose root plus a whole-tile `shift` may lie
    /// in the box `low..high` (texels, unwrapped).
    fn visit(&self, low: Vec2, high: Vec2, mut visit: impl FnMut(u32, Vec2)) {
        let cell_texels = self.size / self.cells as f32;
        let (x0, y0) = ((low.x / cell_texels).floor() as i64, (low.y / cell_texels).floor() as i64);
        let (x1, y1) = ((high.x / cell_texels).floor() as i64, (high.y / cell_texels).floor() as i64);
        for y in y0..=y1 {
            for x in x0..=x1 {
                let shift = Vec2::new(x.div_euclid(self.cells) as f32, y.div_euclid(self.cells) as f32) * self.size;
                let bucket = y.rem_euclid(self.cells) * self.cells + x.rem_euclid(self.cells);
                for &index in &self.strands[bucket as usize] {
                    visit(index, shift);
                }
            }
        }
    }
}
