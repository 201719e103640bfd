//! Which strands of a batch contact must solve: eight at once, before any strand is taken apart.
//!
//! Nearly every strand touches nothing in a step (on the bunny under wind, fewer than one in a
//! hundred reaches its skin planes), and the per-strand solve ([`super::Resolve`]) costs most of
//! its time finding that out. The screen tests every node of the batch's eight strands at once
//! against their skin planes (posed by each lane's frame) and against every collider within
//! reach (its exact distance, or a mesh's bounding ball), in plain lane arithmetic the compiler
//! turns into vector instructions. A lane that clears everything by [`SCREEN_MARGIN`] of a segment is left as the bend made it,
//! which is what the solve would do with it (it only changes a strand with a node below a plane
//! or inside a collider); every other lane is solved as before, so the screen changes no byte of
//! the result, only the time. Strands held by the grasp are always solved; of those the screen
//! leaves, strands with skin triangles are still tested against them, one by one.

// Index loops over the batch's lanes are the form LLVM turns into one vector instruction.
#![allow(clippy::needless_range_loop)]

use glam::Vec3;

use super::{Near, SKIN_PLANES, StepCollider};
use crate::sim::kernel::{LANES, Lanes, VecLanes};

/// How far (in segments of the strand's mean length) a node must clear a plane or a collider's
/// bounding ball for its strand to be left unsolved: far above the screen's rounding (a few
/// ulps of the strand's reach) and below any real contact.
pub(super) const SCREEN_MARGIN: f32 = 1e-3;

/// A little more than a segment's length is taken off a lane's budget per segment, for rounding.
const SKIP_SLACK: f32 = 1.001;

/// One batch as the screen reads it.
pub(crate) struct Batch<'a> {
    /// The batch's index.
    pub b: usize,
    /// How many of its lanes are strands.
    pub lanes: usize,
    /// Its `L + 1` nodes, as the bend left them.
    pub nodes: &'a [VecLanes],
    /// Its rest segment lengths, root first.
    pub lengths: &'a [Lanes],
    /// Each lane's strand length (the sum of its rest segments).
    pub reach: &'a Lanes,
    /// Each lane's grasp weight times the grip's presence (0: not held).
    pub held: &'a Lanes,
}

/// A collider as the screen tests it, with the lanes it cannot reach pushed infinitely far away.
struct Bound {
    centre: [f32; 3],
    shape: BoundShape,
    /// 0 where the lane's strand can reach the collider, infinite where it cannot.
    away: Lanes,
}

/// A collider's shape as signed distances the screen evaluates (each 1-Lipschitz, none more
/// than the collider's own).
enum BoundShape {
    /// A ball: a sphere, or the bounding ball of a shape the screen has no exact form for.
    Ball { radius: f32 },
    /// The points within `radius` of the segment `centre +- axis * half_length`.
    Capsule { axis: [f32; 3], half_length: f32, radius: f32 },
    /// An oriented box: `axes` are its local axes in the world.
    Box { axes: [[f32; 3]; 3], half_extents: [f32; 3] },
    /// The half-space below the plane with this normal.
    Plane { normal: [f32; 3] },
}

impl BoundShape {
    /// The shape of `c`; `None` for an unbounded shape the screen cannot test.
    fn of(c: &StepCollider) -> Option<Self> {
        Some(match c.kind {
            StepCollider::SPHERE => Self::Ball { radius: c.radius },
            StepCollider::CAPSULE => Self::Capsule {
                axis: (c.rotation * Vec3::Y).to_array(),
                half_length: c.half_extents.y,
                radius: c.radius,
            },
            StepCollider::BOX => Self::Box {
                axes: [Vec3::X, Vec3::Y, Vec3::Z].map(|a| (c.rotation * a).to_array()),
                half_extents: c.half_extents.to_array(),
            },
            StepCollider::PLANE => Self::Plane { normal: (c.rotation * Vec3::Y).to_array() },
            _ if c.bound.is_finite() => Self::Ball { radius: c.bound },
            _ => return None,
        })
    }
}

/// The lanes (bit `lane`) of `batch` that may touch the skin planes, a collider of `near` or
/// the grip: the ones contact solves. (Of the others, the solve still tests those with skin
/// triangles against them.)
///
/// Every node is tested, but not every node is evaluated: a node lies a segment's length from
/// the one before, and planes and collider distances are 1-Lipschitz, so a lane whose last
/// evaluated node cleared the planes (or a collider) by `c` cannot touch them within the next
/// `c` of its length (the per-strand solve skips nodes the same way). The planes and each
/// collider keep their own budgets; a node is evaluated against one, for all eight lanes at
/// once, when some lane's budget for it runs out.
#[inline(always)]
pub(crate) fn lanes_to_solve(
    batch: &Batch<'_>,
    skin: Option<&BatchPlanes>,
    roots: &[Vec3],
    frames: &[glam::Quat],
    near: Near<'_>,
) -> u32 {
    let first = batch.b * LANES;
    let all = (1_u32 << batch.lanes) - 1;
    let mut solve = 0_u32;
    for lane in 0..batch.lanes {
        if batch.held[lane] != 0.0 {
            solve |= 1 << lane;
        }
    }
    if solve == all {
        return solve;
    }
    let layers = batch.nodes.len() - 1;
    let mut root = [[0.0; LANES]; 3];
    let mut tolerance = [0.0; LANES];
    for lane in 0..batch.lanes {
        let r = roots[first + lane];
        root[0][lane] = r.x;
        root[1][lane] = r.y;
        root[2][lane] = r.z;
        tolerance[lane] = SCREEN_MARGIN * batch.reach[lane] / layers.max(1) as f32;
    }
    let mut planes = [[[0.0_f32; LANES]; 4]; SKIN_PLANES];
    let count = match skin {
        Some(skin) => posed_planes(batch, skin, frames, &mut planes),
        None => 0,
    };
    let planes = &planes[..count];
    // The planes and each collider keep their own budgets: a collider far from the batch is
    // evaluated once or twice, however often the planes near the roots are.
    if !planes.is_empty() {
        solve |= touching(batch, solve, &tolerance, &Planes { root: &root, planes });
    }
    for c in near.iter() {
        if solve == all {
            break;
        }
        let away: Lanes = std::array::from_fn(|lane| {
            let reaches = lane < batch.lanes && roots[first + lane].distance(c.centre) <= c.bound + batch.reach[lane];
            if reaches { 0.0 } else { f32::INFINITY }
        });
        if !away.contains(&0.0) {
            continue;
        }
        match BoundShape::of(c) {
            Some(shape) => {
                let bound = Bound { centre: c.centre.to_array(), shape, away };
                solve |= touching(batch, solve, &tolerance, &bound);
            }
            None => {
                for lane in 0..batch.lanes {
                    if away[lane] == 0.0 {
                        solve |= 1 << lane;
                    }
                }
            }
        }
    }
    solve & all
}

/// The lanes of `batch` not in `solve` with a node whose `clear`ance (1-Lipschitz in the node,
/// per lane) falls below their `tolerance`. A node is evaluated, for all eight lanes at once,
/// when some lane's budget runs out.
#[inline(always)]
fn touching(batch: &Batch<'_>, solve: u32, tolerance: &Lanes, clear: &impl Clearance) -> u32 {
    // Lanes already solved, and lanes past the batch's strands, never ask for an evaluation.
    let mut budget: Lanes =
        std::array::from_fn(|lane| if lane >= batch.lanes || solve & (1 << lane) != 0 { f32::INFINITY } else { -1.0 });
    let mut lowest = [f32::INFINITY; LANES];
    // How much of each lane's strand lies beyond the node, with the slack the budgets take off.
    let first = batch.lengths.first().copied().unwrap_or([0.0; LANES]);
    let mut beyond: Lanes = std::array::from_fn(|lane| (batch.reach[lane] - first[lane]) * SKIP_SLACK);
    let nodes = &batch.nodes[1..];
    for (i, node) in nodes.iter().enumerate() {
        if budget.iter().any(|b| *b < 0.0) {
            let clear = clear.at(node);
            for lane in 0..LANES {
                let c = clear[lane] - tolerance[lane];
                lowest[lane] = if c < lowest[lane] { c } else { lowest[lane] };
                // A lane that touches needs no more evaluations: it is solved whatever follows.
                budget[lane] = if c < 0.0 || budget[lane] == f32::INFINITY { f32::INFINITY } else { c };
            }
            // Every lane clear of the rest of its strand: nothing further can touch.
            if (0..LANES).all(|lane| budget[lane] > beyond[lane]) {
                break;
            }
        }
        // The next node lies one segment (the next one) further on.
        if let Some(lengths) = batch.lengths.get(i + 1) {
            for lane in 0..LANES {
                budget[lane] -= lengths[lane] * SKIP_SLACK;
                beyond[lane] -= lengths[lane] * SKIP_SLACK;
            }
        }
    }
    let mut touch = 0;
    for lane in 0..batch.lanes {
        if lowest[lane] < 0.0 {
            touch |= 1 << lane;
        }
    }
    touch
}

/// A clearance the screen evaluates for eight nodes at once (1-Lipschitz in the node, per lane).
trait Clearance {
    fn at(&self, node: &VecLanes) -> Lanes;
}

/// The skin planes (posed) about the roots.
struct Planes<'a> {
    root: &'a VecLanes,
    planes: &'a [[Lanes; 4]],
}

impl Clearance for Planes<'_> {
    #[inline(always)]
    fn at(&self, node: &VecLanes) -> Lanes {
        plane_clearance(node, self.root, self.planes)
    }
}

impl Clearance for Bound {
    #[inline(always)]
    fn at(&self, node: &VecLanes) -> Lanes {
        bound_clearance(node, self)
    }
}

/// A batch's skin planes, lane by lane, as [`skin_lanes`] stores them.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct BatchPlanes {
    /// Plane slot by slot: `n` (x, y, z) in the strand's rest frame and `h`, infinite where the
    /// lane's strand has no plane in that slot.
    planes: [[Lanes; 4]; SKIN_PLANES],
    /// Slots any lane uses (a strand's planes come first).
    count: usize,
}

/// Every batch's skin planes from each strand's (`skin`, strand by strand): the screen's layout,
/// kept beside the per-strand one the solve and the GPU read.
pub(crate) fn skin_lanes(skin: &[[glam::Vec4; SKIN_PLANES]]) -> Vec<BatchPlanes> {
    skin.chunks(LANES)
        .map(|strands| {
            let mut batch = BatchPlanes {
                planes: [[[0.0; LANES], [0.0; LANES], [0.0; LANES], [f32::INFINITY; LANES]]; SKIN_PLANES],
                count: 0,
            };
            for (lane, planes) in strands.iter().enumerate() {
                for (p, plane) in planes.iter().enumerate() {
                    if plane.truncate() != Vec3::ZERO {
                        for c in 0..4 {
                            batch.planes[p][c][lane] = plane[c];
                        }
                        batch.count = batch.count.max(p + 1);
                    }
                }
            }
            batch
        })
        .collect()
}

/// Each lane's skin planes posed by its frame, `(n, h)`; returns how many slots are used.
#[inline(always)]
fn posed_planes(
    batch: &Batch<'_>,
    skin: &BatchPlanes,
    frames: &[glam::Quat],
    planes: &mut [[Lanes; 4]; SKIN_PLANES],
) -> usize {
    let first = batch.b * LANES;
    let mut q = [[0.0; LANES], [0.0; LANES], [0.0; LANES], [1.0; LANES]];
    for lane in 0..batch.lanes {
        let f = frames[first + lane];
        q[0][lane] = f.x;
        q[1][lane] = f.y;
        q[2][lane] = f.z;
        q[3][lane] = f.w;
    }
    for (plane, rest) in planes.iter_mut().zip(&skin.planes[..skin.count]) {
        let [x, y, z] = rotate(&q, &[rest[0], rest[1], rest[2]]);
        *plane = [x, y, z, rest[3]];
    }
    skin.count
}

/// Per lane, the least of the node's heights above its skin planes (1-Lipschitz in the node).
#[inline(always)]
fn plane_clearance(node: &VecLanes, root: &VecLanes, planes: &[[Lanes; 4]]) -> Lanes {
    let mut least = [f32::INFINITY; LANES];
    let mut d = [[0.0; LANES]; 3];
    for lane in 0..LANES {
        for c in 0..3 {
            d[c][lane] = node[c][lane] - root[c][lane];
        }
    }
    for plane in planes {
        for lane in 0..LANES {
            let h = plane[0][lane] * d[0][lane]
                + plane[1][lane] * d[1][lane]
                + plane[2][lane] * d[2][lane]
                + plane[3][lane];
            least[lane] = if h < least[lane] { h } else { least[lane] };
        }
    }
    least
}

/// Per lane, the node's distance outside `bound` (1-Lipschitz in the node), infinite for lanes
/// that cannot reach it.
#[inline(always)]
fn bound_clearance(node: &VecLanes, bound: &Bound) -> Lanes {
    let [cx, cy, cz] = bound.centre;
    let mut gap = [0.0; LANES];
    match bound.shape {
        BoundShape::Ball { radius } => {
            for lane in 0..LANES {
                let (x, y, z) = (node[0][lane] - cx, node[1][lane] - cy, node[2][lane] - cz);
                gap[lane] = (x * x + y * y + z * z).sqrt() - radius;
            }
        }
        BoundShape::Capsule { axis: [ax, ay, az], half_length, radius } => {
            for lane in 0..LANES {
                let (x, y, z) = (node[0][lane] - cx, node[1][lane] - cy, node[2][lane] - cz);
                let t = (ax * x + ay * y + az * z).max(-half_length).min(half_length);
                let (x, y, z) = (x - ax * t, y - ay * t, z - az * t);
                gap[lane] = (x * x + y * y + z * z).sqrt() - radius;
            }
        }
        BoundShape::Box { axes, half_extents } => {
            for lane in 0..LANES {
                let (x, y, z) = (node[0][lane] - cx, node[1][lane] - cy, node[2][lane] - cz);
                let (mut outside, mut inside) = (0.0_f32, f32::NEG_INFINITY);
                for (axis, half) in axes.iter().zip(half_extents) {
                    let q = (axis[0] * x + axis[1] * y + axis[2] * z).abs() - half;
                    let out = q.max(0.0);
                    outside += out * out;
                    inside = inside.max(q);
                }
                gap[lane] = outside.sqrt() + inside.min(0.0);
            }
        }
        BoundShape::Plane { normal: [nx, ny, nz] } => {
            for lane in 0..LANES {
                gap[lane] = nx * (node[0][lane] - cx) + ny * (node[1][lane] - cy) + nz * (node[2][lane] - cz);
            }
        }
    }
    for lane in 0..LANES {
        gap[lane] += bound.away[lane];
    }
    gap
}

/// `v` turned by the unit quaternions `q` (`xyzw`), lane by lane: `v + w t + q x t` with
/// `t = 2 q x v`.
#[inline(always)]
fn rotate(q: &[Lanes; 4], v: &VecLanes) -> VecLanes {
    let mut out = [[0.0; LANES]; 3];
    for lane in 0..LANES {
        let (x, y, z, w) = (q[0][lane], q[1][lane], q[2][lane], q[3][lane]);
        let (vx, vy, vz) = (v[0][lane], v[1][lane], v[2][lane]);
        let tx = 2.0 * (y * vz - z * vy);
        let ty = 2.0 * (z * vx - x * vz);
        let tz = 2.0 * (x * vy - y * vx);
        out[0][lane] = vx + w * tx + (y * tz - z * ty);
        out[1][lane] = vy + w * ty + (z * tx - x * tz);
        out[2][lane] = vz + w * tz + (x * ty - y * tx);
    }
    out
}

#[cfg(test)]
mod tests {
    use glam::{Quat, Vec3};

    use super::*;
    use crate::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
    use crate::mesh::builtin::Builtin;
    use crate::sim::{
        Collider, ColliderMesh, ContactParams, CpuKernel, GraspParams, Shape, SimParams, Simulation, WindParams,
    };

    /// The screen only saves time: with the skin, colliders of every shape (a mesh too) moving through the
    /// fur and a grasp, under strong wind and gravity, the nodes are the same bits with and
    /// without it, for both instruction sets.
    #[test]
    fn screening_changes_no_bit() {
        let (mesh, _) = Builtin::Bunny.mesh();
        let length = 0.08 * mesh.bounding_sphere().1;
        let direction = GrowthDirection { random_angle_rad: 0.3, seed: 2, ..GrowthDirection::default() };
        let fur = FurStructure::new(mesh, &FurParams { layers: 12, length: FurLength::Constant(length), direction })
            .expect("fur");
        let params = SimParams {
            gravity_strength: 4.0,
            wind: WindParams { direction: Vec3::new(0.3, -1.0, 0.2), strength: 3.0, seed: 7, ..WindParams::default() },
            contact: ContactParams { skin: true },
            ..SimParams::default()
        };
        let v = fur.vertex_count();
        let length = fur.lengths.iter().copied().fold(0.0, f32::max);
        let back = (0..v).max_by(|&a, &b| fur.positions[a].y.total_cmp(&fur.positions[b].y)).expect("a vertex");
        let (hit, normal) = (fur.positions[back], fur.mesh.normals[back]);
        let make = |kernel: CpuKernel, screen: bool| {
            let mut simulation = Simulation::new(&fur, &params).expect("simulation");
            simulation.set_cpu_kernel(kernel);
            simulation.contact_screen = screen;
            simulation
        };
        let mut runs = [make(CpuKernel::Auto, true), make(CpuKernel::Auto, false), make(CpuKernel::Portable, true)];
        let (sphere, _) = Builtin::Sphere.mesh();
        let pebble_radius = sphere.positions.iter().map(|p| p.length()).fold(0.0, f32::max);
        let pebble = std::sync::Arc::new(ColliderMesh::new(sphere, 12).expect("a closed sphere"));
        let mut free = Simulation::new(&fur, &SimParams { contact: ContactParams { skin: false }, ..params.clone() })
            .expect("simulation");
        let mut touched = 0;
        for step in 1..=40_u32 {
            let t = f64::from(step) / 60.0;
            let x = (0.5 * (t * 4.0).sin()) as f32 * length;
            let colliders = [
                Collider::at(
                    1,
                    Shape::Sphere { radius: 0.8 * length },
                    t,
                    hit + normal * length + Vec3::X * x,
                    Quat::IDENTITY,
                ),
                Collider::at(
                    2,
                    Shape::Capsule { radius: 0.2 * length, half_length: length },
                    t,
                    hit + normal * 0.5 * length - Vec3::Z * x,
                    Quat::from_rotation_x(1.2),
                ),
                Collider::at(
                    3,
                    Shape::Box { half_extents: Vec3::splat(0.4 * length) },
                    t,
                    hit + Vec3::X * length,
                    Quat::from_rotation_y(0.5),
                ),
                Collider::at(
                    4,
                    Shape::Plane,
                    t,
                    hit + normal * (0.2 * length),
                    Quat::from_rotation_arc(Vec3::Y, -normal),
                ),
                Collider::at(
                    5,
                    Shape::Mesh { mesh: pebble.clone(), scale: 0.7 * length / pebble_radius },
                    t,
                    hit + normal * (0.6 * length) - Vec3::X * x,
                    Quat::from_rotation_z(0.3),
                ),
            ];
            for simulation in &mut runs {
                simulation.set_colliders(&colliders).expect("colliders");
                match step {
                    10 => simulation
                        .grasp_begin(hit + normal * 0.5 * length, 2.0 * length, 0.3 * length, GraspParams::default(), t)
                        .expect("grasp"),
                    11..=25 => {
                        simulation.grasp_move(hit + normal * (0.5 + 0.05 * (step - 10) as f32) * length).expect("grip")
                    }
                    26 => simulation.grasp_end(t),
                    _ => {}
                }
                simulation.advance_to(t);
            }
            let bits =
                |s: &Simulation| s.positions().iter().flat_map(|p| p.to_array().map(f32::to_bits)).collect::<Vec<_>>();
            let unscreened = bits(&runs[1]);
            assert!(bits(&runs[0]) == unscreened, "step {step}: the screen changed a node");
            assert!(bits(&runs[2]) == unscreened, "step {step}: the portable screen changed a node");
            free.advance_to(t);
            let moved = free
                .positions()
                .iter()
                .zip(runs[1].positions())
                .filter(|(a, b)| a.distance(**b) > 1e-3 * length)
                .count();
            touched = touched.max(moved);
        }
        // Contact moved many nodes, so the comparison means something.
        assert!(touched > 100, "contact moved only {touched} nodes");
        eprintln!("contact moved up to {touched} nodes");
    }

    /// Strands the screen clears of their planes and the colliders are still tested against their
    /// skin triangles: on the bunny, each strand with triangles that has a spot above its planes
    /// but behind its triangles (where its planes' intersection reaches below the skin: creases,
    /// the ears' bases) is bent to it. The screened solve gives the unscreened one's bits, and
    /// moves those strands in front of their triangles (failed with the screen's strands left
    /// untested against them).
    #[test]
    fn strands_clear_of_their_planes_still_meet_their_triangles() {
        use crate::sim::contact::{ContactStep, ContactStrands, Resolve, skin_planes, skin_surface};
        use crate::sim::kernel::RestBatches;
        let (mesh, _) = Builtin::Bunny.mesh();
        let length = 0.4 * mesh.bounding_sphere().1;
        let fur = FurStructure::new(
            mesh,
            &FurParams { layers: 8, length: FurLength::Constant(length), direction: GrowthDirection::default() },
        )
        .expect("fur");
        let (v, layers) = (fur.vertex_count(), fur.layers as usize);
        let planes = skin_planes(&fur);
        let surface = skin_surface(&fur, &planes);
        let mut state = 3_u32;
        let mut next = move || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1 << 24) as f32 * 2.0 - 1.0
        };
        // Every strand's nodes at rest (batch-major), then the chosen strands' bent to their spot.
        let mut nodes = vec![[[0.0_f32; LANES]; 3]; v.div_ceil(LANES) * (layers + 1)];
        let mut put = |j: usize, k: usize, x: Vec3| {
            for c in 0..3 {
                nodes[(j / LANES) * (layers + 1) + k][c][j % LANES] = x[c];
            }
        };
        for j in 0..v {
            for k in 0..=layers {
                put(j, k, fur.positions[k * v + j]);
            }
        }
        let mut bent = Vec::new();
        for j in (0..v).filter(|&j| !surface.strand(j).is_empty()) {
            let root = fur.positions[j];
            let spot = (0..20000).map(|_| root + Vec3::new(next(), next(), next()) * length).find(|&x| {
                x.distance(root) < 0.9 * length
                    && planes[j].iter().all(|p| p.truncate().dot(x - root) + p.w > 0.001 * length)
                    && surface.closest(j, x).is_some_and(|(_, _, s)| s < -0.01 * length)
            });
            if let Some(spot) = spot {
                for k in 1..=layers {
                    put(j, k, spot);
                }
                bent.push(j);
            }
        }
        assert!(bent.len() >= 5, "only {} strands have a spot above their planes behind their triangles", bent.len());
        let rest = RestBatches::new(&fur.positions, v, layers);
        let lanes = skin_lanes(&planes);
        let step = ContactStep { skin: true, ..ContactStep::default() };
        let roots = &fur.positions[..v];
        let frames = vec![Quat::IDENTITY; v];
        let solved = |screen: bool| {
            let resolve = Resolve {
                step: &step,
                strands: ContactStrands { skin: &planes, grasp_weights: &[], surface: &surface, rest_roots: roots },
                skin_lanes: &lanes,
                kernel: CpuKernel::Auto,
                screen,
                roots,
                frames: &frames,
                rest: &rest,
                layers,
                vertex_count: v,
            };
            let mut out = nodes.clone();
            for (b, batch) in out.chunks_mut(layers + 1).enumerate() {
                resolve.batch(b, batch);
            }
            out
        };
        let (screened, unscreened) = (solved(true), solved(false));
        let bits = |n: &[VecLanes]| n.iter().flatten().flatten().map(|x| x.to_bits()).collect::<Vec<_>>();
        assert!(bits(&screened) == bits(&unscreened), "the screen changed a node");
        for &j in &bent {
            for k in 1..=layers {
                let node = screened[(j / LANES) * (layers + 1) + k];
                let x = Vec3::new(node[0][j % LANES], node[1][j % LANES], node[2][j % LANES]);
                let (_, _, s) = surface.closest(j, x).expect("triangles");
                assert!(s >= -1e-4 * length, "strand {j} node {k}: {s} behind its triangles");
            }
        }
        eprintln!("{} strands bent behind their triangles", bent.len());
    }

    /// The lane rotation turns vectors as glam's quaternions do.
    #[test]
    fn lane_rotation_matches_glam() {
        let quats: [Quat; LANES] =
            std::array::from_fn(|i| Quat::from_axis_angle(Vec3::new(1.0, i as f32, -0.5).normalize(), 0.4 * i as f32));
        let vectors: [Vec3; LANES] = std::array::from_fn(|i| Vec3::new(0.3 * i as f32, -1.0, 2.0 - i as f32));
        let q: [Lanes; 4] = std::array::from_fn(|c| std::array::from_fn(|lane| quats[lane].to_array()[c]));
        let v: VecLanes = std::array::from_fn(|c| std::array::from_fn(|lane| vectors[lane][c]));
        let turned = rotate(&q, &v);
        for lane in 0..LANES {
            let expected = quats[lane] * vectors[lane];
            let got = Vec3::new(turned[0][lane], turned[1][lane], turned[2][lane]);
            assert!(got.distance(expected) < 1e-5, "lane {lane}: {got} vs {expected}");
        }
    }
}
