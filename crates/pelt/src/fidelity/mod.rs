//! `pelt fidelity`: how close shells and fins come to the strands they stand for. The same
//! seeded strand field is rendered three ways from each view (shells + fins, shells alone, and
//! every strand as a supersampled ribbon: the reference), then compared with SSIM over the fur
//! and over the silhouette band, and by mean colour difference.

mod metrics;

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use glam::{Mat4, Vec3};
use pelt_core::anim::Pose;
use pelt_core::light::direction_from_angles;
use pelt_core::reference::shadow::{ShadowCasters, ribbon_transmittance};
use pelt_core::reference::{StrandReference, WetClumps};
use pelt_core::sim::{FurStepper, SimParams, WindParams};
use pelt_core::{Builtin, FurStructure, Mesh, Preset, Stage, texture};
use pelt_render::{
    Backend, Camera, DEFAULT_BACKGROUND, FurDrawSettings, FurDriver, FurLook, FurRenderer, FurTarget, FurView, Gpu,
    HEADLESS_FORMAT, Headless, KernelChoice, PlainMesh, StrandRenderer, StrandRibbons, Studio, Surroundings, ViewData,
    default_sample_count, tile_mapping,
};

use self::metrics::Mask;
use crate::mesh_args::MeshArgs;
use crate::render::PLAIN_COLOUR;

/// Seconds simulated before the pictures are taken (the fur settles under gravity and wind; the
/// try-on body is 1.5 s into its walk, the right leg back and bent).
const SETTLE_SECS: f64 = 1.5;
/// Colour difference (0..=1) a channel must pass for a pixel to count as changed.
const CHANGED: u8 = 3;

/// Arguments of `pelt fidelity`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Renders shells + fins, shells alone and the explicit strands (the same seeded strands, as
supersampled ribbons) from each view; writes MODEL-VIEW.png (shells + fins | shells | strands |
difference heat map) into --out and prints SSIM over the fur and over the silhouette band. The
key light's shadow falls on both pictures unless --no-shadows; --light-angles 0,45,90,180
measures each view at those view-light angles.
Example: `pelt fidelity assets/meshes/spot.obj --preset assets/presets/spot.toml --json spot.json`.")]
pub struct Args {
    #[command(flatten)]
    mesh: MeshArgs,
    /// The fur preset (TOML); the built-in default fur without one.
    #[arg(long, value_name = "P")]
    preset: Option<PathBuf>,
    /// Views, comma separated: front (the default framing's angle), side (90 degrees round),
    /// back (180).
    #[arg(long, default_value = "front,side,back", value_name = "front,side,back")]
    views: String,
    /// Wind x,y,z (direction and strength); calm without it.
    #[arg(long, value_name = "X,Y,Z", value_parser = crate::values::parse_vec3, allow_hyphen_values = true)]
    wind: Option<Vec3>,
    /// A uniformly wet coat, 0 (dry) to 1 (soaked), held, as `pelt render --wetness` wets it:
    /// the shells darken, shine and clump, and the strands gather into the same clumps and
    /// darken and shine alike (the preset's `[wet]` says how much).
    #[arg(long, value_name = "W", value_parser = crate::values::parse_wetness)]
    wetness: Option<f32>,
    /// Write the results as JSON here.
    #[arg(long, value_name = "FILE")]
    json: Option<PathBuf>,
    #[command(flatten)]
    lights: crate::light_args::LightArgs,
    /// View-light angles, degrees, comma separated (e.g. 0,45,90,180): each view is measured
    /// once per angle, the key light (a sun) placed that far round from the direction to the
    /// camera, turned about the camera's vertical (toward increasing azimuth), so 0 lights the
    /// fur from the eye and 180 from straight behind it. Replaces --light's direction.
    #[arg(long, value_name = "DEGREES,...", value_delimiter = ',', conflicts_with = "light")]
    light_angles: Vec<f32>,
    /// No shadows: the shells without the key light's shadow maps and the strands without
    /// their traced shadow (by default the shells take the key light's shadow and deep opacity
    /// maps as `pelt render` draws them, and the strands their own shadow traced on the CPU).
    #[arg(long)]
    no_shadows: bool,
    /// The share of the key light a strand stops where it covers another from the light, in
    /// the strands' traced shadow: 1 (the default) makes them opaque, as they are drawn; less
    /// lets that share of what crosses them through (a what-if: hair passes some light on).
    #[arg(long, default_value_t = 1.0, value_name = "A", value_parser = parse_opacity)]
    strand_opacity: f32,
    /// Folder for the side-by-side images.
    #[arg(long, default_value = "fidelity", value_name = "DIR")]
    out: PathBuf,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512", value_parser = crate::values::parse_size)]
    size: (u32, u32),
    /// The strands are rendered at this many times the size on each axis, then filtered down.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=8))]
    supersample: u32,
    /// MSAA samples of the shells and fins: 1, 2, 4 or 8. Default: 1 on a CPU rasteriser
    /// (lavapipe), 4 on a GPU (as `pelt render`).
    #[arg(long, value_name = "N", value_parser = crate::values::parse_msaa)]
    msaa: Option<u32>,
    /// Graphics backend: vulkan, gl (or metal, dx12); default `WGPU_BACKEND`, else the best there is.
    #[arg(long, default_value = "auto")]
    backend: Backend,
}

fn parse_opacity(text: &str) -> Result<f32, String> {
    match text.trim().parse::<f32>() {
        Ok(value) if (0.0..=1.0).contains(&value) => Ok(value),
        _ => Err(format!("expected a share from 0 to 1, got {text:?}")),
    }
}

/// One model and view's figures (the `--json` keys).
#[derive(Debug, serde::Serialize)]
struct Figures {
    model: String,
    view: String,
    wind: [f32; 3],
    wetness: f32,
    /// Whether the key light cast shadows (shells: shadow maps; strands: traced).
    shadows: bool,
    /// The key light's azimuth and elevation, degrees (none: it follows the camera).
    light_deg: Option<[f32; 2]>,
    /// The angle between the directions to the camera and to the key light, degrees.
    light_angle_deg: Option<f32>,
    ssim_fur_shells_fins: f64,
    ssim_fur_shells: f64,
    ssim_silhouette_shells_fins: f64,
    ssim_silhouette_shells: f64,
    mean_colour_difference: f64,
    /// The reference against itself moved a quarter pixel (with 4x supersampling; `1 /
    /// supersample` pixel below that): how much SSIM sub-pixel placement alone costs.
    ssim_fur_reference_shifted: f64,
    /// The share of the skin's pixels the strands hide (differ from the bare skin there).
    coverage_strands: f64,
    /// The same for shells + fins.
    coverage_shells_fins: f64,
}

#[derive(Debug, serde::Serialize)]
struct Report {
    results: Vec<Figures>,
}

/// Degrees round from the front (the default framing's azimuth).
fn view_turn(name: &str) -> anyhow::Result<f32> {
    Ok(match name.trim() {
        "front" => 0.0,
        "side" => 90.0,
        "back" => 180.0,
        other => bail!("--views: unknown view {other:?}; choose from front, side, back"),
    })
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    // Each view's turn from the front.
    let views: Vec<(String, f32)> = args
        .views
        .split(',')
        .map(|name| Ok((name.trim().to_owned(), view_turn(name)?)))
        .collect::<anyhow::Result<_>>()?;
    let preset = match &args.preset {
        Some(path) => Preset::load(path)?,
        None => Preset::default(),
    };
    let (model, stage) = load_meshes(&args.mesh)?;
    let Stage { fur_mesh: mesh, rig, mut plain, body, .. } = stage;
    let fur = preset.grow(mesh, &model)?;
    // One strand field: the textures are drawn from it and the reference places it.
    let field = preset.strand_field()?;
    let textures = texture::generate_from(preset.layers, &field);

    let wind = args.wind.unwrap_or(Vec3::ZERO);
    let direction = wind.try_normalize().unwrap_or(Vec3::X);
    let simulation_params = SimParams {
        wind: WindParams { direction, strength: wind.length(), ..preset.simulation.wind.clone() },
        ..preset.simulation.clone()
    };
    let mut stepper = FurStepper::new(&fur, &preset.simulation)?;
    stepper.simulation_mut().set_wind(&simulation_params.wind)?;
    if args.wetness.is_some() {
        stepper.set_wet(&crate::render::wet_params(&preset, args.wetness))?;
    }
    // The try-on walks: the skirt and the body posed at `SETTLE_SECS` of the walk, the skirt's
    // fur pushed out of the legs by the body's capsules (as `pelt render --builtin tryon`).
    if let (Some(rig), Some(body), Some(body_mesh)) = (rig, &body, plain.first_mut()) {
        stepper.set_clip(rig, Some(0));
        stepper.set_body(Some((body_mesh.clone(), body.rig.clone(), body.capsules.clone())));
        let mut pose = Pose::default();
        body.rig.pose(body_mesh, Some(0), SETTLE_SECS, &mut pose);
        body_mesh.positions = pose.positions;
        body_mesh.normals = pose.normals;
    }

    let (width, height) = args.size;
    let gpu = Gpu::new(args.backend)?;
    let samples = args.msaa.unwrap_or_else(|| default_sample_count(&gpu.adapter.get_info()));
    let shells = Headless::with_target(gpu, FurTarget::new(HEADLESS_FORMAT).with_sample_count(samples), width, height)?;
    let factor = args.supersample;
    let shift = (factor / 4).max(1);
    let strands = Headless::with_target(
        Gpu::new(args.backend)?,
        FurTarget::new(HEADLESS_FORMAT).with_sample_count(1),
        width * factor,
        height * factor,
    )?;
    // The preset's `[shading]`, for the shells and the strands alike.
    let look = crate::light_args::preset_look(&preset);
    let shadows = !args.no_shadows;
    let mut shell_side = Side::new(&shells, &fur, &textures, &mut stepper, &plain, look, (shadows, (width, height)))?;
    // The strands' side has the same shadow maps (fitted to the output's size, not the
    // supersampled one): the skin and plain meshes under the strands take the same shadow as
    // under the shells; the strands themselves take their traced shadow instead.
    let mut strand_side = Side::new(&strands, &fur, &textures, &mut stepper, &plain, look, (shadows, (width, height)))?;
    let positions = stepper.simulation().positions();
    let reference = strand_reference(&fur, field, &stepper)?;
    let strand_renderer = StrandRenderer::new(&strands.gpu.device, &strand_side.renderer)?;
    let normals = stepper.moved_pose().map_or(&fur.mesh.normals, |pose| &pose.normals);
    let ribbons = StrandRibbons::new(&strands.gpu.device, &reference, positions, normals, &fur.mesh.triangles)?;
    // What casts the strands' traced shadow: the strands and the posed skin and plain meshes.
    let node_positions = reference.node_positions(positions)?;
    let node_radii = reference.node_radii();
    let node_ranges = reference.node_ranges();
    let skin = &positions[..fur.mesh.vertex_count()];
    let surfaces: Vec<[Vec3; 3]> = fur
        .mesh
        .triangles
        .iter()
        .map(|t| t.map(|j| skin[j as usize]))
        .chain(plain.iter().flat_map(|m| m.triangles.iter().map(|t| t.map(|j| m.positions[j as usize]))))
        .collect();
    let casters = ShadowCasters {
        nodes: &node_positions,
        radii: &node_radii,
        strands: &node_ranges,
        surfaces: &surfaces,
        opacity: args.strand_opacity,
    };

    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;
    let front = preset.render.camera_azimuth_deg.unwrap_or(30.0);
    let elevation = preset.render.camera_elevation_deg.unwrap_or(15.0);
    let fur_length = fur.lengths.iter().copied().fold(0.0, f32::max);
    // The posed skin (the simulation's roots) and the plain meshes.
    let roots = &positions[..fur.mesh.vertex_count()];
    let points: Vec<Vec3> = roots.iter().chain(plain.iter().flat_map(|m| &m.positions)).copied().collect();
    let (low, high) = points
        .iter()
        .fold((Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)), |(l, h), p| (l.min(*p), h.max(*p)));
    let centre = (low + high) * 0.5;
    let aspect = width as f32 / height as f32;
    let wetness = args.wetness.unwrap_or(0.0);
    let mut tag = if wind == Vec3::ZERO { String::new() } else { "-wind".to_owned() };
    if wetness > 0.0 {
        tag += &format!("-wet{wetness}");
    }
    let environment = args.lights.environment(None)?;
    let studio = args.lights.studio(None, environment, 0.0);
    // Each view once per view-light angle, or once in --light's (or the default) light.
    let angles: Vec<Option<f32>> =
        if args.light_angles.is_empty() { vec![None] } else { args.light_angles.iter().copied().map(Some).collect() };
    let mut results = Vec::new();
    for ((name, azimuth), angle) in views.iter().flat_map(|v| angles.iter().map(move |a| (v, *a))) {
        let camera_azimuth = front + azimuth;
        let camera =
            Camera::framing_points(centre, points.iter().copied(), fur_length, camera_azimuth, elevation, aspect);
        let (studio, light_deg) = match angle {
            Some(angle) => {
                let (light_azimuth, light_elevation) = light_at_angle(camera_azimuth, elevation, angle);
                let sun = Studio::sun_at(light_azimuth, light_elevation);
                (studio.with_lights(&[sun], studio.environment), Some([light_azimuth, light_elevation]))
            }
            None => (studio, key_light_angles(&studio)),
        };
        let view_data = studio.view_data(&camera, aspect);
        shell_side.prepare(&shells, &view_data)?;
        strand_side.prepare(&strands, &view_data)?;
        // The strands' own shadow, traced on the CPU for this view's key light, for each half of
        // each ribbon as this camera sees it (the fur's transform is the identity here).
        if shadows {
            let started = std::time::Instant::now();
            let receivers = ribbons.shadow_receivers(camera.eye);
            let transmittance = ribbon_transmittance(&casters, view_data.light_direction_world, &receivers);
            ribbons.set_transmittance(&strands.gpu.queue, Some(&transmittance))?;
            let sum: f64 = transmittance.iter().flatten().map(|&t| f64::from(t)).sum();
            println!(
                "{:>8} {name:<5} the strands' shadow traced in {:.1} s: mean transmittance {:.3} over {} points",
                "",
                started.elapsed().as_secs_f64(),
                sum / (2 * transmittance.len()).max(1) as f64,
                transmittance.len()
            );
        }
        let mut tag = tag.clone();
        if let Some(angle) = angle {
            tag += &format!("-light{angle}");
        }
        let empty = shells.render(DEFAULT_BACKGROUND, |_| {})?;
        let skin = shell_side.render(&shells, FurDrawSettings::SKIN, true)?;
        let fur_skin = shell_side.render(&shells, FurDrawSettings::SKIN, false)?;
        let shells_fins = shell_side.render(&shells, FurDrawSettings::SILHOUETTE, true)?;
        let shells_only =
            shell_side.render(&shells, FurDrawSettings { fins: false, ..FurDrawSettings::SILHOUETTE }, true)?;
        let big = strands.render(DEFAULT_BACKGROUND, |pass| {
            for mesh in &strand_side.plain {
                strand_side.renderer.draw_plain(pass, &strand_side.view, mesh);
            }
            strand_side.fur.draw(pass, &strand_side.renderer, &strand_side.view, &FurDrawSettings::SKIN);
            strand_renderer.draw(pass, &strand_side.view, strand_side.fur.fur(), &ribbons);
        })?;
        let reference_image = metrics::downsample(&big, factor);
        // The same strands a quarter pixel off: the measurement's own precision.
        let shifted_reference = metrics::downsample(&metrics::shifted(&big, shift), factor);

        let fur_mask = Mask::differing(&reference_image, &skin, CHANGED)
            .union(&Mask::differing(&shells_fins, &skin, CHANGED))
            .union(&Mask::differing(&shells_only, &skin, CHANGED));
        // The silhouette band: within the fur's projected length (and 2 pixels) of the outline.
        let body = Mask::differing(&fur_skin, &empty, 1);
        let distance = camera.eye.distance(camera.target);
        let pixels_per_unit = height as f32 / (2.0 * distance * (camera.fov_y_rad * 0.5).tan());
        let band_radius = (fur_length * pixels_per_unit).ceil() as u32 + 2;
        let band = body.dilate(band_radius).minus(&body.erode(band_radius));
        if fur_mask.count() == 0 || body.count() == 0 {
            bail!("{model} {name}: nothing was drawn (the fur is out of view or the render failed)");
        }
        let ssim = |image: &image::RgbaImage, mask: &Mask| -> anyhow::Result<f64> {
            metrics::masked_ssim(image, &reference_image, mask)?
                .with_context(|| format!("{model} {name}: the mask is empty"))
        };
        let result = Figures {
            model: model.clone(),
            view: name.clone(),
            wind: wind.to_array(),
            wetness,
            shadows,
            light_deg,
            light_angle_deg: angle,
            ssim_fur_shells_fins: ssim(&shells_fins, &fur_mask)?,
            ssim_fur_shells: ssim(&shells_only, &fur_mask)?,
            ssim_silhouette_shells_fins: ssim(&shells_fins, &band)?,
            ssim_silhouette_shells: ssim(&shells_only, &band)?,
            mean_colour_difference: metrics::mean_colour_difference(&shells_fins, &reference_image, &fur_mask)
                .unwrap_or(0.0),
            ssim_fur_reference_shifted: ssim(&shifted_reference, &fur_mask)?,
            coverage_strands: body.share_of(&Mask::differing(&reference_image, &skin, CHANGED)),
            coverage_shells_fins: body.share_of(&Mask::differing(&shells_fins, &skin, CHANGED)),
        };
        let heat = metrics::heat_map(&shells_fins, &reference_image, 0.25);
        let sheet = metrics::side_by_side(&[&shells_fins, &shells_only, &reference_image, &heat], 4, [255, 255, 255]);
        let path = args.out.join(format!("{model}-{name}{tag}.png"));
        sheet.save(&path).with_context(|| format!("cannot write {}", path.display()))?;
        println!(
            "{model:>8} {name:<5} wind {wind:<14} SSIM fur: shells+fins {:.3}, shells {:.3}; silhouette: shells+fins {:.3}, \
             shells {:.3}; mean colour difference {:.3}  -> {}",
            result.ssim_fur_shells_fins,
            result.ssim_fur_shells,
            result.ssim_silhouette_shells_fins,
            result.ssim_silhouette_shells,
            result.mean_colour_difference,
            path.display(),
            wind = format!("{:.2},{:.2},{:.2}", wind.x, wind.y, wind.z),
        );
        let statistics = |image: &image::RgbaImage| {
            let (mean, contrast) = metrics::luma_statistics(image, &fur_mask);
            format!("{mean:.0}/{contrast:.1}")
        };
        if let Some([light_azimuth, light_elevation]) = light_deg {
            println!(
                "{:>8} {name:<5} key light at {light_azimuth:.1},{light_elevation:.1}{}, shadows {}",
                "",
                angle.map_or(String::new(), |a| format!(" ({a} degrees from the camera)")),
                if shadows { "on" } else { "off" }
            );
        }
        println!(
            "{:>8} {name:<5} the strands against themselves {shift}/{factor} pixel off: SSIM fur {:.3}",
            "", result.ssim_fur_reference_shifted
        );
        println!(
            "{:>8} {name:<5} the skin hidden: by the strands {:.3}, by shells+fins {:.3}",
            "", result.coverage_strands, result.coverage_shells_fins
        );
        println!(
            "{:>8} {name:<5} luma mean/local contrast over the fur: shells+fins {}, shells {}, strands {}",
            "",
            statistics(&shells_fins),
            statistics(&shells_only),
            statistics(&reference_image)
        );
        results.push(result);
    }
    println!(
        "{} strands ({} ribbon triangles) at {}x supersampling; shells at {}x MSAA on {}",
        ribbons.strand_count(),
        ribbons.triangle_count(),
        factor,
        samples,
        shells.gpu.summary()
    );
    if let Some(path) = &args.json {
        let text = serde_json::to_string_pretty(&Report { results })?;
        std::fs::write(path, text + "\n").with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// The model's name and its stage (the furry mesh, any plain ones: the try-on body).
fn load_meshes(args: &MeshArgs) -> anyhow::Result<(String, Stage)> {
    let name = args.source(Builtin::Bunny)?.name();
    Ok((name, args.stage(Builtin::Bunny, &[])?))
}

/// The key light's azimuth and elevation (degrees) for a light that points `toward` it:
/// [`direction_from_angles`] undone.
fn angles_of(toward: Vec3) -> [f32; 2] {
    let d = toward.normalize_or(Vec3::Y);
    [d.x.atan2(d.z).to_degrees(), d.y.clamp(-1.0, 1.0).asin().to_degrees()]
}

/// The studio's key light's angles, when it is a sun fixed in the world.
fn key_light_angles(studio: &Studio) -> Option<[f32; 2]> {
    let key = studio.lights.as_slice().first()?;
    (key.kind == pelt_core::light::LightKind::Directional).then(|| angles_of(key.direction))
}

/// The key light `angle_deg` degrees round from the direction to a camera at `azimuth_deg`,
/// `elevation_deg` (about the camera's vertical, toward increasing azimuth), as azimuth and
/// elevation in degrees: the direction to the camera turned in the plane it shares with the
/// horizontal direction across the view, so the angle between the two is exactly `angle_deg`.
fn light_at_angle(azimuth_deg: f32, elevation_deg: f32, angle_deg: f32) -> (f32, f32) {
    let to_camera = direction_from_angles(azimuth_deg, elevation_deg);
    let across = direction_from_angles(azimuth_deg + 90.0, 0.0);
    let (sin, cos) = angle_deg.to_radians().sin_cos();
    let [azimuth, elevation] = angles_of(to_camera * cos + across * sin);
    (azimuth, elevation)
}

/// One headless target's renderer, fur, view, plain meshes and the key light's shadow maps.
struct Side {
    renderer: FurRenderer,
    fur: FurDriver,
    view: FurView,
    plain: Vec<PlainMesh>,
    surroundings: Surroundings,
}

impl Side {
    fn new(
        headless: &Headless,
        fur: &FurStructure,
        textures: &pelt_core::FurTextures,
        stepper: &mut FurStepper,
        plain_meshes: &[Mesh],
        look: FurLook,
        (shadows, picture_size): (bool, (u32, u32)),
    ) -> anyhow::Result<Self> {
        let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
        let renderer = headless.renderer()?;
        // The fur settled under gravity (and `--wind`): a still frame.
        let params = stepper.simulation().params().clone();
        let mut gpu_fur = FurDriver::new(device, queue, &renderer, fur, textures, &params, KernelChoice::Cpu)?;
        gpu_fur.set_look(look);
        gpu_fur.advance_to(device, queue, stepper, SETTLE_SECS)?;
        let plain = plain_meshes
            .iter()
            .map(|mesh| PlainMesh::new(device, &renderer, mesh, PLAIN_COLOUR))
            .collect::<Result<Vec<_>, _>>()?;
        for mesh in &plain {
            mesh.prepare(queue, Mat4::IDENTITY);
        }
        let view = FurView::new(device, &renderer);
        // As `pelt render` draws them: the key light's shadow and deep opacity maps fitted to
        // the picture.
        let mut surroundings = Surroundings::new(device, queue, &renderer, shadows, None, (fur, plain_meshes))
            .context("making the shadow maps")?;
        surroundings.fit_to_frame(device, &renderer, picture_size).context("fitting the shadow maps")?;
        Ok(Self { renderer, fur: gpu_fur, view, plain, surroundings })
    }

    /// Prepares the view for `view_data` and draws the key light's shadow maps (skin, plain
    /// meshes, shells and fins) for it.
    fn prepare(&mut self, headless: &Headless, view_data: &ViewData) -> anyhow::Result<()> {
        let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
        self.view.prepare(queue, view_data);
        self.surroundings
            .prepare((device, queue), &self.renderer, view_data, &mut self.view)
            .context("aiming the shadow maps")?;
        if !self.surroundings.has_shadows() {
            return Ok(());
        }
        let mut encoder =
            device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pelt fidelity shadows") });
        self.surroundings.record(&mut encoder, |pass, light| {
            for mesh in &self.plain {
                self.renderer.draw_plain(pass, light, mesh);
            }
            self.fur.draw(pass, &self.renderer, light, &FurDrawSettings::ALL);
        });
        queue.submit([encoder.finish()]);
        Ok(())
    }

    /// The shells' side: `settings` for the fur, with or without the plain meshes.
    fn render(
        &self,
        headless: &Headless,
        settings: FurDrawSettings,
        with_plain: bool,
    ) -> anyhow::Result<image::RgbaImage> {
        Ok(headless.render_with(
            DEFAULT_BACKGROUND,
            |encoder| {
                if settings.fins {
                    self.fur.record_view(encoder, &self.renderer, &self.view);
                }
            },
            |pass| {
                if with_plain {
                    for mesh in &self.plain {
                        self.renderer.draw_plain(pass, &self.view, mesh);
                    }
                }
                self.fur.draw(pass, &self.renderer, &self.view, &settings);
            },
        )?)
    }
}

/// Every strand `fur`'s shells stand for, placed on the mesh as `stepper` leaves the coat: a wet
/// coat's strands gather into the clumps the shells draw. `pelt fidelity` compares with them and
/// `pelt export -o *.usda` writes them.
pub fn strand_reference(
    fur: &FurStructure,
    field: texture::StrandField,
    stepper: &FurStepper,
) -> anyhow::Result<StrandReference> {
    let mapping = tile_mapping(&fur.mesh, &FurLook::default());
    if stepper.wetness().is_dry() {
        return Ok(StrandReference::new(fur, field, mapping)?);
    }
    let wet = stepper.wet();
    let clumps = WetClumps {
        wetness: stepper.wetness().values().to_vec(),
        clump_size: wet.clump_size,
        clump_strength: wet.clump_strength,
        groom_clump: fur.groom.as_ref().and_then(|g| g.clump.clone()),
    };
    Ok(StrandReference::wet(fur, field, mapping, &clumps)?)
}
