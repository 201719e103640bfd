//! `pelt view` in a real window under Xvfb: the window's own frame comes back as a PNG.
//!
//! Needs `xvfb-run` (Debian's xvfb and xauth) and a Vulkan or GL driver (lavapipe, llvmpipe);
//! `.ci/run` installs them.

use std::path::{Path, PathBuf};
use std::process::Command;

const WIDTH_PX: u32 = 960;
const HEIGHT_PX: u32 = 640;
/// The panel's default width in points (and pixels: Xvfb has a scale factor of 1).
const PANEL_PX: u32 = 320;

fn out_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli_view_{name}.png"))
}

/// Runs `pelt view ARGS --screenshot-after FRAMES --out OUT` under Xvfb and loads the PNG.
fn screenshot(name: &str, frames: u32, args: &[&str]) -> image::RgbaImage {
    let out = out_path(name);
    let _stale = std::fs::remove_file(&out);
    let output = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1280x800x24"])
        .arg(env!("CARGO_BIN_EXE_pelt"))
        .arg("view")
        .args(args)
        .args(["--size", &format!("{WIDTH_PX}x{HEIGHT_PX}"), "--screenshot-after", &frames.to_string(), "--out"])
        .arg(&out)
        .output()
        .expect("xvfb-run runs (install xvfb and xauth)");
    assert!(
        output.status.success(),
        "pelt view failed ({}):\n{}\n{}",
        output.status,
        String::from_utf8_lossy(&output.stdout),
        String::from_utf8_lossy(&output.stderr)
    );
    image::open(&out).unwrap_or_else(|e| panic!("reading {}: {e}", out.display())).to_rgba8()
}

fn luminance(pixel: &image::Rgba<u8>) -> f64 {
    let [r, g, b, _] = pixel.0;
    0.2126 * f64::from(r) + 0.7152 * f64::from(g) + 0.0722 * f64::from(b)
}

/// Horizontal luminance jumps of more than 40 levels inside `x0..x1`: text and widget edges make
/// many, a flat fill none.
fn edges(image: &image::RgbaImage, x0: u32, x1: u32) -> usize {
    let mut count = 0;
    for y in 0..image.height() {
        for x in x0 + 1..x1 {
            if (luminance(image.get_pixel(x, y)) - luminance(image.get_pixel(x - 1, y))).abs() > 40.0 {
                count += 1;
            }
        }
    }
    count
}

#[test]
fn the_window_shows_the_panel_with_text_beside_the_3d_view() {
    let image = screenshot("panel", 4, &["--builtin", "sphere"]);
    assert_eq!(image.dimensions(), (WIDTH_PX, HEIGHT_PX), "the screenshot is the window's frame");
    let panel_x0 = WIDTH_PX - PANEL_PX;
    let panel_edges = edges(&image, panel_x0, WIDTH_PX);
    assert!(panel_edges > 2_000, "the panel has text and widgets: {panel_edges} edges");
    let distinct: std::collections::HashSet<_> = (panel_x0..WIDTH_PX)
        .flat_map(|x| (0..HEIGHT_PX).map(move |y| (x, y)))
        .map(|(x, y)| image.get_pixel(x, y).0)
        .collect();
    assert!(distinct.len() > 20, "anti-aliased text gives many shades: {}", distinct.len());
}
