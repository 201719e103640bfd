//! The simulation invariants of docs/paper-notes.md section 4, plus touch, interpolation, picking and
//! scene scripts.

use std::path::Path;

use glam::{Quat, Vec3};
use pelt_core::fur::{FurLength, FurParams, FurStructure, GrowthDirection};
use pelt_core::mesh::builtin::Builtin;
use pelt_core::sim::{
    CpuKernel, Scene, SceneError, SimParams, Simulation, SoakStep, SoakSubject, WindParams, bend_strand,
    bend_strand_literal, pick, soak,
};
use proptest::prelude::*;

fn grow(builtin: Builtin, layers: u32, length: f32) -> FurStructure {
    let (mesh, _) = builtin.mesh();
    let direction = GrowthDirection { random_angle_rad: 0.4, seed: 5, ..GrowthDirection::default() };
    FurStructure::new(mesh, &FurParams { layers, length: FurLength::Constant(length), direction }).unwrap()
}

fn still() -> SimParams {
    SimParams { gravity_strength: 0.0, ..SimParams::default() }
}

fn windy() -> WindParams {
    WindParams { strength: 1.5, direction: Vec3::new(1.0, 0.2, -0.5), ..WindParams::default() }
}

/// The largest relative error of any segment length against the rest pose.
fn worst_length_error(fur: &FurStructure, positions: &[Vec3]) -> f32 {
    let v = fur.vertex_count();
    let mut worst = 0.0f32;
    for k in 0..fur.layers as usize {
        for j in 0..v {
            let rest = fur.positions[(k + 1) * v + j].distance(fur.positions[k * v + j]);
            let now = positions[(k + 1) * v + j].distance(positions[k * v + j]);
            worst = worst.max((now - rest).abs() / rest.max(1e-12));
        }
    }
    worst
}

/// A straight strand of `layers` segments along `direction`, total length `length`.
fn straight(layers: usize, direction: Vec3, length: f32) -> Vec<Vec3> {
    vec![direction.normalize() * (length / layers as f32); layers]
}

fn run_both(root: Vec3, frame: Quat, segments: &[Vec3], force: Vec3, stability: f32) -> (Vec<Vec3>, Vec<Vec3>) {
    let mut fast = vec![Vec3::ZERO; segments.len() + 1];
    let mut literal = fast.clone();
    bend_strand(root, frame, segments, force, stability, &mut fast);
    bend_strand_literal(root, frame, segments, force, stability, &mut literal);
    (fast, literal)
}

/// The angle between `a` and `b`, well conditioned near 0 (f32 `acos` of a dot product cannot
/// resolve angles below about 5e-4 radians: one ulp under 1 is already that angle).
fn turn(a: Vec3, b: Vec3) -> f32 {
    let (a, b) = (a.as_dvec3(), b.as_dvec3());
    a.cross(b).length().atan2(a.dot(b)) as f32
}

fn unit(v: (f32, f32, f32)) -> Vec3 {
    Vec3::new(v.0, v.1, v.2).try_normalize().unwrap_or(Vec3::Y)
}

fn vec3() -> impl Strategy<Value = (f32, f32, f32)> {
    (-1.0f32..1.0, -1.0f32..1.0, -1.0f32..1.0)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]

    #[test]
    fn roots_stay_lengths_keep_and_literal_agrees(
        layers in 1usize..40,
        grow_dir in vec3(),
        force_dir in vec3(),
        force_log10 in -3.0f32..9.0,
        stability_log10 in -6.0f32..9.0,
        frame_axis in vec3(),
        frame_angle in -3.0f32..3.0,
        root in vec3(),
    ) {
        let segments = straight(layers, unit(grow_dir), 2.0);
        let force = unit(force_dir) * 10f32.powf(force_log10);
        let stability = 10f32.powf(stability_log10);
        let frame = Quat::from_axis_angle(unit(frame_axis), frame_angle);
        let root = Vec3::new(root.0, root.1, root.2) * 5.0;
        let (fast, literal) = run_both(root, frame, &segments, force, stability);
        prop_assert_eq!(fast[0], root);
        prop_assert_eq!(literal[0], root);
        for k in 0..layers {
            let rest = segments[k].length();
            let now = fast[k + 1].distance(fast[k]);
            prop_assert!((now - rest).abs() <= 1e-5 * rest, "segment {} {} vs {}", k, now, rest);
        }
        for (a, b) in fast.iter().zip(&literal) {
            prop_assert!(a.is_finite() && b.is_finite());
            prop_assert!(a.distance(*b) <= 1e-5 * 2.0 + 1e-5 * root.length(), "{} vs {}", a, b);
        }
    }

    #[test]
    fn no_segment_turns_past_the_force(
        layers in 1usize..33,
        grow_dir in vec3(),
        force_dir in vec3(),
        force_log10 in -2.0f32..9.0,
        stability_log10 in -6.0f32..3.0,
    ) {
        let rest_direction = unit(grow_dir);
        let f = unit(force_dir);
        let segments = straight(layers, rest_direction, 1.0);
        let (nodes, _) = run_both(Vec3::ZERO, Quat::IDENTITY, &segments, f * 10f32.powf(force_log10), 10f32.powf(stability_log10));
        let rest_angle = turn(rest_direction, f);
        let rest_side = rest_direction.cross(f);
        for k in 0..layers {
            let d = (nodes[k + 1] - nodes[k]).normalize();
            prop_assert!(turn(d, f) <= rest_angle + 1e-4, "segment {} overshot", k);
            // Still on the rest side of the force (it may reach it, never cross it).
            prop_assert!(d.cross(f).dot(rest_side) >= -1e-5, "segment {} crossed the force", k);
        }
    }

    #[test]
    fn deflection_falls_as_stability_rises(
        layers in 1usize..33,
        grow_dir in vec3(),
        force_dir in vec3(),
        force in 0.01f32..100.0,
        stability in 0.01f32..100.0,
        stiffer in 1.0f32..10.0,
    ) {
        let rest_direction = unit(grow_dir);
        let segments = straight(layers, rest_direction, 1.0);
        let force = unit(force_dir) * force;
        let (soft, _) = run_both(Vec3::ZERO, Quat::IDENTITY, &segments, force, stability);
        let (stiff, _) = run_both(Vec3::ZERO, Quat::IDENTITY, &segments, force, stability * stiffer);
        for k in 0..layers {
            let soft_turn = turn(soft[k + 1] - soft[k], rest_direction);
            let stiff_turn = turn(stiff[k + 1] - stiff[k], rest_direction);
            prop_assert!(stiff_turn <= soft_turn + 1e-4, "segment {}: {} > {}", k, stiff_turn, soft_turn);
        }
        let soft_tip = soft[layers].distance(Vec3::ZERO + rest_direction);
        let stiff_tip = stiff[layers].distance(Vec3::ZERO + rest_direction);
        prop_assert!(stiff_tip <= soft_tip + 1e-5);
    }
}

#[test]
fn no_nan_or_infinity_at_the_edges() {
    let directions = [Vec3::Y, Vec3::NEG_Y, Vec3::X, Vec3::new(1e-7, 1.0, 0.0), Vec3::new(-1e-7, -1.0, 1e-8)];
    let magnitudes = [0.0, 1e-30, 1e-6, 1.0, 1e3, 1e9, 1e30, f32::MAX];
    let stabilities = [1e-6, 1e-3, 1.0, 8.0, 1e6, 1e9];
    for layers in [1, 2, 16, 32, 128] {
        let segments = straight(layers, Vec3::Y, 1.0);
        for d in directions {
            for m in magnitudes {
                for s in stabilities {
                    let (fast, literal) = run_both(Vec3::ONE, Quat::IDENTITY, &segments, d * m, s);
                    assert!(fast.iter().chain(&literal).all(|p| p.is_finite()), "{layers} {d} {m} {s}");
                    let tip_length = fast[layers].distance(fast[0]);
                    assert!(tip_length <= 1.0 + 1e-5, "strand grew: {tip_length}");
                }
            }
        }
    }
    // Zero-length fur stays at its roots.
    let (fast, literal) = run_both(Vec3::ONE, Quat::IDENTITY, &[Vec3::ZERO; 4], Vec3::X, 1.0);
    assert!(fast.iter().chain(&literal).all(|p| *p == Vec3::ONE));
}

#[test]
fn force_along_or_against_the_strand_changes_nothing() {
    let segments = straight(16, Vec3::Y, 1.0);
    for force in [Vec3::Y * 5.0, Vec3::NEG_Y * 5.0, Vec3::ZERO] {
        let (nodes, _) = run_both(Vec3::ZERO, Quat::IDENTITY, &segments, force, 1.0);
        for (k, node) in nodes.iter().enumerate() {
            assert!(node.distance(Vec3::Y * (k as f32 / 16.0)) < 1e-6);
        }
    }
}

#[test]
fn zero_force_leaves_the_rest_pose() {
    let fur = grow(Builtin::Bunny, 16, 0.4);
    let mut sim = Simulation::new(&fur, &still()).unwrap();
    sim.advance_to(0.5);
    for (now, rest) in sim.positions().iter().zip(&fur.positions) {
        assert!(now.distance(*rest) <= 1e-5 * rest.length().max(1.0), "{now} vs {rest}");
    }
}

#[test]
fn gravity_pulls_fur_down_and_keeps_roots_and_lengths() {
    let fur = grow(Builtin::Sphere, 16, 0.3);
    let mut sim = Simulation::new(&fur, &SimParams::default()).unwrap();
    sim.advance_to(0.2);
    let positions = sim.positions();
    let v = fur.vertex_count();
    assert_eq!(&positions[..v], &fur.positions[..v], "roots never move");
    assert!(worst_length_error(&fur, positions) < 1e-5);
    let tips = 16 * v..17 * v;
    let drop: f32 = positions[tips.clone()].iter().zip(&fur.positions[tips]).map(|(a, b)| b.y - a.y).sum();
    assert!(drop / v as f32 > 0.01, "mean tip drop {}", drop / v as f32);
}

fn simulate_with_threads(threads: usize, kernel: CpuKernel, curved: bool) -> Vec<u8> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
    pool.install(|| {
        let mut fur = grow(Builtin::Bunny, 16, 0.5);
        if curved {
            // Every strand bends away from its growth line: the general form of the kernel.
            let v = fur.vertex_count();
            for k in 1..=16 {
                for j in 0..v {
                    fur.positions[k * v + j] += Vec3::new(0.0, 0.002, 0.001) * (k * k) as f32;
                }
            }
        }
        let params = SimParams { wind: windy(), ..SimParams::default() };
        let mut sim = Simulation::new(&fur, &params).unwrap();
        sim.set_cpu_kernel(kernel);
        assert_eq!(sim.straight_share() == 1.0, !curved);
        sim.touch_begin(fur.mesh.positions[100], 1.5).unwrap();
        sim.touch_drag(fur.mesh.positions[100] + Vec3::new(0.5, -1.0, 0.0)).unwrap();
        let mut bytes = Vec::new();
        for frame in 0..12 {
            sim.advance_to(f64::from(frame) / 60.0);
            bytes.extend(sim.positions().iter().flat_map(|p| p.to_array()).flat_map(f32::to_le_bytes));
        }
        bytes
    })
}

#[test]
fn results_do_not_depend_on_the_thread_count_or_the_instructions() {
    for curved in [false, true] {
        let reference = simulate_with_threads(1, CpuKernel::Portable, curved);
        assert!(reference == simulate_with_threads(4, CpuKernel::Portable, curved), "curved {curved}: threads");
        // On a CPU without AVX2 + FMA this runs the portable kernel again (the oracle tests say
        // which ran).
        assert!(reference == simulate_with_threads(3, CpuKernel::Avx2Fma, curved), "curved {curved}: AVX2");
    }
}

#[test]
fn touch_changes_the_field_only_within_its_radius_and_release_restores_it() {
    let fur = grow(Builtin::Bunny, 8, 0.4);
    let params = SimParams { wind: windy(), ..SimParams::default() };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let v = fur.vertex_count();
    let mut before = vec![Vec3::ZERO; v];
    let mut during = before.clone();
    let mut after = before.clone();
    let time = 0.37;
    sim.evaluate_field(time, &mut before);
    let radius = 1.2;
    let above = fur.mesh.positions[500] + fur.mesh.normals[500] * 3.0;
    assert!(sim.touch_ray(&fur.mesh.triangles, above, Vec3::Y, radius).unwrap().is_none(), "a miss begins nothing");
    assert!(sim.touch().is_none());
    let hit = sim.touch_ray(&fur.mesh.triangles, above, -fur.mesh.normals[500], radius).unwrap().unwrap();
    let point = hit.point;
    assert!(point.distance(fur.mesh.positions[500]) < 0.5, "{point}");
    assert_eq!(sim.touch().unwrap().point, point);
    sim.touch_drag(point + Vec3::new(0.0, -2.0, 0.0)).unwrap();
    sim.evaluate_field(time, &mut during);
    let mut changed = 0;
    for j in 0..v {
        let inside = fur.mesh.positions[j].distance(point) < radius;
        if inside {
            changed += usize::from(during[j] != before[j]);
        } else {
            assert_eq!(during[j], before[j], "vertex {j} outside the radius changed");
        }
    }
    assert!(changed > 5, "only {changed} vertices changed");
    sim.touch_end();
    assert!(sim.touch().is_none());
    sim.evaluate_field(time, &mut after);
    assert_eq!(after, before, "release restores the original field exactly");
}

#[test]
fn touch_eases_back_over_release_secs_then_restores_exactly() {
    let fur = grow(Builtin::Sphere, 8, 0.3);
    let mut params = still();
    params.touch.release_secs = 0.5;
    let mut sim = Simulation::new(&fur, &params).unwrap();
    sim.field_mut().fill(Vec3::new(0.1, 0.2, 0.3));
    let v = fur.vertex_count();
    let original = sim.field().values().to_vec();
    let point = fur.mesh.positions[10];
    sim.touch_begin(point, 0.5).unwrap();
    sim.touch_drag(point + Vec3::X).unwrap();
    sim.advance_to(1.0);
    let held = sim.external_field().to_vec();
    sim.touch_end();
    let mut halfway = vec![Vec3::ZERO; v];
    sim.evaluate_field(1.25, &mut halfway);
    for j in 0..v {
        let full = held[j].distance(original[j]);
        let half = halfway[j].distance(original[j]);
        assert!(half <= full * 0.5 + 1e-5 && (full == 0.0 || half > 0.0), "{j}: {half} of {full}");
    }
    sim.advance_to(1.6);
    assert!(sim.touch().is_none(), "a faded touch is dropped");
    sim.advance_to(1.7);
    assert_eq!(sim.external_field(), original.as_slice());
}

#[test]
fn touch_bends_fur_toward_the_drag() {
    let fur = grow(Builtin::Sphere, 16, 0.3);
    let mut sim = Simulation::new(&fur, &still()).unwrap();
    let j = 200;
    let point = fur.mesh.positions[j];
    let drag = Vec3::new(0.0, 0.0, 1.0).cross(fur.mesh.normals[j]).normalize();
    sim.touch_begin(point, 0.3).unwrap();
    sim.touch_drag(point + drag * 0.3).unwrap();
    sim.advance_to(0.1);
    sim.advance_to(0.2);
    let v = fur.vertex_count();
    let moved = sim.positions()[16 * v + j] - fur.positions[16 * v + j];
    assert!(moved.dot(drag) > 0.05, "tip moved {moved}");
}

#[test]
fn interpolation_hits_the_stored_states_at_alpha_zero_and_one() {
    let fur = grow(Builtin::Box, 16, 0.3);
    let params = SimParams { wind: windy(), ..SimParams::default() };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let n = fur.positions.len();
    let mut current = vec![Vec3::ZERO; n];
    let mut previous = vec![Vec3::ZERO; n];
    sim.advance_to(1.0 / 30.0 * 5.5);
    assert!((sim.alpha() - 0.5).abs() < 1e-4);
    sim.write_lerp(1.0, &mut current);
    assert!(worst_length_error(&fur, &current) < 1e-5, "states keep lengths");
    // The next step: the old current becomes the previous, exactly.
    sim.advance_to(1.0 / 30.0 * 6.25);
    sim.write_lerp(0.0, &mut previous);
    assert_eq!(previous, current);
    // Interpolated positions lie between the two states.
    sim.write_lerp(1.0, &mut current);
    for ((p, a), b) in sim.positions().iter().zip(&previous).zip(&current) {
        let expected = *a * 0.75 + *b * 0.25;
        assert!(p.distance(expected) < 1e-4);
    }
    // Steps are pure functions of time: a jump lands on the same state as stepping there.
    let mut jumped = Simulation::new(&fur, &params).unwrap();
    jumped.advance_to(1.0 / 30.0 * 6.25);
    assert_eq!(jumped.positions(), sim.positions());
    assert!(jumped.steps_taken() <= 4);
}

#[test]
fn without_interpolation_every_frame_is_simulated() {
    let fur = grow(Builtin::Box, 8, 0.3);
    let params = SimParams { interpolate: false, wind: windy(), ..SimParams::default() };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let before = sim.steps_taken();
    let mut current = vec![Vec3::ZERO; fur.positions.len()];
    for frame in 1..=10 {
        sim.advance_to(f64::from(frame) / 120.0);
        sim.write_lerp(1.0, &mut current);
        assert_eq!(sim.positions(), current.as_slice());
    }
    assert_eq!(sim.steps_taken() - before, 10);
    // With interpolation, frames between steps run no step: the last step's time stays.
    let mut sim = Simulation::new(&fur, &SimParams { interpolate: true, ..params }).unwrap();
    sim.advance_to(1.0);
    let (steps, secs) = (sim.steps_taken(), sim.last_step_secs());
    assert!(secs > 0.0 && secs < 10.0, "{secs}");
    sim.advance_to(1.0 + 0.5 / 30.0);
    assert_eq!((sim.steps_taken(), sim.last_step_secs()), (steps, secs));
    sim.advance_to(1.0 + 1.5 / 30.0);
    assert_eq!(sim.steps_taken(), steps + 1);
    assert_ne!(sim.last_step_secs(), secs, "a new step is timed anew");
}

#[test]
fn a_rotated_base_carries_the_rest_pose_along() {
    let rotation = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 0.5).normalize(), 1.1);
    let offset = Vec3::new(3.0, -1.0, 2.0);
    // Fur along the normals follows the normals alone; leaning fur needs the full rotations.
    let (mesh, _) = Builtin::Torus.mesh();
    let upright = FurStructure::new(
        mesh,
        &FurParams { layers: 8, length: FurLength::Constant(0.3), direction: GrowthDirection::default() },
    )
    .unwrap();
    for (fur, full) in [(upright, false), (grow(Builtin::Torus, 8, 0.3), true)] {
        let mut sim = Simulation::new(&fur, &still()).unwrap();
        let positions: Vec<Vec3> = fur.mesh.positions.iter().map(|p| rotation * *p + offset).collect();
        let normals: Vec<Vec3> = fur.mesh.normals.iter().map(|n| rotation * *n).collect();
        if full {
            sim.set_base_rotations(&positions, &vec![rotation; positions.len()]).unwrap();
        } else {
            sim.set_base(&positions, &normals).unwrap();
        }
        sim.advance_to(0.5);
        for (now, rest) in sim.positions().iter().zip(&fur.positions) {
            assert!(now.distance(rotation * *rest + offset) < 1e-4, "{now}");
        }
        assert!(sim.set_base(&positions[1..], &normals).is_err());
        let mut bad = normals.clone();
        bad[3] = Vec3::NAN;
        assert!(sim.set_base(&positions, &bad).is_err());
    }
}

/// The soak CI runs: 10,000 bunny steps under extreme, changing inputs (`pelt bench --soak`
/// runs a million).
#[test]
fn soak_keeps_every_node_finite_and_every_length() {
    let fur = grow(Builtin::Bunny, 16, 0.5);
    let mut sim = Simulation::new(&fur, &SimParams::default()).unwrap();
    let report = soak(&fur, &mut sim, 10_000, |_| {}).unwrap();
    assert_eq!(report.steps, 10_000);
    assert!(report.passed(1e-5), "{report:?}");
    // The schedule reaches its extremes within those steps.
    let steps: Vec<SoakStep> = (0..10_000).map(|i| SoakStep::at(i, fur.vertex_count(), 3.0)).collect();
    assert!(steps.iter().any(|s| s.params.gravity_strength == 1000.0));
    assert!(steps.iter().any(|s| s.params.stability < 1e-4));
    assert!(steps.iter().any(|s| s.params.wind.strength > 1e3));
    assert!(steps.iter().any(|s| s.field.is_some_and(|f| f.x.abs() >= 1e29)));
    assert!(
        steps.iter().any(|s| s.base.is_some()) && steps.iter().any(|s| s.stability_map.is_some_and(|m| m.is_some()))
    );
}

#[test]
fn soak_catches_a_kernel_that_stretches_strands() {
    /// Wraps a simulation and stretches one segment of its state by 1e-3 of its length.
    struct Stretching(Simulation);
    impl SoakSubject for Stretching {
        fn step(&mut self, step: &SoakStep) -> Result<(), pelt_core::SimError> {
            self.0.step(step)
        }
        fn read_state(&mut self, out: &mut [Vec3]) -> Result<(), pelt_core::SimError> {
            self.0.read_state(out)?;
            let v = self.0.vertex_count();
            out[2 * v + 5] += (out[2 * v + 5] - out[v + 5]) * 1e-3;
            Ok(())
        }
    }
    let fur = grow(Builtin::Sphere, 8, 0.3);
    let mut subject = Stretching(Simulation::new(&fur, &SimParams::default()).unwrap());
    let report = soak(&fur, &mut subject, 20, |_| {}).unwrap();
    assert!(!report.passed(1e-5), "{report:?}");
    assert!(report.worst_length_error > 1e-5);
}

#[test]
fn picking_hits_the_right_triangle() {
    let (mesh, _) = Builtin::Bunny.mesh();
    for t in (0..mesh.triangles.len()).step_by(97) {
        let [a, b, c] = mesh.triangles[t].map(|i| mesh.positions[i as usize]);
        let centre = (a + b + c) / 3.0;
        let normal = mesh.face_normal(t);
        let origin = centre + normal * 1e-3;
        let hit = pick(&mesh.positions, &mesh.triangles, origin, -normal).expect("a ray at a face hits");
        assert_eq!(hit.triangle as usize, t);
        assert!(hit.point.distance(centre) < 1e-3);
        assert!((hit.distance - 1e-3).abs() < 1e-4);
        assert!(hit.barycentric.distance(Vec3::splat(1.0 / 3.0)) < 1e-3);
    }
    let miss = pick(&mesh.positions, &mesh.triangles, Vec3::new(0.0, 50.0, 0.0), Vec3::Y);
    assert_eq!(miss, None);
    assert_eq!(pick(&mesh.positions, &mesh.triangles, Vec3::ZERO, Vec3::ZERO), None);
    // From far above, the hit is the highest crossing of all triangles on that vertical line.
    for (x, z) in [(0.3, 0.2), (-2.8, 0.1), (2.5, 1.0), (1.0, -2.0)] {
        let top = pick(&mesh.positions, &mesh.triangles, Vec3::new(x, 50.0, z), Vec3::NEG_Y).unwrap();
        let highest = mesh
            .triangles
            .iter()
            .filter_map(|t| {
                let [a, b, c] = t.map(|i| mesh.positions[i as usize]);
                let area = |p: Vec3, q: Vec3, r: Vec3| (q.x - p.x) * (r.z - p.z) - (r.x - p.x) * (q.z - p.z);
                let point = Vec3::new(x, 0.0, z);
                let total = area(a, b, c);
                let (wa, wb, wc) = (area(point, b, c) / total, area(a, point, c) / total, area(a, b, point) / total);
                (total != 0.0 && wa >= 0.0 && wb >= 0.0 && wc >= 0.0).then_some(wa * a.y + wb * b.y + wc * c.y)
            })
            .fold(f32::MIN, f32::max);
        assert!((top.point.y - highest).abs() < 1e-3, "({x}, {z}): {} vs {highest}", top.point.y);
    }
}

fn scene_error(text: &str) -> String {
    let error = Scene::from_toml_str(text, Path::new("scenes/bad.toml")).unwrap_err();
    let message = error.to_string();
    assert!(message.starts_with("scenes/bad.toml"), "{message}");
    message
}

#[test]
fn scene_errors_name_file_and_key() {
    let message =
        scene_error("[[stroke]]\nstart_secs = 1.0\nend_secs = 2.0\nradius = \"big\"\npath = [[0.0, 0.0, 0.0]]\n");
    assert!(message.contains("radius"), "{message}");
    let message = scene_error("[[wind]]\ntime_secs = 0.0\ndirection = [1.0, 0.0, 0.0]\nstrength = 1.0\nspeed = 3.0\n");
    assert!(message.contains("speed"), "{message}");
    let message = scene_error("[[stroke]]\nstart_secs = 2.0\nend_secs = 1.0\nradius = 1.0\npath = [[0.0, 0.0, 0.0]]\n");
    assert!(message.contains("stroke[0].end_secs"), "{message}");
    let message = scene_error(
        "[[wind]]\ntime_secs = 1.0\ndirection = [1, 0, 0]\nstrength = 1.0\n\
         [[wind]]\ntime_secs = 0.5\ndirection = [0, 0, 0]\nstrength = 1.0\n",
    );
    assert!(message.contains("wind[1].time_secs"), "{message}");
    let message = scene_error("[[wind]]\ntime_secs = 0.0\ndirection = [0, 0, 0]\nstrength = 1.0\n");
    assert!(message.contains("wind[0].direction"), "{message}");
    match Scene::load(Path::new("no/such/scene.toml")) {
        Err(SceneError::Io { file, .. }) => assert_eq!(file, Path::new("no/such/scene.toml")),
        other => panic!("{other:?}"),
    }
}

#[test]
fn shipped_scenes_drive_the_bunny() {
    let fur = grow(Builtin::Bunny, 16, 0.5);
    let scenes = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/scenes");
    for name in ["gust.toml", "pat.toml"] {
        let scene = Scene::load(&scenes.join(name)).unwrap();
        let mut sim = Simulation::new(&fur, &SimParams::default()).unwrap();
        for stroke in &scene.strokes {
            let touched = fur.mesh.positions.iter().filter(|p| p.distance(stroke.path[0]) < stroke.radius).count();
            assert!(touched >= 10, "{name}: a stroke touches only {touched} roots");
        }
        let frames = (scene.duration_secs() * 30.0) as u32;
        let mut touched_frames = 0;
        let mut windy_frames = 0;
        for frame in 0..=frames {
            let t = f64::from(frame) / 30.0;
            scene.apply(t, &mut sim).unwrap();
            sim.advance_to(t);
            touched_frames += usize::from(sim.touch().is_some());
            windy_frames += usize::from(sim.params().wind.strength > 0.0);
            assert!(sim.positions().iter().all(|p| p.is_finite()));
        }
        assert!(touched_frames > 0 || windy_frames > 0, "{name} does nothing");
        assert_eq!(touched_frames > 0, !scene.strokes.is_empty(), "{name}");
        assert!(sim.touch().is_none(), "{name}: every stroke ends");
    }
}

#[test]
fn batched_simulation_matches_the_per_strand_bend() {
    // 1,839 strands: not a multiple of the batch width, so the padded lanes are exercised too.
    let fur = grow(Builtin::Bunny, 12, 0.6);
    let params = SimParams { wind: windy(), gravity_strength: 2.0, ..SimParams::default() };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let v = fur.vertex_count();
    let map: Vec<f32> = (0..v).map(|j| 0.5 + (j % 13) as f32).collect();
    sim.set_stability_map(Some(map.clone())).unwrap();
    assert!(sim.set_stability_map(Some(vec![1.0; 3])).is_err());
    assert!(sim.set_stability_map(Some(vec![0.0; v])).is_err());
    sim.field_mut().values_mut()[7] = Vec3::new(0.0, 0.0, 1e9);
    sim.advance_to(2.0);
    let mut current = vec![Vec3::ZERO; fur.positions.len()];
    sim.write_lerp(1.0, &mut current);
    let gravity = Vec3::NEG_Y * 2.0;
    let layers = 12;
    let mut nodes = vec![Vec3::ZERO; layers + 1];
    for j in 0..v {
        let segments: Vec<Vec3> =
            (0..layers).map(|k| fur.positions[(k + 1) * v + j] - fur.positions[k * v + j]).collect();
        let force = gravity + sim.external_field()[j];
        bend_strand(fur.positions[j], Quat::IDENTITY, &segments, force, map[j], &mut nodes);
        for (i, node) in nodes.iter().enumerate() {
            let got = current[i * v + j];
            assert!(got.distance(*node) <= 1e-5 * node.length().max(1.0), "strand {j} node {i}: {got} vs {node}");
        }
    }
}

/// Mean over strands of the tip's offset from its root, minus the same at rest.
fn mean_tip_lean(fur: &FurStructure, positions: &[Vec3]) -> Vec3 {
    let v = fur.vertex_count();
    let tips = fur.layers as usize * v;
    let lean: Vec3 =
        (0..v).map(|j| (positions[tips + j] - positions[j]) - (fur.positions[tips + j] - fur.positions[j])).sum();
    lean / v as f32
}

/// Steps to the inertia tests' base: translated by `offset`, not turned.
fn move_base(sim: &mut Simulation, fur: &FurStructure, offset: Vec3) {
    let positions: Vec<Vec3> = fur.mesh.positions.iter().map(|p| *p + offset).collect();
    sim.set_base_rotations(&positions, &vec![Quat::IDENTITY; positions.len()]).unwrap();
}

#[test]
fn a_sudden_start_tilts_the_fur_back_then_it_swings_past_and_settles() {
    let fur = grow(Builtin::Plane, 8, 0.3);
    let (_, radius) = fur.mesh.bounding_sphere();
    let params = SimParams { inertia: 0.2, damping: 0.3, ..still() };
    let rate = f64::from(params.rate_hz);
    let mut sim = Simulation::new(&fur, &params).unwrap();
    // At rest for 10 steps, then from step 10 on a constant velocity of 1 radius/s along +X:
    // one step of acceleration, then none.
    let speed = Vec3::X * radius;
    let mut leans = Vec::new();
    let mut forces = Vec::new();
    for n in 1..=120_i32 {
        let moving_secs = (n - 10).max(0) as f32 / params.rate_hz;
        move_base(&mut sim, &fur, speed * moving_secs);
        sim.advance_to(f64::from(n) / rate);
        let step_positions = {
            let mut out = vec![Vec3::ZERO; sim.positions().len()];
            sim.write_lerp(1.0, &mut out);
            out
        };
        leans.push(mean_tip_lean(&fur, &step_positions).x);
        forces.push(sim.inertial_forces()[0].x);
    }
    assert!(leans[..10].iter().all(|l| l.abs() < 1e-6), "still at rest before the start: {:?}", &leans[..10]);
    let back = leans.iter().copied().fold(0.0, f32::min);
    let past = leans.iter().copied().fold(0.0, f32::max);
    assert!(back < -0.01 * 0.3, "the tips lag against the acceleration (+X): {back}");
    assert!(past > 0.0, "and swing past afterwards: {past}");
    let first_back = leans.iter().position(|l| *l < back * 0.5).unwrap();
    assert!((10..16).contains(&first_back), "the lag shows within a few steps of the start: {first_back}");
    // Damping ratio 0.3 at 2 Hz: the envelope falls by e^(-0.3 * 2 pi * 2 * t), to 1% in 1.2 s.
    // Stated: within 45 steps (1.5 s) of the start the force is below 1% of its peak.
    let peak = forces.iter().map(|f| f.abs()).fold(0.0, f32::max);
    assert!(forces[10 + 45..].iter().all(|f| f.abs() < 0.01 * peak), "settled: {:?}", &forces[10 + 45..]);
    // The pose follows: within 45 steps the lean is below 2% of the largest lag, within 90
    // below 0.1% (a small force bends relatively more than a large one, so it trails the force).
    assert!(leans[10 + 45..].iter().all(|l| l.abs() < 0.02 * back.abs()), "{back}: {:?}", &leans[10 + 45..]);
    assert!(leans[10 + 90..].iter().all(|l| l.abs() < 0.001 * back.abs()), "{back}: {:?}", &leans[10 + 90..]);
}

#[test]
fn a_teleport_does_not_fling_the_fur() {
    let fur = grow(Builtin::Torus, 8, 0.3);
    let (_, radius) = fur.mesh.bounding_sphere();
    let params = SimParams { inertia: 1.0, ..still() };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    for n in 1..=5 {
        sim.advance_to(f64::from(n) / 30.0);
    }
    let far = Vec3::new(10.0 * radius, 0.0, 0.0);
    move_base(&mut sim, &fur, far);
    sim.advance_to(6.0 / 30.0);
    assert!(sim.inertial_forces().iter().all(|f| *f == Vec3::ZERO));
    assert_eq!(sim.inertia().teleports(), 1);
    let mut arrived = vec![Vec3::ZERO; fur.positions.len()];
    sim.write_lerp(1.0, &mut arrived);
    for (now, rest) in arrived.iter().zip(&fur.positions) {
        assert!(now.distance(*rest + far) < 1e-4, "the fur arrives in its rest pose: {now}");
    }
    // A new animation: the host resets, and the next steps see no jump either.
    sim.reset_motion();
    move_base(&mut sim, &fur, Vec3::ZERO);
    sim.advance_to(7.0 / 30.0);
    sim.advance_to(8.0 / 30.0);
    assert!(sim.inertial_forces().iter().all(|f| *f == Vec3::ZERO));
}

#[test]
fn ten_thousand_animated_steps_stay_finite_and_keep_lengths() {
    let fur = grow(Builtin::Sphere, 8, 0.3);
    let params = SimParams { inertia: 2.0, damping: 0.1, wind: windy(), gravity_strength: 1.0, ..SimParams::default() };
    let mut sim = Simulation::new(&fur, &params).unwrap();
    let mut positions = vec![Vec3::ZERO; fur.positions.len()];
    let mut worst = 0.0f32;
    for n in 1..=10_000_u32 {
        let t = n as f32 / 30.0;
        // A body that bobs, sways and turns, with a jerk every 97 steps.
        let turn = Quat::from_rotation_y((t * 1.3).sin() * 2.0) * Quat::from_rotation_x((t * 0.7).cos() * 0.4);
        let jerk = if n % 97 == 0 { 0.2 } else { 0.0 };
        let offset = Vec3::new((t * 2.1).sin() * 0.8 + jerk, (t * 5.0).sin().abs() * 0.3, (t * 0.9).cos());
        let roots: Vec<Vec3> = fur.mesh.positions.iter().map(|p| turn * *p + offset).collect();
        sim.set_base_rotations(&roots, &vec![turn; roots.len()]).unwrap();
        sim.advance_to(f64::from(n) / 30.0);
        if n % 500 == 0 || n == 10_000 {
            sim.write_lerp(1.0, &mut positions);
            assert!(positions.iter().all(|p| p.is_finite()), "step {n}");
            worst = worst.max(worst_length_error(&fur, &positions));
        }
    }
    assert!(sim.inertial_forces().iter().any(|f| f.length() > 0.1), "the motion did make inertial forces");
    assert!(worst < 1e-4, "segment lengths drift by {worst}");
}
