//! `pelt`: render, view, measure and author real-time fur.

mod bench;
mod export;
mod export_usd;
mod fidelity;
mod format;
mod groom;
mod herd;
mod light_args;
mod lod;
mod mesh_args;
mod render;
mod shadows;
mod sim_kernel;
mod stats;
mod textures;
mod values;
mod view;

use clap::{Parser, Subcommand};

/// Real-time fur simulation and rendering (shells and fins on one shared vertex array).
#[derive(Debug, Parser)]
#[command(name = "pelt", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Render fur to a PNG, a numbered PNG sequence or a GIF (headless).
    Render(render::Args),
    /// Open the interactive viewer and authoring tool.
    View(view::Args),
    /// Print the paper's Table 2 for a mesh: unified vs separated structure, counts and GPU bytes.
    Stats(stats::Args),
    /// Write a preset's shell and fin textures as PNGs, plus a contact sheet.
    Textures(textures::Args),
    /// Measure how close shells and fins come to the explicit strands they stand for (SSIM).
    Fidelity(fidelity::Args),
    /// Write the fur as a standard glTF file (.glb or .gltf) for other viewers and engines, or
    /// its strands as USD hair curves (.usda) for Blender, Houdini and path tracers.
    Export(export::Args),
    /// Grooms as files: bake a strand groom (USD hair curves) into a per-vertex .groom.
    Groom(groom::Args),
    /// Measure memory, frame time, simulation and texture generation side by side.
    Bench(bench::Args),
}

fn main() -> anyhow::Result<()> {
    match Cli::parse().command {
        Command::Render(args) => render::run(&args),
        Command::View(args) => view::run(&args),
        Command::Stats(args) => stats::run(&args),
        Command::Textures(args) => textures::run(&args),
        Command::Export(args) => export::run(&args),
        Command::Groom(args) => groom::run(&args),
        Command::Bench(args) => bench::run(&args),
        Command::Fidelity(args) => fidelity::run(&args),
    }
}
