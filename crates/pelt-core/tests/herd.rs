//! Herds: every member stepped in one parallel pass ends as the same fur stepped alone with its
//! inputs, to the bit; each stands where its heading and speed put it and plays its own phase;
//! bad `[[instance]]` tables are errors naming the file and key.

use std::path::Path;

use glam::{Mat4, Quat, Vec3};
use pelt_core::sim::herd;
use pelt_core::sim::{FurStepper, Scene, SimParams};
use pelt_core::{FurStructure, ImportOptions, Preset, Stage, StageSource};

fn fox() -> (FurStructure, pelt_core::anim::Rig) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes/Fox.glb");
    let stage = Stage::load(&StageSource::File(path), &[], &ImportOptions::default()).expect("Fox.glb");
    let preset = Preset::default();
    let structure = FurStructure::new(stage.fur_mesh.clone(), &preset.fur_params(&stage.fur_mesh)).expect("fur");
    (structure, stage.rig.expect("the Fox is rigged"))
}

const WINDY: &str = "
[[wind]]
time_secs = 0.0
direction = [1.0, 0.0, 0.3]
strength = 0.6

[[instance]]
position = [0.0, 0.0, 0.0]
clip = \"Walk\"

[[instance]]
position = [300.0, 0.0, -40.0]
heading_deg = 90.0
speed = 60.0
clip = \"Walk\"
time_offset_secs = 0.3

[[instance]]
position = [-250.0, 0.0, 120.0]
heading_deg = -35.0
speed = 150.0
clip = \"Run\"
time_offset_secs = 0.7
";

fn stepper(structure: &FurStructure, rig: &pelt_core::anim::Rig, scene: &Scene, k: usize) -> FurStepper {
    let instance = &scene.instance[k];
    let clips = herd::resolve_clips(&scene.instance, Some(rig), Some(0)).expect("clips");
    let mut stepper = FurStepper::new(structure, &SimParams::default()).expect("stepper");
    stepper.set_clip(rig.clone(), clips[k]);
    stepper.set_scene(Some(scene.clone()));
    stepper.set_placement(Some(instance.clone()));
    stepper
}

#[test]
fn each_member_of_a_herd_steps_as_it_would_alone_to_the_bit() {
    let (structure, rig) = fox();
    let scene = Scene::from_toml_str(WINDY, Path::new("herd.toml")).expect("scene");
    let count = scene.instance.len();
    let mut herd: Vec<FurStepper> = (0..count).map(|k| stepper(&structure, &rig, &scene, k)).collect();
    let mut alone: Vec<FurStepper> = (0..count).map(|k| stepper(&structure, &rig, &scene, k)).collect();
    for frame in 0..24 {
        let time_secs = f64::from(frame) / 30.0;
        FurStepper::advance_herd(&mut herd, &scene.instance, time_secs).expect("herd step");
        for (k, stepper) in alone.iter_mut().enumerate() {
            stepper.advance_with_clip_at(time_secs, time_secs + scene.instance[k].time_offset_secs).expect("step");
        }
        for k in 0..count {
            assert_eq!(
                herd[k].simulation().positions(),
                alone[k].simulation().positions(),
                "instance {k}, frame {frame}"
            );
        }
    }
    // The members differ: their own place, clip and phase.
    assert_ne!(herd[0].simulation().positions(), herd[1].simulation().positions());
}

#[test]
fn a_member_stands_where_its_heading_and_speed_take_it_in_its_own_phase() {
    let (structure, rig) = fox();
    let scene = Scene::from_toml_str(WINDY, Path::new("herd.toml")).expect("scene");
    let k = 2;
    let instance = &scene.instance[k];
    let mut placed = stepper(&structure, &rig, &scene, k);
    let time_secs = 0.5;
    FurStepper::advance_herd(std::slice::from_mut(&mut placed), std::slice::from_ref(instance), time_secs)
        .expect("step");
    // By hand: the Run clip 0.7 s ahead, turned -35 degrees about +Y, carried 150 * 0.5 along the
    // turned +Z.
    let clip = rig.find_animation("Run").unwrap();
    let mut pose = pelt_core::anim::Pose::default();
    rig.pose(&structure.mesh, Some(clip), time_secs + 0.7, &mut pose);
    let angle = (-35.0f32).to_radians();
    let ahead = Vec3::new(angle.sin(), 0.0, angle.cos());
    let world = Mat4::from_translation(Vec3::new(-250.0, 0.0, 120.0) + ahead * 75.0)
        * Mat4::from_quat(Quat::from_rotation_y(angle));
    // Within 1e-5 of the farthest point's distance from the origin (f32 rounding of the sums).
    let reach = pose.positions.iter().map(|p| world.transform_point3(*p).length()).fold(0.0f32, f32::max);
    for (root, p) in placed.simulation().roots().iter().zip(&pose.positions) {
        assert!((*root - world.transform_point3(*p)).length() < 1e-5 * reach, "{root} against {p}");
    }
    // Another phase is another pose.
    let mut other = pelt_core::anim::Pose::default();
    rig.pose(&structure.mesh, Some(clip), time_secs, &mut other);
    assert_ne!(pose.positions, other.positions);
}

#[test]
fn bad_instances_name_the_file_and_key() {
    let nan = "[[instance]]\nposition = [0.0, nan, 0.0]\n";
    let error = Scene::from_toml_str(nan, Path::new("herd.toml")).unwrap_err().to_string();
    assert!(error.contains("herd.toml") && error.contains("instance[0].position"), "{error}");
    let unknown =
        "[[instance]]\nposition = [0.0, 0.0, 0.0]\n\n[[instance]]\nposition = [1.0, 0.0, 0.0]\nclip = \"Gallop\"\n";
    let scene = Scene::from_toml_str(unknown, Path::new("herd.toml")).expect("parsed: clips resolve against a rig");
    let (_, rig) = fox();
    let (key, problem) = herd::resolve_clips(&scene.instance, Some(&rig), None).unwrap_err();
    assert_eq!(key, "instance[1].clip");
    // The file's clips, listed.
    assert!(problem.contains("Gallop") && problem.contains("Survey") && problem.contains("Walk"), "{problem}");
    let misspelt = "[[instance]]\nposition = [0.0, 0.0, 0.0]\nheading = 3.0\n";
    let error = Scene::from_toml_str(misspelt, Path::new("herd.toml")).unwrap_err().to_string();
    assert!(error.contains("heading"), "{error}");
    for (line, key) in [
        ("tint = [1.0, nan, 1.0]", "instance[0].tint"),
        ("tint = [1.0, -0.5, 1.0]", "instance[0].tint"),
        ("length_scale = 0.0", "instance[0].length_scale"),
        ("length_scale = 50.0", "instance[0].length_scale"),
    ] {
        let bad = format!("[[instance]]\nposition = [0.0, 0.0, 0.0]\n{line}\n");
        let error = Scene::from_toml_str(&bad, Path::new("herd.toml")).unwrap_err().to_string();
        assert!(error.contains("herd.toml") && error.contains(key), "{line}: {error}");
    }
}

/// A member's `length_scale` grows its strands that much longer from the same roots, along the
/// same strands: every segment scaled, the topology and roots kept.
#[test]
fn a_members_length_scale_lengthens_every_segment_from_its_root() {
    let (structure, _) = fox();
    let scaled = structure.with_length_scale(1.5);
    let v = structure.mesh.vertex_count();
    assert_eq!(scaled.positions.len(), structure.positions.len());
    assert_eq!(&scaled.positions[..v], &structure.positions[..v], "the roots stay");
    for (k, (a, b)) in structure.positions.iter().zip(&scaled.positions).enumerate().skip(v) {
        let (below, below_scaled) = (structure.positions[k - v], scaled.positions[k - v]);
        let (segment, segment_scaled) = (*a - below, *b - below_scaled);
        assert!((segment_scaled - 1.5 * segment).length() <= 1e-4 * segment.length().max(1.0), "node {k}");
    }
    assert!(structure.lengths.iter().zip(&scaled.lengths).all(|(a, b)| (b - 1.5 * a).abs() <= 1e-5 * a.max(1.0)));
    // A member stepped with it keeps its longer strands.
    let mut stepper = FurStepper::new(&scaled, &SimParams::default()).expect("stepper");
    stepper.advance_to(0.5).expect("step");
    let shown = stepper.simulation().positions();
    for j in (0..v).step_by(11) {
        let rest = scaled.positions[v + j].distance(scaled.positions[j]);
        assert!((shown[v + j].distance(shown[j]) - rest).abs() < 1e-3 * rest, "vertex {j}");
    }
}

/// A walking Fox in wind stepped at every `stride`-th step, with `params`, shown at frames of
/// 90 per second: its positions at each frame.
fn strided_walk(params: &SimParams, stride: u32, frames: u32) -> (Vec<Vec<Vec3>>, u64) {
    let (structure, rig) = fox();
    let scene = Scene::from_toml_str(WINDY, Path::new("herd.toml")).expect("scene");
    let mut stepper = FurStepper::new(&structure, params).expect("stepper");
    stepper.set_clip(rig, Some(0));
    stepper.set_scene(Some(scene));
    stepper.set_step_stride(stride);
    let shown = (0..frames)
        .map(|f| {
            stepper.advance_to(f64::from(f) / 90.0).expect("step");
            stepper.simulation().positions().to_vec()
        })
        .collect();
    (shown, stepper.simulation().steps_taken())
}

/// Without inertia a step's state depends only on its time, so a fur stepped every second step
/// shows the full rate's states, one full-rate step later (each shown state is the previous one
/// at its step's time), and halfway between them halfway between two of them.
#[test]
fn a_far_member_stepped_every_second_step_shows_the_full_rates_states() {
    let params = SimParams { inertia: 0.0, ..SimParams::default() };
    // 90 frames a second at 30 steps a second: a full step every 3 frames, a strided one every 6.
    let (full, full_steps) = strided_walk(&params, 1, 60);
    let (strided, strided_steps) = strided_walk(&params, 2, 60);
    assert!(strided_steps * 10 < full_steps * 6, "steps taken: {strided_steps} strided, {full_steps} full");
    // Frame 6m shows state 2m - 2 (strided) and frame 6m - 3 shows it too (full rate).
    for m in 2..10 {
        assert_eq!(strided[6 * m], full[6 * m - 3], "frame {}: the strided state", 6 * m);
        // Frame 6m + 3 is halfway from state 2m - 2 to 2m.
        for (k, p) in strided[6 * m + 3].iter().enumerate() {
            let halfway = 0.5 * (full[6 * m - 3][k] + full[6 * m + 3][k]);
            assert!(p.distance(halfway) < 1e-3, "frame {} node {k}: {p} against {halfway}", 6 * m + 3);
        }
    }
}

/// Strides changed while the Fox walks with inertia: every position finite, and every root
/// segment its rest length in the states shown whole (frames on a step of every stride; between
/// them the interpolation shortens strands a little, as at the full rate).
#[test]
fn changing_a_members_stride_keeps_its_strands_whole() {
    let (structure, rig) = fox();
    let scene = Scene::from_toml_str(WINDY, Path::new("herd.toml")).expect("scene");
    let mut stepper = FurStepper::new(&structure, &SimParams::default()).expect("stepper");
    stepper.set_clip(rig, Some(0));
    stepper.set_scene(Some(scene));
    let v = structure.mesh.vertex_count();
    for f in 0..120u32 {
        stepper.set_step_stride([1, 4, 2, 1][(f / 30) as usize]);
        stepper.advance_to(f64::from(f) / 30.0).expect("step");
        let positions = stepper.simulation().positions();
        assert!(positions.iter().all(|p| p.is_finite()), "frame {f}: a position is not finite");
        if f % 4 != 0 {
            continue;
        }
        for j in (0..v).step_by(7) {
            let rest = structure.positions[v + j].distance(structure.positions[j]);
            let shown = positions[v + j].distance(positions[j]);
            assert!(
                (shown - rest).abs() < 1e-3 * rest.max(1e-3) + 1e-4,
                "frame {f} vertex {j}: {shown} against {rest}"
            );
        }
    }
}

/// A member whose strands bend elsewhere leaves its skinning to the host: each advance poses its
/// joints only (placed in the world) and the simulation takes the move unseen; as soon as the CPU
/// reads the pose (its own bending, a collider) the CPU poses the vertices again.
#[test]
fn joint_posing_leaves_the_vertices_to_the_host_while_nothing_reads_them() {
    let (structure, rig) = fox();
    let walk = rig.find_animation("Walk").expect("a Walk clip");
    let instance = pelt_core::sim::HerdInstance {
        heading_deg: 30.0,
        speed: 40.0,
        time_offset_secs: 0.2,
        ..pelt_core::sim::HerdInstance::at(Vec3::new(100.0, 0.0, -50.0))
    };
    let mut stepper = FurStepper::new(&structure, &SimParams::default()).expect("stepper");
    stepper.set_clip(rig.clone(), Some(walk));
    stepper.set_placement(Some(instance.clone()));
    stepper.set_joint_posing(true);
    // Bending on the CPU reads the roots: the CPU poses.
    stepper.advance_to(0.05).expect("advance");
    assert!(stepper.posed_joints().is_none() && stepper.moved_pose().is_some());
    stepper.simulation_mut().set_cpu_bending(false);
    let base = stepper.simulation().input_versions().base;
    let time_secs = 0.1;
    stepper.advance_with_clip_at(time_secs, instance.clip_time(time_secs)).expect("advance");
    let joints = stepper.posed_joints().expect("the joints alone are posed");
    assert!(stepper.moved_pose().is_none(), "no vertices posed on the CPU");
    assert!(stepper.simulation().base_posed_elsewhere());
    assert_eq!(stepper.simulation().input_versions().base, base + 1, "the move counts for the kernel that bends");
    let mut pose = pelt_core::anim::Pose::default();
    rig.pose_joints(Some(walk), instance.clip_time(time_secs), &mut pose);
    let placed: Vec<Mat4> =
        rig.joint_matrices(&pose).iter().map(|m| instance.world_from_model(time_secs) * *m).collect();
    assert_eq!(joints, &placed[..]);
    // A collider reads the roots: the CPU poses again, and says so.
    let ball = pelt_core::sim::Collider::at(
        7,
        pelt_core::sim::Shape::Sphere { radius: 5.0 },
        0.0,
        Vec3::new(0.0, 1e4, 0.0),
        Quat::IDENTITY,
    );
    stepper.simulation_mut().set_colliders(&[ball]).expect("collider");
    stepper.advance_to(0.15).expect("advance");
    assert!(stepper.posed_joints().is_none() && stepper.moved_pose().is_some());
    assert!(!stepper.simulation().base_posed_elsewhere());
}
