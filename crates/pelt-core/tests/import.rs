//! Mesh import end to end: the real meshes Pelt ships, broken files, and small glTF scenes
//! built here byte by byte.

use std::path::{Path, PathBuf};

use glam::Vec3;
use pelt_core::mesh::{MeshError, NormalSource};
use pelt_core::{ImportOptions, Mesh, MeshReport};

fn asset(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes").join(name)
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

fn load(path: &Path) -> (Mesh, MeshReport) {
    Mesh::load(path, &ImportOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

/// Six times the signed volume: positive when a closed mesh is wound counter-clockwise outside.
fn signed_volume(mesh: &Mesh) -> f32 {
    mesh.triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
            a.dot(b.cross(c))
        })
        .sum()
}

/// Expected counts, from `assets/CREDITS.md` and the asset README, not from running the importer.
struct Expected {
    file: &'static str,
    vertices: usize,
    triangles: usize,
    boundary_loops: usize,
    has_uvs: bool,
}

const REAL_MESHES: [Expected; 6] = [
    Expected { file: "bunny.obj", vertices: 1_839, triangles: 3_674, boundary_loops: 0, has_uvs: false },
    Expected { file: "spot.obj", vertices: 2_930, triangles: 5_856, boundary_loops: 0, has_uvs: true },
    Expected { file: "female1605.obj", vertices: 1_605, triangles: 2 * 1_584, boundary_loops: 4, has_uvs: true },
    Expected { file: "female_generic.obj", vertices: 13_868, triangles: 2 * 13_866, boundary_loops: 0, has_uvs: true },
    Expected { file: "skirthelper.obj", vertices: 720, triangles: 2 * 684, boundary_loops: 2, has_uvs: true },
    Expected { file: "Fox.glb", vertices: 290, triangles: 576, boundary_loops: 0, has_uvs: true },
];

#[test]
fn real_meshes_import_with_their_published_counts() {
    for expected in REAL_MESHES {
        let (mesh, report) = load(&asset(expected.file));
        let name = expected.file;
        assert_eq!((mesh.vertex_count(), mesh.triangles.len()), (expected.vertices, expected.triangles), "{name}");
        assert_eq!(report.boundary_loops, expected.boundary_loops, "{name}: {report}");
        assert_eq!(report.has_uvs, expected.has_uvs, "{name}");
        assert_eq!(mesh.corner_uvs.as_ref().map(Vec::len), expected.has_uvs.then_some(expected.triangles), "{name}");
        assert_eq!(report.non_manifold_edges, 0, "{name}: {report}");
        assert_eq!(report.inconsistent_winding_edges, 0, "{name}: {report}");
        assert_eq!(report.reoriented_triangles, 0, "{name} is consistently wound as shipped: {report}");
        // None of these files carry normals, so all are computed, unit length.
        assert_eq!(report.normals, NormalSource::Computed, "{name}");
        assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-4), "{name}");
        assert!(mesh.positions.iter().all(|p| p.is_finite()), "{name}");
        // Every edge is listed once, with its faces; a closed mesh has E = 3F/2.
        assert!(mesh.edges.windows(2).all(|w| w[0] < w[1]), "{name}: edges sorted and unique");
        let half_edges: usize = mesh.edge_faces.iter().map(|f| 1 + usize::from(f[1] != u32::MAX)).sum();
        assert_eq!(half_edges, 3 * mesh.triangles.len(), "{name}");
        if expected.boundary_loops == 0 {
            assert!(report.is_closed_manifold(), "{name}: {report}");
            assert_eq!(2 * mesh.edges.len(), 3 * mesh.triangles.len(), "{name}");
            assert!(signed_volume(&mesh) > 0.0, "{name} is wound inside out");
        } else {
            assert!(report.boundary_edges > 0, "{name}");
        }
    }
}

#[test]
fn closed_genus_zero_meshes_have_euler_characteristic_two() {
    for file in ["bunny.obj", "spot.obj", "female_generic.obj", "Fox.glb"] {
        let (mesh, _) = load(&asset(file));
        let euler = mesh.vertex_count() as i64 - mesh.edges.len() as i64 + mesh.triangles.len() as i64;
        assert_eq!(euler, 2, "{file}");
    }
    // An open tube: one component, genus 0, two rims.
    let (mesh, _) = load(&asset("skirthelper.obj"));
    assert_eq!(mesh.vertex_count() as i64 - mesh.edges.len() as i64 + mesh.triangles.len() as i64, 0);
}

#[test]
fn the_fox_is_a_triangle_soup_that_welding_joins() {
    let (mesh, report) = load(&asset("Fox.glb"));
    assert_eq!(report.input_vertices, 3 * 576);
    assert_eq!(report.welded_vertices, 3 * 576 - 290);
    assert_eq!(mesh.edges.len(), 864);

    let unwelded = ImportOptions { weld: false, ..ImportOptions::default() };
    let (mesh, report) = Mesh::load(&asset("Fox.glb"), &unwelded).unwrap();
    assert_eq!(mesh.vertex_count(), 3 * 576);
    assert_eq!(report.boundary_edges, 3 * 576, "without welding no triangle has a neighbour");
}

#[test]
fn import_is_deterministic() {
    for file in ["spot.obj", "Fox.glb"] {
        let first = load(&asset(file));
        let second = load(&asset(file));
        assert_eq!(first, second, "{file}");
    }
}

#[test]
fn obj_quads_groups_and_relative_indices_weld_into_a_closed_cube() {
    let (mesh, report) = load(&fixture("cube_groups.obj"));
    assert_eq!((report.input_vertices, report.input_triangles), (12, 12), "{report}");
    assert_eq!((mesh.vertex_count(), mesh.triangles.len(), mesh.edges.len()), (8, 12, 18));
    assert!(report.is_closed_manifold(), "{report}");
    assert!((signed_volume(&mesh) / 6.0 - 1.0).abs() < 1e-5, "unit cube, outward");
    assert!((mesh.surface_area() - 6.0).abs() < 1e-5);
    // A cube corner's smooth normal points along the diagonal.
    let corner = mesh.positions.iter().position(|p| *p == Vec3::ONE).unwrap();
    assert!(mesh.normals[corner].dot(Vec3::ONE.normalize()) > 0.999);
}

/// Loads a broken fixture and returns its error message, which must name the file.
fn error_of(name: &str) -> (MeshError, String) {
    let path = fixture(name);
    let err = Mesh::load(&path, &ImportOptions::default()).expect_err(name);
    let message = err.to_string();
    assert!(message.contains(name), "the message names the file: {message}");
    (err, message)
}

#[test]
fn broken_files_are_clear_errors() {
    let (err, message) = error_of("index_out_of_range.obj");
    assert!(matches!(err, MeshError::Parse { line: Some(8), .. }), "{message}");
    assert!(message.contains("vertex 9") && message.contains("only 4"), "{message}");

    let (err, message) = error_of("bad_number.obj");
    assert!(matches!(err, MeshError::Parse { line: Some(3), .. }), "{message}");

    let (err, message) = error_of("nan.obj");
    assert!(matches!(err, MeshError::NonFinite { vertex: 2, .. }), "{message}");

    let (err, message) = error_of("empty.obj");
    assert!(matches!(err, MeshError::NoTriangles { .. }), "{message}");

    let (err, message) = error_of("lines_only.obj");
    assert!(matches!(err, MeshError::NoTriangles { .. }), "{message}");

    let (_, message) = error_of("all_degenerate.obj");
    assert!(message.contains("degenerate"), "{message}");

    let (err, message) = error_of("garbage.glb");
    assert!(matches!(err, MeshError::Parse { .. }), "{message}");

    let (err, message) = error_of("cube.stl");
    assert!(matches!(err, MeshError::UnknownFormat { .. }), "{message}");

    let (err, message) = error_of("missing.obj");
    assert!(matches!(err, MeshError::Io { .. }), "{message}");
}

#[test]
fn a_directory_is_an_error_not_a_panic() {
    let dir = fixture("");
    assert!(Mesh::load(&dir, &ImportOptions::default()).is_err());
    let dir_named_obj = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests");
    assert!(Mesh::load(&dir_named_obj.with_extension("obj"), &ImportOptions::default()).is_err());
}

mod gltf_scenes {
    //! glTF files written here: a tetrahedron (outward winding) stored once in a buffer and
    //! placed by nodes.

    use super::*;

    const TETRAHEDRON: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    const TETRAHEDRON_TRIANGLES: [[u16; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];

    fn base64(bytes: &[u8]) -> String {
        const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
        let mut out = String::new();
        for chunk in bytes.chunks(3) {
            let n = chunk.iter().enumerate().fold(0u32, |n, (k, &b)| n | u32::from(b) << (16 - 8 * k));
            for k in 0..4 {
                if k <= chunk.len() {
                    out.push(ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char);
                } else {
                    out.push('=');
                }
            }
        }
        out
    }

    /// A glTF document with one mesh of one primitive of `mode`: a POSITION accessor, an index
    /// accessor (when `indices` is not empty) and a NORMAL accessor (when `normals` is not
    /// empty), each in a buffer of its own, plus the given `nodes` / `scenes` JSON.
    fn document_with_normals(
        positions: &[[f32; 3]],
        normals: &[[f32; 3]],
        indices: &[u16],
        mode: u32,
        nodes: &str,
        scenes: &str,
    ) -> Vec<u8> {
        let (mut buffers, mut views, mut accessors, mut attributes) = (vec![], vec![], vec![], String::new());
        let mut add = |bytes: Vec<u8>, accessor: String| {
            let k = buffers.len();
            buffers.push(format!(
                r#"{{"byteLength":{},"uri":"data:application/octet-stream;base64,{}"}}"#,
                bytes.len(),
                base64(&bytes)
            ));
            views.push(format!(r#"{{"buffer":{k},"byteLength":{}}}"#, bytes.len()));
            accessors.push(accessor.replace("VIEW", &k.to_string()));
            k
        };
        let floats = |values: &[[f32; 3]]| values.iter().flatten().flat_map(|v| v.to_le_bytes()).collect::<Vec<u8>>();
        let (min, max) = positions.iter().fold(([f32::MAX; 3], [f32::MIN; 3]), |(lo, hi), p| {
            (std::array::from_fn(|k| lo[k].min(p[k])), std::array::from_fn(|k| hi[k].max(p[k])))
        });
        let count = positions.len();
        let vec3 = format!(r#"{{"bufferView":VIEW,"componentType":5126,"count":{count},"type":"VEC3""#);
        let k = add(floats(positions), format!(r#"{vec3},"min":{min:?},"max":{max:?}}}"#));
        attributes.push_str(&format!(r#""POSITION":{k}"#));
        if !normals.is_empty() {
            let k = add(floats(normals), format!("{vec3}}}"));
            attributes.push_str(&format!(r#","NORMAL":{k}"#));
        }
        let mut index_ref = String::new();
        if !indices.is_empty() {
            let mut bytes: Vec<u8> = indices.iter().flat_map(|i| i.to_le_bytes()).collect();
            bytes.resize(bytes.len().next_multiple_of(4), 0);
            let accessor =
                format!(r#"{{"bufferView":VIEW,"componentType":5123,"count":{},"type":"SCALAR"}}"#, indices.len());
            index_ref = format!(r#","indices":{}"#, add(bytes, accessor));
        }
        format!(
            r#"{{
  "asset": {{"version": "2.0"}},
  "buffers": [{}],
  "bufferViews": [{}],
  "accessors": [{}],
  "meshes": [{{"name":"tet","primitives":[{{"attributes":{{{attributes}}},"mode":{mode}{index_ref}}}]}}],
  "nodes": {nodes},
  "scenes": {scenes},
  "scene": 0
}}"#,
            buffers.join(","),
            views.join(","),
            accessors.join(","),
        )
        .into_bytes()
    }

    fn document(positions: &[[f32; 3]], indices: &[u16], mode: u32, nodes: &str, scenes: &str) -> Vec<u8> {
        document_with_normals(positions, &[], indices, mode, nodes, scenes)
    }

    fn tetrahedron(nodes: &str, scenes: &str) -> Vec<u8> {
        let indices: Vec<u16> = TETRAHEDRON_TRIANGLES.iter().flatten().copied().collect();
        document(&TETRAHEDRON, &indices, 4, nodes, scenes)
    }

    fn import(bytes: &[u8]) -> Result<(Mesh, MeshReport), MeshError> {
        Mesh::from_gltf_slice(bytes, Path::new("scene.gltf"), &ImportOptions::default())
    }

    #[test]
    fn base64_matches_the_rfc_examples() {
        assert_eq!(base64(b"foob"), "Zm9vYg==");
        assert_eq!(base64(b"fooba"), "Zm9vYmE=");
        assert_eq!(base64(b"foobar"), "Zm9vYmFy");
    }

    #[test]
    fn file_normals_follow_a_non_uniform_scale() {
        // A quad in the plane x + y = 1, its normals along (1, 1, 0); scaled by 4 along y it lies
        // in 4x + y = 4, whose normal is (4, 1, 0) / sqrt(17), not the scaled (1, 4, 0).
        let quad = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 1.0], [1.0, 0.0, 1.0]];
        let normal = Vec3::new(1.0, 1.0, 0.0).normalize().to_array();
        let nodes = r#"[{"mesh":0,"scale":[1,4,1]}]"#;
        let bytes = document_with_normals(&quad, &[normal; 4], &[0, 1, 2, 0, 2, 3], 4, nodes, r#"[{"nodes":[0]}]"#);
        let (mesh, report) = import(&bytes).unwrap();
        assert_eq!(report.normals, NormalSource::File);
        let expected = Vec3::new(4.0, 1.0, 0.0).normalize();
        for n in &mesh.normals {
            assert!(n.distance(expected) < 1e-5, "{n} should be {expected}");
        }
        assert!(mesh.face_normal(0).distance(expected) < 1e-5, "winding agrees with the normals");
    }

    #[test]
    fn node_transforms_are_applied_and_nested() {
        let nodes = r#"[{"translation":[10,0,0],"children":[1]},{"mesh":0,"scale":[2,2,2]}]"#;
        let (mesh, report) = import(&tetrahedron(nodes, r#"[{"nodes":[0]}]"#)).unwrap();
        assert!(report.is_closed_manifold(), "{report}");
        assert_eq!(mesh.positions[1], Vec3::new(12.0, 0.0, 0.0), "scaled by the child, then moved by the parent");
        assert_eq!(mesh.bounds(), (Vec3::new(10.0, 0.0, 0.0), Vec3::new(12.0, 2.0, 2.0)));
        assert!(signed_volume(&mesh) > 0.0);
    }

    #[test]
    fn a_mirroring_node_keeps_the_winding_outward() {
        let nodes = r#"[{"mesh":0,"scale":[-1,1,1]}]"#;
        let (mesh, report) = import(&tetrahedron(nodes, r#"[{"nodes":[0]}]"#)).unwrap();
        assert_eq!(mesh.positions[1], Vec3::new(-1.0, 0.0, 0.0));
        assert!(report.is_closed_manifold(), "{report}");
        assert_eq!(report.reoriented_triangles, 0, "the loader itself undid the mirroring");
        assert!(signed_volume(&mesh) > 0.0, "mirrored but still wound outward");
        let centre = Vec3::new(-0.25, 0.25, 0.25);
        for (p, n) in mesh.positions.iter().zip(&mesh.normals) {
            assert!(n.dot(*p - centre) > 0.0, "normals point out of the mirrored tetrahedron");
        }
    }

    #[test]
    fn every_instance_of_a_mesh_is_imported() {
        let nodes = r#"[{"mesh":0},{"mesh":0,"translation":[5,0,0]}]"#;
        let (mesh, report) = import(&tetrahedron(nodes, r#"[{"nodes":[0,1]}]"#)).unwrap();
        assert_eq!((mesh.vertex_count(), mesh.triangles.len()), (8, 8));
        assert!(report.is_closed_manifold(), "{report}");
    }

    #[test]
    fn without_a_scene_every_mesh_is_imported_once() {
        let bytes = tetrahedron("[]", "[]");
        let text = String::from_utf8(bytes).unwrap().replace(",\n  \"scene\": 0", "");
        assert!(!text.contains("\"scene\""));
        let (mesh, _) = import(text.as_bytes()).unwrap();
        assert_eq!(mesh.vertex_count(), 4);
    }

    #[test]
    fn strips_and_fans_become_consistently_wound_triangles() {
        // A 3 x 2 grid of vertices in the z = 0 plane, facing +Z.
        let grid =
            [[0.0, 0.0, 0.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [2.0, 0.0, 0.0], [2.0, 1.0, 0.0]];
        let nodes = r#"[{"mesh":0}]"#;
        let scenes = r#"[{"nodes":[0]}]"#;
        let strip = document(&grid, &[1, 0, 3, 2, 5, 4], 5, nodes, scenes);
        let (mesh, report) = import(&strip).unwrap();
        assert_eq!(mesh.triangles.len(), 4);
        assert_eq!(report.inconsistent_winding_edges, 0, "{report}");
        assert!((0..4).all(|t| mesh.face_normal(t).z > 0.99), "all face +Z");

        let fan = document(&grid, &[0, 2, 3, 1], 6, nodes, scenes);
        let (mesh, report) = import(&fan).unwrap();
        assert_eq!(mesh.triangles.len(), 2);
        assert_eq!(report.inconsistent_winding_edges, 0, "{report}");
        assert!((0..2).all(|t| mesh.face_normal(t).z > 0.99));

        // No index accessor: the vertices in order.
        let unindexed = document(&grid[..3], &[], 4, nodes, scenes);
        let (mesh, _) = import(&unindexed).unwrap();
        assert_eq!(mesh.triangles.len(), 1);
    }

    #[test]
    fn broken_scenes_are_clear_errors() {
        let nodes = r#"[{"mesh":0}]"#;
        let scenes = r#"[{"nodes":[0]}]"#;

        let points = document(&TETRAHEDRON, &[], 0, nodes, scenes);
        let message = import(&points).unwrap_err().to_string();
        assert!(message.contains("scene.gltf") && message.contains("points or lines"), "{message}");

        let out_of_range = document(&TETRAHEDRON, &[0, 1, 7], 4, nodes, scenes);
        let message = import(&out_of_range).unwrap_err().to_string();
        assert!(message.contains("index 7") && message.contains("\"tet\""), "{message}");

        let message = import(b"{ not json").unwrap_err().to_string();
        assert!(message.contains("scene.gltf") && message.contains("not valid glTF"), "{message}");

        // A buffer in a file next to the glTF cannot be found from bytes alone.
        let external = String::from_utf8(tetrahedron(nodes, scenes)).unwrap();
        let start = external.find("data:").unwrap();
        let end = start + external[start..].find('"').unwrap();
        let external = format!("{}tet.bin{}", &external[..start], &external[end..]);
        let message = import(external.as_bytes()).unwrap_err().to_string();
        assert!(message.contains("cannot read a buffer"), "{message}");
    }
}

mod arbitrary_input {
    //! Whatever the bytes, import returns a mesh that holds its invariants or an error: never a
    //! panic.

    use proptest::prelude::*;

    use super::*;

    fn number() -> impl Strategy<Value = String> {
        prop_oneof![
            (-3.0f32..3.0).prop_map(|x| x.to_string()),
            Just("nan".to_owned()),
            Just("inf".to_owned()),
            Just("1e39".to_owned()),
            Just("x".to_owned()),
        ]
    }

    fn corner() -> impl Strategy<Value = String> {
        (-12i64..12, proptest::option::of(-4i64..6), proptest::option::of(-4i64..6)).prop_map(|(v, t, n)| {
            match (t, n) {
                (None, None) => v.to_string(),
                (Some(t), None) => format!("{v}/{t}"),
                (t, Some(n)) => format!("{v}/{}/{n}", t.map(|t| t.to_string()).unwrap_or_default()),
            }
        })
    }

    fn line() -> impl Strategy<Value = String> {
        prop_oneof![
            4 => proptest::collection::vec(number(), 3).prop_map(|n| format!("v {}", n.join(" "))),
            1 => proptest::collection::vec(number(), 2).prop_map(|n| format!("vt {}", n.join(" "))),
            1 => proptest::collection::vec(number(), 3).prop_map(|n| format!("vn {}", n.join(" "))),
            4 => proptest::collection::vec(corner(), 0..6).prop_map(|c| format!("f {}", c.join(" "))),
            1 => Just("o part".to_owned()),
            1 => Just("l 1 2".to_owned()),
            1 => "[ -~]{0,12}",
        ]
    }

    fn check_invariants(mesh: &Mesh, report: &MeshReport) {
        let v = mesh.vertex_count() as u32;
        assert!(!mesh.triangles.is_empty());
        assert!(mesh.triangles.iter().flatten().all(|&i| i < v));
        assert!(mesh.positions.iter().all(|p| p.is_finite()));
        assert!(mesh.normals.iter().all(|n| (n.length() - 1.0).abs() < 1e-3), "unit normals");
        assert_eq!(mesh.edges.len(), report.edges);
        assert_eq!(mesh.edge_faces.len(), mesh.edges.len());
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]

        #[test]
        fn any_obj_text_imports_or_errors(lines in proptest::collection::vec(line(), 0..40)) {
            let text = lines.join("\n");
            if let Ok((mesh, report)) = Mesh::from_obj_str(&text, Path::new("fuzz.obj"), &ImportOptions::default()) {
                check_invariants(&mesh, &report);
            }
        }

        #[test]
        fn a_corrupted_glb_imports_or_errors(
            edits in proptest::collection::vec((0.0f64..1.0, any::<u8>(), any::<bool>()), 1..6),
        ) {
            let mut bytes = std::fs::read(asset("Fox.glb")).unwrap();
            // Half of the edits land in the JSON chunk (the first few kilobytes), where they do most harm.
            let json_end = 20 + u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
            for (at, value, in_json) in edits {
                let limit = if in_json { json_end } else { bytes.len() };
                let index = ((at * limit as f64) as usize).min(bytes.len() - 1);
                bytes[index] = value;
            }
            if let Ok((mesh, report)) = Mesh::from_gltf_slice(&bytes, Path::new("fox.glb"), &ImportOptions::default()) {
                check_invariants(&mesh, &report);
            }
        }

        #[test]
        fn any_bytes_as_gltf_error_cleanly(bytes in proptest::collection::vec(any::<u8>(), 0..200)) {
            let mut glb = b"glTF\x02\x00\x00\x00".to_vec();
            glb.extend(&bytes);
            for candidate in [&bytes, &glb] {
                let result = Mesh::from_gltf_slice(candidate, Path::new("fuzz.glb"), &ImportOptions::default());
                prop_assert!(result.is_err());
            }
        }
    }
}

#[test]
fn a_real_mesh_with_scrambled_winding_is_repaired_to_the_original() {
    let (original, _) = load(&asset("spot.obj"));
    let mut raw = pelt_core::mesh::RawMesh {
        positions: original.positions.clone(),
        triangles: original.triangles.clone(),
        ..Default::default()
    };
    // Flip every third triangle, and the first one too, so the seed of the walk is wrong.
    let mut flipped = 0;
    for (t, tri) in raw.triangles.iter_mut().enumerate() {
        if t % 3 == 0 {
            tri.swap(1, 2);
            flipped += 1;
        }
    }
    let (mesh, report) = Mesh::from_raw(raw, Path::new("scrambled spot"), &ImportOptions::default()).unwrap();
    assert_eq!(report.reoriented_triangles, flipped);
    assert!(report.is_closed_manifold(), "{report}");
    for (repaired, original) in mesh.triangles.iter().zip(&original.triangles) {
        let rotations = [*original, [original[1], original[2], original[0]], [original[2], original[0], original[1]]];
        assert!(rotations.contains(repaired), "{repaired:?} is wound like {original:?}");
    }
}

#[test]
fn obj_relative_indices_to_missing_elements_are_errors() {
    // tobj 4.0.5 overflows (and panics) on these; the importer must refuse them first.
    for (text, expected) in [
        ("v 0 0 0\nf -1/-2 -1 -1\n", "texture coordinate -2"),
        ("v 0 0 0\nvt 0 0\nf -1/-1/-3 -1 -1\n", "normal -3"),
        ("v 0 0 0\nf 1 -2 1\n", "vertex -2"),
        ("v 0 0 0\nf 0 1 1\n", "vertex 0"),
        ("v 0 0 0\nv 1 0 0\nf 1 2\n", "at least 3 corners"),
    ] {
        let err = Mesh::from_obj_str(text, Path::new("relative.obj"), &ImportOptions::default()).unwrap_err();
        let message = err.to_string();
        assert!(message.contains(expected) && message.starts_with("relative.obj:"), "{text:?}: {message}");
    }
    // Inline comments are not numbers.
    let text = "v 0 0 0 # origin\nv 1 0 0\nv 0 1 0\nf 1 2 3 # the only face\n";
    let (mesh, _) = Mesh::from_obj_str(text, Path::new("comments.obj"), &ImportOptions::default()).unwrap();
    assert_eq!(mesh.triangles.len(), 1);
}

/// Vertices shaded by a cache like lavapipe's (256 entries picked by index modulo 256, emptied
/// every 1,023 indices), written here apart from the importer's own cache model.
fn direct_mapped_cache_shading(mesh: &Mesh) -> usize {
    let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
    let mut shaded = 0;
    for segment in indices.chunks(1023) {
        let mut slots = [u32::MAX; 256];
        for &i in segment {
            if slots[i as usize % 256] != i {
                slots[i as usize % 256] = i;
                shaded += 1;
            }
        }
    }
    shaded
}

type Triangle = [u32; 3];
type CornerUvs = [[f32; 2]; 3];

#[test]
fn triangles_are_reordered_for_the_vertex_cache_and_nothing_else_changes() {
    for name in ["bunny.obj", "spot.obj"] {
        let (ordered, report) = load(&asset(name));
        let as_read = ImportOptions { vertex_cache_order: false, ..ImportOptions::default() };
        let (file_order, file_report) = Mesh::load(&asset(name), &as_read).unwrap();
        assert_eq!(report, file_report, "{name}: the report does not depend on the order");
        assert_eq!(ordered.positions, file_order.positions, "{name}: vertices keep their indices");
        assert_eq!(ordered.normals, file_order.normals, "{name}");
        assert_eq!(ordered.edges, file_order.edges, "{name}");
        // The same triangles with the same corners in the same turn, each with its own uvs.
        let corners = |mesh: &Mesh| {
            let mut all: Vec<(Triangle, Option<CornerUvs>)> = (0..mesh.triangles.len())
                .map(|t| (mesh.triangles[t], mesh.corner_uvs.as_ref().map(|uvs| uvs[t].map(|uv| uv.to_array()))))
                .collect();
            all.sort_by_key(|corner| corner.0);
            all
        };
        assert_eq!(corners(&ordered), corners(&file_order), "{name}");
        assert_ne!(ordered.triangles, file_order.triangles, "{name}: the order changed");
        let (before, after) = (direct_mapped_cache_shading(&file_order), direct_mapped_cache_shading(&ordered));
        let vertices = ordered.vertex_count();
        assert!(
            after as f64 <= 1.4 * vertices as f64 && (after as f64) < 0.7 * before as f64,
            "{name}: {before} vertex shadings in the file's order, {after} reordered ({vertices} vertices)"
        );
    }
}

#[test]
fn wedges_give_every_corner_its_vertex_and_uv_and_split_only_at_seams() {
    let (mesh, _) = load(&asset("spot.obj"));
    let corner_uvs = mesh.corner_uvs.as_ref().unwrap();
    let wedges = mesh.wedges().unwrap();
    assert_eq!(wedges.corners.len(), 3 * mesh.triangles.len());
    for (corner, &wedge) in wedges.corners.iter().enumerate() {
        let (triangle, k) = (corner / 3, corner % 3);
        assert_eq!(wedges.vertices[wedge as usize], mesh.triangles[triangle][k], "corner {corner}");
        assert_eq!(wedges.uvs[wedge as usize], corner_uvs[triangle][k], "corner {corner}");
    }
    // Distinct (vertex, uv) pairs, counted here another way: every wedge is one.
    let mut pairs: Vec<(u32, [u32; 2])> = mesh
        .triangles
        .iter()
        .zip(corner_uvs)
        .flat_map(|(t, uvs)| (0..3).map(move |k| (t[k], uvs[k].to_array().map(f32::to_bits))))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    assert_eq!(wedges.vertices.len(), pairs.len());
    // Spot's file has 3,225 distinct (v, vt) pairs over 2,930 vertices.
    assert_eq!(wedges.vertices.len(), 3_225);
    // Numbered by first use: the first corners' wedges count up from 0.
    assert_eq!(&wedges.corners[..3], &[0, 1, 2]);
    assert!(load(&asset("bunny.obj")).0.wedges().is_none(), "no uvs, no wedges");
}
