//! Lights as data: validation naming file and key, keys over time, unit conversion, and the
//! environment's spherical harmonics against a brute-force integral over the sphere.

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use glam::{Mat3, Vec3};
use pelt_core::light::{CubeContent, Environment, LightKind, LightSpec, direction_from_angles};
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

/// The face and texel coordinates (0..1, rows from the top) a cube texture looks up along `d`:
/// the major axis and the `sc`, `tc` table of the Vulkan specification (cube map face
/// selection), written out here for the oracle.
fn cube_lookup(d: Vec3) -> (usize, f32, f32) {
    let a = d.abs();
    let (face, sc, tc, ma) = if a.x >= a.y && a.x >= a.z {
        if d.x > 0.0 { (0, -d.z, -d.y, a.x) } else { (1, d.z, -d.y, a.x) }
    } else if a.y >= a.z {
        if d.y > 0.0 { (2, d.x, d.z, a.y) } else { (3, d.x, -d.z, a.y) }
    } else if d.z > 0.0 {
        (4, d.x, -d.y, a.z)
    } else {
        (5, -d.x, -d.y, a.z)
    };
    (face, 0.5 * (sc / ma + 1.0), 0.5 * (tc / ma + 1.0))
}

/// A cube map of `radiance`, six faces of `size x size`.
fn cube(radiance: &dyn Fn(Vec3) -> Vec3, size: u32) -> Vec<Vec3> {
    (0..6)
        .flat_map(|face| (0..size * size).map(move |i| (face, i % size, i / size)))
        .map(|(face, column, row)| radiance(Environment::cube_direction(face, column as f32, row as f32, size)))
        .collect()
}

#[test]
fn a_cubes_texels_lie_where_a_cube_texture_looks_them_up() {
    let size = 4;
    for face in 0..6 {
        for (column, row) in (0..size).flat_map(|c| (0..size).map(move |r| (c, r))) {
            let d = Environment::cube_direction(face, column as f32, row as f32, size);
            assert!((d.length() - 1.0).abs() < 1e-6, "{d}");
            let (looked_up, u, v) = cube_lookup(d);
            let want = ((column as f32 + 0.5) / size as f32, (row as f32 + 0.5) / size as f32);
            assert_eq!(looked_up, face, "texel ({column}, {row}) of face {face} along {d}");
            assert!((u - want.0).abs() < 1e-5 && (v - want.1).abs() < 1e-5, "face {face}: ({u}, {v}) for {want:?}");
        }
    }
}

#[test]
fn a_constant_cube_is_the_uniform_environment() {
    let radiance = Vec3::new(0.2, 0.5, 1.5);
    let uniform = 4.0 * PI * 0.282_094_8 * radiance;
    for content in [CubeContent::Radiance, CubeContent::Irradiance] {
        let environment = Environment::from_cube_faces(&vec![radiance; 6 * 3 * 3], 3, content).unwrap();
        let c = environment.sh.coefficients;
        assert!((c[0] - uniform).abs().max_element() < 1e-4, "{content:?}: {} against {uniform}", c[0]);
        assert!(c[1..].iter().all(|k| k.abs().max_element() < 1e-4), "{content:?}: {c:?}");
    }
}

#[test]
fn a_cube_bright_only_on_top_is_a_sky() {
    let size = 16;
    let texels: Vec<Vec3> =
        (0..6 * size * size).map(|i| if i / (size * size) == 2 { Vec3::ONE } else { Vec3::ZERO }).collect();
    let c = Environment::from_cube_faces(&texels, size, CubeContent::Radiance).unwrap().sh.coefficients;
    // The top face holds a sixth of the sphere; its cosine to +Y integrates to pi times the form
    // factor of a unit square's centre to the parallel face at distance 1 (four corner-rectangle
    // form factors): 2 sqrt 2 atan(1 / sqrt 2).
    let want_0 = 0.282_094_8 * 4.0 * PI / 6.0;
    let want_y = 0.488_602_5 * 2.0 * 2f32.sqrt() * (1.0 / 2f32.sqrt()).atan();
    assert!((c[0].x - want_0).abs() < 1e-4 && (c[1].x - want_y).abs() < 1e-4, "{} {}", c[0], c[1]);
    // Symmetric about +Y: the terms odd in x or z vanish.
    for k in [2, 3, 4, 5, 7] {
        assert!(c[k].abs().max_element() < 1e-5, "coefficient {k}: {}", c[k]);
    }
    let environment = Environment::from_cube_faces(&texels, size, CubeContent::Radiance).unwrap();
    assert!(environment.sh.irradiance(Vec3::Y).x > 4.0 * environment.sh.irradiance(Vec3::NEG_Y).x.abs());
}

#[test]
fn a_cubes_irradiance_matches_the_integral() {
    let toward = Vec3::new(-0.3, 0.5, 0.8).normalize();
    let radiance =
        move |d: Vec3| Vec3::new(1.2, 1.6, 2.0) * (1.5 * (d.dot(toward) - 1.0)).exp() + Vec3::new(0.1, 0.07, 0.05);
    let environment = Environment::from_cube_faces(&cube(&radiance, 32), 32, CubeContent::Radiance).unwrap();
    for n in normals() {
        assert_close(environment.sh.irradiance(n), brute_irradiance(&radiance, n), 0.04, &format!("normal {n}"));
    }
}

#[test]
fn an_irradiance_cube_gives_back_the_radiance_it_was_made_from() {
    // A sky over a ground shows a white Lambertian surface tilted toward d the mean of the two
    // plus half their difference times d.y: the sky view factor (1 + cos tilt) / 2.
    let (sky, ground) = (Vec3::new(0.5, 0.6, 0.9), Vec3::new(0.2, 0.15, 0.1));
    let diffuse = move |d: Vec3| (sky + ground) * 0.5 + (sky - ground) * (0.5 * d.y);
    let environment = Environment::from_cube_faces(&cube(&diffuse, 16), 16, CubeContent::Irradiance).unwrap();
    let radiance = move |d: Vec3| if d.y > 0.0 { sky } else { ground };
    for n in normals() {
        assert_close(environment.sh.irradiance(n), brute_irradiance(&radiance, n), 0.01, &format!("normal {n}"));
    }
}

#[test]
fn a_transformed_environment_arrives_from_the_carried_directions() {
    let (sky, ground) = (Vec3::new(0.5, 0.6, 0.9), Vec3::new(0.2, 0.15, 0.1));
    let environment = Environment::sky_ground(sky, ground);
    // Half a turn about X puts the sky below.
    let upside_down = environment.transformed(Mat3::from_rotation_x(PI));
    for n in normals() {
        let want = Environment::sky_ground(ground, sky).sh.irradiance(n);
        assert_close(upside_down.sh.irradiance(n), want, 0.01, &format!("normal {n}"));
    }
    // A mirror through z = 0 sends a lobe toward +Z to -Z.
    let lobe = |d: Vec3| Vec3::splat((2.0 * (d.z - 1.0)).exp());
    let toward_z = Environment::from_cube_faces(&cube(&lobe, 16), 16, CubeContent::Radiance).unwrap();
    let mirrored = toward_z.transformed(Mat3::from_diagonal(Vec3::new(1.0, 1.0, -1.0)));
    assert!(mirrored.sh.irradiance(Vec3::NEG_Z).x > 3.0 * mirrored.sh.irradiance(Vec3::Z).x);
    assert_close(mirrored.sh.irradiance(Vec3::NEG_Z), toward_z.sh.irradiance(Vec3::Z), 0.01, "mirrored");
    // A matrix that is neither a rotation nor a reflection changes nothing.
    assert_eq!(environment.transformed(Mat3::from_diagonal(Vec3::splat(2.0))), environment);
    assert_eq!(environment.transformed(Mat3::from_diagonal(Vec3::splat(f32::NAN))), environment);
}

#[test]
fn bad_cubes_are_errors() {
    let short = Environment::from_cube_faces(&[Vec3::ONE; 5], 1, CubeContent::Radiance).unwrap_err().to_string();
    assert!(short.contains("5 texels") && short.contains("1x1"), "{short}");
    let empty = Environment::from_cube_faces(&[], 0, CubeContent::Radiance).unwrap_err().to_string();
    assert!(empty.contains("0x0"), "{empty}");
    let mut texels = vec![Vec3::ONE; 6 * 4];
    texels[13] = Vec3::new(0.0, f32::NAN, 0.0);
    let nan = Environment::from_cube_faces(&texels, 2, CubeContent::Irradiance).unwrap_err().to_string();
    assert!(nan.contains("texel 1 of face 3") && nan.contains("not finite"), "{nan}");
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
