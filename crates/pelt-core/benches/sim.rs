//! Simulation figures: strand-node updates per second (O(L) against the literal loop, bunny and
//! `female_generic.obj`, 16 and 32 layers) and the CPU cost per drawn frame with interpolation
//! (30 Hz simulation, 120 Hz drawing) against simulating every frame.
//!
//! `cargo bench -p pelt-core --bench sim -- --warm-up-time 1 --measurement-time 3`

use std::hint::black_box;
use std::path::Path;

use criterion::{BenchmarkId, Criterion, Throughput, criterion_group, criterion_main};
use glam::{Quat, Vec3};
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
use pelt_core::mesh::builtin::Builtin;
use pelt_core::mesh::{ImportOptions, Mesh};
use pelt_core::sim::{SimParams, Simulation, WindParams, bend_strand, bend_strand_literal};
use rayon::prelude::*;

fn meshes() -> Vec<(&'static str, Mesh)> {
    let female = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/meshes/female_generic.obj");
    let (female, _) = Mesh::load(&female, &ImportOptions::default())
        .expect("crates/pelt-core/assets/meshes/female_generic.obj loads");
    vec![("bunny", Builtin::Bunny.mesh().0), ("female_generic", female)]
}

fn grow(mesh: &Mesh, layers: u32) -> FurStructure {
    let length = FurLength::Constant(mesh.mean_edge_length() * 2.0);
    let direction = GrowthDirection { random_angle_rad: 0.3, seed: 1, ..GrowthDirection::default() };
    FurStructure::new(mesh.clone(), &FurParams { layers, length, direction }).expect("valid fur")
}

fn params() -> SimParams {
    SimParams { wind: WindParams { strength: 1.0, ..WindParams::default() }, ..SimParams::default() }
}

/// One bend of every strand (gravity + a per-strand force), parallel, strand-major output.
fn bend_all(
    bend: fn(Vec3, Quat, &[Vec3], Vec3, f32, &mut [Vec3]),
    roots: &[Vec3],
    segments: &[Vec3],
    forces: &[Vec3],
    layers: usize,
    nodes: &mut [Vec3],
) {
    nodes.par_chunks_mut(layers + 1).enumerate().with_min_len(64).for_each(|(j, strand)| {
        let rest = &segments[j * layers..(j + 1) * layers];
        bend(roots[j], Quat::IDENTITY, rest, Vec3::NEG_Y + forces[j], 8.0, strand);
    });
}

fn node_updates(c: &mut Criterion) {
    let mut group = c.benchmark_group("sim_nodes");
    for (name, mesh) in meshes() {
        for layers in [16u32, 32] {
            let fur = grow(&mesh, layers);
            let (v, l) = (fur.vertex_count(), layers as usize);
            group.throughput(Throughput::Elements((v * l) as u64));
            let segments: Vec<Vec3> = (0..v)
                .flat_map(|j| (0..l).map(move |k| (j, k)))
                .map(|(j, k)| fur.positions[(k + 1) * v + j] - fur.positions[k * v + j])
                .collect();
            let forces: Vec<Vec3> = (0..v).map(|j| Vec3::new((j % 7) as f32 * 0.3, 0.0, 0.5)).collect();
            let mut nodes = vec![Vec3::ZERO; v * (l + 1)];
            let roots = &fur.positions[..v];
            let id = format!("{name}/L{layers}");
            group.bench_function(BenchmarkId::new("o_l", &id), |b| {
                b.iter(|| bend_all(bend_strand, roots, &segments, &forces, l, black_box(&mut nodes)));
            });
            group.bench_function(BenchmarkId::new("literal", &id), |b| {
                b.iter(|| bend_all(bend_strand_literal, roots, &segments, &forces, l, black_box(&mut nodes)));
            });
            // A whole step: wind field (gusts, jitter) plus the bend, plus the layer-major lerp.
            let mut sim = Simulation::new(&fur, &SimParams { interpolate: false, ..params() }).expect("valid");
            let mut time = 0.0;
            group.bench_function(BenchmarkId::new("step", &id), |b| {
                b.iter(|| {
                    time += 1.0 / 30.0;
                    sim.advance_to(time);
                    black_box(sim.positions());
                });
            });
        }
    }
    group.finish();
}

fn frame_cost(c: &mut Criterion) {
    let mut group = c.benchmark_group("sim_frame_120hz");
    for (name, mesh) in meshes() {
        for layers in [16u32, 32] {
            let fur = grow(&mesh, layers);
            for interpolate in [true, false] {
                let mut sim = Simulation::new(&fur, &SimParams { interpolate, ..params() }).expect("valid");
                let mut frame = 0u64;
                let mode = if interpolate { "interpolated_30hz" } else { "every_frame" };
                group.bench_function(BenchmarkId::new(mode, format!("{name}/L{layers}")), |b| {
                    b.iter(|| {
                        frame += 1;
                        sim.advance_to(frame as f64 / 120.0);
                        black_box(sim.positions());
                    });
                });
            }
        }
    }
    group.finish();
}

criterion_group!(benches, node_updates, frame_cost);
criterion_main!(benches);
