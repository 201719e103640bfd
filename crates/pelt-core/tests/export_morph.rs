//! `pelt_core::export` with morph targets: a source's targets carried onto the fur (every strand
//! by its root's displacement, driven by the source's own weights animation), and a looping
//! weights animation over baked frames. The morph-target fixture `assets/meshes/morph_ball.gltf`
//! is generated here (rerun with `PELT_WRITE_FIXTURES=1` to rewrite it).

use std::path::{Path, PathBuf};

use glam::Vec3;
use pelt_core::export::{AlphaMode, Export, ExportInput, FurMorphs, MorphAnimation, carried_up};
use pelt_core::reference::TileMapping;
use pelt_core::{FurStructure, ImportOptions, Preset, Stage, StageSource};
use serde_json::{Value, json};

const MAPPING: TileMapping = TileMapping { tiles_per_uv: 2.0, tiles_per_world: 3.0 };
const SEGMENTS: usize = 16;
const RINGS: usize = 10;

fn ball_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes/morph_ball.gltf")
}

/// The ball's vertices (unit sphere, poles first), triangles (outward), and its two targets'
/// deltas: "stretch" lengthens it along y, "bulge" pushes its +x side out.
fn ball() -> (Vec<Vec3>, Vec<[u16; 3]>, [Vec<Vec3>; 2]) {
    let mut positions = vec![Vec3::Y, -Vec3::Y];
    for ring in 1..RINGS {
        let polar = std::f32::consts::PI * ring as f32 / RINGS as f32;
        for segment in 0..SEGMENTS {
            let azimuth = std::f32::consts::TAU * segment as f32 / SEGMENTS as f32;
            positions.push(Vec3::new(polar.sin() * azimuth.cos(), polar.cos(), -polar.sin() * azimuth.sin()));
        }
    }
    let at = |ring: usize, segment: usize| (2 + (ring - 1) * SEGMENTS + segment % SEGMENTS) as u16;
    let mut triangles = Vec::new();
    for s in 0..SEGMENTS {
        triangles.push([0, at(1, s), at(1, s + 1)]);
        triangles.push([1, at(RINGS - 1, s + 1), at(RINGS - 1, s)]);
        for ring in 1..RINGS - 1 {
            triangles.push([at(ring, s), at(ring + 1, s), at(ring + 1, s + 1)]);
            triangles.push([at(ring, s), at(ring + 1, s + 1), at(ring, s + 1)]);
        }
    }
    let stretch = positions.iter().map(|p| Vec3::new(0.0, 0.4 * p.y, 0.0)).collect();
    let bulge = positions.iter().map(|p| *p * 0.35 * p.x.max(0.0)).collect();
    (positions, triangles, [stretch, bulge])
}

/// The fixture's glTF text: one mesh with NORMAL and two POSITION targets, and "Breathe", a
/// 3-second weights animation (rest, stretched, bulged, rest), its buffer as a data URI.
fn ball_gltf() -> String {
    let (positions, triangles, targets) = ball();
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut accessors = Vec::new();
    let mut add = |bytes: Vec<u8>, target: Option<u32>, accessor: Value| {
        let mut view = json!({ "buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len() });
        if let Some(target) = target {
            view["target"] = json!(target);
        }
        bin.extend_from_slice(&bytes);
        bin.resize(bin.len().next_multiple_of(4), 0);
        views.push(view);
        let mut accessor = accessor;
        accessor["bufferView"] = json!(views.len() - 1);
        accessors.push(accessor);
        accessors.len() - 1
    };
    let floats = |values: &[f32]| values.iter().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>();
    let vec3 = |values: &[Vec3]| {
        let low = values.iter().fold(Vec3::INFINITY, |a, b| a.min(*b));
        let high = values.iter().fold(Vec3::NEG_INFINITY, |a, b| a.max(*b));
        let flat: Vec<f32> = values.iter().flat_map(|v| v.to_array()).collect();
        (
            floats(&flat),
            json!({ "componentType": 5126, "count": values.len(), "type": "VEC3", "min": low.to_array(), "max": high.to_array() }),
        )
    };
    let (bytes, accessor) = vec3(&positions);
    let position = add(bytes, Some(34962), accessor);
    let (bytes, mut accessor) = vec3(&positions);
    accessor.as_object_mut().expect("object").retain(|k, _| k != "min" && k != "max");
    let normal = add(bytes, Some(34962), accessor);
    let morphs: Vec<usize> = targets
        .iter()
        .map(|deltas| {
            let (bytes, accessor) = vec3(deltas);
            add(bytes, Some(34962), accessor)
        })
        .collect();
    let index_bytes: Vec<u8> = triangles.iter().flatten().flat_map(|i| i.to_le_bytes()).collect();
    let indices =
        add(index_bytes, Some(34963), json!({ "componentType": 5123, "count": 3 * triangles.len(), "type": "SCALAR" }));
    let times = [0.0_f32, 1.0, 2.0, 3.0];
    let input = add(
        floats(&times),
        None,
        json!({ "componentType": 5126, "count": 4, "type": "SCALAR", "min": [0.0], "max": [3.0] }),
    );
    let weights = [0.0_f32, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0];
    let output = add(floats(&weights), None, json!({ "componentType": 5126, "count": 8, "type": "SCALAR" }));
    let document = json!({
        "asset": { "version": "2.0", "generator": "pelt-core tests/export_morph.rs" },
        "scene": 0,
        "scenes": [{ "nodes": [0] }],
        "nodes": [{ "name": "ball", "mesh": 0 }],
        "meshes": [{
            "name": "morph ball",
            "primitives": [{
                "attributes": { "POSITION": position, "NORMAL": normal },
                "targets": [{ "POSITION": morphs[0] }, { "POSITION": morphs[1] }],
                "indices": indices,
            }],
            "weights": [0.0, 0.0],
            "extras": { "targetNames": ["stretch", "bulge"] },
        }],
        "animations": [{
            "name": "Breathe",
            "samplers": [{ "input": input, "output": output, "interpolation": "LINEAR" }],
            "channels": [{ "sampler": 0, "target": { "node": 0, "path": "weights" } }],
        }],
        "buffers": [{ "byteLength": bin.len(), "uri": format!("data:application/octet-stream;base64,{}", base64(&bin)) }],
        "bufferViews": views,
        "accessors": accessors,
    });
    serde_json::to_string_pretty(&document).expect("JSON") + "\n"
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = chunk.iter().enumerate().fold(0_u32, |n, (k, &b)| n | u32::from(b) << (16 - 8 * k));
        for k in 0..4 {
            out.push(if k <= chunk.len() { ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

#[test]
fn the_shipped_morph_ball_is_the_generated_one() {
    let expected = ball_gltf();
    if std::env::var_os("PELT_WRITE_FIXTURES").is_some() {
        std::fs::write(ball_path(), &expected).expect("write the fixture");
    }
    let shipped = std::fs::read_to_string(ball_path()).expect("assets/meshes/morph_ball.gltf");
    assert!(shipped == expected, "assets/meshes/morph_ball.gltf is stale: rerun with PELT_WRITE_FIXTURES=1");
}

/// The GLB's JSON and its fur mesh's primitives' morph target deltas (per primitive, per target).
fn read_targets(glb: &[u8]) -> (Value, Vec<Vec<Vec<Vec3>>>) {
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(glb).expect("the export parses");
    let buffers = gltf::import_buffers(&document, None, blob).expect("buffers");
    let mesh = document.meshes().find(|m| m.name() == Some("pelt fur")).expect("a fur mesh");
    let targets = mesh
        .primitives()
        .map(|primitive| {
            let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            reader
                .read_morph_targets()
                .map(|(positions, _, _)| positions.expect("POSITION deltas").map(Vec3::from_array).collect())
                .collect()
        })
        .collect();
    let json_length = u32::from_le_bytes(glb[12..16].try_into().expect("4 bytes")) as usize;
    (serde_json::from_slice(&glb[20..20 + json_length]).expect("JSON"), targets)
}

fn small_preset() -> Preset {
    let mut preset = Preset::default();
    preset.layers = 4;
    preset.texture.size = 64;
    preset
}

#[test]
fn the_fur_follows_a_sources_morph_targets() {
    let path = ball_path();
    let stage = Stage::load(&StageSource::File(path.clone()), &[], &ImportOptions::default()).expect("the ball");
    let rig = stage.rig.expect("morph targets make a rig");
    let (node, deltas) = rig.morph_position_deltas().expect("one node's targets");
    assert_eq!((node, deltas.len()), (0, 2));
    let preset = small_preset();
    let fur = FurStructure::new(stage.fur_mesh.clone(), &preset.fur_params(&stage.fur_mesh)).expect("fur");
    let textures = preset.generate_textures().expect("textures");
    let input = ExportInput {
        fur: &fur,
        positions: &fur.positions,
        textures: &textures,
        mapping: MAPPING,
        root_occlusion: 0.3,
        shells: 4,
        alpha: AlphaMode::Mask,
        skin: None,
        source: Some(&path),
        plain: &[],
        extras: json!({}),
        morphs: Some(FurMorphs {
            targets: deltas.iter().map(|d| carried_up(d, fur.layers)).collect(),
            weights: vec![0.0, 0.0],
            animation: MorphAnimation::FollowNode(node),
        }),
    };
    let (json, targets) = read_targets(&Export::build(&input).expect("export").glb());
    // The fixture's own deltas, from its generator: each fur vertex moves as some ball vertex.
    let (_, _, ball_targets) = ball();
    assert_eq!(targets.len(), 4 + 1, "four shells and the fins");
    for primitive in &targets {
        assert_eq!(primitive.len(), 2, "both targets on every primitive");
        for (deltas, expected) in primitive.iter().zip(&ball_targets) {
            for d in deltas {
                assert!(expected.iter().any(|e| e.distance(*d) < 1e-5), "{d} is no root's displacement");
            }
            // Not all zero: the fur moves.
            assert!(deltas.iter().any(|d| d.length() > 0.1));
        }
    }
    // "Breathe" drives the fur's weights with the ball's own sampler.
    let fur_node = json["nodes"].as_array().expect("nodes").iter().position(|n| n["name"] == "pelt fur");
    let channels = json["animations"][0]["channels"].as_array().expect("channels");
    assert_eq!(channels.len(), 2);
    assert_eq!(channels[1]["target"], json!({ "node": fur_node, "path": "weights" }));
    assert_eq!(channels[1]["sampler"], channels[0]["sampler"]);
}

#[test]
fn a_morph_loop_crossfades_its_frames_in_turn() {
    let path = ball_path();
    let stage = Stage::load(&StageSource::File(path), &[], &ImportOptions::default()).expect("the ball");
    let preset = small_preset();
    let fur = FurStructure::new(stage.fur_mesh.clone(), &preset.fur_params(&stage.fur_mesh)).expect("fur");
    let textures = preset.generate_textures().expect("textures");
    let frames: Vec<Vec<Vec3>> =
        (0..3).map(|k| vec![Vec3::new(0.01 * (k + 1) as f32, 0.0, 0.0); fur.positions.len()]).collect();
    let input = ExportInput {
        fur: &fur,
        positions: &fur.positions,
        textures: &textures,
        mapping: MAPPING,
        root_occlusion: 0.3,
        shells: 2,
        alpha: AlphaMode::Mask,
        skin: None,
        source: None,
        plain: &[],
        extras: json!({}),
        morphs: Some(FurMorphs {
            targets: frames.clone(),
            weights: Vec::new(),
            animation: MorphAnimation::Loop { name: "sway".to_owned(), period_secs: 1.5 },
        }),
    };
    let glb = Export::build(&input).expect("export").glb();
    let (json, targets) = read_targets(&glb);
    assert_eq!(targets.len(), 1 + 2 + 1, "the skin, two shells, the fins");
    for primitive in &targets {
        for (k, deltas) in primitive.iter().enumerate() {
            assert!(deltas.iter().all(|d| *d == frames[k][0]), "target {k} is frame {k}");
        }
    }
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(&glb).expect("parses");
    let buffers = gltf::import_buffers(&document, None, blob).expect("buffers");
    let animation = document.animations().find(|a| a.name() == Some("sway")).expect("the loop");
    let channel = animation.channels().next().expect("a channel");
    assert_eq!(channel.target().node().name(), Some("pelt fur"));
    let reader = channel.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
    let times: Vec<f32> = reader.read_inputs().expect("times").collect();
    assert_eq!(times, [0.0, 0.5, 1.0, 1.5]);
    let Some(gltf::animation::util::ReadOutputs::MorphTargetWeights(weights)) = reader.read_outputs() else {
        panic!("weights")
    };
    let weights: Vec<f32> = weights.into_f32().collect();
    assert_eq!(weights, [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0], "each in turn, then the first");
    assert_eq!(json["animations"].as_array().map(Vec::len), Some(1));
}
