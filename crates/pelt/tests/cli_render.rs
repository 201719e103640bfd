//! `pelt render` end to end: the binary on lavapipe (CI) writes PNGs, sequences and GIFs.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

// The golden-image helpers pelt-render's GPU tests use (limits, silhouette band, `PELT_UPDATE_GOLDEN=1`).
use crate::common;

fn pelt(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pelt")).args(args).current_dir(dir).output().expect("run pelt")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_render").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn text(output: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr))
}

/// The fraction of pixels that differ from the corner pixel (the background).
fn drawn_fraction(image: &image::RgbaImage) -> f64 {
    let background = *image.get_pixel(0, 0);
    let drawn = image.pixels().filter(|p| p.0.iter().zip(background.0).any(|(a, b)| a.abs_diff(b) > 6)).count();
    drawn as f64 / f64::from(image.width() * image.height())
}

#[test]
fn no_arguments_but_a_size_render_the_bunny_to_pelt_png() {
    let dir = temp_dir("default");
    let output = pelt(&["render", "--size", "160x120"], &dir);
    assert!(output.status.success(), "{}", text(&output));
    let image = image::open(dir.join("pelt.png")).expect("pelt.png").to_rgba8();
    assert_eq!(image.dimensions(), (160, 120));
    let drawn = drawn_fraction(&image);
    assert!((0.1..0.9).contains(&drawn), "the bunny fills a good part of the frame: {drawn}");
    assert!(text(&output).contains("1 frame of 160x120"), "{}", text(&output));
}

/// The same command gives the same bytes, run after run (the CPU kernel: `--sim auto` picks a
/// kernel by timing). Fins and the view-angle shell list blend in the order the compute passes
/// list them; listed by an atomic append, that order followed the threads' timing and 8 runs
/// of this command gave 5 different images.
#[test]
fn the_same_render_gives_the_same_bytes() {
    let dir = temp_dir("same-bytes");
    let mut images = Vec::new();
    for run in 0..4 {
        let name = format!("run{run}.png");
        let output = pelt(&["render", "--builtin", "bunny", "--size", "160x160", "--sim", "cpu", "-o", &name], &dir);
        assert!(output.status.success(), "{}", text(&output));
        images.push(std::fs::read(dir.join(&name)).expect("the PNG"));
    }
    for (run, image) in images.iter().enumerate().skip(1) {
        assert!(image == &images[0], "run {run} wrote other bytes than run 0");
    }
}

#[test]
fn folders_get_numbered_frames_and_gifs_animate() {
    let dir = temp_dir("sequence");
    let output = pelt(&["render", "--builtin", "box", "--size", "64x48", "--frames", "3", "-o", "frames"], &dir);
    assert!(output.status.success(), "{}", text(&output));
    for k in 1..=3 {
        assert!(dir.join(format!("frames/frame_{k:04}.png")).is_file(), "frame {k}");
    }
    assert!(text(&output).contains("3 frames"), "the summary line: {}", text(&output));
    let output = pelt(&["render", "--builtin", "torus", "--size", "64x48", "--frames", "2", "-o", "fur.gif"], &dir);
    assert!(output.status.success(), "{}", text(&output));
    let file = std::fs::File::open(dir.join("fur.gif")).expect("gif");
    let decoder = image::codecs::gif::GifDecoder::new(std::io::BufReader::new(file)).expect("gif decoder");
    let frames = image::AnimationDecoder::into_frames(decoder).collect_frames().expect("frames");
    assert_eq!(frames.len(), 2);
}

#[test]
fn tryon_draws_the_body_and_the_furry_garment() {
    let dir = temp_dir("tryon");
    let output = pelt(&["render", "--builtin", "tryon", "--size", "96x128", "-o", "tryon.png"], &dir);
    assert!(output.status.success(), "{}", text(&output));
    let image = image::open(dir.join("tryon.png")).expect("tryon.png").to_rgba8();
    assert!(drawn_fraction(&image) > 0.1);
}

/// Pixels far brighter than the pixels around them: luminance (the channels' mean) above the
/// median of its 8 neighbours by more than 45 of 255 and above every one of them.
fn pale_specks(image: &image::RgbaImage) -> Vec<(u32, u32)> {
    let luminance = |x: u32, y: u32| image.get_pixel(x, y).0[..3].iter().map(|&c| f32::from(c)).sum::<f32>() / 3.0;
    let mut specks = Vec::new();
    for y in 1..image.height() - 1 {
        for x in 1..image.width() - 1 {
            let mut around = Vec::with_capacity(8);
            for (dx, dy) in [(0, 0), (1, 0), (2, 0), (0, 1), (2, 1), (0, 2), (1, 2), (2, 2)] {
                around.push(luminance(x + dx - 1, y + dy - 1));
            }
            around.sort_by(f32::total_cmp);
            let median = 0.5 * (around[3] + around[4]);
            let here = luminance(x, y);
            if here > median + 45.0 && here > around[7] {
                specks.push((x, y));
            }
        }
    }
    specks
}

/// With MSAA a fragment is shaded once for the samples it covers, at the pixel's centre even
/// where that lies outside the triangle; interpolated at the centre, the lighting terms, fade
/// and height of a thin shell or fin triangle ran past their corners' values and lit single
/// pixels pale along the silhouette (the default 4x on GPUs: 16 such pixels in this frame, 0
/// once the fur's varyings are interpolated at the centroid of the covered samples).
#[test]
fn msaa_leaves_no_pale_specks_on_the_fur() {
    let dir = temp_dir("msaa-specks");
    let output = pelt(&["render", "--size", "960x540", "--msaa", "4", "-o", "msaa.png"], &dir);
    assert!(output.status.success(), "{}", text(&output));
    let specks = pale_specks(&png(&dir, "msaa.png"));
    assert!(specks.len() <= 6, "{} pale specks, e.g. at {:?}", specks.len(), &specks[..specks.len().min(8)]);
}

#[test]
fn bad_arguments_are_clear_errors() {
    let dir = temp_dir("errors");
    let cases: [(&[&str], &str); 4] = [
        (&["render", "--size", "0x10"], "WIDTHxHEIGHT"),
        (&["render", "--backend", "glide"], "unknown backend"),
        (&["render", "--frames", "4", "-o", "one.png"], "folder or a .gif"),
        (&["render", "missing.obj"], "missing.obj"),
    ];
    for (args, message) in cases {
        let output = pelt(args, &dir);
        assert!(!output.status.success(), "{args:?} should fail");
        assert!(text(&output).contains(message), "{args:?}: {}", text(&output));
    }
}

/// `--sim gpu` draws what `--sim cpu` draws (a windy sequence, so the fur moves), and the summary
/// says which kernel ran; `auto` says what it measured.
#[test]
fn the_gpu_simulation_renders_what_the_cpu_one_does() {
    let dir = temp_dir("sim");
    let common = ["render", "--builtin", "bunny", "--size", "128x96", "--frames", "4", "--wind", "2,0,1"];
    let mut frames = Vec::new();
    for kernel in ["cpu", "gpu"] {
        let output = pelt(&[&common[..], &["--sim", kernel, "-o", kernel]].concat(), &dir);
        assert!(output.status.success(), "{}", text(&output));
        let upper = kernel.to_ascii_uppercase();
        assert!(text(&output).contains(&format!("on the {upper} (--sim {kernel})")), "{}", text(&output));
        frames.push(image::open(dir.join(kernel).join("frame_0004.png")).expect("frame").to_rgba8());
    }
    let differing = frames[0].pixels().zip(frames[1].pixels()).filter(|(a, b)| a != b).count();
    let fraction = differing as f64 / f64::from(frames[0].width() * frames[0].height());
    assert!(fraction < 0.01, "{:.2}% of the pixels differ between the kernels", fraction * 100.0);
    let output = pelt(&["render", "--builtin", "box", "--size", "32x32", "--sim", "auto"], &dir);
    assert!(output.status.success(), "{}", text(&output));
    assert!(text(&output).contains("(auto: GPU "), "{}", text(&output));
}

fn png(dir: &Path, name: &str) -> image::RgbaImage {
    image::open(dir.join(name)).unwrap_or_else(|e| panic!("{name}: {e}")).to_rgba8()
}

/// Pixels whose colour differs by more than a small amount.
fn differing_fraction(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    let differ =
        a.pixels().zip(b.pixels()).filter(|(p, q)| p.0.iter().zip(q.0).any(|(x, y)| x.abs_diff(y) > 24)).count();
    differ as f64 / f64::from(a.width() * a.height())
}

/// The rows `[top, bottom)` where either image draws anything (differs from its corner pixel).
fn drawn_rows(a: &image::RgbaImage, b: &image::RgbaImage) -> (u32, u32) {
    let drawn_row = |y: u32| {
        [a, b].iter().any(|image| {
            let background = image.get_pixel(0, 0).0;
            (0..image.width())
                .any(|x| image.get_pixel(x, y).0[..3].iter().zip(background).any(|(p, q)| p.abs_diff(q) > 6))
        })
    };
    let rows: Vec<u32> = (0..a.height()).filter(|&y| drawn_row(y)).collect();
    (rows[0], rows[rows.len() - 1] + 1)
}

/// Of the pixels in rows `[top, bottom)`, the fraction whose colour differs by more than a small amount.
fn differing_fraction_in_rows(a: &image::RgbaImage, b: &image::RgbaImage, top: u32, bottom: u32) -> f64 {
    let (mut differ, mut all) = (0_u32, 0_u32);
    for y in top..bottom {
        for x in 0..a.width() {
            all += 1;
            differ += u32::from(a.get_pixel(x, y).0.iter().zip(b.get_pixel(x, y).0).any(|(p, q)| p.abs_diff(q) > 24));
        }
    }
    f64::from(differ) / f64::from(all)
}

#[test]
fn the_fox_walks_and_unknown_animations_list_the_real_ones() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let fox = root.join("assets/meshes/Fox.glb");
    let fox = fox.to_str().unwrap();
    let dir = temp_dir("fox");
    // Walk frames 1 and 6 (a sixth of a second apart); `--sim cpu` so the golden frame does not
    // depend on which kernel `auto` picks. `none` renders the rest pose.
    let walk = ["render", fox, "--animation", "Walk", "--size", "160x120", "--frames", "6", "--sim", "cpu", "--no-lod"];
    let output = pelt(&[&walk[..], &["-o", "walk"]].concat(), &dir);
    assert!(output.status.success(), "{}", text(&output));
    let output = pelt(&["render", fox, "--animation", "none", "--size", "160x120", "-o", "rest.png"], &dir);
    assert!(output.status.success(), "{}", text(&output));
    let (first, later) = (png(&dir, "walk/frame_0001.png"), png(&dir, "walk/frame_0006.png"));
    let moved = differing_fraction(&first, &later);
    assert!(moved > 0.01, "the walk moves the fox: {moved}");
    // The legs swing and the back barely moves: the lower 40% of the rows the fox covers
    // (the legs, in this side view) change far more than the upper 40% (back, head, tail).
    let (top, bottom) = drawn_rows(&first, &later);
    let band = (bottom - top) * 2 / 5;
    let legs = differing_fraction_in_rows(&first, &later, bottom - band, bottom);
    let back = differing_fraction_in_rows(&first, &later, top, top + band);
    eprintln!("fox rows {top}..{bottom}: legs differ {legs:.4}, back differs {back:.4}");
    assert!(legs > 0.05, "the legs move between walk frames: {legs:.4}");
    assert!(legs > 2.0 * back, "the legs move more than the back: legs {legs:.4}, back {back:.4}");
    // Mid-walk with the default fur, against a golden frame (lavapipe; `PELT_UPDATE_GOLDEN=1`
    // rewrites it). The same frame with the fur cut to almost nothing fails it.
    common::check_golden("fox-walk", &later);
    let bald = dir.join("bald.toml");
    std::fs::write(&bald, "layers = 2\nlength = 0.001\n").expect("bald preset");
    let output = pelt(&[&walk[..], &["--preset", bald.to_str().unwrap(), "-o", "bald"]].concat(), &dir);
    assert!(output.status.success(), "{}", text(&output));
    let difference = common::golden_difference("fox-walk", &png(&dir, "bald/frame_0006.png"));
    eprintln!(
        "bald fox against fox-walk: mean {:.2}, silhouette band mean {:.2}",
        difference.mean, difference.silhouette_mean
    );
    assert!(
        !difference.within_limits(),
        "the fox without fur passed the golden test (mean {:.2}, silhouette band {:.2})",
        difference.mean,
        difference.silhouette_mean
    );
    let output = pelt(&["render", fox, "--animation", "Dance", "-o", "x.png"], &dir);
    assert!(!output.status.success());
    assert!(text(&output).contains("Survey") && text(&output).contains("Walk"), "{}", text(&output));
    let output = pelt(&["render", "--builtin", "torus", "--animation", "Walk", "-o", "x.png"], &dir);
    assert!(!output.status.success() && text(&output).contains("no animations"), "{}", text(&output));
}

#[test]
fn the_try_on_body_walks_and_the_skirt_goes_with_it() {
    let dir = temp_dir("tryon-walk");
    // Half a second apart: a quarter of the walk cycle, the legs in another place.
    let args = ["render", "--builtin", "tryon", "--fps", "2", "--frames", "2", "--size", "96x128"];
    let walking = pelt(&[&args[..], &["-o", "walk"]].concat(), &dir);
    assert!(walking.status.success(), "{}", text(&walking));
    let still = pelt(&[&args[..], &["--animation", "none", "-o", "still"]].concat(), &dir);
    assert!(still.status.success(), "{}", text(&still));
    let moved = |folder: &str| {
        differing_fraction(
            &png(&dir, &format!("{folder}/frame_0001.png")),
            &png(&dir, &format!("{folder}/frame_0002.png")),
        )
    };
    let (walk, rest) = (moved("walk"), moved("still"));
    assert!(walk > 0.02 && walk > 4.0 * rest, "walking changes {walk} of the image, standing still {rest}");
}

/// The walking try-on's body collides with the skirt through capsules, drawn over the body only
/// with `--show-colliders`: the default frame differs from the one that draws them.
#[test]
fn the_body_capsules_are_drawn_only_when_asked() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let script = root.join("assets/scenes/catwalk.toml");
    let dir = temp_dir("show-colliders");
    // The second frame, half a second in: the capsules are posed from the first step on.
    let script = script.to_str().unwrap();
    let args = ["render", "--builtin", "tryon", "--script", script, "--size", "120x160", "--fps", "2", "--frames", "2"];
    // One kernel for both, so only the capsules can tell the frames apart.
    let args = [&args[..], &["--sim", "cpu"]].concat();
    let plain = pelt(&[&args[..], &["-o", "plain"]].concat(), &dir);
    assert!(plain.status.success(), "{}", text(&plain));
    let shown = pelt(&[&args[..], &["--show-colliders", "-o", "shown"]].concat(), &dir);
    assert!(shown.status.success(), "{}", text(&shown));
    let (plain, shown) = (png(&dir, "plain/frame_0002.png"), png(&dir, "shown/frame_0002.png"));
    let differ = differing_fraction(&plain, &shown);
    // The capsules cover part of the body (1.4% of this frame), not the frame.
    assert!(differ > 0.005 && differ < 0.5, "the capsules change {differ} of the frame: drawn by default, or never");
}

#[test]
fn the_catwalk_script_moves_the_body_and_the_skirt_together() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let script = root.join("assets/scenes/catwalk.toml");
    let dir = temp_dir("catwalk");
    // Frames at 0, 2, 4 and 6 seconds: walking, turned, walking back.
    let args = ["render", "--builtin", "tryon", "--script", script.to_str().unwrap(), "--fps", "0.5", "--frames", "4"];
    let output = pelt(&[&args[..], &["--size", "96x128", "-o", "cat"]].concat(), &dir);
    assert!(output.status.success(), "{}", text(&output));
    let frames: Vec<_> = (1..=4).map(|k| png(&dir, &format!("cat/frame_{k:04}.png"))).collect();
    for pair in frames.windows(2) {
        assert!(differing_fraction(&pair[0], &pair[1]) > 0.01, "every frame shows her elsewhere");
    }
}

/// On GL (llvmpipe through EGL) the fur draws what Vulkan draws: the key light's shadow on a
/// furred sphere and its ground, a coat of 24 shells (a multiple of six square layers), and a
/// pooled herd. wgpu's GL backend guesses a texture's kind from its layers (one: a plain 2D
/// texture; a multiple of six, square: a cube map), so array textures of such sizes read 0 there
/// (the whole coat shadowed, the lamb's shells black) unless they get a layer more; and naga's
/// GLSL drops a last member's `@size`, which put every pooled copy past the first at the wrong
/// object. The CPU kernel on both (`auto` may pick either kernel, whose pictures differ a little).
#[test]
fn gl_draws_the_shadows_shells_and_herds_vulkan_draws() {
    let dir = temp_dir("gl");
    let cases: [(&str, &[&str]); 3] = [
        ("shadowed", &["--builtin", "sphere", "--ground"]),
        ("lamb", &["--preset", concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/presets/lamb.toml"), "--no-shadows"]),
        (
            "herd",
            &[
                concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes/Fox.glb"),
                "--animation",
                "Walk",
                "--herd",
                "4",
                "--pooling",
                "on",
            ],
        ),
    ];
    for (name, args) in cases {
        for backend in ["vulkan", "gl"] {
            let out = format!("{name}-{backend}.png");
            let output = pelt(
                &[&["render", "--size", "128x128", "--sim", "cpu", "--backend", backend, "-o", &out][..], args]
                    .concat(),
                &dir,
            );
            assert!(output.status.success(), "{}", text(&output));
            let said = if backend == "gl" { "(Gl," } else { "(Vulkan," };
            assert!(text(&output).contains(said), "{}", text(&output));
        }
        let (vulkan, gl) = (png(&dir, &format!("{name}-vulkan.png")), png(&dir, &format!("{name}-gl.png")));
        let channels = vulkan.as_raw().iter().zip(gl.as_raw());
        let mean = channels.map(|(a, b)| f64::from(a.abs_diff(*b))).sum::<f64>() / vulkan.as_raw().len() as f64;
        let differing = differing_fraction(&vulkan, &gl);
        assert!(
            mean < 0.5 && differing < 0.01,
            "{name}: GL differs from Vulkan by {mean:.2} levels, {differing:.4} of pixels"
        );
    }
}
