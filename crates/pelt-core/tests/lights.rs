//! Lights as data: validation naming file and key, keys over time, unit conversion, and the
//! environment's spherical harmonics against a brute-force integral over the sphere.

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use glam::Vec3;
use pelt_core::light::{Environment, LightKind, LightSpec, direction_from_angles};
use pelt_core::preset::{Preset, ShadingModel};
use pelt_core::sim::Scene;

/// `n` directions spread evenly over the sphere (a Fibonacci lattice), each standing for
/// `4 pi / n` steradians: a quadrature that shares nothing with the equirectangular projection.
fn fibonacci_sphere(n: usize) -> Vec<Vec3> {
    let golden = PI * (3.0 - 5f32.sqrt());
    (0..n)
        .map(|i| {
            let y = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
            let r = (1.0 - y * y).max(0.0).sqrt();
            let phi = golden * i as f32;
            Vec3::new(r * phi.cos(), y, r * phi.sin())
        })
        .collect()
}

/// Irradiance on a surface of normal `n` under radiance `radiance`, summed over the lattice.
fn brute_irradiance(radiance: &dyn Fn(Vec3) -> Vec3, n: Vec3) -> Vec3 {
    let directions = fibonacci_sphere(200_000);
    let weight = 4.0 * PI / directions.len() as f32;
    directions.iter().fold(Vec3::ZERO, |sum, &d| sum + radiance(d) * (n.dot(d).max(0.0) * weight))
}

fn normals() -> Vec<Vec3> {
    vec![Vec3::Y, Vec3::NEG_Y, Vec3::X, Vec3::new(0.3, 0.8, -0.5).normalize(), Vec3::new(-0.6, -0.2, 0.7).normalize()]
}

fn assert_close(got: Vec3, want: Vec3, tolerance: f32, what: &str) {
    let error = (got - want).abs().max_element();
    assert!(error <= tolerance * want.max_element().max(1e-3), "{what}: got {got}, brute force {want}");
}

#[test]
fn sky_and_ground_irradiance_matches_the_integral() {
    let (sky, ground) = (Vec3::new(0.5, 0.6, 0.9), Vec3::new(0.2, 0.15, 0.1));
    let environment = Environment::sky_ground(sky, ground);
    let radiance = move |d: Vec3| if d.y > 0.0 { sky } else { ground };
    for n in normals() {
        assert_close(environment.sh.irradiance(n), brute_irradiance(&radiance, n), 0.01, &format!("normal {n}"));
    }
    // A uniform environment's irradiance is pi times its radiance.
    let uniform = Environment::uniform(Vec3::splat(0.5));
    assert_close(uniform.sh.irradiance(Vec3::X), Vec3::splat(0.5 * PI), 1e-4, "uniform");
}

/// An equirectangular image of `radiance`, `width x height`.
fn equirect(radiance: &dyn Fn(Vec3) -> Vec3, width: u32, height: u32) -> Vec<Vec3> {
    (0..height)
        .flat_map(|row| (0..width).map(move |column| (column, row)))
        .map(|(column, row)| radiance(Environment::equirect_direction(column as f32, row as f32, width, height)))
        .collect()
}

#[test]
fn an_images_irradiance_matches_the_integral() {
    // A broad warm lobe from the upper right over a dim blue fill.
    let toward = Vec3::new(0.6, 0.7, 0.3).normalize();
    let radiance =
        move |d: Vec3| Vec3::new(2.0, 1.6, 1.2) * (1.5 * (d.dot(toward) - 1.0)).exp() + Vec3::new(0.05, 0.07, 0.1);
    let image = equirect(&radiance, 256, 128);
    let environment = Environment::from_equirect(&image, 256, 128).unwrap();
    for n in normals() {
        // Nine coefficients hold a lobe this broad to a few percent of its irradiance.
        assert_close(environment.sh.irradiance(n), brute_irradiance(&radiance, n), 0.04, &format!("normal {n}"));
    }
}

fn folder(name: &str) -> PathBuf {
    let folder = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lights").join(name);
    std::fs::create_dir_all(&folder).unwrap();
    folder
}

#[test]
fn an_hdr_image_loads_as_the_radiance_it_holds() {
    let folder = folder("hdr");
    let (sky, ground) = (Vec3::new(1.5, 1.7, 2.0), Vec3::new(0.3, 0.25, 0.2));
    let texels = equirect(&|d: Vec3| if d.y > 0.0 { sky } else { ground }, 128, 64);
    let image = image::Rgb32FImage::from_fn(128, 64, |x, y| {
        let t = texels[(y * 128 + x) as usize];
        image::Rgb([t.x, t.y, t.z])
    });
    let path = folder.join("sky.hdr");
    image::DynamicImage::ImageRgb32F(image).save(&path).unwrap();
    let loaded = Environment::load_image(&path).unwrap();
    let closed_form = Environment::sky_ground(sky, ground);
    for n in normals() {
        assert_close(loaded.sh.irradiance(n), closed_form.sh.irradiance(n), 0.02, &format!("normal {n}"));
    }
}

fn scene_error(name: &str, text: &str) -> String {
    let path = folder(name).join("scene.toml");
    match Scene::from_toml_str(text, &path) {
        Ok(_) => panic!("{name}: accepted"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn bad_lights_and_environments_are_errors_naming_file_and_key() {
    let cases = [
        ("nan", "[[light]]\nlux = nan\n", "light[0].lux"),
        ("negative", "[[light]]\nkind = \"point\"\ncandela = -2.0\n", "light[0].candela"),
        ("cone0", "[[light]]\nkind = \"spot\"\nposition = [0.0, 2.0, 0.0]\ncone_deg = 0.0\n", "light[0].cone_deg"),
        ("cone190", "[[light]]\nkind = \"spot\"\nposition = [0.0, 2.0, 0.0]\ncone_deg = 190.0\n", "light[0].cone_deg"),
        ("sky", "[environment]\nsky = [1.0, -1.0, 1.0]\nground = [0.0, 0.0, 0.0]\n", "environment.sky"),
    ];
    for (name, text, key) in cases {
        let message = scene_error(name, text);
        assert!(message.contains("scene.toml") && message.contains(key), "{name}: {message}");
    }
    let folder = folder("not_an_image");
    std::fs::write(folder.join("notes.hdr"), "these are words, not radiance").unwrap();
    let message = scene_error("not_an_image", "[environment]\nimage = \"notes.hdr\"\n");
    assert!(
        message.contains("scene.toml") && message.contains("environment.image") && message.contains("notes.hdr"),
        "{message}"
    );
}

#[test]
fn a_named_light_moves_between_its_keys() {
    let text = r#"
[[light]]
name = "key"
time_secs = 0.0
azimuth_deg = 0.0
elevation_deg = 30.0
lux = 2.0
[[light]]
name = "key"
time_secs = 2.0
azimuth_deg = 90.0
elevation_deg = 30.0
lux = 4.0
[[light]]
kind = "point"
position = [0.0, 3.0, 0.0]
lumens = 100.0
shadows = false
"#;
    let scene = Scene::from_toml_str(text, Path::new("moving.toml")).unwrap();
    let lights = scene.lights_at(1.0);
    assert_eq!(lights.len(), 2);
    let key = lights[0];
    assert_eq!(key.kind, LightKind::Directional);
    assert!(key.direction.distance(direction_from_angles(45.0, 30.0)) < 1e-5, "{}", key.direction);
    assert!((key.intensity.x - 3.0).abs() < 1e-5);
    assert!(scene.lights_at(5.0)[0].direction.distance(direction_from_angles(90.0, 30.0)) < 1e-5);
    let bulb = lights[1];
    assert_eq!(bulb.kind, LightKind::Point);
    assert!(!bulb.casts_shadows);
    assert!((bulb.intensity.x - 100.0 / (4.0 * PI)).abs() < 1e-4, "lumens over the sphere: {}", bulb.intensity);
    assert_eq!(scene.duration_secs(), 2.0);
    let unsorted = text.replace("time_secs = 2.0", "time_secs = -0.0");
    let unsorted = unsorted.replacen("time_secs = 0.0", "time_secs = 1.0", 1);
    assert!(
        Scene::from_toml_str(&unsorted, Path::new("unsorted.toml"))
            .unwrap_err()
            .to_string()
            .contains("light[1].time_secs")
    );
}

#[test]
fn a_spots_lumens_spread_over_its_cone() {
    let spot = LightSpec {
        kind: LightKind::Spot,
        position: Vec3::new(0.0, 2.0, 0.0),
        lumens: Some(100.0),
        cone_deg: 60.0,
        ..LightSpec::default()
    };
    // The cone's solid angle: 2 pi (1 - cos 30 degrees).
    let candela = 100.0 / (2.0 * PI * (1.0 - (PI / 6.0).cos()));
    assert!((spot.source().intensity.x - candela).abs() < 1e-3 * candela);
    assert!(spot.source().direction.distance(Vec3::NEG_Y) < 1e-6);
}

#[test]
fn shading_table_reads_and_checks() {
    let preset = Preset::from_toml_str("[shading]\nmodel = \"fur\"\nmelanin = 1.0\n", Path::new("fur.toml")).unwrap();
    assert_eq!(preset.shading.model, ShadingModel::Fur);
    let colour = preset.shading.pigment_colour();
    assert!(colour.x > colour.y && colour.y > colour.z, "eumelanin is brown: {colour}");
    let error = Preset::from_toml_str("[shading]\nroughness = 2.0\n", Path::new("rough.toml")).unwrap_err().to_string();
    assert!(error.contains("rough.toml") && error.contains("shading.roughness"), "{error}");
}
