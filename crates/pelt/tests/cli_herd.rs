//! `pelt render` with a herd: each member walks at its own phase (changing one member's phase
//! changes only its side of the picture), `--herd N` scatters N Foxes on a ground, bends on
//! either kernel, and bad herds are clear errors naming the flag, or the file and key.

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

fn pelt(args: &[&str], dir: &Path) -> Output {
    Command::new(env!("CARGO_BIN_EXE_pelt")).args(args).current_dir(dir).output().expect("run pelt")
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join("cli_herd").join(name);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("temp dir");
    dir
}

fn text(output: &Output) -> String {
    format!("{}{}", String::from_utf8_lossy(&output.stdout), String::from_utf8_lossy(&output.stderr))
}

fn fox() -> String {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes/Fox.glb").to_str().unwrap().to_owned()
}

/// Two Foxes side by side facing the camera's right, the second `offset` seconds into its walk;
/// a fixed camera, the sun straight above (their shadows stay under them), no wind.
fn two_foxes(dir: &Path, name: &str, offset: f32) -> image::RgbaImage {
    two_foxes_with(dir, name, offset, "")
}

/// [`two_foxes`] with `extra` lines in the second Fox's `[[instance]]`.
fn two_foxes_with(dir: &Path, name: &str, offset: f32, extra: &str) -> image::RgbaImage {
    let script = dir.join(format!("{name}.toml"));
    std::fs::write(
        &script,
        format!(
            "[camera]\ntarget = [0.0, 40.0, 0.0]\nazimuth_deg = 0.0\nelevation_deg = 10.0\ndistance = 700.0\n\n\
             [[light]]\nkind = \"directional\"\nazimuth_deg = 0.0\nelevation_deg = 89.0\nlux = 1.0\n\n\
             [[instance]]\nposition = [-150.0, 0.0, 0.0]\nheading_deg = 90.0\nclip = \"Walk\"\n\n\
             [[instance]]\nposition = [150.0, 0.0, 0.0]\nheading_deg = 90.0\nclip = \"Walk\"\ntime_offset_secs = {offset}\n{extra}"
        ),
    )
    .expect("script");
    let png = format!("{name}.png");
    let args = ["render", &fox(), "--script", script.to_str().unwrap(), "--size", "200x100", "--sim", "cpu"];
    let output = pelt(&[&args[..], &["--wind", "0,0,0", "-o", &png]].concat(), dir);
    assert!(output.status.success(), "{}", text(&output));
    assert!(text(&output).contains("a herd of 2 (0 out of view"), "{}", text(&output));
    image::open(dir.join(png)).expect("the PNG").to_rgba8()
}

/// Pixels of columns `columns` that differ by more than a little.
fn differing(a: &image::RgbaImage, b: &image::RgbaImage, columns: std::ops::Range<u32>) -> usize {
    let differs = |x: u32, y: u32| a.get_pixel(x, y).0.iter().zip(b.get_pixel(x, y).0).any(|(p, q)| p.abs_diff(q) > 8);
    columns.flat_map(|x| (0..a.height()).map(move |y| (x, y))).filter(|&(x, y)| differs(x, y)).count()
}

#[test]
fn each_member_walks_at_its_own_phase() {
    let dir = temp_dir("phase");
    let together = two_foxes(&dir, "together", 0.0);
    let apart = two_foxes(&dir, "apart", 0.35);
    // The left Fox is the same in both; the right one is half a stride further on.
    let left = differing(&together, &apart, 0..90);
    let right = differing(&together, &apart, 110..200);
    assert!(right > 100, "{right} pixels of the right Fox moved");
    assert!(left * 20 < right, "{left} pixels of the left Fox changed, {right} of the right");
}

/// Members the camera cannot see are not drawn (the summary counts them), and the one it can is
/// drawn as it is alone: three Foxes 5,000 units apart, against the middle one by itself (no
/// shadows: their map would be fitted to the whole herd).
#[test]
fn members_out_of_view_are_not_drawn() {
    let dir = temp_dir("out-of-view");
    let camera = "[camera]\ntarget = [0.0, 40.0, 0.0]\nazimuth_deg = 0.0\nelevation_deg = 10.0\ndistance = 400.0\n\n\
                  [ground]\nsize = 600.0\nheight = -0.5\n\n";
    let fox_at = |x: f32| format!("[[instance]]\nposition = [{x}, 0.0, 0.0]\nclip = \"Walk\"\n\n");
    let render = |name: &str, script: String| {
        std::fs::write(dir.join(format!("{name}.toml")), script).unwrap();
        let script = format!("{name}.toml");
        let png = format!("{name}.png");
        let args = ["render", &fox(), "--script", &script, "--size", "160x90", "--sim", "cpu", "--no-shadows"];
        let output = pelt(&[&args[..], &["-o", &png]].concat(), &dir);
        assert!(output.status.success(), "{}", text(&output));
        (text(&output), image::open(dir.join(png)).expect("the PNG").to_rgba8())
    };
    let (said, three) = render("three", format!("{camera}{}{}{}", fox_at(-5000.0), fox_at(0.0), fox_at(5000.0)));
    assert!(said.contains("a herd of 3 (2 out of view"), "{said}");
    let (said, one) = render("one", format!("{camera}{}", fox_at(0.0)));
    assert!(said.contains("a herd of 1 (0 out of view"), "{said}");
    let differing = differing(&three, &one, 0..160);
    assert!(differing < 10, "{differing} pixels differ from the middle Fox drawn alone");
}

#[test]
fn herd_n_scatters_foxes_on_a_ground() {
    let dir = temp_dir("scatter");
    let args = ["render", &fox(), "--animation", "Walk", "--size", "160x90", "--sim", "cpu"];
    for n in ["1", "6"] {
        let output = pelt(&[&args[..], &["--herd", n, "-o", &format!("herd{n}.png")]].concat(), &dir);
        assert!(output.status.success(), "{}", text(&output));
        assert!(text(&output).contains(&format!("a herd of {n}")), "{}", text(&output));
    }
    // Framed whole either way, the six stand smaller on more ground: the ground's colour takes a
    // larger share of the picture.
    let ground = |name: &str| {
        let image = image::open(dir.join(name)).expect("the PNG").to_rgba8();
        let grey = |p: &image::Rgba<u8>| p[0].abs_diff(p[1]) < 8 && p[1].abs_diff(p[2]) < 8 && p[0] > 50;
        image.pixels().filter(|p| grey(p)).count() as f64 / f64::from(image.width() * image.height())
    };
    let (one, six) = (ground("herd1.png"), ground("herd6.png"));
    assert!(one > 0.05 && six > one, "ground share: one Fox {one:.3}, six {six:.3}");
}

/// `--sim gpu` bends a herd's strands on the GPU kernel: the walking Foxes' last frame is the CPU
/// kernel's but for a few pixels, while the walk itself moved many more between the frames. With
/// `--pooling on` (a GPU's default) their bases are skinned on the GPU too, to the same picture.
#[test]
fn a_herd_bends_on_the_gpu_kernel_as_on_the_cpu() {
    let dir = temp_dir("gpu");
    let args = ["render", &fox(), "--animation", "Walk", "--herd", "3", "--size", "160x90", "--frames", "6"];
    for (name, sim, pooling, kernel) in [
        ("cpu", "cpu", "off", "on the CPU (a herd"),
        ("gpu", "gpu", "off", "on the GPU (a herd, --sim gpu, posed in one parallel pass"),
        ("posed", "gpu", "on", "on the GPU (a herd, --sim gpu, posed on the GPU"),
    ] {
        let output = pelt(&[&args[..], &["--sim", sim, "--pooling", pooling, "-o", name]].concat(), &dir);
        assert!(output.status.success(), "{}", text(&output));
        assert!(text(&output).contains(kernel), "{}", text(&output));
    }
    let frame =
        |sim: &str, k: u32| image::open(dir.join(sim).join(format!("frame_{k:04}.png"))).expect("PNG").to_rgba8();
    let cpu = frame("cpu", 6);
    let walked = differing(&frame("cpu", 1), &cpu, 0..cpu.width());
    assert!(walked > 200, "the Foxes hardly moved: {walked} pixels");
    for other in ["gpu", "posed"] {
        let kernels = differing(&cpu, &frame(other, 6), 0..cpu.width());
        assert!(kernels * 20 < walked, "{kernels} pixels differ from {other}, {walked} between the frames");
    }
}

#[test]
fn bad_herds_are_clear_errors() {
    let dir = temp_dir("bad");
    let output = pelt(&["render", &fox(), "--herd", "0", "-o", "x.png"], &dir);
    assert!(!output.status.success());
    assert!(text(&output).contains("--herd 0") && text(&output).contains("at least one"), "{}", text(&output));
    std::fs::write(dir.join("nan.toml"), "[[instance]]\nposition = [0.0, nan, 0.0]\n").unwrap();
    let output = pelt(&["render", &fox(), "--script", "nan.toml", "-o", "x.png"], &dir);
    assert!(!output.status.success());
    assert!(text(&output).contains("nan.toml") && text(&output).contains("instance[0].position"), "{}", text(&output));
    std::fs::write(dir.join("gallop.toml"), "[[instance]]\nposition = [0.0, 0.0, 0.0]\nclip = \"Gallop\"\n").unwrap();
    let output = pelt(&["render", &fox(), "--script", "gallop.toml", "-o", "x.png"], &dir);
    assert!(!output.status.success());
    let said = text(&output);
    assert!(said.contains("gallop.toml") && said.contains("instance[0].clip"), "{said}");
    assert!(
        said.contains("Survey") && said.contains("Walk") && said.contains("Run"),
        "the file's clips listed: {said}"
    );
    assert!(!dir.join("x.png").exists(), "nothing drawn");
    let output = pelt(&["render", &fox(), "--script", "gallop.toml", "--herd", "3", "-o", "x.png"], &dir);
    assert!(!output.status.success() && text(&output).contains("use one of them"), "{}", text(&output));
}

/// Sums `value` of each pixel in `columns`.
fn sum_over(image: &image::RgbaImage, columns: std::ops::Range<u32>, value: impl Fn([u8; 4]) -> i64) -> i64 {
    columns.flat_map(|x| (0..image.height()).map(move |y| (x, y))).map(|(x, y)| value(image.get_pixel(x, y).0)).sum()
}

/// A member's `tint` colours its coat alone, and its `length_scale` makes its coat larger on
/// screen; the other Fox stays as it was.
#[test]
fn a_members_tint_and_length_scale_reach_its_coat_only() {
    let dir = temp_dir("tint");
    let plain = two_foxes(&dir, "plain", 0.0);
    let blue = two_foxes_with(&dir, "blue", 0.0, "tint = [0.3, 0.5, 1.0]\n");
    let long = two_foxes_with(&dir, "long", 0.0, "length_scale = 2.0\n");
    for (name, image) in [("blue", &blue), ("long", &long)] {
        let moved = differing(&plain, image, 0..100);
        assert!(moved < 10, "{name}: {moved} pixels of the left Fox moved");
    }
    // Blue over red on the right Fox's pixels: the orange coat turns toward blue.
    let blueness = |image: &image::RgbaImage| sum_over(image, 100..200, |p| i64::from(p[2]) - i64::from(p[0]));
    let (before, after) = (blueness(&plain), blueness(&blue));
    assert!(after > before + 2_000, "blue minus red on the right: {before} plain, {after} tinted");
    // The coat's pixels (red well above blue: neither the grey ground nor the sky).
    let coat =
        |image: &image::RgbaImage, columns| sum_over(image, columns, |p| i64::from(p[0] > p[2].saturating_add(25)));
    let (short, longer) = (coat(&plain, 100..200), coat(&long, 100..200));
    assert!(longer as f64 > 1.07 * short as f64, "coat pixels on the right: {short} plain, {longer} twice as long");
}
