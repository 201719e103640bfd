//! `pelt bench --load`: where the time to a mesh's first frame goes, phase by phase, in the
//! order every host runs them: the file read and parsed, the mesh repaired (welding, normals,
//! winding), the unified structure grown, the shell and fin textures made, the skin contact's
//! planes and triangles found (only by a coat with skin contact on, `[simulation.contact] skin`),
//! and the fur uploaded to the GPU.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context as _;
use pelt_core::sim::contact::{skin_planes, skin_surface};
use pelt_core::{ImportOptions, Mesh, Preset};
use pelt_render::{Backend, FurRenderer, FurStates, FurTarget, Gpu, GpuFur, HEADLESS_FORMAT};

/// Every mesh file in `meshes_dir` (`.obj`, `.gltf`, `.glb`) and then `extra`, each timed.
pub fn run(meshes_dir: &Path, extra: &[PathBuf]) -> anyhow::Result<()> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(meshes_dir)
        .with_context(|| format!("cannot list {}", meshes_dir.display()))?
        .filter_map(|entry| entry.ok().map(|e| e.path()))
        .filter(|path| {
            path.extension().is_some_and(|e| ["obj", "gltf", "glb"].iter().any(|x| e.eq_ignore_ascii_case(x)))
        })
        .collect();
    files.sort();
    files.extend(extra.iter().cloned());
    let gpu = Gpu::new(Backend::Auto).context("opening a GPU for the upload phase")?;
    let renderer = FurRenderer::new(&gpu.device, FurTarget::new(HEADLESS_FORMAT))?;
    let preset = Preset::default();
    println!(
        "Load phases (ms) with the default preset (L = {}), on {}; skin setup is paid only with skin contact on:\n",
        preset.layers,
        gpu.summary()
    );
    println!("| mesh | triangles | parse | repair | structure | textures | skin setup | GPU upload | total |");
    println!("|---|---:|---:|---:|---:|---:|---:|---:|---:|");
    for path in &files {
        let mut phases = Vec::new();
        let mut time = |started: Instant| {
            phases.push(started.elapsed().as_secs_f64() * 1000.0);
            Instant::now()
        };
        let started = Instant::now();
        let (raw, colour_sets) = Mesh::read_raw(path)?;
        let started = time(started);
        let (mesh, _) = if colour_sets.is_empty() {
            Mesh::from_raw(raw, path, &ImportOptions::default())?
        } else {
            // Colour sets ride through the repair only with `Mesh::load`: parse again inside.
            Mesh::load(path, &ImportOptions::default())?
        };
        let triangles = mesh.triangles.len();
        let name = path.file_name().map_or_else(|| path.display().to_string(), |n| n.to_string_lossy().into_owned());
        let started = time(started);
        let fur = preset.grow(mesh, &name)?;
        let started = time(started);
        let textures = preset.generate_textures()?;
        let started = time(started);
        let planes = skin_planes(&fur);
        std::hint::black_box(skin_surface(&fur, &planes));
        let started = time(started);
        let uploaded = GpuFur::new(&gpu.device, &gpu.queue, &renderer, &fur, &textures, FurStates::One)?;
        gpu.device.poll(wgpu::PollType::wait_indefinitely())?;
        drop(uploaded);
        time(started);
        let total: f64 = phases.iter().sum();
        let cells: Vec<String> = phases.iter().map(|ms| format!("{ms:.0}")).collect();
        println!("| {name} | {triangles} | {} | {total:.0} |", cells.join(" | "));
    }
    Ok(())
}
