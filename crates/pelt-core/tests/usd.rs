//! USD hair: the USDA grammar read back as written, the groomed Fox's strands exported and baked
//! back into its groom, a groom written by Pixar's own library in Z-up centimetres landing on a
//! Y-up metre mesh, and bad files as clear errors naming them.

use std::path::{Path, PathBuf};

use glam::Vec3;
use pelt_core::export::{StrandBasis, StrandExportInput, StrandFrame, write_strands_usda};
use pelt_core::groom::{Groom, GroomParams};
use pelt_core::mesh::{ImportOptions, Mesh};
use pelt_core::reference::{StrandReference, TileMapping};
use pelt_core::usd::{CurveBasis, CurveType, CurveWrap, UpAxis, read_curves, read_curves_from};
use pelt_core::{FurStructure, Preset};

fn assets() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets")
}

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures").join(name)
}

/// A fresh folder under the target directory for files a test writes.
fn scratch(name: &str) -> PathBuf {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("usd").join(name);
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder).unwrap();
    folder
}

/// Exports `fur`'s strands at its rest pose to `path` (linear or Catmull-Rom).
fn export_rest(preset: &Preset, fur: &FurStructure, path: &Path, basis: StrandBasis) -> StrandReference {
    let reference =
        StrandReference::new(fur, preset.strand_field().unwrap(), TileMapping::standard(&fur.mesh)).unwrap();
    let frames = [StrandFrame { time_code: None, positions: fur.positions.clone(), normals: fur.mesh.normals.clone() }];
    let input = StrandExportInput {
        fur,
        reference: &reference,
        frames: &frames,
        fraction: 1.0,
        basis,
        meters_per_unit: 1.0,
        frames_per_second: 24.0,
        doc: "test".to_owned(),
    };
    write_strands_usda(path, &input).unwrap();
    reference
}

/// A preset like `preset` whose groom is the strand file `strands` alone.
fn with_strands(preset: &Preset, strands: &Path) -> Preset {
    let mut baked = preset.clone();
    baked.groom = GroomParams { strands: Some(strands.to_path_buf()), ..GroomParams::default() };
    baked
}

fn angle_deg(a: Vec3, b: Vec3) -> f32 {
    a.normalize().dot(b.normalize()).clamp(-1.0, 1.0).acos().to_degrees()
}

/// How a baked groom compares with the painted one over the furred vertices.
struct RoundTrip {
    lengths: Vec<f32>,
    angles: Vec<f32>,
    bald_grown: Vec<(usize, f32)>,
    report: String,
}

impl RoundTrip {
    /// Every furred vertex's length within 5% and direction within 10 degrees; bald stays bald.
    fn assert_within_the_bar(&self, name: &str) {
        assert!(self.bald_grown.is_empty(), "{name}: bald vertices grew fur: {:?}", self.bald_grown);
        let worst_length = Self::quantile(&self.lengths, 1.0);
        let worst_angle = Self::quantile(&self.angles, 1.0);
        assert!(worst_length <= 0.05, "{name}: a furred vertex's length is off by {worst_length}");
        assert!(worst_angle <= 10.0, "{name}: a furred vertex's direction is off by {worst_angle} degrees");
    }

    fn quantile(values: &[f32], q: f32) -> f32 {
        let mut sorted = values.to_vec();
        sorted.sort_by(f32::total_cmp);
        sorted[((sorted.len() - 1) as f32 * q).round() as usize]
    }
}

/// Exports `preset`'s fur on the Fox at rest, bakes it back and compares; `foreign`: with the
/// texture offsets renamed to a primvar Pelt does not read.
fn round_trip(preset: &Preset, basis: StrandBasis, name: &str, foreign: bool) -> RoundTrip {
    let (mesh, _) = Mesh::load(&assets().join("meshes/Fox.glb"), &ImportOptions::default()).unwrap();
    let fur = preset.grow(mesh.clone(), "Fox.glb").unwrap();
    let path = scratch(name).join("fox.usda");
    export_rest(preset, &fur, &path, basis);
    let text = std::fs::read_to_string(&path).unwrap();
    assert_eq!(text.matches("vector3f[] primvars:pelt:textureOffset = [").count(), 1, "no texture offsets written");
    if foreign {
        std::fs::write(&path, text.replace("primvars:pelt:textureOffset", "primvars:other:textureOffset")).unwrap();
    }
    let baked_preset = with_strands(preset, &path);
    let (groom, report) = baked_preset.groom_with_report(&mesh, "Fox.glb").unwrap();
    let (groom, report) = (groom.unwrap(), report.unwrap());
    assert_eq!(report.off_surface, 0, "{report}");
    assert_eq!(report.curves, report.on_surface, "{report}");
    let painted: &Groom = fur.groom.as_ref().unwrap();
    let regrown = baked_preset.grow(mesh.clone(), "Fox.glb").unwrap();
    let mut result =
        RoundTrip { lengths: Vec::new(), angles: Vec::new(), bald_grown: Vec::new(), report: report.to_string() };
    for j in 0..mesh.vertex_count() {
        let (want, got) = (painted.length_factor(j), groom.length_factor(j));
        if want == 0.0 {
            if got != 0.0 {
                result.bald_grown.push((j, got));
            }
            continue;
        }
        result.lengths.push((got / want - 1.0).abs());
        result.angles.push(angle_deg(fur.directions[j], regrown.directions[j]));
    }
    eprintln!(
        "{name} {basis:?}: {report}\n  length error median {:.4}, 95% {:.4}, max {:.4}; direction median {:.2}, 95% {:.2}, max {:.2} degrees",
        RoundTrip::quantile(&result.lengths, 0.5),
        RoundTrip::quantile(&result.lengths, 0.95),
        RoundTrip::quantile(&result.lengths, 1.0),
        RoundTrip::quantile(&result.angles, 0.5),
        RoundTrip::quantile(&result.angles, 0.95),
        RoundTrip::quantile(&result.angles, 1.0),
    );
    result
}

/// The groomed Fox as shipped (its texture clumps, leans and curls its strands), exported and
/// baked back as its groom: every furred vertex's length within 5% and growth direction within
/// 10 degrees, bald vertices bald, for linear and Catmull-Rom curves. The texture's lean would
/// otherwise be baked into the groom and added again when the preset grows it (worst vertex 16%
/// and 18 degrees off); the export's texture offsets let the bake take it off.
#[test]
fn the_groomed_fox_round_trips_through_usd_curves() {
    let preset = Preset::load(assets().join("presets/fox_groomed.toml")).unwrap();
    assert!(preset.texture.clump >= 0.2 && preset.texture.lean > 0.0, "the shipped Fox's texture clumps and leans");
    for basis in [StrandBasis::Linear, StrandBasis::CatmullRom] {
        let trip = round_trip(&preset, basis, &format!("round_trip_{basis:?}"), false);
        trip.assert_within_the_bar(&format!("{basis:?}"));
    }
}

/// Curves without Pelt's texture offsets (as Blender or another tool writes them: here the
/// primvar renamed out of Pelt's namespace) bake from their geometry alone: with the texture's
/// clumping off the strands follow their columns but for the texture's lean, and the round trip
/// meets the same bar.
#[test]
fn curves_without_texture_offsets_bake_from_their_geometry() {
    let mut preset = Preset::load(assets().join("presets/fox_groomed.toml")).unwrap();
    preset.texture.clump = 0.0;
    let trip = round_trip(&preset, StrandBasis::Linear, "round_trip_foreign", true);
    assert!(!trip.report.contains("textureOffset"), "{}", trip.report);
    trip.assert_within_the_bar("foreign");
}

/// The grammar: a layer using what the reader takes (metadata with list ops and dictionaries, doc
/// strings, nested prims with transforms, time samples, relationships, variant sets, comments,
/// every curve basis) gives the curves an independent reading of the text says.
#[test]
fn the_usda_grammar_reads_curves_and_their_transforms() {
    let text = r#"#usda 1.0
(
    """A doc string
    over two lines"""
    customLayerData = {
        string creator = "hand { written }"
        dictionary nested = { int answer = 42 }
    }
    defaultPrim = "Root"
    metersPerUnit = 0.01
    upAxis = "Z"
    subLayers = [@./other.usda@, @@@odd@name.usda@@@]
)

# A comment line, and prims of every specifier.
class "Template" {}
def Xform "Root" (
    kind = "component"
    prepend apiSchemas = ["MaterialBindingAPI"]
)
{
    double3 xformOp:translate = (10, 0, 0)
    float xformOp:rotateZ.timeSamples = { 5: 0, 1: 90, }
    uniform token[] xformOpOrder = ["xformOp:translate", "xformOp:rotateZ"]
    rel material:binding = </Root/Looks/Fur>
    variantSet "lod" = {
        "high" { def Mesh "Hidden" {} }
    }

    def Xform "Scaled"
    {
        float3 xformOp:scale = (2, 2, 2)
        uniform token[] xformOpOrder = ["xformOp:scale"]

        def BasisCurves "Hair" (
            doc = "linear"
        )
        {
            uniform token type = "linear"
            int[] curveVertexCounts = [2, 3]
            point3f[] points.timeSamples = {
                2: [(9, 9, 9), (9, 9, 9), (9, 9, 9), (9, 9, 9), (9, 9, 9)],
                0.5: [(1, 0, 0), (1, 0, 1), (0, 1, 0), (0, 1, 1), (0, 1, 2.5e0)],
            }
            float[] widths = [0.1, 0.1, 0.1, 0.1, 0.1] (interpolation = "vertex")
            color3f[] primvars:displayColor = [(1, 0, 0), (0, 0.5, 1)] (
                interpolation = "uniform"
            )
            custom string userNote = 'single \'quoted\''
            float[] primvars:pelt:lengthFactor = [1, 0.5] (interpolation = "uniform")
            vector3f[] primvars:pelt:textureOffset = [(0, 0, 0), (1, 0, 0), (0, 0, 0), (0, 1, 0), (0, 0, 1)] (
                interpolation = "vertex"
            )
        }
    }

    over "Overridden" { }
    def BasisCurves "Cubic"
    {
        uniform token type = "cubic"
        uniform token basis = "catmullRom"
        uniform token wrap = "pinned"
        int[] curveVertexCounts = [2]
        point3f[] points = [(0, 0, 0), (0, 0, -inf)]
    }
}
"#;
    // The second curve set has a non-finite point: an error naming the prim.
    let error = read_curves_from(text.as_bytes(), Path::new("grammar.usda")).unwrap_err().to_string();
    assert!(error.contains("grammar.usda") && error.contains("/Root/Cubic") && error.contains("not finite"), "{error}");

    let text = text.replace("(0, 0, -inf)", "(0, 0, 3)");
    let stage = read_curves_from(text.as_bytes(), Path::new("grammar.usda")).unwrap();
    assert_eq!(stage.up_axis, UpAxis::Z);
    assert_eq!(stage.meters_per_unit, 0.01);
    assert_eq!(stage.default_prim.as_deref(), Some("Root"));
    assert_eq!(stage.meshes, 0, "the mesh inside a variant is read past");
    assert_eq!(stage.curves.len(), 2);
    let hair = &stage.curves[0];
    assert_eq!(hair.path, "/Root/Scaled/Hair");
    assert_eq!((hair.curve_type, hair.counts.clone()), (CurveType::Linear, vec![2, 3]));
    // The earliest sample (time 0.5), scaled by 2, turned 90 degrees about Z (the rotation's
    // earliest sample, time 1), moved 10 along X: (x, y, z) -> (10 - 2y, 2x, 2z).
    let expected = [[10.0, 2.0, 0.0], [10.0, 2.0, 2.0], [8.0, 0.0, 0.0], [8.0, 0.0, 2.0], [8.0, 0.0, 5.0]];
    for (got, want) in hair.points.iter().zip(expected) {
        assert!(got.distance(Vec3::from(want)) < 1e-5, "{got} vs {want:?}");
    }
    assert_eq!(hair.colours.as_ref().unwrap(), &vec![Vec3::new(1.0, 0.0, 0.0), Vec3::new(0.0, 0.5, 1.0)]);
    assert_eq!(hair.length_factors.as_ref().unwrap(), &vec![1.0, 0.5]);
    // Offsets are vectors: turned and scaled, not moved: (x, y, z) -> (-2y, 2x, 2z).
    let offsets = [[0.0, 0.0, 0.0], [0.0, 2.0, 0.0], [0.0, 0.0, 0.0], [-2.0, 0.0, 0.0], [0.0, 0.0, 2.0]];
    for (got, want) in hair.texture_offsets.as_ref().unwrap().iter().zip(offsets) {
        assert!(got.distance(Vec3::from(want)) < 1e-5, "offset {got} vs {want:?}");
    }
    let cubic = &stage.curves[1];
    assert_eq!(
        (cubic.curve_type, cubic.basis, cubic.wrap),
        (CurveType::Cubic, CurveBasis::CatmullRom, CurveWrap::Pinned)
    );
    // A pinned Catmull-Rom curve runs from its first point to its last along the line between.
    let line = cubic.polyline(cubic.curve(&cubic.offsets(), 0), 4);
    assert_eq!(line.first(), Some(&Vec3::new(10.0, 0.0, 0.0)));
    assert!(line.last().unwrap().distance(Vec3::new(10.0, 0.0, 3.0)) < 1e-5);
    assert!(line.iter().all(|p| (p.x - 10.0).abs() < 1e-5 && p.y.abs() < 1e-5));
}

/// What Pelt writes, Pelt reads: counts, points and colours of an export come back.
#[test]
fn an_export_reads_back() {
    let preset = Preset::load(assets().join("presets/fox_groomed.toml")).unwrap();
    let (mesh, _) = Mesh::load(&assets().join("meshes/Fox.glb"), &ImportOptions::default()).unwrap();
    let fur = preset.grow(mesh, "Fox.glb").unwrap();
    let path = scratch("read_back").join("fox.usda");
    export_rest(&preset, &fur, &path, StrandBasis::CatmullRom);
    let stage = read_curves(&path).unwrap();
    assert_eq!((stage.up_axis, stage.meters_per_unit, stage.default_prim.as_deref()), (UpAxis::Y, 1.0, Some("Fur")));
    assert_eq!(stage.meshes, 1);
    let curves = &stage.curves[0];
    assert_eq!(curves.path, "/Fur/Strands");
    assert_eq!(
        (curves.curve_type, curves.basis, curves.wrap),
        (CurveType::Cubic, CurveBasis::CatmullRom, CurveWrap::Pinned)
    );
    assert_eq!(curves.colours.as_ref().unwrap().len(), curves.counts.len());
    assert_eq!(curves.points.len(), curves.counts.iter().map(|&n| n as usize).sum::<usize>());
    // One texture offset per point; a root stands on its own column, so its offset is zero.
    let offsets = curves.texture_offsets.as_ref().unwrap();
    assert_eq!(offsets.len(), curves.points.len());
    assert!(curves.offsets().iter().all(|&first| offsets[first] == Vec3::ZERO));
    assert!(offsets.iter().any(|o| o.length() > 0.0), "the texture leans no strand");
}

/// Bad files: each a clear error naming the file, never a panic.
#[test]
fn bad_curve_files_are_clear_errors_naming_the_file() {
    let folder = scratch("bad");
    let preset = Preset::load(assets().join("presets/fox.toml")).unwrap();
    let mesh = pelt_core::Builtin::Sphere.mesh().0;
    let deep = format!("#usda 1.0\ndef Xform \"A\" {{\n float3 x = {}\n}}\n", "(".repeat(100_000));
    let cases: [(&str, &[u8], &str); 12] = [
        ("deep.usda", deep.as_bytes(), "nested more than"),
        ("empty.usda", b"", "the file is empty"),
        ("crate.usd", b"PXR-USDC\0\0\0\0", "binary USD crate file"),
        ("archive.usdz", b"PK\x03\x04rest", ".usdz archive"),
        ("not_usd.usda", b"ply\nformat ascii 1.0\n", "not a USD text file"),
        ("no_curves.usda", b"#usda 1.0\ndef Mesh \"Body\" {\n    int[] faceVertexCounts = [3]\n}\n", "no BasisCurves prims"),
        ("zero_curves.usda", b"#usda 1.0\ndef BasisCurves \"H\" {\n int[] curveVertexCounts = []\n point3f[] points = []\n}\n", "BasisCurves with no curves"),
        ("truncated.usda", b"#usda 1.0\ndef BasisCurves \"H\" {\n int[] curveVertexCounts = [2]\n point3f[] points = [(0, 0, 0), (0", "truncated.usda:4"),
        ("counts.usda", b"#usda 1.0\ndef BasisCurves \"H\" {\n uniform token type = \"linear\"\n int[] curveVertexCounts = [3]\n point3f[] points = [(0, 0, 0), (0, 1, 0)]\n}\n", "add up to 3 points, but there are 2"),
        ("offsets.usda", b"#usda 1.0\ndef BasisCurves \"H\" {\n uniform token type = \"linear\"\n int[] curveVertexCounts = [2]\n point3f[] points = [(0, 0, 0), (0, 1, 0)]\n vector3f[] primvars:pelt:textureOffset = [(0, 0, 0)]\n}\n", "textureOffset has 1 offsets for 2 points"),
        ("nan_offsets.usda", b"#usda 1.0\ndef BasisCurves \"H\" {\n uniform token type = \"linear\"\n int[] curveVertexCounts = [2]\n point3f[] points = [(0, 0, 0), (0, 1, 0)]\n vector3f[] primvars:pelt:textureOffset = [(0, 0, 0), (nan, 0, 0)]\n}\n", "textureOffset must be finite"),
        ("far.usda", b"#usda 1.0\n(\n metersPerUnit = 1\n)\ndef BasisCurves \"H\" {\n uniform token type = \"linear\"\n int[] curveVertexCounts = [2]\n point3f[] points = [(50, 0, 0), (51, 0, 0)]\n}\n", "none of its 1 curves has its root within"),
    ];
    for (name, bytes, expected) in cases {
        let path = folder.join(name);
        std::fs::write(&path, bytes).unwrap();
        let error = with_strands(&preset, &path).groom(&mesh, "sphere").unwrap_err().to_string();
        assert!(error.contains(name) && error.contains(expected), "{name}: {error}");
    }
    let missing = folder.join("missing.usda");
    let error = with_strands(&preset, &missing).groom(&mesh, "sphere").unwrap_err().to_string();
    assert!(error.contains("missing.usda") && error.contains("cannot read"), "{error}");
}

/// A groom written by Pixar's USD library (`tests/fixtures/make_zup_groom.py`, usd-core): curves
/// on the bunny's upper +X side in a Z-up centimetre stage, under a translated Xform, as pinned
/// cubic B-splines, baked onto the Y-up metre bunny: every root lands on the surface, the fur
/// grows on that side alone, along the normals, as long as the curves.
#[test]
fn a_z_up_centimetre_groom_from_usd_lands_on_the_right_side() {
    let (mesh, _) = Mesh::load(&assets().join("meshes/bunny.obj"), &ImportOptions::default()).unwrap();
    let preset = with_strands(&Preset::default(), &fixture("zup_cm_groom.usda"));
    let (groom, report) = preset.groom_with_report(&mesh, "bunny.obj").unwrap();
    let (groom, report) = (groom.unwrap(), report.unwrap());
    assert_eq!((report.curves, report.on_surface, report.off_surface), (89, 89, 0), "{report}");
    assert!(report.root_distance_max < 1e-4, "{report}");
    let fur = preset.grow(mesh.clone(), "bunny.obj").unwrap();
    let furred: Vec<usize> = (0..mesh.vertex_count()).filter(|&j| groom.length_factor(j) > 0.0).collect();
    assert!(furred.len() >= 20, "{report}");
    // The curves root on faces whose centres have x > 1 and y > 5: their corners lie within an
    // edge or two of that.
    let edge = mesh.mean_edge_length();
    for &j in &furred {
        let p = mesh.positions[j];
        assert!(p.x > 1.0 - 3.0 * edge && p.y > 5.0 - 3.0 * edge, "vertex {j} at {p} is furred");
    }
    // 0.3 m curves over the field's mean strand length and the preset's length.
    let field = preset.strand_field().unwrap();
    let mean_factor = field.strands.iter().map(|s| s.length_factor()).sum::<f32>() / field.strands.len() as f32;
    let expected = 0.3 / mean_factor / (preset.length * mesh.bounding_sphere().1);
    let mut factors: Vec<f32> = furred.iter().map(|&j| groom.length_factor(j)).collect();
    factors.sort_by(f32::total_cmp);
    let median = factors[factors.len() / 2];
    assert!((median / expected - 1.0).abs() < 0.15, "median length factor {median}, expected {expected}");
    let mut angles: Vec<f32> = furred.iter().map(|&j| angle_deg(fur.directions[j], mesh.normals[j])).collect();
    angles.sort_by(f32::total_cmp);
    // The curves follow face normals, the vertices' normals average several faces.
    assert!(angles[angles.len() / 2] < 12.0, "growth directions off the normals: {angles:?}");
    // The file's colour over the preset's own (white by default) as a tint.
    let tint = groom.tint.as_ref().unwrap()[furred[0]];
    assert!(tint.x > tint.y && tint.y > tint.z, "{tint}");
}
