//! The frame driver: its CPU and GPU kernels draw the same fur from the same script (wind,
//! touch strokes and rigid motion played by a `FurStepper`), alone or as a herd's members, a
//! host that never records the GPU's steps still draws the CPU's state, and the same frames
//! give the same bytes. Fails,
//! never skips, without an adapter.

use crate::common;

use std::path::Path;

use common::{BROWN_ROOT, BROWN_TIP, builtin_fur, framed, gpu, strand_textures};
use glam::Vec3;
use pelt_core::sim::{FurStepper, HerdInstance, Scene, SimParams};
use pelt_core::{Builtin, FurStructure};
use pelt_render::{
    DEFAULT_BACKGROUND, FurAsset, FurDrawSettings, FurDriver, FurView, Headless, KernelChoice, Light, POSITIONS_USAGE,
    SimKernel,
};

const RATE_HZ: f64 = 30.0;

/// Wind with gusts, a touch stroke across the back, and the whole bunny turning and moving: every
/// per-step input the stepper feeds the kernels.
const SCRIPT: &str = r#"
[[wind]]
time_secs = 0.0
direction = [1.0, 0.2, -0.3]
strength = 2.0
gust_strength = 0.5
jitter = 0.3

[[stroke]]
start_secs = 0.3
end_secs = 1.0
radius = 0.5
path = [[0.0, 0.6, 0.0], [0.3, 0.5, 0.1]]

[[motion]]
time_secs = 0.0

[[motion]]
time_secs = 1.5
translation = [0.3, 0.1, 0.0]
rotation_deg = [0.0, 40.0, 0.0]
ease = "in_out"
"#;

fn scripted_stepper(structure: &FurStructure) -> FurStepper {
    let mut stepper = FurStepper::new(structure, &SimParams::default()).expect("stepper");
    let scene = Scene::from_toml_str(SCRIPT, Path::new("driver-test.toml")).expect("script");
    stepper.set_scene(Some(scene));
    stepper
}

/// The positions `driver` draws this frame: its current state, or between its two states at
/// the frame's interpolation.
fn drawn_positions(gpu: &pelt_render::Gpu, driver: &FurDriver, nodes: usize) -> Vec<Vec3> {
    let read = |state: wgpu::BufferSlice<'_>| -> Vec<Vec3> {
        assert!(state.buffer().usage().contains(POSITIONS_USAGE));
        let bytes = nodes as u64 * 12;
        let staging = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("readback"),
            size: bytes,
            usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        encoder.copy_buffer_to_buffer(state.buffer(), state.offset(), &staging, 0, bytes);
        gpu.queue.submit([encoder.finish()]);
        let slice = staging.slice(..);
        slice.map_async(wgpu::MapMode::Read, |result| result.expect("map"));
        gpu.device.poll(wgpu::PollType::wait_indefinitely()).expect("poll");
        let mapped = slice.get_mapped_range().expect("mapped");
        bytemuck::cast_slice::<u8, f32>(&mapped).chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect()
    };
    let current = read(driver.fur().current_positions());
    let t = driver.frame().interpolation;
    match driver.kernel() {
        SimKernel::Cpu => current,
        SimKernel::Gpu => {
            let previous = read(driver.fur().previous_positions());
            previous.iter().zip(&current).map(|(p, c)| *p * (1.0 - t) + *c * t).collect()
        }
    }
}

/// The largest `|a - b| / strand length` over every node (NaN counts as infinitely far).
fn worst_relative_difference(structure: &FurStructure, a: &[Vec3], b: &[Vec3]) -> f32 {
    let v = structure.vertex_count();
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .enumerate()
        .map(|(n, (x, y))| {
            let d = x.distance(*y) / structure.lengths[n % v];
            if d.is_nan() { f32::INFINITY } else { d }
        })
        .fold(0.0, f32::max)
}

#[test]
fn cpu_and_gpu_kernels_draw_the_same_fur_through_the_driver() {
    let gpu = gpu();
    let headless = Headless::with_gpu(gpu, 64, 64).expect("headless");
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer().expect("renderer");
    let structure = builtin_fur(Builtin::Bunny, 16);
    let textures = strand_textures(32, 16, BROWN_ROOT, BROWN_TIP);
    let params = SimParams::default();
    let mut drivers = [KernelChoice::Cpu, KernelChoice::Gpu].map(|choice| {
        FurDriver::new(device, queue, &renderer, &structure, &textures, &params, choice).expect("driver")
    });
    assert_eq!(drivers.each_ref().map(FurDriver::kernel), [SimKernel::Cpu, SimKernel::Gpu]);
    let mut steppers = [scripted_stepper(&structure), scripted_stepper(&structure)];
    let nodes = structure.positions.len();
    let (mut worst, mut moved) = (0.0_f32, 0.0_f32);
    // Frames at 45 Hz against steps at 30: most frames fall between two states.
    for frame in 1..=72 {
        let time_secs = f64::from(frame) / 45.0;
        let mut drawn = Vec::new();
        for (driver, stepper) in drivers.iter_mut().zip(&mut steppers) {
            driver.advance_to(device, queue, stepper, time_secs).expect("advance");
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            driver.record(&mut encoder).expect("record");
            queue.submit([encoder.finish()]);
            drawn.push(drawn_positions(&headless.gpu, driver, nodes));
        }
        let difference = worst_relative_difference(&structure, &drawn[0], &drawn[1]);
        assert!(difference <= 1e-4, "frame {frame}: a node is {difference} strand lengths from the CPU kernel's");
        worst = worst.max(difference);
        moved = moved.max(worst_relative_difference(&structure, &drawn[0], &structure.positions));
    }
    assert_eq!(drivers[1].kernel(), SimKernel::Gpu, "a host that records keeps the GPU kernel");
    assert!(steppers[0].simulation().steps_taken() >= 40, "the frames stepped the simulation");
    // The script moves the fur well away from its rest pose, so agreement means something.
    assert!(moved > 0.3, "the fur hardly moved ({moved} strand lengths)");
    eprintln!("driver: worst CPU/GPU kernel difference {worst:e} strand lengths over 72 frames");
}

/// Renders `frames` frames at 30 Hz of the scripted bunny through a driver of `choice`, recording
/// the GPU's steps only when `record`; returns the last image and the kernel that ended up
/// bending.
fn render_scripted(choice: KernelChoice, record: bool, frames: u32) -> (image::RgbaImage, SimKernel) {
    let headless = Headless::with_gpu(gpu(), 96, 72).expect("headless");
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer().expect("renderer");
    let structure = builtin_fur(Builtin::Bunny, 16);
    let textures = strand_textures(32, 16, BROWN_ROOT, BROWN_TIP);
    let mut driver =
        FurDriver::new(device, queue, &renderer, &structure, &textures, &SimParams::default(), choice).expect("driver");
    let mut stepper = scripted_stepper(&structure);
    let view = FurView::new(device, &renderer);
    let camera = framed(&structure, headless.aspect_ratio());
    view.prepare(queue, &camera.view_data(headless.aspect_ratio(), &Light::default()));
    let mut image = None;
    for frame in 0..frames {
        driver.advance_to(device, queue, &mut stepper, f64::from(frame) / RATE_HZ).expect("advance");
        if record {
            let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
            driver.record(&mut encoder).expect("record");
            queue.submit([encoder.finish()]);
        }
        image = Some(
            headless
                .render_with(
                    DEFAULT_BACKGROUND,
                    |encoder| driver.record_view(encoder, &renderer, &view),
                    |pass| driver.draw(pass, &renderer, &view, &FurDrawSettings::SILHOUETTE),
                )
                .expect("render"),
        );
    }
    (image.expect("at least one frame"), driver.kernel())
}

#[test]
fn a_host_that_never_records_the_gpu_steps_draws_the_cpu_state() {
    let (cpu, kernel) = render_scripted(KernelChoice::Cpu, true, 12);
    assert_eq!(kernel, SimKernel::Cpu);
    let (unrecorded, kernel) = render_scripted(KernelChoice::Gpu, false, 12);
    assert_eq!(kernel, SimKernel::Cpu, "unrecorded GPU steps hand the bending to the CPU");
    // The CPU took over from the current inputs (a quasi-static jump, the inertia restarted), so
    // the picture is the CPU kernel's within a few pixels of rounding.
    let differing = cpu.pixels().zip(unrecorded.pixels()).filter(|(a, b)| common::pixel_difference(a, b) > 8).count();
    let total = (cpu.width() * cpu.height()) as usize;
    assert!(differing * 200 <= total, "{differing} of {total} pixels differ from the CPU kernel's frame");
    // Against a frame of the fur at rest (no script) it must differ: the unrecorded driver moved.
    let (recorded_gpu, _) = render_scripted(KernelChoice::Gpu, true, 1);
    let moved =
        unrecorded.pixels().zip(recorded_gpu.pixels()).filter(|(a, b)| common::pixel_difference(a, b) > 8).count();
    assert!(moved * 50 > total, "the 12th frame hardly differs from the first ({moved} pixels)");
}

#[test]
fn the_same_frames_give_the_same_bytes() {
    for choice in [KernelChoice::Cpu, KernelChoice::Gpu] {
        let (first, _) = render_scripted(choice, true, 8);
        let (second, _) = render_scripted(choice, true, 8);
        assert!(first.as_raw() == second.as_raw(), "{choice:?}: two runs of the same frames differ");
    }
}

/// A herd on the GPU kernel (`FurDriver::advance_herd`: the bases posed in one parallel pass, one
/// asset, one set of kernels): each member bends within 1e-4 strand lengths of the same herd on
/// the CPU kernel, and the last draws to the bit what a bunny with its own asset and kernels,
/// placed and advanced alone, draws.
#[test]
fn a_herd_on_the_gpu_kernel_bends_each_member_as_alone() {
    let headless = Headless::with_gpu(gpu(), 64, 64).expect("headless");
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer().expect("renderer");
    let structure = builtin_fur(Builtin::Bunny, 8);
    let textures = strand_textures(32, 8, BROWN_ROOT, BROWN_TIP);
    let params = SimParams::default();
    let asset = FurAsset::new(device, queue, &renderer, &structure, &textures).expect("asset");
    // Each its own place, heading, pace and phase: turning the wind and the script's motion.
    let instances: Vec<HerdInstance> = [(0.0, 0.0, 0.0), (90.0, 0.4, 0.3), (200.0, 1.2, 0.7)]
        .into_iter()
        .enumerate()
        .map(|(k, (heading_deg, speed, time_offset_secs))| HerdInstance {
            heading_deg,
            speed,
            time_offset_secs,
            ..HerdInstance::at(Vec3::new(3.0 * k as f32, 0.0, 0.0))
        })
        .collect();
    let placed = |instance: &HerdInstance| {
        let mut stepper = scripted_stepper(&structure);
        stepper.set_placement(Some(instance.clone()));
        stepper
    };
    let mut herds = [KernelChoice::Gpu, KernelChoice::Cpu].map(|choice| {
        let drivers: Vec<FurDriver> = instances
            .iter()
            .map(|_| {
                FurDriver::with_asset(device, queue, &renderer, &asset, &structure, &params, choice).expect("driver")
            })
            .collect();
        (drivers, instances.iter().map(placed).collect::<Vec<_>>())
    });
    let last = instances.len() - 1;
    let mut alone =
        FurDriver::new(device, queue, &renderer, &structure, &textures, &params, KernelChoice::Gpu).expect("driver");
    let mut alone_stepper = placed(&instances[last]);
    let nodes = structure.positions.len();
    let start = drawn_positions(&headless.gpu, &herds[0].0[last], nodes);
    let mut worst = 0.0_f32;
    for frame in 1..=30 {
        let time_secs = f64::from(frame) / 45.0;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        for (drivers, steppers) in &mut herds {
            FurDriver::advance_herd((device, queue), drivers, steppers, &instances, time_secs).expect("advance");
            for driver in drivers.iter_mut() {
                driver.record(&mut encoder).expect("record");
            }
        }
        alone.advance_to(device, queue, &mut alone_stepper, time_secs).expect("advance");
        alone.record(&mut encoder).expect("record");
        queue.submit([encoder.finish()]);
        for member in 0..instances.len() {
            let on_gpu = drawn_positions(&headless.gpu, &herds[0].0[member], nodes);
            let on_cpu = drawn_positions(&headless.gpu, &herds[1].0[member], nodes);
            let difference = worst_relative_difference(&structure, &on_gpu, &on_cpu);
            assert!(difference <= 1e-4, "frame {frame}: member {member} is {difference} strand lengths off the CPU's");
            worst = worst.max(difference);
        }
        let member = drawn_positions(&headless.gpu, &herds[0].0[last], nodes);
        assert!(
            member == drawn_positions(&headless.gpu, &alone, nodes),
            "frame {frame}: the member differs from alone"
        );
    }
    assert!(herds[0].0.iter().all(|driver| driver.kernel() == SimKernel::Gpu));
    let moved =
        worst_relative_difference(&structure, &start, &drawn_positions(&headless.gpu, &herds[0].0[last], nodes));
    assert!(moved > 0.3, "the member hardly moved ({moved} strand lengths)");
    eprintln!("driver: a herd of three on the GPU kernel, worst difference from the CPU's {worst:e} strand lengths");
}
