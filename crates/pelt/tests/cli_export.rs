//! `pelt export` run as a program: bad input fails with a message naming the problem and leaves
//! no file behind; `--motion` writes its looping animation and reports the file's size;
//! `--screen-size` picks fewer shells for a smaller fur on screen.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pelt(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(args)
        .current_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("../.."))
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("the pelt binary runs")
}

fn stdout(output: &Output) -> String {
    String::from_utf8_lossy(&output.stdout).into_owned()
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// An empty folder of its own for one test.
fn folder(name: &str) -> PathBuf {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("pelt-cli-export-{name}"));
    let _ = std::fs::remove_dir_all(&folder);
    std::fs::create_dir_all(&folder).expect("a temporary folder");
    folder
}

fn files(folder: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(folder)
        .expect("list")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

/// Runs `pelt export ARGS -o FOLDER/fur.glb`, expects it to fail with every piece of `wanted`
/// in its message, and no file but `keep` left in the folder.
fn fails(name: &str, args: &[&str], wanted: &[&str], keep: &[&str]) {
    let folder = folder(name);
    for file in keep {
        std::fs::write(folder.join(file), b"not a mesh").expect("write");
    }
    let output_path = folder.join("fur.glb");
    let path = |p: &str| p.replace("FOLDER", &folder.display().to_string());
    let mut all: Vec<String> = vec!["export".to_owned()];
    all.extend(args.iter().map(|a| path(a)));
    if !args.contains(&"-o") {
        all.extend(["-o".to_owned(), output_path.display().to_string()]);
    }
    let all: Vec<&str> = all.iter().map(String::as_str).collect();
    let output = pelt(&all);
    let message = stderr(&output);
    assert!(!output.status.success(), "{name}: it should fail");
    assert!(!message.contains("panicked"), "{name}: {message}");
    for piece in wanted {
        assert!(message.contains(&path(piece)), "{name}: {piece:?} not in {message}");
    }
    assert_eq!(files(&folder), keep, "{name}: a file was left behind");
    std::fs::remove_dir_all(&folder).expect("clean up");
}

#[test]
fn bad_input_fails_clearly_and_leaves_no_file() {
    fails("layers0", &["--builtin", "box", "--layers", "0"], &["--layers", "0"], &[]);
    fails("motion-neg", &["--builtin", "box", "--motion", "-1"], &["--motion", "-1"], &[]);
    fails("motion-nan", &["--builtin", "box", "--motion", "NaN"], &["--motion", "NaN"], &[]);
    fails("motion-0", &["--builtin", "box", "--motion", "0"], &["--motion"], &[]);
    fails("time-neg", &["assets/meshes/Fox.glb", "--time", "-2"], &["--time", "-2"], &[]);
    fails("screen0", &["--builtin", "box", "--screen-size", "0"], &["--screen-size"], &[]);
    fails("both", &["--builtin", "box", "--layers", "4", "--screen-size", "100"], &["--layers", "--screen-size"], &[]);
    fails(
        "time-past",
        &["assets/meshes/Fox.glb", "--animation", "Walk", "--time", "100"],
        &["--time 100", "past the end", "Walk"],
        &[],
    );
    fails("bad-mesh", &["FOLDER/broken.glb"], &["FOLDER/broken.glb"], &["broken.glb"]);
    fails("no-mesh", &["FOLDER/missing.obj"], &["FOLDER/missing.obj"], &[]);
    // The output's folder is a file; the output is a folder; the output is not glTF.
    fails(
        "parent-file",
        &["--builtin", "box", "-o", "FOLDER/note.txt/fur.glb"],
        &["FOLDER/note.txt/fur.glb"],
        &["note.txt"],
    );
    fails("is-folder", &["--builtin", "box", "-o", "FOLDER"], &["FOLDER"], &[]);
    fails(
        "not-gltf",
        &["--builtin", "box", "-o", "FOLDER/fur.obj"],
        &["FOLDER/fur.obj", ".glb, .gltf or .usda (.usd)"],
        &[],
    );
}

/// The JSON chunk of a GLB.
fn glb_json(path: &Path) -> serde_json::Value {
    let glb = std::fs::read(path).expect("the export");
    assert_eq!(&glb[..4], b"glTF");
    let length = u32::from_le_bytes(glb[12..16].try_into().expect("4 bytes")) as usize;
    serde_json::from_slice(&glb[20..20 + length]).expect("JSON")
}

#[test]
fn motion_writes_a_looping_weights_animation_and_reports_the_size() {
    let folder = folder("motion");
    let path = folder.join("sway.glb");
    let output =
        pelt(&["export", "--builtin", "box", "--layers", "2", "--motion", "1", "-o", &path.display().to_string()]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stdout(&output);
    let bytes = std::fs::metadata(&path).expect("written").len();
    assert!(text.contains(&format!("{:.2} MB", bytes as f64 / 1e6)), "the size is reported: {text}");
    assert!(text.contains("1 s of motion in 4 morph targets"), "{text}");
    let json = glb_json(&path);
    let animation = &json["animations"][0];
    assert_eq!(animation["name"], "pelt fur motion");
    let fur_node = json["nodes"].as_array().expect("nodes").iter().position(|n| n["name"] == "pelt fur");
    assert_eq!(animation["channels"][0]["target"], serde_json::json!({ "node": fur_node, "path": "weights" }));
    let input = &json["accessors"][animation["samplers"][0]["input"].as_u64().expect("input") as usize];
    assert_eq!(input["max"][0], 1.0, "the loop lasts --motion seconds");
    let fur = &json["meshes"][json["nodes"][fur_node.expect("a fur node")]["mesh"].as_u64().expect("mesh") as usize];
    for primitive in fur["primitives"].as_array().expect("primitives") {
        assert_eq!(primitive["targets"].as_array().map(Vec::len), Some(4), "a target per sampled frame");
    }
    // The wind moves the tips: a target's bounds are not all zero.
    let target = &json["accessors"][fur["primitives"][1]["targets"][1]["POSITION"].as_u64().expect("target") as usize];
    let spread: f64 =
        (0..3).map(|k| target["max"][k].as_f64().unwrap_or(0.0) - target["min"][k].as_f64().unwrap_or(0.0)).sum();
    assert!(spread > 1e-4, "{target}");
    std::fs::remove_dir_all(&folder).expect("clean up");
}

#[test]
fn a_smaller_screen_size_exports_fewer_shells() {
    let folder = folder("screen");
    let shells = |pixels: &str| {
        let path = folder.join(format!("fur-{pixels}.glb"));
        let output = pelt(&["export", "--builtin", "box", "--screen-size", pixels, "-o", &path.display().to_string()]);
        assert!(output.status.success(), "{}", stderr(&output));
        glb_json(&path)["asset"]["extras"]["pelt"]["shells"].as_array().expect("shells").len()
    };
    let layers = glb_json(&{
        let path = folder.join("all.glb");
        let output = pelt(&["export", "--builtin", "box", "-o", &path.display().to_string()]);
        assert!(output.status.success(), "{}", stderr(&output));
        path
    })["asset"]["extras"]["pelt"]["layers"]
        .as_u64()
        .expect("layers") as usize;
    let (tiny, small, large) = (shells("8"), shells("150"), shells("100000"));
    assert_eq!(large, layers, "a fur filling a huge screen keeps every layer");
    assert_eq!(tiny, 2, "a speck keeps the coarsest level: two shells");
    assert!(tiny < small && small < large, "{tiny} {small} {large}");
    std::fs::remove_dir_all(&folder).expect("clean up");
}
