//! Steps the bunny as `pelt bench --contact` does (L = 32, default preset, a steady wind) with
//! contact `off`, `skin` or `colliders` (first argument) for a few CPU seconds (second), and
//! prints node updates per CPU second: a target for `perf record`, e.g.
//! `RAYON_NUM_THREADS=1 perf record -g target/release/examples/contact_profile skin 3`.
//! `STEPS=n` runs `n` steps instead.
use std::time::Instant;

use glam::{Quat, Vec3};
use pelt_core::sim::{Collider, ContactParams, Shape, Simulation};
use pelt_core::{Builtin, Preset};

fn main() {
    let case = std::env::args().nth(1).unwrap_or_else(|| "skin".into());
    if case.starts_with("tryon") {
        return try_on(&case);
    }
    let mut preset = Preset::default();
    preset.layers = 32;
    let fur = preset.grow(Builtin::Bunny.mesh().0, "bunny").unwrap();
    let mut params = preset.simulation.clone();
    params.contact = ContactParams { skin: case != "off" };
    params.rate_hz = 60.0;
    params.interpolate = false;
    if params.wind.strength == 0.0 {
        params.wind.strength = 0.5;
    }
    let mut sim = Simulation::new(&fur, &params).unwrap();
    if case == "colliders" {
        let (_, radius) = fur.mesh.bounding_sphere();
        let length = fur.lengths.iter().copied().fold(0.0, f32::max);
        let v = fur.vertex_count();
        let colliders: Vec<Collider> = (0..8)
            .map(|i| {
                let j = (i * v) / 8 + v / 16;
                let size = 0.1 * radius;
                let shape = match i % 3 {
                    0 => Shape::Sphere { radius: size },
                    1 => Shape::Capsule { radius: 0.5 * size, half_length: size },
                    _ => Shape::Box { half_extents: Vec3::splat(0.7 * size) },
                };
                let centre = fur.positions[j] + fur.mesh.normals[j] * (0.5 * length + size);
                Collider {
                    appear_secs: 0.0,
                    ..Collider::at(i as u32, shape, 0.0, centre, Quat::from_rotation_y(0.3 * i as f32))
                }
            })
            .collect();
        sim.set_colliders(&colliders).unwrap();
    }
    println!("{} strands", fur.vertex_count());
    let mut t = 0.0;
    for _ in 0..60 {
        t += 1.0 / 60.0;
        sim.step_at(t);
    }
    let secs: f64 = std::env::args().nth(2).and_then(|s| s.parse().ok()).unwrap_or(5.0);
    let start = Instant::now();
    let cpu_start = cpu_secs();
    let mut steps = 0;
    let fixed: Option<usize> = std::env::var("STEPS").ok().and_then(|s| s.parse().ok());
    while fixed.map_or(cpu_secs() - cpu_start < secs, |n| steps < n) {
        t += 1.0 / 60.0;
        sim.step_at(t);
        steps += 1;
    }
    let rate = (steps * fur.vertex_count() * 32) as f64 / (cpu_secs() - cpu_start);
    let _ = start;
    println!("{case}: {rate:.3e} node updates/s");
}

/// CPU seconds this process has run (user + system, every thread): timings that other work on
/// the machine does not stretch.
fn cpu_secs() -> f64 {
    let stat = std::fs::read_to_string("/proc/self/stat").unwrap_or_default();
    let fields: Vec<&str> = stat.rsplit(')').next().unwrap_or("").split_whitespace().collect();
    let ticks = |i: usize| fields.get(i).and_then(|f| f.parse::<f64>().ok()).unwrap_or(0.0);
    (ticks(11) + ticks(12)) / 100.0
}

/// The walking try-on's skirt (`tryon`: the skin; `tryon-body`: and the body's capsules).
fn try_on(case: &str) {
    use pelt_core::{FurStepper, ImportOptions, Stage, StageSource};
    let stage = Stage::load(&StageSource::builtin("tryon").unwrap(), &[], &ImportOptions::default()).unwrap();
    let mut preset = Preset::default();
    preset.layers = 32;
    let fur = preset.grow(stage.fur_mesh.clone(), "tryon").unwrap();
    let mut params = preset.simulation.clone();
    params.contact = ContactParams { skin: true };
    params.rate_hz = 60.0;
    params.interpolate = false;
    let mut stepper = FurStepper::new(&fur, &params).unwrap();
    stepper.set_clip(stage.rig.clone().unwrap(), Some(0));
    if case == "tryon-body" {
        let body = stage.body.as_ref().unwrap();
        stepper.set_body(Some((stage.plain[0].clone(), body.rig.clone(), body.capsules.clone())));
    }
    let steps: usize = std::env::var("STEPS").ok().and_then(|s| s.parse().ok()).unwrap_or(600);
    let mut secs = 0.0;
    for step in 0..steps {
        stepper.advance_to(step as f64 / 60.0).unwrap();
        secs += stepper.simulation().last_step_secs();
    }
    let colliders = stepper.simulation().colliders().len();
    let step = stepper.simulation().contact_step(steps as f64 / 60.0);
    let roots = stepper.simulation().roots();
    let inside = roots.iter().filter(|r| step.colliders.iter().any(|c| c.closest(**r).2 < 0.0)).count();
    let reach = fur.lengths.iter().copied().fold(0.0, f32::max);
    let near = roots.iter().filter(|r| step.colliders.iter().any(|c| c.closest(**r).2 < reach)).count();
    println!("roots inside a capsule {inside}, within a strand length {near}, samples {}", step.colliders.len());
    println!(
        "{case}: {} strands, {colliders} colliders, {:.3e} node updates/s (step time)",
        fur.vertex_count(),
        (steps * fur.vertex_count() * 32) as f64 / secs
    );
}
