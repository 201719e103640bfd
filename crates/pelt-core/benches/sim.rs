//! Simulation figures: strand-node updates per second of `Simulation`'s kernel (straight and
//! curved strands, all threads and one) against the paper's literal loop (bunny and
//! `female_generic.obj`, 16 and 32 layers), and the CPU cost per drawn frame with interpolation
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
use pelt_core::sim::{SimParams, Simulation, WindParams, bend_strand_literal};

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

/// Curls every strand of `fur` a little (each segment turned about a fixed axis by 2 degrees
/// more than the last, about an axis across the strand), so the general form of the kernel bends them.
fn curl(fur: &mut FurStructure) {
    let v = fur.vertex_count();
    let layers = fur.layers as usize;
    for j in 0..v {
        let segments: Vec<Vec3> =
            (0..layers).map(|k| fur.positions[(k + 1) * v + j] - fur.positions[k * v + j]).collect();
        let axis = segments[0].any_orthonormal_vector();
        let mut node = fur.positions[j];
        for (k, segment) in segments.into_iter().enumerate() {
            node += Quat::from_axis_angle(axis, (2.0 * k as f32).to_radians()) * segment;
            fur.positions[(k + 1) * v + j] = node;
        }
    }
}

/// Node updates of the kernel `Simulation` runs (`step_at`: field, then the bend), on all
/// threads and on one, for straight (grown) and curved strands; and the paper's literal loop on
/// one thread, timed the same way.
fn node_updates(c: &mut Criterion) {
    let mut group = c.benchmark_group("sim_nodes");
    let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build().expect("a pool");
    for (name, mesh) in meshes() {
        for layers in [16u32, 32] {
            let fur = grow(&mesh, layers);
            let (v, l) = (fur.vertex_count(), layers as usize);
            group.throughput(Throughput::Elements((v * l) as u64));
            let id = format!("{name}/L{layers}");
            let mut curled = fur.clone();
            curl(&mut curled);
            for (shape, fur) in [("straight", &fur), ("curved", &curled)] {
                let mut sim = Simulation::new(fur, &SimParams { interpolate: false, ..params() }).expect("valid");
                sim.field_mut().fill(Vec3::new(0.5, 0.0, 0.2));
                let mut time = 0.0;
                group.bench_function(BenchmarkId::new(format!("step_{shape}_all_threads"), &id), |b| {
                    b.iter(|| {
                        time += 1.0 / 30.0;
                        sim.step_at(time);
                    });
                });
                group.bench_function(BenchmarkId::new(format!("step_{shape}_1_thread"), &id), |b| {
                    one_thread.install(|| {
                        b.iter(|| {
                            time += 1.0 / 30.0;
                            sim.step_at(time);
                        });
                    });
                });
            }
            let segments: Vec<Vec3> = (0..v)
                .flat_map(|j| (0..l).map(move |k| (j, k)))
                .map(|(j, k)| fur.positions[(k + 1) * v + j] - fur.positions[k * v + j])
                .collect();
            let mut nodes = vec![Vec3::ZERO; l + 1];
            let force = Vec3::new(0.5, -1.0, 0.2);
            group.bench_function(BenchmarkId::new("literal_1_thread", &id), |b| {
                b.iter(|| {
                    for (root, strand) in fur.positions[..v].iter().zip(segments.chunks_exact(l)) {
                        bend_strand_literal(*root, Quat::IDENTITY, black_box(strand), force, 8.0, &mut nodes);
                        black_box(&nodes);
                    }
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
