//! Groomed furs on the GPU: bald triangles draw no shells and bald edges no fins.

use crate::common;

use std::path::Path;

use common::{Rig, load_asset, out_dir, pixel_difference, strand_textures};
use glam::{Vec3, Vec4Swizzles as _};
use pelt_core::sim::pick;
use pelt_core::{FurStructure, Preset};
use pelt_render::{Camera, DEFAULT_BACKGROUND, FurDrawSettings, Light, SeparatedFur, SeparatedRenderer};

const SIZE_PX: u32 = 192;
/// Red roots, green tips: fur drawn over the root-coloured skin shows.
const ROOT: [u8; 3] = [170, 40, 30];
const TIP: [u8; 3] = [40, 200, 60];

/// The Fox grown with `fox_groomed.toml` (bald nose and eyes).
fn groomed_fox() -> FurStructure {
    let preset_file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/presets/fox_groomed.toml");
    let preset = Preset::load(&preset_file).expect("fox_groomed.toml");
    preset.grow(load_asset("Fox.glb"), "Fox.glb").expect("groomed Fox")
}

/// A camera in front of the Fox's face (the Fox looks along +Z), framing its head.
fn face_camera(fur: &FurStructure) -> Camera {
    let positions = &fur.mesh.positions;
    let nose_z = positions.iter().map(|p| p.z).fold(f32::MIN, f32::max);
    let (_, radius) = fur.mesh.bounding_sphere();
    let head: Vec<Vec3> = positions.iter().copied().filter(|p| p.z > nose_z - 0.3 * radius).collect();
    let centre = head.iter().copied().sum::<Vec3>() / head.len() as f32;
    Camera::framing_points(centre, head, 0.0, 0.0, 5.0, 1.0)
}

/// The pixels whose ray meets a bald triangle first, and every pixel within `margin` of them too
/// (so fur standing on the furred triangles around cannot reach in): found by ray casting the
/// base mesh on the CPU, sharing nothing with the renderer.
fn bald_pixels(fur: &FurStructure, camera: &Camera, margin: i32) -> Vec<(u32, u32)> {
    let world_from_clip = camera.clip_from_world(1.0).inverse();
    let size = SIZE_PX as i32;
    let bald: Vec<bool> = (0..size * size)
        .map(|k| {
            let (x, y) = (k % size, k / size);
            let ndc = |z: f32| {
                let x_ndc = (x as f32 + 0.5) / SIZE_PX as f32 * 2.0 - 1.0;
                let y_ndc = 1.0 - (y as f32 + 0.5) / SIZE_PX as f32 * 2.0;
                let world = world_from_clip * glam::Vec4::new(x_ndc, y_ndc, z, 1.0);
                world.xyz() / world.w
            };
            let (near, far) = (ndc(0.0), ndc(1.0));
            pick(&fur.mesh.positions, &fur.mesh.triangles, near, far - near)
                .is_some_and(|hit| !fur.triangle_has_fur(hit.triangle as usize))
        })
        .collect();
    let is_bald = |x: i32, y: i32| x >= 0 && y >= 0 && x < size && y < size && bald[(y * size + x) as usize];
    (0..size * size)
        .map(|k| (k % size, k / size))
        .filter(|&(x, y)| (-margin..=margin).all(|dy| (-margin..=margin).all(|dx| is_bald(x + dx, y + dy))))
        .map(|(x, y)| (x as u32, y as u32))
        .collect()
}

/// Where the Fox's face is bald, drawing the whole fur (skin, shells, silhouette fins) leaves the
/// skin as the skin alone draws it: no shell or fin fragment lands there. Drawing the bald
/// triangles' shells (at zero height, on the skin) paints strands over it.
#[test]
fn bald_triangles_draw_no_fur_pixels() {
    let fur = groomed_fox();
    assert!(fur.furred_triangles().len() < fur.mesh.triangles.len(), "the groom has bald triangles");
    let camera = face_camera(&fur);
    let mask = bald_pixels(&fur, &camera, 2);
    assert!(mask.len() >= 40, "the bald face shows in {} pixels only", mask.len());

    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let gpu_fur = rig.fur(&fur, &strand_textures(64, fur.layers, ROOT, TIP));
    let skin = rig.render(&gpu_fur, &camera, &FurDrawSettings::SKIN);
    let whole = rig.render_silhouette(&gpu_fur, &camera, &FurDrawSettings::ALL);
    let dir = out_dir();
    skin.save(dir.join("groomed-fox-face-skin.png")).expect("save");
    whole.save(dir.join("groomed-fox-face.png")).expect("save");

    let furred = mask.iter().filter(|&&(x, y)| pixel_difference(skin.get_pixel(x, y), whole.get_pixel(x, y)) > 8);
    let furred = furred.count();
    assert!(
        furred * 100 <= mask.len(),
        "{furred} of the {} bald pixels show fur (images in {})",
        mask.len(),
        dir.display()
    );
}

/// The separated baseline grows the same groom: its bald triangles draw no shells and its bald
/// edges no fins either (`bald_triangles_draw_no_fur_pixels` on `SeparatedFur`), while the
/// rest of the face keeps its fur.
#[test]
fn separated_baseline_is_groomed_too() {
    let fur = groomed_fox();
    let camera = face_camera(&fur);
    let mask = bald_pixels(&fur, &camera, 2);
    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let separated_renderer = SeparatedRenderer::new(rig.device(), &rig.renderer).expect("separated renderer");
    let textures = strand_textures(64, fur.layers, ROOT, TIP);
    let separated = SeparatedFur::new(rig.device(), rig.queue(), &rig.renderer, &fur, &textures, 8).expect("separated");
    separated.prepare(rig.queue(), &common::paper_frame());
    rig.view.prepare(rig.queue(), &camera.view_data(1.0, &Light::default()));
    let draw = |settings: &FurDrawSettings| {
        rig.headless
            .render(DEFAULT_BACKGROUND, |pass| separated_renderer.draw(pass, &rig.view, &separated, settings))
            .expect("frame")
    };
    let (skin, whole) = (draw(&FurDrawSettings::SKIN), draw(&FurDrawSettings::ALL));
    let dir = out_dir();
    whole.save(dir.join("groomed-fox-face-separated.png")).expect("save");
    let furred = mask.iter().filter(|&&(x, y)| pixel_difference(skin.get_pixel(x, y), whole.get_pixel(x, y)) > 8);
    let furred = furred.count();
    assert!(furred * 100 <= mask.len(), "{furred} of the {} bald pixels show separated fur", mask.len());
    let furred_pixels = (0..SIZE_PX * SIZE_PX)
        .filter(|k| {
            pixel_difference(skin.get_pixel(k % SIZE_PX, k / SIZE_PX), whole.get_pixel(k % SIZE_PX, k / SIZE_PX)) > 8
        })
        .count();
    assert!(furred_pixels > 1000, "the separated fur shows elsewhere ({furred_pixels} pixels)");
}

/// The structure's bytes on the GPU are still the footprint's with a groom (the topology is
/// reordered, not grown), and the silhouette pass lists no more fins than edges that grow them.
#[test]
fn groomed_gpu_bytes_are_the_footprints_and_fins_stay_on_fin_edges() {
    let fur = groomed_fox();
    let rig = Rig::new(SIZE_PX, SIZE_PX);
    let gpu_fur = rig.fur(&fur, &strand_textures(64, fur.layers, ROOT, TIP));
    let footprint = fur.footprint();
    let bytes = gpu_fur.gpu_bytes();
    assert_eq!(bytes.positions, footprint.position_bytes);
    assert_eq!(bytes.attributes, footprint.attribute_bytes);
    assert_eq!(bytes.indices, footprint.index_bytes + 6 * u64::from(fur.layers) * 4);

    let camera = face_camera(&fur);
    rig.render_silhouette(&gpu_fur, &camera, &FurDrawSettings::ALL);
    let draw = rig.read_u32s(gpu_fur.silhouette_draw().expect("fins"));
    let fin_edges = fur.fin_edges().len();
    assert!(fin_edges < fur.mesh.edges.len());
    assert!(draw[1] > 0 && (draw[1] as usize) <= fin_edges, "{} fins listed of {fin_edges}", draw[1]);
    let instances = rig.read_u32s(gpu_fur.silhouette_instances().expect("fins"));
    assert!(instances.chunks(2).take(draw[1] as usize).all(|fin| (fin[0] as usize) < fin_edges));
}
