//! A bounding volume hierarchy over the skin's triangles, for the per-strand setup queries
//! (`skin` and `surface`): a strand needs the triangles within its reach that rise above a
//! plane through its root, and on a dense mesh under long fur most triangles within reach lie
//! below it. Whole subtrees below the plane or beyond the reach are skipped, so a query costs
//! about what it finds rather than everything within reach.

use std::cmp::Reverse;
use std::collections::BinaryHeap;

use glam::Vec3;

/// Triangles in a leaf at most.
const LEAF: usize = 8;

#[derive(Clone, Copy, Debug)]
struct Node {
    lo: Vec3,
    hi: Vec3,
    /// Leaves: the first of `count` triangles in `order`. Inner nodes (`count == 0`): the first
    /// child; the second follows it.
    first: u32,
    count: u32,
}

/// The hierarchy: median splits along the longest axis of the triangles' centroids.
#[derive(Debug)]
pub(super) struct Bvh {
    nodes: Vec<Node>,
    order: Vec<u32>,
}

impl Bvh {
    pub(super) fn new(points: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        let corners = |t: u32| triangles[t as usize].map(|i| points[i as usize]);
        let bounds = |ts: &[u32]| {
            ts.iter().flat_map(|&t| corners(t)).fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)))
        };
        let centroid = |t: u32| {
            let [a, b, c] = corners(t);
            (a + b + c) * (1.0 / 3.0)
        };
        let mut order: Vec<u32> = (0..triangles.len() as u32).collect();
        let mut nodes = Vec::with_capacity(2 * triangles.len() / LEAF + 1);
        let (lo, hi) = bounds(&order);
        nodes.push(Node { lo, hi, first: 0, count: order.len() as u32 });
        // (node, range of `order` it holds), split until leaves are small.
        let mut stack = vec![(0_usize, 0..order.len())];
        while let Some((node, range)) = stack.pop() {
            if range.len() <= LEAF {
                continue;
            }
            let slice = &mut order[range.clone()];
            let (clo, chi) =
                slice.iter().map(|&t| centroid(t)).fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| (lo.min(p), hi.max(p)));
            let extent = chi - clo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let middle = slice.len() / 2;
            slice.select_nth_unstable_by(middle, |&a, &b| {
                centroid(a)[axis].total_cmp(&centroid(b)[axis]).then(a.cmp(&b))
            });
            let first = nodes.len();
            for part in [range.start..range.start + middle, range.start + middle..range.end] {
                let (lo, hi) = bounds(&order[part.clone()]);
                nodes.push(Node { lo, hi, first: part.start as u32, count: part.len() as u32 });
                stack.push((nodes.len() - 1, part));
            }
            nodes[node].first = first as u32;
            nodes[node].count = 0;
        }
        Self { nodes, order }
    }

    /// Visits every triangle of a subtree `keep` accepts (given its box's corners `lo`, `hi`),
    /// skipping the subtrees it refuses. `keep` must accept every box that holds a triangle the
    /// caller wants: the visit order is the tree's, so callers that need an order sort.
    pub(super) fn visit(&self, mut keep: impl FnMut(Vec3, Vec3) -> bool, mut visit: impl FnMut(u32)) {
        if self.order.is_empty() {
            return;
        }
        let mut stack = vec![0_u32];
        while let Some(n) = stack.pop() {
            let node = self.nodes[n as usize];
            if !keep(node.lo, node.hi) {
                continue;
            }
            if node.count > 0 {
                self.leaf(node).iter().for_each(|&t| visit(t));
            } else {
                stack.push(node.first + 1);
                stack.push(node.first);
            }
        }
    }

    /// Visits the triangles of the subtrees `keep` accepts, the box nearest `p` first, until
    /// `enough(d)` holds for `d` the least distance from `p` any box left could hold (less a
    /// margin for rounding): a caller that keeps the nearest few stops once none nearer can come.
    pub(super) fn visit_nearest(
        &self,
        p: Vec3,
        mut keep: impl FnMut(Vec3, Vec3) -> bool,
        mut visit: impl FnMut(u32),
        mut enough: impl FnMut(f32) -> bool,
    ) {
        if self.order.is_empty() {
            return;
        }
        let distance = |node: &Node| {
            let slack = 1e-5 * (p.abs().max_element() + (node.hi - node.lo).max_element());
            (p.clamp(node.lo, node.hi).distance(p) - slack).max(0.0)
        };
        let mut queue = BinaryHeap::new();
        queue.push(Reverse(ByDistance(distance(&self.nodes[0]), 0)));
        while let Some(Reverse(ByDistance(d, n))) = queue.pop() {
            if enough(d) {
                return;
            }
            let node = self.nodes[n as usize];
            if !keep(node.lo, node.hi) {
                continue;
            }
            if node.count > 0 {
                for &t in self.leaf(node) {
                    visit(t);
                }
            } else {
                for child in [node.first, node.first + 1] {
                    queue.push(Reverse(ByDistance(distance(&self.nodes[child as usize]), child)));
                }
            }
        }
    }

    fn leaf(&self, node: Node) -> &[u32] {
        &self.order[node.first as usize..(node.first + node.count) as usize]
    }
}

/// A distance and a key, ordered by the distance and then the key (a total order: heaps of
/// nearest things, here and in `skin`, pop the same element whatever the order of pushes).
#[derive(Clone, Copy, PartialEq)]
pub(super) struct ByDistance<K>(pub f32, pub K);

impl<K: Ord> Eq for ByDistance<K> {}

impl<K: Ord> PartialOrd for ByDistance<K> {
    fn partial_cmp(&self, other: &Self) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl<K: Ord> Ord for ByDistance<K> {
    fn cmp(&self, other: &Self) -> std::cmp::Ordering {
        self.0.total_cmp(&other.0).then(self.1.cmp(&other.1))
    }
}

/// Whether the box `lo..hi` may hold a point within `r` of `p` and a point `x` with
/// `n . (x - p) > h`, with room for rounding (a box is refused only when it is clearly out):
/// the test the setup queries prune with.
pub(super) fn box_may_reach(lo: Vec3, hi: Vec3, p: Vec3, r: f32, n: Vec3, h: f32) -> bool {
    box_may_reach_all(lo, hi, p, r, std::iter::once((n, h)))
}

/// [`box_may_reach`] for several half-spaces at once: whether the box may hold, within `r` of
/// `p`, points above each of them (a box wholly below any one is refused).
pub(super) fn box_may_reach_all(
    lo: Vec3,
    hi: Vec3,
    p: Vec3,
    r: f32,
    mut planes: impl Iterator<Item = (Vec3, f32)>,
) -> bool {
    let slack = 1e-5 * (p.abs().max_element() + (hi - lo).max_element() + r);
    let nearest = p.clamp(lo, hi);
    if nearest.distance(p) > r + slack {
        return false;
    }
    let centre = (lo + hi) * 0.5;
    let half = (hi - lo) * 0.5;
    planes.all(|(n, h)| n.dot(centre - p) + n.abs().dot(half) > h - slack)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::builtin::Builtin;

    /// Every triangle within a ball and above a plane is visited, on meshes with and without
    /// creases, for planes and balls all round them; brute force is the oracle.
    #[test]
    fn pruned_queries_visit_every_triangle_they_must() {
        let mut rng = crate::rng::Rng::new(3);
        for builtin in [Builtin::Bunny, Builtin::Torus, Builtin::Sphere] {
            let (mut visited, mut visits) = (0, 0);
            let (mesh, _) = builtin.mesh();
            let bvh = Bvh::new(&mesh.positions, &mesh.triangles);
            let (centre, radius) = mesh.bounding_sphere();
            for _ in 0..200 {
                let mut random = || rng.next_f32() * 2.0 - 1.0;
                let p = centre + Vec3::new(random(), random(), random()) * radius;
                let n = Vec3::new(random(), random(), random()).normalize_or(Vec3::Y);
                let r = radius * (0.05 + 0.5 * rng.next_f32());
                let wanted = |t: usize| {
                    let [a, b, c] = mesh.triangles[t].map(|i| mesh.positions[i as usize]);
                    let above = [a, b, c].iter().any(|y| n.dot(*y - p) > 0.0);
                    // Within r: a corner or the middle within r is enough for the oracle's set.
                    let near = [a, b, c, (a + b + c) / 3.0].iter().any(|y| y.distance(p) <= r);
                    above && near
                };
                let mut seen = vec![false; mesh.triangles.len()];
                bvh.visit(|lo, hi| box_may_reach(lo, hi, p, r, n, 0.0), |t| seen[t as usize] = true);
                for (t, seen) in seen.iter().enumerate() {
                    assert!(!wanted(t) || *seen, "{builtin:?}: triangle {t} missed");
                }
                visited += seen.iter().filter(|s| **s).count();
                visits += mesh.triangles.len();
            }
            assert!(visited * 2 < visits, "{builtin:?}: {visited} of {visits} visited");
        }
    }
}
