//! The shadows and the ground of Pelt's own pictures and viewer (`--shadows`, `--no-shadows`,
//! `--ground`, a script's `[ground]`): the key light's [`ShadowMap`] and the plane under the
//! meshes.

use anyhow::Context as _;
use glam::{Mat4, Vec3};
use pelt_core::sim::SceneGround;
use pelt_core::{FurStructure, Mesh};
use pelt_render::{FurRenderer, FurView, PlainMesh, ShadowCaster, ShadowMap, ShadowSettings, ViewData, ground_mesh};

/// The ground's colour without a script's (linear RGB): a warm mid grey.
pub const GROUND_COLOUR: Vec3 = Vec3::new(0.34, 0.32, 0.3);

/// The flags every picture-making command shares.
#[derive(Clone, Copy, Debug, Default, clap::Args)]
pub struct ShadowArgs {
    /// The key light casts shadows: the skin, plain meshes, colliders and ground through a
    /// shadow map, the fur through a deep opacity map (it shadows itself and what is below it).
    #[arg(long)]
    pub shadows: bool,
    /// No shadows, even with --ground or a script's [ground].
    #[arg(long, conflicts_with = "shadows")]
    pub no_shadows: bool,
    /// A ground plane under the meshes, taking their shadow (shadows on unless --no-shadows).
    #[arg(long)]
    pub ground: bool,
}

/// What surrounds the fur: the shadow map and the ground, each where asked for.
#[derive(Debug)]
pub struct Surroundings {
    pub shadows: Option<ShadowMap>,
    pub ground: Option<PlainMesh>,
    /// Every caster lies within this sphere.
    bounds: (Vec3, f32),
}

impl Surroundings {
    /// The shadows and ground `args` and the script's `[ground]` ask for, around `fur` and
    /// `plain`.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        args: &ShadowArgs,
        scene_ground: Option<&SceneGround>,
        (fur, plain): (&FurStructure, &[Mesh]),
    ) -> anyhow::Result<Self> {
        let (centre, radius, bottom) = bounds(fur, plain);
        let ground = if args.ground || scene_ground.is_some() {
            let ground = scene_ground.cloned().unwrap_or_default();
            let size = ground.size.unwrap_or(4.0 * radius);
            let height = ground.height.unwrap_or(bottom - 0.01 * radius);
            let mesh = PlainMesh::new(device, renderer, &ground_mesh(), ground.colour.unwrap_or(GROUND_COLOUR))
                .context("uploading the ground")?;
            let world_from_ground = Mat4::from_translation(Vec3::new(centre.x, height, centre.z))
                * Mat4::from_scale(Vec3::new(0.5 * size, 1.0, 0.5 * size));
            mesh.prepare(queue, world_from_ground);
            Some(mesh)
        } else {
            None
        };
        let on = !args.no_shadows && (args.shadows || ground.is_some());
        let fur_length = fur.lengths.iter().copied().fold(0.0f32, f32::max).max(1e-3 * radius);
        let shadows = on
            .then(|| ShadowMap::new(device, renderer, ShadowSettings::for_fur(fur_length)))
            .transpose()
            .context("making the shadow maps")?;
        // Room for the meshes to move a little (a script's motion, the wind).
        Ok(Self { shadows, ground, bounds: (centre, 1.25 * radius) })
    }

    /// Aims the shadow map at the key light of `view` (the picture's view data), and lights
    /// `picture` with it.
    pub fn prepare(&self, queue: &wgpu::Queue, view: &ViewData, picture: &mut FurView) {
        if let Some(map) = &self.shadows {
            map.prepare(queue, &ShadowCaster::Directional { toward_light: view.light_direction_world }, self.bounds);
        }
        picture.set_shadows(self.shadows.as_ref());
    }

    /// Records the shadow map (if any): `draw` draws the scene through the view it is given.
    pub fn record(&self, encoder: &mut wgpu::CommandEncoder, draw: impl FnMut(&mut wgpu::RenderPass<'_>, &FurView)) {
        if let Some(map) = &self.shadows {
            map.record(encoder, draw);
        }
    }

    /// Draws the ground (first: it is opaque).
    pub fn draw_ground(&self, pass: &mut wgpu::RenderPass<'_>, renderer: &FurRenderer, view: &FurView) {
        if let Some(ground) = &self.ground {
            renderer.draw_plain(pass, view, ground);
        }
    }
}

/// A sphere about the fur (its every layer) and the plain meshes, and their lowest y.
fn bounds(fur: &FurStructure, plain: &[Mesh]) -> (Vec3, f32, f32) {
    let points = fur.positions.iter().chain(plain.iter().flat_map(|mesh| mesh.positions.iter()));
    let (low, high) =
        points.fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(low, high), p| (low.min(*p), high.max(*p)));
    if !(low.is_finite() && high.is_finite()) || low.cmpgt(high).any() {
        return (Vec3::ZERO, 1.0, 0.0);
    }
    let centre = 0.5 * (low + high);
    (centre, (0.5 * (high - low).length()).max(1e-3), low.y)
}
