//! The strands' own shadow from a directional light, traced offline on the CPU: how much of the
//! key light reaches each node of the strand reference through the other strands and the opaque
//! surfaces (the skin, plain meshes). It is the oracle for the renderer's deep opacity maps and
//! shares no code with them.
//!
//! The model: every strand is opaque, a cylinder of its own radius about its polyline (the
//! reference draws it as an opaque ribbon of that width). A node receives light across its own
//! cross-section, `2 r` wide; a strand between it and the light whose cylinder passes at distance
//! `d` from the node's light ray (measured across the ray) covers the part of that width its own
//! `2 r_b` overlaps, `[d - r_b, d + r_b]` against `[-r, r]`. Strands block independently, so the
//! node's transmittance is the product of `1 - covered share` over every strand nearer the light;
//! a node of zero radius (a tapered tip) is blocked wholly or not at all. A strand never shadows
//! itself. An opaque triangle crossing the ray toward the light blocks it wholly.
//!
//! All rays of a directional light are parallel, so the casters are projected once onto the
//! plane across the light and bucketed in a uniform 2D grid; each node reads the one cell it
//! falls in. Nodes are independent (rayon over strands) and each product runs in the cells'
//! fixed order, so the result has the same bytes on any number of threads.

use std::ops::Range;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

/// What casts the key light's shadow: the strands (nodes with radii, strand by strand) and the
/// opaque triangles, all in one space with the light's direction.
#[derive(Clone, Copy, Debug)]
pub struct ShadowCasters<'a> {
    /// Every strand's nodes, strand after strand.
    pub nodes: &'a [Vec3],
    /// Each node's cross-section radius (same length as `nodes`).
    pub radii: &'a [f32],
    /// Each strand's nodes in `nodes` (consecutive, covering `nodes` in order).
    pub strands: &'a [Range<usize>],
    /// Opaque triangles (the skin and plain meshes), corner positions.
    pub surfaces: &'a [[Vec3; 3]],
    /// The share of the light a strand stops where it covers a receiver (1: opaque strands).
    pub opacity: f32,
}

/// Cells the grid aims for per strand segment.
const CELLS_PER_SEGMENT: f32 = 1.0;
/// The grid's largest side, in cells.
const MAX_CELLS_PER_SIDE: usize = 2048;
/// How far (a share of the scene's size) an opaque triangle must stand toward the light from a
/// node to block it: the roots lie on the skin they grow from.
const SURFACE_EPSILON: f32 = 1e-4;

/// Each node's transmittance (0 = in full shadow, 1 = lit) toward a directional light
/// `toward_light` (unit vector toward it) through `casters`, in the order of `casters.nodes`.
///
/// # Panics
/// When `radii` and `nodes` differ in length or a strand's range lies outside `nodes`.
#[must_use]
pub fn key_light_transmittance(casters: &ShadowCasters<'_>, toward_light: Vec3) -> Vec<f32> {
    assert_eq!(casters.nodes.len(), casters.radii.len(), "one radius per node");
    let Some(grid) = LightGrid::new(casters, toward_light) else {
        return vec![1.0; casters.nodes.len()];
    };
    let mut out = vec![1.0f32; casters.nodes.len()];
    let chunks = strand_chunks(casters, &mut out);
    chunks.into_par_iter().for_each(|(strand, out)| {
        let range = casters.strands[strand].clone();
        for (value, node) in out.iter_mut().zip(range) {
            *value = grid.transmittance(casters.nodes[node], casters.radii[node], Some(strand as u32));
        }
    });
    out
}

/// A point of a strand's ribbon that takes the key light: a node, or a point between two.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Receiver {
    /// Where it is (on the strand's centre line).
    pub position: Vec3,
    /// Unit vector across the strand, as its ribbon is drawn (facing the camera).
    pub across: Vec3,
    /// The strand's radius there.
    pub radius: f32,
    /// The strand it lies on (an index into [`ShadowCasters::strands`]), which does not shadow it.
    pub strand: u32,
}

/// [`key_light_transmittance`] for each half of each receiver's ribbon: the half on the
/// `-across` and the half on the `+across` side, each a receiver half the radius wide about its
/// middle. A renderer that interpolates the two across the ribbon shows the open half of a
/// half-covered strand lit (seen from the light, the covered half is the one hidden). Receivers
/// are independent: the same bytes on any number of threads.
#[must_use]
pub fn ribbon_transmittance(casters: &ShadowCasters<'_>, toward_light: Vec3, receivers: &[Receiver]) -> Vec<[f32; 2]> {
    let Some(grid) = LightGrid::new(casters, toward_light) else {
        return vec![[1.0; 2]; receivers.len()];
    };
    receivers
        .par_iter()
        .map(|receiver| {
            let r = 0.5 * receiver.radius.max(0.0);
            let across = receiver.across * r;
            [
                grid.transmittance(receiver.position - across, r, Some(receiver.strand)),
                grid.transmittance(receiver.position + across, r, Some(receiver.strand)),
            ]
        })
        .collect()
}

/// `out` (one value per node) cut into each strand's nodes, with the strand's index.
fn strand_chunks<'a, T>(casters: &ShadowCasters<'_>, out: &'a mut [T]) -> Vec<(usize, &'a mut [T])> {
    let mut chunks = Vec::with_capacity(casters.strands.len());
    let mut rest = out;
    let mut at = 0;
    for (index, strand) in casters.strands.iter().enumerate() {
        assert!(strand.start >= at && strand.end <= casters.nodes.len(), "strands are ordered and inside nodes");
        let (_, tail) = std::mem::take(&mut rest).split_at_mut(strand.start - at);
        let (head, tail) = tail.split_at_mut(strand.len());
        rest = tail;
        at = strand.end;
        chunks.push((index, head));
    }
    chunks
}

/// The transmittance toward `toward_light` at `points` (each of radius `radius`; 0: points),
/// through every strand and surface of `casters`: what a surface under the strands receives.
#[must_use]
pub fn points_transmittance(casters: &ShadowCasters<'_>, toward_light: Vec3, points: &[Vec3], radius: f32) -> Vec<f32> {
    let Some(grid) = LightGrid::new(casters, toward_light) else {
        return vec![1.0; points.len()];
    };
    points.par_iter().map(|p| grid.transmittance(*p, radius, None)).collect()
}

/// One strand segment projected across the light: 2D ends, depths toward the light, radii.
#[derive(Clone, Copy, Debug)]
struct Segment {
    a: Vec2,
    b: Vec2,
    depth: [f32; 2],
    radius: [f32; 2],
    strand: u32,
}

/// One opaque triangle projected across the light.
#[derive(Clone, Copy, Debug)]
struct Surface {
    corners: [Vec2; 3],
    depth: [f32; 3],
}

/// The casters projected onto the plane across the light and bucketed in a uniform grid.
struct LightGrid {
    /// Light space: across (u, v) and toward the light (w).
    u: Vec3,
    v: Vec3,
    w: Vec3,
    origin: Vec2,
    cell: f32,
    size: [usize; 2],
    segments: Vec<Segment>,
    /// Cell `i`'s segments: `segment_items[segment_starts[i]..segment_starts[i + 1]]`.
    segment_starts: Vec<u32>,
    segment_items: Vec<u32>,
    surfaces: Vec<Surface>,
    surface_starts: Vec<u32>,
    surface_items: Vec<u32>,
    surface_epsilon: f32,
    opacity: f32,
}

impl LightGrid {
    /// `None` when there is nothing to cast a shadow or the light has no direction.
    fn new(casters: &ShadowCasters<'_>, toward_light: Vec3) -> Option<Self> {
        let w = toward_light.try_normalize()?;
        let (u, v) = w.any_orthonormal_pair();
        let project = |p: Vec3| (Vec2::new(p.dot(u), p.dot(v)), p.dot(w));
        let mut segments = Vec::new();
        for (strand, range) in casters.strands.iter().enumerate() {
            for k in range.start..range.end.saturating_sub(1) {
                let (a, za) = project(casters.nodes[k]);
                let (b, zb) = project(casters.nodes[k + 1]);
                let radius = [casters.radii[k].max(0.0), casters.radii[k + 1].max(0.0)];
                segments.push(Segment { a, b, depth: [za, zb], radius, strand: strand as u32 });
            }
        }
        let surfaces: Vec<Surface> = casters
            .surfaces
            .iter()
            .map(|corners| {
                let p = corners.map(project);
                Surface { corners: p.map(|(c, _)| c), depth: p.map(|(_, z)| z) }
            })
            .collect();
        if segments.is_empty() && surfaces.is_empty() {
            return None;
        }
        let points = casters.nodes.iter().chain(casters.surfaces.iter().flatten());
        let (mut low, mut high) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
        let (mut depth_low, mut depth_high) = (f32::INFINITY, f32::NEG_INFINITY);
        for p in points {
            let (q, z) = project(*p);
            low = low.min(q);
            high = high.max(q);
            depth_low = depth_low.min(z);
            depth_high = depth_high.max(z);
        }
        let reach = casters.radii.iter().copied().fold(0.0f32, f32::max);
        low -= Vec2::splat(2.0 * reach);
        high += Vec2::splat(2.0 * reach);
        let extent = (high - low).max(Vec2::splat(1e-6));
        if !extent.is_finite() {
            return None;
        }
        let area = extent.x * extent.y;
        let wanted = (segments.len().max(surfaces.len()) as f32 * CELLS_PER_SEGMENT).max(1.0);
        let cell = (area / wanted).sqrt().max(extent.max_element() / MAX_CELLS_PER_SIDE as f32).max(1e-9);
        let size = [
            ((extent.x / cell).ceil() as usize).clamp(1, MAX_CELLS_PER_SIDE),
            ((extent.y / cell).ceil() as usize).clamp(1, MAX_CELLS_PER_SIDE),
        ];
        let scene = extent.max_element().max(depth_high - depth_low);
        let mut grid = Self {
            u,
            v,
            w,
            origin: low,
            cell,
            size,
            segments: Vec::new(),
            segment_starts: Vec::new(),
            segment_items: Vec::new(),
            surfaces: Vec::new(),
            surface_starts: Vec::new(),
            surface_items: Vec::new(),
            surface_epsilon: SURFACE_EPSILON * scene,
            opacity: casters.opacity.clamp(0.0, 1.0),
        };
        // A segment reaches every node within its radius plus the node's own.
        let boxes: Vec<(Vec2, Vec2)> = segments
            .iter()
            .map(|s| {
                let r = Vec2::splat(s.radius[0].max(s.radius[1]) + reach);
                (s.a.min(s.b) - r, s.a.max(s.b) + r)
            })
            .collect();
        (grid.segment_starts, grid.segment_items) = grid.bucket(&boxes);
        let boxes: Vec<(Vec2, Vec2)> = surfaces
            .iter()
            .map(|s| {
                let [a, b, c] = s.corners;
                (a.min(b).min(c), a.max(b).max(c))
            })
            .collect();
        (grid.surface_starts, grid.surface_items) = grid.bucket(&boxes);
        grid.segments = segments;
        grid.surfaces = surfaces;
        Some(grid)
    }

    /// The cell range a box covers.
    fn cells(&self, low: Vec2, high: Vec2) -> ([usize; 2], [usize; 2]) {
        let index = |p: Vec2| {
            let q = (p - self.origin) / self.cell;
            [
                (q.x.floor().max(0.0) as usize).min(self.size[0] - 1),
                (q.y.floor().max(0.0) as usize).min(self.size[1] - 1),
            ]
        };
        (index(low), index(high))
    }

    /// Items by cell (compressed rows): every box listed in each cell it overlaps, in item order.
    fn bucket(&self, boxes: &[(Vec2, Vec2)]) -> (Vec<u32>, Vec<u32>) {
        let cell_count = self.size[0] * self.size[1];
        let mut counts = vec![0u32; cell_count + 1];
        for &(low, high) in boxes {
            let (a, b) = self.cells(low, high);
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    counts[y * self.size[0] + x + 1] += 1;
                }
            }
        }
        for i in 0..cell_count {
            counts[i + 1] += counts[i];
        }
        let mut fill = counts.clone();
        let mut items = vec![0u32; counts[cell_count] as usize];
        for (item, &(low, high)) in boxes.iter().enumerate() {
            let (a, b) = self.cells(low, high);
            for y in a[1]..=b[1] {
                for x in a[0]..=b[0] {
                    let slot = &mut fill[y * self.size[0] + x];
                    items[*slot as usize] = item as u32;
                    *slot += 1;
                }
            }
        }
        (counts, items)
    }

    /// The light reaching a point of cross-section radius `radius` at `p`, leaving out strand
    /// `own`'s segments.
    fn transmittance(&self, p: Vec3, radius: f32, own: Option<u32>) -> f32 {
        let q = Vec2::new(p.dot(self.u), p.dot(self.v));
        let depth = p.dot(self.w);
        let (cell, _) = self.cells(q, q);
        let index = cell[1] * self.size[0] + cell[0];
        let mut light = 1.0f32;
        let surfaces = self.surface_starts[index] as usize..self.surface_starts[index + 1] as usize;
        for &item in &self.surface_items[surfaces] {
            if self.surfaces[item as usize].blocks(q, depth + self.surface_epsilon) {
                return 0.0;
            }
        }
        // A cell lists a strand's segments one after another; a strand covers the receiver
        // once, by the largest share of its segments (two meet at each node).
        let segments = self.segment_starts[index] as usize..self.segment_starts[index + 1] as usize;
        let (mut strand, mut covered) = (u32::MAX, 0.0f32);
        for &item in &self.segment_items[segments] {
            let segment = &self.segments[item as usize];
            if Some(segment.strand) == own {
                continue;
            }
            if segment.strand != strand {
                light *= 1.0 - self.opacity * covered;
                (strand, covered) = (segment.strand, 0.0);
            }
            covered = covered.max(segment.covered(q, depth, radius));
        }
        (light * (1.0 - self.opacity * covered)).max(0.0)
    }
}

impl Segment {
    /// The share of a receiver's width (`radius` either side of `q`, at `depth` toward the
    /// light) this segment covers from the light.
    fn covered(&self, q: Vec2, depth: f32, radius: f32) -> f32 {
        let along = self.b - self.a;
        let length2 = along.length_squared();
        let s = if length2 > 0.0 { ((q - self.a).dot(along) / length2).clamp(0.0, 1.0) } else { 0.0 };
        // Only what stands nearer the light than the receiver casts onto it.
        let z = self.depth[0] + (self.depth[1] - self.depth[0]) * s;
        if z <= depth {
            return 0.0;
        }
        let d = q.distance(self.a + along * s);
        let r = self.radius[0] + (self.radius[1] - self.radius[0]) * s;
        if radius <= 0.0 {
            return if d < r { 1.0 } else { 0.0 };
        }
        let overlap = (d + r).min(radius) - (d - r).max(-radius);
        (overlap / (2.0 * radius)).clamp(0.0, 1.0)
    }
}

impl Surface {
    /// Whether the triangle covers `q` nearer the light than `depth`.
    fn blocks(&self, q: Vec2, depth: f32) -> bool {
        let [a, b, c] = self.corners;
        let area = (b - a).perp_dot(c - a);
        if area == 0.0 {
            return false;
        }
        let wa = (b - q).perp_dot(c - q) / area;
        let wb = (c - q).perp_dot(a - q) / area;
        let wc = 1.0 - wa - wb;
        if wa < 0.0 || wb < 0.0 || wc < 0.0 {
            return false;
        }
        wa * self.depth[0] + wb * self.depth[1] + wc * self.depth[2] > depth
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Strands straight up +Y from roots on the plane y = 0, each `nodes` long, radius `r`.
    fn upright(roots: &[Vec2], nodes: usize, r: f32) -> (Vec<Vec3>, Vec<f32>, Vec<Range<usize>>) {
        let mut points = Vec::new();
        let mut ranges = Vec::new();
        for root in roots {
            let start = points.len();
            points.extend((0..nodes).map(|k| Vec3::new(root.x, k as f32 * 0.1, root.y)));
            ranges.push(start..points.len());
        }
        let radii = vec![r; points.len()];
        (points, radii, ranges)
    }

    fn trace(points: &[Vec3], radii: &[f32], ranges: &[Range<usize>], surfaces: &[[Vec3; 3]], light: Vec3) -> Vec<f32> {
        key_light_transmittance(&ShadowCasters { nodes: points, radii, strands: ranges, surfaces, opacity: 1.0 }, light)
    }

    #[test]
    fn a_lone_strand_is_fully_lit() {
        // A strand never shadows itself, even lit along its length.
        let (points, radii, ranges) = upright(&[Vec2::ZERO], 8, 0.01);
        for toward in [Vec3::new(1.0, 1.0, 0.0).normalize(), Vec3::Y] {
            let light = trace(&points, &radii, &ranges, &[], toward);
            assert!(light.iter().all(|&t| t == 1.0), "toward {toward}: {light:?}");
        }
    }

    #[test]
    fn a_strand_behind_a_wall_of_strands_is_darker_than_the_wall() {
        // A dense wall along z at x = 0, the receiver at x = -0.5, the light from +x (level).
        let wall: Vec<Vec2> = (0..200).map(|i| Vec2::new(0.0, -0.5 + i as f32 * 0.005)).collect();
        let mut roots = wall.clone();
        roots.push(Vec2::new(-0.5, 0.0013));
        let (points, radii, ranges) = upright(&roots, 8, 0.004);
        let light = trace(&points, &radii, &ranges, &[], Vec3::X);
        let receiver = &light[ranges[200].clone()];
        let front = &light[ranges[100].clone()];
        let mean = |t: &[f32]| t.iter().sum::<f32>() / t.len() as f32;
        assert!(mean(front) > 0.99, "the wall's own strands stand in the light: {front:?}");
        assert!(mean(receiver) < 0.1, "behind the wall: {receiver:?}");
        assert!(mean(receiver) < mean(front));
    }

    #[test]
    fn a_blocker_covers_its_share_of_the_receivers_width() {
        // Receiver and blocker of equal radius, the blocker toward the light (+x), offset across.
        let r = 0.01;
        for (offset, expected) in [(0.0, 0.0), (r, 0.5), (2.0 * r, 1.0), (3.0 * r, 1.0)] {
            let (points, radii, ranges) = upright(&[Vec2::new(0.0, 0.0), Vec2::new(0.5, offset)], 4, r);
            let light = trace(&points, &radii, &ranges, &[], Vec3::X);
            for t in &light[ranges[0].clone()] {
                assert!((t - expected).abs() < 1e-5, "offset {offset}: {t} against {expected}");
            }
            // The blocker, nearer the light, is lit whatever the offset.
            assert!(light[ranges[1].clone()].iter().all(|&t| t == 1.0));
        }
    }

    #[test]
    fn a_half_covered_ribbon_is_lit_on_its_open_half() {
        // The blocker covers the receiver's +z half from the light (+x); the ribbon runs across z.
        let r = 0.01;
        let (points, radii, ranges) = upright(&[Vec2::new(0.0, 0.0), Vec2::new(0.5, r)], 4, r);
        let casters = ShadowCasters { nodes: &points, radii: &radii, strands: &ranges, surfaces: &[], opacity: 1.0 };
        let receivers: Vec<Receiver> = ranges[0]
            .clone()
            .map(|k| Receiver { position: points[k], across: Vec3::Z, radius: r, strand: 0 })
            .collect();
        let light = ribbon_transmittance(&casters, Vec3::X, &receivers);
        for [minus, plus] in &light {
            assert!(*minus > 0.99 && *plus < 0.01, "open half {minus}, covered half {plus}");
        }
    }

    #[test]
    fn skin_between_the_light_and_a_node_blocks_it() {
        // A strand under a large triangle at y = 2, the light from above.
        let (points, radii, ranges) = upright(&[Vec2::ZERO], 8, 0.01);
        let roof = [Vec3::new(-5.0, 2.0, -5.0), Vec3::new(5.0, 2.0, -5.0), Vec3::new(0.0, 2.0, 5.0)];
        let light = trace(&points, &radii, &ranges, &[roof], Vec3::Y);
        assert!(light.iter().all(|&t| t == 0.0), "{light:?}");
        // From below, the roof is behind the strand: no shadow.
        let light = trace(&points, &radii, &ranges, &[roof], -Vec3::Y);
        assert!(light.iter().all(|&t| t == 1.0), "{light:?}");
        // The roots stand on a floor they grow from: it does not shadow them from above.
        let floor = [Vec3::new(-5.0, 0.0, -5.0), Vec3::new(5.0, 0.0, -5.0), Vec3::new(0.0, 0.0, 5.0)];
        let light = trace(&points, &radii, &ranges, &[floor], Vec3::Y);
        assert!(light.iter().all(|&t| t == 1.0), "{light:?}");
        let under = points_transmittance(
            &ShadowCasters { nodes: &points, radii: &radii, strands: &ranges, surfaces: &[roof], opacity: 1.0 },
            Vec3::Y,
            &[Vec3::new(1.0, 0.0, 0.0)],
            0.0,
        );
        assert_eq!(under, vec![0.0]);
    }

    #[test]
    fn same_bytes_on_any_number_of_threads() {
        let roots: Vec<Vec2> = (0..400)
            .map(|i| {
                let a = i as f32 * 2.399_963;
                Vec2::new(a.cos(), a.sin()) * (i as f32).sqrt() * 0.02
            })
            .collect();
        let (mut points, radii, ranges) = upright(&roots, 10, 0.006);
        for (k, p) in points.iter_mut().enumerate() {
            p.x += (k as f32 * 0.37).sin() * 0.05 * p.y;
        }
        let light = Vec3::new(0.3, 0.8, -0.5).normalize();
        let run = |threads| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| trace(&points, &radii, &ranges, &[], light))
        };
        let one = run(1);
        let four = run(4);
        assert_eq!(
            one.iter().map(|t| t.to_bits()).collect::<Vec<_>>(),
            four.iter().map(|t| t.to_bits()).collect::<Vec<_>>()
        );
        let shadowed = one.iter().filter(|&&t| t < 1.0).count();
        assert!(shadowed > one.len() / 10, "a tuft shadows itself: {shadowed} of {}", one.len());
    }
}
