//! Renderer tests on a real adapter (lavapipe in CI). They fail, never skip, without one.

use crate::common;

use common::*;
use glam::Vec3;
use pelt_core::Builtin;
use pelt_render::{Camera, DEFAULT_BACKGROUND, FurDrawSettings, SeparatedFur, SeparatedRenderer};

const SIZE: u32 = 256;

#[test]
fn golden_bunny_still() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    check_golden("bunny-still", &rig.render_in_studio(&gpu_fur, &framed(&fur, 1.0), &settings()));
}

/// The golden tests guard the fins: the bunny and the box without them fail, in the silhouette
/// band (over the whole image a missing fringe is within the limits).
#[test]
fn golden_tests_fail_without_fins() {
    let rig = Rig::new(SIZE, SIZE);
    let no_fins = FurDrawSettings { fins: false, ..settings() };
    for (name, builtin, root, tip) in
        [("bunny-still", Builtin::Bunny, BROWN_ROOT, BROWN_TIP), ("box", Builtin::Box, [40, 40, 44], [235, 235, 240])]
    {
        let fur = builtin_fur(builtin, 16);
        let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, root, tip));
        // The bunny's golden is Pelt's look; the box's the paper's, where its fins' fringe
        // stands out against its flat faces (in Pelt's studio a box without fins passes).
        let camera = framed(&fur, 1.0);
        let image = if name == "box" {
            rig.render(&gpu_fur, &camera, &no_fins)
        } else {
            rig.render_in_studio(&gpu_fur, &camera, &no_fins)
        };
        let difference = golden_difference(name, &image);
        eprintln!("{name} without fins: mean {:.2}, band {:.2}", difference.mean, difference.silhouette_mean);
        assert!(
            !difference.within_limits(),
            "{name} without fins passed the golden test (mean {:.2}, silhouette band {:.2})",
            difference.mean,
            difference.silhouette_mean
        );
    }
}

#[test]
fn golden_box() {
    let fur = builtin_fur(Builtin::Box, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, [40, 40, 44], [235, 235, 240]));
    check_golden("box", &rig.render(&gpu_fur, &framed(&fur, 1.0), &settings()));
}

/// The walking try-on's golden frame: 0.75 s into the walk, mid-stride (the legs wide apart),
/// the skirt skinned to them, its fur colliding with the body's capsules.
const TRYON_WALK_SECS: f64 = 0.75;

/// The walking try-on (`pelt render --builtin tryon`'s stage) at `walk_secs` of `clip` (`None`:
/// standing in the rest pose): the skirt's fur simulated from the start at 30 steps a second,
/// colliding with the body's capsules; the body drawn posed with the same clip.
fn render_walking_tryon(walk_secs: f64, clip: Option<usize>) -> image::RgbaImage {
    use pelt_core::anim::Pose;
    use pelt_core::sim::{FurStepper, SimParams};
    use pelt_core::{ImportOptions, Stage, StageSource};

    let stage = Stage::load(&StageSource::TryOn, &[], &ImportOptions::default()).expect("try-on stage");
    let (rig, body, body_mesh) = (stage.rig.expect("skirt rig"), stage.body.expect("walking body"), &stage.plain[0]);
    let garment = grow(stage.fur_mesh, 16, 0.3);
    let mut stepper = FurStepper::new(&garment, &SimParams::default()).expect("stepper");
    stepper.set_clip(rig, clip);
    stepper.set_body(Some((body_mesh.clone(), body.rig.clone(), body.capsules.clone())));
    let steps = (walk_secs * 30.0).round() as u32;
    for step in 0..=steps {
        stepper.advance_to(f64::from(step) / 30.0).expect("step");
    }
    let time_secs = f64::from(steps) / 30.0;
    let render = Rig::new(SIZE, SIZE);
    let fur = render.fur(&garment, &strand_textures(256, 16, [30, 20, 45], [150, 110, 190]));
    fur.set_positions(render.queue(), stepper.simulation().positions()).expect("positions");
    if let Some(pose) = stepper.moved_pose() {
        fur.set_base_normals(render.queue(), &pose.normals).expect("normals");
    }
    let plain = render.plain(body_mesh, Vec3::new(0.6, 0.45, 0.38));
    let mut body_pose = Pose::default();
    body.rig.pose(body_mesh, clip, time_secs, &mut body_pose);
    plain.set_pose(render.queue(), &body_pose.positions, &body_pose.normals).expect("body pose");
    // Framed on the posed body, from 60 degrees off its walk: the stride and the skirt's front.
    let (low, high) = body_pose
        .positions
        .iter()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(l, h), p| (l.min(*p), h.max(*p)));
    let centre = 0.5 * (low + high);
    let camera = Camera::framing(centre, 0.5 * (high - low).length() * 1.05, 60.0, 10.0, 1.0);
    render.render_scene(&[&plain], Some(&fur), &camera, &settings())
}

#[test]
fn golden_tryon() {
    check_golden("tryon", &render_walking_tryon(TRYON_WALK_SECS, Some(0)));
}

/// The try-on golden guards the walk: the standing body fails it, and so does the body half a
/// step later (the legs the other way round).
#[test]
fn golden_tryon_fails_standing_or_on_another_step() {
    for (what, image) in [
        ("the standing body", render_walking_tryon(TRYON_WALK_SECS, None)),
        ("another step", render_walking_tryon(TRYON_WALK_SECS + 1.0, Some(0))),
    ] {
        let difference = golden_difference("tryon", &image);
        eprintln!(
            "try-on, {what}: mean {:.2}, p99 {}, band {:.2}",
            difference.mean, difference.p99, difference.silhouette_mean
        );
        assert!(!difference.within_limits(), "the try-on with {what} passed its golden test");
    }
}

#[test]
fn golden_bunny_in_wind() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    gpu_fur.set_positions(rig.queue(), golden_wind(&fur).positions()).expect("positions");
    check_golden("bunny-wind", &rig.render_in_studio(&gpu_fur, &framed(&fur, 1.0), &settings()));
}

/// Simulated wind toward the camera's right moves the fur's pixels right, shells and fins alike.
#[test]
fn wind_moves_fur_pixels_in_the_wind_direction() {
    let fur = grow(Builtin::Sphere.mesh().0, 16, 0.25);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    // Looking down -Z, so +X is right in the image.
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 6.0);
    let fur_only = FurDrawSettings { skin: false, ..settings() };
    let background = rig.background();
    let mut centroids = Vec::new();
    for direction in [Vec3::NEG_X, Vec3::X] {
        let simulation = windy_simulation(&fur, direction, 3.0, 6);
        gpu_fur.set_positions(rig.queue(), simulation.positions()).expect("positions");
        centroids.push(centroid_x(&rig.render(&gpu_fur, &camera, &fur_only), background));
    }
    assert!(centroids[1] > centroids[0] + 2.0, "fur follows the wind: centroid x {centroids:?}");
}

/// Fins only add pixels at the silhouette: on a sphere (no inner silhouettes) every pixel they
/// change lies within the fur's reach of the bare sphere's outline.
#[test]
fn fins_change_silhouette_pixels_only() {
    let fur = builtin_fur(Builtin::Sphere, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let camera = framed(&fur, 1.0);
    let with_fins = rig.render(&gpu_fur, &camera, &settings());
    let without = rig.render(&gpu_fur, &camera, &FurDrawSettings { fins: false, ..settings() });
    let bare = rig.render(&gpu_fur, &camera, &FurDrawSettings::SKIN);
    let background = rig.background();
    let inside = |x: u32, y: u32| covered(bare.get_pixel(x, y), background);
    // The outline of the bare sphere, and the fur length in pixels (the sphere has radius 1).
    let outline: Vec<(i64, i64)> = (1..SIZE - 1)
        .flat_map(|y| (1..SIZE - 1).map(move |x| (x, y)))
        .filter(|&(x, y)| {
            inside(x, y) && !(inside(x - 1, y) && inside(x + 1, y) && inside(x, y - 1) && inside(x, y + 1))
        })
        .map(|(x, y)| (i64::from(x), i64::from(y)))
        .collect();
    assert!(outline.len() > 100, "the sphere has an outline");
    let sphere_pixels =
        (outline.iter().map(|p| p.0).max().unwrap() - outline.iter().map(|p| p.0).min().unwrap()) as f32;
    let reach = (fur.lengths[0] * sphere_pixels / 2.0).ceil() as i64 + 3;
    let mut changed = 0;
    for (x, y, pixel) in with_fins.enumerate_pixels() {
        if pixel_difference(pixel, without.get_pixel(x, y)) <= 8 {
            continue;
        }
        changed += 1;
        let (x, y) = (i64::from(x), i64::from(y));
        let near = outline.iter().any(|&(ox, oy)| (ox - x).pow(2) + (oy - y).pow(2) <= reach * reach);
        assert!(near, "fins changed pixel ({x}, {y}) more than {reach} px from the silhouette");
    }
    assert!(changed > 50, "fins change the silhouette ({changed} pixels)");
}

/// The silhouette pass keeps only the edges whose fins show, and drawing those gives the picture
/// of every edge's fin testing itself.
#[test]
fn silhouette_fins_draw_what_every_edge_draws() {
    let fur = builtin_fur(Builtin::Bunny, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let camera = framed(&fur, 1.0);
    let every_edge = rig.render(&gpu_fur, &camera, &settings());
    let silhouette = rig.render_silhouette(&gpu_fur, &camera, &settings());
    let draw = rig.read_u32s(gpu_fur.silhouette_draw().expect("fins"));
    let (indices, kept, edges) = (draw[0], draw[1] as usize, fur.mesh.edges.len());
    assert_eq!(indices, 6 * fur.layers, "one strip of 6L indices per fin");
    // The oracle: the same test on the CPU, from the rest pose (which the GPU has).
    let eye = camera.eye;
    let shown = fur
        .mesh
        .edges
        .iter()
        .zip(&fur.mesh.edge_faces)
        .filter(|([a, b], faces)| {
            let middle = 0.5 * (fur.mesh.positions[*a as usize] + fur.mesh.positions[*b as usize]);
            let to_camera = (eye - middle).normalize();
            let facing: Vec<f32> = faces
                .iter()
                .filter(|&&f| f != pelt_core::mesh::NO_FACE)
                .map(|&f| fur.mesh.face_normal(f as usize).dot(to_camera))
                .collect();
            let silhouette = facing.len() == 2 && facing[0] * facing[1] <= 0.0;
            silhouette || facing.iter().any(|f| f.abs() < pelt_render::FurLook::default().fin_fade_cos)
        })
        .count();
    assert!(kept < edges / 3, "the pass keeps a fraction of the {edges} edges: {kept}");
    assert!(kept.abs_diff(shown) <= shown / 50 + 2, "kept {kept}, the CPU finds {shown}");
    // The fins are really there: without them the picture changes ...
    let without = rig.render(&gpu_fur, &camera, &FurDrawSettings { fins: false, ..settings() });
    let fin_pixels = silhouette.pixels().zip(without.pixels()).filter(|(p, q)| pixel_difference(p, q) > 8).count();
    assert!(fin_pixels > 200, "silhouette fins change {fin_pixels} pixels");
    // ... and the silhouette edges give every edge's picture, up to the order in which
    // overlapping fins blend: the pass appends edges in whatever order the GPU's threads
    // finish, so a few fin pixels may differ from run to run (0 to 105 of some 4,400 on lavapipe).
    // A pass that lost fins would differ on a large share of the fin pixels.
    let changed = every_edge.pixels().zip(silhouette.pixels()).filter(|(p, q)| pixel_difference(p, q) > 8).count();
    eprintln!("silhouette vs every edge: {changed} pixels differ; fins change {fin_pixels}");
    assert!(
        changed * 10 < fin_pixels,
        "{changed} pixels differ between every edge and silhouette edges (fins change {fin_pixels})"
    );
}

/// Coverage: the mean difference from the background, 0 (nothing drawn) to 1.
fn fur_coverage(image: &image::RgbaImage, background: [u8; 3]) -> f64 {
    let total: f64 = image
        .pixels()
        .map(|p| f64::from(p.0.iter().zip(background).map(|(a, b)| a.abs_diff(b)).max().unwrap_or(0)) / 255.0)
        .sum();
    total / f64::from(image.width() * image.height())
}

#[test]
fn more_layers_raise_fur_coverage() {
    let rig = Rig::new(SIZE, SIZE);
    let textures = strand_textures(256, 16, BROWN_ROOT, BROWN_TIP);
    let fur_only = FurDrawSettings { skin: false, fins: false, ..settings() };
    let background = rig.background();
    let mut coverage = Vec::new();
    let mut camera = None;
    for layers in [2, 6, 16] {
        let fur = builtin_fur(Builtin::Torus, layers);
        let camera = *camera.get_or_insert_with(|| framed(&fur, 1.0));
        let gpu_fur = rig.fur(&fur, &textures);
        coverage.push(fur_coverage(&rig.render(&gpu_fur, &camera, &fur_only), background));
    }
    assert!(coverage[0] < coverage[1] && coverage[1] < coverage[2], "coverage by layers 2, 6, 16: {coverage:?}");
}

/// Mean of the largest channel difference per pixel.
fn mean_difference(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    a.pixels().zip(b.pixels()).map(|(p, q)| f64::from(pixel_difference(p, q))).sum::<f64>()
        / f64::from(a.width() * a.height())
}

/// Horizontal centre of the drawn pixels.
fn centroid_x(image: &image::RgbaImage, background: [u8; 3]) -> f64 {
    let (mut sum, mut count) = (0.0, 0.0);
    for (x, _, pixel) in image.enumerate_pixels() {
        if covered(pixel, background) {
            sum += f64::from(x);
            count += 1.0;
        }
    }
    sum / count
}

/// Bending the shared vertices (as the simulation does) moves shells and fins together: fur
/// blown toward the camera's right lands right of the rest pose.
#[test]
fn bent_shared_vertices_move_fur_pixels_that_way() {
    let fur = builtin_fur(Builtin::Sphere, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 5.0);
    let fur_only = FurDrawSettings { skin: false, ..settings() };
    let background = rig.background();
    let rest = centroid_x(&rig.render(&gpu_fur, &camera, &fur_only), background);
    // The camera looks down -Z from +Z, so +X is to the right in the image.
    let v = fur.vertex_count();
    let bent: Vec<Vec3> = fur
        .positions
        .iter()
        .enumerate()
        .map(|(k, p)| *p + Vec3::X * (0.08 * (k / v) as f32 / fur.layers as f32))
        .collect();
    gpu_fur.set_positions(rig.queue(), &bent).expect("positions");
    let blown = centroid_x(&rig.render(&gpu_fur, &camera, &fur_only), background);
    assert!(blown > rest + 1.0, "fur moved right: centroid {rest:.2} -> {blown:.2}");
    let error = gpu_fur.set_positions(rig.queue(), &bent[1..]).expect_err("wrong count");
    assert!(error.to_string().contains("(L + 1) * V"), "{error}");
}

#[test]
fn alpha_to_coverage_draws_the_same_fur() {
    let fur = builtin_fur(Builtin::Torus, 16);
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &strand_textures(256, 16, BROWN_ROOT, BROWN_TIP));
    let camera = framed(&fur, 1.0);
    let background = rig.background();
    let blended = rig.render(&gpu_fur, &camera, &settings());
    let coverage = rig.render(&gpu_fur, &camera, &FurDrawSettings { alpha_to_coverage: true, ..settings() });
    // The same outline; inside, coverage quantised to 4 samples drops the faint strand edges.
    let drawn = |image: &image::RgbaImage| image.pixels().filter(|p| covered(p, background)).count() as f64;
    let (a, b) = (drawn(&blended), drawn(&coverage));
    assert!((a - b).abs() < 0.05 * a, "pixels drawn blended {a}, alpha-to-coverage {b}");
    // A PNG is opaque: coverage decides which samples a strand covers, never the stored alpha.
    for (name, image) in [("blended", &blended), ("alpha-to-coverage", &coverage)] {
        let translucent = image.pixels().filter(|p| p.0[3] != 255).count();
        assert_eq!(translucent, 0, "{name}: {translucent} pixels with alpha below 255");
    }
    // Colour only: the alpha channel is checked above and must not dilute the mean.
    let rgb_difference = |p: &image::Rgba<u8>, q: &image::Rgba<u8>| {
        p.0[..3].iter().zip(&q.0[..3]).map(|(a, b)| a.abs_diff(*b)).max().unwrap_or(0)
    };
    let mean = blended.pixels().zip(coverage.pixels()).map(|(p, q)| f64::from(rgb_difference(p, q))).sum::<f64>()
        / f64::from(SIZE * SIZE);
    assert!(mean > 0.0 && mean < 60.0, "similar but not identical: mean colour difference {mean:.2}");
}

#[test]
fn separated_structure_renders_the_same_scene() {
    let fur = builtin_fur(Builtin::Box, 16);
    let rig = Rig::new(SIZE, SIZE);
    let textures = strand_textures(256, 16, BROWN_ROOT, BROWN_TIP);
    let unified = rig.fur(&fur, &textures);
    let camera = framed(&fur, 1.0);
    let background = rig.background();
    let unified_image = rig.render(&unified, &camera, &settings());
    let separated_renderer = SeparatedRenderer::new(rig.device(), &rig.renderer).expect("separated pipelines");
    for fin_faces in [2, 30] {
        let separated =
            SeparatedFur::new(rig.device(), rig.queue(), &rig.renderer, &fur, &textures, fin_faces).expect("separated");
        separated.prepare(rig.queue(), &common::paper_frame());
        let image = rig
            .headless
            .render(DEFAULT_BACKGROUND, |pass| separated_renderer.draw(pass, &rig.view, &separated, &settings()))
            .expect("frame");
        let (a, b) = (fur_coverage(&unified_image, background), fur_coverage(&image, background));
        assert!((a - b).abs() < 0.1 * a, "{fin_faces}-face fins: coverage unified {a:.3}, separated {b:.3}");
        // The same skin: where neither draws fur, the pictures agree.
        let skin_unified = rig.render(&unified, &camera, &FurDrawSettings::SKIN);
        let skin_separated = rig
            .headless
            .render(DEFAULT_BACKGROUND, |pass| {
                separated_renderer.draw(pass, &rig.view, &separated, &FurDrawSettings::SKIN);
            })
            .expect("frame");
        let skin_difference = mean_difference(&skin_unified, &skin_separated);
        assert!(skin_difference < 0.5, "{fin_faces}: skins differ by {skin_difference:.3} on average");
        let expected_vertices =
            (fur.positions.len() + fur.mesh.edges.len() * 6 * fin_faces.div_ceil(2) as usize) as u64;
        assert_eq!(separated.gpu_bytes().structure(), expected_vertices * 32 + fur.mesh.triangles.len() as u64 * 12);
        assert_eq!(separated.gpu_bytes().textures, unified.gpu_bytes().textures);
    }
}

/// `PELT_TEST_BACKEND` (CI runs the suite on lavapipe and on llvmpipe) really picks that backend.
#[test]
fn adapter_uses_the_requested_backend() {
    let gpu = gpu();
    let backend = gpu.adapter.get_info().backend;
    match std::env::var("PELT_TEST_BACKEND").as_deref() {
        Ok("gl") => assert_eq!(backend, wgpu::Backend::Gl),
        Ok("vulkan") => assert_eq!(backend, wgpu::Backend::Vulkan),
        _ => assert_ne!(backend, wgpu::Backend::Noop),
    }
    eprintln!("adapter: {}", gpu.summary());
}

/// Surface colour mode: grey strands take the mesh texture's colour at their roots.
#[test]
fn surface_colour_tints_strands_by_the_mesh_uvs() {
    let fur = builtin_fur(Builtin::Sphere, 16);
    assert!(fur.mesh.corner_uvs.is_some(), "the sphere has uvs");
    let mut textures = strand_textures(256, 16, [180, 180, 180], [255, 255, 255]);
    // Red and blue stripes across u (around the sphere), each 1/8 of the way round.
    let pixels = (0..8).flat_map(|x| if x % 2 == 0 { [230, 20, 20, 255] } else { [20, 20, 230, 255] }).collect();
    textures.surface = Some(pelt_core::texture::ImageRgba8 { width: 8, height: 1, pixels });
    let rig = Rig::new(SIZE, SIZE);
    let gpu_fur = rig.fur(&fur, &textures);
    let camera = Camera::orbit(Vec3::ZERO, 0.0, 0.0, 5.0);
    let image = rig.render(&gpu_fur, &camera, &settings());
    let reddish = image.pixels().filter(|p| i32::from(p.0[0]) > i32::from(p.0[2]) + 40).count();
    let bluish = image.pixels().filter(|p| i32::from(p.0[2]) > i32::from(p.0[0]) + 40).count();
    assert!(reddish > 500 && bluish > 500, "red {reddish} and blue {bluish} pixels");
}

/// The separated fins are decided a whole fin at a time (Lengyel's fade at the middle of the
/// fin's edge, with the fin's plane normal) and those that do not show are culled. Oracle, from
/// the mesh and the rest strands here, not the shader: drawn alone with an opaque fin texture,
/// every fin whose fade is clearly above 0 covers the pixel at its centre, and most fins whose
/// fade is 0 leave theirs empty. Culling fins with a fade up to 0.9, or drawing the hidden ones
/// at half opacity, fails it (tried once each).
#[test]
fn separated_fins_show_where_lengyels_fade_says() {
    let fur = builtin_fur(Builtin::Box, 4);
    let rig = Rig::new(SIZE, SIZE);
    let mut textures = strand_textures(64, 4, BROWN_ROOT, BROWN_TIP);
    for texel in textures.fin.chunks_exact_mut(4) {
        texel[3] = 255;
    }
    let renderer = SeparatedRenderer::new(rig.device(), &rig.renderer).expect("separated pipelines");
    let separated = SeparatedFur::new(rig.device(), rig.queue(), &rig.renderer, &fur, &textures, 2).expect("fur");
    let frame = common::paper_frame();
    separated.prepare(rig.queue(), &frame);
    let background = rig.background();
    let camera = framed(&fur, 1.0);
    rig.view.prepare(rig.queue(), &camera.view_data(1.0, &pelt_render::Light::default()));
    let fins_only = FurDrawSettings { skin: false, shells: false, fins: true, ..settings() };
    let image = rig
        .headless
        .render(DEFAULT_BACKGROUND, |pass| renderer.draw(pass, &rig.view, &separated, &fins_only))
        .expect("frame");

    let fade_cos = frame.look.fin_fade_cos;
    let clip_from_world = camera.clip_from_world(1.0);
    let (mut shown, mut hidden, mut hidden_drawn) = (0, 0, 0);
    for &[a, b] in &fur.mesh.edges {
        let root = |j: u32| fur.positions[j as usize];
        let tip = |j: u32| fur.positions[fur.index(fur.layers, j) as usize];
        let along = root(b) - root(a);
        let up = (tip(a) - root(a) + tip(b) - root(b)) * 0.5;
        let normal = along.cross(up).normalize();
        let middle = (root(a) + root(b)) * 0.5;
        let facing = normal.dot((camera.eye - middle).normalize()).abs();
        let centre = (root(a) + root(b) + tip(a) + tip(b)) * 0.25;
        let clip = clip_from_world * centre.extend(1.0);
        let ndc = clip.truncate() / clip.w;
        let (x, y) = ((ndc.x * 0.5 + 0.5) * SIZE as f32, (0.5 - ndc.y * 0.5) * SIZE as f32);
        let p = image.get_pixel((x as u32).min(SIZE - 1), (y as u32).min(SIZE - 1)).0;
        let drawn = p.iter().zip(background).any(|(&v, b)| v.abs_diff(b) > 8);
        if facing > 1.0 - 0.4 * fade_cos {
            // Fade above 0.6: the opaque fin covers its centre at least that much.
            shown += 1;
            assert!(drawn, "edge {a}-{b} (|n . v| {facing:.3}) shows but its centre is empty");
        } else if facing < 1.0 - 1.5 * fade_cos {
            hidden += 1;
            hidden_drawn += usize::from(drawn);
        }
    }
    eprintln!("{shown} fins shown, {hidden} hidden ({hidden_drawn} of those centres covered by other fins)");
    assert!(shown >= 10, "only {shown} fins clearly show: the check means little");
    assert!(hidden_drawn * 4 < hidden, "{hidden_drawn} of {hidden} hidden fins' centres are drawn");
}

/// The unified structure's bytes on the GPU are what `Footprint` (the memory table's model)
/// says, with and without uvs (wedges), apart from the two small buffers it leaves out: the fin
/// strip (`6L` indices) and, without uvs, the one dummy uv.
#[test]
fn unified_gpu_bytes_are_the_footprints() {
    let rig = Rig::new(64, 64);
    for (builtin, layers) in [(Builtin::Sphere, 8), (Builtin::Bunny, 16)] {
        let fur = builtin_fur(builtin, layers);
        let gpu_fur = rig.fur(&fur, &strand_textures(64, layers, BROWN_ROOT, BROWN_TIP));
        let footprint = fur.footprint();
        let bytes = gpu_fur.gpu_bytes();
        let has_uvs = fur.mesh.corner_uvs.is_some();
        assert_eq!(bytes.positions, footprint.position_bytes, "{builtin:?}");
        assert_eq!(bytes.attributes, footprint.attribute_bytes + if has_uvs { 0 } else { 8 }, "{builtin:?}");
        assert_eq!(bytes.indices, footprint.index_bytes + 6 * u64::from(layers) * 4, "{builtin:?}");
    }
}
