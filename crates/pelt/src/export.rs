//! `pelt export`: the fur, settled, as a standard glTF file (`.glb`, or `.gltf` with a `.bin`)
//! that glTF viewers and engines draw with their own materials.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context as _, bail};
use glam::Vec3;
use pelt_core::anim::{Pose, Rig};
use pelt_core::export::{
    AlphaMode, Export, ExportInput, FurSkin, bind_space_positions, exported_layers, source_skin_joints,
};
use pelt_core::sim::{FurStepper, WindParams};
use pelt_core::{Builtin, FurStructure, Preset, Stage, StageSource};
use pelt_render::{FurLook, tile_mapping};
use serde_json::json;

use crate::mesh_args::MeshArgs;
use crate::render::PLAIN_COLOUR;

/// How long the fur settles under gravity before it is written (seconds of simulated time).
const SETTLE_SECS: f64 = 1.5;
/// Frame rate the simulation is driven at while a clip plays to `--time`.
const DRIVE_FPS: f64 = 30.0;

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
Examples: `pelt export --builtin bunny -o bunny.glb`, `pelt export assets/meshes/Fox.glb
--preset assets/presets/fox.toml --time 0.5 --animation Walk -o fox.glb`.")]
pub struct Args {
    #[command(flatten)]
    mesh: MeshArgs,
    /// The fur preset (TOML); the built-in default fur without one.
    #[arg(long, value_name = "P")]
    preset: Option<PathBuf>,
    /// Shells to write (spread evenly up to the tips); default every layer of the preset.
    #[arg(long, value_name = "N")]
    layers: Option<u32>,
    /// Settle the fur at this time (seconds) of the animation instead of the rest pose.
    #[arg(long, value_name = "T")]
    time: Option<f64>,
    /// The animation `--time` refers to: its name or index (default: the first).
    #[arg(long, value_name = "NAME|INDEX")]
    animation: Option<String>,
    /// How the fur's materials treat alpha. `mask` by default: in three.js it comes closer to
    /// `pelt render`'s picture than `blend` (web/export-test), and it needs no sorting.
    #[arg(long, value_enum, default_value_t = Alpha::Mask)]
    alpha: Alpha,
    /// Output: a .glb, or a .gltf (its buffer written beside it as a .bin).
    #[arg(short, long, default_value = "pelt.glb")]
    output: PathBuf,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let started = Instant::now();
    check_output(args)?;
    if args.layers == Some(0) {
        bail!("--layers must be at least 1, got 0");
    }
    if let Some(time) = args.time
        && !(time.is_finite() && time >= 0.0)
    {
        bail!("--time must be a number of seconds, 0 or more, got {time}");
    }
    let preset = match &args.preset {
        Some(path) => Preset::load(path)?,
        None => Preset::default(),
    };
    let source = args.mesh.source(Builtin::Bunny)?;
    let Stage { fur_mesh: mesh, rig, plain, .. } = args.mesh.stage(Builtin::Bunny, &[])?;
    let clip = choose_clip(args, rig.as_ref())?;
    let params = preset.fur_params(&mesh);
    let fur = FurStructure::new(mesh, &params)?;
    let shells = args.layers.unwrap_or(fur.layers);
    if shells > fur.layers {
        bail!("--layers {shells}: the preset has only {} layers", fur.layers);
    }
    let textures = preset.generate_textures()?;

    let (positions, time_secs) = settle(&fur, &preset, rig.as_ref(), clip, args.time)?;
    let gltf_source = match &source {
        StageSource::File(path) if is_gltf(path) => Some(path.clone()),
        _ => None,
    };
    let (positions, skin, notes) = bind(&fur, positions, rig.as_ref(), clip, time_secs, gltf_source.as_deref())?;
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
    };
    let export = Export::build(&input)?;
    export.write(&args.output)?;
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
    println!(
        "{}: {:.2} MB, {} shells of {} vertices and {} triangles, fins of {} vertices and {} triangles, {}; {:.2} s",
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

fn is_gltf(path: &Path) -> bool {
    matches!(path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(), Some("gltf" | "glb"))
}

/// Fails early, before any work, on an output that cannot be written.
fn check_output(args: &Args) -> anyhow::Result<()> {
    let path = &args.output;
    if !matches!(
        path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref(),
        Some("glb" | "gltf")
    ) {
        bail!("{}: the output must end in .glb or .gltf", path.display());
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
fn choose_clip(args: &Args, rig: Option<&Rig>) -> anyhow::Result<Option<usize>> {
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

/// Settles the fur under gravity (no wind): at the rest pose, or in the clip's first pose and
/// then through the clip to `time`. The shared array at the end, posed, and the clip time.
fn settle(
    fur: &FurStructure,
    preset: &Preset,
    rig: Option<&Rig>,
    clip: Option<usize>,
    time: Option<f64>,
) -> anyhow::Result<(Vec<Vec3>, f64)> {
    let mut params = preset.simulation.clone();
    params.wind = WindParams { strength: 0.0, ..params.wind };
    let mut stepper = FurStepper::new(fur, &params)?;
    if let (Some(rig), Some(_)) = (rig, clip) {
        stepper.set_clip(rig.clone(), clip);
    }
    let settle_frames = (SETTLE_SECS * DRIVE_FPS).round() as u32;
    for frame in 0..=settle_frames {
        stepper.advance_with_clip_at(f64::from(frame) / DRIVE_FPS, 0.0)?;
    }
    let clip_secs = if clip.is_some() { time.unwrap_or(0.0) } else { 0.0 };
    if clip_secs > 0.0 {
        let frames = (clip_secs * DRIVE_FPS).ceil() as u32;
        for frame in 1..=frames {
            let t = (f64::from(frame) / DRIVE_FPS).min(clip_secs);
            stepper.advance_with_clip_at(SETTLE_SECS + t, t)?;
        }
    }
    Ok((stepper.simulation().positions().to_vec(), clip_secs))
}

/// The shared array in the mesh's own space (the bind pose of a skinned glTF), the skin the fur
/// is bound to, and notes on what could not follow.
fn bind(
    fur: &FurStructure,
    posed: Vec<Vec3>,
    rig: Option<&Rig>,
    clip: Option<usize>,
    time_secs: f64,
    source: Option<&Path>,
) -> anyhow::Result<(Vec<Vec3>, Option<FurSkin>, Vec<String>)> {
    let (Some(rig), Some(source)) = (rig, source) else { return Ok((posed, None, Vec::new())) };
    let mut pose = Pose::default();
    rig.pose(&fur.mesh, clip, time_secs, &mut pose);
    let positions = bind_space_positions(&posed, &fur.positions, &rig.vertex_matrices(&pose));
    let skins = source_skin_joints(source)?;
    let skin = skins
        .iter()
        .enumerate()
        .find_map(|(s, joints)| rig.influences_in_skin(joints).map(|influences| FurSkin { skin: s, influences }));
    let mut notes = Vec::new();
    if skin.is_none() && !rig.animations().is_empty() {
        notes.push("the fur does not follow the file's animations: its mesh is not bound to a single skin".to_owned());
    }
    if rig.morph_target_count() > 0 {
        notes.push("the fur's roots do not follow the file's morph targets".to_owned());
    }
    Ok((positions, skin, notes))
}
