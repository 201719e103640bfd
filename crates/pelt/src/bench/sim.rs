//! Simulation figures: the throughput of the kernel `Simulation` runs (one thread and all
//! threads), the paper's literal loop timed the same way, and the CPU cost per drawn frame with
//! and without interpolation.

use std::hint::black_box;
use std::time::Instant;

use glam::{Quat, Vec3};
use pelt_core::FurStructure;
use pelt_core::sim::{SimParams, Simulation, bend_strand_literal};

use super::report::SimFigures;

/// The paper's setting: simulate at 30 Hz, draw at 120 Hz.
pub const SIM_RATE_HZ: f32 = 30.0;
pub const DRAW_RATE_HZ: f64 = 120.0;

/// A steady side force added to gravity, so no strand is parallel to the force and every node
/// turns (the throughput of a windy scene without the wind's noise).
const SIDE_FORCE: Vec3 = Vec3::new(0.5, 0.0, 0.0);

/// How long each measurement runs.
#[derive(Clone, Copy, Debug)]
pub struct SimBudget {
    /// Repeated runs per throughput figure; the figure is their median.
    pub runs: u32,
    /// Each run repeats whole passes over every strand until at least this long has passed.
    pub min_run_secs: f64,
    /// Drawn frames the per-frame cost is averaged over.
    pub drawn_frames: u32,
}

/// Node updates per second of the product's kernel on `fur`: one thread and all threads.
#[derive(Clone, Copy, Debug)]
pub struct Throughput {
    pub one_thread: f64,
    pub all_threads: f64,
}

/// Times `Simulation`'s steps (force field, then the bend of every strand: what a step costs
/// the product) under `params` plus [`SIDE_FORCE`], on one thread and on all.
pub fn throughput(fur: &FurStructure, params: &SimParams, budget: SimBudget) -> anyhow::Result<Throughput> {
    let mut simulation = Simulation::new(fur, &SimParams { interpolate: false, ..params.clone() })?;
    simulation.field_mut().fill(SIDE_FORCE);
    let nodes_per_step = (fur.vertex_count() * fur.layers as usize) as f64;
    let mut time = 0.0;
    let mut step = || {
        time += 1.0 / f64::from(SIM_RATE_HZ);
        simulation.step_at(time);
        black_box(simulation.steps_taken());
    };
    let all_threads = median_rate(budget, nodes_per_step, &mut step);
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build()?;
    let one_thread = pool.install(|| median_rate(budget, nodes_per_step, &mut step));
    Ok(Throughput { one_thread, all_threads })
}

/// Measures `fur` under `params` (its gravity and stability; wind switched on for the per-frame
/// costs, so the field is evaluated every step, as in a windy scene).
pub fn measure(fur: &FurStructure, params: &SimParams, budget: SimBudget) -> anyhow::Result<SimFigures> {
    let product = throughput(fur, params, budget)?;
    let literal = literal_rate(fur, params, budget);

    let mut windy = params.clone();
    windy.rate_hz = SIM_RATE_HZ;
    if windy.wind.strength == 0.0 {
        windy.wind.strength = 0.5;
    }
    let interpolated = cpu_ms_per_drawn_frame(fur, &SimParams { interpolate: true, ..windy.clone() }, budget)?;
    let every_frame = cpu_ms_per_drawn_frame(fur, &SimParams { interpolate: false, ..windy }, budget)?;
    Ok(SimFigures {
        sim_node_updates_per_sec: Some(product.one_thread),
        sim_node_updates_per_sec_all_threads: Some(product.all_threads),
        sim_literal_node_updates_per_sec: Some(literal),
        sim_cpu_ms_per_frame_interpolated: Some(interpolated),
        sim_cpu_ms_per_frame_every_frame: Some(every_frame),
        sim_unavailable_reason: None,
    })
}

/// The paper's literal O(L^2) loop (`bend_strand_literal`) over every strand, one thread, the
/// same force per strand as [`throughput`] gives (gravity plus [`SIDE_FORCE`]), timed the same
/// way: median of repeated runs of whole passes.
fn literal_rate(fur: &FurStructure, params: &SimParams, budget: SimBudget) -> f64 {
    let v = fur.vertex_count();
    let layers = fur.layers as usize;
    let p = &fur.positions;
    let segments: Vec<Vec3> =
        (0..v).flat_map(|j| (0..layers).map(move |k| p[(k + 1) * v + j] - p[k * v + j])).collect();
    let force = params.gravity_direction.normalize_or_zero() * params.gravity_strength + SIDE_FORCE;
    let mut nodes = vec![Vec3::ZERO; layers + 1];
    let mut pass = || {
        for (root, strand) in p[..v].iter().zip(segments.chunks_exact(layers)) {
            bend_strand_literal(*root, Quat::IDENTITY, black_box(strand), force, params.stability, &mut nodes);
            black_box(&nodes);
        }
    };
    median_rate(budget, (v * layers) as f64, &mut pass)
}

/// The median over `budget.runs` runs of `nodes_per_pass * passes / seconds`, each run
/// repeating `pass` for at least `budget.min_run_secs` after one untimed pass (caches, pages,
/// thread pool).
pub(super) fn median_rate(budget: SimBudget, nodes_per_pass: f64, pass: &mut dyn FnMut()) -> f64 {
    pass();
    let mut rates: Vec<f64> = (0..budget.runs.max(1))
        .map(|_| {
            let started = Instant::now();
            let mut passes = 0_u64;
            loop {
                pass();
                passes += 1;
                let elapsed = started.elapsed().as_secs_f64();
                if elapsed >= budget.min_run_secs {
                    return passes as f64 * nodes_per_pass / elapsed;
                }
            }
        })
        .collect();
    rates.sort_by(f64::total_cmp);
    rates[rates.len() / 2]
}

/// Wall-clock CPU milliseconds per drawn frame: `advance_to` at 120 Hz render times (all threads).
fn cpu_ms_per_drawn_frame(fur: &FurStructure, params: &SimParams, budget: SimBudget) -> anyhow::Result<f64> {
    let mut simulation = Simulation::new(fur, params)?;
    let frames = budget.drawn_frames.max(1);
    let started = Instant::now();
    for frame in 1..=frames {
        simulation.advance_to(f64::from(frame) / DRAW_RATE_HZ);
        black_box(simulation.positions());
    }
    Ok(started.elapsed().as_secs_f64() * 1000.0 / f64::from(frames))
}
