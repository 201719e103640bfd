//! What surrounds a fur in Pelt's own hosts (`pelt render`, the viewer, the web page): the
//! lights' [`ShadowMap`] and a ground plane under the meshes, each where asked for.

use glam::{Mat4, Vec3};
use pelt_core::sim::SceneGround;
use pelt_core::{FurStructure, Mesh};

use crate::RenderError;
use crate::colliders::ground_mesh;
use crate::plain::PlainMesh;
use crate::renderer::FurRenderer;
use crate::shadows::{MAX_SHADOW_VIEWS, ShadowCaster, ShadowMap, ShadowSettings};
use crate::view::{FurView, ViewData};

/// The ground's colour without a script's (linear RGB): a warm mid grey.
pub const GROUND_COLOUR: Vec3 = Vec3::new(0.34, 0.32, 0.3);

/// The lights' shadow maps and the ground, around one fur and its plain meshes.
#[derive(Debug)]
pub struct Surroundings {
    shadows: Option<ShadowMap>,
    ground: Option<PlainMesh>,
    /// The fur's depth the shadow maps were made for (refitting keeps it).
    fur_length: f32,
    /// Every caster lies within this sphere.
    bounds: (Vec3, f32),
}

impl Surroundings {
    /// Shadows where `shadows`, and a ground where `ground` is given (its unset fields: just
    /// under the meshes, four times their radius wide, [`GROUND_COLOUR`]), around `fur` and
    /// `plain`.
    ///
    /// # Errors
    /// The ground's upload or the shadow maps' [`RenderError`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        shadows: bool,
        ground: Option<&SceneGround>,
        (fur, plain): (&FurStructure, &[Mesh]),
    ) -> Result<Self, RenderError> {
        let fur_length = fur.lengths.iter().copied().fold(0.0f32, f32::max);
        Self::around(device, queue, renderer, (shadows, ground), fur_length, bounds(fur, plain))
    }

    /// [`Surroundings::new`] about the box `(low, high)` (say, a herd's field over a scene)
    /// for a fur whose longest strand is `fur_length`.
    ///
    /// # Errors
    /// As [`Surroundings::new`].
    pub fn around_box(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        (shadows, ground): (bool, Option<&SceneGround>),
        fur_length: f32,
        (low, high): (Vec3, Vec3),
    ) -> Result<Self, RenderError> {
        Self::around(device, queue, renderer, (shadows, ground), fur_length, box_bounds(low, high))
    }

    fn around(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        (shadows, ground): (bool, Option<&SceneGround>),
        fur_length: f32,
        (centre, radius, bottom): (Vec3, f32, f32),
    ) -> Result<Self, RenderError> {
        let ground = ground
            .map(|ground| {
                let size = ground.size.unwrap_or(4.0 * radius);
                let height = ground.height.unwrap_or(bottom - 0.01 * radius);
                let mesh = PlainMesh::new(device, renderer, &ground_mesh(), ground.colour.unwrap_or(GROUND_COLOUR))?;
                let world_from_ground = Mat4::from_translation(Vec3::new(centre.x, height, centre.z))
                    * Mat4::from_scale(Vec3::new(0.5 * size, 1.0, 0.5 * size));
                mesh.prepare(queue, world_from_ground);
                Ok::<_, RenderError>(mesh)
            })
            .transpose()?;
        let fur_length = fur_length.max(1e-3 * radius);
        let shadows =
            shadows.then(|| ShadowMap::new(device, renderer, ShadowSettings::for_fur(fur_length))).transpose()?;
        // Room for the meshes to move a little (a script's motion, the wind).
        Ok(Self { shadows, ground, fur_length, bounds: (centre, 1.25 * radius) })
    }

    /// Fits the shadow maps (if any) to a `width` x `height` picture
    /// ([`crate::fitted_shadow_size`]), making them anew only where their size changes. Call
    /// it before [`Surroundings::prepare`] when the picture's size is known or changes.
    ///
    /// # Errors
    /// The new maps' [`RenderError`].
    pub fn fit_to_frame(
        &mut self,
        device: &wgpu::Device,
        renderer: &FurRenderer,
        (width, height): (u32, u32),
    ) -> Result<(), RenderError> {
        let settings = ShadowSettings::for_frame(self.fur_length, (width, height));
        if let Some(map) = &mut self.shadows
            && map.settings() != settings
        {
            *map = ShadowMap::with_views(device, renderer, settings, map.view_capacity())?;
        }
        Ok(())
    }

    /// Whether the lights cast shadows.
    #[must_use]
    pub fn has_shadows(&self) -> bool {
        self.shadows.is_some()
    }

    /// Whether there is a ground.
    #[must_use]
    pub fn has_ground(&self) -> bool {
        self.ground.is_some()
    }

    /// Aims the shadow maps at every shadowing light of `view` (the picture's view data; suns,
    /// spots and point lights: [`ShadowCaster::for_view`]), making them anew with more light views
    /// where its lights need them, and lights `picture` with them. Call it again when the lights
    /// move.
    ///
    /// # Errors
    /// The new maps' [`RenderError`].
    pub fn prepare(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        renderer: &FurRenderer,
        view: &ViewData,
        picture: &mut FurView,
    ) -> Result<(), RenderError> {
        if let Some(map) = &mut self.shadows {
            let casters = ShadowCaster::for_view(view, self.bounds);
            let needed = casters.iter().map(|(_, caster)| caster.view_count()).sum::<u32>().min(MAX_SHADOW_VIEWS);
            if needed > map.view_capacity() {
                *map = ShadowMap::with_views(device, renderer, map.settings(), needed)?;
            }
            map.prepare(queue, (&casters, view.lights.as_slice().len()), self.bounds);
        }
        picture.set_shadows(self.shadows.as_ref());
        Ok(())
    }

    /// Records the shadow maps (if any): `draw` draws the scene through the view it is given.
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
    box_bounds(low, high)
}

/// A sphere about the box `(low, high)` and its lowest y.
fn box_bounds(low: Vec3, high: Vec3) -> (Vec3, f32, f32) {
    if !(low.is_finite() && high.is_finite()) || low.cmpgt(high).any() {
        return (Vec3::ZERO, 1.0, 0.0);
    }
    let centre = 0.5 * (low + high);
    (centre, (0.5 * (high - low).length()).max(1e-3), low.y)
}
