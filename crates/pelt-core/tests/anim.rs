//! Skinning and animation end to end: small glTF files written here byte by byte (a two-bone
//! strip whose posed positions are worked out by hand), the Fox, and broken rigs.

use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};
use pelt_core::anim::{Pose, Rig};
use pelt_core::{ImportOptions, Mesh, MeshError};
use serde_json::{Value, json};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes").join(name)
}

/// Writes a GLB: the JSON document plus one binary buffer of accessors added with `add`.
#[derive(Default)]
struct Glb {
    bin: Vec<u8>,
    views: Vec<Value>,
    accessors: Vec<Value>,
}

impl Glb {
    /// Adds an accessor of `count` elements of `kind` (SCALAR, VEC3, ...) holding `bytes`.
    fn add(&mut self, bytes: &[u8], component: u32, kind: &str, count: usize) -> usize {
        while !self.bin.len().is_multiple_of(4) {
            self.bin.push(0);
        }
        self.views.push(json!({"buffer": 0, "byteOffset": self.bin.len(), "byteLength": bytes.len()}));
        self.bin.extend_from_slice(bytes);
        self.accessors.push(
            json!({"bufferView": self.views.len() - 1, "componentType": component, "type": kind, "count": count}),
        );
        self.accessors.len() - 1
    }

    fn floats(&mut self, values: &[f32], kind: &str) -> usize {
        let width = match kind {
            "SCALAR" => 1,
            "VEC3" => 3,
            "VEC4" => 4,
            "MAT4" => 16,
            _ => unreachable!(),
        };
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        let index = self.add(&bytes, 5126, kind, values.len() / width);
        if kind == "VEC3" {
            // POSITION accessors need bounds; harmless elsewhere.
            let (mut lo, mut hi) = ([f32::MAX; 3], [f32::MIN; 3]);
            for p in values.chunks(3) {
                for k in 0..3 {
                    lo[k] = lo[k].min(p[k]);
                    hi[k] = hi[k].max(p[k]);
                }
            }
            self.accessors[index]["min"] = json!(lo);
            self.accessors[index]["max"] = json!(hi);
        }
        index
    }

    fn u16s(&mut self, values: &[u16], kind: &str, count: usize) -> usize {
        let bytes: Vec<u8> = values.iter().flat_map(|v| v.to_le_bytes()).collect();
        self.add(&bytes, 5123, kind, count)
    }

    fn finish(self, mut document: Value) -> Vec<u8> {
        document["asset"] = json!({"version": "2.0"});
        document["buffers"] = json!([{"byteLength": self.bin.len()}]);
        document["bufferViews"] = Value::Array(self.views);
        document["accessors"] = Value::Array(self.accessors);
        let mut text = serde_json::to_vec(&document).unwrap();
        while !text.len().is_multiple_of(4) {
            text.push(b' ');
        }
        let mut bin = self.bin;
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
        let mut glb = Vec::new();
        glb.extend(b"glTF");
        glb.extend(2_u32.to_le_bytes());
        glb.extend(((12 + 8 + text.len() + 8 + bin.len()) as u32).to_le_bytes());
        glb.extend((text.len() as u32).to_le_bytes());
        glb.extend(b"JSON");
        glb.extend(text);
        glb.extend((bin.len() as u32).to_le_bytes());
        glb.extend(b"BIN\0");
        glb.extend(bin);
        glb
    }
}

/// A strip two units tall facing +Z: rows at y = 0, 1, 2, x = -0.5 and 0.5.
const STRIP: [[f32; 3]; 6] =
    [[-0.5, 0.0, 0.0], [0.5, 0.0, 0.0], [-0.5, 1.0, 0.0], [0.5, 1.0, 0.0], [-0.5, 2.0, 0.0], [0.5, 2.0, 0.0]];
const STRIP_TRIANGLES: [u16; 12] = [0, 1, 3, 0, 3, 2, 2, 3, 5, 2, 5, 4];

/// What to break in the two-bone file.
#[derive(Clone, Copy, Default)]
struct Breakage {
    no_inverse_bind_matrices: bool,
    zero_weights_on_top: bool,
    joint_out_of_range: bool,
    nan_key: bool,
    target_missing_node: bool,
}

/// Bone 0 at the origin, bone 1 one unit up (its child); the bottom row follows bone 0, the
/// middle row half and half, the top row bone 1. The animation moves bone 0 to x = 2 and turns
/// bone 1 by 90 degrees about Z over one second (LINEAR).
fn two_bones(broken: Breakage) -> Vec<u8> {
    let mut glb = Glb::default();
    let positions = glb.floats(STRIP.as_flattened(), "VEC3");
    let normals = glb.floats(&[0.0, 0.0, 1.0].repeat(6), "VEC3");
    let indices = glb.u16s(&STRIP_TRIANGLES, "SCALAR", 12);
    let top_joint = if broken.joint_out_of_range { 7 } else { 1 };
    let joints = glb.u16s(&[0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, top_joint, 0, 0, 0, 1, 0, 0, 0], "VEC4", 6);
    let top = if broken.zero_weights_on_top { 0.0 } else { 1.0 };
    let weights = glb.floats(
        &[1.0, 0., 0., 0., 1.0, 0., 0., 0., 0.5, 0.5, 0., 0., 0.5, 0.5, 0., 0., top, 0., 0., 0., top, 0., 0., 0.],
        "VEC4",
    );
    let attributes = json!({"POSITION": positions, "NORMAL": normals, "JOINTS_0": joints, "WEIGHTS_0": weights});
    let inverse_bind = glb.floats(
        &[
            1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., //
            1., 0., 0., 0., 0., 1., 0., 0., 0., 0., 1., 0., 0., -1., 0., 1.,
        ],
        "MAT4",
    );
    let times = glb.floats(&[0.0, 1.0], "SCALAR");
    let half = std::f32::consts::FRAC_1_SQRT_2;
    let w = if broken.nan_key { f32::NAN } else { half };
    let rotations = glb.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 0.0, half, w], "VEC4");
    let translations = glb.floats(&[0.0, 0.0, 0.0, 2.0, 0.0, 0.0], "VEC3");
    let mut skin = json!({"joints": [0, 1], "inverseBindMatrices": inverse_bind});
    if broken.no_inverse_bind_matrices {
        skin = json!({"joints": [0, 1]});
    }
    let rotated_node = if broken.target_missing_node { 9 } else { 1 };
    glb.finish(json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "root", "children": [1]},
            {"name": "tip", "translation": [0.0, 1.0, 0.0]},
            {"name": "strip", "mesh": 0, "skin": 0}
        ],
        "meshes": [{"primitives": [{"attributes": attributes, "indices": indices}]}],
        "skins": [skin],
        "animations": [{
            "name": "bend",
            "samplers": [
                {"input": times, "output": rotations, "interpolation": "LINEAR"},
                {"input": times, "output": translations, "interpolation": "LINEAR"}
            ],
            "channels": [
                {"sampler": 0, "target": {"node": rotated_node, "path": "rotation"}},
                {"sampler": 1, "target": {"node": 0, "path": "translation"}}
            ]
        }]
    }))
}

fn import(bytes: &[u8]) -> Result<(Mesh, Rig), MeshError> {
    let (mesh, _, rig) = Mesh::from_gltf_slice_animated(bytes, Path::new("rig.glb"), &ImportOptions::default())?;
    Ok((mesh, rig.expect("the file has a skin")))
}

/// The analytic pose of the strip at clip time `t` in `0..1`: bone 0 at `(2t, 0, 0)`, bone 1
/// turned by `90t` degrees about Z around `(2t, 1, 0)`; the middle row is the average of both
/// bones' transforms.
fn analytic(rest: Vec3, t: f32) -> Vec3 {
    let angle = std::f32::consts::FRAC_PI_2 * t;
    let shift = Vec3::new(2.0 * t, 0.0, 0.0);
    let by_bone_0 = rest + shift;
    let local = rest - Vec3::Y;
    let turned = Vec3::new(
        local.x * angle.cos() - local.y * angle.sin(),
        local.x * angle.sin() + local.y * angle.cos(),
        local.z,
    );
    let by_bone_1 = turned + Vec3::Y + shift;
    match rest.y {
        y if y < 0.5 => by_bone_0,
        y if y < 1.5 => (by_bone_0 + by_bone_1) * 0.5,
        _ => by_bone_1,
    }
}

fn find(mesh: &Mesh, rest: [f32; 3]) -> usize {
    mesh.positions.iter().position(|p| *p == Vec3::from_array(rest)).expect("every strip vertex survives import")
}

#[test]
fn two_bones_skin_to_the_analytic_positions() {
    let (mesh, rig) = import(&two_bones(Breakage::default())).unwrap();
    assert!(rig.report().is_empty(), "{:?}", rig.report());
    assert_eq!(rig.skins().len(), 1);
    assert_eq!(rig.skins()[0].joints, 2);
    assert_eq!(rig.animations().len(), 1);
    assert_eq!(rig.animations()[0].duration_secs(), 1.0);
    let mut pose = Pose::default();
    for t in [0.0_f32, 0.25, 0.5, 0.9] {
        rig.pose(&mesh, Some(0), f64::from(t), &mut pose);
        for rest in STRIP {
            let j = find(&mesh, rest);
            let expected = analytic(Vec3::from_array(rest), t);
            assert!(
                pose.positions[j].distance(expected) < 1e-5,
                "t {t} vertex {rest:?}: {} vs {expected}",
                pose.positions[j]
            );
            assert!(pose.normals[j].distance(Vec3::Z) < 1e-5, "turning about Z keeps the +Z normal");
        }
        // The top row turns with bone 1: its frame's X axis is turned by 90t degrees.
        let top = find(&mesh, STRIP[5]);
        let angle = std::f32::consts::FRAC_PI_2 * t;
        let x = pose.rotations[top] * Vec3::X;
        assert!(x.distance(Vec3::new(angle.cos(), angle.sin(), 0.0)) < 1e-5, "t {t}: {x}");
    }
    // Looping: one clip later is the same pose.
    let mut later = Pose::default();
    rig.pose(&mesh, Some(0), 1.5, &mut later);
    rig.pose(&mesh, Some(0), 0.5, &mut pose);
    assert_eq!(later.positions, pose.positions);
}

#[test]
fn the_rest_pose_is_the_static_mesh() {
    for (name, bytes) in
        [("two bones", two_bones(Breakage::default())), ("fox", std::fs::read(asset("Fox.glb")).unwrap())]
    {
        let (mesh, rig) = import(&bytes).unwrap();
        let (still, _) = Mesh::from_gltf_slice(&bytes, Path::new("still.glb"), &ImportOptions::default()).unwrap();
        assert_eq!(mesh, still, "{name}: loading the rig changes nothing in the mesh");
        let (_, radius) = mesh.bounding_sphere();
        let mut pose = Pose::default();
        rig.pose(&mesh, None, 0.0, &mut pose);
        for (j, (posed, rest)) in pose.positions.iter().zip(&mesh.positions).enumerate() {
            assert!(posed.distance(*rest) <= 1e-5 * radius, "{name} vertex {j}: {posed} vs {rest}");
        }
        for (posed, rest) in pose.normals.iter().zip(&mesh.normals) {
            assert!(posed.distance(*rest) < 1e-4, "{name}: {posed} vs {rest}");
        }
    }
}

#[test]
fn the_fox_walks() {
    let (mesh, _, rig) = Mesh::load_animated(&asset("Fox.glb"), &ImportOptions::default()).unwrap();
    let rig = rig.expect("the fox is skinned");
    assert!(rig.report().is_empty(), "{:?}", rig.report());
    let names: Vec<_> = rig.animations().iter().map(|a| a.name.clone().unwrap_or_default()).collect();
    assert_eq!(names, ["Survey", "Walk", "Run"]);
    assert_eq!(rig.skins()[0].joints, 24);
    let walk = rig.find_animation("Walk").unwrap();
    assert_eq!(rig.find_animation("1").unwrap(), 1);
    let err = rig.find_animation("Dance").unwrap_err();
    assert!(err.contains("Survey") && err.contains("Walk") && err.contains("Run"), "{err}");
    let (_, radius) = mesh.bounding_sphere();
    let (mut a, mut b) = (Pose::default(), Pose::default());
    rig.pose(&mesh, Some(walk), 0.0, &mut a);
    rig.pose(&mesh, Some(walk), 0.35, &mut b);
    let moved = a.positions.iter().zip(&b.positions).map(|(p, q)| p.distance(*q)).fold(0.0, f32::max);
    assert!(moved > 0.05 * radius, "the legs move: {moved} of radius {radius}");
    for pose in [&a, &b] {
        assert!(pose.positions.iter().all(|p| p.is_finite()));
        assert!(pose.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4));
        assert!(pose.rotations.iter().all(|q| q.is_normalized()));
    }
}

#[test]
fn broken_rigs_are_reported_not_panics() {
    let cases: [(Breakage, &str); 4] = [
        (Breakage { no_inverse_bind_matrices: true, ..Breakage::default() }, "no inverse bind matrices; identity used"),
        (Breakage { zero_weights_on_top: true, ..Breakage::default() }, "2 vertices have weights that sum to 0"),
        (Breakage { joint_out_of_range: true, ..Breakage::default() }, "1 influences name a joint past"),
        (Breakage { nan_key: true, ..Breakage::default() }, "non-finite key value"),
    ];
    for (broken, line) in cases {
        let (mesh, rig) = import(&two_bones(broken)).unwrap();
        assert!(rig.report().iter().any(|l| l.contains(line)), "{line:?} not in {:?}", rig.report());
        let mut pose = Pose::default();
        rig.pose(&mesh, Some(0), 0.5, &mut pose);
        assert!(pose.positions.iter().chain(&pose.normals).all(|p| p.is_finite()));
    }
    let (_, rig) = import(&two_bones(Breakage { nan_key: true, ..Breakage::default() })).unwrap();
    assert_eq!(rig.animations()[0].channels.len(), 1, "the channel with the NaN key is dropped");

    let (_, rig) = import(&two_bones(Breakage { target_missing_node: true, ..Breakage::default() })).unwrap();
    assert!(
        rig.report().iter().any(|l| l.contains("channel 0: it targets node 9, which does not exist; channel dropped")),
        "{:?}",
        rig.report()
    );
    assert_eq!(rig.animations()[0].channels.len(), 1);
}

#[test]
fn more_than_four_influences_keep_the_largest_renormalised() {
    let mut glb = Glb::default();
    let positions = glb.floats(STRIP.as_flattened(), "VEC3");
    let indices = glb.u16s(&STRIP_TRIANGLES, "SCALAR", 12);
    // Joints 0..6 (one more than any vertex needs); every vertex: set 0 gives joints 0-3 weight
    // 0.1 each, set 1 gives joint 4 weight 0.4 and joint 5 weight 0.2: the four largest are
    // 4 (0.4), 5 (0.2) and two of the 0.1s, so the translation of joint 4 dominates.
    let joints0 = glb.u16s(&[0, 1, 2, 3].repeat(6), "VEC4", 6);
    let weights0 = glb.floats(&[0.1; 24], "VEC4");
    let joints1 = glb.u16s(&[4, 5, 0, 0].repeat(6), "VEC4", 6);
    let weights1 = glb.floats(&[0.4, 0.2, 0.0, 0.0].repeat(6), "VEC4");
    let nodes: Vec<Value> =
        (0..6).map(|k| if k == 4 { json!({"translation": [10.0, 0.0, 0.0]}) } else { json!({}) }).collect();
    let mut nodes = nodes;
    nodes.push(json!({"mesh": 0, "skin": 0}));
    let bytes = glb.finish(json!({
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3, 4, 5, 6]}],
        "nodes": nodes,
        "meshes": [{"primitives": [{"attributes": {"POSITION": positions, "JOINTS_0": joints0, "WEIGHTS_0": weights0,
            "JOINTS_1": joints1, "WEIGHTS_1": weights1}, "indices": indices}]}],
        "skins": [{"joints": [0, 1, 2, 3, 4, 5]}]
    }));
    let (mesh, rig) = import(&bytes).unwrap();
    assert!(rig.report().iter().any(|l| l.contains("6 vertices have more than 4 influences")), "{:?}", rig.report());
    let mut pose = Pose::default();
    rig.pose(&mesh, None, 0.0, &mut pose);
    // Kept: 0.4 (joint 4, +10 x), 0.2, 0.1, 0.1 -> joint 4's share is 0.4 / 0.8 = 0.5.
    for (posed, rest) in pose.positions.iter().zip(&mesh.positions) {
        assert!((posed.x - rest.x - 5.0).abs() < 1e-5, "{posed} vs {rest}");
    }
}

#[test]
fn a_node_animation_without_a_skin_moves_rigidly_and_morph_weights_apply() {
    let mut glb = Glb::default();
    let positions = glb.floats(STRIP.as_flattened(), "VEC3");
    let indices = glb.u16s(&STRIP_TRIANGLES, "SCALAR", 12);
    // One morph target pushing the top row +1 in z.
    let deltas: Vec<f32> = STRIP.iter().flat_map(|p| [0.0, 0.0, if p[1] > 1.5 { 1.0 } else { 0.0 }]).collect();
    let target = glb.floats(&deltas, "VEC3");
    let times = glb.floats(&[0.0, 2.0], "SCALAR");
    let rotations = glb.floats(&[0.0, 0.0, 0.0, 1.0, 0.0, 1.0, 0.0, 0.0], "VEC4"); // 180 degrees about Y
    let weights = glb.floats(&[0.0, 1.0], "SCALAR");
    let step_times = glb.floats(&[0.0, 1.0], "SCALAR");
    let bytes = glb.finish(json!({
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0, "translation": [0.0, 0.0, 3.0]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": positions}, "indices": indices,
            "targets": [{"POSITION": target}]}], "weights": [0.0]}],
        "animations": [{
            "samplers": [
                {"input": times, "output": rotations, "interpolation": "LINEAR"},
                {"input": step_times, "output": weights, "interpolation": "STEP"}
            ],
            "channels": [
                {"sampler": 0, "target": {"node": 0, "path": "rotation"}},
                {"sampler": 1, "target": {"node": 0, "path": "weights"}}
            ]
        }]
    }));
    let (mesh, _, rig) =
        Mesh::from_gltf_slice_animated(&bytes, Path::new("spin.glb"), &ImportOptions::default()).unwrap();
    let rig = rig.expect("animated");
    assert_eq!(rig.morph_target_count(), 1);
    let mut pose = Pose::default();
    // t = 1: half way, 90 degrees about Y about the node's origin (0, 0, 3); the STEP weight is
    // 1, so the top row is first pushed +1 in z (local space), then turned.
    rig.pose(&mesh, Some(0), 1.0, &mut pose);
    let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_2);
    for rest in STRIP {
        let j = find(&mesh, [rest[0], rest[1], rest[2] + 3.0]);
        let local = Vec3::from_array(rest) + if rest[1] > 1.5 { Vec3::Z } else { Vec3::ZERO };
        let expected = turn * local + Vec3::new(0.0, 0.0, 3.0);
        assert!(pose.positions[j].distance(expected) < 1e-5, "{rest:?}: {} vs {expected}", pose.positions[j]);
    }
    // t = 0.5: the weight is still 0 (STEP), a quarter turn of 180 is 45 degrees.
    rig.pose(&mesh, Some(0), 0.5, &mut pose);
    let turn = Quat::from_rotation_y(std::f32::consts::FRAC_PI_4);
    let j = find(&mesh, [0.5, 2.0, 3.0]);
    assert!(pose.positions[j].distance(turn * Vec3::new(0.5, 2.0, 0.0) + Vec3::new(0.0, 0.0, 3.0)) < 1e-5);
}
