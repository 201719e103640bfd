//! GPU skinning against pelt-core's CPU skinning: the walking Fox posed at three clip times in
//! one dispatch, every vertex within 1e-5 of the mesh's size of `pelt_core::anim::Rig::pose`, its
//! normal within 1e-4 and its frame's rotation within 1e-3.

use glam::{Mat4, Vec3};
use pelt_core::anim::Pose;
use pelt_core::{ImportOptions, Mesh};
use pelt_render::{GpuSkin, RenderError};

use crate::common::{asset, gpu, read_bytes};

/// The posed sections (positions, normals, rotations) of every instance after one dispatch.
fn read_posed(gpu: &pelt_render::Gpu, skin: &GpuSkin) -> Vec<[f32; 4]> {
    let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
    skin.record(&mut encoder);
    gpu.queue.submit([encoder.finish()]);
    read_bytes(&gpu.device, &gpu.queue, skin.posed().slice(..))
        .chunks_exact(16)
        .map(|c| std::array::from_fn(|k| f32::from_le_bytes([c[4 * k], c[4 * k + 1], c[4 * k + 2], c[4 * k + 3]])))
        .collect()
}

#[test]
fn gpu_skinning_agrees_with_pelt_core_for_every_instance_in_one_dispatch() {
    let (mesh, _, rig) = Mesh::load_animated(&asset("Fox.glb"), &ImportOptions::default()).expect("the Fox");
    let rig = rig.expect("the Fox is rigged");
    let walk = rig.find_animation("Walk").expect("a Walk clip");
    let gpu = gpu();
    let times = [0.0, 0.37, 0.81];
    let skin = GpuSkin::new(
        &gpu.device,
        (&mesh.positions, &mesh.normals),
        &rig.vertex_influences(),
        rig.joint_count(),
        times.len(),
    )
    .expect("GPU skin");
    let mut poses = Vec::new();
    for (instance, &time) in times.iter().enumerate() {
        // The GPU's joints from the clip alone (`pose_joints`), the oracle's vertices from `pose`.
        let mut joints = Pose::default();
        rig.pose_joints(Some(walk), time, &mut joints);
        skin.set_joints(&gpu.queue, instance, &rig.joint_matrices(&joints)).expect("joints");
        let mut pose = Pose::default();
        rig.pose(&mesh, Some(walk), time, &mut pose);
        poses.push(pose);
    }
    let posed = read_posed(&gpu, &skin);
    let v = mesh.vertex_count();
    assert_eq!(posed.len(), 3 * v * times.len());
    let size = mesh.bounding_sphere().1 * 2.0;
    let mut worst = (0.0f32, 0.0f32, 0.0f32);
    for (instance, pose) in poses.iter().enumerate() {
        for j in 0..v {
            let p = posed[3 * instance * v + j];
            let n = posed[3 * instance * v + v + j];
            // q and -q are one rotation. `Quat::from_rotation_arc` (the correction that takes the
            // turned rest normal onto the posed one) is the identity below about 7e-4 radians,
            // so normals a float apart may differ there by that turn: 3.5e-4 in the quaternion.
            let q = glam::Vec4::from(posed[3 * instance * v + 2 * v + j]);
            let cpu = glam::Vec4::from(pose.rotations[j]);
            let rotation_error = (q - cpu).length().min((q + cpu).length());
            assert!(rotation_error <= 1e-3, "instance {instance} vertex {j}: rotation {q} against {cpu}");
            let position_error = (Vec3::new(p[0], p[1], p[2]) - pose.positions[j]).length() / size;
            let normal_error = (Vec3::new(n[0], n[1], n[2]) - pose.normals[j]).length();
            assert!(
                position_error <= 1e-5,
                "instance {instance} vertex {j}: {p:?} on the GPU, {} on the CPU",
                pose.positions[j]
            );
            assert!(normal_error <= 1e-4, "instance {instance} vertex {j}: normal {n:?} against {}", pose.normals[j]);
            worst = (worst.0.max(position_error), worst.1.max(normal_error), worst.2.max(rotation_error));
        }
    }
    // The clip moves the Fox: the instances' poses differ, so each read its own matrices.
    let moved = (0..v).filter(|&j| (poses[1].positions[j] - poses[2].positions[j]).length() > 1e-3 * size).count();
    assert!(moved > v / 4, "{moved} of {v} vertices moved between the two times");
    println!("worst position error {:e} of the Fox's size, normal {:e}, rotation {:e}", worst.0, worst.1, worst.2);
}

#[test]
fn gpu_skinning_refuses_bad_input() {
    let gpu = gpu();
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y];
    let normals = [Vec3::Z; 3];
    let influences = [([0, 0, 0, 0], [1.0, 0.0, 0.0, 0.0]); 3];
    let made = |influences: &[([u32; 4], [f32; 4])], joints| {
        GpuSkin::new(&gpu.device, (&positions, &normals), influences, joints, 2)
    };
    let past = [([0, 0, 0, 0], [1.0, 0.0, 0.0, 0.0]), ([3, 0, 0, 0], [1.0, 0.0, 0.0, 0.0]), influences[0]];
    assert!(matches!(made(&past, 2), Err(RenderError::Target(m)) if m.contains("vertex 1") && m.contains("joint 3")));
    let nan = [influences[0], influences[0], ([0, 0, 0, 0], [f32::NAN, 0.0, 0.0, 0.0])];
    assert!(matches!(made(&nan, 1), Err(RenderError::Target(m)) if m.contains("vertex 2")));
    assert!(matches!(made(&influences[..2], 1), Err(RenderError::Count { .. })));
    let skin = made(&influences, 1).expect("a valid skin");
    assert!(matches!(skin.set_joints(&gpu.queue, 2, &[Mat4::IDENTITY]), Err(RenderError::Count { .. })));
    assert!(matches!(skin.set_joints(&gpu.queue, 0, &[Mat4::IDENTITY; 2]), Err(RenderError::Count { .. })));
    let broken = Mat4::from_translation(Vec3::new(f32::INFINITY, 0.0, 0.0));
    assert!(matches!(skin.set_joints(&gpu.queue, 1, &[broken]), Err(RenderError::Target(m)) if m.contains("joint 0")));
}
