//! `FurStepper`: what moves the base (a clip, a script's motion, a host's pose), when the
//! simulation restarts, and that a stepped fur equals the simulation stepped by hand.

use std::path::Path;

use glam::{Mat4, Quat, Vec3};
use pelt_core::sim::{FurStepper, Scene, SimParams, Simulation};
use pelt_core::{Builtin, FurStructure, ImportOptions, Preset, Stage, StageSource};

fn fur(builtin: Builtin) -> FurStructure {
    let (mesh, _) = builtin.mesh();
    let preset = Preset::default();
    FurStructure::new(mesh.clone(), &preset.fur_params(&mesh)).expect("fur")
}

fn fox() -> (FurStructure, pelt_core::anim::Rig) {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes/Fox.glb");
    let stage = Stage::load(&StageSource::File(path), &[], &ImportOptions::default()).expect("Fox.glb");
    let preset = Preset::default();
    let structure = FurStructure::new(stage.fur_mesh.clone(), &preset.fur_params(&stage.fur_mesh)).expect("fur");
    (structure, stage.rig.expect("the Fox is rigged"))
}

#[test]
fn a_still_fur_steps_as_its_simulation_does_and_reports_no_pose() {
    let structure = fur(Builtin::Bunny);
    let mut stepper = FurStepper::new(&structure, &SimParams::default()).expect("stepper");
    let mut simulation = Simulation::new(&structure, &SimParams::default()).expect("simulation");
    assert!(!stepper.moves());
    for frame in 1..=20 {
        let time_secs = f64::from(frame) / 24.0;
        stepper.advance_to(time_secs).expect("advance");
        simulation.advance_to(time_secs);
        assert!(stepper.moved_pose().is_none(), "nothing moves the base");
        assert_eq!(stepper.simulation().positions(), simulation.positions(), "frame {frame}");
    }
    assert_eq!(stepper.world_from_model(), Mat4::IDENTITY);
}

#[test]
fn a_clip_poses_the_base_every_step_and_a_new_clip_restarts_from_its_first_pose() {
    let (structure, rig) = fox();
    let mut stepper = FurStepper::new(&structure, &SimParams::default()).expect("stepper");
    stepper.set_clip(rig, Some(0));
    assert!(stepper.moves());
    stepper.advance_to(0.1).expect("advance");
    let first = stepper.moved_pose().expect("posed").positions.clone();
    assert_eq!(stepper.simulation().roots(), &first[..], "the roots are the pose's");
    stepper.advance_to(0.4).expect("advance");
    assert_ne!(stepper.simulation().roots(), &first[..], "the clip moves the roots");
    // A restart leaves no inertia behind: the first pose of another clip starts at rest.
    stepper.change_clip(Some(1));
    stepper.advance_to(0.5).expect("advance");
    assert!(stepper.simulation().inertial_forces().iter().all(|f| *f == Vec3::ZERO), "restarted at rest");
    stepper.clear_clip();
    stepper.advance_to(0.6).expect("advance");
    assert!(stepper.moved_pose().is_none(), "without a clip nothing poses the base");
}

#[test]
fn a_script_moves_the_base_rigidly_and_plays_its_wind() {
    let structure = fur(Builtin::Sphere);
    let script = r#"
        [[wind]]
        time_secs = 0.0
        direction = [0.0, 0.0, 1.0]
        strength = 1.5

        [[motion]]
        time_secs = 0.0

        [[motion]]
        time_secs = 1.0
        translation = [2.0, 0.0, 0.0]
        rotation_deg = [0.0, 90.0, 0.0]
    "#;
    let mut stepper = FurStepper::new(&structure, &SimParams::default()).expect("stepper");
    stepper.set_scene(Some(Scene::from_toml_str(script, Path::new("script.toml")).expect("script")));
    assert!(stepper.moves());
    stepper.advance_to(1.0).expect("advance");
    let expected =
        Mat4::from_rotation_translation(Quat::from_rotation_y(90_f32.to_radians()), Vec3::new(2.0, 0.0, 0.0));
    assert!(stepper.world_from_model().abs_diff_eq(expected, 1e-5), "{}", stepper.world_from_model());
    let pose = stepper.moved_pose().expect("the motion poses the base");
    for (posed, rest) in pose.positions.iter().zip(&structure.mesh.positions) {
        assert!(posed.distance(expected.transform_point3(*rest)) < 1e-4);
    }
    assert_eq!(stepper.simulation().params().wind.strength, 1.5, "the script's wind plays");
}

#[test]
fn a_host_pose_moves_the_roots_and_bad_poses_are_errors() {
    let structure = fur(Builtin::Box);
    let v = structure.vertex_count();
    let mut stepper = FurStepper::new(&structure, &SimParams::default()).expect("stepper");
    let turn = Quat::from_rotation_x(0.5);
    let positions: Vec<Vec3> = structure.mesh.positions.iter().map(|p| turn * *p + Vec3::Y).collect();
    let normals: Vec<Vec3> = structure.mesh.normals.iter().map(|n| turn * *n).collect();
    stepper.set_pose(&positions, &normals, &vec![turn; v]).expect("pose");
    stepper.advance_to(0.2).expect("advance");
    assert_eq!(stepper.simulation().roots(), &positions[..]);
    assert_eq!(stepper.moved_pose().expect("posed").normals, normals);
    stepper.advance_to(0.3).expect("advance");
    assert!(stepper.moved_pose().is_none(), "no new pose this step");
    assert!(stepper.set_pose(&positions[1..], &normals[1..], &vec![turn; v - 1]).is_err(), "wrong count");
    let mut bad = positions.clone();
    bad[0] = Vec3::NAN;
    assert!(stepper.set_pose(&bad, &normals, &vec![turn; v]).is_err(), "NaN");
}

#[test]
fn the_stage_loads_files_built_ins_and_the_try_on_and_names_unknown_built_ins() {
    let tryon = Stage::load(&StageSource::TryOn, &[], &ImportOptions::default()).expect("try-on");
    assert_eq!(tryon.plain.len(), 1, "the body is drawn plain");
    // The skirt follows the body's walk: its own rig, the body's clip, and the body's rig beside it.
    let rig = tryon.rig.as_ref().expect("the try-on skirt is skinned");
    assert_eq!(rig.vertex_count(), tryon.fur_mesh.vertex_count());
    let body = tryon.body.as_ref().expect("the try-on body walks");
    assert_eq!(body.rig.vertex_count(), tryon.plain[0].vertex_count());
    assert_eq!(rig.animations(), body.rig.animations());
    assert!(!rig.animations().is_empty());
    let bunny = Stage::load(&StageSource::builtin("bunny").expect("bunny"), &[], &ImportOptions::default());
    assert!(bunny.expect("bunny").plain.is_empty());
    let error = StageSource::builtin("dragon").unwrap_err().to_string();
    assert!(error.contains("dragon") && error.contains("tryon") && error.contains("torus"), "{error}");
    let missing = Stage::load(&StageSource::File("no/such.obj".into()), &[], &ImportOptions::default());
    assert!(missing.unwrap_err().to_string().contains("no/such.obj"));
}
