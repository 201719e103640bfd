//! What `pelt render` and `pelt view` share about herds: where the members stand (`--herd N` or a
//! script's `[[instance]]`s).

use anyhow::bail;
use pelt_core::Mesh;
use pelt_core::anim::Rig;
use pelt_core::sim::Scene;
use pelt_core::sim::herd::{self, HerdInstance};

/// How a herd's copies share the GPU's work (`--pooling`): the shadow casters of copies made
/// together in one draw a pass, the camera's draws by level, the GPU kernel's steps in one
/// dispatch a step and the bases skinned on the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, clap::ValueEnum)]
pub enum Pooling {
    /// On a discrete or integrated GPU; off on a CPU rasteriser (lavapipe), which runs a copy at
    /// a time as fast and poses faster on the CPU.
    #[default]
    Auto,
    /// Everything pooled, wherever the device (GL keeps the camera's draws a copy at a time).
    On,
    /// A draw, a dispatch and a CPU pose a copy.
    Off,
}

impl Pooling {
    /// `Some(on)` when asked for, `None` for the device's default.
    pub fn forced(self) -> Option<bool> {
        match self {
            Self::Auto => None,
            Self::On => Some(true),
            Self::Off => Some(false),
        }
    }

    /// Sets the renderer's switches (`FurRenderer::set_pooled_casting` and the others).
    pub fn apply(self, renderer: &mut pelt_render::FurRenderer) {
        if let Some(on) = self.forced() {
            renderer.set_pooled_casting(on);
            renderer.set_pooled_stepping(on);
            renderer.set_pooled_drawing(on);
            renderer.set_herd_posing(on);
        }
    }
}

/// The herd to draw: `--herd N` (`count`) scattered, or the script's `[[instance]]`s; none for
/// one fur.
pub fn instances(
    count: Option<usize>,
    scene: Option<&Scene>,
    mesh: &Mesh,
    (rig, clip): (Option<&Rig>, Option<usize>),
) -> anyhow::Result<Vec<HerdInstance>> {
    let scripted = scene.map_or(&[][..], |s| &s.instance[..]);
    match count {
        Some(_) if !scripted.is_empty() => {
            bail!("--herd and the script's [[instance]] tables both place a herd: use one of them")
        }
        Some(count) => {
            // A body length and a half apart, each somewhere in its clip's first loop.
            let (low, high) = mesh.bounds();
            let spacing = 1.5 * (high - low).max_element();
            let phase = clip.and_then(|k| rig.map(|r| f64::from(r.animations()[k].duration_secs()))).unwrap_or(1.0);
            herd::scatter(count, spacing, phase, 0).map_err(|e| anyhow::anyhow!("--herd {count}: {e}"))
        }
        None => Ok(scripted.to_vec()),
    }
}
