//! `pelt stats` run as a program: exit codes, stdout and error messages.

use std::path::Path;
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

#[test]
fn the_default_mesh_is_the_papers_box() {
    let output = pelt(&["stats"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(text.contains("builtin:box") && text.contains("5,032") && text.contains("31,492"), "{text}");
    assert!(text.contains("matches"), "{text}");
}

#[test]
fn a_mesh_file_gives_json_on_request() {
    let output = pelt(&["stats", "assets/meshes/skirthelper.obj", "--layers", "8", "--json"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("valid JSON");
    assert_eq!(json["mesh"]["vertices"], 720);
    assert_eq!(json["mesh"]["boundary_loops"], 2);
    assert_eq!(json["unified"]["vertices"], 720 * 9);
    assert_eq!(json["layers"], 8);
}

#[test]
fn bad_input_fails_with_a_message_not_a_panic() {
    for (args, expected) in [
        (&["stats", "no/such/mesh.obj"][..], "no/such/mesh.obj"),
        (&["stats", "crates/pelt-core/tests/fixtures/bad_number.obj"][..], "bad_number.obj:3"),
        (&["stats", "--builtin", "cube"][..], "unknown built-in mesh \"cube\""),
        (&["stats", "--layers", "0"][..], "--layers 0"),
        (&["stats", "--fin-faces", "0"][..], "--fin-faces"),
    ] {
        let output = pelt(args);
        let message = stderr(&output);
        assert!(!output.status.success(), "{args:?} should fail");
        assert!(message.contains(expected), "{args:?}: {message}");
        assert!(!message.contains("panicked"), "{args:?}: {message}");
    }
}

#[test]
fn an_animated_file_lists_its_skins_joints_and_animations() {
    let output = pelt(&["stats", "assets/meshes/Fox.glb"]);
    assert!(output.status.success(), "{}", stderr(&output));
    let text = stdout(&output);
    assert!(text.contains("1 skins, 24 joints"), "{text}");
    for clip in ["animation 0 \"Survey\"", "animation 1 \"Walk\": 0.708 s", "animation 2 \"Run\""] {
        assert!(text.contains(clip), "{clip} in {text}");
    }
    let output = pelt(&["stats", "assets/meshes/Fox.glb", "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("valid JSON");
    assert_eq!(json["motion"]["skins"][0]["joints"], 24);
    let walk = &json["motion"]["animations"][1];
    assert_eq!(walk["name"], "Walk");
    assert!(walk["duration_secs"].as_f64().unwrap() > 0.5, "{walk}");
    // A file that does not move has no motion section.
    let output = pelt(&["stats", "assets/meshes/skirthelper.obj", "--json"]);
    let json: serde_json::Value = serde_json::from_slice(&output.stdout).expect("valid JSON");
    assert!(json.get("motion").is_none());
}

/// A preset's groom leaves the bald faces out of the counts, for the unified and the separated
/// structures alike; the vertices and the topology's bytes stay.
#[test]
fn a_groomed_preset_counts_only_the_faces_drawn() {
    let fox = "assets/meshes/Fox.glb";
    let json = |args: &[&str]| -> serde_json::Value {
        let output = pelt(args);
        assert!(output.status.success(), "{}", stderr(&output));
        serde_json::from_slice(&output.stdout).expect("valid JSON")
    };
    let uniform = json(&["stats", fox, "--json"]);
    let groomed = json(&["stats", fox, "--json", "--preset", "assets/presets/fox_groomed.toml"]);
    assert!(uniform.get("groom").is_none());
    assert_eq!(groomed["groom"], "assets/presets/fox_groomed.toml");
    for structure in ["unified", "separated2", "separated_n"] {
        let faces = |stats: &serde_json::Value, key: &str| stats[structure][key].as_u64().unwrap();
        assert!(faces(&groomed, "shell_faces") < faces(&uniform, "shell_faces"), "{structure}");
        assert!(faces(&groomed, "fin_faces") < faces(&uniform, "fin_faces"), "{structure}");
    }
    assert_eq!(groomed["unified"]["index_bytes"], uniform["unified"]["index_bytes"]);
    let text = stdout(&pelt(&["stats", fox, "--preset", "assets/presets/fox_groomed.toml"]));
    assert!(text.contains("groomed by assets/presets/fox_groomed.toml"), "{text}");
}
