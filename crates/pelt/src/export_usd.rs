//! `pelt export ... -o coat.usda`: the strands the shells stand for as USD hair curves on the
//! base mesh (`pelt_core::export::write_strands_usda`), settled as the glTF export settles them,
//! with `--motion` as time samples.

use std::path::Path;
use std::time::Instant;

use anyhow::bail;
use glam::Vec3;
use pelt_core::export::{StrandBasis, StrandExportCounts, StrandExportInput, StrandFrame, write_strands_usda};
use pelt_core::sim::{FurStepper, WindParams};
use pelt_core::{Builtin, Preset, Stage};

use crate::export::{Args, DRIVE_FPS, Progress, SETTLE_SECS, choose_clip, settle_frames, settle_wet};
use crate::render::LIGHT_WIND;

/// Time samples per second of `--motion` in a USD export, and at most.
const USD_FPS: f64 = 12.0;
const USD_MAX_SAMPLES: u32 = 240;

/// The `--curves` choices.
#[derive(Clone, Copy, Debug, clap::ValueEnum)]
pub enum Curves {
    /// Straight segments between the points: the shells' strands exactly.
    Linear,
    /// A pinned Catmull-Rom spline through the same points.
    CatmullRom,
}

/// Whether `path` names a USD file Pelt writes: `.usda`, or `.usd` (USD tells text from binary
/// by the content, and Pelt writes text).
pub fn is_usda(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("usda") || e.eq_ignore_ascii_case("usd"))
}

pub fn run(args: &Args, started: Instant) -> anyhow::Result<()> {
    if args.layers.is_some() || args.screen_size.is_some() {
        bail!(
            "--layers and --screen-size choose shells; a .usda export writes strands, a point per layer of the preset"
        );
    }
    if matches!(args.alpha, crate::export::Alpha::Blend) {
        bail!("--alpha: a .usda export has no shell materials");
    }
    let fraction = args.strand_fraction.unwrap_or(1.0);
    if !(fraction.is_finite() && fraction > 0.0 && fraction <= 1.0) {
        bail!("--strand-fraction must be above 0 and at most 1, got {fraction}");
    }
    let meters_per_unit = args.meters_per_unit.unwrap_or(1.0);
    if !(meters_per_unit.is_finite() && meters_per_unit > 0.0) {
        bail!("--meters-per-unit must be a positive number, got {meters_per_unit}");
    }
    crate::export::check_time_and_motion(args)?;
    let preset = match &args.preset {
        Some(path) => Preset::load(path)?,
        None => Preset::default(),
    };
    let source = args.mesh.source(Builtin::Bunny)?;
    let Stage { fur_mesh: mesh, rig, .. } = args.mesh.stage(Builtin::Bunny, &[])?;
    let clip = choose_clip(args, rig.as_ref())?;
    let fur = preset.grow(mesh, &source.name())?;
    let field = preset.strand_field()?;
    let samples = args.motion.map(|secs| ((secs * USD_FPS).round() as u32).clamp(2, USD_MAX_SAMPLES));
    let motion_steps = samples.map_or(0, |n| (f64::from(n) / USD_FPS * DRIVE_FPS).ceil() as u64 + u64::from(n));
    let progress = Progress::new(settle_frames(args.time) + motion_steps);
    let mut stepper = settle_wet(&fur, &preset, rig.as_ref(), clip, args.time, args.wetness, &progress)?;
    let clip_secs = if clip.is_some() { args.time.unwrap_or(0.0) } else { 0.0 };
    // The strands `pelt fidelity` compares with (a wet coat's gathered into its clumps).
    let reference = crate::fidelity::strand_reference(&fur, field, &stepper)?;
    let frame = |stepper: &FurStepper, time_code: Option<f64>| StrandFrame {
        time_code,
        positions: stepper.simulation().positions().to_vec(),
        normals: stepper.moved_pose().map_or_else(|| fur.mesh.normals.clone(), |pose| pose.normals.clone()),
    };
    let frames = match samples {
        None => vec![frame(&stepper, None)],
        Some(count) => {
            // The wind blows (the preset's, or `pelt render`'s light breeze) and the clip plays
            // on from `--time`; a sample every 1 / USD_FPS seconds.
            let mut wind = preset.simulation.wind.clone();
            if wind.strength <= 0.0 {
                wind = WindParams { direction: LIGHT_WIND.normalize(), strength: LIGHT_WIND.length(), ..wind };
            }
            stepper.simulation_mut().set_wind(&wind)?;
            let start = SETTLE_SECS + clip_secs;
            let mut frames = vec![frame(&stepper, Some(0.0))];
            let mut now = 0.0;
            for k in 1..count {
                let to = f64::from(k) / USD_FPS;
                while now < to - 1e-9 {
                    now = (now + 1.0 / DRIVE_FPS).min(to);
                    let clip_time = if clip.is_some() { clip_secs + now } else { 0.0 };
                    stepper.advance_with_clip_at(start + now, clip_time)?;
                    progress.step();
                }
                frames.push(frame(&stepper, Some(f64::from(k))));
                progress.step();
            }
            frames
        }
    };
    progress.finish_simulation();
    let basis = match args.curves.unwrap_or(Curves::Linear) {
        Curves::Linear => StrandBasis::Linear,
        Curves::CatmullRom => StrandBasis::CatmullRom,
    };
    let when = match (clip, rig.as_ref()) {
        (Some(k), Some(rig)) => {
            format!("at {clip_secs:.2} s of {:?}", rig.animations()[k].name.as_deref().unwrap_or("(unnamed)"))
        }
        _ => "at the rest pose".to_owned(),
    };
    let doc = format!(
        "Pelt {}: the strands of {} with {}, {when}",
        env!("CARGO_PKG_VERSION"),
        source.name(),
        args.preset.as_ref().map_or_else(|| "the default fur".to_owned(), |p| p.display().to_string()),
    );
    let input = StrandExportInput {
        fur: &fur,
        reference: &reference,
        frames: &frames,
        fraction,
        basis,
        meters_per_unit,
        frames_per_second: USD_FPS,
        doc,
    };
    let counts = write_strands_usda(&args.output, &input)?;
    progress.done();
    let bytes = std::fs::metadata(&args.output).map(|m| m.len()).unwrap_or(0);
    print_summary(&args.output, bytes, &counts, when, args.motion, started);
    Ok(())
}

/// The export's line, and a second with what a USD reader should find (CI checks it against
/// Pixar's library).
fn print_summary(
    path: &Path,
    bytes: u64,
    counts: &StrandExportCounts,
    when: String,
    motion: Option<f64>,
    started: Instant,
) {
    let motion_text = match motion {
        Some(secs) => format!(", {secs} s of motion in {} time samples", counts.time_samples),
        None => String::new(),
    };
    println!(
        "{}: {:.2} MB, {} curves of {} points on a mesh of {} vertices and {} triangles, {when}{motion_text}; {:.2} s",
        path.display(),
        bytes as f64 / 1e6,
        counts.curves,
        counts.points,
        counts.mesh_vertices,
        counts.mesh_triangles,
        started.elapsed().as_secs_f64(),
    );
    let extent = |[low, high]: [Vec3; 2]| format!("{} {} {} {} {} {}", low.x, low.y, low.z, high.x, high.y, high.z);
    println!(
        "usd: curves {} points {} mesh_vertices {} mesh_triangles {} time_samples {} curves_extent {} mesh_extent {}",
        counts.curves,
        counts.points,
        counts.mesh_vertices,
        counts.mesh_triangles,
        counts.time_samples,
        extent(counts.curves_extent),
        extent(counts.mesh_extent),
    );
}
