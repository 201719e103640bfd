//! `pelt bench --herd`: how a herd's cost grows. 1, 10, 100 and 1,000 Foxes (default preset,
//! 16 layers) walk across a field at their own phases (`herd::scatter`, each walking ahead),
//! framed whole at 1280x720 with the Fox's shadows on a ground, as `pelt render --herd N` draws
//! them: one `FurAsset`, a driver and a stepper per Fox, the steppers posing (and on the CPU
//! kernel bending) in one parallel pass, or each Fox on the GPU kernel (`--sim gpu`), drawn
//! farthest first through the camera's plan (`HerdDraws`: on a GPU a level's Foxes in a skin
//! draw and a shell draw). Per size: the simulation's time a frame, the CPU's time to record a
//! frame (the plan included), the camera's draws, the rest of the frame (the GPU's work and the
//! readback), the GPU bytes of the shared asset and of each Fox, what one more Fox adds to each,
//! and posing every Fox's base once on the CPU (`Rig::pose`) against on the GPU
//! (`Rig::pose_joints` per Fox, then one `GpuSkin` dispatch).

use std::path::Path;
use std::time::{Duration, Instant};

use anyhow::Context as _;
use glam::{Mat4, Quat, Vec3};
use pelt_core::sim::herd;
use pelt_core::sim::{Collider, FurStepper, Shape};
use pelt_core::{ImportOptions, Preset, Stage, StageSource};
use pelt_render::{
    Backend, Camera, FurAsset, FurDrawSettings, FurDriver, FurTarget, FurView, Gpu, GpuSkin, HEADLESS_FORMAT, Headless,
    HerdDraws, HerdPosing, KernelChoice, SimKernel, Studio,
};

/// Figures for one herd size.
#[derive(Clone, Debug, serde::Serialize)]
pub struct HerdRow {
    pub foxes: usize,
    /// Where the strands bend: `cpu` or `gpu`.
    pub kernel: String,
    /// Whether the shadow casters of the Foxes drew in one draw a shadow pass
    /// (`FurRenderer::pooled_casting`: a GPU's default) or a draw each (a CPU rasteriser's).
    pub pooled_casting: bool,
    /// Whether on the GPU kernel the Foxes stepped in one dispatch a step
    /// (`FurRenderer::pooled_stepping`: a GPU's default) or a dispatch each.
    pub pooled_stepping: bool,
    /// Whether the camera drew the Foxes of a level (those sharing no pixel) in a skin draw and a
    /// shell draw (`FurRenderer::pooled_drawing`: a GPU's default) or each Fox alone.
    pub pooled_drawing: bool,
    /// The camera's draws in the last frame, and the levels its plan put the Foxes in
    /// (`HerdDraws`).
    pub camera_draws: usize,
    pub camera_levels: usize,
    /// Whether a ball rolled through the herd (a collider every Fox's steps meet: on the GPU
    /// kernel each step with contact, pooled or each Fox's own).
    pub ball: bool,
    /// Whether on the GPU kernel the Foxes' bases were skinned on the GPU (`HerdPosing`,
    /// `FurRenderer::herd_posing`: a GPU's default; the CPU posing joints only) or on the CPU.
    pub gpu_posing: bool,
    /// `WIDTHxHEIGHT`, and the MSAA samples.
    pub size: String,
    pub msaa_samples: u32,
    pub frames: u32,
    /// Stepping every Fox (one parallel pass) and uploading their states, mean per frame; on the
    /// GPU kernel, posing them and recording their steps (the GPU's work is in the next figure).
    pub simulation_ms: f64,
    /// Recording the frame on the CPU (the shadow and main passes' draws).
    pub record_ms: f64,
    /// From the end of recording to the picture read back: the GPU's work.
    pub gpu_and_readback_ms: f64,
    /// The whole frame: simulation, recording, GPU and readback.
    pub frame_ms: f64,
    /// Posing every Fox's base on the CPU (`Rig::pose`: the clip, the joints and the vertices).
    pub cpu_pose_ms: f64,
    /// Posing them on the GPU: the clip and joints on the CPU, the vertices in one `GpuSkin`
    /// dispatch, waited for.
    pub gpu_pose_ms: f64,
    /// Bytes every Fox shares (topology, uvs, fin strip, textures, the gathered draws' indices;
    /// on the GPU kernel the simulation's rest segments), once.
    pub shared_gpu_bytes: u64,
    /// Bytes of each Fox's own state (shared-array state, normals, silhouette and shell lists;
    /// on the GPU kernel a second state and its simulation's buffers).
    pub per_fox_gpu_bytes: u64,
    /// Bytes of the herd's GPU posing (the skin's rest pose and influences, each Fox's joint
    /// matrices and posed vertices); 0 where the CPU poses.
    pub posing_gpu_bytes: u64,
    pub total_gpu_bytes: u64,
    /// What the device's allocator holds for the herd's drivers, by its own count (Vulkan; none
    /// elsewhere): their buffers with the allocator's alignment and the per-Fox uniforms.
    pub allocated_gpu_bytes: Option<u64>,
}

/// Bytes the device's allocator holds for Pelt (wgpu's own, such as upload staging, left out).
fn allocated(device: &wgpu::Device) -> Option<u64> {
    device.poll(wgpu::PollType::Wait { submission_index: None, timeout: None }).ok()?;
    let report = device.generate_allocator_report()?;
    Some(report.allocations.iter().filter(|a| !a.name.starts_with("(wgpu internal)")).map(|a| a.size).sum())
}

const COUNTS: [usize; 4] = [1, 10, 100, 1000];
const SIZE: (u32, u32) = (1280, 720);
/// World units a second: about the Fox's walking pace.
const PACE: f32 = 70.0;

/// Runs the sizes and prints the table (Markdown); `json` also gets the rows.
pub fn run(
    quick: bool,
    meshes: &Path,
    json: Option<&Path>,
    (kernel, pooled): (SimKernel, Option<bool>),
) -> anyhow::Result<()> {
    let counts: &[usize] = if quick { &COUNTS[..2] } else { &COUNTS };
    let frames: u32 = if quick { 2 } else { 4 };
    let gpu = Gpu::new(Backend::Auto)?;
    // Lavapipe's single sample, as `pelt render` draws there (MSAA where a GPU is).
    let samples = pelt_render::default_sample_count(&gpu.adapter.get_info());
    let (rows, adapter) = measure(gpu, meshes, counts, (SIZE, samples), frames, (kernel, pooled, false))?;
    println!("{}", markdown(&rows, &adapter));
    if let Some(path) = json {
        let text = serde_json::to_string_pretty(&rows)? + "\n";
        std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))?;
    }
    Ok(())
}

/// The rows for herds of `counts` Foxes at `size` with `samples` MSAA samples, `frames` timed
/// frames each, on `gpu`, bending on `kernel`, the shadow casters, the camera's draws, the GPU
/// kernel's steps and posing pooled as `pooled` says (`None`: the device's default), with a
/// ball rolled through the herd where `ball`; and the adapter's summary.
pub fn measure(
    gpu: Gpu,
    meshes: &Path,
    counts: &[usize],
    (size, samples): ((u32, u32), u32),
    frames: u32,
    (kernel, pooled, ball): (SimKernel, Option<bool>, bool),
) -> anyhow::Result<(Vec<HerdRow>, String)> {
    let choice = KernelChoice::from(kernel);
    let path = meshes.join("Fox.glb");
    let stage = Stage::load(&StageSource::File(path.clone()), &[], &ImportOptions::default())
        .with_context(|| format!("loading {}", path.display()))?;
    let rig = stage.rig.context("the Fox is rigged")?;
    let walk = rig.find_animation("Walk").map_err(|e| anyhow::anyhow!("{}: {e}", path.display()))?;
    let preset = Preset::default();
    let fur = preset.grow(stage.fur_mesh.clone(), "fox")?;
    let textures = preset.generate_textures()?;
    let target = FurTarget::new(HEADLESS_FORMAT).with_sample_count(samples);
    let headless = Headless::with_target(gpu, target, size.0, size.1)?;
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let mut renderer = headless.renderer()?;
    if let Some(pooled) = pooled {
        renderer.set_pooled_casting(pooled);
        renderer.set_pooled_stepping(pooled);
        renderer.set_pooled_drawing(pooled);
        renderer.set_herd_posing(pooled);
    }
    // A ball's contact reads the posed vertices on the CPU: the CPU poses.
    let gpu_posing = kernel == SimKernel::Gpu && renderer.herd_posing() && !ball;
    let asset = FurAsset::new(device, queue, &renderer, &fur, &textures)?;
    let (low, high) = fur.mesh.bounds();
    // What a Fox draws lies within its mesh's sphere grown by its longest strand.
    let (mesh_centre, mesh_radius) = fur.mesh.bounding_sphere();
    let reach = mesh_radius + fur.lengths.iter().copied().fold(0.0, f32::max);
    let spacing = 1.5 * (high - low).max_element();
    let fps = 30.0;
    let mut rows = Vec::new();
    for &foxes in counts {
        eprintln!("pelt bench: a herd of {foxes}");
        let duration = f64::from(rig.animations()[walk].duration_secs());
        let mut instances = herd::scatter(foxes, spacing, duration, 0).map_err(|e| anyhow::anyhow!(e))?;
        for instance in &mut instances {
            instance.speed = PACE;
        }
        // The asset as allocated before this herd (a GPU kernel's first copy adds its rest
        // segments to it, counted in the herd's allocation).
        let asset_before = asset.gpu_bytes().total();
        let before = allocated(device);
        let mut drivers =
            FurDriver::herd_with_asset(device, queue, &renderer, (&asset, &fur), &preset.simulation, choice, foxes)?;
        let mut posing = gpu_posing.then(|| HerdPosing::new(device, &fur.mesh, &rig, foxes)).transpose()?;
        let herd_bytes = allocated(device).zip(before).map(|(after, before)| after - before);
        let mut steppers = instances
            .iter()
            .map(|instance| {
                let mut stepper = FurStepper::new(&fur, &preset.simulation)?;
                stepper.set_clip(rig.clone(), Some(walk));
                stepper.set_placement(Some(instance.clone()));
                stepper.set_joint_posing(gpu_posing);
                Ok(stepper)
            })
            .collect::<anyhow::Result<Vec<_>>>()?;
        let secs = f64::from(frames + 1) / fps;
        let points = instances.iter().flat_map(|i| {
            [0.0, secs].into_iter().flat_map(move |t| {
                let world: Mat4 = i.world_from_model(t);
                [low, high].map(|p| world.transform_point3(p))
            })
        });
        let (points, centre) = {
            let points: Vec<Vec3> = points.collect();
            let centre = points.iter().fold(Vec3::ZERO, |s, p| s + *p) / points.len() as f32;
            (points, centre)
        };
        let length = fur.lengths.iter().copied().fold(0.0, f32::max);
        let camera =
            Camera::framing_points(centre, points.iter().copied(), length, 20.0, 28.0, headless.aspect_ratio());
        let studio = Studio::default();
        let view_data = studio.view_data(&camera, headless.aspect_ratio());
        let mut view = FurView::new(device, &renderer);
        view.prepare(queue, &view_data);
        let extent =
            points.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
        let ground = pelt_core::sim::SceneGround::default();
        let mut surroundings =
            pelt_render::Surroundings::around_box(device, queue, &renderer, (true, Some(&ground)), length, extent)?;
        surroundings.prepare((device, queue), &renderer, &view_data, &mut view)?;
        let lod = crate::lod::settings(&preset.render.lod, false);
        let (mut simulation, mut record, mut gpu) = (Duration::ZERO, Duration::ZERO, Duration::ZERO);
        let mut plan = HerdDraws::new();
        let mut camera_draws = 0;
        // One frame to warm up (pipelines, first poses), then the timed ones.
        for frame in 0..=frames {
            let time_secs = f64::from(frame) / fps;
            let started = Instant::now();
            // As `pelt render`: each member's level, far ones stepped less often.
            let levels: Vec<_> = instances
                .iter()
                .map(|instance| {
                    let eye = instance.world_from_model(time_secs).inverse().transform_point3(camera.eye);
                    crate::lod::level(&lod, &fur, eye, camera.fov_y_rad, size.1)
                })
                .collect();
            for (stepper, level) in steppers.iter_mut().zip(&levels) {
                stepper.set_step_stride(level.step_stride());
                if ball {
                    // Half a Fox wide, rolling across the herd's middle at a walking pace.
                    let at = centre + Vec3::X * (PACE * (time_secs as f32 - 1.0)) + Vec3::Y * (0.1 * spacing);
                    let shape = Shape::Sphere { radius: 0.25 * spacing };
                    let rolled = Quat::from_rotation_z(-(time_secs as f32) * PACE / (0.25 * spacing));
                    stepper.simulation_mut().set_colliders(&[Collider::at(1, shape, time_secs, at, rolled)])?;
                }
            }
            FurDriver::advance_herd((device, queue), &mut drivers, &mut steppers, &instances, time_secs)?;
            for (driver, level) in drivers.iter_mut().zip(levels) {
                driver.set_level(level);
            }
            if kernel == SimKernel::Gpu {
                let mut encoder =
                    device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("herd steps") });
                if let Some(posing) = &mut posing {
                    posing.prepare((device, queue), &drivers, &steppers)?;
                    posing.record(&mut encoder);
                }
                FurDriver::record_herd(&mut encoder, &mut drivers)?;
                queue.submit([encoder.finish()]);
            }
            let stepped = Instant::now();
            // Blended fur draws farthest first, in the plan's levels.
            let spheres: Vec<(Vec3, f32)> = instances
                .iter()
                .map(|i| (i.world_from_model(time_secs).transform_point3(mesh_centre), reach))
                .collect();
            let mut order: Vec<usize> = (0..foxes).collect();
            let distance = |k: usize| spheres[k].0.distance(camera.eye);
            order.sort_by(|&a, &b| distance(b).total_cmp(&distance(a)));
            let members: Vec<_> = order.iter().map(|&k| (drivers[k].fur(), spheres[k])).collect();
            plan.prepare((device, queue), &renderer, &view_data, &members);
            let furs: Vec<_> = members.iter().map(|(fur, _)| *fur).collect();
            let mut recorded = None;
            headless.render_with(
                studio.background,
                |encoder| {
                    FurDriver::record_views(encoder, &renderer, &view, &drivers);
                    surroundings.record(encoder, |pass, light| {
                        surroundings.draw_ground(pass, &renderer, light);
                        FurDriver::draw_herd(pass, &renderer, light, &drivers, &FurDrawSettings::ALL);
                    });
                },
                |pass| {
                    surroundings.draw_ground(pass, &renderer, &view);
                    camera_draws = renderer.draw_herd_planned(pass, &view, &plan, &furs, &FurDrawSettings::SILHOUETTE);
                    recorded = Some(Instant::now());
                },
            )?;
            let done = Instant::now();
            let recorded = recorded.unwrap_or(done);
            if frame > 0 {
                simulation += stepped - started;
                record += recorded - stepped;
                gpu += done - recorded;
            }
        }
        let (cpu_pose_ms, gpu_pose_ms) = time_posing((device, queue), (&rig, walk), &fur.mesh, &instances, frames)?;
        let per_frame = |d: Duration| d.as_secs_f64() * 1000.0 / f64::from(frames);
        let shared_gpu_bytes = asset.gpu_bytes().total() + drivers[0].fur().herd_list_bytes();
        let posing_gpu_bytes = posing.as_ref().map_or(0, HerdPosing::gpu_bytes);
        let own = drivers[0].fur().own_bytes();
        let per_fox_gpu_bytes =
            own.positions + own.attributes + drivers[0].fur().silhouette_list_bytes() + drivers[0].simulation_bytes();
        rows.push(HerdRow {
            foxes,
            kernel: kernel.to_string().to_lowercase(),
            pooled_casting: renderer.pooled_casting(),
            pooled_stepping: kernel == SimKernel::Gpu && renderer.pooled_stepping(),
            pooled_drawing: renderer.pooled_drawing(),
            gpu_posing: posing.is_some(),
            ball,
            camera_draws,
            camera_levels: plan.levels(),
            size: format!("{}x{}", size.0, size.1),
            msaa_samples: samples,
            frames,
            simulation_ms: per_frame(simulation),
            record_ms: per_frame(record),
            gpu_and_readback_ms: per_frame(gpu),
            frame_ms: per_frame(simulation + record + gpu),
            cpu_pose_ms,
            gpu_pose_ms,
            shared_gpu_bytes,
            per_fox_gpu_bytes,
            posing_gpu_bytes,
            total_gpu_bytes: shared_gpu_bytes + foxes as u64 * per_fox_gpu_bytes + posing_gpu_bytes,
            // The asset was allocated before every herd: count it once with each.
            allocated_gpu_bytes: herd_bytes.map(|bytes| bytes + asset_before),
        });
    }
    Ok((rows, headless.gpu.summary()))
}

/// Milliseconds to pose every member's base at one time, on the CPU and on the GPU (after one
/// untimed round of each), the mean of `rounds` rounds.
fn time_posing(
    (device, queue): (&wgpu::Device, &wgpu::Queue),
    (rig, walk): (&pelt_core::anim::Rig, usize),
    mesh: &pelt_core::Mesh,
    instances: &[herd::HerdInstance],
    rounds: u32,
) -> anyhow::Result<(f64, f64)> {
    let skin = GpuSkin::new(
        device,
        (&mesh.positions, &mesh.normals),
        &rig.vertex_influences(),
        rig.joint_count(),
        instances.len(),
    )?;
    let mut pose = pelt_core::anim::Pose::default();
    let (mut cpu, mut gpu) = (Duration::ZERO, Duration::ZERO);
    for round in 0..=rounds {
        let time_secs = f64::from(round) / 30.0;
        let started = Instant::now();
        for instance in instances {
            rig.pose(mesh, Some(walk), instance.clip_time(time_secs), &mut pose);
        }
        let posed_on_cpu = Instant::now();
        for (k, instance) in instances.iter().enumerate() {
            rig.pose_joints(Some(walk), instance.clip_time(time_secs), &mut pose);
            skin.set_joints(queue, k, &rig.joint_matrices(&pose))?;
        }
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("herd skin") });
        skin.record(&mut encoder);
        queue.submit([encoder.finish()]);
        device.poll(wgpu::PollType::wait_indefinitely())?;
        if round > 0 {
            cpu += posed_on_cpu - started;
            gpu += posed_on_cpu.elapsed();
        }
    }
    let per_round = |d: Duration| d.as_secs_f64() * 1000.0 / f64::from(rounds.max(1));
    Ok((per_round(cpu), per_round(gpu)))
}

fn markdown(rows: &[HerdRow], adapter: &str) -> String {
    let mut out = format!(
        "### A herd of walking Foxes ({}, {}x MSAA, 16 layers, shadows on a ground {}, {}, bent on the {}; {adapter})\n\n\
         | Foxes | frame ms | simulation ms | record ms | GPU + readback ms | one more Fox adds (frame / record, ms) | camera draws (levels) | GPU bytes (shared + per Fox) | allocated | posing every base, CPU / GPU ms |\n\
         |---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
        rows.first().map_or("", |r| r.size.as_str()),
        rows.first().map_or(1, |r| r.msaa_samples),
        if rows.first().is_some_and(|r| r.pooled_casting) { "cast in one draw a pass" } else { "cast a Fox a draw" },
        if rows.first().is_some_and(|r| r.pooled_drawing) {
            "the camera's draws pooled by level"
        } else {
            "the camera's draws a Fox at a time"
        },
        match rows.first() {
            Some(r) if r.kernel == "gpu" && r.pooled_stepping => "GPU in one dispatch a step".to_owned(),
            Some(r) => r.kernel.to_uppercase(),
            None => String::new(),
        } + if rows.first().is_some_and(|r| r.gpu_posing) { ", posed on the GPU" } else { "" },
    );
    for (k, row) in rows.iter().enumerate() {
        let more = match k.checked_sub(1).map(|p| &rows[p]) {
            Some(before) => {
                let n = (row.foxes - before.foxes) as f64;
                format!("{:.3} / {:.4}", (row.frame_ms - before.frame_ms) / n, (row.record_ms - before.record_ms) / n)
            }
            None => "-".to_owned(),
        };
        out += &format!(
            "| {} | {:.1} | {:.1} | {:.2} | {:.1} | {more} | {} ({}) | {} ({} + {} x {}{}) | {} | {:.2} / {:.2} |\n",
            row.foxes,
            row.frame_ms,
            row.simulation_ms,
            row.record_ms,
            row.gpu_and_readback_ms,
            row.camera_draws,
            row.camera_levels,
            row.total_gpu_bytes,
            row.shared_gpu_bytes,
            row.foxes,
            row.per_fox_gpu_bytes,
            if row.posing_gpu_bytes > 0 { format!(" + posing {}", row.posing_gpu_bytes) } else { String::new() },
            row.allocated_gpu_bytes.map_or_else(|| "-".to_owned(), |b| b.to_string()),
            row.cpu_pose_ms,
            row.gpu_pose_ms,
        );
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_adds_one_more_fox_between_rows() {
        let row = |foxes, frame_ms, record_ms| HerdRow {
            foxes,
            kernel: "gpu".to_owned(),
            pooled_casting: false,
            pooled_stepping: true,
            pooled_drawing: true,
            gpu_posing: true,
            ball: false,
            camera_draws: 2 * foxes,
            camera_levels: foxes / 2,
            size: "1280x720".to_owned(),
            msaa_samples: 1,
            frames: 1,
            simulation_ms: 0.0,
            record_ms,
            gpu_and_readback_ms: 0.0,
            frame_ms,
            cpu_pose_ms: 3.0,
            gpu_pose_ms: 0.5,
            shared_gpu_bytes: 10,
            per_fox_gpu_bytes: 2,
            posing_gpu_bytes: 3,
            total_gpu_bytes: 13 + 2 * foxes as u64,
            allocated_gpu_bytes: Some(11 + 2 * foxes as u64),
        };
        let table = markdown(&[row(1, 10.0, 1.0), row(11, 30.0, 2.0)], "lavapipe");
        assert!(table.contains("| 11 | 30.0 |"), "{table}");
        assert!(table.contains("2.000 / 0.1000"), "{table}");
        assert!(table.contains("| 22 (5) | 35 (10 + 11 x 2 + posing 3) | 33 | 3.00 / 0.50 |"), "{table}");
        assert!(table.contains("the camera's draws pooled by level"), "{table}");
        assert!(table.contains("bent on the GPU in one dispatch a step, posed on the GPU"), "{table}");
    }
}
