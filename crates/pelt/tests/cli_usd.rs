//! USD hair from the command line: `pelt export -o *.usda` writes the strands `pelt fidelity`'s
//! reference places (same count, same lengths) and the same bytes each time, bad arguments fail
//! naming the problem with no file left, `pelt groom bake` bakes a curve file into a groom file,
//! and `pelt --help` names every command on its first line.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

use pelt_core::groom::Groom;
use pelt_core::mesh::{ImportOptions, Mesh};
use pelt_core::reference::{StrandReference, TileMapping};
use pelt_core::sim::{FurStepper, WindParams};
use pelt_core::usd::read_curves;
use pelt_core::{Builtin, Preset};

fn pelt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(args)
        .current_dir(root())
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("the pelt binary runs")
}

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

fn folder(name: &str) -> PathBuf {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("pelt-cli-usd-{name}"));
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder).expect("a temporary folder");
    folder
}

fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// `pelt export --builtin bunny -o bunny.usda` against the reference built here the way `pelt
/// fidelity` builds it (the preset's field, the standard tile mapping, the fur settled 1.5 s
/// under gravity at 30 frames a second): the same strands, each as long.
#[test]
fn an_export_holds_the_reference_strands() {
    let folder = folder("reference");
    let path = folder.join("bunny.usda");
    let output = pelt(&["export", "--builtin", "bunny", "-o", path.to_str().unwrap()]);
    assert!(output.status.success(), "{}", text(&output.stderr));
    let printed = text(&output.stdout);
    assert!(printed.contains("bunny.usda:") && printed.contains(" MB, ") && printed.contains("curves of"), "{printed}");

    let preset = Preset::default();
    let (mesh, _) = Builtin::Bunny.mesh();
    let fur = preset.grow(mesh, "bunny").unwrap();
    let mut params = preset.simulation.clone();
    params.wind = WindParams { strength: 0.0, ..params.wind };
    let mut stepper = FurStepper::new(&fur, &params).unwrap();
    for frame in 0..=45 {
        stepper.advance_with_clip_at(f64::from(frame) / 30.0, 0.0).unwrap();
    }
    let reference =
        StrandReference::new(&fur, preset.strand_field().unwrap(), TileMapping::standard(&fur.mesh)).unwrap();
    let nodes = reference.node_positions(stepper.simulation().positions()).unwrap();
    let lengths: Vec<f32> = reference
        .strands
        .iter()
        .map(|s| {
            let first = s.first_node as usize;
            nodes[first..first + s.node_count as usize].windows(2).map(|w| w[0].distance(w[1])).sum()
        })
        .collect();

    let stage = read_curves(&path).unwrap();
    let curves = &stage.curves[0];
    assert_eq!(curves.counts.len(), reference.strands.len(), "strand count");
    assert!(printed.contains(&format!("{} curves of", reference.strands.len())), "{printed}");
    let offsets = curves.offsets();
    for (k, want) in lengths.iter().enumerate() {
        let got: f32 = curves.curve(&offsets, k).windows(2).map(|w| w[0].distance(w[1])).sum();
        assert!((got - want).abs() <= 1e-5 * want.max(1e-3), "strand {k}: {got} vs the reference's {want}");
    }
}

/// Bad arguments fail before any work, naming the problem, and leave no file.
#[test]
fn bad_usd_arguments_fail_and_leave_no_file() {
    let folder = folder("bad");
    let usda = folder.join("fur.usda");
    let glb = folder.join("fur.glb");
    let missing = folder.join("missing/fur.usda");
    let cases: [(&[&str], &str); 5] = [
        (&["--strand-fraction", "0", "-o", usda.to_str().unwrap()], "--strand-fraction must be above 0"),
        (&["--strand-fraction", "0.5", "-o", glb.to_str().unwrap()], "--strand-fraction: only a .usda export"),
        (&["--layers", "4", "-o", usda.to_str().unwrap()], "a .usda export writes strands"),
        (&["--meters-per-unit", "-1", "-o", usda.to_str().unwrap()], "--meters-per-unit must be a positive number"),
        (&["-o", missing.to_str().unwrap()], "cannot write"),
    ];
    for (args, wanted) in cases {
        let mut all = vec!["export", "--builtin", "box"];
        all.extend_from_slice(args);
        let output = pelt(&all);
        let message = text(&output.stderr);
        assert!(!output.status.success() && message.contains(wanted), "{args:?}: {message}");
        assert!(!message.contains("panicked"), "{message}");
    }
    assert_eq!(std::fs::read_dir(&folder).unwrap().count(), 0, "a file was left behind");
}

/// `pelt groom bake` writes the groom of a curve file (the usd-core fixture) that the mesh then
/// loads, and reports what it read; a preset that names no curves is a clear error.
#[test]
fn groom_bake_writes_a_groom_file() {
    let folder = folder("bake");
    let groom_path = folder.join("zup.groom");
    let fixture = root().join("crates/pelt-core/tests/fixtures/zup_cm_groom.usda");
    let output = pelt(&[
        "groom",
        "bake",
        "assets/meshes/bunny.obj",
        "--strands",
        fixture.to_str().unwrap(),
        "-o",
        groom_path.to_str().unwrap(),
    ]);
    let printed = text(&output.stdout);
    assert!(output.status.success(), "{}", text(&output.stderr));
    assert!(
        printed.contains("zup_cm_groom.usda: 89 curves") && printed.contains("89 rooted on the surface"),
        "{printed}"
    );
    let (mesh, _) = Mesh::load(&root().join("assets/meshes/bunny.obj"), &ImportOptions::default()).unwrap();
    let groom = Groom::load(&groom_path, &mesh, "bunny.obj").unwrap();
    assert!((0..mesh.vertex_count()).any(|j| groom.length_factor(j) > 0.0));
    assert!((0..mesh.vertex_count()).any(|j| groom.is_bald(j)));

    let output = pelt(&["groom", "bake", "--builtin", "bunny", "-o", folder.join("none.groom").to_str().unwrap()]);
    let message = text(&output.stderr);
    assert!(!output.status.success() && message.contains("names no [groom] strands file"), "{message}");
    let output = pelt(&["groom", "bake", "--builtin", "bunny", "--strands", "assets/meshes/bunny.obj"]);
    let message = text(&output.stderr);
    assert!(
        !output.status.success() && message.contains("bunny.obj") && message.contains("not a USD text file"),
        "{message}"
    );
}

/// `pelt --help`'s first line names every command `pelt help` lists.
#[test]
fn help_names_every_command_on_its_first_line() {
    let help = text(&pelt(&["--help"]).stdout);
    let first = help.lines().next().unwrap();
    let commands: Vec<&str> = help
        .lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .collect();
    assert!(commands.len() >= 8, "{help}");
    for command in commands {
        assert!(first.contains(command), "{command} is missing from {first:?}");
    }
}

/// Same command, same bytes: the strands are seeded and written in a fixed order.
#[test]
fn the_same_export_writes_the_same_bytes() {
    let folder = folder("same");
    // `.usd` is the same text as `.usda`.
    let (a, b) = (folder.join("a.usda"), folder.join("b.usd"));
    for path in [&a, &b] {
        let args = ["export", "--builtin", "sphere", "--curves", "catmull-rom", "--strand-fraction", "0.3", "-o"];
        let mut all = args.to_vec();
        all.push(path.to_str().unwrap());
        let output = pelt(&all);
        assert!(output.status.success(), "{}", text(&output.stderr));
    }
    let (a, b) = (std::fs::read(&a).unwrap(), std::fs::read(&b).unwrap());
    assert!(a.len() > 1000 && a == b, "two runs of one export differ");
}
