//! `pelt bench --device-report FILE`: every figure that needs a real GPU, in one run of a few
//! minutes on one, written as one JSON object: the bunny's and the try-on's frames at 1920x1080
//! (the adapter's MSAA: 4x on a GPU) with and without the key light's shadows, herds of 100 and
//! 1,000 walking Foxes at that size bent on the CPU (their shadow casters in one draw a pass and
//! the camera's draws pooled by level, then a draw a Fox) and on the GPU kernel (pooled: also
//! their steps in one dispatch and their bases skinned on the GPU), 100 on the GPU kernel with a
//! ball rolled through them (every step with contact: two dispatches for the herd, then two a
//! Fox), the GPU kernel's node updates per second on the 35,000-vertex torus, and contact's share
//! of each kernel
//! (`pelt bench --contact`). A session lent a GPU runs it first and records the figures
//! (BENCHMARKS.md).

use std::path::Path;
use std::time::Instant;

use anyhow::Context as _;
use pelt_core::Preset;
use pelt_render::{Backend, Gpu, SimKernel};

use super::models::{self, MODELS, Model};
use super::report::{Adapter, RenderFigures};
use super::{contact, herd, render};

/// Frames of one model at the report's size.
#[derive(Debug, serde::Serialize)]
struct ModelFrames {
    model: &'static str,
    layers: u32,
    figures: RenderFigures,
}

#[derive(Debug, serde::Serialize)]
struct DeviceReport {
    pelt_version: &'static str,
    date_utc: String,
    quick: bool,
    adapter: Adapter,
    /// `WIDTHxHEIGHT` of the frames and herds.
    size: String,
    frames: Vec<ModelFrames>,
    herd: Vec<herd::HerdRow>,
    torus_vertices: u64,
    torus_layers: u32,
    gpu_sim_node_updates_per_sec_torus: f64,
    contact: contact::ContactFigures,
    wall_time_s: f64,
}

/// Runs every part and writes `out`; `quick` shrinks each (a CPU rasteriser's check that the
/// command works: 320x180, herds of 1 and 2, few frames and steps).
pub fn run(meshes: &Path, out: &Path, quick: bool) -> anyhow::Result<()> {
    let started = Instant::now();
    let bench = render::Bench::open(pelt_render::Studio::default())?;
    let adapter = bench.adapter();
    eprintln!("pelt bench: device report on {}", adapter.name);
    let size = if quick { (320, 180) } else { (1920, 1080) };
    let budget = if quick {
        render::RenderBudget { warmup_frames: 1, min_frames: 2, max_frames: 2, max_secs_per_case: 0.0 }
    } else {
        render::RenderBudget { warmup_frames: 2, min_frames: 5, max_frames: 61, max_secs_per_case: 1.0 }
    };
    let mut frames = Vec::new();
    for key in ["bunny", "women"] {
        let spec = MODELS.into_iter().find(|m| m.key == key).context("the model table")?;
        let model = Model::load(spec, meshes)?;
        let mut preset = Preset::default();
        preset.layers = 16;
        let fur = preset.grow(model.fur.clone(), key)?;
        let textures = preset.generate_textures()?;
        eprintln!("pelt bench: {key} frames");
        let lod = crate::lod::settings(&preset.render.lod, false);
        let figures = bench.measure(
            &fur,
            model.body.as_ref(),
            &textures,
            budget,
            lod,
            &[size],
            (true, crate::light_args::preset_look(&preset)),
        )?;
        frames.push(ModelFrames { model: key, layers: preset.layers, figures });
    }
    let counts: &[usize] = if quick { &[1, 2] } else { &[100, 1000] };
    let mut herd = Vec::new();
    // Each kernel's herds pooled (the shadow casters, the camera's draws, the GPU kernel's steps
    // and posing) and a draw, a dispatch and a CPU pose a Fox: what pooling saves a GPU.
    let settings = [true, false].map(|pooled| [(SimKernel::Cpu, Some(pooled)), (SimKernel::Gpu, Some(pooled))]);
    let herd_frames = if quick { 1 } else { 4 };
    for (kernel, pooled) in [settings[0][0], settings[1][0], settings[0][1], settings[1][1]] {
        let gpu = Gpu::new(Backend::Auto)?;
        let setting = (kernel, pooled, false);
        herd.extend(herd::measure(gpu, meshes, counts, (size, adapter.msaa_samples), herd_frames, setting)?.0);
    }
    // A ball through the GPU kernel's herd of 100: every Fox's steps with contact, in two
    // dispatches a step for the herd or two a Fox.
    for pooled in [true, false] {
        let gpu = Gpu::new(Backend::Auto)?;
        let setting = (SimKernel::Gpu, Some(pooled), true);
        let sizes = (size, adapter.msaa_samples);
        let foxes: &[usize] = if quick { &[2] } else { &[100] };
        herd.extend(herd::measure(gpu, meshes, foxes, sizes, herd_frames, setting)?.0);
    }
    eprintln!("pelt bench: the GPU kernel on the torus");
    let mut preset = Preset::default();
    preset.layers = 32;
    let torus = preset.grow(models::large_mesh()?, models::LARGE_MESH)?;
    let (steps, runs) = if quick { (2, 1) } else { (30, 7) };
    let node_updates = bench.node_updates_per_sec(&torus, &preset.simulation, steps, runs)?;
    let (contact, _) = contact::measure(quick)?;
    let report = DeviceReport {
        pelt_version: env!("CARGO_PKG_VERSION"),
        date_utc: super::system::utc_now(),
        quick,
        adapter,
        size: format!("{}x{}", size.0, size.1),
        frames,
        herd,
        torus_vertices: torus.vertex_count() as u64,
        torus_layers: preset.layers,
        gpu_sim_node_updates_per_sec_torus: node_updates,
        contact,
        wall_time_s: started.elapsed().as_secs_f64(),
    };
    let json = serde_json::to_string_pretty(&report)? + "\n";
    std::fs::write(out, json).with_context(|| format!("cannot write {}", out.display()))?;
    eprintln!("pelt bench: wrote {} in {:.0} s", out.display(), report.wall_time_s);
    Ok(())
}
