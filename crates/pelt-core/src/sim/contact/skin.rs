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

use std::collections::HashMap;

use glam::{Vec3, Vec4};

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
    let grid = Grid::new(&mesh.positions, &mesh.triangles, cell);
    let mut stamp = vec![u32::MAX; mesh.triangles.len()];
    let mut candidates: Vec<Vec4> = Vec::new();
    let mut rising: Vec<[Vec3; 3]> = Vec::new();
    let planes = strands
        .map(|j| {
            let root = positions[j];
            let nodes: Vec<Vec3> = (1..=layers).map(|k| positions[k * v + j] - root).collect();
            let normal = mesh.normals[j].try_normalize().or_else(|| nodes.last().and_then(|t| t.try_normalize()));
            let mut planes = [NO_PLANE; SKIN_PLANES];
            let Some(n0) = normal else { return planes };
            // Relaxed so the rest strand satisfies the plane.
            let relax = |n: Vec3, h: f32| nodes.iter().map(|x| -n.dot(*x)).fold(h, f32::max);
            planes[0] = n0.extend(relax(n0, 0.0));
            let r = reach[j] * 1.05;
            if r <= 0.0 {
                return planes;
            }
            // The faces within reach that rise above the tangent plane, and the planes of those
            // with the root on their upper side: cover the rising faces greedily, each plane
            // taken for the most faces that lie on or below it.
            rising.clear();
            grid.near(root, r, |t| {
                if stamp[t as usize] == j as u32 {
                    return;
                }
                stamp[t as usize] = j as u32;
                let corners = mesh.triangles[t as usize].map(|i| mesh.positions[i as usize]);
                let [a, b, c] = corners;
                if distance_to_triangle(root, a, b, c) > r {
                    return;
                }
                let rise = corners.iter().map(|y| n0.dot(*y - root)).fold(f32::MIN, f32::max);
                if rise > 1e-6 * r {
                    rising.push(corners);
                }
            });
            candidates.clear();
            for [a, b, c] in &rising {
                let Some(nf) = (*b - *a).cross(*c - *a).try_normalize() else { continue };
                let d = nf.dot(root - *a);
                if d >= -1e-6 * r {
                    let h = relax(nf, d.max(0.0));
                    // A plane the rest strand crosses covers nothing it was taken for.
                    if h <= d.max(0.0) + 1e-4 * r {
                        candidates.push(nf.extend(h));
                    }
                }
            }
            let covers = |plane: Vec4, corners: &[Vec3; 3]| {
                corners.iter().all(|y| plane.truncate().dot(*y - root) <= -plane.w + 1e-5 * r)
            };
            let mut uncovered: Vec<bool> = rising.iter().map(|t| !covers(planes[0], t)).collect();
            for slot in planes.iter_mut().skip(1) {
                let best = candidates
                    .iter()
                    .map(|&plane| {
                        let count = rising.iter().zip(&uncovered).filter(|(t, u)| **u && covers(plane, t)).count();
                        (count, plane)
                    })
                    .max_by_key(|(count, _)| *count);
                let Some((count, plane)) = best.filter(|(count, _)| *count > 0) else { break };
                let _ = count;
                *slot = plane;
                for (t, u) in rising.iter().zip(uncovered.iter_mut()) {
                    if *u && covers(plane, t) {
                        *u = false;
                    }
                }
            }
            planes
        })
        .collect();
    (cell, planes)
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

/// Triangles binned by the cells their boxes cover.
pub(super) struct Grid {
    cell: f32,
    bins: HashMap<[i32; 3], Vec<u32>>,
}

impl Grid {
    pub(super) fn new(points: &[Vec3], triangles: &[[u32; 3]], cell: f32) -> Self {
        let mut bins: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
        let key = |p: Vec3| (p / cell).floor().as_ivec3().to_array();
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| points[i as usize]);
            let (lo, hi) = (key(a.min(b).min(c)), key(a.max(b).max(c)));
            for x in lo[0]..=hi[0] {
                for y in lo[1]..=hi[1] {
                    for z in lo[2]..=hi[2] {
                        bins.entry([x, y, z]).or_default().push(t as u32);
                    }
                }
            }
        }
        Self { cell, bins }
    }

    pub(super) fn near(&self, p: Vec3, r: f32, mut visit: impl FnMut(u32)) {
        let key = |p: Vec3| (p / self.cell).floor().as_ivec3().to_array();
        let (lo, hi) = (key(p - Vec3::splat(r)), key(p + Vec3::splat(r)));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    for &t in self.bins.get(&[x, y, z]).map_or(&[][..], Vec::as_slice) {
                        visit(t);
                    }
                }
            }
        }
    }
}

/// Distance from `p` to the triangle `abc` (Ericson, Real-Time Collision Detection 5.1.5).
/// The triangle grid's cell for strands of `reach`: the longest reach, but no smaller than a
/// 32nd of the mesh, so short or bald fur does not bin each triangle into millions of cells.
pub(super) fn grid_cell(points: &[Vec3], reach: &[f32]) -> f32 {
    let (lo, hi) = points.iter().fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(*p), h.max(*p)));
    let extent = (hi - lo).max_element();
    let floor = if extent.is_finite() && extent > 0.0 { extent / 32.0 } else { 1.0 };
    reach.iter().copied().fold(0.0_f32, f32::max).max(floor)
}

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
