//! `pelt render`: fur on a mesh to a PNG, a numbered PNG sequence or an animated GIF, headless.

use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use anyhow::{Context as _, bail};
use glam::{Mat4, Vec3};
use pelt_core::anim::{Pose, Rig};
use pelt_core::sim::herd::{self, HerdInstance};
use pelt_core::sim::{FurStepper, Scene, SceneCamera, WindParams};
use pelt_core::{Builtin, FurStructure, Mesh, Preset, Stage};
use pelt_render::{
    Backend, Camera, ColliderMeshes, FurAsset, FurDrawSettings, FurDriver, FurLook, FurTarget, FurView, Gpu,
    HEADLESS_FORMAT, Headless, HerdDraws, HerdPosing, KernelChoice, PlainMesh, SAMPLE_COUNT, default_sample_count,
};

use crate::light_args::{LightArgs, preset_look};
use crate::lod;
use crate::mesh_args::MeshArgs;
use crate::sim_kernel::SimChoice;

/// Skin tone of plain meshes (linear RGB).
pub const PLAIN_COLOUR: Vec3 = Vec3::new(0.62, 0.46, 0.38);

/// Wind of the default render (no `--wind`, and the preset has none): a light breeze from the
/// camera's left.
pub const LIGHT_WIND: Vec3 = Vec3::new(0.35, 0.0, 0.1);

/// Arguments of `pelt render`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
With no arguments: the built-in bunny, the default fur and a light breeze, to pelt.png.
`--builtin tryon` renders a body (plain) wearing a furry garment; with your own meshes:
`pelt render GARMENT.obj --plain-mesh BODY.obj`. An animated glTF plays its first animation
(`--animation` picks another, `none` keeps the rest pose): `pelt render assets/meshes/Fox.glb
--animation Walk --frames 90 -o fox.gif`. A script's [[motion]] keys move the meshes:
`pelt render --builtin tryon --script assets/scenes/catwalk.toml -o catwalk.gif`. A herd:
`--herd N` scatters N copies on a ground, a script's [[instance]] tables place them
(`pelt render --script assets/scenes/herd.toml -o herd.gif`).")]
pub struct Args {
    #[command(flatten)]
    mesh: MeshArgs,
    /// Meshes drawn without fur beside the furry one (e.g. the body under a furry garment).
    #[arg(long, value_name = "MESH")]
    plain_mesh: Vec<PathBuf>,
    /// The fur preset (TOML); the built-in default fur without one.
    #[arg(long, value_name = "P")]
    preset: Option<PathBuf>,
    /// A scene script (TOML): wind keys, touch strokes and rigid motion over time.
    #[arg(long, value_name = "SCENE.toml")]
    script: Option<PathBuf>,
    /// The animation of an animated glTF to play: its name or index, or `none` for the rest
    /// pose. Default: the first animation.
    #[arg(long, value_name = "NAME|INDEX|none")]
    animation: Option<String>,
    /// Frames to render (default: 1 for a .png; the script's length, or 2 seconds, otherwise).
    #[arg(long, value_name = "N")]
    frames: Option<u32>,
    /// Frames per second of simulated time.
    #[arg(long, default_value_t = 30.0)]
    fps: f64,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", value_parser = crate::values::parse_size)]
    size: (u32, u32),
    /// Camera as azimuth,elevation (degrees) and distance (world units) around the meshes'
    /// centre; without it the camera frames the meshes automatically.
    #[arg(long, value_name = "AZIMUTH,ELEVATION,DISTANCE", value_parser = crate::values::parse_vec3, allow_hyphen_values = true)]
    camera: Option<Vec3>,
    /// Wind x,y,z (direction and strength; 0,0,0 for none). Default: the preset's, or a light breeze.
    #[arg(long, value_name = "X,Y,Z", value_parser = crate::values::parse_vec3, allow_hyphen_values = true)]
    wind: Option<Vec3>,
    /// Graphics backend: vulkan, gl (or metal, dx12); default `WGPU_BACKEND`, else the best there is.
    #[arg(long, default_value = "auto")]
    backend: Backend,
    /// Where the fur is simulated: the CPU, the GPU (a compute pass), or auto (both timed on
    /// this fur first, the GPU when clearly faster, so one command draws the same bytes).
    #[arg(long, value_enum, default_value_t = SimChoice::Auto)]
    sim: SimChoice,
    /// How a herd's copies share the GPU's work: shadow casters and the camera's draws pooled,
    /// the GPU kernel's steps in one dispatch, the bases skinned on the GPU (auto: on a GPU).
    #[arg(long, value_enum, default_value_t = crate::herd::Pooling::Auto)]
    pooling: crate::herd::Pooling,
    /// Shells and fins with alpha-to-coverage instead of blending (needs MSAA: 4 unless --msaa says more).
    #[arg(long)]
    alpha_to_coverage: bool,
    /// MSAA samples: 1, 2, 4 or 8. Default: 1 on a CPU rasteriser (lavapipe), 4 on a GPU.
    #[arg(long, value_name = "N", value_parser = crate::values::parse_msaa)]
    msaa: Option<u32>,
    /// Draw a body's collision capsules over it (the walking try-on's); colliders a script
    /// places are drawn either way.
    #[arg(long)]
    show_colliders: bool,
    /// Leave out the fins (shells only).
    #[arg(long)]
    no_fins: bool,
    /// Every shell and fin segment however small the fur is on screen (the preset's
    /// `[render.lod]` is on by default).
    #[arg(long)]
    no_lod: bool,
    /// A uniformly wet coat, 0 (dry) to 1 (soaked), held (no drying): the preset's `[wet]`
    /// says what wetness does. A script's `[[rain]]` and `[[water]]` add to it.
    #[arg(long, value_name = "W", value_parser = crate::values::parse_wetness)]
    wetness: Option<f32>,
    #[command(flatten)]
    shadows: crate::shadows::ShadowArgs,
    /// A herd: N copies of the fur scattered on a ground, each at its own phase of the clip,
    /// posed in one parallel pass and simulated there on the CPU, or on the GPU with --sim gpu
    /// (posed there too on a GPU; see --pooling) (a script's [[instance]] tables place them
    /// instead).
    #[arg(long, value_name = "N")]
    herd: Option<usize>,
    /// Output: a .png (one frame), a .gif (animated) or a folder (numbered PNGs).
    #[arg(short, long, default_value = "pelt.png")]
    output: PathBuf,
    #[command(flatten)]
    lights: LightArgs,
}

/// The preset's `[wet]`, with `--wetness` as the whole coat's wetness, held.
pub fn wet_params(preset: &Preset, wetness: Option<f32>) -> pelt_core::wet::WetParams {
    let mut wet = preset.wet.clone();
    if let Some(w) = wetness {
        wet.wetness = w;
        wet.drying_per_sec = 0.0;
    }
    wet
}

/// Where frames go.
enum Output {
    Png(PathBuf),
    Folder(PathBuf),
    Gif(PathBuf),
}

impl Output {
    fn new(path: &Path) -> Self {
        match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
            Some("png") => Self::Png(path.to_path_buf()),
            Some("gif") => Self::Gif(path.to_path_buf()),
            _ => Self::Folder(path.to_path_buf()),
        }
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let started = Instant::now();
    let output = Output::new(&args.output);
    let frames = match (&output, args.frames) {
        (Output::Png(_), Some(n)) if n > 1 => {
            bail!("{} frames need a folder or a .gif as output, not {}", n, args.output.display())
        }
        (_, Some(0)) => bail!("--frames must be at least 1"),
        (_, Some(n)) => n,
        (Output::Png(_), None) => 1,
        (_, None) => 0, // decided below from the script
    };
    if !(args.fps.is_finite() && args.fps > 0.0) {
        bail!("--fps must be a positive number, got {}", args.fps);
    }
    let preset = match &args.preset {
        Some(path) => Preset::load(path)?,
        None => Preset::default(),
    };
    let scene = args.script.as_deref().map(Scene::load).transpose()?;
    let Stage { fur_mesh: mesh, rig, plain, body, .. } = args.mesh.stage(Builtin::Bunny, &args.plain_mesh)?;
    let clip = choose_animation(args, rig.as_ref())?;
    let frames = if frames > 0 {
        frames
    } else {
        // One loop of the animation, or the script, or 2 seconds.
        let clip_secs = clip.and_then(|k| rig.as_ref().map(|r| f64::from(r.animations()[k].duration_secs())));
        let secs = scene.as_ref().map(Scene::duration_secs).or(clip_secs).unwrap_or(2.0);
        ((secs * args.fps).round() as u32).max(1)
    };
    let instances = crate::herd::instances(args.herd, scene.as_ref(), &mesh, (rig.as_ref(), clip))?;
    let fur = preset.grow(mesh, &args.mesh.source(Builtin::Bunny)?.name())?;
    let textures = preset.generate_textures()?;
    let mut simulation_params = preset.simulation.clone();
    let wind = match args.wind {
        Some(wind) => Some(wind),
        None if preset.simulation.wind.strength > 0.0 => None,
        None => Some(LIGHT_WIND),
    };
    if let Some(wind) = wind {
        let direction = wind.try_normalize().unwrap_or(Vec3::X);
        simulation_params.wind = WindParams { direction, strength: wind.length(), ..preset.simulation.wind.clone() };
    }

    let (width, height) = args.size;
    let gpu = Gpu::new(args.backend)?;
    let samples = match args.msaa {
        Some(samples) => samples,
        None if args.alpha_to_coverage => SAMPLE_COUNT,
        None => default_sample_count(&gpu.adapter.get_info()),
    };
    if args.alpha_to_coverage && samples < 2 {
        bail!("--alpha-to-coverage needs MSAA: --msaa 2 or more, got {samples}");
    }
    let headless =
        Headless::with_target(gpu, FurTarget::new(HEADLESS_FORMAT).with_sample_count(samples), width, height)?;
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let mut renderer = headless.renderer()?;
    args.pooling.apply(&mut renderer);
    let asset = FurAsset::new(device, queue, &renderer, &fur, &textures)?;
    // A herd poses its bases in one parallel pass and bends on the CPU there unless asked for the
    // GPU (timing one fur's kernels says little of a hundred's); one fur on the kernel asked for.
    let kernel = match (instances.is_empty(), args.sim) {
        (true, choice) => choice.into(),
        (false, SimChoice::Gpu) => KernelChoice::Gpu,
        (false, _) => KernelChoice::Cpu,
    };
    let members = instances.len().max(1);
    let mut drivers =
        FurDriver::herd_with_asset(device, queue, &renderer, (&asset, &fur), &simulation_params, kernel, members)?;
    let clips = match rig.as_ref() {
        Some(rig) => herd::resolve_clips(&instances, Some(rig), clip),
        None => herd::resolve_clips(&instances, None, clip),
    }
    .map_err(|(key, problem)| {
        let file = args.script.as_deref().map_or_else(|| "--herd".to_owned(), |p| p.display().to_string());
        anyhow::anyhow!("{file}: {key}: {problem}")
    })?;
    // A member with its own length scale grows its own strands on the shared topology.
    let member_furs: Vec<std::borrow::Cow<'_, FurStructure>> = (0..members)
        .map(|member| match instances.get(member).map(|i| i.length_scale) {
            Some(scale) if scale != 1.0 => std::borrow::Cow::Owned(fur.with_length_scale(scale)),
            _ => std::borrow::Cow::Borrowed(&fur),
        })
        .collect();
    let mut steppers = Vec::with_capacity(members);
    for (member, member_fur) in member_furs.iter().enumerate() {
        // The wind is set after the state at time 0 is made, as a host changing it live would.
        let mut stepper = FurStepper::new(member_fur, &preset.simulation)?;
        stepper.simulation_mut().set_wind(&simulation_params.wind)?;
        stepper.set_wet(&wet_params(&preset, args.wetness))?;
        let clip = clips.get(member).copied().unwrap_or(clip);
        // A rig poses the base only while it plays a clip or the script moves it.
        if let Some(rig) =
            rig.clone().filter(|_| clip.is_some() || scene.as_ref().is_some_and(|s| !s.motion.is_empty()))
        {
            stepper.set_clip(rig, clip);
        }
        stepper.set_scene(scene.clone());
        stepper.set_placement(instances.get(member).cloned());
        steppers.push(stepper);
    }
    // The walking try-on's body pushes the skirt's fur out of its legs.
    if let (Some(body), Some(mesh), [stepper]) = (&body, plain.first(), &mut steppers[..]) {
        stepper.set_body(Some((mesh.clone(), body.rig.clone(), body.capsules.clone())));
    }
    // On a GPU a herd that bends there is posed there too: the CPU poses joints only.
    let mut posing = match rig.as_ref() {
        Some(rig) if !instances.is_empty() && kernel == KernelChoice::Gpu && renderer.herd_posing() => {
            for stepper in &mut steppers {
                stepper.set_joint_posing(true);
            }
            Some(HerdPosing::new(device, &fur.mesh, rig, members)?)
        }
        _ => None,
    };
    let stepper = &steppers[0];
    let moves = stepper.moves();
    let plain_meshes = plain
        .iter()
        .map(|mesh| PlainMesh::new(device, &renderer, mesh, PLAIN_COLOUR))
        .collect::<Result<Vec<_>, _>>()?;
    for mesh in &plain_meshes {
        mesh.prepare(queue, Mat4::IDENTITY);
    }
    let motion_keys = stepper.scene().map_or(&[][..], |s| &s.motion[..]);
    let scene_camera = stepper.scene().and_then(|s| s.camera.as_ref());
    let camera =
        camera(args, (&preset, &fur, &plain), (motion_keys, scene_camera, &instances), frames, headless.aspect_ratio());
    let environment = args.lights.environment(stepper.scene())?;
    let studio = args.lights.studio(stepper.scene(), environment, 0.0);
    let mut view = FurView::new(device, &renderer);
    let view_data = studio.view_data(&camera, headless.aspect_ratio());
    view.prepare(queue, &view_data);
    for (member, driver) in drivers.iter_mut().enumerate() {
        let tint = instances.get(member).map_or(Vec3::ONE, |i| i.tint);
        driver.set_look(FurLook { tint, ..preset_look(&preset) });
    }
    // A herd stands on a ground (under all of it, wherever it walks) unless the script has one.
    let scene_ground = stepper.scene().and_then(|s| s.ground.as_ref());
    let herd_ground = (!instances.is_empty() && scene_ground.is_none()).then(pelt_core::sim::SceneGround::default);
    let shadow_args =
        crate::shadows::ShadowArgs { ground: args.shadows.ground || herd_ground.is_some(), ..args.shadows };
    let extent = pelt_core::sim::herd::extent(&fur, &instances, &[0.0, f64::from(frames) / args.fps]);
    let mut surroundings =
        shadow_args.surroundings((device, queue, &renderer), scene_ground, (&fur, &plain), extent.as_ref())?;
    surroundings.fit_to_frame(device, &renderer, (width, height)).context("fitting the shadow maps to the picture")?;
    surroundings.prepare((device, queue), &renderer, &view_data, &mut view).context("aiming the shadow maps")?;
    let lod_settings = lod::settings(&preset.render.lod, args.no_lod);
    // The camera stays put: one level serves every frame of one fur; a herd's members move.
    let level_at = |member: usize, time_secs: f64| {
        let eye = instances
            .get(member)
            .map_or(camera.eye, |i| i.world_from_model(time_secs).inverse().transform_point3(camera.eye));
        lod::level(&lod_settings, &member_furs[member], eye, camera.fov_y_rad, height)
    };
    for (member, driver) in drivers.iter_mut().enumerate() {
        driver.set_level(level_at(member, 0.0));
    }
    let (mesh_centre, mesh_radius) = fur.mesh.bounding_sphere();
    let reach = mesh_radius + fur.lengths.iter().copied().fold(0.0, f32::max);
    // A herd member's sphere at a time (what it draws lies within it); none for a lone fur.
    let member_sphere = |member: usize, time_secs: f64| {
        instances.get(member).map(|i| (i.world_from_model(time_secs).transform_point3(mesh_centre), reach))
    };
    let level = level_at(0, 0.0);
    let mut plan = HerdDraws::new();
    let settings = FurDrawSettings {
        alpha_to_coverage: args.alpha_to_coverage,
        fins: !args.no_fins,
        ..FurDrawSettings::SILHOUETTE
    };

    let progress = (frames > 1).then(|| {
        let bar = indicatif::ProgressBar::new(u64::from(frames));
        bar.set_style(
            indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} frames, {elapsed} elapsed, eta {eta}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar
    });
    if let Output::Folder(folder) = &output {
        std::fs::create_dir_all(folder).with_context(|| format!("cannot create {}", folder.display()))?;
    }
    let mut gif = match &output {
        Output::Gif(path) => {
            let file = File::create(path).with_context(|| format!("cannot create {}", path.display()))?;
            let mut encoder = image::codecs::gif::GifEncoder::new_with_speed(BufWriter::new(file), 10);
            encoder.set_repeat(image::codecs::gif::Repeat::Infinite)?;
            Some(encoder)
        }
        _ => None,
    };
    let mut colliders = ColliderMeshes::new();
    let (mut render_time, mut simulation_time) = (Duration::ZERO, Duration::ZERO);
    let mut out_of_view = 0;
    let mut body_pose = Pose::default();
    for frame in 0..frames {
        let time_secs = f64::from(frame) / args.fps;
        let sim_started = Instant::now();
        if instances.is_empty() {
            drivers[0].advance_to(device, queue, &mut steppers[0], time_secs)?;
        } else {
            // Far members are stepped less often (their level's stride), interpolated between.
            let levels: Vec<_> = (0..members).map(|member| level_at(member, time_secs)).collect();
            for (stepper, level) in steppers.iter_mut().zip(&levels) {
                stepper.set_step_stride(level.step_stride());
            }
            FurDriver::advance_herd((device, queue), &mut drivers, &mut steppers, &instances, time_secs)?;
            for (driver, level) in drivers.iter_mut().zip(levels) {
                driver.set_level(level);
            }
        }
        simulation_time += sim_started.elapsed();
        let stepper = &steppers[0];
        // Blended fur draws farthest first; a member the camera cannot see is not drawn (it still
        // casts its shadow).
        let spheres: Vec<_> = (0..members).map(|k| member_sphere(k, time_secs)).collect();
        let mut order: Vec<usize> =
            (0..members).filter(|&k| spheres[k].is_none_or(|(c, r)| view_data.sees_sphere(c, r))).collect();
        out_of_view = members - order.len();
        let distance = |k: usize| instances.get(k).map_or(0.0, |i| i.position_at(time_secs).distance(camera.eye));
        order.sort_by(|&a, &b| distance(b).total_cmp(&distance(a)));
        let render_started = Instant::now();
        // A script's lights may move.
        if frame > 0 && args.lights.light.is_none() && stepper.scene().is_some_and(|s| !s.light.is_empty()) {
            let studio = args.lights.studio(stepper.scene(), environment, time_secs);
            let view_data = studio.view_data(&camera, headless.aspect_ratio());
            view.prepare(queue, &view_data);
            // Their shadows move with them.
            surroundings
                .prepare((device, queue), &renderer, &view_data, &mut view)
                .context("aiming the shadow maps")?;
        }
        // The walking try-on body takes the fur's clip at the same time.
        if let (Some(body), Some(body_mesh), Some(plain_mesh)) = (&body, plain.first(), plain_meshes.first()) {
            body.rig.pose(body_mesh, clip, time_secs, &mut body_pose);
            plain_mesh.set_pose(queue, &body_pose.positions, &body_pose.normals)?;
        }
        // The simulation's GPU steps in a submission of their own: the frame's closures below
        // only read the driver.
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("simulation") });
        if let Some(posing) = &mut posing {
            posing.prepare((device, queue), &drivers, &steppers)?;
            posing.record(&mut encoder);
        }
        FurDriver::record_herd(&mut encoder, &mut drivers)?;
        queue.submit([encoder.finish()]);
        if moves {
            for mesh in &plain_meshes {
                mesh.prepare(queue, stepper.world_from_model());
            }
        }
        let simulation = stepper.simulation();
        let shown = stepper.shown_colliders(time_secs, args.show_colliders);
        let plane_half_size = 1.5 * simulation.bounding_radius();
        // The simulation runs in the world (the base is posed with the script's motion).
        colliders.update(device, queue, &renderer, &shown, Mat4::IDENTITY, plane_half_size)?;
        // The camera's draws in levels of members that share no pixel (`HerdDraws`).
        let members: Vec<_> =
            order.iter().map(|&k| (drivers[k].fur(), spheres[k].unwrap_or((Vec3::ZERO, f32::INFINITY)))).collect();
        plan.prepare((device, queue), &renderer, &view_data, &members);
        let furs: Vec<_> = members.iter().map(|(fur, _)| *fur).collect();
        let image = headless.render_with(
            studio.background,
            |encoder| {
                FurDriver::record_views(encoder, &renderer, &view, order.iter().map(|&member| &drivers[member]));
                surroundings.record(encoder, |pass, light| {
                    surroundings.draw_ground(pass, &renderer, light);
                    for mesh in &plain_meshes {
                        renderer.draw_plain(pass, light, mesh);
                    }
                    colliders.draw(pass, &renderer, light);
                    FurDriver::draw_herd(pass, &renderer, light, &drivers, &FurDrawSettings::ALL);
                });
            },
            |pass| {
                surroundings.draw_ground(pass, &renderer, &view);
                for mesh in &plain_meshes {
                    renderer.draw_plain(pass, &view, mesh);
                }
                colliders.draw(pass, &renderer, &view);
                renderer.draw_herd_planned(pass, &view, &plan, &furs, &settings);
            },
        )?;
        render_time += render_started.elapsed();
        match (&output, &mut gif) {
            (Output::Png(path), _) => save_png(&image, path)?,
            (Output::Folder(folder), _) => save_png(&image, &folder.join(format!("frame_{:04}.png", frame + 1)))?,
            (Output::Gif(_), Some(encoder)) => {
                let delay = image::Delay::from_saturating_duration(Duration::from_secs_f64(1.0 / args.fps));
                encoder.encode_frame(image::Frame::from_parts(image, 0, 0, delay))?;
            }
            (Output::Gif(_), None) => unreachable!("the GIF encoder exists for GIF output"),
        }
        if let Some(bar) = &progress {
            bar.inc(1);
        }
    }
    drop(gif);
    if let Some(bar) = progress {
        bar.finish_and_clear();
    }
    if let Some(body) = &body {
        println!("try-on: {}", body.transfer);
    }
    let per_frame = |total: Duration| total.as_secs_f64() * 1000.0 / f64::from(frames);
    let herd = if instances.is_empty() {
        String::new()
    } else {
        let stride = |k: u32| steppers.iter().filter(|s| s.simulation().step_stride() == k).count();
        format!(
            "a herd of {members} ({out_of_view} out of view, {} stepped every second step and {} every fourth in the \
             last frame), ",
            stride(2),
            stride(4)
        )
    };
    println!(
        "{}: {frames} frame{} of {width}x{height}, {herd}{} shell layers on {} triangles (level of detail: {}); mean frame {:.1} ms \
         (render and read back), simulation {:.1} ms a frame on the {} ({}); {:.1} s in all on {}, {}x MSAA",
        args.output.display(),
        if frames == 1 { "" } else { "s" },
        fur.layers,
        fur.mesh.triangles.len(),
        level.describe(fur.layers),
        per_frame(render_time),
        per_frame(simulation_time),
        drivers[0].kernel(),
        match args.sim {
            SimChoice::Gpu if posing.is_some() => "a herd, --sim gpu, posed on the GPU".to_owned(),
            SimChoice::Gpu if !instances.is_empty() => "a herd, --sim gpu, posed in one parallel pass".to_owned(),
            _ if !instances.is_empty() => "a herd, in one parallel pass".to_owned(),
            SimChoice::Auto => drivers[0].kernel_reason().to_owned(),
            SimChoice::Cpu => "--sim cpu".to_owned(),
            SimChoice::Gpu => "--sim gpu".to_owned(),
        },
        started.elapsed().as_secs_f64(),
        headless.gpu.summary(),
        headless.target().sample_count,
    );
    Ok(())
}

/// The animation `--animation` names: by default the first one an animated file has.
fn choose_animation(args: &Args, rig: Option<&Rig>) -> anyhow::Result<Option<usize>> {
    let clips = rig.map_or(0, |r| r.animations().len());
    match (args.animation.as_deref(), rig) {
        (Some("none"), _) => Ok(None),
        (Some(name), Some(rig)) if clips > 0 => {
            rig.find_animation(name).map(Some).map_err(|e| anyhow::anyhow!("--animation: {e}"))
        }
        (Some(name), _) => bail!("--animation {name:?}: the mesh has no animations"),
        (None, _) => Ok((clips > 0).then_some(0)),
    }
}

/// `--camera`, else the script's `[camera]`, else a view that frames the fur (and any plain
/// meshes) tightly, wherever the script's motion takes them: from the preset's `[render]`
/// angles, else from the front left.
fn camera(
    args: &Args,
    (preset, fur, plain): (&Preset, &FurStructure, &[Mesh]),
    (motion, scene_camera, instances): (&[pelt_core::sim::MotionKey], Option<&SceneCamera>, &[HerdInstance]),
    frames: u32,
    aspect_ratio: f32,
) -> Camera {
    let meshes = || std::iter::once(&fur.mesh).chain(plain);
    // The transforms the meshes take: every tenth of a second of the motion (or none), for each
    // member of a herd.
    let secs = f64::from(frames) / args.fps;
    let times = || (0..=(secs * 10.0).ceil() as u32).map(|k| f64::from(k) / 10.0);
    let motions: Vec<(f64, Mat4)> = if motion.is_empty() {
        vec![(0.0, Mat4::IDENTITY)]
    } else {
        times().filter_map(|t| pelt_core::sim::motion::motion_at(motion, t).map(|m| (t, m))).collect()
    };
    let transforms: Vec<Mat4> = if instances.is_empty() {
        motions.iter().map(|(_, m)| *m).collect()
    } else {
        // A herd walks whether or not the script moves it.
        let motions: Vec<(f64, Mat4)> =
            if motion.is_empty() { times().map(|t| (t, Mat4::IDENTITY)).collect() } else { motions };
        instances.iter().flat_map(|i| motions.iter().map(move |(t, m)| i.world_from_model(*t) * *m)).collect()
    };
    let all_points = || {
        transforms.iter().flat_map(move |m| {
            meshes().flat_map(move |mesh| mesh.positions.iter().map(move |p| m.transform_point3(*p)))
        })
    };
    let (low, high) = all_points()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(lo, hi), p| (lo.min(p), hi.max(p)));
    let centre = (low + high) * 0.5;
    let fur_length = fur.lengths.iter().copied().fold(0.0, f32::max);
    match (args.camera, scene_camera) {
        (Some(v), _) => Camera::orbit(centre, v.x, v.y, v.z),
        (None, Some(scene)) => {
            let target = scene.target.unwrap_or(centre);
            let (azimuth, elevation) = (scene.azimuth_deg, scene.elevation_deg);
            match scene.distance {
                Some(distance) => Camera::orbit(target, azimuth, elevation, distance),
                None => Camera::framing_points(target, all_points(), fur_length, azimuth, elevation, aspect_ratio),
            }
        }
        (None, None) => {
            let points = all_points();
            let azimuth = preset.render.camera_azimuth_deg.unwrap_or(30.0);
            let elevation = preset.render.camera_elevation_deg.unwrap_or(15.0);
            Camera::framing_points(centre, points, fur_length, azimuth, elevation, aspect_ratio)
        }
    }
}

fn save_png(image: &image::RgbaImage, path: &Path) -> anyhow::Result<()> {
    image.save(path).with_context(|| format!("cannot write {}", path.display()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn outputs_follow_the_extension() {
        assert!(matches!(Output::new(Path::new("a/b.PNG")), Output::Png(_)));
        assert!(matches!(Output::new(Path::new("a.gif")), Output::Gif(_)));
        assert!(matches!(Output::new(Path::new("frames")), Output::Folder(_)));
    }
}
