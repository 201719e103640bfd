//! `pelt bench`: the report that puts Pelt's figures beside the paper's.
//!
//! Memory (the paper's Table 2) is computed for every model; frame time, simulation and texture
//! generation are measured. Criterion benches stay the fine-grained tools; this is the summary
//! a reader (or CI) runs in one go.

mod anim;
mod contact;
mod device_report;
mod guard;
mod herd;
mod load;
mod models;
mod render;
mod report;
mod sim;
mod soak;
mod system;
mod table2;

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context as _;
use pelt_core::Preset;

use self::models::{MODELS, Model};
use self::report::{
    AnimFigures, GpuSimFigures, LargeMeshFigures, Machine, RenderFigures, Report, ResultRow, SimFigures, SkippedModel,
    TextureFigures,
};
use self::table2::Table2Row;

/// Arguments of `pelt bench`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// A reduced set for CI: Table 2 on every model, timings on the Box only, few frames.
    #[arg(long)]
    pub quick: bool,
    /// Write every figure as JSON (stable keys, see BENCHMARKS.md).
    #[arg(long, value_name = "FILE")]
    pub json: Option<PathBuf>,
    /// Write the report as Markdown tables.
    #[arg(long, value_name = "FILE")]
    pub md: Option<PathBuf>,
    /// Only these models (box, bunny, spot, skirt, women, fox); repeat for several. Default: all.
    #[arg(long = "model", value_name = "NAME")]
    pub models: Vec<String>,
    /// The folder with the mesh files (default: `assets/meshes`).
    #[arg(long, value_name = "DIR")]
    pub meshes: Option<PathBuf>,
    /// Instead of the report: soak the simulation (the bunny at 16 layers) under extreme,
    /// changing forces on the CPU kernel, then on the GPU kernel, and report each one's worst
    /// segment length error; fails if any node is not finite or a length moved by more than
    /// 1e-5 of its strand's length.
    #[arg(long)]
    pub soak: bool,
    /// Instead of the report: the kernels' node updates per second on the bunny at 32 layers
    /// with contact off, the skin only, and the skin with 8 colliders, CPU and GPU.
    #[arg(long, conflicts_with = "soak")]
    pub contact: bool,
    /// Time the models with this preset (its look, textures, simulation and groom; the layer
    /// counts stay the table's) instead of the default one, e.g. a groomed Fox against the
    /// uniform coat: `--model fox --preset assets/presets/fox_groomed.toml`. Its groom must fit
    /// every model timed.
    #[arg(long, value_name = "FILE")]
    pub preset: Option<PathBuf>,
    /// Leave out the level-of-detail measurements (the frame-time table always draws every
    /// shell).
    #[arg(long)]
    pub no_lod: bool,
    /// Also time every structure at this frame size (repeat for several), with frames per
    /// second as a game loop without vsync gets them: frames submitted back to back, two in
    /// flight.
    #[arg(long = "size", value_name = "WIDTHxHEIGHT", value_parser = crate::values::parse_size)]
    pub sizes: Vec<(u32, u32)>,
    /// Instead of the report: the speed guard CI runs. Times the default bunny frame against
    /// its skin alone and the skin contact's setup against growing the fur, each pair in turns in
    /// this one run, and fails if a ratio is more than 15% above the one recorded in FILE
    /// (BENCHMARKS.md's "CI speed guard" table).
    #[arg(long, value_name = "FILE", conflicts_with_all = ["soak", "contact"])]
    pub guard: Option<PathBuf>,
    #[command(flatten)]
    pub lights: crate::light_args::LightArgs,
    /// Also time the unified fur with the key light's shadows (its shadow maps and deep opacity
    /// map, as `pelt render --shadows` draws them), in turn with the frame-time table's cases.
    #[arg(long)]
    pub shadows: bool,
    /// Instead of the report: 1, 10, 100 and 1,000 walking Foxes (1 and 10 with --quick) at
    /// 1280x720, one fur asset shared: frame, simulation and recording time, GPU bytes, and what
    /// one more Fox adds (with --json, the rows as JSON).
    #[arg(long, conflicts_with_all = ["soak", "contact", "guard"])]
    pub herd: bool,
    /// With --herd: where the Foxes' strands bend, cpu (one parallel pass; auto too, as for
    /// `pelt render --herd`) or gpu (each Fox's kernel; on a GPU their bases skinned there).
    #[arg(long, value_enum, default_value_t = crate::sim_kernel::SimChoice::Cpu, requires = "herd")]
    pub sim: crate::sim_kernel::SimChoice,
    /// With --herd: how the Foxes share the GPU's work, as `pelt render --pooling` (auto: pooled
    /// on a GPU, a Fox at a time on a CPU rasteriser).
    #[arg(long, value_enum, default_value_t = crate::herd::Pooling::Auto, requires = "herd")]
    pub pooling: crate::herd::Pooling,
    /// Instead of the report: every figure that needs a real GPU, written to FILE as JSON in a
    /// few minutes on one (frames at 1920x1080 with the adapter's MSAA, shadows on and off, herds
    /// of 100 and 1,000 Foxes, the GPU kernel on the 35,000-vertex torus, contact's share);
    /// `--quick` shrinks every part, to check the command on a CPU rasteriser.
    #[arg(long, value_name = "FILE", conflicts_with_all = ["soak", "contact", "guard", "herd"])]
    pub device_report: Option<PathBuf>,
    /// Instead of the report: the time to a first frame phase by phase (parse, repair,
    /// structure, textures, skin setup, GPU upload) for every mesh in the meshes folder and
    /// each `--load-mesh`.
    #[arg(long, conflicts_with_all = ["soak", "contact", "guard"])]
    pub load: bool,
    /// A mesh file `--load` also times (repeat for several).
    #[arg(long = "load-mesh", value_name = "FILE", requires = "load")]
    pub load_meshes: Vec<PathBuf>,
    /// Steps of `--soak` on the CPU kernel.
    #[arg(long, value_name = "N", default_value_t = 1_000_000, requires = "soak")]
    pub steps: u64,
    /// Steps of `--soak` on the GPU kernel (0: none). Fewer than the CPU's by default: every
    /// step is read back to be checked, which costs milliseconds on a software rasteriser.
    #[arg(long, value_name = "N", default_value_t = 100_000, requires = "soak")]
    pub gpu_steps: u64,
}

/// The layer counts the paper's comparison is made at.
const LAYER_COUNTS: [u32; 2] = [16, 32];

/// How much work each measurement does.
#[derive(Clone, Copy, Debug)]
struct Plan<'a> {
    quick: bool,
    /// `--no-lod`.
    no_lod: bool,
    /// `--size`: frame sizes timed besides the two standard ones.
    extra_sizes: &'a [(u32, u32)],
    /// `--preset`: the preset timed in place of the default one.
    preset: Option<&'a Preset>,
    /// `--shadows`.
    shadows: bool,
}

impl Plan<'_> {
    /// The preset timed at `layers`: `--preset`'s, else the default.
    fn preset(self, layers: u32) -> Preset {
        let mut preset = self.preset.cloned().unwrap_or_default();
        preset.layers = layers;
        preset
    }
}

impl Plan<'_> {
    /// Whether `model` gets timings (Table 2 is computed for all).
    fn times(self, model: &str) -> bool {
        !self.quick || model == "box"
    }

    /// Whether `model` at `layers` gets frame times: a software rasteriser takes about a second
    /// a frame at 1280x720, so `--quick` draws the Box at 16 layers only.
    fn renders(self, model: &str, layers: u32) -> bool {
        self.times(model) && (!self.quick || layers == LAYER_COUNTS[0])
    }

    fn render_budget(self) -> render::RenderBudget {
        if self.quick {
            render::RenderBudget { warmup_frames: 1, min_frames: 3, max_frames: 3, max_secs_per_case: 0.0 }
        } else {
            // Enough frames for a stable median on a GPU; at least 5 where a frame takes a second.
            render::RenderBudget { warmup_frames: 2, min_frames: 5, max_frames: 101, max_secs_per_case: 2.0 }
        }
    }

    /// GPU simulation: (steps per timed run, runs); the figure is the median run.
    fn gpu_sim_runs(self) -> (u32, usize) {
        if self.quick { (4, 3) } else { (30, 7) }
    }

    fn texture_runs(self) -> u32 {
        if self.quick { 1 } else { 3 }
    }

    fn sim_budget(self) -> sim::SimBudget {
        if self.quick {
            sim::SimBudget { runs: 3, min_run_secs: 0.02, drawn_frames: 24 }
        } else {
            // 4 s of simulated time: 120 steps at 30 Hz under 480 drawn frames.
            sim::SimBudget { runs: 7, min_run_secs: 0.15, drawn_frames: 480 }
        }
    }
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    if args.soak {
        return soak::run(args.steps, args.gpu_steps);
    }
    if args.contact {
        return contact::run(args.quick);
    }
    if let Some(recorded) = &args.guard {
        return guard::run(recorded);
    }
    if let Some(out) = &args.device_report {
        return device_report::run(&models::meshes_dir(args.meshes.as_deref()), out, args.quick);
    }
    if args.herd {
        let meshes = models::meshes_dir(args.meshes.as_deref());
        let kernel = match args.sim {
            crate::sim_kernel::SimChoice::Gpu => pelt_render::SimKernel::Gpu,
            _ => pelt_render::SimKernel::Cpu,
        };
        return herd::run(args.quick, &meshes, args.json.as_deref(), (kernel, args.pooling.forced()));
    }
    if args.load {
        return load::run(&models::meshes_dir(args.meshes.as_deref()), &args.load_meshes);
    }
    let started = Instant::now();
    for name in &args.models {
        anyhow::ensure!(
            MODELS.iter().any(|m| m.key == name),
            "unknown model {name:?}; choose from {}",
            MODELS.iter().map(|m| m.key).collect::<Vec<_>>().join(", ")
        );
    }
    let preset = args.preset.as_deref().map(Preset::load).transpose()?;
    let plan = Plan {
        quick: args.quick,
        no_lod: args.no_lod,
        extra_sizes: &args.sizes,
        preset: preset.as_ref(),
        shadows: args.shadows,
    };
    let meshes_dir = models::meshes_dir(args.meshes.as_deref());

    // One GPU for the whole run; without one the frame times are null with the reason.
    let environment = args.lights.environment(None)?;
    let gpu = match render::Bench::open(args.lights.studio(None, environment, 0.0)) {
        Ok(gpu) => {
            eprintln!("pelt bench: adapter {}", gpu.adapter().name);
            Ok(gpu)
        }
        Err(error) => {
            eprintln!("pelt bench: no GPU adapter, frame times will be null: {error:#}");
            Err(format!("no GPU adapter: {error:#}"))
        }
    };

    let mut results = Vec::new();
    let mut skipped_models = Vec::new();
    for spec in MODELS.into_iter().filter(|m| args.models.is_empty() || args.models.iter().any(|n| n == m.key)) {
        eprintln!("pelt bench: {} ({})", spec.key, spec.paper_model);
        let model = match Model::load(spec, &meshes_dir) {
            Ok(model) => model,
            Err(error) => {
                eprintln!("pelt bench: skipping {}: {error:#}", spec.key);
                skipped_models.push(SkippedModel { model: spec.key, reason: format!("{error:#}") });
                continue;
            }
        };
        for layers in LAYER_COUNTS {
            results.push(measure(&model, layers, plan, gpu.as_ref())?);
        }
    }

    eprintln!("pelt bench: simulation on a {}-vertex mesh", models::LARGE_MESH_VERTICES);
    let sim_large_mesh = Some(measure_large_mesh(plan, gpu.as_ref())?);

    let report = Report {
        pelt_version: env!("CARGO_PKG_VERSION"),
        date_utc: system::utc_now(),
        command: std::env::args().collect::<Vec<_>>().join(" "),
        quick: args.quick,
        build_profile: if cfg!(debug_assertions) { "debug" } else { "release" },
        machine: Machine {
            cpu: system::cpu_name(),
            cpu_threads: system::cpu_threads(),
            memory_bytes: system::total_memory_bytes(),
            os: std::env::consts::OS,
        },
        adapter: gpu.as_ref().ok().map(render::Bench::adapter),
        adapter_unavailable_reason: gpu.as_ref().err().cloned(),
        paper_savings_vs_2_percent: table2::PAPER_SAVINGS_VS_2_PERCENT,
        paper_savings_vs_30_percent: table2::PAPER_SAVINGS_VS_30_PERCENT,
        sim_cpu_kernel: pelt_core::sim::CpuKernel::Auto.name(),
        sim_large_mesh,
        results,
        skipped_models,
        peak_rss_bytes: system::peak_rss_bytes(),
        wall_time_s: started.elapsed().as_secs_f64(),
    };

    let markdown = report.to_markdown();
    println!("{markdown}");
    if let Some(path) = &args.json {
        let json = serde_json::to_string_pretty(&report)?;
        std::fs::write(path, json + "\n").with_context(|| format!("cannot write {}", path.display()))?;
    }
    if let Some(path) = &args.md {
        std::fs::write(path, markdown).with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

const QUICK_SKIPS: &str = "--quick times the Box only";
const NOT_ANIMATED: &str = "a static model";
const QUICK_DRAWS: &str = "--quick draws the Box at 16 layers only";

/// Every figure for one model at one layer count.
fn measure(
    model: &Model,
    layers: u32,
    plan: Plan<'_>,
    gpu: Result<&render::Bench, &String>,
) -> anyhow::Result<ResultRow> {
    let row = |render, sim, texture, gpu_sim, anim| -> anyhow::Result<ResultRow> {
        Ok(ResultRow {
            model: model.spec.key,
            paper_model: model.spec.paper_model,
            mesh: model.source(),
            layers,
            table2: (&Table2Row::compute(model, layers)?).into(),
            render,
            sim,
            texture,
            gpu_sim,
            anim,
        })
    };
    if !plan.times(model.spec.key) {
        let reason = || Some(QUICK_SKIPS.to_owned());
        return row(
            RenderFigures { render_unavailable_reason: reason(), ..RenderFigures::default() },
            SimFigures { sim_unavailable_reason: reason(), ..SimFigures::default() },
            TextureFigures { texture_unavailable_reason: reason(), ..TextureFigures::default() },
            GpuSimFigures { gpu_sim_unavailable_reason: reason(), ..GpuSimFigures::default() },
            measure_anim(model, layers, plan)?,
        );
    }

    // Everything timed uses the default preset (or `--preset`'s) at this layer count.
    let preset = plan.preset(layers);
    let fur = preset.grow(model.fur.clone(), model.spec.key)?;
    let key = model.spec.key;
    eprintln!("pelt bench:   {key} L={layers}: textures");
    // The median of a few runs: the first one also pays for the thread pool and fresh pages.
    let mut generation_ms = Vec::new();
    let mut textures = None;
    for _ in 0..plan.texture_runs() {
        let started = Instant::now();
        textures = Some(preset.generate_textures()?);
        generation_ms.push(started.elapsed().as_secs_f64() * 1000.0);
    }
    let textures = textures.context("at least one texture run")?;
    generation_ms.sort_by(f64::total_cmp);
    let texture = TextureFigures {
        texture_generation_ms: Some(generation_ms[generation_ms.len() / 2]),
        texture_size_texels: Some(textures.size),
        texture_unavailable_reason: None,
    };
    let render = match gpu {
        _ if !plan.renders(key, layers) => {
            RenderFigures { render_unavailable_reason: Some(QUICK_DRAWS.to_owned()), ..RenderFigures::default() }
        }
        Ok(gpu) => {
            eprintln!("pelt bench:   {key} L={layers}: frame time");
            let lod = crate::lod::settings(&preset.render.lod, plan.no_lod);
            gpu.measure(
                &fur,
                model.body.as_ref(),
                &textures,
                plan.render_budget(),
                lod,
                plan.extra_sizes,
                (plan.shadows, crate::light_args::preset_look(&preset)),
            )?
        }
        Err(reason) => RenderFigures { render_unavailable_reason: Some(reason.clone()), ..RenderFigures::default() },
    };
    eprintln!("pelt bench:   {key} L={layers}: simulation");
    let sim = sim::measure(&fur, &preset.simulation, plan.sim_budget())?;
    let gpu_sim = match gpu {
        Ok(gpu) => {
            eprintln!("pelt bench:   {key} L={layers}: GPU simulation");
            let (steps, runs) = plan.gpu_sim_runs();
            gpu.measure_simulation(&fur, &preset.simulation, steps, runs, plan.sim_budget().drawn_frames)?
        }
        Err(reason) => GpuSimFigures { gpu_sim_unavailable_reason: Some(reason.clone()), ..GpuSimFigures::default() },
    };
    row(render, sim, texture, gpu_sim, measure_anim(model, layers, plan)?)
}

/// The posing figures of an animated model (also under `--quick`: a few frames cost little).
fn measure_anim(model: &Model, layers: u32, plan: Plan<'_>) -> anyhow::Result<AnimFigures> {
    let (Some(rig), Some(clip)) = (&model.rig, model.spec.animation) else {
        return Ok(AnimFigures { anim_unavailable_reason: Some(NOT_ANIMATED.to_owned()), ..AnimFigures::default() });
    };
    let preset = plan.preset(layers);
    let fur = preset.grow(model.fur.clone(), model.spec.key)?;
    eprintln!("pelt bench:   {} L={layers}: posing ({clip})", model.spec.key);
    anim::measure(&fur, rig, clip, &preset.simulation, plan.sim_budget().drawn_frames)
}

/// The simulation's throughput on the 35,000-vertex mesh at 32 layers, default preset.
fn measure_large_mesh(plan: Plan<'_>, gpu: Result<&render::Bench, &String>) -> anyhow::Result<LargeMeshFigures> {
    let mesh = models::large_mesh()?;
    let mut preset = Preset::default();
    preset.layers = 32;
    let fur = preset.grow(mesh, models::LARGE_MESH)?;
    let throughput = sim::throughput(&fur, &preset.simulation, plan.sim_budget())?;
    // The GPU kernel on a mesh big enough to fill a GPU (the bench's models are launch-bound).
    let gpu_sim_node_updates_per_sec = match gpu {
        Ok(gpu) => {
            let (steps, runs) = plan.gpu_sim_runs();
            Some(gpu.node_updates_per_sec(&fur, &preset.simulation, steps, runs)?)
        }
        Err(_) => None,
    };
    Ok(LargeMeshFigures {
        mesh: models::LARGE_MESH.to_owned(),
        vertices: fur.vertex_count() as u64,
        layers: preset.layers,
        sim_node_updates_per_sec: throughput.one_thread,
        sim_node_updates_per_sec_all_threads: throughput.all_threads,
        gpu_sim_node_updates_per_sec,
    })
}
