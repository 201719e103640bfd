//! The fur in Bevy's shadow maps and prepass: the ground under a furred (skinless) cube is
//! darker than with `NotShadowCaster` on the fur; under TAA a moving fur writes motion vectors
//! along its motion (read back from Bevy's motion-vector texture) and a still one converges to
//! the picture drawn without TAA.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, Mutex};

use bevy::anti_alias::taa::TemporalAntiAliasing;
use bevy::asset::RenderAssetUsages;
use bevy::camera::RenderTarget;
use bevy::core_pipeline::prepass::{DepthPrepass, MotionVectorPrepass, ViewPrepassTextures};
use bevy::core_pipeline::tonemapping::Tonemapping;
use bevy::core_pipeline::{Core3dSystems, schedule::Core3d};
use bevy::light::NotShadowCaster;
use bevy::prelude::*;
use bevy::render::render_resource::TextureFormat;
use bevy::render::renderer::{RenderContext, RenderDevice, ViewQuery};
use bevy::render::{Render, RenderApp, RenderSystems};
use bevy_pelt::{Fur, FurGpuStats, FurState};

use crate::common::{self, luma, test_assets as assets, update};
use crate::render::{SIZE, capture, capture_now, cuboid, preset};

/// The skinless furred cube over a lit ground, the sun almost straight above (slightly behind it,
/// so the shadow falls toward the camera); `caster` leaves the fur casting (else
/// `NotShadowCaster`).
fn shadow_scene(caster: bool) -> image::RgbaImage {
    let images = capture(1, |world, targets| {
        let ground = world.resource_mut::<Assets<StandardMaterial>>().add(StandardMaterial::from(Color::WHITE));
        let ground_mesh = world.resource_mut::<Assets<Mesh>>().add(Plane3d::default().mesh().size(8.0, 8.0));
        world.spawn((Mesh3d(ground_mesh), MeshMaterial3d(ground), Transform::from_xyz(0.0, -1.0, 0.0)));
        let cube = cuboid(world, Vec3::ONE);
        let fur = Fur::new(preset(world, "presets/long.toml")).without_skin();
        let mut furred = world.spawn((Mesh3d(cube), fur, Transform::from_rotation(Quat::from_rotation_y(0.5))));
        if !caster {
            furred.insert(NotShadowCaster);
        }
        world.spawn((
            DirectionalLight { illuminance: 4000.0, shadow_maps_enabled: true, ..default() },
            Transform::from_xyz(0.3, 6.0, -1.0).looking_at(Vec3::ZERO, Vec3::Y),
        ));
        world.spawn((
            Camera3d::default(),
            RenderTarget::Image(targets[0].clone().into()),
            Tonemapping::None,
            Transform::from_xyz(0.0, 3.0, 4.0).looking_at(Vec3::new(0.0, -0.8, 0.0), Vec3::Y),
        ));
    });
    images.into_iter().next().unwrap()
}

#[test]
fn the_fur_casts_into_bevys_shadow_maps() {
    let cast = shadow_scene(true);
    let not_cast = shadow_scene(false);
    crate::render::save(&cast, "shadow_cast");
    crate::render::save(&not_cast, "shadow_not_cast");
    // The fur draws the same either way; only the ground under it darkens.
    let darker = cast.pixels().zip(not_cast.pixels()).filter(|(a, b)| luma(a) + 20.0 < luma(b)).count();
    let brighter = cast.pixels().zip(not_cast.pixels()).filter(|(a, b)| luma(a) > luma(b) + 20.0).count();
    assert!(darker > 250, "{darker} pixels darker with the fur casting");
    assert!(brighter < darker / 10, "{brighter} pixels brighter, {darker} darker");
}

/// Bevy's motion-vector texture of the camera, copied out after the prepass each frame.
#[derive(Resource, Clone, Default)]
struct MotionReadback(Arc<Mutex<Option<wgpu::Buffer>>>);

/// Copies the motion vectors (`Rg16Float`, bindable but not copyable) into a buffer of f32 pairs.
const COPY_WGSL: &str = "
@group(0) @binding(0) var motion: texture_2d<f32>;
@group(0) @binding(1) var<storage, read_write> copied: array<vec2<f32>>;
@compute @workgroup_size(8, 8)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let size = textureDimensions(motion);
    if id.x < size.x && id.y < size.y {
        copied[id.y * size.x + id.x] = textureLoad(motion, vec2<i32>(id.xy), 0).xy;
    }
}
";

fn copy_motion_vectors(
    view: ViewQuery<&ViewPrepassTextures>,
    readback: Res<MotionReadback>,
    device: Res<RenderDevice>,
    mut ctx: RenderContext,
) {
    let Some(motion) = &view.into_inner().motion_vectors else { return };
    let device = device.wgpu_device();
    let bytes = u64::from(SIZE * SIZE * 8);
    let buffer = |usage| {
        device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("motion readback"),
            size: bytes,
            usage,
            mapped_at_creation: false,
        })
    };
    let copied = buffer(wgpu::BufferUsages::STORAGE | wgpu::BufferUsages::COPY_SRC);
    let mapped = buffer(wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ);
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some("motion readback"),
        source: wgpu::ShaderSource::Wgsl(COPY_WGSL.into()),
    });
    let pipeline = device.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some("motion readback"),
        layout: None,
        module: &module,
        entry_point: Some("main"),
        compilation_options: wgpu::PipelineCompilationOptions::default(),
        cache: None,
    });
    let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("motion readback"),
        layout: &pipeline.get_bind_group_layout(0),
        entries: &[
            wgpu::BindGroupEntry {
                binding: 0,
                resource: wgpu::BindingResource::TextureView(&motion.texture.default_view),
            },
            wgpu::BindGroupEntry { binding: 1, resource: copied.as_entire_binding() },
        ],
    });
    let encoder = ctx.command_encoder();
    {
        let mut pass = encoder.begin_compute_pass(&wgpu::ComputePassDescriptor::default());
        pass.set_pipeline(&pipeline);
        pass.set_bind_group(0, &bind_group, &[]);
        pass.dispatch_workgroups(SIZE.div_ceil(8), SIZE.div_ceil(8), 1);
    }
    encoder.copy_buffer_to_buffer(&copied, 0, &mapped, 0, bytes);
    *readback.0.lock().unwrap() = Some(mapped);
}

fn read_motion(app: &App) -> Vec<[f32; 2]> {
    let buffer = app.world().resource::<MotionReadback>().0.lock().unwrap().take();
    let buffer = buffer.expect("the motion vectors were copied");
    buffer.slice(..).map_async(wgpu::MapMode::Read, |result| result.expect("mapped"));
    app.world()
        .resource::<RenderDevice>()
        .wgpu_device()
        .poll(wgpu::PollType::Wait { submission_index: None, timeout: None })
        .expect("the device answers");
    let bytes = buffer.slice(..).get_mapped_range().expect("the copy is mapped").to_vec();
    bytes
        .chunks_exact(8)
        .map(|texel| {
            let component = |k: usize| f32::from_le_bytes([texel[k], texel[k + 1], texel[k + 2], texel[k + 3]]);
            [component(0), component(4)]
        })
        .collect()
}

/// How many furs the render world's cameras drew last frame (`FurGpuStats::drawn`), readable from
/// the main world.
#[derive(Resource, Clone, Default)]
struct DrawnCopy(Arc<AtomicUsize>);

fn copy_drawn(stats: Res<FurGpuStats>, copy: Res<DrawnCopy>) {
    copy.0.store(stats.drawn.load(Ordering::Relaxed), Ordering::Relaxed);
}

/// Moves the furred cube along +X each frame by this much while `Moving` is set.
#[derive(Resource)]
struct Moving(f32);

#[derive(Component)]
struct Furred;

fn slide(moving: Res<Moving>, mut furred: Query<&mut Transform, With<Furred>>) {
    for mut transform in &mut furred {
        transform.translation.x += moving.0;
    }
}

/// The furred cube (skin included) before nothing, seen by a camera with Bevy's prepasses and,
/// with `taa`, TAA; `step` is its motion along +X per frame. Returns the app after `frames`
/// frames with the fur built.
fn prepass_app(taa: bool, step: f32, frames: u32) -> (App, Handle<Image>) {
    let readback = MotionReadback::default();
    let drawn = DrawnCopy::default();
    // A frame is a thirtieth of a second of the fur's time whatever the machine's load: on real
    // time, how far the strands step in the frame that is read follows the load.
    let frame = std::time::Duration::from_secs_f64(1.0 / 30.0);
    let mut app = common::headless_app_with(&assets(), false, Some(frame), |app| {
        app.sub_app_mut(RenderApp)
            .insert_resource(readback.clone())
            .insert_resource(drawn.clone())
            .add_systems(Core3d, copy_motion_vectors.after(Core3dSystems::Prepass).before(Core3dSystems::MainPass))
            .add_systems(Render, copy_drawn.after(RenderSystems::Render).before(RenderSystems::Cleanup));
    });
    // The same buffer slot and count, read from the main world.
    app.insert_resource(readback).insert_resource(drawn);
    app.insert_resource(Moving(0.0)).add_systems(Update, slide);
    let world = app.world_mut();
    let mut image = Image::new_target_texture(SIZE, SIZE, TextureFormat::Rgba8UnormSrgb, None);
    image.asset_usage = RenderAssetUsages::RENDER_WORLD;
    let target = world.resource_mut::<Assets<Image>>().add(image);
    let cube = cuboid(world, Vec3::ONE);
    let fur = Fur::new(preset(world, "presets/long.toml"));
    world.spawn((Mesh3d(cube), fur, Furred, Transform::from_rotation(Quat::from_euler(EulerRot::YXZ, 0.6, 0.4, 0.0))));
    let mut camera = world.spawn((
        Camera3d::default(),
        RenderTarget::Image(target.clone().into()),
        Tonemapping::None,
        Msaa::Off,
        DepthPrepass,
        MotionVectorPrepass,
        Transform::from_xyz(0.0, 0.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    if taa {
        camera.insert(TemporalAntiAliasing::default());
    }
    // Built and drawn by the camera within two minutes however loaded the machine (the camera's
    // first frame can come after the fur is built), then drawn still for a few frames, so the
    // slide starts from fur already on the GPU (its previous frame's transform known).
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(120);
    loop {
        update(&mut app);
        let drawn = app.world().resource::<DrawnCopy>().0.load(Ordering::Relaxed);
        let world = app.world_mut();
        if world.query::<&FurState>().iter(world).count() == 1 && drawn == 1 {
            break;
        }
        assert!(std::time::Instant::now() < deadline, "the fur was not built and drawn in two minutes");
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    for _ in 0..3 {
        update(&mut app);
    }
    app.insert_resource(Moving(step));
    for _ in 0..frames {
        update(&mut app);
    }
    (app, target)
}

#[test]
fn moving_fur_writes_motion_vectors_under_taa() {
    // 0.02 a frame along +X: about 0.02 / (2 * 4 * tan(fov / 2)) of the width, ~0.006 in uv.
    let (app, _) = prepass_app(true, 0.02, 4);
    let moving = read_motion(&app);
    let (app, _) = prepass_app(true, 0.0, 4);
    let still = read_motion(&app);
    // A third of the slide's motion: the still fur's settling strands move far less.
    let moved: Vec<&[f32; 2]> = moving.iter().filter(|m| m[0].abs() + m[1].abs() > 2e-3).collect();
    let stirred = still.iter().filter(|m| m[0].abs() + m[1].abs() > 2e-3).count();
    assert!(moved.len() > 1500, "{} of {} pixels moved", moved.len(), moving.len());
    assert!(stirred < moved.len() / 5, "{stirred} pixels of the still fur moved, {} of the sliding one", moved.len());
    // Along +X in uv (x right), a few thousandths a frame.
    let mean_x = moved.iter().map(|m| m[0]).sum::<f32>() / moved.len() as f32;
    let mean_y = moved.iter().map(|m| m[1]).sum::<f32>() / moved.len() as f32;
    assert!((0.002..0.02).contains(&mean_x), "mean motion x {mean_x}");
    assert!(mean_y.abs() < mean_x * 0.2, "mean motion y {mean_y} against x {mean_x}");
}

#[test]
fn a_still_fur_under_taa_converges_to_the_picture_without_it() {
    let (mut app, target) = prepass_app(true, 0.0, 40);
    let with_taa = capture_now(&mut app, &target);
    let (mut app, target) = prepass_app(false, 0.0, 4);
    let without = capture_now(&mut app, &target);
    crate::render::save(&with_taa, "taa_still");
    crate::render::save(&without, "taa_off_still");
    let differences: Vec<f32> =
        with_taa.pixels().zip(without.pixels()).map(|(a, b)| (luma(a) - luma(b)).abs()).collect();
    let mean = differences.iter().sum::<f32>() / differences.len() as f32;
    let far = differences.iter().filter(|&&d| d > 48.0).count();
    assert!(mean < 4.0, "mean |difference| {mean}");
    assert!(far < differences.len() / 50, "{far} pixels far apart");
}
