//! A herd's steps on the GPU kernel: the copies made together step in one dispatch (two with
//! contact) with the bytes each copy's own dispatches give, and a herd posed on the GPU bends as
//! one posed on the CPU. Fails, never skips, without an adapter.

use crate::common;

use common::{BROWN_ROOT, BROWN_TIP, Rig, builtin_fur, strand_textures};
use glam::Vec3;
use pelt_core::Builtin;
use pelt_render::{FurAsset, FurDriver, KernelChoice};

use crate::herd::is_gpu;

/// Records each member of `alone` on its own and `together` as one herd; the dispatches each
/// member alone recorded, and the herd's.
fn record_each_and_together<S>(
    encoder: &mut wgpu::CommandEncoder,
    alone: &mut [(FurDriver, S)],
    together: &mut [(FurDriver, S)],
) -> (Vec<usize>, usize) {
    let each =
        alone.iter_mut().map(|(driver, _)| FurDriver::record_herd(encoder, [driver]).expect("record alone")).collect();
    let recorded = FurDriver::record_herd(encoder, together.iter_mut().map(|(driver, _)| driver)).expect("herd");
    (each, recorded)
}

/// A herd made together on the GPU kernel steps every member in one dispatch a step: the states
/// come out with the bytes each member's own dispatches give, each member bent its own way.
#[test]
fn a_herds_gpu_steps_take_one_dispatch_and_match_each_recorded_alone() {
    let mut rig = Rig::new(64, 64);
    let gpu = is_gpu(&rig);
    assert_eq!(rig.renderer.pooled_stepping(), gpu, "a GPU pools the steps, a CPU rasteriser steps each alone");
    rig.renderer.set_pooled_stepping(true);
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let asset = FurAsset::new(rig.device(), rig.queue(), &rig.renderer, &structure, &textures).expect("asset");
    let (device, queue) = (rig.device(), rig.queue());
    const MEMBERS: usize = 4;
    // Gravity pulls each member along its own direction; member 1 is posed (its roots and frames
    // turned), member 2 is wet (heavier), member 3 steps every other frame only.
    let params = |k: usize| pelt_core::sim::SimParams {
        gravity_direction: Vec3::new(k as f32 - 1.0, -1.0, 0.5 * k as f32).normalize(),
        ..pelt_core::sim::SimParams::default()
    };
    let turn = glam::Quat::from_rotation_z(0.7);
    let stepper = |k: usize| {
        let mut stepper = pelt_core::sim::FurStepper::new(&structure, &params(k)).expect("stepper");
        if k == 1 {
            let mesh = &structure.mesh;
            let positions: Vec<Vec3> = mesh.positions.iter().map(|&p| turn * p + Vec3::X * 0.1).collect();
            let normals: Vec<Vec3> = mesh.normals.iter().map(|&n| turn * n).collect();
            stepper.set_pose(&positions, &normals, &vec![turn; positions.len()]).expect("pose");
        }
        if k == 2 {
            let wet = pelt_core::wet::WetParams { wetness: 0.6, added_weight: 3.0, ..Default::default() };
            stepper.set_wet(&wet).expect("wet");
        }
        stepper
    };
    let made_together = FurDriver::herd_with_asset(
        device,
        queue,
        &rig.renderer,
        (&asset, &structure),
        &params(0),
        KernelChoice::Gpu,
        MEMBERS,
    )
    .expect("herd");
    let mut together: Vec<_> = made_together.into_iter().enumerate().map(|(k, driver)| (driver, stepper(k))).collect();
    let mut alone: Vec<_> = (0..MEMBERS)
        .map(|k| {
            let driver =
                FurDriver::with_asset(device, queue, &rig.renderer, &asset, &structure, &params(k), KernelChoice::Gpu)
                    .expect("driver");
            (driver, stepper(k))
        })
        .collect();
    let mut dispatches = Vec::new();
    for frame in 1..=6 {
        let time_secs = f64::from(frame) / 20.0;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        for herd in [&mut alone, &mut together] {
            for (k, (driver, stepper)) in herd.iter_mut().enumerate() {
                if k != 3 || frame % 2 == 0 {
                    driver.advance_to(device, queue, stepper, time_secs).expect("advance");
                }
            }
        }
        dispatches.push(record_each_and_together(&mut encoder, &mut alone, &mut together));
        queue.submit([encoder.finish()]);
    }
    let state = |driver: &FurDriver| common::read_bytes(device, queue, driver.fur().current_positions());
    for k in 0..MEMBERS {
        assert_eq!(state(&alone[k].0), state(&together[k].0), "member {k}'s state stepped with the herd");
    }
    for k in 1..MEMBERS {
        assert_ne!(state(&together[0].0), state(&together[k].0), "members 0 and {k} bent alike");
    }
    // A step of the herd is one dispatch, where each member alone dispatches each of its own.
    for (frame, (each, recorded)) in (1..).zip(&dispatches) {
        let stepped = |k: usize| k != 3 || frame % 2 == 0;
        for (k, &d) in each.iter().enumerate() {
            assert_eq!(d > 0, stepped(k), "member {k}'s own dispatches, frame {frame}: {dispatches:?}");
        }
        assert_eq!(
            *recorded,
            *each.iter().max().expect("members"),
            "the herd's dispatches, frame {frame}: {dispatches:?}"
        );
    }
}

/// Steps with contact pool too: a herd made together whose members each meet their own
/// colliders (a ball; a capsule and a box joined by ten balls mid-run, so the slots' room grows
/// after the grasp's hand grew it and the members before have written their slots;
/// a mesh collider's distance field; a grasp; the skin alone), one stepping every other frame,
/// takes two dispatches a step for all of them and comes out with the bytes each member's own
/// dispatches give.
#[test]
fn a_herds_gpu_steps_with_contact_take_two_dispatches_and_match_each_recorded_alone() {
    use glam::Quat;
    use pelt_core::mesh::{ImportOptions, Mesh};
    use pelt_core::sim::{Collider, ColliderMesh, ContactParams, GraspParams, Shape};
    let mut rig = Rig::new(64, 64);
    rig.renderer.set_pooled_stepping(true);
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let asset = FurAsset::new(rig.device(), rig.queue(), &rig.renderer, &structure, &textures).expect("asset");
    let (device, queue) = (rig.device(), rig.queue());
    const MEMBERS: usize = 5;
    let params = pelt_core::sim::SimParams { contact: ContactParams { skin: true }, ..Default::default() };
    let v = structure.vertex_count();
    let radius = structure.mesh.bounding_sphere().1;
    let length = structure.lengths[0];
    // Each member's colliders sit over a strand of its own, `out` strand lengths out along it
    // and `clear` further (a collider's size, so its surface reaches into the fur).
    let over = |j: usize, out: f32, clear: f32| {
        let root = structure.positions[j];
        root + (structure.positions[v + j] - root).normalize() * (out * length + clear)
    };
    let file = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/meshes/pebble.obj");
    let (mesh, _) = Mesh::load(&file, &ImportOptions::default()).expect("the pebble");
    let pebble = std::sync::Arc::new(ColliderMesh::new(mesh, 16).expect("a closed pebble"));
    let colliders = |k: usize, frame: u32, t: f64| -> Vec<Collider> {
        let sway = Vec3::X * (0.1 * (t * 5.0).sin()) as f32 * radius;
        match k {
            0 => vec![Collider::at(
                1,
                Shape::Sphere { radius: 0.1 * radius },
                t,
                over(10, 0.4, 0.1 * radius) + sway,
                Quat::IDENTITY,
            )],
            1 => {
                let mut c = vec![
                    Collider::at(
                        1,
                        Shape::Capsule { radius: 0.03 * radius, half_length: 0.2 * radius },
                        t,
                        over(200, 0.5, 0.03 * radius) + sway,
                        Quat::from_rotation_x(1.5),
                    ),
                    Collider::at(
                        2,
                        Shape::Box { half_extents: Vec3::new(0.05, 0.05, 0.15) * radius },
                        t,
                        over(210, 0.4, 0.05 * radius) - sway,
                        Quat::from_rotation_y(0.4),
                    ),
                ];
                if frame > 6 {
                    c.extend((0..10_u32).map(|i| {
                        let centre = over(200 + 7 * i as usize, 0.3, 0.04 * radius);
                        Collider::at(10 + i, Shape::Sphere { radius: 0.04 * radius }, t, centre, Quat::IDENTITY)
                    }));
                }
                c
            }
            2 => vec![Collider::at(
                1,
                Shape::Mesh { mesh: std::sync::Arc::clone(&pebble), scale: 0.12 * radius },
                t,
                over(400, 0.4, 0.08 * radius) + sway,
                Quat::from_rotation_y(t as f32),
            )],
            _ => Vec::new(),
        }
    };
    let made_together = FurDriver::herd_with_asset(
        device,
        queue,
        &rig.renderer,
        (&asset, &structure),
        &params,
        KernelChoice::Gpu,
        MEMBERS,
    )
    .expect("herd");
    let stepper = || pelt_core::sim::FurStepper::new(&structure, &params).expect("stepper");
    let mut together: Vec<_> = made_together.into_iter().map(|driver| (driver, stepper())).collect();
    let mut alone: Vec<_> = (0..MEMBERS)
        .map(|_| {
            let driver =
                FurDriver::with_asset(device, queue, &rig.renderer, &asset, &structure, &params, KernelChoice::Gpu)
                    .expect("driver");
            (driver, stepper())
        })
        .collect();
    let mut dispatches = Vec::new();
    for frame in 1..=10_u32 {
        let time_secs = f64::from(frame) / 20.0;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        for herd in [&mut alone, &mut together] {
            for (k, (driver, stepper)) in herd.iter_mut().enumerate() {
                if k == 4 && frame % 2 == 1 {
                    continue;
                }
                let simulation = stepper.simulation_mut();
                simulation.set_colliders(&colliders(k, frame, time_secs)).expect("colliders");
                if k == 3 {
                    match frame {
                        2 => simulation
                            .grasp_begin(
                                over(300, 0.5, 0.0),
                                2.0 * length,
                                0.2 * length,
                                GraspParams::default(),
                                time_secs,
                            )
                            .expect("grasp"),
                        3..=7 => simulation.grasp_move(over(300, 0.5 + 0.1 * (frame - 2) as f32, 0.0)).expect("grip"),
                        8 => simulation.grasp_end(time_secs),
                        _ => {}
                    }
                }
                driver.advance_to(device, queue, stepper, time_secs).expect("advance");
            }
        }
        dispatches.push(record_each_and_together(&mut encoder, &mut alone, &mut together));
        queue.submit([encoder.finish()]);
    }
    let state = |driver: &FurDriver| common::read_bytes(device, queue, driver.fur().current_positions());
    let rest: Vec<u8> = bytemuck::cast_slice(&structure.positions).to_vec();
    for k in 0..MEMBERS {
        let (a, b) = (state(&alone[k].0), state(&together[k].0));
        assert_ne!(a, rest, "member {k} never moved");
        assert!(a == b, "member {k}'s state stepped with the herd differs from its own");
    }
    for j in 1..MEMBERS {
        assert_ne!(state(&together[0].0), state(&together[j].0), "members 0 and {j} met the same contact");
    }
    // Every member steps with contact: two dispatches a step for the herd, two a step for each
    // member alone.
    for (frame, (each, recorded)) in (1..).zip(&dispatches) {
        assert_eq!(*recorded, *each.iter().max().expect("members"), "frame {frame}: {dispatches:?}");
        assert!(*recorded >= 2, "frame {frame}: {dispatches:?}");
    }
}

/// A walking herd on the GPU kernel posed on the GPU (`HerdPosing`: the CPU poses joints only)
/// bends as when the CPU poses every member: after twelve frames each member's state and base
/// normals lie within 1e-4 of the Fox's size of the CPU-posed herd's, each member at its own
/// place, heading and phase. One member keeps its posing on the CPU inside the GPU-posed herd,
/// and one goes back to the CPU after six frames (with the inertia judging a jump from the roots
/// it last saw, six frames back, its state was 7.6 units off, half a tenth of the Fox).
#[test]
fn a_herd_posed_on_the_gpu_bends_as_posed_on_the_cpu() {
    use pelt_core::sim::{FurStepper, HerdInstance};
    let rig = Rig::new(64, 64);
    assert_eq!(rig.renderer.herd_posing(), is_gpu(&rig), "a GPU poses herds, a CPU rasteriser does not");
    let (mesh, _, fox) =
        pelt_core::Mesh::load_animated(&common::asset("Fox.glb"), &pelt_core::ImportOptions::default())
            .expect("the Fox");
    let fox = fox.expect("the Fox is rigged");
    let walk = fox.find_animation("Walk").expect("a Walk clip");
    let structure = common::grow(mesh, 8, 0.08);
    let size = 2.0 * structure.mesh.bounding_sphere().1;
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let (device, queue) = (rig.device(), rig.queue());
    let asset = FurAsset::new(device, queue, &rig.renderer, &structure, &textures).expect("asset");
    const MEMBERS: usize = 3;
    let instances: Vec<HerdInstance> = (0..MEMBERS)
        .map(|k| HerdInstance {
            heading_deg: 70.0 * k as f32 - 40.0,
            speed: 0.4 * size,
            time_offset_secs: 0.29 * k as f64,
            ..HerdInstance::at(Vec3::new(1.5 * size * k as f32, 0.0, 0.0))
        })
        .collect();
    let params = pelt_core::sim::SimParams::default();
    let herd = |gpu_posing: bool| {
        let drivers = FurDriver::herd_with_asset(
            device,
            queue,
            &rig.renderer,
            (&asset, &structure),
            &params,
            KernelChoice::Gpu,
            MEMBERS,
        )
        .expect("herd");
        let steppers: Vec<FurStepper> = instances
            .iter()
            .enumerate()
            .map(|(k, instance)| {
                let mut stepper = FurStepper::new(&structure, &params).expect("stepper");
                stepper.set_clip(fox.clone(), Some(walk));
                stepper.set_placement(Some(instance.clone()));
                stepper.set_joint_posing(gpu_posing && k != 1);
                stepper
            })
            .collect();
        (drivers, steppers)
    };
    let (mut cpu_drivers, mut cpu_steppers) = herd(false);
    let (mut gpu_drivers, mut gpu_steppers) = herd(true);
    let mut posing = pelt_render::HerdPosing::new(device, &structure.mesh, &fox, MEMBERS).expect("posing");
    for frame in 1..=12 {
        let time_secs = f64::from(frame) / 20.0;
        // From frame 7 member 0 meets a collider (far away): its CPU poses again, and its motion
        // carries on from the poses made on the GPU.
        if frame == 7 {
            let shape = pelt_core::sim::Shape::Sphere { radius: 0.01 };
            let far = pelt_core::sim::Collider::at(9, shape, time_secs, Vec3::splat(1e4), glam::Quat::IDENTITY);
            for steppers in [&mut cpu_steppers, &mut gpu_steppers] {
                steppers[0].simulation_mut().set_colliders(std::slice::from_ref(&far)).expect("far");
            }
        }
        FurDriver::advance_herd((device, queue), &mut cpu_drivers, &mut cpu_steppers, &instances, time_secs)
            .expect("CPU-posed herd");
        FurDriver::advance_herd((device, queue), &mut gpu_drivers, &mut gpu_steppers, &instances, time_secs)
            .expect("GPU-posed herd");
        posing.prepare((device, queue), &gpu_drivers, &gpu_steppers).expect("posing");
        let switched = frame >= 7;
        assert_eq!(posing.members_on_gpu(), MEMBERS - 1 - usize::from(switched), "frame {frame}");
        for (k, stepper) in gpu_steppers.iter().enumerate() {
            let cpu = k == 1 || (k == 0 && switched);
            assert_eq!(stepper.posed_joints().is_some(), !cpu, "member {k} poses its joints only");
            assert_eq!(stepper.moved_pose().is_some(), cpu, "member {k} poses its vertices on the CPU");
        }
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        posing.record(&mut encoder);
        FurDriver::record_herd(&mut encoder, &mut gpu_drivers).expect("record");
        FurDriver::record_herd(&mut encoder, &mut cpu_drivers).expect("record");
        queue.submit([encoder.finish()]);
    }
    let floats = |slice: wgpu::BufferSlice<'_>| -> Vec<f32> {
        common::read_bytes(device, queue, slice)
            .chunks_exact(4)
            .map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect()
    };
    for k in 0..MEMBERS {
        for (what, tolerance, cpu, gpu) in [
            (
                "state",
                1e-4 * size,
                floats(cpu_drivers[k].fur().current_positions()),
                floats(gpu_drivers[k].fur().current_positions()),
            ),
            ("normals", 1e-4, floats(cpu_drivers[k].fur().base_normals()), floats(gpu_drivers[k].fur().base_normals())),
        ] {
            assert_eq!(cpu.len(), gpu.len());
            let worst = cpu.iter().zip(&gpu).map(|(a, b)| (a - b).abs()).fold(0.0f32, f32::max);
            assert!(worst <= tolerance, "member {k}'s {what} differs by {worst} (tolerance {tolerance})");
            println!("member {k}: {what} within {worst:e}");
        }
    }
    // Each member walks its own way: the states differ.
    let state = |k: usize| floats(gpu_drivers[k].fur().current_positions());
    assert!(state(0).iter().zip(state(2)).any(|(a, b)| (a - b).abs() > 0.1 * size), "members 0 and 2 coincide");
}
