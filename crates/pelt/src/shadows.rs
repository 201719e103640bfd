//! The shadow and ground flags of Pelt's own pictures and viewer (`--shadows`, `--no-shadows`,
//! `--ground`, a script's `[ground]`), made into pelt-render's [`Surroundings`].

use anyhow::Context as _;
use pelt_core::sim::SceneGround;
use pelt_core::{FurStructure, Mesh};
use pelt_render::{FurRenderer, Surroundings};

/// The flags every picture-making command shares.
#[derive(Clone, Copy, Debug, Default, clap::Args)]
pub struct ShadowArgs {
    /// The key light casts shadows (the default): the skin, plain meshes, colliders and ground
    /// through a shadow map, the fur through a deep opacity map (it shadows itself and what is
    /// below it).
    #[arg(long)]
    pub shadows: bool,
    /// No shadows, even with --ground or a script's [ground].
    #[arg(long, conflicts_with = "shadows")]
    pub no_shadows: bool,
    /// A ground plane under the meshes, taking their shadow.
    #[arg(long)]
    pub ground: bool,
}

impl ShadowArgs {
    /// The shadows and ground these flags and the script's `[ground]` ask for, around `fur` and
    /// `plain`, or about the box `extent` (a herd's field) where given: shadows unless
    /// `--no-shadows`.
    pub fn surroundings(
        &self,
        (device, queue, renderer): (&wgpu::Device, &wgpu::Queue, &FurRenderer),
        scene_ground: Option<&SceneGround>,
        (fur, plain): (&FurStructure, &[Mesh]),
        extent: Option<&(glam::Vec3, glam::Vec3)>,
    ) -> anyhow::Result<Surroundings> {
        let ground = (self.ground || scene_ground.is_some()).then(|| scene_ground.cloned().unwrap_or_default());
        let shadows = !self.no_shadows;
        match extent {
            Some(&extent) => {
                let fur_length = fur.lengths.iter().copied().fold(0.0f32, f32::max);
                Surroundings::around_box(device, queue, renderer, (shadows, ground.as_ref()), fur_length, extent)
            }
            None => Surroundings::new(device, queue, renderer, shadows, ground.as_ref(), (fur, plain)),
        }
        .context("making the shadow maps and the ground")
    }
}
