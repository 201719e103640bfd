//! `pelt_core::export`: the written glTF read back with the `gltf` crate and with Pelt's own mesh
//! loader: the fur's vertex and face counts are the structure's, every index is in range, every
//! shell vertex is the shared vertex it stands for, and a skinned source keeps its skin and
//! animations with every fur vertex bound.

use std::path::{Path, PathBuf};

use glam::Vec3;
use pelt_core::export::{AlphaMode, Export, ExportInput, FurSkin, exported_layers, source_skin_joints};
use pelt_core::groom::Groom;
use pelt_core::reference::TileMapping;
use pelt_core::{Builtin, FurStructure, FurTextures, ImportOptions, Mesh, Preset, Stage, StageSource};

const MAPPING: TileMapping = TileMapping { tiles_per_uv: 2.0, tiles_per_world: 3.0 };

fn small_preset(layers: u32) -> Preset {
    let mut preset = Preset::default();
    preset.layers = layers;
    preset.texture.size = 64;
    preset
}

fn textures(preset: &Preset) -> FurTextures {
    preset.generate_textures().expect("textures")
}

fn fox_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes/Fox.glb")
}

/// One primitive read back: vertex count, triangle count, material name, positions.
type Primitive = (usize, usize, String, Vec<Vec3>);

/// Every primitive of the file's fur mesh, each index checked against its vertex count.
fn read_fur(glb: &[u8]) -> (gltf::Document, Vec<Primitive>) {
    let gltf::Gltf { document, blob } = gltf::Gltf::from_slice(glb).expect("the export parses");
    let buffers = gltf::import_buffers(&document, None, blob).expect("buffers");
    let mesh = document.meshes().find(|m| m.name() == Some("pelt fur")).expect("a fur mesh");
    let primitives = mesh
        .primitives()
        .map(|primitive| {
            let reader = primitive.reader(|b| buffers.get(b.index()).map(|d| &d.0[..]));
            let positions: Vec<Vec3> = reader.read_positions().expect("positions").map(Vec3::from_array).collect();
            let indices: Vec<u32> = reader.read_indices().expect("indices").into_u32().collect();
            assert_eq!(indices.len() % 3, 0);
            assert!(indices.iter().all(|&i| (i as usize) < positions.len()), "an index out of range");
            let name = primitive.material().name().unwrap_or("").to_owned();
            (positions.len(), indices.len() / 3, name, positions)
        })
        .collect();
    (document, primitives)
}

#[test]
fn a_builtin_export_reads_back_with_the_structures_counts() {
    let (mesh, _) = Builtin::Box.mesh();
    let preset = small_preset(8);
    let fur = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh)).expect("fur");
    let textures = textures(&preset);
    for shells in [8, 3] {
        let input = ExportInput {
            fur: &fur,
            positions: &fur.positions,
            textures: &textures,
            mapping: MAPPING,
            root_occlusion: 0.3,
            shells,
            alpha: AlphaMode::Blend,
            skin: None,
            source: None,
            plain: &[],
            extras: serde_json::json!({ "preset": "default" }),
            morphs: None,
        };
        let export = Export::build(&input).expect("export");
        let glb = export.glb();
        let (document, primitives) = read_fur(&glb);
        let layers = exported_layers(fur.layers, shells);
        // The skin, the shells, the fins.
        assert_eq!(primitives.len(), 1 + layers.len() + 1);
        let f = fur.mesh.triangles.len();
        let e = fur.mesh.edges.len();
        let v = fur.vertex_count();
        assert_eq!(primitives[0].2, "pelt skin");
        assert_eq!(primitives[0].1, f);
        for ((vertices, triangles, name, positions), layer) in primitives[1..=layers.len()].iter().zip(&layers) {
            assert_eq!(*name, format!("pelt shell {layer}/{}", fur.layers));
            assert_eq!(*triangles, f, "a shell repeats the base triangles");
            assert!(*vertices >= v, "every base vertex, once per tile coordinate");
            // Every shell vertex is a shared vertex of its layer.
            let layer_positions = &fur.positions[*layer as usize * v..(*layer as usize + 1) * v];
            assert!(positions.iter().all(|p| layer_positions.contains(p)));
        }
        let (fin_vertices, fin_triangles, name, _) = &primitives[layers.len() + 1];
        assert_eq!(name, "pelt fins");
        assert_eq!(*fin_triangles, 2 * e * layers.len(), "two triangles per edge and layer step");
        assert_eq!(*fin_vertices, 2 * e * (layers.len() + 1));
        assert_eq!(export.counts.fin_triangles, *fin_triangles);
        assert_eq!(export.counts.shell_layers, layers);
        let json_length = u32::from_le_bytes(glb[12..16].try_into().expect("4 bytes")) as usize;
        let json: serde_json::Value = serde_json::from_slice(&glb[20..20 + json_length]).expect("JSON");
        assert_eq!(json["asset"]["extras"]["pelt"]["preset"], "default");
        assert!(document.meshes().count() == 1);

        // Pelt's own loader takes the whole file as one mesh: skin, shells and fins.
        let options =
            ImportOptions { weld: false, orient: false, vertex_cache_order: false, ..ImportOptions::default() };
        let (read, _) = Mesh::from_gltf_slice(&glb, Path::new("export.glb"), &options).expect("Pelt reads the export");
        assert_eq!(read.triangles.len(), f + layers.len() * f + 2 * e * layers.len());
    }
}

#[test]
fn a_skinned_export_keeps_the_skin_and_binds_every_fur_vertex() {
    let path = fox_path();
    let stage = Stage::load(&StageSource::File(path.clone()), &[], &ImportOptions::default()).expect("Fox.glb");
    let rig = stage.rig.expect("the Fox is rigged");
    let preset = small_preset(4);
    let fur = FurStructure::new(stage.fur_mesh.clone(), &preset.fur_params(&stage.fur_mesh)).expect("fur");
    let textures = textures(&preset);
    let skins = source_skin_joints(&path).expect("skins");
    assert_eq!(skins.len(), 1);
    let influences = rig.influences_in_skin(&skins[0]).expect("the Fox's vertices all ride its one skin");
    let input = ExportInput {
        fur: &fur,
        positions: &fur.positions,
        textures: &textures,
        mapping: MAPPING,
        root_occlusion: 0.3,
        shells: 4,
        alpha: AlphaMode::Mask,
        skin: Some(FurSkin { skin: 0, influences }),
        source: Some(&path),
        plain: &[],
        extras: serde_json::json!({}),
        morphs: None,
    };
    let glb = Export::build(&input).expect("export").glb();
    let (document, primitives) = read_fur(&glb);
    // The shells and the fins; the Fox's own mesh draws the skin.
    assert_eq!(primitives.len(), 4 + 1);
    let source = gltf::Gltf::open(&path).expect("source");
    assert_eq!(document.animations().count(), source.animations().count());
    assert_eq!(document.skins().count(), 1);
    assert_eq!(document.meshes().count(), source.meshes().count() + 1);
    let node = document.nodes().find(|n| n.name() == Some("pelt fur")).expect("the fur's node");
    assert_eq!(node.skin().map(|s| s.index()), Some(0));
    for primitive in node.mesh().expect("mesh").primitives() {
        let attributes: Vec<String> = primitive.attributes().map(|(s, _)| s.to_string()).collect();
        for needed in ["JOINTS_0", "WEIGHTS_0"] {
            assert!(attributes.iter().any(|a| a == needed), "{needed} missing from {attributes:?}");
        }
    }
    // Pelt reads the export back with its rig: the Fox's animations, now moving the fur too.
    let (_, _, read_rig) =
        Mesh::from_gltf_slice_animated(&glb, Path::new("fox.glb"), &ImportOptions::default()).expect("reads back");
    assert_eq!(read_rig.expect("a rig").animations().len(), 3);
}

#[test]
fn a_failed_write_leaves_no_file() {
    let (mesh, _) = Builtin::Box.mesh();
    let preset = small_preset(2);
    let fur = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh)).expect("fur");
    let textures = textures(&preset);
    let input = ExportInput {
        fur: &fur,
        positions: &fur.positions,
        textures: &textures,
        mapping: MAPPING,
        root_occlusion: 0.3,
        shells: 2,
        alpha: AlphaMode::Blend,
        skin: None,
        source: None,
        plain: &[],
        extras: serde_json::json!({}),
        morphs: None,
    };
    let export = Export::build(&input).expect("export");
    let folder = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("pelt-export-test");
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder).expect("folder");
    let missing = folder.join("no/such/folder/fur.glb");
    let error = export.write(&missing).expect_err("no folder");
    assert!(error.to_string().contains("fur.glb"), "{error}");
    assert!(export.write(&folder.join("fur.obj")).is_err(), "only .glb and .gltf");
    let gltf_path = folder.join("fur.gltf");
    export.write(&gltf_path).expect("a .gltf with its .bin");
    assert!(folder.join("fur.bin").exists());
    let entries: Vec<String> = std::fs::read_dir(&folder)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into())
        .collect();
    assert!(entries.iter().all(|name| !name.contains("partial")), "{entries:?}");
    let (read, _) = Mesh::load(&gltf_path, &ImportOptions::default()).expect("the .gltf loads");
    assert!(read.triangles.len() > fur.mesh.triangles.len());
    std::fs::remove_dir_all(&folder).expect("clean up");

    let bad = ExportInput { shells: 3, ..input };
    assert!(Export::build(&bad).is_err(), "more shells than layers");
}

#[test]
fn a_groomed_export_has_no_fur_on_its_bald_faces() {
    let (mesh, _) = Builtin::Box.mesh();
    let preset = small_preset(4);
    // Bald where the base vertex lies above the cube's middle: the top face and the upper sides.
    let bald: Vec<bool> = mesh.positions.iter().map(|p| p.y > 0.0).collect();
    let groom = Groom { length: Some(bald.iter().map(|&b| if b { 0.0 } else { 1.0 }).collect()), ..Groom::default() };
    let fur = FurStructure::new_groomed(mesh.clone(), &preset.fur_params(&mesh), Some(groom)).expect("fur");
    // The oracle counts the faces from the mesh and the bald flags alone.
    let furred_triangles = mesh.triangles.iter().filter(|t| !t.iter().all(|&j| bald[j as usize])).count();
    let fin_edges = mesh.edges.iter().filter(|e| !e.iter().all(|&j| bald[j as usize])).count();
    assert!(furred_triangles > 0 && furred_triangles < mesh.triangles.len(), "the groom bares some faces only");
    let textures = textures(&preset);
    let input = ExportInput {
        fur: &fur,
        positions: &fur.positions,
        textures: &textures,
        mapping: MAPPING,
        root_occlusion: 0.3,
        shells: 4,
        alpha: AlphaMode::Mask,
        skin: None,
        source: None,
        plain: &[],
        extras: serde_json::json!({}),
        morphs: None,
    };
    let glb = Export::build(&input).expect("export").glb();
    let (_, primitives) = read_fur(&glb);
    let layers = exported_layers(fur.layers, 4);
    assert_eq!(primitives[0].1, mesh.triangles.len(), "the skin keeps every triangle");
    for (_, triangles, name, _) in &primitives[1..=layers.len()] {
        assert_eq!(*triangles, furred_triangles, "{name}: only the furred triangles");
    }
    let (_, fin_triangles, name, _) = &primitives[layers.len() + 1];
    assert_eq!(name, "pelt fins");
    assert_eq!(*fin_triangles, 2 * fin_edges * layers.len(), "fins on the furred edges only");
}
