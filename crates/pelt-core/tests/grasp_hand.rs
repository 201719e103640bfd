//! The grasp's hand (fingers, thumb and palm about the grip) and bad contact input, checked with
//! the test's own distance formulas (no `sim::contact` code).

use crate::common;

use std::path::Path;

use common::back;
use glam::{Quat, Vec3};
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
use pelt_core::mesh::builtin::Builtin;
use pelt_core::sim::{
    Collider, ColliderKey, ContactParams, GraspParams, HAND_PARTS, Scene, Shape, SimParams, Simulation, StepCollider,
};

fn bunny_fur(length_fraction: f32) -> FurStructure {
    let (mesh, _) = Builtin::Bunny.mesh();
    let (lo, hi) = mesh.positions.iter().fold((Vec3::MAX, Vec3::MIN), |(l, h), p| (l.min(*p), h.max(*p)));
    let radius = mesh.positions.iter().map(|p| p.distance((lo + hi) * 0.5)).fold(0.0, f32::max);
    let direction = GrowthDirection { random_angle_rad: 0.4, seed: 5, ..GrowthDirection::default() };
    let params = FurParams { layers: 8, length: FurLength::Constant(length_fraction * radius), direction };
    FurStructure::new(mesh, &params).unwrap()
}

/// A part's ends (a ball's twice) and radius, from its pose alone.
fn segment(part: &StepCollider) -> (Vec3, Vec3, f32) {
    let half = part.rotation * Vec3::new(0.0, part.half_extents.y, 0.0);
    (part.centre - half, part.centre + half, part.radius)
}

/// Signed distance of `x` to a ball swept from `a` to `b`.
fn swept_ball_distance(x: Vec3, (a, b, radius): (Vec3, Vec3, f32)) -> f32 {
    let ab = b - a;
    let t = if ab.length_squared() > 0.0 { ((x - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0) } else { 0.0 };
    x.distance(a + ab * t) - radius
}

/// A hand closes on the back and lifts: it closes (the fingertips come in toward the grip against
/// the knuckles), its
/// parts push every strand it does not hold out of them (no node deeper than 0.5% of the fur's
/// length), and the strands it holds pass through it (bit for bit as under a grasp without a
/// hand: strands do not touch each other).
#[test]
fn the_hand_closes_pushes_the_rest_and_lets_the_held_pass() {
    let fur = bunny_fur(0.12);
    let v = fur.vertex_count();
    let length = fur.lengths[0];
    let top = back(&fur);
    let (point, normal) = (fur.mesh.positions[top], fur.mesh.normals[top]);
    let params = SimParams { contact: ContactParams { skin: true }, interpolate: false, ..SimParams::default() };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let mut bare = Simulation::new(&fur, &params).unwrap();
    let hand_radius = 0.7 * length;
    let start = point + normal * 0.5 * length;
    sim.grasp_begin(start, length, hand_radius, GraspParams::default(), 0.0).unwrap();
    bare.grasp_begin(start, length, 0.0, GraspParams::default(), 0.0).unwrap();
    let weights = sim.grasp().unwrap().weights().to_vec();
    let grip_at = |t: f64| start + normal * (0.8 * t as f32).min(0.6) * length;
    let tip_gap = |sim: &Simulation, t: f64| {
        let parts = sim.shown_colliders(t);
        // Each fingertip's distance from the grip against its knuckle's: free of the hand's size.
        let ratios = parts[..4].iter().map(|f| {
            let (knuckle, tip, _) = segment(f);
            tip.distance(grip_at(t)) / knuckle.distance(grip_at(t))
        });
        ratios.sum::<f32>() / 4.0
    };
    let (mut worst, mut touched, mut moved) = (0.0_f32, 0, 0);
    let mut first_gap = None;
    for n in 1..=40 {
        let t = f64::from(n) / 30.0;
        for s in [&mut sim, &mut bare] {
            s.grasp_move(grip_at(t)).unwrap();
            s.advance_to(t);
        }
        let hand: Vec<StepCollider> = sim.contact_step(t).colliders.into_iter().filter(|c| c.grasp_hand).collect();
        assert_eq!(hand.len(), HAND_PARTS, "step {n}");
        assert_eq!(hand.iter().filter(|c| c.kind == StepCollider::CAPSULE).count(), 5, "four fingers and a thumb");
        first_gap.get_or_insert(tip_gap(&sim, t));
        let (positions, without) = (sim.positions(), bare.positions());
        for (j, &weight) in weights.iter().enumerate() {
            let nodes = (1..=8).map(|k| k * v + j);
            if weight > 0.0 {
                let same = nodes.clone().all(|i| positions[i].to_array() == without[i].to_array());
                assert!(same, "step {n}: held strand {j} moved by the hand");
                continue;
            }
            moved += usize::from(nodes.clone().any(|i| positions[i] != without[i]));
            for i in nodes {
                let depth =
                    hand.iter().map(|part| -swept_ball_distance(positions[i], segment(part))).fold(f32::MIN, f32::max);
                worst = worst.max(depth / length);
                touched += usize::from(depth > -0.02 * length);
            }
        }
    }
    let closed_gap = tip_gap(&sim, 40.0 / 30.0);
    assert!(closed_gap < 0.6 * first_gap.unwrap(), "the fingertips close in: {first_gap:?} -> {closed_gap}");
    assert!(touched > 20 && moved > 5, "the hand reaches the fur it does not hold ({touched} nodes at it)");
    assert!(worst <= 5e-3, "a node the hand does not hold lies {worst} of the fur's length inside it");
}

/// Bad colliders through the API: each a clear error naming the collider and key; nothing changes.
#[test]
fn degenerate_colliders_through_the_api_name_their_key() {
    let (mesh, _) = Builtin::Box.mesh();
    let params = FurParams { layers: 4, length: FurLength::Constant(0.2), direction: GrowthDirection::default() };
    let fur = FurStructure::new(mesh, &params).unwrap();
    let mut sim = Simulation::new(&fur, &SimParams::default()).unwrap();
    let good = Collider::at(3, Shape::Sphere { radius: 1.0 }, 0.0, Vec3::ZERO, Quat::IDENTITY);
    let key = |position: Vec3, rotation: Quat| vec![ColliderKey { time_secs: 0.0, position, rotation }];
    for (collider, named) in [
        (Collider { shape: Shape::Sphere { radius: f32::INFINITY }, ..good.clone() }, "radius"),
        (Collider { shape: Shape::Capsule { radius: 1.0, half_length: -0.5 }, ..good.clone() }, "half_length"),
        (Collider { shape: Shape::Box { half_extents: Vec3::new(-1.0, 1.0, 1.0) }, ..good.clone() }, "half_extents.x"),
        (
            Collider { keys: key(Vec3::new(0.0, f32::INFINITY, 0.0), Quat::IDENTITY), ..good.clone() },
            "keys[0].position",
        ),
        (
            Collider { keys: key(Vec3::ZERO, Quat::from_xyzw(f32::NAN, 0.0, 0.0, 1.0)), ..good.clone() },
            "keys[0].rotation",
        ),
        (Collider { keys: key(Vec3::ZERO, Quat::from_xyzw(0.0, 0.0, 0.0, 0.0)), ..good.clone() }, "keys[0].rotation"),
        (Collider { friction: f32::NAN, ..good.clone() }, "friction"),
    ] {
        let error = sim.set_colliders(&[good.clone(), collider]).unwrap_err().to_string();
        assert!(error.starts_with(&format!("collider 1 (id 3): {named}")), "{error}");
        assert!(sim.colliders().is_empty(), "nothing changes");
    }
    let error = sim.grasp_begin(Vec3::ZERO, 1.0, -0.1, GraspParams::default(), 0.0).unwrap_err().to_string();
    assert!(error.contains("-0.1"), "{error}");
    assert!(sim.grasp_begin(Vec3::ZERO, f32::NAN, 0.0, GraspParams::default(), 0.0).is_err());
    assert!(sim.grasp_begin(Vec3::ZERO, 1.0, 0.0, GraspParams::default(), f64::INFINITY).is_err());
    assert!(sim.grasp().is_none());
}

/// Bad colliders and grasps in a script: the file and the key in the message.
#[test]
fn degenerate_script_contact_names_the_file_and_key() {
    let keys = "keys = [{ time_secs = 0.0, position = [0.0, 0.0, 0.0] }]";
    for (script, message) in [
        (
            format!("[[collider]]\nshape = {{ kind = \"sphere\", radius = 0.0 }}\n{keys}\n"),
            "s.toml: collider[0].radius: must be finite and positive, got 0",
        ),
        (
            format!("[[collider]]\nshape = {{ kind = \"box\", half_extents = [1.0, 0.0, 1.0] }}\n{keys}\n"),
            "s.toml: collider[0].half_extents.y: must be finite and positive, got 0",
        ),
        (
            format!("[[collider]]\nshape = {{ kind = \"capsule\", radius = inf, half_length = 1.0 }}\n{keys}\n"),
            "s.toml: collider[0].radius: must be finite and positive, got inf",
        ),
        (
            "[[collider]]\nshape = { kind = \"sphere\", radius = 1.0 }\nkeys = [{ time_secs = 0.0, position = [nan, 0.0, 0.0] }]\n"
                .into(),
            "s.toml: collider[0].keys[0].position: must be finite, got [NaN, 0, 0]",
        ),
        (
            "[[collider]]\nshape = { kind = \"sphere\", radius = 1.0 }\nkeys = [{ time_secs = inf, position = [0.0, 0.0, 0.0] }]\n"
                .into(),
            "s.toml: collider[0].keys[0].time_secs: must be finite, got inf",
        ),
        (
            "[[collider]]\nshape = { kind = \"plane\" }\nkeys = [{ time_secs = 0.0, position = [0.0, 0.0, 0.0], rotation_deg = [0.0, nan, 0.0] }]\n"
                .into(),
            "s.toml: collider[0].keys[0].rotation_deg: must be finite",
        ),
        (
            "[[grasp]]\nstart_secs = 0.0\nend_secs = 1.0\nradius = 0.0\npath = [[0.0, 0.0, 0.0]]\n".into(),
            "s.toml: grasp[0].radius: ",
        ),
        (
            "[[grasp]]\nstart_secs = 0.0\nend_secs = 1.0\nradius = -1.0\npath = [[0.0, 0.0, 0.0]]\n".into(),
            "s.toml: grasp[0].radius: ",
        ),
        (
            "[[grasp]]\nstart_secs = 0.0\nend_secs = 1.0\nradius = 1.0\nhand_radius = -0.2\npath = [[0.0, 0.0, 0.0]]\n"
                .into(),
            "s.toml: grasp[0].hand_radius: ",
        ),
        (
            "[[grasp]]\nstart_secs = 0.0\nend_secs = 1.0\nradius = 1.0\npath = [[0.0, 0.0, 0.0], [0.0, nan, 0.0]]\n"
                .into(),
            "s.toml: grasp[0].path[1]: must be finite",
        ),
    ] {
        let error = Scene::from_toml_str(&script, Path::new("s.toml")).unwrap_err().to_string();
        assert!(error.starts_with(message), "{script}\n{error}");
    }
}
