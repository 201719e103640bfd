//! The fur's own skin as a few planes per strand.
//!
//! Each strand keeps up to [`SKIN_PLANES`] half-spaces, in its rest frame relative to its root,
//! that every node must stay in: the root's tangent plane, and the planes of the faces within the
//! strand's reach that rise above it (a crease, the far wall of a fold, the base of an ear),
//! the most restrictive first. Outside the skin, locally, is the root's upper half-space where
//! the surface is convex (the surface falls away below the tangent plane) and the intersection
//! with the rising faces' half-spaces where it is concave, so the intersection of these
//! half-spaces lies outside the surface within the strand's reach. The planes turn and move with
//! the strand's posed frame and root, so they follow skinning and rigid motion with no per-step
//! mesh query, and a node is tested with a dot product per plane: the same small per-strand
//! input for the CPU and the GPU kernel. Planes are relaxed where the rest strand itself would
//! cross them, so the rest pose is never moved. Where the intersection of the planes still
//! reaches below the surface (saddles, creases), [`surface`](super::surface) keeps triangles.

use std::collections::BinaryHeap;

use glam::{Vec3, Vec4};
use rayon::prelude::*;

use super::bvh::{Bvh, ByDistance, box_may_reach};
use crate::fur::FurStructure;

/// Half-spaces per strand.
pub const SKIN_PLANES: usize = 16;

/// An unused plane: `0 . x >= -1` holds everywhere.
const NO_PLANE: Vec4 = Vec4::new(0.0, 0.0, 0.0, 1.0);

/// The skin planes of every strand of `fur`: `(n, h)` in the strand's rest frame, the node `x`
/// must satisfy `n . (x - root) >= -h`. A strand's planes fill its first slots; the rest have
/// `n` zero (the GPU kernel stops reading at the first).
#[must_use]
pub fn skin_planes(fur: &FurStructure) -> Vec<[Vec4; SKIN_PLANES]> {
    skin_planes_of(fur, 0..fur.vertex_count()).1
}

/// The skin planes of `strands` alone (those a groom dab reshaped), with the size of the grid
/// cell they were found in: the longest strand's reach. Equal to [`skin_planes`]'s for the same
/// cell (the cell orders the faces a tie between planes is decided by).
pub(crate) fn skin_planes_of(
    fur: &FurStructure,
    strands: impl Iterator<Item = usize>,
) -> (f32, Vec<[Vec4; SKIN_PLANES]>) {
    let v = fur.vertex_count();
    let layers = fur.layers as usize;
    let positions = &fur.positions;
    let mesh = &fur.mesh;
    let reach: Vec<f32> = (0..v)
        .map(|j| (0..layers).map(|k| positions[(k + 1) * v + j].distance(positions[k * v + j])).sum::<f32>())
        .collect();
    let cell = grid_cell(&mesh.positions, &reach);
    let faces = Faces { bvh: Bvh::new(&mesh.positions, &mesh.triangles), cell };
    let strands: Vec<usize> = strands.collect();
    // Strands are independent: each thread keeps its own scratch, and the order of the result
    // is the strands'.
    let planes = strands
        .par_iter()
        .with_min_len(64)
        .map_init(Vec::new, |rising, &j| strand_planes(fur, &faces, reach[j], j, rising))
        .collect();
    (cell, planes)
}

/// The skin's triangles for the planes' queries, and the cell that orders them.
struct Faces {
    bvh: Bvh,
    /// The cover's ties are decided by the order faces come in: that of a grid of this cell
    /// walked x, y, z about the root, a face where the walk first meets it, then by index.
    cell: f32,
}

impl Faces {
    /// The order key of triangle `t` (lower corner `lo`) for a walk from `root` out to `r`.
    fn key(&self, lo: Vec3, root: Vec3, r: f32, t: u32) -> ([i32; 3], u32) {
        let cell = |p: Vec3| (p / self.cell).floor().as_ivec3();
        (cell(lo).max(cell(root - Vec3::splat(r))).to_array(), t)
    }
}

/// A rising face within reach: its order key, distance to the root and corners.
type Rising = (([i32; 3], u32), f32, [Vec3; 3]);

/// Most rising faces one strand's cover is counted over, and most candidate planes it chooses
/// from, where it has more than [`EXACT_RISING`] rising faces or the whole cover would cost
/// more than [`EXACT_COVER_WORK`]: the nearest faces, and one plane per direction bin (see
/// [`thin_candidates`]). Dense meshes (a human's 37,000
/// triangles under a coat as long as a hand) put thousands of faces within a strand's reach; a
/// cover counted over all of them is quadratic in them. Faces the thinned cover leaves above
/// the planes are caught by the skin's triangles (`surface`), as at any crease.
const COVER_FACES: usize = 256;
const COVER_CANDIDATES: usize = 48;
/// Rising faces above which a strand's cover is thinned without looking for the rest.
const EXACT_RISING: usize = 512;
/// Candidate-face tests above which a strand's cover is thinned (above every strand of the
/// built-ins, the Fox, Spot and Cesium Man, whose covers stay exact: at most 15,520 there).
const EXACT_COVER_WORK: usize = 1 << 14;

/// Strand `j`'s planes (see [`skin_planes`]).
fn strand_planes(
    fur: &FurStructure,
    faces: &Faces,
    reach: f32,
    j: usize,
    rising: &mut Vec<Rising>,
) -> [Vec4; SKIN_PLANES] {
    let v = fur.vertex_count();
    let (positions, mesh) = (&fur.positions, &fur.mesh);
    let root = positions[j];
    let nodes: Vec<Vec3> = (1..=fur.layers as usize).map(|k| positions[k * v + j] - root).collect();
    let normal = mesh.normals[j].try_normalize().or_else(|| nodes.last().and_then(|t| t.try_normalize()));
    let mut planes = [NO_PLANE; SKIN_PLANES];
    let Some(n0) = normal else { return planes };
    // Relaxed so the rest strand satisfies the plane.
    let relax = |n: Vec3, h: f32| nodes.iter().map(|x| -n.dot(*x)).fold(h, f32::max);
    planes[0] = n0.extend(relax(n0, 0.0));
    let r = reach * 1.05;
    if r <= 0.0 {
        return planes;
    }
    // The faces within reach that rise above the tangent plane, and the planes of those with
    // the root on their upper side: cover the rising faces greedily, each plane taken for the
    // most faces that lie on or below it.
    rising.clear();
    // Most faces within reach lie below the tangent plane: whole subtrees of them are skipped.
    let threshold = 1e-6 * r;
    let keep = |lo, hi| box_may_reach(lo, hi, root, r, n0, threshold);
    let rising_face = |t: u32| {
        let corners = mesh.triangles[t as usize].map(|i| mesh.positions[i as usize]);
        let rise = corners.iter().map(|y| n0.dot(*y - root)).fold(f32::MIN, f32::max);
        if rise <= threshold {
            return None;
        }
        let [a, b, c] = corners;
        let distance = distance_to_triangle(root, a, b, c);
        (distance <= r).then(|| (faces.key(a.min(b).min(c), root, r, t), distance, corners))
    };
    // Nearest box first, all of them while the faces are few; past `EXACT_RISING` of them only
    // the nearest `COVER_FACES` are wanted, and the walk stops once no nearer one can come.
    // Both closures below read the heap of the nearest and the count (one writes, one reads):
    // shared through cells.
    let nearest = std::cell::RefCell::new(BinaryHeap::new());
    let found = std::cell::Cell::new(0_usize);
    faces.bvh.visit_nearest(
        root,
        keep,
        |t| {
            if let Some(face) = rising_face(t) {
                let mut nearest = nearest.borrow_mut();
                nearest.push(ByDistance(face.1, face.0));
                if nearest.len() > COVER_FACES {
                    nearest.pop();
                }
                rising.push(face);
                found.set(found.get() + 1);
            }
        },
        |d| {
            let nearest = nearest.borrow();
            found.get() > EXACT_RISING && nearest.peek().is_some_and(|worst| d > worst.0)
        },
    );
    let complete = rising.len() <= EXACT_RISING;
    let candidate = |[a, b, c]: [Vec3; 3]| {
        let nf = (b - a).cross(c - a).try_normalize()?;
        let d = nf.dot(root - a);
        if d < -1e-6 * r {
            return None;
        }
        let h = relax(nf, d.max(0.0));
        // A plane the rest strand crosses covers nothing it was taken for.
        (h <= d.max(0.0) + 1e-4 * r).then(|| nf.extend(h))
    };
    let mut candidates = Vec::new();
    if complete {
        rising.sort_unstable_by_key(|(key, _, _)| *key);
        candidates.extend(rising.iter().filter_map(|(_, _, t)| candidate(*t)));
    }
    if !complete || candidates.len() * rising.len() > EXACT_COVER_WORK {
        // The nearest faces (ties in the walk's order), so the thinned cover keeps the faces a
        // strand meets first.
        rising.sort_by(|x, y| x.1.total_cmp(&y.1).then(x.0.cmp(&y.0)));
        rising.truncate(COVER_FACES);
        candidates = thin_candidates(rising.iter().filter_map(|(_, _, t)| candidate(*t)));
    }
    let covers = |plane: Vec4, corners: &[Vec3; 3]| {
        corners.iter().all(|y| plane.truncate().dot(*y - root) <= -plane.w + 1e-5 * r)
    };
    // Which faces each candidate covers, one bit a face, counted once: the greedy rounds then
    // count the still uncovered ones a word at a time.
    let words = rising.len().div_ceil(64);
    let bits = |plane: Vec4| {
        let mut set = vec![0_u64; words];
        for (f, (_, _, t)) in rising.iter().enumerate() {
            if covers(plane, t) {
                set[f / 64] |= 1 << (f % 64);
            }
        }
        set
    };
    let mut uncovered: Vec<u64> = bits(planes[0]).iter().map(|w| !w).collect();
    if let Some(last) = uncovered.last_mut()
        && !rising.len().is_multiple_of(64)
    {
        *last &= (1 << (rising.len() % 64)) - 1;
    }
    let coverage: Vec<Vec<u64>> = candidates.iter().map(|&plane| bits(plane)).collect();
    for slot in planes.iter_mut().skip(1) {
        // The last of the candidates covering the most (as `max_by_key` breaks ties).
        let best = coverage
            .iter()
            .enumerate()
            .map(|(c, set)| (set.iter().zip(&uncovered).map(|(s, u)| (s & u).count_ones()).sum::<u32>(), c))
            .max_by_key(|(count, _)| *count);
        let Some((_, c)) = best.filter(|(count, _)| *count > 0) else { break };
        *slot = candidates[c];
        for (u, s) in uncovered.iter_mut().zip(&coverage[c]) {
            *u &= !s;
        }
    }
    planes
}

/// At most [`COVER_CANDIDATES`] of `candidates` (in their order): the first of each direction
/// bin (the octahedral map of the normal on a 16 x 16 grid, about 8 degrees a bin), as faces of
/// one smooth patch give near-equal planes and one of them covers what the others would.
fn thin_candidates(candidates: impl Iterator<Item = Vec4>) -> Vec<Vec4> {
    let mut seen = std::collections::HashSet::new();
    candidates
        .filter(|plane| {
            let n = plane.truncate();
            let p = n / (n.x.abs() + n.y.abs() + n.z.abs());
            let (x, y) = if p.z >= 0.0 {
                (p.x, p.y)
            } else {
                ((1.0 - p.y.abs()) * p.x.signum(), (1.0 - p.x.abs()) * p.y.signum())
            };
            let bin = |u: f32| ((u * 0.5 + 0.5) * 16.0).clamp(0.0, 15.0) as u32;
            seen.insert(bin(x) * 16 + bin(y))
        })
        .take(COVER_CANDIDATES)
        .collect()
}

/// Rounds of [`skin_cone`]'s search for its axis.
const CONE_ROUNDS: u32 = 64;

/// One cone that holds within every plane of a strand's `planes` ([`skin_planes`]), for a
/// screen cheaper than the planes: `(a, s)`, in the same rest frame, such that a node `x` with
/// `a . (x - root) >= s |x - root|` satisfies every plane. Every plane's `h` is at least 0, and
/// `n . d >= a . d - |n - a| |d|`, so `s` is the largest `|n - a|` (plus rounding's share); the
/// axis `a` is searched to keep it small (Badoiu and Clarkson's walk toward the farthest normal,
/// kept on the unit sphere). Zero without planes: every node passes.
#[must_use]
pub fn skin_cone(planes: &[Vec4; SKIN_PLANES]) -> Vec4 {
    let normals: Vec<Vec3> = planes.iter().map(|p| p.truncate()).take_while(|n| *n != Vec3::ZERO).collect();
    let Some(&first) = normals.first() else { return Vec4::ZERO };
    let farthest = |a: Vec3| normals.iter().copied().max_by(|x, y| (*x - a).length().total_cmp(&(*y - a).length()));
    let mut axis = first;
    for round in 0..CONE_ROUNDS {
        let Some(far) = farthest(axis) else { break };
        axis = (axis + (far - axis) / (round as f32 + 2.0)).try_normalize().unwrap_or(axis);
    }
    let spread = normals.iter().map(|n| (*n - axis).length()).fold(0.0, f32::max);
    // What rounding takes off a dot product of unit vectors, and off turning both by a frame.
    axis.extend(spread * (1.0 + 1e-4) + 1e-5)
}

/// The cell of the grid whose walk orders a strand's faces (`Faces`) for strands of `reach`: the
/// longest reach, but no smaller than a 32nd of the mesh.
pub(super) fn grid_cell(points: &[Vec3], reach: &[f32]) -> f32 {
    let (lo, hi) = points.iter().fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(*p), h.max(*p)));
    let extent = (hi - lo).max_element();
    let floor = if extent.is_finite() && extent > 0.0 { extent / 32.0 } else { 1.0 };
    reach.iter().copied().fold(0.0_f32, f32::max).max(floor)
}

/// Distance from `p` to the triangle `abc` (Ericson, Real-Time Collision Detection 5.1.5).
pub(super) fn distance_to_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> f32 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(a);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p.distance(a + ab * (d1 / (d1 - d3)));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p.distance(a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return p.distance(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denominator = 1.0 / (va + vb + vc);
    p.distance(a + ab * (vb * denominator) + ac * (vc * denominator))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fur::{FurLength, FurParams, GrowthDirection};
    use crate::mesh::builtin::Builtin;

    /// A bald coat (every strand of length 0) gets its planes and skin triangles at once: the
    /// triangle grid's cells do not shrink with the fur.
    #[test]
    fn a_bald_coat_has_planes_without_a_huge_grid() {
        let (mesh, _) = Builtin::Sphere.mesh();
        let params = FurParams { layers: 8, length: FurLength::Constant(0.0), direction: GrowthDirection::default() };
        let fur = FurStructure::new(mesh, &params).unwrap();
        let planes = skin_planes(&fur);
        assert_eq!(planes.len(), fur.vertex_count());
        let surface = super::super::skin_surface(&fur, &planes);
        assert_eq!(surface.strands.len(), fur.vertex_count());
    }

    /// Every strand's planes fill a prefix of its slots (the GPU kernel reads up to the first
    /// unused one), on meshes with creases and saddles where strands take many planes.
    #[test]
    fn planes_fill_the_first_slots() {
        for builtin in [Builtin::Bunny, Builtin::Torus] {
            let (mesh, _) = builtin.mesh();
            let params =
                FurParams { layers: 8, length: FurLength::Constant(0.5), direction: GrowthDirection::default() };
            let fur = FurStructure::new(mesh, &params).unwrap();
            let planes = skin_planes(&fur);
            let mut most = 0;
            for (j, strand) in planes.iter().enumerate() {
                let used = strand.iter().take_while(|p| p.truncate() != Vec3::ZERO).count();
                assert!(
                    strand[used..].iter().all(|p| p.truncate() == Vec3::ZERO),
                    "{builtin:?} strand {j}: {strand:?}"
                );
                most = most.max(used);
            }
            assert!(most > 2, "{builtin:?}: no strand took more than {most} planes");
        }
    }

    /// A node a strand's cone clears is above every one of its planes (`n . d + h >= 0`, tested
    /// plane by plane), for directions all round each strand of a bunny and a torus; and the
    /// cone clears most of the upper half-space of a strand with one plane.
    #[test]
    fn the_cone_clears_only_what_every_plane_clears() {
        let mut rng = crate::rng::Rng::new(7);
        for builtin in [Builtin::Bunny, Builtin::Torus] {
            let (mesh, _) = builtin.mesh();
            let params =
                FurParams { layers: 8, length: FurLength::Constant(0.5), direction: GrowthDirection::default() };
            let fur = FurStructure::new(mesh, &params).unwrap();
            let (mut cleared, mut tested) = (0, 0);
            for (j, strand) in skin_planes(&fur).iter().enumerate() {
                let cone = skin_cone(strand);
                let used: Vec<Vec4> = strand.iter().copied().filter(|p| p.truncate() != Vec3::ZERO).collect();
                for _ in 0..64 {
                    let d = Vec3::new(rng.next_f32() - 0.5, rng.next_f32() - 0.5, rng.next_f32() - 0.5) * 2.0;
                    if cone.truncate().dot(d) < cone.w * d.length() {
                        continue;
                    }
                    cleared += 1;
                    for plane in &used {
                        let height = plane.x * d.x + plane.y * d.y + plane.z * d.z + plane.w;
                        assert!(height >= 0.0, "{builtin:?} strand {j}: {d} below {plane} ({height}) in {cone}");
                    }
                }
                tested += 64;
                if used.len() == 1 {
                    let n = used[0].truncate();
                    let up = n * 0.9 + n.any_orthonormal_vector() * 0.43;
                    assert!(cone.truncate().dot(up) >= cone.w * up.length(), "{builtin:?} strand {j}: {cone}");
                }
            }
            assert!(cleared * 4 > tested, "{builtin:?}: the cones cleared {cleared} of {tested}");
        }
    }
}
