//! What one groom brush dab costs while painting, as the viewer pays it: the dab itself (the
//! editor), regrowing the rest positions, the simulation taking the reshaped strands in place
//! (`FurStepper::regroom`), and the GPU upload
//! (length, cut and comb: new vertex buffers, `FurDriver::set_structure`; tint: the per-vertex groom
//! rewritten, `FurDriver::set_groom`; submitted and waited for), on the bunny and the Fox; and,
//! for comparison, the textures a dab does not rebuild. For BENCHMARKS.md:
//! `cargo run --release -p pelt --example stroke_cost` (`DABS=40` dabs per row).

mod profile;

use std::path::Path;
use std::time::Instant;

use glam::Vec3;
use pelt_core::groom::{Brush, BrushKind, Groom, GroomEditor};
use pelt_core::sim::FurStepper;
use pelt_core::{Builtin, FurStructure, ImportOptions, Mesh, Preset};
use pelt_render::{FurDriver, FurRenderer, HEADLESS_FORMAT, KernelChoice};
use profile::{Profile, env_number};

fn main() -> anyhow::Result<()> {
    let profile = Profile::open()?;
    let (device, queue) = (profile.device(), profile.queue());
    println!("{}", profile.describe());
    let renderer = FurRenderer::new(device, profile.target(HEADLESS_FORMAT))?;
    let dabs: usize = env_number("DABS", 40);
    let presets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/presets");
    let fox = Mesh::load(&presets.join("../meshes/Fox.glb"), &ImportOptions::default())?.0;
    let models =
        [("bunny", Builtin::Bunny.mesh().0, Preset::default()), ("Fox", fox, Preset::load(presets.join("fox.toml"))?)];
    println!(
        "model | V | brush | dab ms | regrow ms | simulation ms | GPU upload ms | total ms | textures ms (not rebuilt)"
    );
    for (name, mesh, preset) in models {
        let started = Instant::now();
        let textures = preset.generate_textures()?;
        let textures_ms = started.elapsed().as_secs_f64() * 1e3;
        let params = preset.fur_params(&mesh);
        let radius = mesh.bounding_sphere().1;
        for kind in [BrushKind::Grow, BrushKind::Cut, BrushKind::Comb, BrushKind::Tint] {
            // Groomed from the start (a white tint), as a fur being painted is.
            let groom = Groom { tint: Some(vec![Vec3::ONE; mesh.vertex_count()]), ..Groom::default() };
            let mut structure = FurStructure::new_groomed(mesh.clone(), &params, Some(groom.clone()))?;
            let mut stepper = FurStepper::new(&structure, &preset.simulation)?;
            let mut driver =
                FurDriver::new(device, queue, &renderer, &structure, &textures, &preset.simulation, KernelChoice::Cpu)?;
            let mut editor = GroomEditor::new(&mesh, Some(groom), preset.direction.comb)?;
            let brush = Brush { kind, radius: 0.1 * radius, strength: 0.3, ..Brush::default() };
            // A stroke across the model's vertices, one dab per vertex visited.
            let mut times = [0.0f64; 4];
            editor.begin_stroke();
            for k in 0..dabs {
                let point = mesh.positions[(k * 7919) % mesh.vertex_count()];
                let t0 = Instant::now();
                editor.stroke_to(&brush, point);
                let t1 = Instant::now();
                let reshaped = kind != BrushKind::Tint;
                let mut strands = Vec::new();
                if reshaped {
                    let regrown = FurStructure::new_groomed(mesh.clone(), &params, Some(editor.groom().clone()))?;
                    strands = structure.changed_strands(&regrown);
                    structure = regrown;
                } else {
                    structure.groom = Some(editor.groom().clone());
                }
                let t2 = Instant::now();
                if reshaped {
                    stepper.regroom(&structure, &strands)?;
                }
                let t3 = Instant::now();
                if reshaped {
                    driver.set_structure(device, queue, &renderer, &structure)?;
                } else {
                    driver.set_groom(queue, editor.groom())?;
                }
                queue.submit([]);
                device.poll(wgpu::PollType::wait_indefinitely())?;
                let t4 = Instant::now();
                for (time, (a, b)) in times.iter_mut().zip([(t0, t1), (t1, t2), (t2, t3), (t3, t4)]) {
                    *time += (b - a).as_secs_f64() * 1e3 / dabs as f64;
                }
            }
            editor.end_stroke();
            let total: f64 = times.iter().sum();
            println!(
                "{name} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {total:.3} | {textures_ms:.0}",
                mesh.vertex_count(),
                kind.name(),
                times[0],
                times[1],
                times[2],
                times[3]
            );
        }
    }
    Ok(())
}
