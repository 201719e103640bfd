//! `pelt view`: the interactive viewer and authoring tool. A winit window drawn with wgpu: the
//! fur in the central area, an egui panel that edits everything live, an overlay with timings
//! and sizes.

mod app;
mod camera;
mod capture;
mod contact;
mod fur;
mod gpu;
mod herd;
mod lights;
mod model;
mod paint;
mod panel;
mod shell_share;
mod ui;
mod ui_layer;
mod viewport;
mod wet;

use std::path::PathBuf;

use anyhow::Context as _;

use crate::mesh_args::MeshArgs;

/// Arguments of `pelt view`.
#[derive(Debug, clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub mesh: MeshArgs,
    /// Draw N frames, save the window's own frame as a PNG to `--out` and exit. Time then advances
    /// by exactly 1/60 s per frame, so runs repeat (used by the tests under Xvfb).
    #[arg(long, value_name = "N", requires = "out")]
    pub screenshot_after: Option<u32>,
    /// Where `--screenshot-after` writes its PNG.
    #[arg(long, value_name = "FILE.png", requires = "screenshot_after")]
    pub out: Option<PathBuf>,
    /// A fur preset (TOML) to start from; the panel edits it, Save writes it back.
    #[arg(long, value_name = "P")]
    pub preset: Option<PathBuf>,
    /// Play a scene script (the simulation's TOML: wind keys and touch strokes in world
    /// coordinates) on the simulation clock.
    #[arg(long, value_name = "SCENE.toml")]
    pub script: Option<PathBuf>,
    /// Start with the overlay (timings, sizes, brush and hints) hidden; O shows it.
    #[arg(long)]
    pub no_overlay: bool,
    /// Where the fur is simulated: the CPU, the GPU (a compute pass), or auto (both timed on
    /// this fur when the window opens, the GPU when clearly faster; a herd: the CPU). A herd's
    /// copies bend where the edited fur does. The panel switches it live.
    #[arg(long, value_enum, default_value_t = crate::sim_kernel::SimChoice::Auto)]
    pub sim: crate::sim_kernel::SimChoice,
    /// How a herd's copies share the GPU's work, as `pelt render --pooling` (auto: pooled on a
    /// GPU: shadow casters, camera draws, GPU steps, the bases skinned on the GPU).
    #[arg(long, value_enum, default_value_t = crate::herd::Pooling::Auto)]
    pub pooling: crate::herd::Pooling,
    /// Every shell and fin segment however small the fur is on screen (the preset's
    /// `[render.lod]` is on by default; the overlay shows the level in use).
    #[arg(long)]
    pub no_lod: bool,
    #[command(flatten)]
    pub shadows: crate::shadows::ShadowArgs,
    #[command(flatten)]
    pub lights: crate::light_args::LightArgs,
    /// A herd: N copies of the fur scattered on a ground, each at its own phase of the clip (a
    /// script's [[instance]] tables place them instead). The panel edits them all; the first is
    /// the one touched and painted.
    #[arg(long, value_name = "N")]
    pub herd: Option<usize>,
    /// Window size in logical pixels, `WIDTHxHEIGHT`.
    #[arg(long, value_name = "WxH", default_value = "1280x800", value_parser = crate::values::parse_size)]
    pub size: (u32, u32),
}

pub fn run(args: &Args) -> anyhow::Result<()> {
    let stage = args.mesh.stage(pelt_core::Builtin::Bunny, &[])?;
    // Files and presets are checked before the display is opened, so their errors come first.
    let mut app = app::App::new(args, stage)?;
    let event_loop = winit::event_loop::EventLoop::new()
        .context("opening the display (is DISPLAY or WAYLAND_DISPLAY set? under CI use xvfb-run)")?;
    event_loop.run_app(&mut app).context("running the window's event loop")?;
    app.finish()
}
