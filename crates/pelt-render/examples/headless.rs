//! Mesh to fur to simulation to PNG, without a window:
//! `cargo run -p pelt-render --example headless [-- OUT.png]`.

use glam::Vec3;
use pelt_core::sim::WindParams;
use pelt_core::{Builtin, FurStructure, Preset, Simulation};
use pelt_render::{
    Backend, Camera, DEFAULT_BACKGROUND, FurDrawSettings, FurFrame, FurStates, FurView, GpuFur, Headless, Light,
};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let output = std::env::args().nth(1).unwrap_or_else(|| "pelt-headless.png".to_owned());

    // A mesh (or `pelt_core::Mesh::load` for OBJ and glTF files) and a fur grown from a preset.
    let (mesh, _report) = Builtin::Bunny.mesh();
    let preset = Preset::default();
    let params = preset.fur_params(&mesh);
    let structure = FurStructure::new(mesh, &params)?;
    let textures = preset.generate_textures()?;

    // One second of a steady breeze from the left, simulated on the CPU at 30 frames a second.
    let mut simulation = Simulation::new(&structure, &preset.simulation)?;
    simulation.set_wind(&WindParams { direction: Vec3::X, strength: 1.0, ..preset.simulation.wind.clone() })?;
    for frame in 0..=30 {
        simulation.advance_to(f64::from(frame) / 30.0);
    }

    // A GPU without a window, the pipelines for its target, the fur and a view on it.
    let headless = Headless::new(Backend::Auto, 800, 600)?;
    let (device, queue) = (&headless.gpu.device, &headless.gpu.queue);
    let renderer = headless.renderer()?;
    let fur = GpuFur::new(device, queue, &renderer, &structure, &textures, FurStates::One)?;
    fur.set_positions(queue, simulation.positions())?;
    fur.prepare(queue, &FurFrame::default());
    let (centre, radius) = structure.mesh.bounding_sphere();
    let camera = Camera::framing(centre, radius * 1.1, 30.0, 15.0, headless.aspect_ratio());
    let view = FurView::new(device, &renderer);
    view.prepare(queue, &camera.view_data(headless.aspect_ratio(), &Light::default()));

    // Draw into a pass and read the frame back.
    let image = headless.render_with(
        DEFAULT_BACKGROUND,
        |encoder| renderer.prepare_fins(encoder, &view, &fur),
        |pass| renderer.draw(pass, &view, &fur, &FurDrawSettings::SILHOUETTE),
    )?;
    image.save(&output)?;
    println!("wrote {output} on {}", headless.gpu.summary());
    Ok(())
}
