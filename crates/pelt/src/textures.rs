//! `pelt textures`: a preset's shell slices, fin texture and a contact sheet as PNGs.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::Context as _;
use pelt_core::Preset;

/// Arguments of `pelt textures`.
#[derive(Debug, clap::Args)]
pub struct Args {
    /// The fur preset (TOML); the built-in default fur without one.
    #[arg(long)]
    preset: Option<PathBuf>,
    /// Overrides the preset's texture seed (`[texture] seed`).
    #[arg(long)]
    seed: Option<u64>,
    /// Folder for `layer_00.png` ..., `fin.png` and `contact_sheet.png` (created if missing).
    #[arg(long)]
    out: PathBuf,
}

/// Contact-sheet tiles are at most this many texels wide (larger tiles are mip-filtered down).
const SHEET_TILE_MAX: u32 = 256;
/// Dark enough that thin, faint tips still show.
const SHEET_BACKGROUND: [u8; 3] = [22, 22, 26];

pub fn run(args: &Args) -> anyhow::Result<()> {
    let mut preset = match &args.preset {
        Some(path) => Preset::load(path)?,
        None => Preset::default(),
    };
    if let Some(seed) = args.seed {
        preset.texture.seed = seed;
    }
    let started = Instant::now();
    let textures = preset.generate_textures()?;
    let generation_secs = started.elapsed().as_secs_f64();
    std::fs::create_dir_all(&args.out).with_context(|| format!("cannot create {}", args.out.display()))?;

    let digits = textures.layers.saturating_sub(1).to_string().len().max(2);
    for k in 0..textures.layers {
        let path = args.out.join(format!("layer_{k:0digits$}.png"));
        save(&path, textures.slice(k), textures.size, textures.size)?;
    }
    save(&args.out.join("fin.png"), &textures.fin, textures.fin_width, textures.fin_height)?;
    let sheet = textures.contact_sheet(SHEET_TILE_MAX, SHEET_BACKGROUND);
    save(&args.out.join("contact_sheet.png"), &sheet.pixels, sheet.width, sheet.height)?;

    let coverage: Vec<String> = (0..textures.layers).map(|k| format!("{:.2}", textures.coverage(k))).collect();
    // Written, not printed: a closed pipe (`| head`) is an error to report, not a panic.
    let mut out = std::io::stdout().lock();
    writeln!(
        out,
        "{file}: {layers} slices of {size}x{size} texels and a {fin_width}x{fin_height} fin in {ms:.0} ms (seed {seed})",
        file = preset.file().display(),
        layers = textures.layers,
        size = textures.size,
        fin_width = textures.fin_width,
        fin_height = textures.fin_height,
        ms = generation_secs * 1000.0,
        seed = preset.texture.seed,
    )?;
    writeln!(out, "coverage root to tip: {}", coverage.join(" "))?;
    writeln!(out, "wrote {}", args.out.display())?;
    Ok(())
}

fn save(path: &Path, rgba: &[u8], width: u32, height: u32) -> anyhow::Result<()> {
    image::save_buffer(path, rgba, width, height, image::ColorType::Rgba8)
        .with_context(|| format!("cannot write {}", path.display()))
}
