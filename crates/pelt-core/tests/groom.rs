//! Grooms: absent means today's fur to the bit; length, bald, direction and file round trips
//! checked against oracles written here; bad input is a clear error; the simulation keeps each
//! strand's own length.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec3};
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection, SeparatedStructure};
use pelt_core::groom::{Groom, GroomError, GroomMap, GroomParams, mesh_hash};
use pelt_core::mesh::{ImportOptions, Mesh};
use pelt_core::sim::{SimParams, Simulation, WindParams};
use pelt_core::{Builtin, Preset, PresetError};
use proptest::prelude::*;

/// A fresh folder under the target directory for files a test writes.
fn scratch(name: &str) -> PathBuf {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("groom").join(name);
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder).unwrap();
    folder
}

fn plane() -> Mesh {
    Builtin::Plane.mesh().0
}

fn params(layers: u32, length: f32, direction: GrowthDirection) -> FurParams {
    FurParams { layers, length: FurLength::Constant(length), direction }
}

fn straight() -> GrowthDirection {
    GrowthDirection::default()
}

fn bits(values: &[Vec3]) -> Vec<u32> {
    values.iter().flat_map(|v| v.to_array()).map(f32::to_bits).collect()
}

/// Writes a grey PNG of `width x height` whose texel `(x, y)` is `value(x, y)` (`0..=1`), 16-bit.
fn grey16(path: &Path, width: u32, height: u32, value: impl Fn(u32, u32) -> f32) {
    let image = image::ImageBuffer::from_fn(width, height, |x, y| {
        image::Luma([(value(x, y).clamp(0.0, 1.0) * 65535.0).round() as u16])
    });
    image.save(path).unwrap();
}

/// Writes an 8-bit RGB PNG filled with one colour.
fn rgb8(path: &Path, rgb: [u8; 3]) {
    image::RgbImage::from_pixel(4, 4, image::Rgb(rgb)).save(path).unwrap();
}

#[test]
fn no_groom_is_todays_structure_to_the_bit() {
    let fox = Preset::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/presets/fox.toml")).unwrap();
    for builtin in Builtin::ALL {
        let (mesh, _) = builtin.mesh();
        let direction = GrowthDirection { random_angle_rad: 0.3, seed: 9, comb: Vec3::NEG_Y, comb_blend: 0.4 };
        let p = params(16, 0.2, direction);
        let today = FurStructure::new(mesh.clone(), &p).unwrap();
        for groom in [None, Some(Groom::default())] {
            let groomed = FurStructure::new_groomed(mesh.clone(), &p, groom).unwrap();
            assert_eq!(bits(&groomed.positions), bits(&today.positions), "{builtin:?}");
            assert_eq!(bits(&groomed.directions), bits(&today.directions));
            assert_eq!(groomed.lengths, today.lengths);
            assert!(groomed.groom.is_none(), "an empty groom is no groom");
            assert_eq!(groomed.footprint(), today.footprint());
            assert_eq!(groomed.furred_triangles().len(), mesh.triangles.len());
            assert_eq!(groomed.fin_edges().len(), mesh.edges.len());
        }
        // A preset without a [groom] table grows the same through `Preset::grow`.
        let preset = Preset::default();
        let grown = preset.grow(mesh.clone(), "builtin").unwrap();
        let plain = FurStructure::new(mesh.clone(), &preset.fur_params(&mesh)).unwrap();
        assert_eq!(bits(&grown.positions), bits(&plain.positions));
        let separated = SeparatedStructure { layers: 16, fin_faces: 30 };
        assert_eq!(separated.footprint_of(&today), separated.footprint(&mesh));
    }
    assert!(fox.groom.is_empty());
    assert!(!fox.to_toml_string().unwrap().contains("groom"), "an empty [groom] is not written");
}

#[test]
fn a_length_groom_scales_each_strand_and_the_tips_height() {
    let mesh = plane();
    let v = mesh.vertex_count();
    let factors: Vec<f32> = (0..v).map(|j| [1.0, 0.5, 0.25, 2.0][j % 4]).collect();
    let groom = Groom { length: Some(factors.clone()), ..Groom::default() };
    let fur = FurStructure::new_groomed(mesh.clone(), &params(8, 0.3, straight()), Some(groom)).unwrap();
    // Measured on the simulation's rest state: tip minus root along the normal.
    let sim = Simulation::new(&fur, &SimParams::default()).unwrap();
    let rest = sim.positions();
    for j in 0..v {
        let height = (rest[8 * v + j] - rest[j]).dot(mesh.normals[j]);
        assert!((height - 0.3 * factors[j]).abs() < 1e-6, "vertex {j}: {height}");
        assert_eq!(fur.lengths[j], 0.3 * factors[j]);
    }
}

#[test]
fn a_16_bit_length_map_halves_the_fur_where_it_says_and_keeps_its_precision() {
    let folder = scratch("length16");
    // Left half 0.5, right half 1, and one column of a value 8 bits cannot hold.
    grey16(&folder.join("length.png"), 64, 64, |x, _| if x < 32 { 0.5 } else { 1.0 });
    grey16(&folder.join("fine.png"), 4, 4, |_, _| 1000.0 / 65535.0);
    let text = "length = 0.1\n[groom]\nlength = \"length.png\"\n";
    let preset = Preset::from_toml_str(text, folder.join("fur.toml")).unwrap();
    let mesh = plane();
    let radius = mesh.bounding_sphere().1;
    let fur = preset.grow(mesh.clone(), "plane").unwrap();
    let uvs = vertex_uvs(&mesh);
    let mut checked = 0;
    for (j, uv) in uvs.iter().enumerate() {
        let expected = if uv.x < 0.45 {
            0.5
        } else if uv.x > 0.55 {
            1.0
        } else {
            continue;
        };
        let factor = fur.lengths[j] / (0.1 * radius);
        assert!((factor - expected).abs() < 1e-4, "vertex {j} at {uv}: {factor}");
        checked += 1;
    }
    assert!(checked > mesh.vertex_count() / 2);

    let fine = "[groom]\nlength = \"fine.png\"\n";
    let preset = Preset::from_toml_str(fine, folder.join("fine.toml")).unwrap();
    let groom = preset.groom(&mesh, "plane").unwrap().unwrap();
    for &factor in groom.length.as_ref().unwrap() {
        // 8 bits would give 4/255 = 0.0157; 16 bits keep 1000/65535 = 0.01526.
        assert!((factor - 1000.0 / 65535.0).abs() < 1e-6, "{factor}");
    }
}

/// Each vertex's uv (the first corner that uses it).
fn vertex_uvs(mesh: &Mesh) -> Vec<Vec2> {
    let mut uvs = vec![Vec2::NAN; mesh.vertex_count()];
    for (triangle, corners) in mesh.triangles.iter().zip(mesh.corner_uvs.as_ref().unwrap()) {
        for (&j, uv) in triangle.iter().zip(corners) {
            if uvs[j as usize].is_nan() {
                uvs[j as usize] = *uv;
            }
        }
    }
    uvs
}

#[test]
fn bald_vertices_grow_nothing_and_bald_triangles_and_fins_are_dropped() {
    let mesh = plane();
    let v = mesh.vertex_count();
    // Bald where x < 0 (the plane spans -1..1).
    let bald: Vec<bool> = mesh.positions.iter().map(|p| p.x < -0.01).collect();
    let groom = Groom { length: Some(bald.iter().map(|&b| if b { 0.0 } else { 1.0 }).collect()), ..Groom::default() };
    let layers = 6;
    let fur = FurStructure::new_groomed(mesh.clone(), &params(layers, 0.2, straight()), Some(groom)).unwrap();
    let expected_triangles: Vec<u32> = (0..mesh.triangles.len() as u32)
        .filter(|&t| !mesh.triangles[t as usize].iter().all(|&j| bald[j as usize]))
        .collect();
    let expected_edges: Vec<u32> =
        (0..mesh.edges.len() as u32).filter(|&e| !mesh.edges[e as usize].iter().all(|&j| bald[j as usize])).collect();
    assert_eq!(fur.furred_triangles(), expected_triangles);
    assert_eq!(fur.fin_edges(), expected_edges);
    assert!(expected_triangles.len() < mesh.triangles.len() * 3 / 4, "a good part is bald");
    assert!(!expected_triangles.is_empty());
    for j in (0..v).filter(|&j| bald[j]) {
        for i in 0..=layers as usize {
            assert_eq!(fur.positions[i * v + j], mesh.positions[j], "a bald column stays at its root");
        }
    }
    let footprint = fur.footprint();
    let l = u64::from(layers);
    assert_eq!(footprint.shell_faces, expected_triangles.len() as u64 * l);
    assert_eq!(footprint.fin_faces, 2 * l * expected_edges.len() as u64);
    assert_eq!(footprint.faces, footprint.shell_faces + footprint.fin_faces);
    assert_eq!(footprint.vertices, v as u64 * (l + 1), "the shared array keeps every column");
    // The separated baseline draws the same fur.
    let separated = SeparatedStructure { layers, fin_faces: 30 }.footprint_of(&fur);
    assert_eq!(separated.shell_faces, footprint.shell_faces);
    assert_eq!(separated.fin_faces, 30 * expected_edges.len() as u64);
    assert!(separated.vertices < SeparatedStructure { layers, fin_faces: 30 }.footprint(&mesh).vertices);
}

/// The growing vector a comb of unit surface direction `along` with blend `blend` gives on a
/// surface of normal `normal` (no random tilt): written from the definition, not from Pelt.
fn combed(normal: Vec3, along: Vec3, blend: f32) -> Vec3 {
    let b = blend * 0.95;
    (normal * (1.0 - b) + along * b).normalize()
}

fn angle_deg(a: Vec3, b: Vec3) -> f32 {
    // atan2 of sine and cosine stays accurate near 0, where acos of a rounded cosine does not.
    let (a, b) = (a.normalize(), b.normalize());
    a.cross(b).length().atan2(a.dot(b)).to_degrees()
}

#[test]
fn a_direction_map_combs_the_fur_along_its_flow() {
    let folder = scratch("direction");
    // The plane lies in y = 0 facing +Y; u grows along +X, v along +Z (the built-in's layout),
    // so the image's right is +X and its top (where v shrinks) is -Z.
    let cases: [([u8; 3], Vec3, f32); 4] = [
        ([255, 128, 0], Vec3::X, 1.0),
        ([0, 128, 0], Vec3::NEG_X, 1.0),
        ([128, 255, 0], Vec3::NEG_Z, 1.0),
        ([128, 64, 0], Vec3::Z, 1.0 - 64.0 / 255.0 * 2.0),
    ];
    let mesh = plane();
    for (k, (rgb, along, strength)) in cases.into_iter().enumerate() {
        rgb8(&folder.join(format!("flow{k}.png")), rgb);
        let text = format!(
            "[direction]\nrandom_angle_deg = 0\ncomb = [0, 0, 1]\ncomb_blend = 0.8\n[groom]\ndirection = \"flow{k}.png\"\n"
        );
        let preset = Preset::from_toml_str(&text, folder.join("fur.toml")).unwrap();
        let fur = preset.grow(mesh.clone(), "plane").unwrap();
        let expected = combed(Vec3::Y, along, 0.8 * strength.abs().min(1.0));
        for (j, direction) in fur.directions.iter().enumerate() {
            assert!(angle_deg(*direction, expected) < 0.05, "{rgb:?} vertex {j}: {direction} vs {expected}");
        }
    }
    // Green-down maps flip the flow's y.
    let text = "[direction]\nrandom_angle_deg = 0\ncomb_blend = 0.8\n[groom]\ndirection = \"flow2.png\"\ndirection_green_down = true\n";
    let fur = Preset::from_toml_str(text, folder.join("fur.toml")).unwrap().grow(mesh.clone(), "plane").unwrap();
    assert!(angle_deg(fur.directions[0], combed(Vec3::Y, Vec3::Z, 0.8)) < 0.05);
    // A flow of zero (128, 128) leaves the fur along the normal.
    rgb8(&folder.join("still.png"), [128, 128, 0]);
    let text = "[direction]\nrandom_angle_deg = 0\ncomb_blend = 0.8\n[groom]\ndirection = \"still.png\"\n";
    let fur = Preset::from_toml_str(text, folder.join("fur.toml")).unwrap().grow(mesh.clone(), "plane").unwrap();
    assert!(fur.directions.iter().all(|d| angle_deg(*d, Vec3::Y) < 1e-3));
}

#[test]
fn without_uvs_the_flow_uses_the_stable_frame() {
    let mut mesh = plane();
    mesh.corner_uvs = None;
    let v = mesh.vertex_count();
    // On a surface facing +Y, up is world -Z and the tangent up x normal = +X.
    let groom = Groom { direction: Some(vec![Vec2::new(0.0, 1.0); v]), ..Groom::default() };
    let direction = GrowthDirection { comb_blend: 0.5, ..straight() };
    let fur = FurStructure::new_groomed(mesh.clone(), &params(4, 0.1, direction), Some(groom)).unwrap();
    assert!(fur.directions.iter().all(|d| angle_deg(*d, combed(Vec3::Y, Vec3::NEG_Z, 0.5)) < 0.05));
    // On a sphere (no uvs) the frame's up is world +Y along the surface away from the poles.
    let (mut sphere, _) = Builtin::Sphere.mesh();
    sphere.corner_uvs = None;
    let frames = pelt_core::groom::tangent_frames(&sphere);
    for (frame, n) in frames.iter().zip(&sphere.normals) {
        assert!(frame.up.dot(*n).abs() < 1e-5 && frame.tangent.dot(*n).abs() < 1e-5);
        assert!(frame.tangent.cross(frame.up).dot(*n) > 0.999, "right-handed without uvs");
        if n.y.abs() < 0.9 {
            let up_along_surface = (Vec3::Y - *n * n.y).normalize();
            assert!(angle_deg(frame.up, up_along_surface) < 0.01, "{n} {frame:?} {up_along_surface}");
        }
    }
    // Images need uvs, and the error says so.
    let folder = scratch("no_uvs");
    rgb8(&folder.join("flow.png"), [255, 128, 0]);
    let preset = Preset::from_toml_str("[groom]\nlength = \"flow.png\"\n", folder.join("fur.toml")).unwrap();
    let message = preset.groom(&mesh, "flat.obj").unwrap_err().to_string();
    assert!(message.contains("flow.png") && message.contains("flat.obj") && message.contains("no UVs"), "{message}");
    assert!(message.contains("groom.length") && message.contains("fur.toml"), "{message}");
}

fn sample_groom(v: usize) -> Groom {
    Groom {
        length: Some((0..v).map(|j| (j % 7) as f32 / 3.0).collect()),
        density: Some((0..v).map(|j| (j % 5) as f32 / 4.0).collect()),
        direction: Some((0..v).map(|j| Vec2::new(((j % 3) as f32 - 1.0) * 0.7, 0.3)).collect()),
        clump: None,
        tint: Some((0..v).map(|j| Vec3::new(0.1, (j % 2) as f32, 0.5)).collect()),
    }
}

#[test]
fn a_groom_file_round_trips_to_the_same_bytes() {
    let folder = scratch("file");
    let (mesh, _) = Builtin::Torus.mesh();
    let groom = sample_groom(mesh.vertex_count());
    let file = folder.join("torus.groom");
    groom.save(&file, &mesh).unwrap();
    let first = std::fs::read(&file).unwrap();
    let loaded = Groom::load(&file, &mesh, "torus").unwrap();
    assert_eq!(loaded, groom);
    loaded.save(&file, &mesh).unwrap();
    assert_eq!(std::fs::read(&file).unwrap(), first, "saving the loaded groom gives the same bytes");
    // The header, read independently.
    assert_eq!(&first[..8], b"PELTGROM");
    assert_eq!(u32::from_le_bytes(first[8..12].try_into().unwrap()), 1);
    assert_eq!(u32::from_le_bytes(first[12..16].try_into().unwrap()) as usize, mesh.vertex_count());
    assert_eq!(u32::from_le_bytes(first[24..28].try_into().unwrap()), 0b10111);
    assert_eq!(first.len(), 28 + 4 * mesh.vertex_count() * (1 + 1 + 2 + 3) + 8);
    // Only the file itself is left in the folder (no temporaries).
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 1);
    // Through a preset, with a map of its own replacing the file's.
    std::fs::write(folder.join("fur.toml"), "[groom]\nfile = \"torus.groom\"\n").unwrap();
    let preset = Preset::load(folder.join("fur.toml")).unwrap();
    assert_eq!(preset.groom(&mesh, "torus").unwrap(), Some(groom));
}

#[test]
fn a_groom_for_another_mesh_is_an_error_naming_both() {
    let folder = scratch("wrong_mesh");
    let (torus, _) = Builtin::Torus.mesh();
    let (sphere, _) = Builtin::Sphere.mesh();
    let file = folder.join("torus.groom");
    sample_groom(torus.vertex_count()).save(&file, &torus).unwrap();
    let error = Groom::load(&file, &sphere, "sphere.glb").unwrap_err();
    let message = error.to_string();
    assert!(matches!(error, GroomError::WrongMesh { .. }), "{message}");
    assert!(message.contains("torus.groom") && message.contains("sphere.glb"), "{message}");
    assert!(
        message.contains(&torus.vertex_count().to_string()) && message.contains(&sphere.vertex_count().to_string())
    );
    // Same vertex count, moved positions: the hash tells them apart.
    let mut moved = torus.clone();
    moved.positions[3].x += 1e-3;
    assert_ne!(mesh_hash(&moved), mesh_hash(&torus));
    assert!(matches!(Groom::load(&file, &moved, "moved").unwrap_err(), GroomError::WrongMesh { .. }));
}

/// 64-bit FNV-1a, written here from its definition for crafting files.
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3))
}

#[test]
fn damaged_groom_files_are_clear_errors() {
    let folder = scratch("damaged");
    let (mesh, _) = Builtin::Box.mesh();
    let groom = Groom { length: Some(vec![0.5; mesh.vertex_count()]), ..Groom::default() };
    let good = groom.to_file_bytes(&mesh).unwrap();
    let write = |name: &str, bytes: &[u8]| {
        let path = folder.join(name);
        std::fs::write(&path, bytes).unwrap();
        path
    };
    let reseal = |mut body: Vec<u8>| {
        let n = body.len() - 8;
        let sum = fnv1a(&body[..n]);
        body[n..].copy_from_slice(&sum.to_le_bytes());
        body
    };
    let mut nan = good.clone();
    nan[28 + 4 * 5..28 + 4 * 6].copy_from_slice(&f32::NAN.to_le_bytes());
    let mut version = good.clone();
    version[8] = 9;
    let mut negative = good.clone();
    negative[28..32].copy_from_slice(&(-1.0f32).to_le_bytes());
    let cases: Vec<(&str, Vec<u8>, &str)> = vec![
        ("truncated.groom", good[..good.len() - 5].to_vec(), "checksum"),
        ("empty.groom", Vec::new(), "PELTGROM"),
        ("nan.groom", reseal(nan), "vertex 5"),
        ("version.groom", reseal(version), "version 9"),
        ("negative.groom", reseal(negative), "outside"),
    ];
    for (name, bytes, says) in cases {
        let path = write(name, &bytes);
        let message = Groom::load(&path, &mesh, "box").unwrap_err().to_string();
        assert!(message.contains(name) && message.contains(says), "{name}: {message}");
    }
    let message = Groom::load(&folder.join("missing.groom"), &mesh, "box").unwrap_err().to_string();
    assert!(message.contains("missing.groom"), "{message}");
    // A failed write leaves no partial file and an existing file as it was.
    let target = write("kept.groom", &good);
    let bad = Groom { length: Some(vec![f32::NAN; mesh.vertex_count()]), ..Groom::default() };
    assert!(bad.save(&target, &mesh).is_err());
    assert!(groom.save(&folder.join("no_such_folder/x.groom"), &mesh).is_err());
    assert_eq!(std::fs::read(&target).unwrap(), good);
    let names: Vec<String> =
        std::fs::read_dir(&folder).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert!(names.iter().all(|n| !n.contains(".tmp")), "{names:?}");
}

#[test]
fn bad_preset_sources_are_clear_errors() {
    let folder = scratch("bad_sources");
    let mesh = plane();
    grey16(&folder.join("grey.png"), 4, 4, |_, _| 0.5);
    image::RgbaImage::from_pixel(2, 2, image::Rgba([1, 2, 3, 4])).save(folder.join("pattern.gif")).unwrap();
    std::fs::write(folder.join("text.png"), "not an image").unwrap();
    let cases = [
        ("direction = \"grey.png\"", "red and green"),
        ("length = \"pattern.gif\"", "not a PNG"),
        ("length = \"text.png\"", "PNG"),
        ("tint = \"COLOR_0\"", "no vertex colour set COLOR_0"),
    ];
    for (line, says) in cases {
        let preset = Preset::from_toml_str(&format!("[groom]\n{line}\n"), folder.join("fur.toml")).unwrap();
        let error = preset.groom(&mesh, "plane.glb").unwrap_err();
        let message = error.to_string();
        assert!(matches!(error, PresetError::Groom { .. }), "{message}");
        assert!(message.contains(says) && message.contains("fur.toml"), "{line}: {message}");
        let key = line.split(' ').next().unwrap();
        assert!(message.contains(&format!("groom.{key}")), "{message}");
    }
    // A missing image or groom file is found when the preset loads, naming the key.
    for line in ["length = \"nowhere.png\"", "file = \"nowhere.groom\""] {
        std::fs::write(folder.join("missing.toml"), format!("[groom]\n{line}\n")).unwrap();
        let message = Preset::load(folder.join("missing.toml")).unwrap_err().to_string();
        let key = line.split(' ').next().unwrap();
        assert!(message.contains("nowhere") && message.contains(&format!("groom.{key}")), "{message}");
    }
    // Unknown keys are refused like everywhere else in a preset.
    assert!(Preset::from_toml_str("[groom]\nlenght = \"x.png\"\n", "typo.toml").is_err());
    // A groom of the wrong size is an error from the structure, not a panic.
    let short = Groom { clump: Some(vec![0.5; 3]), ..Groom::default() };
    assert!(FurStructure::new_groomed(mesh, &params(4, 0.1, straight()), Some(short)).is_err());
}

#[test]
fn the_groom_table_round_trips_through_toml() {
    let mut preset = Preset::default();
    preset.groom = GroomParams {
        file: Some("fox.groom".into()),
        length: Some("fox_length.png".into()),
        tint: Some("COLOR_1".into()),
        direction_green_down: true,
        ..GroomParams::default()
    };
    let text = preset.to_toml_string().unwrap();
    assert!(text.contains("[groom]") && text.contains("fox_length.png"), "{text}");
    assert_eq!(Preset::from_toml_str(&text, "memory.toml").unwrap(), preset);
}

fn base64(bytes: &[u8]) -> String {
    const ALPHABET: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for chunk in bytes.chunks(3) {
        let n = chunk.iter().enumerate().fold(0u32, |n, (k, &b)| n | u32::from(b) << (16 - 8 * k));
        for k in 0..4 {
            out.push(if k <= chunk.len() { ALPHABET[(n >> (18 - 6 * k) & 63) as usize] as char } else { '=' });
        }
    }
    out
}

/// A glTF of one tetrahedron written as 4 unshared triangles (12 vertices the import welds to 4),
/// with COLOR_0 (float RGBA) given per corner.
fn coloured_tetrahedron(colour: impl Fn(usize, [f32; 3]) -> [f32; 4]) -> Vec<u8> {
    const CORNERS: [[f32; 3]; 4] = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]];
    const TRIANGLES: [[usize; 3]; 4] = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let positions: Vec<[f32; 3]> = TRIANGLES.iter().flatten().map(|&i| CORNERS[i]).collect();
    let colours: Vec<[f32; 4]> = positions.iter().enumerate().map(|(k, p)| colour(k, *p)).collect();
    let mut bytes: Vec<u8> = positions.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let colour_offset = bytes.len();
    bytes.extend(colours.iter().flatten().flat_map(|v| v.to_le_bytes()));
    let data = base64(&bytes);
    format!(
        r#"{{"asset":{{"version":"2.0"}},
"buffers":[{{"byteLength":{len},"uri":"data:application/octet-stream;base64,{data}"}}],
"bufferViews":[{{"buffer":0,"byteLength":{colour_offset}}},{{"buffer":0,"byteOffset":{colour_offset},"byteLength":{colour_len}}}],
"accessors":[{{"bufferView":0,"componentType":5126,"count":12,"type":"VEC3","min":[0,0,0],"max":[1,1,1]}},
{{"bufferView":1,"componentType":5126,"count":12,"type":"VEC4"}}],
"meshes":[{{"primitives":[{{"attributes":{{"POSITION":0,"COLOR_0":1}}}}]}}],
"nodes":[{{"mesh":0}}],"scenes":[{{"nodes":[0]}}],"scene":0}}"#,
        len = bytes.len(),
        colour_len = bytes.len() - colour_offset,
    )
    .into_bytes()
}

#[test]
fn a_glb_vertex_colour_set_is_a_groom_source() {
    // Each corner's red is 0.2 + its x; green differs per corner (its index), so welding means it.
    let gltf = coloured_tetrahedron(|k, p| [0.2 + 0.5 * p[0], k as f32 / 11.0, 0.0, 1.0]);
    let name = Path::new("tet.gltf");
    let mesh = match Mesh::from_gltf_slice(&gltf, name, &ImportOptions::default()) {
        Ok((mesh, _)) => mesh,
        Err(e) => panic!("{e}"),
    };
    assert_eq!(mesh.vertex_count(), 4);
    let colours = mesh.colour_set(0).expect("COLOR_0 is kept");
    assert!(mesh.colour_set(1).is_none());
    for (p, c) in mesh.positions.iter().zip(colours) {
        assert!((c.x - (0.2 + 0.5 * p.x)).abs() < 1e-6);
        assert!(c.y > 0.0 && c.y < 1.0, "the mean of the corners welded together");
    }
    let preset = Preset::from_toml_str("[groom]\nlength = \"COLOR_0\"\n", "fur.toml").unwrap();
    let groom = preset.groom(&mesh, "tet.gltf").unwrap().unwrap();
    let expected: Vec<f32> = mesh.positions.iter().map(|p| 0.2 + 0.5 * p.x).collect();
    for (got, want) in groom.length.unwrap().iter().zip(&expected) {
        assert!((got - want).abs() < 1e-6);
    }
    let message = Preset::from_toml_str("[groom]\nclump = \"COLOR_3\"\n", "fur.toml")
        .unwrap()
        .groom(&mesh, "tet.gltf")
        .unwrap_err()
        .to_string();
    assert!(message.contains("COLOR_3") && message.contains("it has COLOR_0") && message.contains("tet.gltf"));
}

#[test]
fn the_simulation_keeps_each_strands_own_length_under_a_groom() {
    let (mesh, _) = Builtin::Sphere.mesh();
    let v = mesh.vertex_count();
    let groom = Groom {
        length: Some((0..v).map(|j| [0.0, 0.3, 1.0, 1.7, 0.05][j % 5]).collect()),
        direction: Some((0..v).map(|j| Vec2::new((j as f32 * 0.37).sin(), (j as f32 * 0.11).cos())).collect()),
        ..Groom::default()
    };
    let direction = GrowthDirection { random_angle_rad: 0.3, seed: 3, comb: Vec3::NEG_Y, comb_blend: 0.6 };
    let layers = 12;
    let fur = FurStructure::new_groomed(mesh, &params(layers, 0.3, direction), Some(groom)).unwrap();
    let wind = WindParams { strength: 2.0, direction: Vec3::new(1.0, 0.3, -0.4), ..WindParams::default() };
    let mut sim = Simulation::new(&fur, &SimParams { wind, ..SimParams::default() }).unwrap();
    sim.advance_to(1.5);
    let now = sim.positions();
    assert_eq!(&now[..v], &fur.positions[..v], "roots never move");
    let l = layers as usize;
    let mut moved = 0;
    for j in 0..v {
        let strand_rest: f32 = (0..l).map(|k| fur.positions[(k + 1) * v + j].distance(fur.positions[k * v + j])).sum();
        assert!((strand_rest - fur.lengths[j]).abs() <= 1e-5 * fur.lengths[j].max(1e-3), "vertex {j}");
        for k in 0..l {
            let rest = fur.positions[(k + 1) * v + j].distance(fur.positions[k * v + j]);
            let got = now[(k + 1) * v + j].distance(now[k * v + j]);
            assert!(now[(k + 1) * v + j].is_finite());
            // Relative to the segment, plus the rounding of the positions it is measured between.
            let rounding = 4.0 * f32::EPSILON * now[j].length();
            assert!((got - rest).abs() <= 1e-5 * rest + rounding, "vertex {j} segment {k}: {got} vs {rest}");
        }
        if fur.lengths[j] == 0.0 {
            assert!((0..=l).all(|i| now[i * v + j] == now[j]), "a bald strand stays at its root");
        } else if now[l * v + j].distance(fur.positions[l * v + j]) > 1e-4 * fur.lengths[j] {
            moved += 1;
        }
    }
    assert!(moved > v / 2, "gravity and wind bend the groomed strands ({moved} of {v})");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(24))]
    #[test]
    fn finite_grooms_grow_finite_fur(
        which in 0usize..5,
        seed in any::<u64>(),
        comb_blend in 0.0f32..=1.0,
        lengths in proptest::collection::vec(0.0f32..=16.0, 1..50),
        flows in proptest::collection::vec((-1.0f32..=1.0, -1.0f32..=1.0), 1..50),
    ) {
        let (mesh, _) = Builtin::ALL[which].mesh();
        let v = mesh.vertex_count();
        let groom = Groom {
            length: Some((0..v).map(|j| lengths[j % lengths.len()]).collect()),
            direction: Some((0..v).map(|j| Vec2::from(flows[j % flows.len()])).collect()),
            ..Groom::default()
        };
        let direction = GrowthDirection { random_angle_rad: 0.5, seed, comb: Vec3::X, comb_blend };
        let fur = FurStructure::new_groomed(mesh, &params(8, 0.2, direction), Some(groom)).unwrap();
        prop_assert!(fur.positions.iter().all(|p| p.is_finite()));
        for (d, n) in fur.directions.iter().zip(&fur.mesh.normals) {
            prop_assert!((d.length() - 1.0).abs() < 1e-4);
            prop_assert!(d.dot(*n) > 0.0, "fur grows outward");
        }
    }
}

#[test]
fn groom_maps_know_their_keys_and_sizes() {
    let groom = sample_groom(10);
    assert_eq!(groom.bytes(), 10 * 4 * (1 + 1 + 2 + 3));
    assert!(groom.has(GroomMap::Tint) && !groom.has(GroomMap::Clump));
    assert!(Groom::default().is_uniform());
    assert!(groom.validate(11, "x").is_err());
}

#[test]
fn the_groomed_fox_is_bald_at_the_nose_and_long_on_the_tail() {
    let assets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets");
    let preset = Preset::load(assets.join("presets/fox_groomed.toml")).unwrap();
    let uniform = Preset::load(assets.join("presets/fox.toml")).unwrap();
    let (mesh, _) = Mesh::load(&assets.join("meshes/Fox.glb"), &ImportOptions::default()).unwrap();
    let radius = mesh.bounding_sphere().1;
    let fur = preset.grow(mesh.clone(), "Fox.glb").unwrap();
    let nose = (0..mesh.vertex_count()).max_by(|&a, &b| mesh.positions[a].z.total_cmp(&mesh.positions[b].z)).unwrap();
    let tail = (0..mesh.vertex_count()).min_by(|&a, &b| mesh.positions[a].z.total_cmp(&mesh.positions[b].z)).unwrap();
    assert_eq!(fur.lengths[nose], 0.0, "the nose tip is bald");
    assert!(fur.groom.as_ref().unwrap().length.as_ref().unwrap().iter().filter(|f| **f == 0.0).count() >= 4);
    // The body keeps fox.toml's length; the tail tip grows about twice that.
    let body_length = uniform.length * radius;
    let middle =
        (0..mesh.vertex_count()).min_by(|&a, &b| mesh.positions[a].z.abs().total_cmp(&mesh.positions[b].z.abs()));
    assert!((fur.lengths[middle.unwrap()] / body_length - 1.0).abs() < 0.02);
    assert!(fur.lengths[tail] > 1.9 * body_length, "{} vs {body_length}", fur.lengths[tail]);
    // The nose is a bald patch: its triangles draw no shells.
    assert!(fur.furred_triangles().len() < fur.mesh.triangles.len());
    assert!(fur.footprint().faces < uniform.grow(mesh, "Fox.glb").unwrap().footprint().faces);
}

/// A flow map (direction) from a float vertex colour set with a NaN in it, and an image larger
/// than any map may be: each a clear error naming the key and the file, never a panic.
#[test]
fn a_nan_in_a_flow_map_and_an_oversized_image_are_clear_errors() {
    let gltf = coloured_tetrahedron(|k, _| if k < 3 { [f32::NAN, 0.5, 0.0, 1.0] } else { [0.5, 0.5, 0.0, 1.0] });
    let name = Path::new("nan.gltf");
    let preset = Preset::from_toml_str("[groom]\ndirection = \"COLOR_0\"\n", "fur.toml").unwrap();
    match Mesh::from_gltf_slice(&gltf, name, &ImportOptions::default()) {
        // The import may refuse the NaN itself, naming the file.
        Err(error) => assert!(error.to_string().contains("nan.gltf"), "{error}"),
        Ok((mesh, _)) => {
            let message = preset.groom(&mesh, "nan.gltf").unwrap_err().to_string();
            assert!(
                message.contains("groom.direction") && message.contains("nan.gltf") && message.contains("finite"),
                "{message}"
            );
        }
    }

    let folder = scratch("oversized");
    // One texel wide, one texel too tall: cheap to write, refused before it is decoded whole.
    image::GrayImage::new(1, 16_385).save(folder.join("tall.png")).unwrap();
    let preset = Preset::from_toml_str("[groom]\ndensity = \"tall.png\"\n", folder.join("fur.toml")).unwrap();
    let message = preset.groom(&plane(), "plane.glb").unwrap_err().to_string();
    assert!(
        message.contains("groom.density") && message.contains("tall.png") && message.contains("16385"),
        "{message}"
    );
}
