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

/// `xvfb-run -a` can hand two servers started at once the same display number: one at a time.
static XVFB: std::sync::Mutex<()> = std::sync::Mutex::new(());

/// Runs `pelt view ARGS --screenshot-after FRAMES --out OUT` under Xvfb and loads the PNG.
fn screenshot(name: &str, frames: u32, args: &[&str]) -> image::RgbaImage {
    screenshot_saying(name, frames, args).0
}

/// [`screenshot`] and what the viewer printed.
fn screenshot_saying(name: &str, frames: u32, args: &[&str]) -> (image::RgbaImage, String) {
    let _one_at_a_time = XVFB.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
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
    let image = image::open(&out).unwrap_or_else(|e| panic!("reading {}: {e}", out.display())).to_rgba8();
    (image, String::from_utf8_lossy(&output.stdout).into_owned())
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

/// Mean absolute difference per channel of two frames inside `x0..x1, y0..y1`.
fn mean_difference(a: &image::RgbaImage, b: &image::RgbaImage, (x0, y0, x1, y1): (u32, u32, u32, u32)) -> f64 {
    let mut sum = 0.0;
    for y in y0..y1 {
        for x in x0..x1 {
            let (p, q) = (a.get_pixel(x, y).0, b.get_pixel(x, y).0);
            sum += (0..3).map(|c| f64::from(p[c].abs_diff(q[c]))).sum::<f64>() / 3.0;
        }
    }
    sum / f64::from((x1 - x0) * (y1 - y0))
}

#[test]
fn a_scripted_touch_flattens_the_fur_where_it_presses_and_nowhere_else() {
    scripted_touch("cpu");
}

/// The same with the strands bent by the GPU simulation's compute pass.
#[test]
fn a_scripted_touch_flattens_the_fur_on_the_gpu_too() {
    scripted_touch("gpu");
}

fn scripted_touch(kernel: &str) {
    // The plane (2 x 2, facing +Y, centred on the origin) is framed in the middle of the 3D view,
    // so the origin lands at the view's centre. The stroke presses there and drags along +X
    // within the first second and holds until after the screenshot.
    let script = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli_view_touch_{kernel}.toml"));
    std::fs::write(
        &script,
        "[[stroke]]\nstart_secs = 0.0\nend_secs = 3.0\nradius = 0.5\n\
         path = [[0.0, 0.0, 0.0], [0.7, 0.0, 0.0], [0.7, 0.0, 0.0], [0.7, 0.0, 0.0]]\n",
    )
    .unwrap();
    // Long upright fur, so a pat shows plainly.
    let preset = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli_view_touch_preset_{kernel}.toml"));
    // In the paper's studio (Kajiya-Kay, the light following the camera, no shadows), where a flattened coat's
    // highlight turns plainest toward the camera.
    std::fs::write(
        &preset,
        "length = 0.2\n[direction]\nrandom_angle_deg = 0.0\ncomb_blend = 0.0\n[shading]\nmodel = \"kajiya-kay\"\n",
    )
    .unwrap();
    let preset = preset.to_str().unwrap();
    let frames = 60;
    // Without the overlay, so only the fur can differ (not the timings or the brush).
    let base = [
        "--builtin",
        "plane",
        "--no-overlay",
        "--preset",
        preset,
        "--sim",
        kernel,
        "--light",
        "camera",
        "--no-shadows",
    ];
    let untouched = screenshot(&format!("untouched-{kernel}"), frames, &base);
    let script = script.to_str().unwrap();
    let touched = screenshot(&format!("touched-{kernel}"), frames, &[&base[..], &["--script", script]].concat());
    let view_centre = ((WIDTH_PX - PANEL_PX) / 2, HEIGHT_PX / 2);
    let around = |half: u32, dy: i32| {
        let y = (view_centre.1 as i32 + dy) as u32;
        (view_centre.0 - half, y - half / 2, view_centre.0 + half, y + half / 2)
    };
    let pressed = mean_difference(&untouched, &touched, around(50, 0));
    // Fur at the plane's left and far corners, well outside the touch radius.
    let left_corner = mean_difference(&untouched, &touched, (75, 315, 135, 335));
    let background = mean_difference(&untouched, &touched, (200, 470, 600, 560));
    println!("{kernel}: pressed {pressed:.2}, left corner {left_corner:.2}, background {background:.2}");
    assert!(pressed > 8.0, "the fur under the touch changed: {pressed:.2}");
    assert!(left_corner < pressed / 8.0, "fur far from the touch stays put: {left_corner:.2} vs {pressed:.2}");
    assert!(background < 0.5, "the background is untouched: {background:.2}");
    let panel = mean_difference(&untouched, &touched, (WIDTH_PX - PANEL_PX + 4, 0, WIDTH_PX, HEIGHT_PX));
    assert!(panel < 0.5, "the panel looks the same: {panel:.2}");
}

/// Runs `pelt view --builtin box ARGS` without a display: it must fail before opening a window;
/// returns its stderr.
fn refused_without_a_window(args: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_pelt"))
        .args(["view", "--builtin", "box"])
        .args(args)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert!(!output.status.success(), "{args:?} was not refused");
    String::from_utf8_lossy(&output.stderr).into_owned()
}

#[test]
fn a_missing_preset_or_script_is_named_before_any_window_opens() {
    for (flag, file) in [("--preset", "no-such-preset.toml"), ("--script", "no-such-scene.toml")] {
        let stderr = refused_without_a_window(&[flag, file]);
        assert!(stderr.contains(file), "{flag}: the error names the file: {stderr}");
    }
}

#[test]
fn an_animated_file_moves_in_the_window() {
    let fox = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes/Fox.glb");
    // The first clip (Survey) plays at 60 fixed frames a second: a second apart, the fox has moved.
    let early = screenshot("fox_early", 3, &[fox]);
    let later = screenshot("fox_later", 63, &[fox]);
    let view = (0, 0, WIDTH_PX - PANEL_PX, HEIGHT_PX);
    let moved = mean_difference(&early, &later, view);
    assert!(moved > 0.5, "the animation moves the fox: mean difference {moved}");
}

/// `--ground` and the Drawing section's switches: the ground under the bunny, and with shadows
/// (on unless `--no-shadows`) the fur's shadow on it and on itself.
#[test]
fn the_window_draws_the_ground_and_the_furs_shadow() {
    let common = ["--builtin", "bunny", "--sim", "cpu", "--no-overlay"];
    let with = |extra: &[&'static str]| common.iter().copied().chain(extra.iter().copied()).collect::<Vec<_>>();
    let shadowed = screenshot("ground_shadows", 4, &with(&["--ground"]));
    let unshadowed = screenshot("ground_no_shadows", 4, &with(&["--ground", "--no-shadows"]));
    let bare = screenshot("no_ground", 4, &common);
    let view = 0..WIDTH_PX - PANEL_PX;
    let count = |a: &image::RgbaImage, b: &image::RgbaImage, by: f64| {
        view.clone()
            .flat_map(|x| (0..HEIGHT_PX).map(move |y| (x, y)))
            .filter(|&(x, y)| luminance(a.get_pixel(x, y)) + by < luminance(b.get_pixel(x, y)))
            .count()
    };
    let ground = count(&bare, &unshadowed, 10.0) + count(&unshadowed, &bare, 10.0);
    assert!(ground > 20_000, "the ground changed {ground} pixels");
    // The sky-ground fill lights the shadow from above: it darkens the ground by less than the
    // key light alone would.
    let darker = count(&shadowed, &unshadowed, 10.0);
    let brighter = count(&unshadowed, &shadowed, 10.0);
    println!("{darker} pixels darker with shadows, {brighter} brighter");
    assert!(darker > 2_000, "{darker} pixels darker with shadows");
    assert!(brighter < darker / 10, "{brighter} pixels brighter, {darker} darker");
}

/// `--light` (the Lights section's first sun): the key light fixed in the world casts the
/// shadow; turned half round, the shadow falls on the other side of the bunny.
#[test]
fn the_windows_key_light_places_the_shadow() {
    let common = ["--builtin", "bunny", "--sim", "cpu", "--no-overlay", "--ground"];
    let with = |light: &'static str| common.iter().copied().chain(["--light", light]).collect::<Vec<_>>();
    let one_side = screenshot("light_40", 4, &with("40,45"));
    let other_side = screenshot("light_220", 4, &with("220,45"));
    let view = 0..WIDTH_PX - PANEL_PX;
    let count = |a: &image::RgbaImage, b: &image::RgbaImage| {
        view.clone()
            .flat_map(|x| (0..HEIGHT_PX).map(move |y| (x, y)))
            .filter(|&(x, y)| luminance(a.get_pixel(x, y)) + 20.0 < luminance(b.get_pixel(x, y)))
            .count()
    };
    // Darker in one picture than in the other, each way: where each shadow falls.
    let (here, there) = (count(&one_side, &other_side), count(&other_side, &one_side));
    assert!(here > 2_000 && there > 2_000, "the shadow did not move with the light: {here} and {there} pixels");
}

/// A herd in the window (a script's `[[instance]]`s): two Foxes side by side, the right one
/// `offset` seconds further into its walk. Each member is drawn and walks on its own: moving the
/// right one's phase changes the right half of the 3D view and leaves the left one's alone.
#[test]
fn the_window_draws_a_herd_each_member_at_its_own_phase() {
    herd_at_phases("cpu");
}

/// The same with every member bent by the GPU simulation (the right Fox is the copy the
/// viewer's herd drives, not the edited fur), pooled as on a GPU: the copy's base skinned on the
/// GPU.
#[test]
fn the_window_draws_a_herd_bent_on_the_gpu() {
    herd_at_phases("gpu");
}

fn herd_at_phases(kernel: &str) {
    let fox = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes/Fox.glb");
    let herd = |name: &str, offset: f32| {
        let name = format!("{name}_{kernel}");
        let script = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("cli_view_{name}.toml"));
        std::fs::write(
            &script,
            format!(
                "[[instance]]\nposition = [-150.0, 0.0, 0.0]\nheading_deg = 90.0\nclip = \"Walk\"\n\n\
                 [[instance]]\nposition = [150.0, 0.0, 0.0]\nheading_deg = 90.0\nclip = \"Walk\"\n\
                 time_offset_secs = {offset}\n"
            ),
        )
        .expect("the script");
        let script = script.to_str().unwrap().to_owned();
        let pooling = if kernel == "gpu" { "on" } else { "auto" };
        let args = [fox, "--script", &script, "--sim", kernel, "--pooling", pooling, "--no-overlay", "--no-shadows"];
        let (image, said) = screenshot_saying(&name, 12, &args);
        // Both furs bent where asked, none fallen back to the CPU.
        let expected = match kernel {
            "gpu" => "bent on the GPU kernel; 1 of the herd's 1 other copies on the GPU, 1 posed there",
            _ => "bent on the CPU kernel; 0 of the herd's 1 other copies on the GPU, 0 posed there",
        };
        assert!(said.contains(expected), "{name}: {said}");
        image
    };
    let together = herd("herd_together", 0.0);
    let apart = herd("herd_apart", 0.35);
    let half = (WIDTH_PX - PANEL_PX) / 2;
    let differing = |x0: u32, x1: u32| {
        (x0..x1)
            .flat_map(|x| (0..HEIGHT_PX).map(move |y| (x, y)))
            .filter(|&(x, y)| (luminance(together.get_pixel(x, y)) - luminance(apart.get_pixel(x, y))).abs() > 8.0)
            .count()
    };
    let (left, right) = (differing(0, half), differing(half, 2 * half));
    println!("{kernel}: {left} pixels of the left half differ, {right} of the right");
    assert!(right > 300, "{right} pixels of the right Fox moved");
    assert!(left * 20 < right, "{left} pixels of the left Fox changed, {right} of the right");
}

/// A herd's bad input stops the viewer before any window opens.
#[test]
fn a_bad_herd_is_refused_before_any_window_opens() {
    for (args, says) in [
        (&["--herd", "0"][..], "--herd 0: a herd needs at least one instance"),
        (&["--herd", "nan"][..], "invalid value 'nan' for '--herd <N>'"),
    ] {
        let stderr = refused_without_a_window(args);
        assert!(stderr.contains(says), "{args:?}: {stderr}");
    }
}
