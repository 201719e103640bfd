//! The fur on the GPU: the structure, its textures and the renderer, kept in step with the
//! panel (a new mesh or layer count rebuilds the structure, a texture setting the textures).

use glam::Vec3;
use pelt_core::texture::FurTextures;
use pelt_core::{FurStructure, Mesh};
use pelt_render::{Camera, RenderSettings, Renderer, SeparatedRenderer};

use super::camera::OrbitCamera;
use super::viewport::{Viewport, target_format};

/// Colour of a plain (furless) body, linear RGB.
const BODY_COLOUR: Vec3 = Vec3::new(0.6, 0.45, 0.38);
/// Faces per fin of the separated structure (Lengyel's quads).
const SEPARATED_FIN_FACES: u32 = 2;

/// The renderers with what they draw.
#[derive(Debug)]
pub struct FurView {
    renderer: Renderer,
    /// The separated structure of Lengyel et al., built when first shown; it holds the rest pose
    /// (its fins are geometry of their own and do not follow the simulation).
    separated: Option<SeparatedRenderer>,
    /// The furless body both structures draw (the try-on scene's), kept for rebuilding.
    body: Option<Mesh>,
    textures: FurTextures,
    pub settings: RenderSettings,
}

impl FurView {
    pub fn new(gpu: &pelt_render::Gpu, structure: &FurStructure, textures: &FurTextures) -> anyhow::Result<Self> {
        let renderer = Renderer::new(&gpu.device, &gpu.queue, target_format(), structure, textures)?;
        Ok(Self {
            renderer,
            separated: None,
            body: None,
            textures: textures.clone(),
            settings: RenderSettings::default(),
        })
    }

    pub fn set_structure(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        self.separated = None;
        Ok(self.renderer.set_structure(&gpu.device, structure)?)
    }

    pub fn set_textures(&mut self, gpu: &pelt_render::Gpu, textures: &FurTextures) -> anyhow::Result<()> {
        self.separated = None;
        self.textures = textures.clone();
        Ok(self.renderer.set_textures(&gpu.device, &gpu.queue, textures)?)
    }

    /// Replaces the furless body drawn with the fur (the try-on scene's), if any.
    pub fn set_body(&mut self, gpu: &pelt_render::Gpu, body: Option<&Mesh>) -> anyhow::Result<()> {
        self.separated = None;
        self.body = body.cloned();
        self.renderer.clear_plain_meshes();
        if let Some(body) = body {
            self.renderer.add_plain_mesh(&gpu.device, body, BODY_COLOUR)?;
        }
        Ok(())
    }

    /// Builds the separated structure if it is to be drawn and is not there yet.
    pub fn prepare_separated(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        if self.separated.is_none() {
            let mut separated = SeparatedRenderer::new(
                &gpu.device,
                &gpu.queue,
                target_format(),
                structure,
                &self.textures,
                SEPARATED_FIN_FACES,
            )?;
            if let Some(body) = &self.body {
                separated.add_plain_mesh(&gpu.device, body, BODY_COLOUR)?;
            }
            self.separated = Some(separated);
        }
        Ok(())
    }

    /// GPU bytes of the separated geometry, once built.
    pub fn separated_bytes(&self) -> Option<u64> {
        self.separated.as_ref().map(SeparatedRenderer::gpu_bytes)
    }

    /// Uploads this frame's shared vertex array (the simulation's output).
    pub fn set_positions(&self, gpu: &pelt_render::Gpu, positions: &[Vec3]) -> anyhow::Result<()> {
        Ok(self.renderer.update_positions(&gpu.queue, positions)?)
    }

    /// Draws the unified structure, or the separated one when `separated` and it is built.
    pub fn draw(
        &self,
        gpu: &pelt_render::Gpu,
        encoder: &mut wgpu::CommandEncoder,
        viewport: &Viewport,
        camera: &OrbitCamera,
        separated: bool,
    ) {
        let (near, far) = camera.near_far();
        let camera =
            Camera { eye: camera.eye(), target: camera.target, up: Vec3::Y, fov_y_rad: camera.fov_y_rad, near, far };
        let (targets, output) = (&viewport.targets, &viewport.colour_view);
        match self.separated.as_ref().filter(|_| separated) {
            Some(renderer) => renderer.render(&gpu.queue, encoder, targets, output, &camera, &self.settings),
            None => self.renderer.render(&gpu.queue, encoder, targets, output, &camera, &self.settings),
        }
    }
}
