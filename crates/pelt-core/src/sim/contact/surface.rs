//! The fur's own skin as triangles, where a strand's skin planes do not suffice.
//!
//! At saddles and concave spots the intersection of a strand's skin planes (see [`skin`](super::skin))
//! reaches below the surface. For such a strand the triangles that reach into that intersection
//! within the strand's reach are kept, with every triangle sharing a vertex with one; after the
//! planes, a node whose closest point on them lies behind the surface (signed by the
//! angle-weighted pseudonormal of the feature it lies on: face, edge or vertex) is turned out
//! above the plane through that point. Triangles are stored once, in the rest mesh's space; a
//! node is taken there by its strand's root and frame, as the planes are, so the test follows
//! skinning and rigid motion with no per-step mesh query. Strands on convex skin keep none and
//! pay nothing.

use std::collections::HashMap;

use glam::{Quat, Vec3, Vec4};
use rayon::prelude::*;

use super::bvh::{Bvh, box_may_reach_all};
use super::skin::{SKIN_PLANES, distance_to_triangle};
use crate::fur::FurStructure;

/// Words per stored triangle: its corners `a`, `b`, `c`, its face normal, the pseudonormals of
/// its edges `ab`, `bc`, `ca` and of its corners `a`, `b`, `c` (each a unit `xyz`); the first
/// word's `w` is the radius of the ball about the triangle's centroid that holds it (a query
/// skips a triangle that ball shows farther than the nearest found), the others' `w` unused.
pub const SURFACE_WORDS: usize = 10;

/// How far (relative to a strand's reach) a triangle may rise into the intersection of the
/// strand's planes before the strand keeps it: half the skin's stated bound (no node more than
/// 1e-5 of the fur's length below it), so a face the planes were fitted to, lying on its plane
/// to rounding, is not kept, and one rising farther is.
const KEEP_TOLERANCE: f32 = 5e-6;

/// Most triangles one strand keeps (the nearest to its root first).
pub const MAX_STRAND_TRIANGLES: usize = 48;

/// The skin triangles every strand tests its nodes against, from [`skin_surface`].
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SkinSurface {
    /// The stored triangles, in the rest mesh's space ([`SURFACE_WORDS`] words each).
    pub triangles: Vec<[Vec4; SURFACE_WORDS]>,
    /// Per strand, `(first, count)` in `lists`; count 0 for strands the planes suffice for.
    pub strands: Vec<[u32; 2]>,
    /// Triangle indices (into `triangles`) of every strand, one run per strand.
    pub lists: Vec<u32>,
    /// Each stored triangle's index in the mesh.
    pub mesh_triangles: Vec<u32>,
    /// Each stored triangle's bounding ball: the centroid (`xyz`) and the radius (`w`, as in
    /// its first word), packed apart so a query's cull reads 16 bytes per triangle.
    pub balls: Vec<Vec4>,
}

impl SkinSurface {
    /// The triangles strand `j` tests.
    #[must_use]
    pub fn strand(&self, j: usize) -> &[u32] {
        let [first, count] = self.strands.get(j).copied().unwrap_or([0, 0]);
        &self.lists[first as usize..(first + count) as usize]
    }

    /// The closest point of strand `j`'s triangles to `x` (rest space): `(point, pseudonormal,
    /// signed distance)`, negative behind the surface; `None` without triangles.
    #[must_use]
    pub fn closest(&self, j: usize, x: Vec3) -> Option<(Vec3, Vec3, f32)> {
        let mut best: Option<(f32, Vec3, Vec3)> = None;
        // What rounding can take off a ball's distance: a few dozen ulps of the coordinates.
        let slack = 4e-6 * x.abs().max_element();
        // A triangle whose ball's centre lies farther than its radius plus the nearest distance
        // found cannot be strictly nearer (only such a triangle replaces the best).
        let mut nearest = f32::INFINITY;
        for &t in self.strand(j) {
            let ball = self.balls[t as usize];
            let beyond = ball.w * (1.0 + 4e-6) + slack + nearest;
            if x.distance_squared(ball.truncate()) > beyond * beyond {
                continue;
            }
            let words = &self.triangles[t as usize];
            let (a, b, c) = (words[0].truncate(), words[1].truncate(), words[2].truncate());
            let (point, feature) = closest_feature(x, a, b, c);
            let d2 = (x - point).length_squared();
            if best.is_none_or(|(b, _, _)| d2 < b) {
                best = Some((d2, point, words[feature].truncate()));
                nearest = d2.sqrt();
            }
        }
        best.map(|(d2, point, normal)| {
            let distance = d2.sqrt();
            (point, normal, if normal.dot(x - point) < 0.0 { -distance } else { distance })
        })
    }

    /// [`SkinSurface::closest`] for a posed node: `x` in the world, the strand's posed `root`
    /// and `frame`, its `rest_root`; the point and normal come back in the world.
    #[must_use]
    pub fn closest_posed(
        &self,
        j: usize,
        x: Vec3,
        root: Vec3,
        frame: Quat,
        rest_root: Vec3,
    ) -> Option<(Vec3, Vec3, f32)> {
        let local = rest_root + frame.conjugate() * (x - root);
        self.closest(j, local).map(|(point, normal, d)| (root + frame * (point - rest_root), frame * normal, d))
    }
}

/// The centre of the ball a triangle's first word's `w` is the radius of.
fn centroid(a: Vec3, b: Vec3, c: Vec3) -> Vec3 {
    (a + b + c) * (1.0 / 3.0)
}

/// The closest point of triangle `abc` to `p` and the word of its feature's normal (Ericson,
/// Real-Time Collision Detection 5.1.5, with the region it ends in).
pub(crate) fn closest_feature(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> (Vec3, usize) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, 7);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, 8);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + ab * (d1 / (d1 - d3)), 4);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, 9);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + ac * (d2 / (d2 - d6)), 6);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), 5);
    }
    let denominator = 1.0 / (va + vb + vc);
    (a + ab * (vb * denominator) + ac * (vc * denominator), 3)
}

/// The triangles each strand of `fur` tests, given its skin `planes` (from
/// [`skin_planes`](super::skin_planes)).
#[must_use]
pub fn skin_surface(fur: &FurStructure, planes: &[[Vec4; SKIN_PLANES]]) -> SkinSurface {
    let scan = Scan::new(fur);
    // Strands are independent: each thread keeps its own stamps, and the order is the strands'.
    let kept: Vec<Vec<u32>> = (0..fur.vertex_count())
        .into_par_iter()
        .with_min_len(64)
        .map_init(|| Stamps::new(fur), |stamps, j| scan.strand(fur, planes, j, stamps))
        .collect();
    pack(&scan.words, kept.iter().map(Vec::as_slice))
}

/// `surface` (this fur's [`skin_surface`] before a groom dab) with `strands` found again for
/// `fur`'s new rest shape and `planes`: equal to [`skin_surface`] of the new fur, to the bit, at
/// the cost of the reshaped strands alone.
pub(crate) fn skin_surface_of(
    surface: &SkinSurface,
    fur: &FurStructure,
    planes: &[[Vec4; SKIN_PLANES]],
    strands: &[u32],
) -> SkinSurface {
    let scan = Scan::new(fur);
    let mut stamps = Stamps::new(fur);
    let mut kept: Vec<Vec<u32>> = (0..fur.vertex_count())
        .map(|j| surface.strand(j).iter().map(|&t| surface.mesh_triangles[t as usize]).collect())
        .collect();
    for &j in strands {
        kept[j as usize] = scan.strand(fur, planes, j as usize, &mut stamps);
    }
    pack(&scan.words, kept.iter().map(Vec::as_slice))
}

/// Stores each strand's triangles (mesh triangle indices), every triangle once, in the order
/// strands first reach them.
fn pack<'a>(words: &[Option<[Vec4; SURFACE_WORDS]>], kept: impl Iterator<Item = &'a [u32]>) -> SkinSurface {
    let mut surface = SkinSurface::default();
    let mut stored: HashMap<u32, u32> = HashMap::new();
    for strand in kept {
        let first = surface.lists.len() as u32;
        for &t in strand {
            let next = surface.triangles.len() as u32;
            let index = *stored.entry(t).or_insert_with(|| {
                let triangle = words[t as usize].expect("kept triangles have area");
                let centre = centroid(triangle[0].truncate(), triangle[1].truncate(), triangle[2].truncate());
                surface.balls.push(centre.extend(triangle[0].w));
                surface.triangles.push(triangle);
                surface.mesh_triangles.push(t);
                next
            });
            surface.lists.push(index);
        }
        surface.strands.push([first, strand.len() as u32]);
    }
    surface
}

/// What finding a strand's triangles needs: the mesh's triangles binned, their words, and which
/// triangles meet at each corner.
struct Scan {
    reach: Vec<f32>,
    bvh: Bvh,
    words: Vec<Option<[Vec4; SURFACE_WORDS]>>,
    corner_triangles: Vec<Vec<u32>>,
}

/// One thread's marks, per mesh triangle, of the last strand that kept it, so each strand
/// keeps a triangle once in time linear in what it meets.
struct Stamps {
    kept: Vec<u32>,
}

impl Stamps {
    fn new(fur: &FurStructure) -> Self {
        Self { kept: vec![u32::MAX; fur.mesh.triangles.len()] }
    }
}

impl Scan {
    fn new(fur: &FurStructure) -> Self {
        let v = fur.vertex_count();
        let layers = fur.layers as usize;
        let positions = &fur.positions;
        let mesh = &fur.mesh;
        let points = &mesh.positions;
        let reach: Vec<f32> = (0..v)
            .map(|j| (0..layers).map(|k| positions[(k + 1) * v + j].distance(positions[k * v + j])).sum::<f32>())
            .collect();
        let bvh = Bvh::new(points, &mesh.triangles);
        let words = triangle_words(points, &mesh.triangles);
        let mut corner_triangles: Vec<Vec<u32>> = vec![Vec::new(); points.len()];
        for (t, tri) in mesh.triangles.iter().enumerate() {
            if words[t].is_some() {
                for &i in tri {
                    corner_triangles[i as usize].push(t as u32);
                }
            }
        }
        Self { reach, bvh, words, corner_triangles }
    }

    /// Strand `j`'s triangles (mesh triangle indices), the nearest to its root first.
    fn strand(&self, fur: &FurStructure, planes: &[[Vec4; SKIN_PLANES]], j: usize, stamps: &mut Stamps) -> Vec<u32> {
        let mesh = &fur.mesh;
        let points = &mesh.positions;
        let root = fur.positions[j];
        let r = self.reach[j] * 1.05;
        let mut kept: Vec<(f32, u32)> = Vec::new();
        if r > 0.0 && j < planes.len() {
            let strand_planes: Vec<Vec4> = planes[j].iter().copied().filter(|p| p.truncate() != Vec3::ZERO).collect();
            let mut hits = Vec::new();
            let mut polygon = Vec::new();
            let words = &self.words;
            // A face wholly below one of the planes is clipped away: whole subtrees of them
            // (below the tangent plane, most of all) are skipped.
            let shifted = |plane: &Vec4| (plane.truncate(), -(plane.w - KEEP_TOLERANCE * r));
            let keep = |lo, hi| box_may_reach_all(lo, hi, root, r, strand_planes.iter().map(shifted));
            self.bvh.visit(keep, |t| {
                if words[t as usize].is_none() {
                    return;
                }
                let [a, b, c] = mesh.triangles[t as usize].map(|i| points[i as usize]);
                if distance_to_triangle(root, a, b, c) > r {
                    return;
                }
                polygon.clear();
                polygon.extend([a, b, c]);
                for plane in &strand_planes {
                    clip(&mut polygon, plane.truncate(), plane.w - KEEP_TOLERANCE * r, root);
                }
                let inside = polygon.len() >= 3
                    && (1..polygon.len() - 1)
                        .any(|i| distance_to_triangle(root, polygon[0], polygon[i], polygon[i + 1]) <= r);
                if inside {
                    hits.push(t);
                }
            });
            // The hits and every triangle sharing a corner with one, so the closest point of a
            // node behind a hit is among them.
            for &t in &hits {
                for &i in &mesh.triangles[t as usize] {
                    for &n in &self.corner_triangles[i as usize] {
                        if stamps.kept[n as usize] != j as u32 {
                            stamps.kept[n as usize] = j as u32;
                            let [a, b, c] = mesh.triangles[n as usize].map(|i| points[i as usize]);
                            kept.push((distance_to_triangle(root, a, b, c), n));
                        }
                    }
                }
            }
            kept.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            kept.truncate(MAX_STRAND_TRIANGLES);
        }
        kept.into_iter().map(|(_, t)| t).collect()
    }
}

/// Each triangle's corners and pseudonormals (Baerentzen and Aanaes 2005); `None` for one with
/// no area.
fn triangle_words(points: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Option<[Vec4; SURFACE_WORDS]>> {
    let faces: Vec<Option<Vec3>> = triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| points[i as usize]);
            (b - a).cross(c - a).try_normalize()
        })
        .collect();
    let mut edges: HashMap<(u32, u32), Vec3> = HashMap::new();
    let mut corners = vec![Vec3::ZERO; points.len()];
    for (tri, face) in triangles.iter().zip(&faces) {
        let Some(n) = face else { continue };
        for e in 0..3 {
            let (i, k) = (tri[e], tri[(e + 1) % 3]);
            *edges.entry((i.min(k), i.max(k))).or_default() += *n;
            let (p, q, s) = (points[i as usize], points[k as usize], points[tri[(e + 2) % 3] as usize]);
            let angle = (q - p).angle_between(s - p);
            if angle.is_finite() {
                corners[i as usize] += *n * angle;
            }
        }
    }
    triangles
        .iter()
        .zip(&faces)
        .map(|(tri, face)| {
            let n = (*face)?;
            let edge = |e: usize| {
                let (i, k) = (tri[e], tri[(e + 1) % 3]);
                edges[&(i.min(k), i.max(k))].try_normalize().unwrap_or(n)
            };
            let corner = |e: usize| corners[tri[e] as usize].try_normalize().unwrap_or(n);
            let [a, b, c] = tri.map(|i| points[i as usize]);
            let mut words =
                [a, b, c, n, edge(0), edge(1), edge(2), corner(0), corner(1), corner(2)].map(|w| w.extend(0.0));
            let centre = centroid(a, b, c);
            words[0].w = [a, b, c].iter().map(|y| y.distance(centre)).fold(0.0, f32::max);
            Some(words)
        })
        .collect()
}

/// Clips the convex `polygon` to the side of the plane where `n . (x - root) >= -h`.
fn clip(polygon: &mut Vec<Vec3>, n: Vec3, h: f32, root: Vec3) {
    if polygon.is_empty() {
        return;
    }
    let side = |x: Vec3| n.dot(x - root) + h;
    // Wholly on one side (most planes and faces): kept or gone as the loop below would leave it.
    let above = polygon.iter().filter(|x| side(**x) >= 0.0).count();
    if above == polygon.len() {
        return;
    }
    if above == 0 {
        polygon.clear();
        return;
    }
    let mut out = Vec::with_capacity(polygon.len() + 1);
    for i in 0..polygon.len() {
        let (x, y) = (polygon[i], polygon[(i + 1) % polygon.len()]);
        let (sx, sy) = (side(x), side(y));
        if sx >= 0.0 {
            out.push(x);
        }
        if (sx >= 0.0) != (sy >= 0.0) {
            out.push(x + (y - x) * (sx / (sx - sy)));
        }
    }
    *polygon = out;
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fur::{FurLength, FurParams, GrowthDirection};
    use crate::mesh::builtin::Builtin;
    use crate::sim::contact::skin_planes;

    fn furred(builtin: Builtin) -> FurStructure {
        let (mesh, _) = builtin.mesh();
        let radius = mesh.bounding_sphere().1;
        let direction = GrowthDirection { random_angle_rad: 0.4, seed: 5, ..GrowthDirection::default() };
        FurStructure::new(mesh, &FurParams { layers: 8, length: FurLength::Constant(0.12 * radius), direction })
            .unwrap()
    }

    /// Strands on convex skin keep no triangles (they cost nothing), nor do the torus's, whose
    /// planes suffice at its saddles too; the bunny's creases (the ears' bases) keep some, at
    /// most the cap.
    #[test]
    fn only_strands_where_the_planes_fall_short_keep_triangles() {
        for builtin in [Builtin::Sphere, Builtin::Torus] {
            let fur = furred(builtin);
            let surface = skin_surface(&fur, &skin_planes(&fur));
            assert!(surface.lists.is_empty(), "{} triangles kept on the {builtin:?}", surface.lists.len());
        }
        let bunny = furred(Builtin::Bunny);
        let surface = skin_surface(&bunny, &skin_planes(&bunny));
        let v = bunny.vertex_count();
        let kept = surface.strands.iter().filter(|[_, count]| *count > 0).count();
        let most = surface.strands.iter().map(|[_, count]| *count).max().unwrap_or(0);
        eprintln!("bunny: {kept} of {v} strands keep triangles, at most {most}, {} in all", surface.lists.len());
        assert!(kept > 0 && kept * 20 < v && most as usize <= MAX_STRAND_TRIANGLES);
    }

    /// The closest point and its feature against a dense sampling of the triangle.
    #[test]
    fn closest_features_match_sampling() {
        let (a, b, c) = (Vec3::new(0.0, 0.0, 0.0), Vec3::new(1.0, 0.1, 0.0), Vec3::new(0.3, 0.9, 0.2));
        let mut state = 7_u32;
        let mut next = move || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1 << 24) as f32 * 3.0 - 1.0
        };
        for _ in 0..200 {
            let p = Vec3::new(next(), next(), next());
            let (point, feature) = closest_feature(p, a, b, c);
            let n = 200;
            let mut best = f32::MAX;
            for i in 0..=n {
                for k in 0..=n - i {
                    let (s, t) = (i as f32 / n as f32, k as f32 / n as f32);
                    best = best.min(p.distance(a + (b - a) * s + (c - a) * t));
                }
            }
            assert!((p.distance(point) - best).abs() < 2e-2, "{p}: {} vs sampled {best}", p.distance(point));
            // The feature is where the point lies: a corner, an edge's inside or the face's.
            let on_segment = |u: Vec3, w: Vec3| (point - u).cross(w - u).length() < 1e-4;
            match feature {
                7 => assert!(point.distance(a) < 1e-5),
                8 => assert!(point.distance(b) < 1e-5),
                9 => assert!(point.distance(c) < 1e-5),
                4 => assert!(on_segment(a, b)),
                5 => assert!(on_segment(b, c)),
                6 => assert!(on_segment(c, a)),
                _ => assert_eq!(feature, 3),
            }
        }
    }
}
