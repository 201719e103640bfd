//! `pelt bench --guard FILE`: the speed guard CI runs. Each figure is a ratio of two timings
//! taken in the same run, in turns, so a slower or busier machine moves both alike: the default
//! bunny frame, shadows included, against its skin alone (what the fur costs to draw), and the skin contact's setup
//! against growing the same fur (what finding the skin planes costs). A figure more than
//! [`TOLERANCE`] above the one recorded in FILE (BENCHMARKS.md's "CI speed guard" table) fails
//! the run.

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::{Context as _, bail};
use glam::Vec3;
use pelt_core::sim::contact::{skin_planes, skin_surface};
use pelt_core::{Builtin, ImportOptions, Mesh, Preset};
use pelt_render::{
    Backend, Camera, FurDrawSettings, FurDriver, FurTarget, FurView, Gpu, HEADLESS_FORMAT, Headless, KernelChoice,
    Studio, Surroundings, default_sample_count,
};

/// How much worse than recorded a ratio may be.
pub const TOLERANCE: f64 = 1.15;

/// Rounds of each pair of timings; the figure is the median round's ratio. Frames are short and
/// a software rasteriser's time moves with the machine's other work: they take more rounds.
const FRAME_ROUNDS: usize = 15;
const SETUP_ROUNDS: usize = 7;

/// One guarded figure: its key in the table, what it divides, and the measured ratio.
struct Figure {
    key: &'static str,
    what: &'static str,
    ratio: f64,
}

pub fn run(recorded: &Path) -> anyhow::Result<()> {
    let table = std::fs::read_to_string(recorded).with_context(|| format!("cannot read {}", recorded.display()))?;
    let limit = |key: &str| {
        recorded_ratio(&table, key)
            .map(|ratio| ratio * TOLERANCE)
            .with_context(|| format!("{}: no ratio recorded for `{key}`", recorded.display()))
    };
    let mut figures = Vec::new();
    for (size, key) in [((1280, 720), "frame_1280x720"), ((256, 256), "frame_256x256")] {
        figures.push(frame_ratio(size, key, limit(key)?)?);
    }
    let meshes = super::models::meshes_dir(None);
    figures.push(setup_ratio("setup_bunny", "bunny", Builtin::Bunny.mesh().0, limit("setup_bunny")?)?);
    let human = meshes.join("female_generic.obj");
    let (mesh, _) =
        Mesh::load(&human, &ImportOptions::default()).with_context(|| format!("cannot load {}", human.display()))?;
    figures.push(setup_ratio("setup_dense", "female_generic.obj", mesh, limit("setup_dense")?)?);

    println!("| guard | measured ratio | recorded | limit | |");
    println!("|---|---:|---:|---:|---|");
    let mut failed = Vec::new();
    for figure in &figures {
        let limit = limit(figure.key)?;
        let recorded = limit / TOLERANCE;
        let verdict = if figure.ratio <= limit { "ok" } else { "SLOWER" };
        println!(
            "| `{}` ({}) | {:.3} | {recorded:.3} | {limit:.3} | {verdict} |",
            figure.key, figure.what, figure.ratio
        );
        if figure.ratio > limit {
            failed.push(figure.key);
        }
    }
    if !failed.is_empty() {
        bail!(
            "the speed guard failed: {} more than {:.0}% slower than recorded in {}",
            failed.join(", "),
            (TOLERANCE - 1.0) * 100.0,
            recorded.display()
        );
    }
    Ok(())
}

/// The ratio recorded for `key`: the last number of the table row that starts with it.
fn recorded_ratio(table: &str, key: &str) -> Option<f64> {
    let start = format!("| `{key}` |");
    let row = table.lines().find(|line| line.starts_with(&start))?;
    row.trim_end()
        .trim_end_matches('|')
        .rsplit('|')
        .next()?
        .trim()
        .parse()
        .ok()
        .filter(|r: &f64| r.is_finite() && *r > 0.0)
}

/// The median of the per-round ratios of `a` over `b`, the two timed in turns; the untimed
/// first round's ratio alone where it is already four times `limit` (a regression that slow
/// would make the rounds take minutes).
fn ratio_in_turns(
    rounds: usize,
    limit: f64,
    mut a: impl FnMut() -> anyhow::Result<Duration>,
    mut b: impl FnMut() -> anyhow::Result<Duration>,
) -> anyhow::Result<f64> {
    // One untimed round: pipelines compile, caches fill.
    let first = a()?.as_secs_f64() / b()?.as_secs_f64().max(1e-9);
    if first > 4.0 * limit {
        return Ok(first);
    }
    let mut ratios = Vec::with_capacity(rounds);
    for _ in 0..rounds {
        let ta = a()?;
        let tb = b()?;
        ratios.push(ta.as_secs_f64() / tb.as_secs_f64().max(1e-9));
    }
    ratios.sort_by(f64::total_cmp);
    Ok(ratios[rounds / 2])
}

/// The default `pelt render` frame of the bunny (Pelt's studio, the key light's shadow maps
/// recorded, drawn and read back) over the same frame with the skin alone, unshadowed.
fn frame_ratio((width, height): (u32, u32), key: &'static str, limit: f64) -> anyhow::Result<Figure> {
    let preset = Preset::default();
    let fur = preset.grow(Builtin::Bunny.mesh().0, "bunny")?;
    let textures = preset.generate_textures()?;
    let gpu = Gpu::new(Backend::Auto)?;
    let samples = default_sample_count(&gpu.adapter.get_info());
    let headless =
        Headless::with_target(gpu, FurTarget::new(HEADLESS_FORMAT).with_sample_count(samples), width, height)?;
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer()?;
    let mut driver = FurDriver::new(device, queue, &renderer, &fur, &textures, &preset.simulation, KernelChoice::Cpu)?;
    let fur_length = fur.lengths.iter().copied().fold(0.0, f32::max);
    let (low, high) =
        fur.mesh.positions.iter().fold((Vec3::INFINITY, Vec3::NEG_INFINITY), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let camera = Camera::framing_points(
        (low + high) * 0.5,
        fur.mesh.positions.iter().copied(),
        fur_length,
        30.0,
        15.0,
        headless.aspect_ratio(),
    );
    // The default look: Pelt's studio and the key light's shadows, maps fitted to the frame.
    let studio = Studio::default();
    let view_data = studio.view_data(&camera, headless.aspect_ratio());
    let mut surroundings = Surroundings::new(device, queue, &renderer, true, None, (&fur, &[]))?;
    surroundings.fit_to_frame(device, &renderer, (width, height))?;
    let mut view = FurView::new(device, &renderer);
    view.prepare(queue, &view_data);
    surroundings.prepare((device, queue), &renderer, &view_data, &mut view)?;
    // The reference: the skin alone, unshadowed (it moves with the machine, not with the fur).
    let skin_view = FurView::new(device, &renderer);
    skin_view.prepare(queue, &view_data);
    let lod = crate::lod::settings(&preset.render.lod, false);
    driver.set_level(crate::lod::level(&lod, &fur, camera.eye, camera.fov_y_rad, height));
    let fur_frame = || -> anyhow::Result<Duration> {
        let started = Instant::now();
        headless.render_with(
            studio.background,
            |encoder| {
                driver.record_view(encoder, &renderer, &view);
                surroundings.record(encoder, |pass, light| driver.draw(pass, &renderer, light, &FurDrawSettings::ALL));
            },
            |pass| driver.draw(pass, &renderer, &view, &FurDrawSettings::SILHOUETTE),
        )?;
        Ok(started.elapsed())
    };
    let skin_frame = || -> anyhow::Result<Duration> {
        let started = Instant::now();
        headless.render_with(
            studio.background,
            |encoder| driver.record_view(encoder, &renderer, &skin_view),
            |pass| driver.draw(pass, &renderer, &skin_view, &FurDrawSettings::SKIN),
        )?;
        Ok(started.elapsed())
    };
    let ratio = ratio_in_turns(FRAME_ROUNDS, limit, fur_frame, skin_frame)?;
    Ok(Figure { key, what: "bunny frame / its skin alone", ratio })
}

/// Finding the skin planes and triangles of `mesh`'s default fur over growing it, on one
/// thread (so the machine's core count does not move the ratio).
fn setup_ratio(key: &'static str, name: &str, mesh: Mesh, limit: f64) -> anyhow::Result<Figure> {
    let preset = Preset::default();
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let fur = pool.install(|| preset.grow(mesh.clone(), name))?;
    let grow = || -> anyhow::Result<Duration> {
        let started = Instant::now();
        let fur = pool.install(|| preset.grow(mesh.clone(), name))?;
        std::hint::black_box(&fur);
        Ok(started.elapsed())
    };
    let setup = || -> anyhow::Result<Duration> {
        let started = Instant::now();
        pool.install(|| {
            let planes = skin_planes(&fur);
            std::hint::black_box(skin_surface(&fur, &planes));
        });
        Ok(started.elapsed())
    };
    let ratio = ratio_in_turns(SETUP_ROUNDS, limit, setup, grow)?;
    let what = if key == "setup_bunny" {
        "bunny skin setup / growing its fur"
    } else {
        "dense mesh skin setup / growing its fur"
    };
    Ok(Figure { key, what, ratio })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn recorded_ratios_are_read_from_their_rows() {
        let table = "text\n| `frame_256x256` | bunny frame / its skin alone | 3.25 |\n| `other` | x | 1 |\n";
        assert_eq!(recorded_ratio(table, "frame_256x256"), Some(3.25));
        assert_eq!(recorded_ratio(table, "frame_1280x720"), None);
        assert_eq!(recorded_ratio("| `k` | x | NaN |", "k"), None);
    }
}
