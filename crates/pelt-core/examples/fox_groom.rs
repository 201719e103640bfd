//! Paints `assets/presets/fox_groomed.groom`, the groom of `fox_groomed.toml`, from the stroke
//! list `fox_groomed.strokes.toml` with the viewer's brush engine ([`GroomEditor`]): bald nose,
//! eyes and inner ears, a short face and legs, a long tail and chest ruff.
//!
//! `cargo run -p pelt-core --example fox_groom` (deterministic: same bytes every run).

use std::path::Path;

use pelt_core::groom::{GroomEditor, StrokeList};
use pelt_core::{ImportOptions, Mesh, Preset};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let presets = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/presets");
    let (mesh, _) = Mesh::load(&presets.join("../meshes/Fox.glb"), &ImportOptions::default())?;
    // fox.toml's comb is fox_groomed.toml's: what an unpainted direction means.
    let preset = Preset::load(presets.join("fox.toml"))?;
    let strokes = StrokeList::load(&presets.join("fox_groomed.strokes.toml"))?;
    let mut editor = GroomEditor::new(&mesh, None, preset.direction.comb)?;
    strokes.apply(&mut editor);
    let out = presets.join("fox_groomed.groom");
    editor.groom().save(&out, &mesh)?;
    let length = editor.groom().length.as_ref().ok_or("the strokes paint no length")?;
    let bald = length.iter().filter(|l| **l == 0.0).count();
    let longest = length.iter().copied().fold(0.0, f32::max);
    println!(
        "wrote {} ({} strokes; {bald} of {} vertices bald, the longest {longest:.2} x the preset's length)",
        out.display(),
        strokes.strokes.len(),
        length.len()
    );
    Ok(())
}
