//! CI smoke test of `pelt bench --quick`: every documented key is there, the counts follow the
//! paper's Table 2 formulas, and every time is a positive finite number or null with a reason.

use std::process::Command;

use serde_json::Value;

const TOP_LEVEL_KEYS: [&str; 16] = [
    "pelt_version",
    "date_utc",
    "command",
    "quick",
    "build_profile",
    "machine",
    "adapter",
    "adapter_unavailable_reason",
    "paper_savings_vs_2_percent",
    "paper_savings_vs_30_percent",
    "sim_cpu_kernel",
    "sim_large_mesh",
    "results",
    "skipped_models",
    "peak_rss_bytes",
    "wall_time_s",
];

const COUNT_KEYS: [&str; 14] = [
    "vertices",
    "faces",
    "fur_vertices",
    "fur_edges",
    "unified_vertices",
    "separated2_vertices",
    "separated30_vertices",
    "unified_faces",
    "separated2_faces",
    "separated30_faces",
    "unified_bytes",
    "separated2_bytes",
    "separated30_bytes",
    "layers",
];

const PERCENT_KEYS: [&str; 4] =
    ["savings_vs_2_percent", "savings_vs_30_percent", "bytes_savings_vs_2_percent", "bytes_savings_vs_30_percent"];

/// Measured figures, grouped by the key that says why they are null when they are.
const MEASURED_KEYS: [(&str, &[&str]); 5] = [
    ("anim_unavailable_reason", &["anim_pose_ms_per_frame", "anim_sim_ms_per_frame", "anim_cpu_ms_per_frame"]),
    (
        "render_unavailable_reason",
        &[
            "frame_ms_unified_1280x720",
            "frame_ms_separated2_1280x720",
            "frame_ms_separated30_1280x720",
            "frame_ms_unified_256x256",
            "frame_ms_separated2_256x256",
            "frame_ms_separated30_256x256",
            "frame_ms_unified_shadows_1280x720",
            "frame_ms_unified_shadows_256x256",
            "render_frames",
            "upload_ms_per_frame",
            "fin_edges_drawn",
        ],
    ),
    (
        "sim_unavailable_reason",
        &[
            "sim_node_updates_per_sec",
            "sim_node_updates_per_sec_all_threads",
            "sim_literal_node_updates_per_sec",
            "sim_cpu_ms_per_frame_interpolated",
            "sim_cpu_ms_per_frame_every_frame",
        ],
    ),
    ("texture_unavailable_reason", &["texture_generation_ms", "texture_size_texels"]),
    (
        "gpu_sim_unavailable_reason",
        &["gpu_sim_node_updates_per_sec", "gpu_sim_steps_per_run", "gpu_sim_cpu_ms_per_frame"],
    ),
];

fn count(row: &Value, key: &str) -> u64 {
    row[key].as_u64().unwrap_or_else(|| panic!("{key} is not a count in {row}"))
}

#[test]
fn quick_bench_writes_every_key_with_sane_values() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR"));
    let json_path = dir.join(format!("bench-quick-{}.json", std::process::id()));
    let md_path = dir.join(format!("bench-quick-{}.md", std::process::id()));
    let output = Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(["bench", "--quick", "--shadows", "--size", "96x64", "--json"])
        .arg(&json_path)
        .arg("--md")
        .arg(&md_path)
        .output()
        .expect("pelt runs");
    assert!(output.status.success(), "pelt bench failed: {}", String::from_utf8_lossy(&output.stderr));
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json_path).unwrap()).unwrap();
    let markdown = std::fs::read_to_string(&md_path).unwrap();
    assert!(markdown.contains("Table 2"), "{markdown}");
    assert!(markdown.contains("### Shadows"), "--shadows adds the shadowed frame's table: {markdown}");

    for key in TOP_LEVEL_KEYS {
        assert!(report.get(key).is_some(), "missing top-level key {key}");
    }
    assert_eq!(report["quick"], true);
    assert!(report["skipped_models"].as_array().unwrap().is_empty(), "{}", report["skipped_models"]);
    if report["adapter"].is_null() {
        assert!(report["adapter_unavailable_reason"].as_str().is_some_and(|r| !r.is_empty()));
    } else {
        assert!(report["adapter"]["name"].is_string());
    }
    if cfg!(target_os = "linux") {
        assert!(report["peak_rss_bytes"].as_u64().is_some_and(|b| b > 1 << 20));
    }

    let kernel = report["sim_cpu_kernel"].as_str().unwrap();
    assert!(kernel == "avx2+fma" || kernel == "portable", "{kernel}");
    let large = &report["sim_large_mesh"];
    assert_eq!(large["vertices"], 35_000);
    assert_eq!(large["layers"], 32);
    for key in ["sim_node_updates_per_sec", "sim_node_updates_per_sec_all_threads"] {
        assert!(large[key].as_f64().is_some_and(|v| v.is_finite() && v > 0.0), "{key} in {large}");
    }
    // The GPU kernel on the large mesh wherever there is an adapter.
    let gpu_updates = &large["gpu_sim_node_updates_per_sec"];
    assert_eq!(gpu_updates.is_null(), report["adapter"].is_null(), "{large}");
    assert!(gpu_updates.is_null() || gpu_updates.as_f64().is_some_and(|v| v.is_finite() && v > 0.0), "{large}");

    let results = report["results"].as_array().unwrap();
    let models: Vec<&str> = results.iter().map(|r| r["model"].as_str().unwrap()).collect();
    for model in ["box", "bunny", "spot", "skirt", "women", "fox"] {
        assert_eq!(models.iter().filter(|m| **m == model).count(), 2, "{model} at 16 and 32 layers");
    }
    // The walking Fox is posed even under --quick; the static models say why they are not.
    for row in results {
        let animated = row["model"] == "fox";
        assert_eq!(row["anim_unavailable_reason"].is_null(), animated, "{row}");
        assert_eq!(row["anim_clip"].as_str() == Some("Walk"), animated, "{row}");
        if animated {
            let (pose, sim) = (row["anim_pose_ms_per_frame"].as_f64(), row["anim_sim_ms_per_frame"].as_f64());
            let cpu = row["anim_cpu_ms_per_frame"].as_f64().unwrap();
            assert!((pose.unwrap() + sim.unwrap() - cpu).abs() < 1e-9 * cpu.max(1.0), "{row}");
        }
    }
    for row in results {
        for key in COUNT_KEYS {
            count(row, key);
        }
        // Table 2's formulas: unified V(L+1), separated V(L+1) + N*E; a body counts once in each.
        let layers = count(row, "layers");
        let body = count(row, "vertices") - count(row, "fur_vertices");
        let shared = count(row, "fur_vertices") * (layers + 1) + body;
        assert_eq!(count(row, "unified_vertices"), shared, "{row}");
        assert_eq!(count(row, "separated2_vertices"), shared + 2 * count(row, "fur_edges"), "{row}");
        assert_eq!(count(row, "separated30_vertices"), shared + 30 * count(row, "fur_edges"), "{row}");
        assert!(count(row, "unified_bytes") < count(row, "separated2_bytes"), "{row}");
        assert!(count(row, "separated2_bytes") < count(row, "separated30_bytes"), "{row}");
        for key in PERCENT_KEYS {
            let percent = row[key].as_f64().unwrap_or_else(|| panic!("{key} in {row}"));
            assert!(percent > 0.0 && percent < 100.0, "{key} = {percent}");
        }
        let expected = 100.0 * (2 * count(row, "fur_edges")) as f64 / count(row, "separated2_vertices") as f64;
        assert!((row["savings_vs_2_percent"].as_f64().unwrap() - expected).abs() < 1e-9);

        for (reason_key, keys) in MEASURED_KEYS {
            let reason = &row[reason_key];
            for key in keys {
                let value = row.get(*key).unwrap_or_else(|| panic!("missing key {key}"));
                match value.as_f64() {
                    Some(v) => assert!(v.is_finite() && v > 0.0, "{key} = {v} in {row}"),
                    None => {
                        assert!(value.is_null(), "{key} = {value}");
                        assert!(reason.as_str().is_some_and(|r| !r.is_empty()), "{key} is null without {reason_key}");
                    }
                }
            }
        }
    }

    // `--size`: the rows that were drawn time that size too, with frames per second near what
    // the frames waited for one by one give (pipelining gains or noise, not orders of magnitude).
    for row in results {
        let sizes = row["extra_sizes"].as_array().unwrap_or_else(|| panic!("extra_sizes in {row}"));
        if row["render_unavailable_reason"].is_string() {
            assert!(sizes.is_empty(), "{row}");
            continue;
        }
        assert_eq!(sizes.len(), 1, "{row}");
        let size = &sizes[0];
        assert_eq!(size["size"], "96x64");
        assert!(size["fps_frames"].as_u64().is_some_and(|n| n >= 3), "{size}");
        assert!(size["level"].as_str().is_some_and(|l| l.contains("shells")), "{size}");
        for structure in ["unified", "separated2", "separated30"] {
            let frame_ms = size[format!("frame_ms_{structure}")].as_f64().unwrap();
            let fps = size[format!("fps_{structure}")].as_f64().unwrap();
            assert!(frame_ms.is_finite() && frame_ms > 0.0 && fps.is_finite() && fps > 0.0, "{size}");
            let waited_fps = 1000.0 / frame_ms;
            assert!(fps > 0.2 * waited_fps && fps < 20.0 * waited_fps, "{structure}: {size}");
        }
        assert!(size["fps_unified_lod"].as_f64().is_some_and(|fps| fps.is_finite() && fps > 0.0), "{size}");
    }
    assert!(markdown.contains("Frames per second at other sizes"), "{markdown}");
    assert!(markdown.contains("| box | 16 | 96x64 |"), "{markdown}");

    let box16 = results.iter().find(|r| r["model"] == "box" && r["layers"] == 16).unwrap();
    assert_eq!(count(box16, "vertices"), 296);
    assert_eq!(count(box16, "faces"), 588);
    assert_eq!(count(box16, "unified_vertices"), 5_032);
    assert_eq!(count(box16, "separated2_vertices"), 6_796);
    assert_eq!(count(box16, "separated30_vertices"), 31_492);

    let _ = std::fs::remove_file(json_path);
    let _ = std::fs::remove_file(md_path);
}

/// `pelt bench --soak` soaks both kernels and names each with its kernel (and the GPU's adapter):
/// a short run, as CI has lavapipe.
#[test]
fn soak_reports_the_cpu_and_the_gpu_kernel() {
    let output = Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(["bench", "--soak", "--steps", "300", "--gpu-steps", "100"])
        .output()
        .expect("run pelt");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&output.stderr));
    let lines: Vec<&str> = stdout.lines().filter(|l| l.starts_with("soak (")).collect();
    assert_eq!(lines.len(), 2, "{stdout}");
    assert!(lines[0].starts_with("soak (CPU kernel, ") && lines[0].contains("300 steps"), "{}", lines[0]);
    assert!(lines[1].starts_with("soak (GPU kernel, ") && lines[1].contains("100 steps"), "{}", lines[1]);
    for line in lines {
        assert!(line.ends_with("steps with a non-finite node: 0"), "{line}");
    }
}

/// `pelt bench --herd --quick`: one and ten Foxes, each row's figures positive, the GPU bytes the
/// shared asset once plus a Fox's own bytes per Fox, and the device's allocator agreeing within
/// its alignment.
#[test]
fn herd_bench_reports_each_size_with_the_asset_counted_once() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_bench_herd");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let json = dir.join("herd.json");
    let meshes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes");
    let output = Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(["bench", "--herd", "--quick", "--meshes", meshes.to_str().unwrap(), "--json", json.to_str().unwrap()])
        .output()
        .expect("run pelt");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(output.status.success(), "{stdout}\n{}", String::from_utf8_lossy(&output.stderr));
    assert!(stdout.contains("### A herd of walking Foxes"), "{stdout}");
    let rows: Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("the JSON")).expect("JSON");
    let rows = rows.as_array().expect("rows");
    assert_eq!(rows.iter().map(|r| r["foxes"].as_u64().unwrap()).collect::<Vec<_>>(), [1, 10]);
    for row in rows {
        for key in ["frame_ms", "simulation_ms", "record_ms", "gpu_and_readback_ms", "cpu_pose_ms", "gpu_pose_ms"] {
            let value = row[key].as_f64().unwrap_or(-1.0);
            assert!(value.is_finite() && value > 0.0, "{key} = {value} in {row}");
        }
        let (shared, own, total) =
            (count(row, "shared_gpu_bytes"), count(row, "per_fox_gpu_bytes"), count(row, "total_gpu_bytes"));
        assert_eq!(total, shared + count(row, "foxes") * own, "{row}");
        let allocated = count(row, "allocated_gpu_bytes");
        assert!(
            allocated >= total && (allocated as f64) < 1.3 * total as f64,
            "allocated {allocated}, counted {total}"
        );
    }
}

/// `pelt bench --device-report FILE --quick` on lavapipe: the command a GPU session runs first
/// writes every part (frames with and without shadows, herds on both kernels, the torus,
/// contact), each figure positive, the GPU kernel's herd bytes counted as the allocator does.
#[test]
fn device_report_writes_every_part() {
    let dir = std::path::Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_bench_device");
    std::fs::create_dir_all(&dir).expect("temp dir");
    let json = dir.join("device.json");
    let meshes = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes");
    let output = Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(["bench", "--device-report", json.to_str().unwrap(), "--quick", "--meshes", meshes.to_str().unwrap()])
        .output()
        .expect("run pelt");
    assert!(output.status.success(), "{}", String::from_utf8_lossy(&output.stderr));
    let report: Value = serde_json::from_str(&std::fs::read_to_string(&json).expect("the JSON")).expect("JSON");
    let positive = |value: &Value, what: &str| {
        let v = value.as_f64().unwrap_or(-1.0);
        assert!(v.is_finite() && v > 0.0, "{what} = {value}");
    };
    assert_eq!(report["size"], "320x180");
    let frames = report["frames"].as_array().expect("frames");
    assert_eq!(frames.iter().map(|f| f["model"].as_str().unwrap()).collect::<Vec<_>>(), ["bunny", "women"]);
    for model in frames {
        let figures = &model["figures"];
        for key in
            ["frame_ms_unified_1280x720", "frame_ms_unified_shadows_1280x720", "frame_ms_unified_shadows_256x256"]
        {
            positive(&figures[key], key);
        }
        positive(&figures["extra_sizes"][0]["frame_ms_unified"], "frame_ms_unified at 320x180");
    }
    let herd = report["herd"].as_array().expect("herd");
    let sizes: Vec<_> = herd
        .iter()
        .map(|r| {
            let pooled = [r["pooled_casting"].as_bool().unwrap(), r["pooled_stepping"].as_bool().unwrap()];
            (r["kernel"].as_str().unwrap(), r["foxes"].as_u64().unwrap(), pooled)
        })
        .collect();
    // Each kernel's herds pooled and not: the CPU kernel's, then the GPU kernel's.
    let (on, off, cast) = ([true; 2], [false; 2], [true, false]);
    let expected = [("cpu", 1, cast), ("cpu", 2, cast), ("cpu", 1, off), ("cpu", 2, off)];
    assert_eq!(sizes[..4], expected);
    assert_eq!(sizes[4..8], [("gpu", 1, on), ("gpu", 2, on), ("gpu", 1, off), ("gpu", 2, off)]);
    // Then a ball through a GPU-kernel herd, its steps with contact pooled and not.
    assert_eq!(sizes[8..], [("gpu", 2, on), ("gpu", 2, off)]);
    for (k, row) in herd.iter().enumerate() {
        assert_eq!(row["ball"].as_bool(), Some(k >= 8), "{row}");
    }
    herd.iter().for_each(|row| positive(&row["frame_ms"], "herd frame_ms"));
    // The GPU kernel's pooled herds skin their bases on the GPU, their bytes counted.
    for (k, row) in herd.iter().enumerate() {
        let posed = (4..6).contains(&k);
        assert_eq!(row["gpu_posing"].as_bool(), Some(posed), "{row}");
        assert_eq!(count(row, "posing_gpu_bytes") > 0, posed, "{row}");
    }
    // On the GPU kernel a Fox's own bytes add its second state and its simulation's buffers,
    // counted as the device's allocator counts them.
    for (on_cpu, on_gpu) in herd[2..4].iter().cycle().zip(&herd[4..8]) {
        assert!(count(on_gpu, "per_fox_gpu_bytes") > count(on_cpu, "per_fox_gpu_bytes"), "{on_cpu}\n{on_gpu}");
        let (total, allocated) = (count(on_gpu, "total_gpu_bytes"), count(on_gpu, "allocated_gpu_bytes"));
        assert!(
            allocated >= total && (allocated as f64) < 1.3 * total as f64,
            "GPU kernel: allocated {allocated}, counted {total}"
        );
    }
    positive(&report["gpu_sim_node_updates_per_sec_torus"], "torus");
    for (case, row) in ["off", "skin", "skin + 8 colliders"].iter().zip(report["contact"]["bunny"].as_array().unwrap())
    {
        assert_eq!(row["case"], *case);
        positive(&row["gpu_node_updates_per_sec"], case);
    }
    assert_eq!(report["contact"]["try_on"].as_array().unwrap().len(), 3);
}
