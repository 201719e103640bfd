//! Mesh to fur to simulation to PNG, without a window:
//! `cargo run -p pelt-render --example headless [-- OUT.png]`.

use glam::Vec3;
use pelt_core::sim::{FurStepper, SimParams, WindParams};
use pelt_core::{Builtin, FurStructure, Preset};
use pelt_render::{Backend, Camera, FurDrawSettings, FurDriver, FurView, Headless, KernelChoice, Studio};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let output = std::env::args().nth(1).unwrap_or_else(|| "pelt-headless.png".to_owned());

    // A mesh (or `pelt_core::Mesh::load` for OBJ and glTF files) and a fur grown from a preset.
    let (mesh, _report) = Builtin::Bunny.mesh();
    let preset = Preset::default();
    let params = preset.fur_params(&mesh);
    let structure = FurStructure::new(mesh, &params)?;
    let textures = preset.generate_textures()?;

    // A steady breeze from the left.
    let wind = WindParams { direction: Vec3::X, strength: 1.0, ..preset.simulation.wind.clone() };
    let simulation = SimParams { wind, ..preset.simulation.clone() };

    // A GPU without a window, the pipelines for its target, the fur (simulated on the CPU) and a
    // view on it, lit as every Pelt host lights it.
    let headless = Headless::new(Backend::Auto, 800, 600)?;
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer()?;
    let mut driver = FurDriver::new(device, queue, &renderer, &structure, &textures, &simulation, KernelChoice::Cpu)?;
    let mut stepper = FurStepper::new(&structure, &preset.simulation)?;
    stepper.simulation_mut().set_wind(&simulation.wind)?;
    let (centre, radius) = structure.mesh.bounding_sphere();
    let camera = Camera::framing(centre, radius * 1.1, 30.0, 15.0, headless.aspect_ratio());
    let studio = Studio::default();
    let view = FurView::new(device, &renderer);
    view.prepare(queue, &studio.view_data(&camera, headless.aspect_ratio()));

    // One second at 30 frames a second; the last one is drawn into a pass and read back.
    for frame in 0..=30 {
        driver.advance_to(device, queue, &mut stepper, f64::from(frame) / 30.0)?;
    }
    let image = headless.render_with(
        studio.background,
        |encoder| driver.record_view(encoder, &renderer, &view),
        |pass| driver.draw(pass, &renderer, &view, &FurDrawSettings::SILHOUETTE),
    )?;
    image.save(&output)?;
    println!("wrote {output} on {}", headless.gpu.summary());
    Ok(())
}
