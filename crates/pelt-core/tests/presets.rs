//! Fur presets: defaults, round trips, the shipped files and every kind of bad preset.

use std::path::{Path, PathBuf};

use pelt_core::fur::FurLength;
use pelt_core::texture::{ColourMode, Rgb, Style};
use pelt_core::{Builtin, Preset, PresetError};

fn presets_folder() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/presets")
}

/// A fresh folder under the target directory for files a test writes.
fn scratch(name: &str) -> PathBuf {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("presets").join(name);
    std::fs::create_dir_all(&folder).unwrap();
    folder
}

#[test]
fn an_empty_file_is_the_default_preset() {
    let preset = Preset::from_toml_str("", "empty.toml").unwrap();
    assert_eq!(preset, Preset::default());
    assert_eq!(preset.layers, 16);
    assert!(preset.length > 0.0);
    // Empty tables too.
    let tables = "[direction]\n[texture]\n[colour]\n[simulation]\n[render]\n";
    assert_eq!(Preset::from_toml_str(tables, "tables.toml").unwrap(), Preset::default());
}

#[test]
fn round_trip_through_toml_and_a_file() {
    let mut preset = Preset::default();
    preset.layers = 40;
    preset.length = 0.3;
    preset.texture.style = Style::Random;
    preset.texture.curl_radius = 2.5;
    preset.texture.seed = u64::from(u32::MAX) + 7;
    preset.colour.mode = ColourMode::Height;
    preset.colour.height_colours = vec![Rgb([1, 2, 3]), Rgb([250, 128, 0])];
    preset.simulation.stability = 3.5;
    let text = preset.to_toml_string().unwrap();
    assert!(text.contains("\"#fa8000\""), "colours are written as #rrggbb:\n{text}");
    assert_eq!(Preset::from_toml_str(&text, "memory.toml").unwrap(), preset);

    let file = scratch("round_trip").join("fur.toml");
    preset.save(&file).unwrap();
    let loaded = Preset::load(&file).unwrap();
    assert_eq!(loaded, preset);
    assert_eq!(loaded.file(), file);
    assert_eq!(loaded.to_toml_string().unwrap(), text);
}

#[test]
fn every_shipped_preset_loads_and_they_differ() {
    let mut presets = Vec::new();
    for name in ["mink", "shaggy", "lamb", "spotted", "dyed", "spot", "fox"] {
        let path = presets_folder().join(format!("{name}.toml"));
        let preset = Preset::load(&path).unwrap_or_else(|e| panic!("{e}"));
        presets.push(preset);
    }
    for (i, a) in presets.iter().enumerate() {
        for b in &presets[i + 1..] {
            assert_ne!(a, b);
        }
    }
    let [mink, shaggy, lamb, spotted, dyed, spot, fox] = &presets[..] else { unreachable!() };
    assert!(mink.length < shaggy.length && mink.texture.density > shaggy.texture.density);
    assert!(lamb.texture.curl_radius > 0.0);
    assert!(spotted.texture.pattern.is_some());
    assert_eq!(dyed.colour.mode, ColourMode::Height);
    assert_eq!(spot.colour.mode, ColourMode::Surface);
    assert!(spot.generate_textures().unwrap().surface.is_some(), "spot.toml finds Spot's texture");
    assert_eq!(fox.colour.mode, ColourMode::Surface);
    let fox_surface = fox.colour.surface.as_deref().map(|file| presets_folder().join(file));
    assert!(fox_surface.is_some_and(|path| path.is_file()), "fox.toml names the Fox's texture beside it");
}

#[test]
fn a_shipped_preset_generates_with_its_pattern() {
    let mut preset = Preset::load(presets_folder().join("spotted.toml")).unwrap();
    preset.texture.size = 64;
    preset.layers = 4;
    let textures = preset.generate_textures().unwrap();
    assert_eq!(textures.size, 64);
    // The pattern tints: the tile holds both the tawny ground and the dark spots.
    let reds: Vec<u8> = textures.slice(0).chunks_exact(4).filter(|p| p[3] == 255).map(|p| p[0]).collect();
    assert!(reds.iter().any(|&r| r > 150) && reds.iter().any(|&r| r < 70));
}

#[test]
fn surface_and_gradient_images_resolve_next_to_the_preset() {
    let folder = scratch("images");
    image::save_buffer(folder.join("skin.png"), &[200, 100, 50, 255].repeat(4), 2, 2, image::ColorType::Rgba8).unwrap();
    // A gradient from red (left, root) to blue (right, tip).
    let gradient = [[255, 0, 0, 255], [0, 0, 255, 255]].concat();
    image::save_buffer(folder.join("dye.png"), &gradient, 2, 1, image::ColorType::Rgba8).unwrap();
    let small = "layers = 4\n[texture]\nsize = 32\n";

    std::fs::write(
        folder.join("surface.toml"),
        format!("{small}[colour]\nmode = \"surface\"\nsurface = \"skin.png\"\n"),
    )
    .unwrap();
    let textures = Preset::load(folder.join("surface.toml")).unwrap().generate_textures().unwrap();
    let surface = textures.surface.expect("surface mode passes the image on");
    assert_eq!((surface.width, surface.height), (2, 2));
    assert_eq!(&surface.pixels[0..4], &[200, 100, 50, 255]);

    std::fs::write(folder.join("dye.toml"), format!("{small}[colour]\nmode = \"height\"\ngradient = \"dye.png\"\n"))
        .unwrap();
    let textures = Preset::load(folder.join("dye.toml")).unwrap().generate_textures().unwrap();
    let red_share = |k: u32| {
        let (red, blue) = textures
            .slice(k)
            .chunks_exact(4)
            .filter(|p| p[3] > 128)
            .fold((0u64, 0u64), |(r, b), p| (r + u64::from(p[0]), b + u64::from(p[2])));
        red as f64 / (red + blue) as f64
    };
    assert!(red_share(0) > 0.6 && red_share(3) < 0.2, "{} {}", red_share(0), red_share(3));
}

#[test]
fn length_is_relative_to_the_mesh() {
    let preset =
        Preset::from_toml_str("length = 0.1\nlayers = 12\n[direction]\nrandom_angle_deg = 30\n", "x.toml").unwrap();
    let (mut mesh, _) = Builtin::Box.mesh();
    let radius = mesh.bounding_sphere().1;
    let params = preset.fur_params(&mesh);
    assert_eq!(params.layers, 12);
    assert_eq!(params.length, FurLength::Constant(0.1 * radius));
    assert!((params.direction.random_angle_rad - 30f32.to_radians()).abs() < 1e-6);
    // Twice the mesh, twice the fur.
    mesh.transform(glam::Mat4::from_scale(glam::Vec3::splat(2.0)));
    let FurLength::Constant(scaled) = preset.fur_params(&mesh).length else { panic!("constant length") };
    assert!((scaled - 0.2 * radius).abs() < 1e-5);
}

/// Parses `text` as `bad.toml` and returns the message, checking it names the file and `key`.
fn bad(text: &str, key: &str) -> String {
    let message = match Preset::from_toml_str(text, "furs/bad.toml") {
        Ok(_) => panic!("accepted a bad preset: {text}"),
        Err(error) => error.to_string(),
    };
    assert!(message.contains("bad.toml"), "no file in: {message}");
    assert!(message.contains(key), "no `{key}` in: {message}");
    message
}

#[test]
fn unknown_keys_and_wrong_types_are_named() {
    bad("fur_colour = 3\n", "fur_colour");
    bad("[texture]\ndensty = 0.5\n", "densty");
    bad("[simulation]\nwind_speed = 2.0\n", "wind_speed");
    bad("[colours]\n", "colours");
    let message = bad("layers = \"many\"\n", "layers");
    assert!(message.contains("line 1"), "{message}");
    bad("[texture]\nstyle = \"wavy\"\n", "wavy");
    bad("[colour]\ncolour = \"brown\"\n", "#rrggbb");
    bad("[colour]\nmode = \"plaid\"\n", "plaid");
    bad("length = [1, 2]\n", "length");
}

#[test]
fn out_of_range_values_name_the_key_and_the_range() {
    let cases = [
        ("layers = 0", "layers", "between 1 and 128"),
        ("layers = 129", "layers", "between 1 and 128"),
        ("length = -0.1", "length", "above 0"),
        ("length = nan", "length", "above 0"),
        ("[direction]\nrandom_angle_deg = 95", "direction.random_angle_deg", "between 0 and 80"),
        ("[direction]\ncomb_blend = 2", "direction.comb_blend", "between 0 and 1"),
        ("[texture]\ndensity = 1.5", "texture.density", "between 0 and 1"),
        ("[texture]\ndensity = -0.5", "texture.density", "between 0 and 1"),
        ("[texture]\nsize = 300", "texture.size", "power of two"),
        ("[texture]\nsize = 4096", "texture.size", "power of two from 32 to 2048"),
        ("[texture]\nthickness = 0", "texture.thickness", "between 0.25 and 16"),
        ("[texture]\ncurl_turns = 100", "texture.curl_turns", "between 0 and 16"),
        ("[colour]\nbrightness_variation = 3", "colour.brightness_variation", "between 0 and 1"),
        ("[colour]\nmode = \"height\"", "colour.height_colours", "at least one colour"),
        ("[colour]\nmode = \"surface\"", "colour.surface", "surface mode needs"),
        ("[simulation]\nstability = -1", "simulation.stability", "between"),
        ("[render]\ncamera_elevation_deg = 95", "render.camera_elevation_deg", "between -89 and 89"),
        ("[render.lod]\npixels_per_shell = 0", "render.lod.pixels_per_shell", "between 0.25 and 16"),
        ("[render.lod]\nfacing_start = 1.5", "render.lod.facing_start", "below 1"),
        ("[render.lod]\nfacing_full = 0.3", "render.lod.facing_full", "above facing_start"),
    ];
    for (text, key, range) in cases {
        let message = bad(text, key);
        assert!(message.contains(range), "no range `{range}` in: {message}");
    }
}

#[test]
fn missing_files_are_errors_naming_them() {
    let folder = scratch("missing");
    let missing = PresetError::to_string(&Preset::load(folder.join("nowhere.toml")).unwrap_err());
    assert!(missing.contains("nowhere.toml"), "{missing}");

    let preset = folder.join("spots.toml");
    std::fs::write(&preset, "[texture]\npattern = \"patterns/none.png\"\n").unwrap();
    let message = Preset::load(&preset).unwrap_err().to_string();
    assert!(message.contains("spots.toml") && message.contains("texture.pattern"), "{message}");
    assert!(message.contains("none.png"), "{message}");

    // A file that is there but is no image fails when the textures are made, still named.
    std::fs::write(folder.join("broken.png"), b"not a png").unwrap();
    std::fs::write(&preset, "[texture]\nsize = 32\npattern = \"broken.png\"\n").unwrap();
    let message = Preset::load(&preset).unwrap().generate_textures().unwrap_err().to_string();
    assert!(message.contains("spots.toml") && message.contains("texture.pattern"), "{message}");
}
