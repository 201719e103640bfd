//! `pelt export`: the fur, settled, as a standard glTF file (`.glb`, or `.gltf` with a `.bin`)
//! that glTF viewers and engines draw with their own materials, or its strands as USD hair
//! curves (`.usda`, `export_usd`).

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context as _, bail};
use glam::Vec3;
use pelt_core::anim::{Pose, Property, Rig};
use pelt_core::export::{
    AlphaMode, Export, ExportInput, FurMorphs, FurSkin, MorphAnimation, bind_space_positions, carried_up,
    exported_layers, source_skin_joints,
};
use pelt_core::sim::{FurStepper, WindParams};
use pelt_core::{Builtin, FurStructure, Preset, Stage, StageSource};
use pelt_render::{FurLook, tile_mapping};
use serde_json::json;

use crate::mesh_args::MeshArgs;
use crate::render::{LIGHT_WIND, PLAIN_COLOUR};

/// How long the fur settles under gravity before it is written (seconds of simulated time).
pub(crate) const SETTLE_SECS: f64 = 1.5;
/// Frame rate the simulation is driven at while a clip plays to `--time`.
pub(crate) const DRIVE_FPS: f64 = 30.0;
/// How long the wind blows before `--motion` samples it (the lean it starts with is not looped).
const MOTION_WARM_SECS: f64 = 1.0;
/// Sampled frames (morph targets) per second of `--motion`, and at most: each frame is a copy of
/// every fur position in the file.
const MOTION_FPS: f64 = 4.0;
const MOTION_MAX_FRAMES: u32 = 24;

/// The `--alpha` choices.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Alpha {
    /// Alpha tested: hard strand edges, no sorting.
    Mask,
    /// Alpha blended: soft strands; players draw the layers in file order.
    Blend,
}

/// Arguments of `pelt export`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
The fur is settled under gravity (no wind) at the rest pose, or with --time at that time of an
animation (--animation picks it; the first by default). A glTF source is copied whole (meshes,
materials, skins, animations); on a skinned mesh every fur vertex follows its root's joints.
A .usda output holds the strands the shells stand for (where `pelt fidelity` places them) as
USD BasisCurves on the base mesh; --motion there adds time samples (the clip plays on from
--time, the fur sways in the wind). Examples: `pelt export --builtin bunny -o bunny.glb`,
`pelt export assets/meshes/Fox.glb --preset assets/presets/fox.toml --time 0.5 --animation Walk
-o fox.glb`, `pelt export assets/meshes/Fox.glb --preset assets/presets/fox_groomed.toml -o
fox.usda`.")]
pub struct Args {
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// The fur preset (TOML); the built-in default fur without one.
    #[arg(long, value_name = "P")]
    pub preset: Option<PathBuf>,
    /// Shells to write (spread evenly up to the tips); default every layer of the preset.
    #[arg(long, value_name = "N", conflicts_with = "screen_size")]
    pub layers: Option<u32>,
    /// Shells for a fur this many pixels tall on screen: the level `pelt render` draws it at
    /// there (the preset's `[render.lod]`), in place of `--layers`.
    #[arg(long, value_name = "PIXELS")]
    pub screen_size: Option<u32>,
    /// Bake this many seconds of the fur swaying in the preset's wind (pelt render's light breeze
    /// if it has none) as morph targets with a looping weights animation ("pelt fur motion").
    #[arg(long, value_name = "SECONDS", allow_negative_numbers = true)]
    pub motion: Option<f64>,
    /// Settle the fur at this time (seconds) of the animation instead of the rest pose.
    #[arg(long, value_name = "T", allow_negative_numbers = true)]
    pub time: Option<f64>,
    /// The animation `--time` refers to: its name or index (default: the first).
    #[arg(long, value_name = "NAME|INDEX")]
    pub animation: Option<String>,
    /// How the fur's materials treat alpha. `mask` by default: in three.js it comes closer to
    /// `pelt render`'s picture than `blend` (web/export-test), and it needs no sorting.
    #[arg(long, value_enum, default_value_t = Alpha::Mask)]
    pub alpha: Alpha,
    /// .usda: the share of the strands written, above 0 and at most 1 (seeded per strand).
    #[arg(long, value_name = "F")]
    pub strand_fraction: Option<f32>,
    /// .usda: how the curves run between their points.
    #[arg(long, value_enum)]
    pub curves: Option<crate::export_usd::Curves>,
    /// .usda: a uniformly wet coat, 0 (dry) to 1 (soaked): the strands gather into the wet
    /// clumps and droop under the water's weight (the preset's `[wet]`).
    #[arg(long, value_name = "W", value_parser = crate::values::parse_wetness)]
    pub wetness: Option<f32>,
    /// .usda: metres per unit of the mesh (`metersPerUnit`; glTF's metres by default).
    #[arg(long, value_name = "M", allow_negative_numbers = true)]
    pub meters_per_unit: Option<f64>,
    /// Output: a .glb, a .gltf (its buffer written beside it as a .bin), or a .usda (the strands
    /// as USD hair curves on the base mesh; .usd writes the same text).
    #[arg(short, long, default_value = "pelt.glb")]
    pub output: PathBuf,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let started = Instant::now();
    check_output(args)?;
    if crate::export_usd::is_usda(&args.output) {
        return crate::export_usd::run(args, started);
    }
    let usd_only = [
        ("--strand-fraction", args.strand_fraction.is_some()),
        ("--curves", args.curves.is_some()),
        ("--wetness", args.wetness.is_some()),
        ("--meters-per-unit", args.meters_per_unit.is_some()),
    ];
    if let Some((flag, _)) = usd_only.iter().find(|(_, given)| *given) {
        bail!("{flag}: only a .usda export (the strands as curves) takes it");
    }
    if args.layers == Some(0) {
        bail!("--layers must be at least 1, got 0");
    }
    check_time_and_motion(args)?;
    if args.screen_size == Some(0) {
        bail!("--screen-size must be at least 1 pixel, got 0");
    }
    let preset = match &args.preset {
        Some(path) => Preset::load(path)?,
        None => Preset::default(),
    };
    let source = args.mesh.source(Builtin::Bunny)?;
    let Stage { fur_mesh: mesh, rig, plain, .. } = args.mesh.stage(Builtin::Bunny, &[])?;
    let clip = choose_clip(args, rig.as_ref())?;
    // The preset's groom too: lengths, directions, and no fur on its bald faces.
    let fur = preset.grow(mesh, &source.name())?;
    let shells = match args.screen_size {
        Some(pixels) => shells_at_screen_size(&preset, &fur, pixels),
        None => args.layers.unwrap_or(fur.layers),
    };
    if shells > fur.layers {
        bail!("--layers {shells}: the preset has only {} layers", fur.layers);
    }
    let textures = preset.generate_textures()?;

    let motion_frames = args.motion.map(|secs| ((secs * MOTION_FPS).round() as u32).clamp(2, MOTION_MAX_FRAMES));
    let progress = Progress::new(settle_frames(args.time) + motion_frames.map_or(0, |n| motion_steps(args, n)));
    let mut stepper = settle(&fur, &preset, rig.as_ref(), clip, args.time, &progress)?;
    let time_secs = if clip.is_some() { args.time.unwrap_or(0.0) } else { 0.0 };
    let settled = stepper.simulation().positions().to_vec();
    let motion = match (args.motion, motion_frames) {
        (Some(secs), Some(frames)) => Some(sway(&mut stepper, &preset, time_secs, secs, frames, &progress)?),
        _ => None,
    };
    let gltf_source = match &source {
        StageSource::File(path) if is_gltf(path) => Some(path.clone()),
        _ => None,
    };
    let rigged = Rigged { fur: &fur, rig: rig.as_ref(), clip, time_secs, source: gltf_source.as_deref() };
    let Bound { positions, skin, morphs, notes } = rigged.bind(settled, motion, args.motion)?;
    progress.finish_simulation();
    let look = FurLook::default();
    let plain: Vec<_> = plain.iter().map(|mesh| (mesh, PLAIN_COLOUR)).collect();
    let layers_written = exported_layers(fur.layers, shells);
    let extras = json!({
        "version": env!("CARGO_PKG_VERSION"),
        "source": source.name(),
        "preset_file": args.preset.as_ref().map(|p| p.display().to_string()),
        "preset": preset.to_toml_string()?,
        "layers": fur.layers,
        "shells": layers_written,
        "time_secs": time_secs,
        "animation": clip.and_then(|k| rig.as_ref().and_then(|r| r.animations()[k].name.clone())),
        "alpha": format!("{:?}", args.alpha).to_ascii_lowercase(),
        "motion_secs": args.motion,
        "motion_frames": motion_frames,
    });
    let input = ExportInput {
        fur: &fur,
        positions: &positions,
        textures: &textures,
        mapping: tile_mapping(&fur.mesh, &look),
        root_occlusion: look.root_occlusion,
        shells,
        alpha: match args.alpha {
            Alpha::Mask => AlphaMode::Mask,
            Alpha::Blend => AlphaMode::Blend,
        },
        skin,
        source: gltf_source.as_deref(),
        plain: &plain,
        extras,
        morphs,
    };
    let export = Export::build(&input)?;
    export.write(&args.output)?;
    progress.done();
    // A .gltf's buffer is its .bin beside it.
    let mut files = vec![args.output.clone()];
    if args.output.extension().is_some_and(|e| e.eq_ignore_ascii_case("gltf")) {
        files.push(args.output.with_extension("bin"));
    }
    let bytes: u64 = files.iter().filter_map(|path| std::fs::metadata(path).ok()).map(|m| m.len()).sum();
    let counts = &export.counts;
    for note in notes {
        println!("note: {note}");
    }
    let motion_text = match (args.motion, motion_frames) {
        (Some(secs), Some(frames)) => format!(", {secs} s of motion in {frames} morph targets"),
        _ => String::new(),
    };
    println!(
        "{}: {:.2} MB, {} shells of {} vertices and {} triangles, fins of {} vertices and {} triangles, {}{motion_text}; {:.2} s",
        args.output.display(),
        bytes as f64 / 1e6,
        counts.shell_layers.len(),
        counts.shell_vertices,
        counts.shell_triangles,
        counts.fin_vertices,
        counts.fin_triangles,
        match (clip, rig.as_ref()) {
            (Some(k), Some(rig)) =>
                format!("at {time_secs:.2} s of {:?}", rig.animations()[k].name.as_deref().unwrap_or("(unnamed)")),
            _ => "at the rest pose".to_owned(),
        },
        started.elapsed().as_secs_f64(),
    );
    Ok(())
}

pub(crate) fn is_gltf(path: &Path) -> bool {
    matches!(path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(), Some("gltf" | "glb"))
}

/// Fails early, before any work, on an output that cannot be written.
pub(crate) fn check_output(args: &Args) -> anyhow::Result<()> {
    let path = &args.output;
    if !matches!(
        path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
        Some("glb" | "gltf" | "usda" | "usd")
    ) {
        bail!("{}: the output must end in .glb, .gltf or .usda (.usd)", path.display());
    }
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p,
        _ => Path::new("."),
    };
    let metadata = std::fs::metadata(folder).with_context(|| format!("cannot write {}", path.display()))?;
    if !metadata.is_dir() {
        bail!("cannot write {}: {} is not a folder", path.display(), folder.display());
    }
    if path.is_dir() {
        bail!("cannot write {}: it is a folder", path.display());
    }
    Ok(())
}

/// The clip `--time` refers to: none without `--time` and `--animation` (the rest pose).
pub(crate) fn choose_clip(args: &Args, rig: Option<&Rig>) -> anyhow::Result<Option<usize>> {
    let clips = rig.map_or(0, |r| r.animations().len());
    let clip = match (args.animation.as_deref(), rig) {
        (Some(name), Some(rig)) if clips > 0 => {
            Some(rig.find_animation(name).map_err(|e| anyhow::anyhow!("--animation: {e}"))?)
        }
        (Some(name), _) => bail!("--animation {name:?}: the mesh has no animations"),
        (None, _) if args.time.is_some() && clips > 0 => Some(0),
        (None, _) => None,
    };
    if let (Some(time), Some(k), Some(rig)) = (args.time, clip, rig) {
        let animation = &rig.animations()[k];
        let duration = f64::from(animation.duration_secs());
        if time > duration + 1e-6 {
            bail!(
                "--time {time}: past the end of the animation {:?} ({duration:.3} s long)",
                animation.name.as_deref().unwrap_or("(unnamed)")
            );
        }
    }
    if args.time.is_some() && clip.is_none() {
        bail!("--time: the mesh has no animations (without --time the fur settles at the rest pose)");
    }
    Ok(clip)
}

/// Simulation frames of the settling (and of the clip up to `--time`).
pub(crate) fn settle_frames(time: Option<f64>) -> u64 {
    let settle = (SETTLE_SECS * DRIVE_FPS).round() as u64 + 1;
    settle + time.map_or(0, |t| (t * DRIVE_FPS).ceil() as u64)
}

/// Simulation frames of `--motion`: the warm-up and the sampled seconds.
fn motion_steps(args: &Args, frames: u32) -> u64 {
    let secs = args.motion.unwrap_or(0.0);
    ((MOTION_WARM_SECS + secs) * DRIVE_FPS).ceil() as u64 + u64::from(frames)
}

/// Settles the fur under gravity (no wind): at the rest pose, or in the clip's first pose and
/// then through the clip to `time`. The stepper at the end (posed at the clip time).
pub(crate) fn settle(
    fur: &FurStructure,
    preset: &Preset,
    rig: Option<&Rig>,
    clip: Option<usize>,
    time: Option<f64>,
    progress: &Progress,
) -> anyhow::Result<FurStepper> {
    settle_wet(fur, preset, rig, clip, time, None, progress)
}

/// [`settle`] with the coat held at `wetness` (the preset's `[wet]`) while it settles.
pub(crate) fn settle_wet(
    fur: &FurStructure,
    preset: &Preset,
    rig: Option<&Rig>,
    clip: Option<usize>,
    time: Option<f64>,
    wetness: Option<f32>,
    progress: &Progress,
) -> anyhow::Result<FurStepper> {
    let mut params = preset.simulation.clone();
    params.wind = WindParams { strength: 0.0, ..params.wind };
    let mut stepper = FurStepper::new(fur, &params)?;
    if wetness.is_some() {
        stepper.set_wet(&crate::render::wet_params(preset, wetness))?;
    }
    if let (Some(rig), Some(_)) = (rig, clip) {
        stepper.set_clip(rig.clone(), clip);
    }
    let settle_frames = (SETTLE_SECS * DRIVE_FPS).round() as u32;
    for frame in 0..=settle_frames {
        stepper.advance_with_clip_at(f64::from(frame) / DRIVE_FPS, 0.0)?;
        progress.step();
    }
    let clip_secs = if clip.is_some() { time.unwrap_or(0.0) } else { 0.0 };
    if clip_secs > 0.0 {
        let frames = (clip_secs * DRIVE_FPS).ceil() as u32;
        for frame in 1..=frames {
            let t = (f64::from(frame) / DRIVE_FPS).min(clip_secs);
            stepper.advance_with_clip_at(SETTLE_SECS + t, t)?;
            progress.step();
        }
    }
    Ok(stepper)
}

/// The settled fur swaying in the preset's wind (`pelt render`'s light breeze if it has none),
/// the pose held at `clip_secs`: after a warm-up, `frames` shared arrays (posed) sampled evenly
/// over `secs`.
fn sway(
    stepper: &mut FurStepper,
    preset: &Preset,
    clip_secs: f64,
    secs: f64,
    frames: u32,
    progress: &Progress,
) -> anyhow::Result<Vec<Vec<Vec3>>> {
    let mut wind = preset.simulation.wind.clone();
    if wind.strength <= 0.0 {
        wind = WindParams { direction: LIGHT_WIND.normalize(), strength: LIGHT_WIND.length(), ..wind };
    }
    stepper.simulation_mut().set_wind(&wind)?;
    let start = SETTLE_SECS + clip_secs;
    let mut now = 0.0;
    let mut advance = |to: f64, stepper: &mut FurStepper| -> anyhow::Result<()> {
        while now < to - 1e-9 {
            now = (now + 1.0 / DRIVE_FPS).min(to);
            stepper.advance_with_clip_at(start + now, clip_secs)?;
            progress.step();
        }
        Ok(())
    };
    let mut sampled = Vec::with_capacity(frames as usize);
    for k in 0..frames {
        advance(MOTION_WARM_SECS + secs * f64::from(k) / f64::from(frames), stepper)?;
        sampled.push(stepper.simulation().positions().to_vec());
        progress.step();
    }
    Ok(sampled)
}

/// The fur and how its file moves, for binding the settled arrays to it.
struct Rigged<'a> {
    fur: &'a FurStructure,
    rig: Option<&'a Rig>,
    clip: Option<usize>,
    time_secs: f64,
    /// The glTF file the mesh came from.
    source: Option<&'a Path>,
}

impl Rigged<'_> {
    /// The settled shared array in the mesh's own space (the bind pose of a skinned glTF, the
    /// morph targets' rest), the skin it is bound to, its morph targets (the source's, carried
    /// up every strand, or the sampled `motion` frames as deltas from it), and notes on what
    /// could not follow.
    fn bind(
        &self,
        posed: Vec<Vec3>,
        motion: Option<Vec<Vec<Vec3>>>,
        motion_secs: Option<f64>,
    ) -> anyhow::Result<Bound> {
        let fur = self.fur;
        let mut notes = Vec::new();
        let (positions, matrices, skin) = match (self.rig, self.source) {
            (Some(rig), Some(source)) => {
                let mut pose = Pose::default();
                rig.pose(&fur.mesh, self.clip, self.time_secs, &mut pose);
                let matrices = rig.vertex_matrices(&pose);
                let mut positions = bind_space_positions(&posed, &fur.positions, &matrices);
                let skins = source_skin_joints(source)?;
                let skin = skins.iter().enumerate().find_map(|(s, joints)| {
                    rig.influences_in_skin(joints).map(|influences| FurSkin { skin: s, influences })
                });
                // Channels on morph weights alone move the fur through its targets, not a skin.
                let moves_nodes =
                    rig.animations().iter().flat_map(|a| &a.channels).any(|c| c.property != Property::Weights);
                if skin.is_none() && moves_nodes {
                    notes.push(
                        "the fur does not follow the file's animations: its mesh is not bound to a single skin"
                            .to_owned(),
                    );
                }
                match rig.morph_position_deltas() {
                    _ if rig.morph_target_count() == 0 => {}
                    Some(_) if motion.is_some() => notes.push(
                        "the fur's roots do not follow the file's morph targets: --motion uses the fur's".to_owned(),
                    ),
                    Some((node, deltas)) => {
                        // The roots sit where the pose's weights put them; the file's targets
                        // start from the rest, so that displacement comes off every strand.
                        let weights = pose.morph_weights(node);
                        let v = fur.vertex_count();
                        for (j, offset) in (0..v).map(|j| {
                            (j, deltas.iter().zip(weights).map(|(d, w)| d[j] * *w).fold(Vec3::ZERO, |a, b| a + b))
                        }) {
                            for layer in 0..=fur.layers as usize {
                                positions[layer * v + j] -= offset;
                            }
                        }
                        let morphs = FurMorphs {
                            targets: deltas.iter().map(|d| carried_up(d, fur.layers)).collect(),
                            weights: rig.nodes()[node].rest_weights.clone(),
                            animation: MorphAnimation::FollowNode(node),
                        };
                        return Ok(Bound { positions, skin, morphs: Some(morphs), notes });
                    }
                    None => notes.push(
                        "the fur's roots do not follow the file's morph targets: they hang on several meshes"
                            .to_owned(),
                    ),
                }
                (positions, Some(matrices), skin)
            }
            _ => (posed, None, None),
        };
        let morphs = motion.map(|frames| FurMorphs {
            targets: frames
                .iter()
                .map(|frame| {
                    let frame = match &matrices {
                        Some(matrices) => bind_space_positions(frame, &fur.positions, matrices),
                        None => frame.clone(),
                    };
                    frame.iter().zip(&positions).map(|(a, b)| *a - *b).collect()
                })
                .collect(),
            weights: Vec::new(),
            animation: MorphAnimation::Loop {
                name: "pelt fur motion".to_owned(),
                period_secs: motion_secs.unwrap_or(1.0) as f32,
            },
        });
        Ok(Bound { positions, skin, morphs, notes })
    }
}

/// The settled fur as the file holds it: what [`Rigged::bind`] gives.
struct Bound {
    positions: Vec<Vec3>,
    skin: Option<FurSkin>,
    morphs: Option<FurMorphs>,
    notes: Vec<String>,
}

/// The shells `pelt render` draws a fur `pixels` tall on screen with (the preset's
/// `[render.lod]`): its strands span `length / (2 * (radius + length))` of that height.
fn shells_at_screen_size(preset: &Preset, fur: &FurStructure, pixels: u32) -> u32 {
    let length = fur.lengths.iter().copied().fold(0.0, f32::max);
    let (_, radius) = fur.mesh.bounding_sphere();
    let strand_pixels = length * pixels as f32 / (2.0 * (radius + length)).max(1e-6);
    crate::lod::settings(&preset.render.lod, false).level(fur.layers, strand_pixels).shells(fur.layers)
}

/// A bar on stderr over the export's simulation frames, drawn only on a terminal.
pub(crate) struct Progress(indicatif::ProgressBar);

impl Progress {
    pub(crate) fn new(steps: u64) -> Self {
        let bar = indicatif::ProgressBar::with_draw_target(Some(steps), indicatif::ProgressDrawTarget::stderr());
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{msg:12} {bar:40} {pos}/{len} frames, {elapsed} elapsed, eta {eta}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        bar.set_message("simulating");
        Self(bar)
    }

    pub(crate) fn step(&self) {
        self.0.inc(1);
    }

    pub(crate) fn finish_simulation(&self) {
        self.0.set_message("writing");
    }

    pub(crate) fn done(&self) {
        self.0.finish_and_clear();
    }
}

/// `--time` and `--motion`, checked alike for every kind of export.
pub fn check_time_and_motion(args: &Args) -> anyhow::Result<()> {
    if let Some(time) = args.time
        && !(time.is_finite() && time >= 0.0)
    {
        bail!("--time must be a number of seconds, 0 or more, got {time}");
    }
    if let Some(motion) = args.motion
        && !(motion.is_finite() && motion > 0.0 && motion <= 60.0)
    {
        bail!("--motion must be a number of seconds above 0 and at most 60, got {motion}");
    }
    Ok(())
}
