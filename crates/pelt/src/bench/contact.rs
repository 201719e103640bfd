//! `pelt bench --contact`: what contact costs the kernels. The bunny at 32 layers (default
//! preset, a steady wind so every strand moves) steps with contact off, the skin only, and the
//! skin with 8 colliders resting in the fur all round it; each kernel's node updates per second
//! are timed the way the report times them (`Simulation` steps on all threads; the GPU kernel
//! through the driver `--sim gpu` runs). The walking try-on's skirt (32 layers) steps with
//! contact off, the skin, and the skin and the body's capsules; its CPU figure is the
//! simulation's own step time (`Simulation::last_step_secs`), so posing the skirt and the body
//! every step is not counted.

use std::hint::black_box;

use glam::{Quat, Vec3};
use pelt_core::sim::{Collider, ContactParams, FurStepper, Shape, SimParams, Simulation};
use pelt_core::{Builtin, FurStructure, ImportOptions, Preset, Stage, StageSource};
use pelt_render::{Backend, Gpu};

use super::sim::{SIM_RATE_HZ, SimBudget, median_rate};

/// Layers the figures are taken at.
const LAYERS: u32 = 32;
/// Colliders of the third case.
const COLLIDERS: usize = 8;

/// One case: its name, whether the skin is on, its colliders.
struct Case {
    name: &'static str,
    skin: bool,
    colliders: Vec<Collider>,
}

/// 8 colliders (spheres, capsules and boxes in turn) spread over the fur, each sunk into it at
/// half the fur's length above a vertex, a tenth of the mesh's radius across.
fn colliders(fur: &FurStructure) -> Vec<Collider> {
    let (_, radius) = fur.mesh.bounding_sphere();
    let length = fur.lengths.iter().copied().fold(0.0, f32::max);
    let v = fur.vertex_count();
    (0..COLLIDERS)
        .map(|i| {
            let j = (i * v) / COLLIDERS + v / (2 * COLLIDERS);
            let size = 0.1 * radius;
            let shape = match i % 3 {
                0 => Shape::Sphere { radius: size },
                1 => Shape::Capsule { radius: 0.5 * size, half_length: size },
                _ => Shape::Box { half_extents: Vec3::splat(0.7 * size) },
            };
            let centre = fur.positions[j] + fur.mesh.normals[j] * (0.5 * length + size);
            Collider {
                appear_secs: 0.0,
                ..Collider::at(i as u32, shape, 0.0, centre, Quat::from_rotation_y(0.3 * i as f32))
            }
        })
        .collect()
}

fn params(skin: bool) -> SimParams {
    let mut params = Preset::default().simulation;
    params.contact = ContactParams { skin };
    params.rate_hz = SIM_RATE_HZ;
    params.interpolate = false;
    if params.wind.strength == 0.0 {
        params.wind.strength = 0.5;
    }
    params
}

/// One case's node updates per second: CPU (all threads) and GPU (none without an adapter).
#[derive(Clone, Debug, serde::Serialize)]
pub struct ContactRow {
    pub case: &'static str,
    pub cpu_node_updates_per_sec: f64,
    pub gpu_node_updates_per_sec: Option<f64>,
    /// The share of the kernel's time contact takes against the first case (contact off):
    /// `1 - rate / rate off`.
    pub cpu_contact_share: f64,
    pub gpu_contact_share: Option<f64>,
}

/// The bunny's and the walking try-on's cases.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ContactFigures {
    pub bunny: Vec<ContactRow>,
    pub try_on: Vec<ContactRow>,
}

/// Runs the cases and prints the table (Markdown).
pub fn run(quick: bool) -> anyhow::Result<()> {
    let (_, md) = measure(quick)?;
    println!("{md}");
    Ok(())
}

/// The cases' figures, and their tables (Markdown).
pub fn measure(quick: bool) -> anyhow::Result<(ContactFigures, String)> {
    let mut preset = Preset::default();
    preset.layers = LAYERS;
    let fur = preset.grow(Builtin::Bunny.mesh().0, "bunny")?;
    let budget = if quick {
        SimBudget { runs: 3, min_run_secs: 0.05, drawn_frames: 0 }
    } else {
        SimBudget { runs: 7, min_run_secs: 0.5, drawn_frames: 0 }
    };
    let gpu = Gpu::new(Backend::Auto);
    if let Err(error) = &gpu {
        eprintln!("pelt bench: no GPU adapter, the GPU column is empty: {error:#}");
    }
    let cases = [
        Case { name: "off", skin: false, colliders: Vec::new() },
        Case { name: "skin", skin: true, colliders: Vec::new() },
        Case { name: "skin + 8 colliders", skin: true, colliders: colliders(&fur) },
    ];
    let nodes = (fur.vertex_count() * LAYERS as usize) as f64;
    let mut rows = Vec::new();
    for case in &cases {
        eprintln!("pelt bench: contact {}", case.name);
        let params = params(case.skin);
        let mut simulation = Simulation::new(&fur, &params)?;
        simulation.set_colliders(&case.colliders)?;
        let mut time = 0.0;
        let cpu = median_rate(budget, nodes, &mut || {
            time += 1.0 / f64::from(SIM_RATE_HZ);
            simulation.step_at(time);
            black_box(simulation.steps_taken());
        });
        let gpu_rate = match gpu.as_ref().ok() {
            Some(gpu) => {
                let mut stepper = FurStepper::new(&fur, &params)?;
                stepper.simulation_mut().set_colliders(&case.colliders)?;
                Some(gpu_rate(gpu, &fur, &params, stepper, quick)?)
            }
            None => None,
        };
        rows.push((case.name, cpu, gpu_rate));
    }
    let mut md = table(&format!("bunny, L = {LAYERS}, {} strands", fur.vertex_count()), &rows);
    let (try_on_rows, try_on_md) = try_on(quick, gpu.as_ref().ok())?;
    md.push_str(&try_on_md);
    Ok((ContactFigures { bunny: figures(&rows), try_on: figures(&try_on_rows) }, md))
}

/// `rows` (`name`, CPU rate, GPU rate; the first contact off) with contact's shares.
fn figures(rows: &[(&'static str, f64, Option<f64>)]) -> Vec<ContactRow> {
    let (_, cpu_off, gpu_off) = rows[0];
    rows.iter()
        .map(|&(case, cpu, gpu)| ContactRow {
            case,
            cpu_node_updates_per_sec: cpu,
            gpu_node_updates_per_sec: gpu,
            cpu_contact_share: 1.0 - cpu / cpu_off,
            gpu_contact_share: gpu.zip(gpu_off).map(|(on, off)| 1.0 - on / off),
        })
        .collect()
}

/// The walking try-on's rows (the skirt's fur off, with its skin, and with the body too) and
/// their table.
type Rows = Vec<(&'static str, f64, Option<f64>)>;

fn try_on(quick: bool, gpu: Option<&Gpu>) -> anyhow::Result<(Rows, String)> {
    let stage = Stage::load(&StageSource::builtin("tryon")?, &[], &ImportOptions::default())?;
    let (Some(rig), Some(body), Some(body_mesh)) = (stage.rig.clone(), stage.body.as_ref(), stage.plain.first()) else {
        anyhow::bail!("the try-on stage has no walking body");
    };
    let mut preset = Preset::default();
    preset.layers = LAYERS;
    let fur = preset.grow(stage.fur_mesh.clone(), "tryon")?;
    let nodes = (fur.vertex_count() * LAYERS as usize) as f64;
    let steps = if quick { 20 } else { 240 };
    let mut rows = Vec::new();
    for (name, skin, with_body) in [("off", false, false), ("skin", true, false), ("skin + body", true, true)] {
        eprintln!("pelt bench: contact, try-on {name}");
        let params = params(skin);
        let stepper = || -> anyhow::Result<FurStepper> {
            let mut stepper = FurStepper::new(&fur, &params)?;
            stepper.set_clip(rig.clone(), Some(0));
            if with_body {
                stepper.set_body(Some((body_mesh.clone(), body.rig.clone(), body.capsules.clone())));
            }
            Ok(stepper)
        };
        let mut cpu_stepper = stepper()?;
        let mut rates = Vec::new();
        let mut time = 0.0;
        for _ in 0..if quick { 3 } else { 7 } {
            let mut secs = 0.0;
            for _ in 0..steps {
                time += 1.0 / f64::from(SIM_RATE_HZ);
                cpu_stepper.advance_to(time)?;
                secs += cpu_stepper.simulation().last_step_secs();
            }
            rates.push(steps as f64 * nodes / secs);
        }
        rates.sort_by(f64::total_cmp);
        let cpu = rates[rates.len() / 2];
        let gpu_rate = match gpu {
            Some(gpu) => Some(gpu_rate(gpu, &fur, &params, stepper()?, quick)?),
            None => None,
        };
        rows.push((name, cpu, gpu_rate));
    }
    let md = table(&format!("walking try-on's skirt, L = {LAYERS}, {} strands", fur.vertex_count()), &rows);
    Ok((rows, md))
}

/// The GPU kernel's node updates per second stepping `stepper` (the driver `--sim gpu` runs).
fn gpu_rate(
    gpu: &Gpu,
    fur: &FurStructure,
    params: &SimParams,
    mut stepper: FurStepper,
    quick: bool,
) -> anyhow::Result<f64> {
    let (steps, runs) = if quick { (4, 3) } else { (30, 7) };
    let renderer = crate::sim_kernel::timing_renderer(&gpu.device)?;
    let secs =
        pelt_render::gpu_secs_per_step_of(&gpu.device, &gpu.queue, &renderer, fur, params, &mut stepper, steps, runs)?;
    Ok((fur.vertex_count() * fur.layers as usize) as f64 / secs)
}

/// A Markdown table of `rows` (`name`, CPU rate, GPU rate), the first row contact off.
fn table(title: &str, rows: &[(&str, f64, Option<f64>)]) -> String {
    let (_, cpu_off, gpu_off) = rows[0];
    let mut md = format!(
        "| {title} | CPU node updates/s (all threads) | contact's share | GPU node updates/s | contact's share |\n|---|---|---|---|---|\n"
    );
    for &(name, cpu, gpu_rate) in rows {
        // The share of the kernel's time contact takes: 1 - (time off / time on).
        let share = |off: f64, on: f64| format!("{:.0}%", 100.0 * (1.0 - on / off));
        let gpu_cells = match (gpu_rate, gpu_off) {
            (Some(on), Some(off)) => (format!("{:.3e}", on), share(off, on)),
            _ => ("-".to_owned(), "-".to_owned()),
        };
        md.push_str(&format!(
            "| {name} | {:.3e} | {} | {} | {} |\n",
            cpu,
            share(cpu_off, cpu),
            gpu_cells.0,
            gpu_cells.1
        ));
    }
    md.push('\n');
    md
}
