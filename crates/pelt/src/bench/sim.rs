//! Simulation figures: bend throughput (O(L) and the paper's literal loop) and the CPU cost per
//! drawn frame with and without interpolation.

use std::hint::black_box;
use std::time::Instant;

use glam::{Quat, Vec3};
use pelt_core::FurStructure;
use pelt_core::sim::{SimParams, Simulation, bend_strand, bend_strand_literal};

use super::report::SimFigures;

/// The paper's setting: simulate at 30 Hz, draw at 120 Hz.
pub const SIM_RATE_HZ: f32 = 30.0;
pub const DRAW_RATE_HZ: f64 = 120.0;

/// How long each measurement runs.
#[derive(Clone, Copy, Debug)]
pub struct SimBudget {
    /// Bend passes over every strand repeat until at least this long has passed.
    pub min_bend_secs: f64,
    /// Drawn frames the per-frame cost is averaged over.
    pub drawn_frames: u32,
}

/// Measures `fur` under `params` (its gravity and stability; wind switched on so the field is
/// evaluated every step, as in a windy scene).
pub fn measure(fur: &FurStructure, params: &SimParams, budget: SimBudget) -> anyhow::Result<SimFigures> {
    let strands = Strands::new(fur);
    // Gravity plus a steady side force, so no strand is parallel to the force and every node turns.
    let force = params.gravity_direction.normalize_or_zero() * params.gravity_strength + Vec3::X * 0.5;
    let o_l = strands.node_updates_per_sec(budget.min_bend_secs, |segments, nodes| {
        bend_strand(nodes[0], Quat::IDENTITY, segments, force, params.stability, nodes);
    });
    let literal = strands.node_updates_per_sec(budget.min_bend_secs, |segments, nodes| {
        bend_strand_literal(nodes[0], Quat::IDENTITY, segments, force, params.stability, nodes);
    });

    let mut windy = params.clone();
    windy.rate_hz = SIM_RATE_HZ;
    if windy.wind.strength == 0.0 {
        windy.wind.strength = 0.5;
    }
    let interpolated = cpu_ms_per_drawn_frame(fur, &SimParams { interpolate: true, ..windy.clone() }, budget)?;
    let every_frame = cpu_ms_per_drawn_frame(fur, &SimParams { interpolate: false, ..windy }, budget)?;
    Ok(SimFigures {
        sim_node_updates_per_sec: Some(o_l),
        sim_literal_node_updates_per_sec: Some(literal),
        sim_cpu_ms_per_frame_interpolated: Some(interpolated),
        sim_cpu_ms_per_frame_every_frame: Some(every_frame),
        sim_unavailable_reason: None,
    })
}

/// The rest strands of a structure, strand-major, for calling the bend functions directly.
struct Strands {
    layers: usize,
    roots: Vec<Vec3>,
    segments: Vec<Vec3>,
}

impl Strands {
    fn new(fur: &FurStructure) -> Self {
        let v = fur.vertex_count();
        let layers = fur.layers as usize;
        let p = &fur.positions;
        let segments = (0..v).flat_map(|j| (0..layers).map(move |k| p[(k + 1) * v + j] - p[k * v + j])).collect();
        Self { layers, roots: p[..v].to_vec(), segments }
    }

    /// Non-root nodes placed per second by `bend` over every strand, on this thread alone (so
    /// the O(L) and literal figures compare the algorithms, not the scheduling).
    fn node_updates_per_sec(&self, min_secs: f64, bend: impl Fn(&[Vec3], &mut [Vec3])) -> f64 {
        let mut nodes = vec![Vec3::ZERO; self.layers + 1];
        let mut pass = || {
            for (root, segments) in self.roots.iter().zip(self.segments.chunks_exact(self.layers)) {
                nodes[0] = *root;
                bend(black_box(segments), &mut nodes);
                black_box(&nodes);
            }
        };
        // One untimed pass brings the strands into cache.
        pass();
        let started = Instant::now();
        let mut passes = 0_u64;
        loop {
            pass();
            passes += 1;
            let elapsed = started.elapsed().as_secs_f64();
            if elapsed >= min_secs {
                return (passes * (self.roots.len() * self.layers) as u64) as f64 / elapsed;
            }
        }
    }
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
