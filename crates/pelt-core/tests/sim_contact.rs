//! Contact: the skin, colliders and the grasp, checked against oracles that share no code with
//! `sim::contact` (the skin against the closest point of the base mesh in f64, signed by the
//! angle-weighted pseudonormal; colliders by their own distance formulas).

use crate::common;

use std::collections::HashMap;
use std::path::Path;

use common::back;
use glam::{DVec3, Quat, Vec3};
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
use pelt_core::mesh::builtin::Builtin;
use pelt_core::sim::{
    Collider, ContactParams, GraspParams, Scene, SceneError, Shape, SimParams, Simulation, WindParams,
};

fn grow(builtin: Builtin, layers: u32, length_fraction: f32) -> FurStructure {
    let (mesh, _) = builtin.mesh();
    let radius = bounding_radius(&mesh.positions);
    let direction = GrowthDirection { random_angle_rad: 0.4, seed: 5, ..GrowthDirection::default() };
    FurStructure::new(mesh, &FurParams { layers, length: FurLength::Constant(length_fraction * radius), direction })
        .unwrap()
}

fn bounding_radius(points: &[Vec3]) -> f32 {
    let (lo, hi) = points.iter().fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(*p), h.max(*p)));
    let centre = (lo + hi) * 0.5;
    points.iter().map(|p| p.distance(centre)).fold(0.0, f32::max)
}

fn with_skin(skin: bool) -> SimParams {
    SimParams { contact: ContactParams { skin }, interpolate: false, ..SimParams::default() }
}

/// The largest relative error of any segment length against the rest pose.
fn worst_length_error(fur: &FurStructure, positions: &[Vec3]) -> f32 {
    let v = fur.vertex_count();
    let mut worst = 0.0f32;
    for k in 0..fur.layers as usize {
        for j in 0..v {
            let rest = fur.positions[(k + 1) * v + j].distance(fur.positions[k * v + j]);
            let now = positions[(k + 1) * v + j].distance(positions[k * v + j]);
            worst = worst.max((now - rest).abs() / rest.max(1e-12));
        }
    }
    worst
}

/// Signed distance to a triangle mesh: the closest point by brute force over the triangles near
/// the query (binned), signed by the pseudonormal of the feature it lies on (Baerentzen and
/// Aanaes 2005: face normal, sum of the two face normals of an edge, angle-weighted vertex normal).
struct MeshOracle {
    points: Vec<DVec3>,
    triangles: Vec<[usize; 3]>,
    face_normals: Vec<DVec3>,
    edge_normals: HashMap<(usize, usize), DVec3>,
    vertex_normals: Vec<DVec3>,
    cell: f64,
    bins: HashMap<(i64, i64, i64), Vec<usize>>,
}

impl MeshOracle {
    fn new(points: &[Vec3], triangles: &[[u32; 3]], cell: f64) -> Self {
        let points: Vec<DVec3> = points.iter().map(|p| p.as_dvec3()).collect();
        let triangles: Vec<[usize; 3]> = triangles.iter().map(|t| t.map(|i| i as usize)).collect();
        let mut face_normals = Vec::new();
        let mut edge_normals: HashMap<(usize, usize), DVec3> = HashMap::new();
        let mut vertex_normals = vec![DVec3::ZERO; points.len()];
        let mut bins: HashMap<(i64, i64, i64), Vec<usize>> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            let [a, b, c] = tri.map(|i| points[i]);
            let n = (b - a).cross(c - a).normalize_or_zero();
            face_normals.push(n);
            for e in 0..3 {
                let (i, j) = (tri[e], tri[(e + 1) % 3]);
                *edge_normals.entry((i.min(j), i.max(j))).or_default() += n;
                let (p, q, r) = (points[tri[e]], points[tri[(e + 1) % 3]], points[tri[(e + 2) % 3]]);
                let angle = (q - p).angle_between(r - p);
                if angle.is_finite() {
                    vertex_normals[tri[e]] += n * angle;
                }
            }
            let key =
                |p: DVec3| ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64, (p.z / cell).floor() as i64);
            let (lo, hi) = (key(a.min(b).min(c)), key(a.max(b).max(c)));
            for x in lo.0..=hi.0 {
                for y in lo.1..=hi.1 {
                    for z in lo.2..=hi.2 {
                        bins.entry((x, y, z)).or_default().push(t);
                    }
                }
            }
        }
        Self { points, triangles, face_normals, edge_normals, vertex_normals, cell, bins }
    }

    /// The signed distance of `x` if the surface is within `cell` of it (negative: inside).
    fn signed_distance(&self, x: Vec3) -> Option<f64> {
        let x = x.as_dvec3();
        let c = |v: f64| (v / self.cell).floor() as i64;
        let mut best: Option<(f64, DVec3, DVec3)> = None;
        let mut seen = std::collections::HashSet::new();
        for i in c(x.x) - 1..=c(x.x) + 1 {
            for j in c(x.y) - 1..=c(x.y) + 1 {
                for k in c(x.z) - 1..=c(x.z) + 1 {
                    for &t in self.bins.get(&(i, j, k)).into_iter().flatten() {
                        if !seen.insert(t) {
                            continue;
                        }
                        let (point, normal) = self.closest_on(t, x);
                        let d = point.distance(x);
                        if best.is_none_or(|(bd, _, _)| d < bd) {
                            best = Some((d, point, normal));
                        }
                    }
                }
            }
        }
        let (d, point, normal) = best?;
        (d <= self.cell).then(|| if (x - point).dot(normal) < 0.0 { -d } else { d })
    }

    /// The closest point of triangle `t` to `x` and the pseudonormal of its feature.
    fn closest_on(&self, t: usize, x: DVec3) -> (DVec3, DVec3) {
        let tri = self.triangles[t];
        let [a, b, c] = tri.map(|i| self.points[i]);
        let n = self.face_normals[t];
        // Inside the face: the projection's barycentric coordinates are all positive.
        let p = x - n * (x - a).dot(n);
        let area = |u: DVec3, v: DVec3, w: DVec3| (v - u).cross(w - u).dot(n);
        let total = area(a, b, c);
        if total > 0.0 {
            let (l0, l1, l2) = (area(p, b, c) / total, area(a, p, c) / total, area(a, b, p) / total);
            if l0 > 0.0 && l1 > 0.0 && l2 > 0.0 {
                return (p, n);
            }
        }
        let mut best = (f64::MAX, DVec3::ZERO, DVec3::ZERO);
        for e in 0..3 {
            let (i, j) = (tri[e], tri[(e + 1) % 3]);
            let (u, v) = (self.points[i], self.points[j]);
            let s = ((x - u).dot(v - u) / (v - u).length_squared()).clamp(0.0, 1.0);
            let q = u + (v - u) * s;
            let normal = if s <= 0.0 {
                self.vertex_normals[i]
            } else if s >= 1.0 {
                self.vertex_normals[j]
            } else {
                self.edge_normals[&(i.min(j), i.max(j))]
            };
            let d = q.distance(x);
            if d < best.0 {
                best = (d, q, normal);
            }
        }
        (best.1, best.2)
    }
}

/// How far below the skin a node may be, as a fraction of the fur's length: f32 rounding of a
/// node placed just above a surface, seen from the oracle's f64.
const SKIN_EPSILON: f64 = 1e-5;

/// How far the deepest node is below the skin, as a fraction of the fur's length (0: none), and
/// how many nodes are below by more than [`SKIN_EPSILON`] of it. `rest_from_world` puts the
/// node where the rest mesh is.
fn below_skin(
    fur: &FurStructure,
    oracle: &MeshOracle,
    positions: &[Vec3],
    rest_from_world: glam::Mat4,
) -> (f64, usize) {
    let length = f64::from(fur.lengths.iter().copied().fold(0.0, f32::max));
    let v = fur.vertex_count();
    let (mut deepest, mut count) = (0.0_f64, 0);
    for (i, x) in positions.iter().enumerate().skip(v) {
        let x = rest_from_world.transform_point3(*x);
        if let Some(d) = oracle.signed_distance(x) {
            let depth = -d / length;
            deepest = deepest.max(depth);
            if depth > SKIN_EPSILON {
                count += 1;
                let _ = i;
            }
        }
    }
    (deepest, count)
}

fn bunny() -> (FurStructure, MeshOracle, f32) {
    furred(Builtin::Bunny)
}

fn furred(builtin: Builtin) -> (FurStructure, MeshOracle, f32) {
    let fur = grow(builtin, 12, 0.12);
    let radius = bounding_radius(&fur.mesh.positions);
    let oracle = MeshOracle::new(&fur.mesh.positions, &fur.mesh.triangles, f64::from(0.13 * radius));
    (fur, oracle, radius)
}

/// Runs `steps` steps of 1/30 s from `sim`'s state, calling `each` before each.
fn run(sim: &mut Simulation, steps: u32, mut each: impl FnMut(&mut Simulation, f64)) {
    let start = (sim.time_secs() * 30.0).round() as u32;
    for n in start + 1..=start + steps {
        let t = f64::from(n) / 30.0;
        each(sim, t);
        sim.advance_to(t);
    }
}

/// Strong downward wind with heavy gravity; a heavy pat pushing into the back; a fast swing of
/// the whole body, on the bunny (creases, the ears' bases) and the torus (saddles all round its
/// hole). With the skin on, no node goes below the base mesh by more than [`SKIN_EPSILON`] of
/// the fur's length; with it off, each of these pushes nodes well below (so the scenes test
/// something).
#[test]
fn no_node_goes_below_the_skin_under_wind_pat_and_swing() {
    below_the_skin_under_wind_pat_and_swing(Builtin::Bunny);
    below_the_skin_under_wind_pat_and_swing(Builtin::Torus);
}

fn below_the_skin_under_wind_pat_and_swing(builtin: Builtin) {
    let (fur, oracle, radius) = furred(builtin);
    let v = fur.vertex_count();
    // The bunny's highest vertex on its back and its normal, for the pat.
    let top = back(&fur);
    let (hit, normal) = (fur.mesh.positions[top], fur.mesh.normals[top]);
    for skin in [true, false] {
        let base = with_skin(skin);
        // Wind and gravity pressing down.
        let params = SimParams {
            gravity_strength: 30.0,
            wind: WindParams { strength: 30.0, direction: Vec3::new(0.3, -1.0, 0.2), ..WindParams::default() },
            ..base.clone()
        };
        let mut sim = Simulation::new(&fur, &params).unwrap();
        run(&mut sim, 20, |_, _| {});
        let wind = below_skin(&fur, &oracle, sim.positions(), glam::Mat4::IDENTITY);
        assert!(worst_length_error(&fur, sim.positions()) <= 1e-5);

        // A heavy pat: the touch dragged deep into the body.
        let params =
            SimParams { touch: pelt_core::sim::TouchParams { strength: 200.0, ..Default::default() }, ..base.clone() };
        let mut sim = Simulation::new(&fur, &params).unwrap();
        sim.touch_begin(hit, 0.3 * radius).unwrap();
        sim.touch_drag(hit - normal * radius).unwrap();
        run(&mut sim, 10, |_, _| {});
        let pat = below_skin(&fur, &oracle, sim.positions(), glam::Mat4::IDENTITY);
        assert!(worst_length_error(&fur, sim.positions()) <= 1e-5);

        // A fast swing: half a turn about Z in a third of a second, and back, with strong inertia.
        let params = SimParams { inertia: 3.0, damping: 0.1, gravity_strength: 3.0, ..base.clone() };
        let mut sim = Simulation::new(&fur, &params).unwrap();
        let mut turn = Quat::IDENTITY;
        run(&mut sim, 30, |sim, t| {
            let angle = (std::f64::consts::PI * (t * 3.0).sin()) as f32;
            turn = Quat::from_rotation_z(angle);
            let positions: Vec<Vec3> = fur.mesh.positions.iter().map(|p| turn * *p).collect();
            sim.set_base_rotations(&positions, &vec![turn; v]).unwrap();
        });
        // The state drawn is the last step's (interpolation alpha 1 at whole steps).
        let world_from_rest = glam::Mat4::from_quat(turn);
        let swing = below_skin(&fur, &oracle, sim.positions(), world_from_rest.inverse());
        assert!(worst_length_error(&fur, sim.positions()) <= 1e-5);

        for (name, (deepest, count)) in [("wind", wind), ("pat", pat), ("swing", swing)] {
            eprintln!(
                "{} skin {skin} {name}: {count} nodes below by more than {SKIN_EPSILON:e} of the fur's length, \
                 deepest {deepest:e}",
                builtin.name()
            );
            if skin {
                assert!(
                    count == 0,
                    "{} {name}: {count} nodes below the skin, deepest {deepest:e} of the fur's length",
                    builtin.name()
                );
            } else {
                assert!(
                    count > 0 && deepest > 0.1,
                    "{name} without the skin: {count} nodes below, deepest {deepest:.4}"
                );
            }
        }
    }
}

/// Distance from `x` to each collider shape, written out here (negative inside).
/// Strands that wind and gravity press into the skin lie down along it: no segment turns back
/// on the one before (a turn past 120 degrees), on the bunny's back, flanks and creases. (The
/// least turn onto a plane pressed nearly along its normal took its side from the bent
/// direction's small tangential part, and such strands folded into a zig-zag.)
#[test]
fn strands_pressed_into_the_skin_lie_down_without_folding() {
    let (fur, oracle, _) = bunny();
    let v = fur.vertex_count();
    let layers = fur.layers as usize;
    let params = SimParams {
        gravity_strength: 6.0,
        wind: WindParams { direction: Vec3::new(0.2, -1.0, 0.1), strength: 4.0, seed: 3, ..WindParams::default() },
        ..with_skin(true)
    };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let (mut folded, mut pressed) = (Vec::new(), 0);
    run(&mut sim, 60, |_, _| {});
    for _ in 0..30 {
        run(&mut sim, 1, |_, _| {});
        let positions = sim.positions();
        for j in 0..v {
            let node = |k: usize| positions[k * v + j];
            let folds = (1..layers)
                .filter(|&k| {
                    let (a, b) = (node(k) - node(k - 1), node(k + 1) - node(k));
                    a.normalize().dot(b.normalize()) < -0.5
                })
                .count();
            if folds > 0 && !folded.contains(&j) {
                folded.push(j);
            }
        }
        pressed = pressed.max(
            (0..v * (layers + 1))
                .filter(|&n| {
                    let near = 0.02 * f64::from(fur.lengths[n % v]);
                    n >= v && oracle.signed_distance(positions[n]).is_some_and(|d| d.abs() < near)
                })
                .count(),
        );
    }
    eprintln!("{} strands fold; at most {pressed} nodes lie on the skin", folded.len());
    assert!(pressed > 1000, "the wind presses the fur onto the skin ({pressed} nodes on it)");
    assert!(folded.is_empty(), "strands {folded:?} fold back on themselves");
}

/// Where a strand keeps no skin triangles, its planes keep the surface out: no point of the base
/// mesh within the strand's reach lies inside the intersection of its planes by more than half
/// the skin's bound (sampled on every triangle near the root). (Failed while a strand kept
/// triangles only where faces rose 1e-4 of its reach into that intersection: nodes of a bunny
/// strand above all its planes ended 4.9e-5 of the fur's length below the skin.)
#[test]
fn strands_without_triangles_have_planes_that_keep_the_surface_out() {
    for builtin in [Builtin::Bunny, Builtin::Torus] {
        let (fur, _, _) = furred(builtin);
        let v = fur.vertex_count();
        let layers = fur.layers as usize;
        let planes = pelt_core::sim::contact::skin_planes(&fur);
        let surface = pelt_core::sim::contact::skin_surface(&fur, &planes);
        let length = fur.lengths.iter().copied().fold(0.0, f32::max);
        let mut deepest = 0.0_f32;
        for j in (0..v).filter(|&j| surface.strand(j).is_empty()) {
            let root = fur.positions[j];
            let reach: f32 =
                (0..layers).map(|k| fur.positions[(k + 1) * v + j].distance(fur.positions[k * v + j])).sum();
            for t in &fur.mesh.triangles {
                let [a, b, c] = t.map(|i| fur.mesh.positions[i as usize]);
                if [a, b, c].iter().all(|p| p.distance(root) > 2.0 * reach) {
                    continue;
                }
                let n = 8;
                for i in 0..=n {
                    for k in 0..=n - i {
                        let (s, w) = (i as f32 / n as f32, k as f32 / n as f32);
                        let x = a + (b - a) * s + (c - a) * w;
                        if x.distance(root) > reach {
                            continue;
                        }
                        let inside = planes[j]
                            .iter()
                            .filter(|p| p.truncate() != Vec3::ZERO)
                            .map(|p| p.truncate().dot(x - root) + p.w)
                            .fold(f32::MAX, f32::min);
                        deepest = deepest.max(inside / length);
                    }
                }
            }
        }
        eprintln!(
            "{}: the surface reaches {deepest:e} of the fur's length into planes without triangles",
            builtin.name()
        );
        assert!(deepest <= 0.5 * SKIN_EPSILON as f32, "{}: {deepest:e}", builtin.name());
    }
}

fn sphere_distance(x: Vec3, centre: Vec3, radius: f32) -> f32 {
    x.distance(centre) - radius
}

fn capsule_distance(x: Vec3, a: Vec3, b: Vec3, radius: f32) -> f32 {
    let t = ((x - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
    x.distance(a + (b - a) * t) - radius
}

fn box_distance(x: Vec3, centre: Vec3, turn: Quat, half: Vec3) -> f32 {
    let local = turn.conjugate() * (x - centre);
    let q = local.abs() - half;
    q.max(Vec3::ZERO).length() + q.max_element().min(0.0)
}

struct Probe {
    centre: Vec3,
    turn: Quat,
    shape: Shape,
}

impl Probe {
    fn distance(&self, x: Vec3) -> f32 {
        match self.shape {
            Shape::Sphere { radius } => sphere_distance(x, self.centre, radius),
            Shape::Capsule { radius, half_length } => {
                let axis = self.turn * Vec3::Y * half_length;
                capsule_distance(x, self.centre - axis, self.centre + axis, radius)
            }
            Shape::Box { half_extents } => box_distance(x, self.centre, self.turn, half_extents),
            Shape::Plane => (self.turn * Vec3::Y).dot(x - self.centre),
            _ => unreachable!("no mesh probes here (tests/sim_collider_mesh.rs has them)"),
        }
    }
}

/// A ball resting on the back, a thin capsule and a box sweeping through the fur: no node ends a
/// step inside any of them (beyond a thousandth of the fur's length), none below the skin,
/// lengths exact. Only strands rooted outside a collider count (a root never moves).
#[test]
fn colliders_keep_the_fur_out() {
    let (fur, oracle, radius) = bunny();
    let v = fur.vertex_count();
    let length = fur.lengths[0];
    let top = back(&fur);
    let (hit, normal) = (fur.mesh.positions[top], fur.mesh.normals[top]);
    let mut sim = Simulation::new(&fur, &SimParams { gravity_strength: 4.0, ..with_skin(true) }).unwrap();
    // Across the back and back within a second, a little above the skin, never into it (checked
    // below): the skin and a collider pressed into the body cannot both hold.
    let probes = |t: f64| {
        let x = (0.2 * (t * std::f64::consts::TAU).sin()) as f32 * radius;
        [
            Probe {
                centre: hit + normal * (0.1 * radius + 0.3 * length),
                turn: Quat::IDENTITY,
                shape: Shape::Sphere { radius: 0.1 * radius },
            },
            Probe {
                centre: hit + normal * (0.6 * length) + Vec3::new(x, 0.0, 0.0),
                turn: Quat::from_rotation_x(std::f32::consts::FRAC_PI_2),
                shape: Shape::Capsule { radius: 0.02 * radius, half_length: 0.05 * radius },
            },
            Probe {
                centre: hit + normal * (0.7 * length + 0.04 * radius) - Vec3::new(x, 0.0, 0.0),
                turn: Quat::from_rotation_y(0.5),
                shape: Shape::Box { half_extents: Vec3::new(0.04, 0.04, 0.06) * radius },
            },
        ]
    };
    let (mut worst, mut worst_skin) = (0.0_f32, 0.0_f64);
    let mut touched = 0;
    for n in 1..=30 {
        let t = f64::from(n) / 30.0;
        let colliders: Vec<Collider> = probes(t)
            .iter()
            .enumerate()
            .map(|(i, p)| Collider { appear_secs: 0.0, ..Collider::at(i as u32, p.shape.clone(), t, p.centre, p.turn) })
            .collect();
        sim.set_colliders(&colliders).unwrap();
        sim.advance_to(t);
        let positions = sim.positions();
        for probe in probes(t) {
            let nearest = fur.mesh.positions.iter().map(|p| probe.distance(*p)).fold(f32::MAX, f32::min);
            assert!(nearest > 0.0, "a collider in the body at step {n}: {:?} {nearest}", probe.shape);
        }
        for probe in probes(t) {
            for j in 0..v {
                if probe.distance(positions[j]) <= 0.0 {
                    continue;
                }
                for k in 1..=fur.layers as usize {
                    let d = probe.distance(positions[k * v + j]);
                    worst = worst.max(-d / length);
                    touched += usize::from(d < 0.01 * length);
                }
            }
        }
        worst_skin = worst_skin.max(below_skin(&fur, &oracle, positions, glam::Mat4::IDENTITY).0);
        assert!(worst_length_error(&fur, positions) <= 1e-5, "step {n}");
    }
    assert!(touched > 100, "the colliders reach the fur ({touched} nodes touch them)");
    assert!(worst <= 5e-3, "a node {worst} of the fur's length inside a collider");
    assert!(worst_skin <= SKIN_EPSILON, "a node {worst_skin:e} of the fur's length below the skin");
}

/// Contact leaves the nodes before a strand's first touch as the bend made them, to the bit:
/// balls pressed into the fur on the back change no node below the first that comes within 1%
/// of the fur's length of one (the sphere's own distance) in the same step without them.
#[test]
fn nodes_before_the_first_touch_keep_the_bends_bytes() {
    let (fur, _, radius) = bunny();
    let v = fur.vertex_count();
    let length = fur.lengths[0];
    let ball = 0.1 * radius;
    let up: Vec<usize> = (0..v).filter(|&j| fur.mesh.normals[j].y > 0.9).collect();
    let centres: Vec<Vec3> = up
        .iter()
        .step_by(up.len().div_ceil(8))
        .map(|&j| fur.mesh.positions[j] + fur.mesh.normals[j] * (0.4 * length + ball))
        .collect();
    let colliders: Vec<Collider> = centres
        .iter()
        .enumerate()
        .map(|(i, &c)| Collider {
            appear_secs: 0.0,
            ..Collider::at(i as u32, Shape::Sphere { radius: ball }, 0.0, c, Quat::IDENTITY)
        })
        .collect();
    let params = SimParams { wind: WindParams { strength: 0.5, ..WindParams::default() }, ..with_skin(false) };
    let mut touched = Simulation::new(&fur, &params).unwrap();
    let mut free = Simulation::new(&fur, &params).unwrap();
    touched.set_colliders(&colliders).unwrap();
    // One step from the same state: the free simulation's nodes are the bend's.
    free.advance_to(1.0 / 30.0);
    touched.advance_to(1.0 / 30.0);
    let (a, b) = (touched.positions(), free.positions());
    let (mut strands, mut kept, mut pushed) = (0, 0, 0);
    for j in 0..v {
        let distance =
            |k: usize| centres.iter().map(|&c| sphere_distance(b[k * v + j], c, ball)).fold(f32::MAX, f32::min);
        let Some(first) = (1..=fur.layers as usize).find(|&k| distance(k) < 0.01 * length) else { continue };
        strands += 1;
        for k in 1..first {
            assert!(a[k * v + j] == b[k * v + j], "strand {j}: node {k} (of {first} before a ball) moved");
            kept += 1;
        }
        pushed += usize::from((first..=fur.layers as usize).any(|k| a[k * v + j] != b[k * v + j]));
    }
    assert!(
        strands > 10 && kept > 80 && pushed > 10,
        "the balls reached {strands} strands ({kept} nodes before them), pushed {pushed}"
    );
}

/// A hand closes on the back, lifts a tuft and lets go. While it holds (after closing), every
/// strand it holds fully has a node within one segment of the grip, or where the grip is beyond
/// its length, its tip within 1% of `distance - length` of it; after release every node is back within 1e-3 of the fur's length of its free pose
/// (no grasp) within 2 seconds (60 steps).
#[test]
fn a_grasp_gathers_follows_and_springs_back() {
    let fur = grow(Builtin::Bunny, 8, 0.12);
    let v = fur.vertex_count();
    let length = fur.lengths[0];
    let segment = length / 8.0;
    let top = back(&fur);
    let (point, normal) = (fur.mesh.positions[top], fur.mesh.normals[top]);
    let params = SimParams { interpolate: false, ..SimParams::default() };
    let mut free = Simulation::new(&fur, &params).unwrap();
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let radius = 2.0 * length;
    sim.grasp_begin(point + normal * 0.5 * length, radius, 0.3 * length, GraspParams::default(), 0.0).unwrap();
    let held: Vec<usize> = (0..v).filter(|&j| sim.grasp().unwrap().weights()[j] == 1.0).collect();
    assert!(held.len() >= 5, "the hand holds {} strands", held.len());
    let grip_at = |t: f64| point + normal * (0.5 + 0.3 * t as f32) * length;
    for n in 1..=60 {
        let t = f64::from(n) / 30.0;
        sim.grasp_move(grip_at(t)).unwrap();
        sim.advance_to(t);
        free.advance_to(t);
        let positions = sim.positions();
        assert!(worst_length_error(&fur, positions) <= 1e-5);
        if t >= 0.35 {
            for &j in &held {
                let nearest = (1..=8).map(|k| positions[k * v + j].distance(grip_at(t))).fold(f32::MAX, f32::min);
                // Out of reach, the tip points at the grip from its length away.
                let gap = (positions[j].distance(grip_at(t)) - length).max(segment);
                assert!(nearest <= gap * 1.01, "step {n}: strand {j} is {nearest} from the grip, allowed {gap}");
            }
        }
    }
    sim.grasp_end(2.0);
    let mut settled_at = None;
    for n in 61..=150 {
        let t = f64::from(n) / 30.0;
        sim.advance_to(t);
        free.advance_to(t);
        let off = sim.positions().iter().zip(free.positions()).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max);
        if off <= 1e-3 * length && settled_at.is_none() {
            settled_at = Some(n - 60);
        }
        if n == 63 {
            assert!(off > 0.1 * length, "just after release the tuft is still up ({off})");
        }
    }
    let settled_at = settled_at.expect("the fur settles after release");
    assert!(settled_at <= 60, "settled {settled_at} steps after release");
    assert!(sim.grasp().is_none(), "a settled grasp is dropped");
}

/// 100,000 steps of a small fur with colliders racing through it and the skin on: nothing
/// non-finite, segment lengths within 1e-5 of rest.
#[test]
fn a_hundred_thousand_steps_with_fast_colliders() {
    let fur = grow(Builtin::Box, 6, 0.3);
    let v = fur.vertex_count();
    let radius = bounding_radius(&fur.mesh.positions);
    let params = SimParams { gravity_strength: 2.0, ..with_skin(true) };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let shapes = [
        Shape::Sphere { radius: 0.2 * radius },
        Shape::Capsule { radius: 0.05 * radius, half_length: 0.5 * radius },
        Shape::Box { half_extents: Vec3::new(0.1, 0.3, 0.2) * radius },
    ];
    let mut worst = 0.0_f32;
    for n in 1..=100_000_u32 {
        let t = f64::from(n) / 30.0;
        if n % 7 == 1 {
            let colliders: Vec<Collider> = shapes
                .iter()
                .enumerate()
                .map(|(i, shape)| {
                    let phase = t * (1.7 + i as f64) + i as f64;
                    let at = Vec3::new(phase.sin() as f32, (phase * 1.3).cos() as f32, (phase * 0.7).sin() as f32);
                    let turn = Quat::from_rotation_y(phase as f32) * Quat::from_rotation_x(1.1 * phase as f32);
                    Collider::at(i as u32, shape.clone(), t, at * 1.3 * radius, turn)
                })
                .collect();
            sim.set_colliders(&colliders).unwrap();
        }
        sim.advance_to(t);
        if n % 97 == 0 {
            let positions = sim.positions();
            assert!(positions.iter().all(|p| p.is_finite()), "step {n}");
            worst = worst.max(worst_length_error(&fur, positions));
        }
    }
    assert!(worst <= 1e-5, "segment lengths drift by {worst}");
    let _ = v;
}

/// Degenerate colliders and grasps are clear errors naming what is wrong; nothing changes.
#[test]
fn bad_contact_input_is_an_error() {
    let fur = grow(Builtin::Box, 4, 0.2);
    let mut sim = Simulation::new(&fur, &with_skin(true)).unwrap();
    let good = Collider::at(7, Shape::Sphere { radius: 1.0 }, 0.0, Vec3::ZERO, Quat::IDENTITY);
    for (collider, key) in [
        (Collider { shape: Shape::Sphere { radius: 0.0 }, ..good.clone() }, "radius"),
        (Collider { shape: Shape::Capsule { radius: -1.0, half_length: 1.0 }, ..good.clone() }, "radius"),
        (Collider { shape: Shape::Box { half_extents: Vec3::new(1.0, 0.0, 1.0) }, ..good.clone() }, "half_extents.y"),
        (
            Collider {
                keys: vec![pelt_core::sim::ColliderKey {
                    time_secs: f64::NAN,
                    position: Vec3::ZERO,
                    rotation: Quat::IDENTITY,
                }],
                ..good.clone()
            },
            "keys[0].time_secs",
        ),
        (
            Collider {
                keys: vec![pelt_core::sim::ColliderKey {
                    time_secs: 0.0,
                    position: Vec3::new(f32::NAN, 0.0, 0.0),
                    rotation: Quat::IDENTITY,
                }],
                ..good.clone()
            },
            "keys[0].position",
        ),
    ] {
        let error = sim.set_colliders(&[good.clone(), collider]).unwrap_err();
        let text = error.to_string();
        assert!(text.starts_with("collider 1 (id 7): ") && text.contains(key), "{text}");
        assert!(sim.colliders().is_empty());
    }
    assert!(sim.grasp_begin(Vec3::ZERO, 0.0, 0.0, GraspParams::default(), 0.0).is_err());
    assert!(sim.grasp_begin(Vec3::NAN, 1.0, 0.0, GraspParams::default(), 0.0).is_err());
    let bad = GraspParams { spring_hz: 0.0, ..GraspParams::default() };
    assert!(sim.grasp_begin(Vec3::ZERO, 1.0, 0.0, bad, 0.0).unwrap_err().to_string().contains("grasp.spring_hz"));
    let scene = "[[collider]]\nshape = { kind = \"sphere\", radius = -2.0 }\nkeys = [{ time_secs = 0.0, position = [0.0, 0.0, 0.0] }]\n";
    let error = Scene::from_toml_str(scene, Path::new("s.toml")).unwrap_err();
    assert!(matches!(error, SceneError::Invalid { .. }), "{error}");
    assert_eq!(error.to_string(), "s.toml: collider[0].radius: must be finite and positive, got -2");
    let scene = "[[grasp]]\nstart_secs = 1.0\nend_secs = 0.5\nradius = 1.0\npath = [[0.0, 0.0, 0.0]]\n";
    let error = Scene::from_toml_str(scene, Path::new("s.toml")).unwrap_err();
    assert_eq!(error.to_string(), "s.toml: grasp[0].end_secs: must be later than start_secs");
}

/// Still inputs give the same nodes every step (no jitter at rest), with the skin and a collider
/// resting in the fur.
#[test]
fn contact_at_rest_does_not_jitter() {
    let fur = grow(Builtin::Sphere, 8, 0.3);
    let mut sim = Simulation::new(&fur, &with_skin(true)).unwrap();
    let collider = Collider::at(1, Shape::Sphere { radius: 0.5 }, 0.0, Vec3::new(0.0, 1.1, 0.0), Quat::IDENTITY);
    sim.set_colliders(&[collider]).unwrap();
    run(&mut sim, 20, |_, _| {});
    let before = sim.positions().to_vec();
    run(&mut sim, 5, |_, _| {});
    let bits = |p: &[Vec3]| p.iter().flat_map(|x| x.to_array().map(f32::to_bits)).collect::<Vec<_>>();
    assert_eq!(bits(&before), bits(sim.positions()));
    assert_ne!(bits(&before), bits(&fur.positions), "the collider moves the fur");
}

/// The shipped grasp script parses, and played on the bunny its hand lifts fur off the back and
/// its ball parts it: the fur moves away from where it is without the script.
#[test]
fn the_grasp_script_lifts_and_parts_the_fur() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes/grasp.toml");
    let scene = Scene::load(&path).unwrap();
    assert_eq!((scene.grasps.len(), scene.colliders.len()), (1, 1));
    let fur = grow(Builtin::Bunny, 8, 0.1);
    let params = with_skin(true);
    let mut played = Simulation::new(&fur, &params).unwrap();
    let mut plain = Simulation::new(&fur, &params).unwrap();
    let moved_at = |time: f64, played: &mut Simulation, plain: &mut Simulation| {
        scene.apply(time, played).unwrap();
        played.advance_to(time);
        plain.advance_to(time);
        played.positions().iter().zip(plain.positions()).map(|(a, b)| a.distance(*b)).fold(0.0, f32::max)
    };
    let length = fur.lengths[0];
    assert!(moved_at(2.0, &mut played, &mut plain) > 0.5 * length, "the hand lifts a tuft");
    assert!(moved_at(5.5, &mut played, &mut plain) > 0.2 * length, "the ball parts the fur");
}
