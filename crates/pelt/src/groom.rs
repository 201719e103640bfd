//! `pelt groom`: grooms as files. `bake` turns a strand groom (USD hair curves, a preset's
//! `[groom] strands` or `--strands`) into a per-vertex `.groom` file the preset, the viewer and
//! every host read.

use std::path::PathBuf;

use anyhow::{Context as _, bail};
use pelt_core::{Builtin, Preset, Stage};

use crate::mesh_args::MeshArgs;

/// Arguments of `pelt groom`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, clap::Subcommand)]
enum Command {
    /// Bake a strand groom (USD BasisCurves in a .usda) into a per-vertex .groom file.
    Bake(BakeArgs),
}

/// Arguments of `pelt groom bake`.
#[derive(Debug, clap::Args)]
#[command(after_help = "\
Each curve's root is placed at the closest point of the mesh's surface (the mesh taken as Y up in
metres, the stage's upAxis and metersPerUnit applied); length, direction, density, clump and tint
are baked per vertex from the curves near it. The report says how many curves were read, how far
their roots lie from the surface, and how many lie off it (left out). Then name the file in the
preset: `[groom] file = \"NAME.groom\"`, paint over it in `pelt view`, or export it back with
`pelt export ... -o coat.usda`. Example: `pelt groom bake assets/meshes/Fox.glb --preset
fox.toml --strands fox.usda -o fox.groom`.")]
pub struct BakeArgs {
    #[command(flatten)]
    mesh: MeshArgs,
    /// The preset the groom is for (its length, growth direction, strands and colour); its
    /// `[groom] strands` names the curves unless --strands does.
    #[arg(long, value_name = "P")]
    preset: Option<PathBuf>,
    /// The curves (.usda), in place of the preset's `[groom] strands`.
    #[arg(long, value_name = "FILE")]
    strands: Option<PathBuf>,
    /// The groom file to write (default: the curve file's name with .groom, beside it).
    #[arg(short, long, value_name = "FILE")]
    output: Option<PathBuf>,
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    match &args.command {
        Command::Bake(bake) => run_bake(bake),
    }
}

fn run_bake(args: &BakeArgs) -> anyhow::Result<()> {
    let mut preset = match &args.preset {
        Some(path) => Preset::load(path)?,
        None => Preset::default(),
    };
    if let Some(strands) = &args.strands {
        // A path given on the command line is the caller's, not relative to the preset.
        let absolute = std::path::absolute(strands).with_context(|| format!("cannot read {}", strands.display()))?;
        preset.groom.strands = Some(absolute);
        preset.groom.file = None;
    }
    let Some(strands) = preset.groom.strands.clone() else {
        bail!(
            "{}: names no [groom] strands file; give the curves with --strands FILE.usda",
            args.preset.as_ref().map_or_else(|| "the default preset".to_owned(), |p| p.display().to_string())
        );
    };
    let source = args.mesh.source(Builtin::Bunny)?;
    let Stage { fur_mesh: mesh, .. } = args.mesh.stage(Builtin::Bunny, &[])?;
    let (groom, report) = preset.groom_with_report(&mesh, &source.name())?;
    let groom = groom.context("the bake gave no groom")?;
    if let Some(report) = report {
        println!("{report}");
    }
    let output = args.output.clone().unwrap_or_else(|| preset.resolve(&strands).with_extension("groom"));
    if !output.extension().is_some_and(|e| e.eq_ignore_ascii_case("groom")) {
        bail!("{}: the output must end in .groom", output.display());
    }
    groom.save(&output, &mesh)?;
    let bytes = std::fs::metadata(&output).map(|m| m.len()).unwrap_or(0);
    println!(
        "{}: {:.1} kB, a groom for {} ({} vertices); name it in the preset as [groom] file = {:?}",
        output.display(),
        bytes as f64 / 1e3,
        source.name(),
        mesh.vertex_count(),
        output.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default(),
    );
    Ok(())
}
