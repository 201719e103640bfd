//! A herd's copies of one fur: a hundred of them allocate its topology, uvs, fin strip and
//! textures once (counted in the device's own allocator report, by label), and each draws its
//! own pose exactly as a fur uploaded alone with that pose. Fails, never skips, without an
//! adapter.

use std::collections::HashMap;

use crate::common;

use common::{BROWN_ROOT, BROWN_TIP, Rig, builtin_fur, framed, settings, strand_textures};
use glam::Vec3;
use pelt_core::Builtin;
use pelt_render::{FurAsset, FurDriver, FurFrame, FurStates, GpuFur, KernelChoice};

/// Pelt's allocations by label, and their bytes, from the device's allocator (wgpu's own, such
/// as the staging of uploads, left out).
fn allocations(device: &wgpu::Device) -> (HashMap<String, usize>, u64) {
    // Uploads' staging buffers are freed once their submission is done.
    device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None }).expect("the device answers");
    let report = device.generate_allocator_report().expect("the Vulkan device reports its allocations");
    let mut counts = HashMap::new();
    let mut bytes = 0;
    for allocation in report.allocations.iter().filter(|a| !a.name.starts_with("(wgpu internal)")) {
        *counts.entry(allocation.name.clone()).or_insert(0) += 1;
        bytes += allocation.size;
    }
    (counts, bytes)
}

#[test]
fn a_hundred_copies_allocate_the_topology_and_textures_once() {
    let rig = Rig::new(64, 64);
    let structure = builtin_fur(Builtin::Bunny, 16);
    let textures = strand_textures(64, 16, BROWN_ROOT, BROWN_TIP);
    let (before, bytes_before) = allocations(rig.device());
    let asset = FurAsset::new(rig.device(), rig.queue(), &rig.renderer, &structure, &textures).expect("asset");
    let copies: Vec<GpuFur> = (0..100)
        .map(|_| GpuFur::from_asset(rig.device(), &rig.renderer, &asset, FurStates::Two).expect("copy"))
        .collect();
    rig.queue().submit([]);
    let (after, bytes_after) = allocations(rig.device());
    let made = |label: &str| after.get(label).copied().unwrap_or(0) - before.get(label).copied().unwrap_or(0);
    for shared in
        ["pelt topology", "pelt wedge uvs", "pelt fin strip", "pelt groom attributes", "pelt fin", "pelt shell slices"]
    {
        assert_eq!(made(shared), 1, "{shared}: allocated once for 100 copies");
    }
    // A copy made alone is a pool of one: its two states in one buffer.
    assert_eq!(made("pelt shared vertices"), 100, "both states of a copy in one buffer");
    assert_eq!(made("pelt base normals"), 100);
    // The bytes: the asset once, each copy's own bytes and lists, and small per-copy buffers
    // (uniform, wetness, draw arguments) with the allocator's alignment.
    let own = copies[0].own_bytes();
    let own = own.positions + own.attributes + copies[0].silhouette_list_bytes();
    let shared = asset.gpu_bytes();
    let expected = shared.positions + shared.attributes + shared.indices + shared.textures + 100 * own;
    let allocated = bytes_after - bytes_before;
    assert!(allocated >= expected, "{allocated} bytes allocated, {expected} counted");
    assert!((allocated as f64) < 1.3 * expected as f64, "{allocated} bytes allocated, {expected} counted");
    assert!(copies.iter().all(|copy| copy.asset().shares_with(&asset)));
}

/// Copies simulated on the GPU kernel share their asset's rest segments (a copy grown longer has
/// its own); each has its own state.
#[test]
fn copies_on_the_gpu_kernel_share_the_rest_segments() {
    let rig = Rig::new(64, 64);
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let asset = FurAsset::new(rig.device(), rig.queue(), &rig.renderer, &structure, &textures).expect("asset");
    let params = pelt_core::sim::SimParams::default();
    let asset_before = asset.gpu_bytes().positions;
    let (before, _) = allocations(rig.device());
    let longer = structure.with_length_scale(1.5);
    let drivers: Vec<FurDriver> = std::iter::repeat_n(&structure, 10)
        .chain([&longer])
        .map(|grown| {
            FurDriver::with_asset(rig.device(), rig.queue(), &rig.renderer, &asset, grown, &params, KernelChoice::Gpu)
                .expect("driver")
        })
        .collect();
    let (after, _) = allocations(rig.device());
    let made = |label: &str| after.get(label).copied().unwrap_or(0) - before.get(label).copied().unwrap_or(0);
    assert_eq!(made("pelt simulation rest segments"), 2, "one shared, one for the longer copy");
    assert_eq!(made("pelt simulation strand state"), drivers.len());
    // The asset counts the shared rest segments once; the longer copy counts its own.
    let rest = asset.gpu_bytes().positions - asset_before;
    assert!(rest > 0, "the asset does not count the shared rest segments");
    assert_eq!(drivers[10].simulation_bytes(), drivers[0].simulation_bytes() + rest);
}

/// Whether the rig's adapter is a discrete or integrated GPU (where a herd pools by default).
pub(crate) fn is_gpu(rig: &Rig) -> bool {
    matches!(rig.device().adapter_info().device_type, wgpu::DeviceType::DiscreteGpu | wgpu::DeviceType::IntegratedGpu)
}

#[test]
fn each_copy_draws_its_own_pose_as_a_fur_uploaded_alone() {
    let rig = Rig::new(96, 96);
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let asset = FurAsset::new(rig.device(), rig.queue(), &rig.renderer, &structure, &textures).expect("asset");
    let copies: Vec<GpuFur> = (0..2)
        .map(|_| GpuFur::from_asset(rig.device(), &rig.renderer, &asset, FurStates::One).expect("copy"))
        .collect();
    // The second copy's strands bent sideways by a tenth of the fur's radius at the tips.
    let radius = structure.mesh.bounding_sphere().1;
    let v = structure.mesh.vertex_count();
    let bent: Vec<Vec3> = structure
        .positions
        .iter()
        .enumerate()
        .map(|(k, p)| *p + Vec3::X * (0.1 * radius * (k / v) as f32 / structure.layers as f32))
        .collect();
    copies[1].set_positions(rig.queue(), &bent).expect("positions");
    for copy in &copies {
        copy.prepare(rig.queue(), &common::paper_frame());
    }
    let camera = framed(&structure, 1.0);
    let first = rig.render(&copies[0], &camera, &settings());
    let second = rig.render(&copies[1], &camera, &settings());
    let alone = rig.fur(&structure, &textures);
    alone.set_positions(rig.queue(), &bent).expect("positions");
    alone.prepare(rig.queue(), &common::paper_frame());
    let bent_alone = rig.render(&alone, &camera, &settings());
    let rest_alone = rig.render(&rig.fur(&structure, &textures), &camera, &settings());
    assert_eq!(first, rest_alone, "the first copy draws the rest pose, as a fur alone does");
    assert_eq!(second, bent_alone, "the second copy draws its own pose, as a fur alone does");
    let differing = first.pixels().zip(second.pixels()).filter(|(a, b)| a != b).count();
    assert!(differing > 200, "{differing} pixels differ between the copies");
    // Their silhouette listings in one compute pass, as a herd records them, show each copy's own
    // fins: the bytes of each listed in its own pass.
    let fins_only = pelt_render::FurDrawSettings { skin: false, shells: false, ..settings() };
    let both: Vec<&GpuFur> = copies.iter().collect();
    let one_pass = rig.render_silhouettes(&both, &camera, &fins_only, true);
    let separate = rig.render_silhouettes(&both, &camera, &fins_only, false);
    let differing = one_pass.pixels().zip(separate.pixels()).filter(|(a, b)| a != b).count();
    assert_eq!(differing, 0, "pixels that differ listed in one pass and in one pass a copy");
    let second_alone = rig.render_silhouettes(&both[1..], &camera, &fins_only, false);
    let background = rig.background();
    let covered = |image: &image::RgbaImage| image.pixels().filter(|p| common::covered(p, background)).count();
    assert!(covered(&one_pass) > covered(&second_alone), "the first copy's fins are drawn as well");
    assert!(covered(&second_alone) > 100, "{} fin pixels of the second copy", covered(&second_alone));
}

/// A fur made small on screen loses its coat gradually: as `FurLevel::coat` falls from 1 to 0 in
/// twenty frames, no frame's change is more than a fifth of the whole, the full coat draws the
/// bytes it always drew, and the bare skin stands in the coat's mean colour (the picture's mean
/// colour over the fur moves by less than 25 of 255 levels: the skin is lit as a surface, the
/// shells as strands).
#[test]
fn a_far_fur_fades_to_its_skin_in_the_coats_colour_without_a_jump() {
    coat_fade(false);
}

/// The same in Pelt's look (the fur model in Pelt's studio), whose coat reflects less than a
/// surface of its colour: the skin it fades to is darkened to match, within 10 levels. With
/// Kajiya-Kay's share instead (tried once) the skin was 23 levels lighter than the coat in red.
#[test]
fn a_far_fur_fades_to_the_coats_colour_in_pelts_look_too() {
    coat_fade(true);
}

fn coat_fade(pelts_look: bool) {
    let rig = Rig::new(96, 96);
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let fur = rig.fur(&structure, &textures);
    let camera = framed(&structure, 1.0);
    let draw = |frame: &FurFrame| {
        if pelts_look {
            rig.render_frame_in_studio(&fur, frame, &camera, &settings())
        } else {
            fur.prepare(rig.queue(), frame);
            rig.render(&fur, &camera, &settings())
        }
    };
    let base = if pelts_look { FurFrame::default() } else { common::paper_frame() };
    let always = draw(&base);
    let at =
        |coat: f32| draw(&FurFrame { level: pelt_render::FurLevel { coat, ..pelt_render::FurLevel::FULL }, ..base });
    let frames: Vec<image::RgbaImage> = (0..=20).map(|k| at(1.0 - k as f32 / 20.0)).collect();
    assert_eq!(frames[0], always, "the full coat draws what it always drew");
    let background = rig.background();
    let (whole, largest, steps) = fade_steps(&frames);
    eprintln!("coat fade: whole change {whole:.3}, largest step {largest:.3}");
    assert!(whole > 0.5, "the coat's going changes the picture: {whole}");
    assert!(largest < 0.2 * whole, "a jump of {largest} in a change of {whole}: {steps:?}");
    // The mean colour where the fur is, with the coat and with the skin alone.
    let mean_colour = |image: &image::RgbaImage| {
        let covered: Vec<&image::Rgba<u8>> = image.pixels().filter(|p| common::covered(p, background)).collect();
        let sum = covered
            .iter()
            .fold([0.0; 3], |s, p| [s[0] + f64::from(p[0]), s[1] + f64::from(p[1]), s[2] + f64::from(p[2])]);
        sum.map(|c| c / covered.len() as f64)
    };
    let (coat, skin) = (mean_colour(&frames[0]), mean_colour(&frames[20]));
    eprintln!("mean colour with the coat {coat:?}, the skin alone {skin:?}");
    let bound = if pelts_look { 10.0 } else { 25.0 };
    for channel in 0..3 {
        assert!((coat[channel] - skin[channel]).abs() < bound, "coat {coat:?} against skin {skin:?}");
    }
}

/// A far fur's fins go before its coat: drawn alone (the silhouette pass's fins, as Pelt's
/// commands draw them), they fade as `FurLevel::fins` falls from 1 to 0 in twenty frames with no
/// frame's change above a fifth of the whole, and at 0 nothing of them is drawn. With the whole
/// fur, full fins draw the bytes the fur always drew.
#[test]
fn a_far_furs_fins_fade_out_without_a_jump() {
    let rig = Rig::new(96, 96);
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let fur = rig.fur(&structure, &textures);
    let camera = framed(&structure, 1.0);
    let base = common::paper_frame();
    let fins_only = pelt_render::FurDrawSettings { skin: false, shells: false, ..settings() };
    let at = |fins: f32, settings: &pelt_render::FurDrawSettings| {
        fur.prepare(
            rig.queue(),
            &FurFrame { level: pelt_render::FurLevel { fins, ..pelt_render::FurLevel::FULL }, ..base },
        );
        rig.render_silhouette(&fur, &camera, settings)
    };
    fur.prepare(rig.queue(), &base);
    assert_eq!(at(1.0, &settings()), rig.render_silhouette(&fur, &camera, &settings()), "full fins: the fur as always");
    let frames: Vec<image::RgbaImage> = (0..=20).map(|k| at(1.0 - k as f32 / 20.0, &fins_only)).collect();
    let background = rig.background();
    let covered = |image: &image::RgbaImage| image.pixels().filter(|p| common::covered(p, background)).count();
    assert!(covered(&frames[0]) > 300, "{} fin pixels at full fins", covered(&frames[0]));
    assert_eq!(covered(&frames[20]), 0, "no fins drawn at 0");
    let (whole, largest, steps) = fade_steps(&frames);
    eprintln!("fin fade: {} fin pixels, whole change {whole:.3}, largest step {largest:.3}", covered(&frames[0]));
    assert!(largest < 0.2 * whole, "a jump of {largest} in a change of {whole}: {steps:?}");
}

/// A fade's frames: the mean per-pixel change from the first to the last, the largest change
/// between consecutive frames, and every such change.
fn fade_steps(frames: &[image::RgbaImage]) -> (f64, f64, Vec<f64>) {
    let mean_difference = |a: &image::RgbaImage, b: &image::RgbaImage| {
        let sum: u64 = a.pixels().zip(b.pixels()).map(|(p, q)| u64::from(common::pixel_difference(p, q))).sum();
        sum as f64 / f64::from(a.width() * a.height())
    };
    let whole = mean_difference(&frames[0], &frames[frames.len() - 1]);
    let steps: Vec<f64> = frames.windows(2).map(|w| mean_difference(&w[0], &w[1])).collect();
    let largest = steps.iter().copied().fold(0.0, f64::max);
    (whole, largest, steps)
}

/// Copies made together list in one dispatch per listing stage for the whole herd: three
/// copies, each shaped, posed and placed its own way and thinning its shells by view angle, list their
/// fins and thinned triangles in 5 dispatches (a lone copy's 5, not 15), and each copy's lists
/// (counts, instances, indices, draws) have the bytes of a copy made alone, posed and placed the
/// same, listed alone; the herd's picture is the lone copies' drawn in turn.
#[test]
fn copies_made_together_list_in_one_dispatch_each_as_each_alone() {
    let rig = Rig::new(96, 96);
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let asset = FurAsset::new(rig.device(), rig.queue(), &rig.renderer, &structure, &textures).expect("asset");
    let (device, renderer) = (rig.device(), &rig.renderer);
    let herd = GpuFur::herd_from_asset(device, renderer, &asset, FurStates::Two, 3).expect("herd");
    let alone: Vec<GpuFur> =
        (0..3).map(|_| GpuFur::from_asset(device, renderer, &asset, FurStates::Two).expect("copy")).collect();
    let radius = structure.mesh.bounding_sphere().1;
    let v = structure.mesh.vertex_count();
    let level = pelt_render::FurLevel { facing: Some(pelt_render::LodSettings::DEFAULT_FACING), ..Default::default() };
    for (k, (together, lone)) in herd.iter().zip(&alone).enumerate() {
        // Copy k squashed to 1 - k/4 of its height (its roots and faces move), bent sideways by
        // k tenths of the radius at the tips, and turned k * 40 degrees.
        let (bend, squash) = (0.1 * radius * k as f32, Vec3::new(1.0, 1.0 - 0.25 * k as f32, 1.0));
        let bent: Vec<Vec3> = (structure.positions.iter().enumerate())
            .map(|(j, p)| *p * squash + Vec3::X * (bend * (j / v) as f32 / structure.layers as f32))
            .collect();
        let frame = FurFrame {
            world_from_model: glam::Mat4::from_rotation_y((40.0 * k as f32).to_radians()),
            level,
            ..common::paper_frame()
        };
        // The squashed surface's normals (the inverse transpose of the squash).
        let normals: Vec<Vec3> = structure.mesh.normals.iter().map(|n| (*n / squash).normalize()).collect();
        for fur in [together, lone] {
            fur.set_positions(rig.queue(), &bent).expect("positions");
            fur.set_base_normals(rig.queue(), &normals).expect("normals");
            fur.prepare(rig.queue(), &frame);
        }
    }
    let camera = framed(&structure, 1.0);
    rig.view.prepare(rig.queue(), &camera.view_data(1.0, &pelt_render::Light::default()));
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    let together = renderer.prepare_fins_of(&mut encoder, &rig.view, &herd);
    let each: Vec<usize> = alone.iter().map(|fur| renderer.prepare_fins_of(&mut encoder, &rig.view, [fur])).collect();
    rig.queue().submit([encoder.finish()]);
    assert_eq!(each, [5, 5, 5], "a lone copy's fin and shell listings");
    assert_eq!(together, 5, "the herd's, three copies in one dispatch a stage");
    let bytes = |slice: Option<wgpu::BufferSlice<'_>>| common::read_bytes(device, rig.queue(), slice.expect("a list"));
    for (k, (together, lone)) in herd.iter().zip(&alone).enumerate() {
        assert!(together.shells_thinned() > 0, "copy {k} thins its shells");
        let count = |fur: &GpuFur| u32::from_le_bytes(bytes(fur.view_lod_count()).try_into().expect("one u32"));
        assert!(count(together) > 0, "copy {k} lists triangles");
        assert_eq!(count(together), count(lone), "copy {k}'s listed triangles");
        let listed = count(lone) as usize * 4;
        assert_eq!(bytes(together.view_lod_indices())[..listed], bytes(lone.view_lod_indices())[..listed], "copy {k}");
        let draw = bytes(together.silhouette_draw());
        assert_eq!(draw, bytes(lone.silhouette_draw()), "copy {k}'s fin draw");
        let fins = u32::from_le_bytes(draw[4..8].try_into().expect("u32")) as usize;
        assert!(fins > 0, "copy {k} shows fins");
        let kept = |fur: &GpuFur| bytes(fur.silhouette_instances())[..8 * fins].to_vec();
        assert_eq!(kept(together), kept(lone), "copy {k}'s fins");
    }
    // Each copy's own pose and place in the picture, listed together or alone.
    let listed_together: Vec<&GpuFur> = herd.iter().collect();
    let listed_alone: Vec<&GpuFur> = alone.iter().collect();
    let herd_picture = rig.render_silhouettes(&listed_together, &camera, &settings(), true);
    assert_eq!(herd_picture, rig.render_silhouettes(&listed_alone, &camera, &settings(), false));
}

/// Through a shadow map, copies made together cast in one draw a pass where copies made alone
/// take a draw each, and the shadows are the same: the picture of the ground and four copies,
/// each posed and placed its own way, has the same bytes. Two draw every shell (one of them
/// fading its coat) and cast together in every pass; one draws every fourth shell (two opacity shells, not four: it casts
/// its opacity alone) and one has faded to its skin (no fur to cast).
#[test]
fn copies_made_together_cast_in_one_draw_a_pass_as_each_alone() {
    let mut rig = Rig::new(192, 144);
    let gpu = is_gpu(&rig);
    assert_eq!(rig.renderer.pooled_casting(), gpu, "a GPU pools the casters, a CPU rasteriser casts each alone");
    rig.renderer.set_pooled_casting(true);
    let structure = builtin_fur(Builtin::Bunny, 8);
    let mut textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    // Strands up to the outermost shell, which a coat thinned to fewer shells than the opacity
    // pass's four draws once (its `opacity_shell` clamps there).
    let slice = (32 * 32 * 4) as usize;
    let below = textures.shell[6 * slice..7 * slice].to_vec();
    textures.shell[7 * slice..].copy_from_slice(&below);
    let asset = FurAsset::new(rig.device(), rig.queue(), &rig.renderer, &structure, &textures).expect("asset");
    let (device, renderer) = (rig.device(), &rig.renderer);
    let herd = GpuFur::herd_from_asset(device, renderer, &asset, FurStates::Two, 4).expect("herd");
    let alone: Vec<GpuFur> =
        (0..4).map(|_| GpuFur::from_asset(device, renderer, &asset, FurStates::Two).expect("copy")).collect();
    let (centre, radius) = structure.mesh.bounding_sphere();
    let v = structure.mesh.vertex_count();
    // Copy 1's coat fading (its opacity fragments read its own `coat_fade`).
    let levels = [
        pelt_render::FurLevel::FULL,
        pelt_render::FurLevel { coat: 0.6, ..pelt_render::FurLevel::FULL },
        pelt_render::FurLevel { stride: 4, ..pelt_render::FurLevel::FULL },
        pelt_render::FurLevel { coat: 0.0, ..pelt_render::FurLevel::FULL },
    ];
    for (k, (together, lone)) in herd.iter().zip(&alone).enumerate() {
        // Copy k bent sideways by k tenths of the radius at the tips, turned k * 40 degrees and
        // standing k * 2.2 radii along x.
        let bend = 0.1 * radius * k as f32;
        let bent: Vec<Vec3> = (structure.positions.iter().enumerate())
            .map(|(j, p)| *p + Vec3::X * (bend * (j / v) as f32 / structure.layers as f32))
            .collect();
        let place = glam::Mat4::from_translation(Vec3::X * (2.2 * radius * k as f32) - centre)
            * glam::Mat4::from_rotation_y((40.0 * k as f32).to_radians());
        let frame = FurFrame { world_from_model: place, level: levels[k], ..common::paper_frame() };
        for fur in [together, lone] {
            fur.set_positions(rig.queue(), &bent).expect("positions");
            fur.prepare(rig.queue(), &frame);
        }
    }
    assert_eq!(herd[2].drawn_shells(), 2, "copy 2 draws two shells");
    let floor = rig.plain(&pelt_render::ground_mesh(), Vec3::splat(0.6));
    let below = glam::Mat4::from_translation(Vec3::new(3.3 * radius, -radius, 0.0));
    floor.prepare(rig.queue(), below * glam::Mat4::from_scale(Vec3::splat(7.0 * radius)));
    let scene = (Vec3::new(3.3 * radius, 0.0, 0.0), 5.0 * radius);
    // Seen from high above, the long shadows of a low light across the ground and the copies.
    let camera = pelt_render::Camera::framing(scene.0, scene.1, 20.0, 60.0, 192.0 / 144.0);
    let light = pelt_render::Light::default();
    let mut view = pelt_render::FurView::new(device, renderer);
    view.prepare(rig.queue(), &camera.view_data(192.0 / 144.0, &light));
    let shadow = pelt_render::ShadowSettings { size: 256, fur_depth: 0.3 * radius, extinction: 0.6 };
    let mut map = pelt_render::ShadowMap::new(device, renderer, shadow).expect("shadow map");
    let caster = pelt_render::ShadowCaster::Directional { toward_light: Vec3::new(1.0, 0.7, 0.3).normalize() };
    map.prepare(rig.queue(), (&[(0, caster)], 1), scene);
    view.set_shadows(Some(&map));
    let picture = |furs: &[GpuFur], together: bool| {
        let mut draws = Vec::new();
        let image = rig
            .headless
            .render_with(
                pelt_render::DEFAULT_BACKGROUND,
                |encoder| {
                    map.record(encoder, |pass, light| {
                        renderer.draw_plain(pass, light, &floor);
                        draws.push(if together {
                            renderer.draw_herd(pass, light, furs, &settings())
                        } else {
                            furs.iter().map(|fur| renderer.draw_herd(pass, light, [fur], &settings())).sum()
                        });
                    });
                },
                |pass| {
                    renderer.draw_plain(pass, &view, &floor);
                    for fur in furs {
                        renderer.draw(pass, &view, fur, &settings());
                    }
                },
            )
            .expect("frame");
        (image, draws)
    };
    let (herd_picture, herd_draws) = picture(&herd, true);
    let (alone_picture, alone_draws) = picture(&alone, false);
    herd_picture.save(common::out_dir().join("herd-shadows.png")).expect("save");
    // The opaque pass draws every skin, the fur's passes the three coats that show.
    assert_eq!(alone_draws, [4, 3, 3], "copies alone: a draw each");
    assert_eq!(herd_draws, [1, 1, 2], "copies made together: one draw a pass, the thinned coat's opacity alone");
    assert!(herd_picture == alone_picture, "the herd's shadows differ from its copies' alone");
}

/// Through the camera, a herd's plan (`HerdDraws`) draws each level's copies of one pool in a
/// skin draw and a shell draw, the shells the view angle thins in one gathered indirect call and
/// the fins in another, and the picture has the bytes of each copy drawn alone, farthest first,
/// with shadows: eight copies in two rows, the back row behind the front one on screen, each
/// posed and placed its own way; one keeps every fourth shell, three thin theirs by the view
/// angle, one fades its coat, one has faded to its skin, one is lit by the other shading model
/// (a coat of its own).
#[test]
fn a_herds_camera_draws_pool_each_level_as_each_copy_alone() {
    let mut rig = Rig::new(192, 144);
    assert_eq!(rig.renderer.pooled_drawing(), is_gpu(&rig), "a GPU pools the camera's draws, a CPU rasteriser not");
    rig.renderer.set_pooled_drawing(true);
    let gathers = rig.device().features().contains(wgpu::Features::INDIRECT_FIRST_INSTANCE);
    if rig.device().adapter_info().backend == wgpu::Backend::Vulkan {
        assert!(gathers, "lavapipe takes an indirect draw's first instance: the gathered draws are tested");
    }
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let asset = FurAsset::new(rig.device(), rig.queue(), &rig.renderer, &structure, &textures).expect("asset");
    let (device, renderer) = (rig.device(), &rig.renderer);
    let herd = GpuFur::herd_from_asset(device, renderer, &asset, FurStates::Two, 8).expect("herd");
    let (centre, radius) = structure.mesh.bounding_sphere();
    let reach = radius + structure.lengths.iter().copied().fold(0.0, f32::max);
    let v = structure.mesh.vertex_count();
    let full = pelt_render::FurLevel::FULL;
    let facing = pelt_render::FurLevel { facing: Some([0.4, 0.7]), ..full };
    let levels = [
        full,
        pelt_render::FurLevel { stride: 4, ..full },
        facing,
        pelt_render::FurLevel { coat: 0.6, ..full },
        pelt_render::FurLevel { coat: 0.8, ..facing },
        pelt_render::FurLevel { coat: 0.0, ..full },
        full,
        facing,
    ];
    let mut spheres = Vec::new();
    for (k, fur) in herd.iter().enumerate() {
        let bend = 0.05 * radius * k as f32;
        let bent: Vec<Vec3> = (structure.positions.iter().enumerate())
            .map(|(j, p)| *p + Vec3::X * (bend * (j / v) as f32 / structure.layers as f32))
            .collect();
        // Four a row, 4.5 radii apart; the back row 4 radii behind, a fifth of a step aside.
        let (row, column) = ((k / 4) as f32, (k % 4) as f32);
        let at = Vec3::new(4.5 * radius * (column + 0.2 * row), 0.0, -4.0 * radius * row);
        let place =
            glam::Mat4::from_translation(at - centre) * glam::Mat4::from_rotation_y((40.0 * k as f32).to_radians());
        let look = if k == 6 { pelt_render::FurLook::default() } else { common::paper_frame().look };
        fur.set_positions(rig.queue(), &bent).expect("positions");
        fur.prepare(rig.queue(), &FurFrame { world_from_model: place, level: levels[k], look, ..FurFrame::default() });
        spheres.push((at, reach));
    }
    let scene = (Vec3::new(7.9 * radius, 0.0, -2.0 * radius), 9.0 * radius);
    // Low in front, so the back row stands behind the front one on screen.
    let camera = pelt_render::Camera::framing(scene.0, scene.1, 0.0, 8.0, 192.0 / 144.0);
    let view_data = camera.view_data(192.0 / 144.0, &pelt_render::Light::default());
    let mut view = pelt_render::FurView::new(device, renderer);
    view.prepare(rig.queue(), &view_data);
    let shadow = pelt_render::ShadowSettings { size: 256, fur_depth: 0.3 * radius, extinction: 0.6 };
    let mut map = pelt_render::ShadowMap::new(device, renderer, shadow).expect("shadow map");
    let caster = pelt_render::ShadowCaster::Directional { toward_light: Vec3::new(0.4, 0.8, 0.5).normalize() };
    map.prepare(rig.queue(), (&[(0, caster)], 1), scene);
    view.set_shadows(Some(&map));
    // Farthest first.
    let mut order: Vec<usize> = (0..8).collect();
    order.sort_by(|&a, &b| spheres[b].0.distance(camera.eye).total_cmp(&spheres[a].0.distance(camera.eye)));
    let furs: Vec<&GpuFur> = order.iter().map(|&k| &herd[k]).collect();
    let members: Vec<(&GpuFur, (Vec3, f32))> = order.iter().map(|&k| (&herd[k], spheres[k])).collect();
    let mut plan = pelt_render::HerdDraws::new();
    plan.prepare((device, rig.queue()), renderer, &view_data, &members);
    let settings = pelt_render::FurDrawSettings::SILHOUETTE;
    let picture = |planned: bool| {
        let mut draws = 0;
        let image = rig
            .headless
            .render_with(
                pelt_render::DEFAULT_BACKGROUND,
                |encoder| {
                    renderer.prepare_fins_of(encoder, &view, furs.iter().copied());
                    map.record(encoder, |pass, light| {
                        renderer.draw_herd(pass, light, furs.iter().copied(), &settings);
                    });
                },
                |pass| {
                    draws = if planned {
                        renderer.draw_herd_planned(pass, &view, &plan, &furs, &settings)
                    } else {
                        furs.iter().map(|fur| renderer.draw_herd(pass, &view, [*fur], &settings)).sum()
                    };
                },
            )
            .expect("frame");
        (image, draws)
    };
    let (planned, planned_draws) = picture(true);
    let (alone, alone_draws) = picture(false);
    planned.save(common::out_dir().join("herd-camera.png")).expect("save");
    // A thinned coat draws a shell at a time.
    assert_eq!(alone_draws, 8 + (4 + 3 * 8) + 7, "a skin, shells and fins a copy, none for the hidden coat");
    assert_eq!(plan.levels(), 2, "the front row and the back row");
    // The coat lit by the other model draws alone; the rest of each row together: their skins in
    // one draw, the whole shells of those whose coat shows in another, the thinned shells in one
    // gathered call, then the fins in one.
    if gathers {
        assert_eq!((plan.pooled_members(), plan.gathered_members()), (7, 3));
        assert_eq!(planned_draws, (1 + 1 + 1 + 1) + (1 + 1 + 1) + 3, "{planned_draws} draws planned");
    } else {
        // Without an indirect draw's first instance the thinned copies and the fins draw alone.
        assert_eq!((plan.pooled_members(), plan.gathered_members()), (4, 0));
        assert_eq!(planned_draws, (1 + 1 + 2) + 3 * (1 + 8 + 1) + 3, "{planned_draws} draws planned");
    }
    assert!(planned == alone, "the planned herd's picture differs from its copies' alone");
    if gathers {
        // A second plan over some of the same copies takes their pool's gathered places (other
        // places: the nearest copy first): the first then draws its thinned shells and fins each
        // alone, to the same picture.
        let mut second = pelt_render::HerdDraws::new();
        let nearest_first: Vec<_> = members.iter().rev().take(7).copied().collect();
        second.prepare((device, rig.queue()), renderer, &view_data, &nearest_first);
        let (stale, stale_draws) = picture(true);
        assert!(stale == alone, "a plan whose pool gathers for another draws another picture");
        // Each row's skins and whole shells pooled, its thinned shells a draw a shell and its fins
        // a draw a coat; the other model's copy alone.
        assert_eq!(stale_draws, (1 + 1 + 8 + 4) + (1 + 2 * 8 + 2) + 3, "{stale_draws} draws");
    }
}
