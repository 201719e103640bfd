//! Writes `assets/presets/skirt_trim.groom`, the per-vertex groom of `skirt_trim.toml`: the
//! try-on skirt (`--builtin tryon`) with long fur in a band at its waistband (a collar) and at
//! its hem (cuffs) over a short body, the trims a little lighter and warmer than the body.
//!
//! `cargo run -p pelt-core --example skirt_groom` (deterministic: same bytes every run).

use std::path::Path;

use glam::Vec3;
use pelt_core::ImportOptions;
use pelt_core::groom::Groom;
use pelt_core::{Stage, StageSource};

/// The length factor of the body between the trims.
const BODY: f32 = 0.25;
/// Each trim's width, as a fraction of the skirt's height, and the blend into the body after it.
const TRIM: f32 = 0.12;
const BLEND: f32 = 0.06;

/// How much a point at height fraction `t` (0 = hem, 1 = waistband) belongs to a trim: 1 within
/// `TRIM` of either edge, 0 past `TRIM + BLEND`, smooth between.
fn trim(t: f32) -> f32 {
    let from_edge = t.min(1.0 - t);
    let s = ((TRIM + BLEND - from_edge) / BLEND).clamp(0.0, 1.0);
    s * s * (3.0 - 2.0 * s)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    // The skirt as `--builtin tryon` stages it (fitted to the body), which the groom must match.
    let garment = Stage::load(&StageSource::TryOn, &[], &ImportOptions::default())?.fur_mesh;
    let (low, high) = garment.positions.iter().fold((f32::MAX, f32::MIN), |(l, h), p| (l.min(p.y), h.max(p.y)));
    let trims: Vec<f32> = garment.positions.iter().map(|p| trim((p.y - low) / (high - low))).collect();
    let groom = Groom {
        length: Some(trims.iter().map(|&s| BODY + (1.0 - BODY) * s).collect()),
        tint: Some(trims.iter().map(|&s| Vec3::new(1.0, 0.9, 0.8).lerp(Vec3::ONE, s)).collect()),
        ..Groom::default()
    };
    let file = root.join("assets/presets/skirt_trim.groom");
    groom.save(&file, &garment)?;
    println!("wrote {}", file.display());
    Ok(())
}
