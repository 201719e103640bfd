//! `pelt fidelity` end to end at a small size: the three renders, the images and the JSON keys.

use std::path::Path;
use std::process::Command;

#[test]
fn fidelity_runs_small_and_writes_images_and_json() {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_fidelity");
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    let output = Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(["fidelity", "--builtin", "sphere", "--size", "64x64", "--supersample", "2", "--views", "front,back"])
        .args(["--wind", "0.5,0,0", "--json", "out.json", "--out", "images"])
        .current_dir(&dir)
        .output()
        .expect("run pelt");
    let text = format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr));
    assert!(output.status.success(), "{text}");
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("out.json")).expect("out.json")).expect("JSON");
    let results = json["results"].as_array().expect("results");
    assert_eq!(results.len(), 2);
    for (result, view) in results.iter().zip(["front", "back"]) {
        assert_eq!(result["model"], "sphere");
        assert_eq!(result["view"], view);
        assert_eq!(result["wind"], serde_json::json!([0.5, 0.0, 0.0]));
        for key in ["ssim_fur_shells_fins", "ssim_fur_shells", "ssim_silhouette_shells_fins", "ssim_silhouette_shells"]
        {
            let value = result[key].as_f64().unwrap_or_else(|| panic!("{key} in {result}"));
            // Shells resemble the strands but are not them.
            assert!((0.05..0.999).contains(&value), "{key} = {value}");
        }
        // The strands against themselves a quarter pixel off: close, and not the same picture.
        let shifted = result["ssim_fur_reference_shifted"].as_f64().expect("ssim_fur_reference_shifted");
        assert!((0.3..0.9999).contains(&shifted), "reference shifted: {shifted}");
        let difference = result["mean_colour_difference"].as_f64().expect("mean_colour_difference");
        assert!((0.0..0.5).contains(&difference) && difference > 0.0, "mean colour difference {difference}");
        let image = image::open(dir.join(format!("images/sphere-{view}-wind.png"))).expect("side-by-side image");
        // Four panels of 64 with three 4-pixel gaps.
        assert_eq!((image.width(), image.height()), (4 * 64 + 3 * 4, 64));
    }

    let bad = Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(["fidelity", "--builtin", "sphere", "--views", "top"])
        .current_dir(&dir)
        .output()
        .expect("run pelt");
    assert!(!bad.status.success());
    assert!(String::from_utf8_lossy(&bad.stderr).contains("unknown view \"top\""));
}
