//! A plain closed mesh as a collider: the pebble pressed into the bunny's fur keeps every node
//! out, by an inside test written here (ray-crossing parity in f64 over the OBJ's own
//! triangles, read here), sharing no code with the baked field or the contact kernels; and a
//! scene script's mesh collider loads relative to the script, or fails naming the file.

use crate::common;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use common::back;
use glam::{DVec3, Quat, Vec3};
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
use pelt_core::mesh::builtin::Builtin;
use pelt_core::mesh::{ImportOptions, Mesh};
use pelt_core::sim::{
    Collider, ColliderKey, ColliderMesh, ContactParams, Scene, SceneError, Shape, SimParams, Simulation, WindParams,
};

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

/// The OBJ's vertices and triangles in f64, read here (`v x y z`, `f a b c` lines).
struct Solid {
    points: Vec<DVec3>,
    triangles: Vec<[usize; 3]>,
    lo: DVec3,
    hi: DVec3,
}

impl Solid {
    fn read(file: &Path) -> Self {
        let text = std::fs::read_to_string(file).unwrap();
        let (mut points, mut triangles) = (Vec::new(), Vec::new());
        for line in text.lines() {
            let words: Vec<&str> = line.split_whitespace().collect();
            match words.first() {
                Some(&"v") => points.push(DVec3::new(
                    words[1].parse().unwrap(),
                    words[2].parse().unwrap(),
                    words[3].parse().unwrap(),
                )),
                Some(&"f") => triangles.push([1, 2, 3].map(|i| words[i].parse::<usize>().unwrap() - 1)),
                _ => {}
            }
        }
        let lo = points.iter().fold(DVec3::MAX, |l, p| l.min(*p));
        let hi = points.iter().fold(DVec3::MIN, |h, p| h.max(*p));
        Self { points, triangles, lo, hi }
    }

    /// Inside by the parity of a ray's crossings, the majority of three unaligned rays (a ray
    /// grazing an edge miscounts; two rays rarely both do).
    fn inside(&self, p: DVec3) -> bool {
        if p.cmplt(self.lo).any() || p.cmpgt(self.hi).any() {
            return false;
        }
        let rays =
            [DVec3::new(0.5377, 0.8031, 0.2566), DVec3::new(-0.3124, 0.1822, 0.9323), DVec3::new(0.7, -0.6, -0.3743)];
        rays.iter().filter(|d| self.crossings(p, d.normalize()) % 2 == 1).count() >= 2
    }

    fn crossings(&self, p: DVec3, d: DVec3) -> usize {
        self.triangles
            .iter()
            .filter(|t| {
                let [a, b, c] = t.map(|i| self.points[i]);
                let n = (b - a).cross(c - a);
                let denominator = n.dot(d);
                if denominator.abs() < 1e-15 {
                    return false;
                }
                let s = n.dot(a - p) / denominator;
                if s <= 0.0 {
                    return false;
                }
                let x = p + d * s;
                // Inside the triangle: x on the inner side of each edge.
                [(a, b), (b, c), (c, a)].iter().all(|(e0, e1)| (*e1 - *e0).cross(x - *e0).dot(n) >= 0.0)
            })
            .count()
    }

    /// Distance to the surface, by each triangle's closest point (its plane, else its edges).
    fn distance(&self, p: DVec3) -> f64 {
        let segment = |a: DVec3, b: DVec3| {
            let t = ((p - a).dot(b - a) / (b - a).length_squared()).clamp(0.0, 1.0);
            p.distance(a + (b - a) * t)
        };
        self.triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| self.points[i]);
                let n = (b - a).cross(c - a).normalize();
                let x = p - n * n.dot(p - a);
                let within = [(a, b), (b, c), (c, a)].iter().all(|(e0, e1)| (*e1 - *e0).cross(x - *e0).dot(n) >= 0.0);
                if within { n.dot(p - a).abs() } else { segment(a, b).min(segment(b, c)).min(segment(c, a)) }
            })
            .fold(f64::MAX, f64::min)
    }
}

fn fur() -> (FurStructure, f32) {
    let (mesh, _) = Builtin::Bunny.mesh();
    let (lo, hi) = mesh.bounds();
    let radius = mesh.positions.iter().map(|p| p.distance((lo + hi) * 0.5)).fold(0.0, f32::max);
    let direction = GrowthDirection { random_angle_rad: 0.4, seed: 5, ..GrowthDirection::default() };
    let params = FurParams { layers: 12, length: FurLength::Constant(0.12 * radius), direction };
    (FurStructure::new(mesh, &params).unwrap(), radius)
}

const RESOLUTION: usize = 32;

/// The pebble pressed into the back and dragged across it, turning, under a strong downward wind
/// and heavy gravity. From when it has grown in, no node of a strand rooted outside it lies
/// inside it by the parity test, except within one cell of its field (longest side / 32, times
/// the scale) of its surface: the field is a trilinear interpolation of distances sampled a cell
/// apart, which is as near as it resolves the surface. Segment lengths stay exact (1e-5
/// relative). Without the collider, many nodes end up inside beyond that (checked once by hand).
#[test]
fn a_mesh_collider_keeps_the_fur_out() {
    let (fur, radius) = fur();
    let v = fur.vertex_count();
    let length = fur.lengths[0];
    let top = back(&fur);
    let (hit, normal) = (fur.mesh.positions[top], fur.mesh.normals[top]);
    let file = assets().join("meshes/pebble.obj");
    let solid = Solid::read(&file);
    let (mesh, _) = Mesh::load(&file, &ImportOptions::default()).unwrap();
    let pebble = Arc::new(ColliderMesh::new(mesh, RESOLUTION).unwrap());
    let scale = 0.15 * radius;
    let cell = (solid.hi - solid.lo).max_element() / RESOLUTION as f64 * f64::from(scale);
    // The pebble's underside (0.6 of its scale below its centre, with bumps) sits in the fur's
    // lower half, well above the skin; it slides across the back and back, turning.
    let rise = 0.72 * scale + 0.35 * length;
    let keys: Vec<ColliderKey> = (0..=10)
        .map(|i| {
            let t = f64::from(i) * 0.1;
            let across = (0.12 * (t * std::f64::consts::TAU).sin()) as f32 * radius;
            ColliderKey {
                time_secs: t,
                position: hit + normal * rise + Vec3::new(across, 0.0, 0.1 * across),
                rotation: Quat::from_rotation_y(1.5 * t as f32),
            }
        })
        .collect();
    let collider = Collider {
        keys,
        ..Collider::at(1, Shape::Mesh { mesh: Arc::clone(&pebble), scale }, 0.0, Vec3::ZERO, Quat::IDENTITY)
    };
    let params = SimParams {
        gravity_strength: 30.0,
        wind: WindParams { strength: 30.0, direction: Vec3::new(0.2, -1.0, 0.1), ..WindParams::default() },
        contact: ContactParams { skin: true },
        interpolate: false,
        ..SimParams::default()
    };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    sim.set_colliders(std::slice::from_ref(&collider)).unwrap();
    let (mut worst, mut near, mut checked) = (0.0_f64, 0, 0);
    for n in 1..=33 {
        let t = f64::from(n) / 30.0;
        sim.advance_to(t);
        let positions = sim.positions();
        let lengths = worst_length_error(&fur, positions);
        assert!(lengths <= 1e-5, "step {n}: a segment's length is off by {lengths:e}");
        if t < 0.3 {
            continue;
        }
        // Into the pebble's own frame: the pose of `pose_at`, written out (the keys are a tenth
        // of a second apart, linear between).
        let i = ((t * 10.0).floor() as usize).min(9);
        let f = (t * 10.0 - i as f64).min(1.0);
        let (a, b) = (&collider.keys[i], &collider.keys[i + 1]);
        let centre = a.position.as_dvec3().lerp(b.position.as_dvec3(), f);
        let turn = a.rotation.as_dquat().slerp(b.rotation.as_dquat(), f);
        let local = |x: Vec3| turn.inverse() * (x.as_dvec3() - centre) / f64::from(scale);
        for p in &fur.mesh.positions {
            assert!(!solid.inside(local(*p)), "step {n}: the pebble is in the body at {p}");
        }
        for j in 0..v {
            for k in 1..=fur.layers as usize {
                let x = local(positions[k * v + j]);
                checked += 1;
                let margin = DVec3::splat(cell / f64::from(scale));
                if x.cmplt(solid.lo - margin).any() || x.cmpgt(solid.hi + margin).any() {
                    continue;
                }
                let d = solid.distance(x) * f64::from(scale);
                near += usize::from(d < cell);
                if solid.inside(x) {
                    worst = worst.max(d);
                }
            }
        }
    }
    eprintln!("{checked} nodes checked, {near} within a cell ({cell:.5}) of the pebble; deepest inside {worst:.5}");
    assert!(near > 200, "the pebble reaches the fur ({near} nodes within a cell of it)");
    assert!(worst <= cell, "a node {worst:.5} inside the pebble (more than a cell, {cell:.5})");
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

const SCRIPT: &str = r#"
[[collider]]
shape = { kind = "mesh", path = "meshes/MESH", resolution = 12, scale = 0.5 }
keys = [{ time_secs = 0.0, position = [0.0, 1.0, 0.0] }]
"#;

/// A script's mesh path is relative to the script; an open mesh fails with the field's "not
/// closed" message naming the mesh file and the key; a missing one names its file.
#[test]
fn a_scripts_mesh_collider_loads_beside_the_script_or_names_the_file() {
    let script = assets().join("scene.toml");
    let scene = Scene::from_toml_str(&SCRIPT.replace("MESH", "pebble.obj"), &script).unwrap();
    let mut sim = Simulation::new(&fur().0, &SimParams::default()).unwrap();
    scene.apply(0.0, &mut sim).unwrap();
    let Shape::Mesh { mesh, scale } = &sim.colliders()[0].shape else { panic!("a mesh: {:?}", sim.colliders()) };
    assert_eq!((*scale, mesh.mesh().triangles.len()), (0.5, 320));

    // An open mesh: the MakeHuman body has boundary loops (its neck, wrists, ankles...).
    let error = Scene::from_toml_str(&SCRIPT.replace("MESH", "female1605.obj"), &script).unwrap_err();
    let message = error.to_string();
    assert!(matches!(error, SceneError::Invalid { .. }), "{message}");
    for part in ["scene.toml", "collider[0].shape.path", "female1605.obj", "not closed"] {
        assert!(message.contains(part), "{message:?} lacks {part:?}");
    }
    let error = Scene::from_toml_str(&SCRIPT.replace("MESH", "no_such.obj"), &script).unwrap_err().to_string();
    assert!(error.contains("no_such.obj") && error.contains("collider[0].shape.path"), "{error}");
    let error = Scene::from_toml_str(&SCRIPT.replace("12", "1"), &script).unwrap_err().to_string();
    assert!(error.contains("collider[0].shape.resolution"), "{error}");
}
