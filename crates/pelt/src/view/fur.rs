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
    textures: FurTextures,
    pub settings: RenderSettings,
}

impl FurView {
    pub fn new(gpu: &pelt_render::Gpu, structure: &FurStructure, textures: &FurTextures) -> anyhow::Result<Self> {
        let renderer = Renderer::new(&gpu.device, &gpu.queue, target_format(), structure, textures)?;
        Ok(Self { renderer, separated: None, textures: textures.clone(), settings: RenderSettings::default() })
    }

    pub fn set_structure(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        self.separated = None;
        Ok(self.renderer.set_structure(&gpu.device, structure)?)
    }

    #[allow(dead_code, reason = "the panel regenerates textures once the preset's generator lands here")]
    pub fn set_textures(&mut self, gpu: &pelt_render::Gpu, textures: &FurTextures) -> anyhow::Result<()> {
        self.separated = None;
        self.textures = textures.clone();
        Ok(self.renderer.set_textures(&gpu.device, &gpu.queue, textures)?)
    }

    /// Replaces the furless body drawn with the fur (the try-on scene's), if any.
    pub fn set_body(&mut self, gpu: &pelt_render::Gpu, body: Option<&Mesh>) -> anyhow::Result<()> {
        self.renderer.clear_plain_meshes();
        if let Some(body) = body {
            self.renderer.add_plain_mesh(&gpu.device, body, BODY_COLOUR)?;
        }
        Ok(())
    }

    /// Builds the separated structure if it is to be drawn and is not there yet.
    pub fn prepare_separated(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        if self.separated.is_none() {
            self.separated = Some(SeparatedRenderer::new(
                &gpu.device,
                &gpu.queue,
                target_format(),
                structure,
                &self.textures,
                SEPARATED_FIN_FACES,
            )?);
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

/// A plain seeded strand field (round tapering strands, brown roots to light tips), drawn until
/// the preset's own textures are wired in.
pub fn interim_textures(layers: u32) -> FurTextures {
    const SIZE: u32 = 64;
    let mut shell = vec![0_u8; (SIZE * SIZE * layers * 4) as usize];
    let mut fin = vec![0_u8; (SIZE * layers * 4) as usize];
    for y in 0..SIZE {
        for x in 0..SIZE {
            let bits = pelt_core::rng::hash(7, u64::from(x), u64::from(y), 0);
            if pelt_core::rng::unit_f32(bits) > 0.3 {
                continue;
            }
            let length = 0.6 + 0.4 * pelt_core::rng::unit_f32(pelt_core::rng::mix64(bits));
            for k in 0..layers {
                let height = (k + 1) as f32 / layers as f32;
                if height > length {
                    break;
                }
                let shade = (90.0 + 140.0 * height) as u8;
                let texel = [shade, (f32::from(shade) * 0.75) as u8, (f32::from(shade) * 0.5) as u8, 255];
                let at = (((k * SIZE + y) * SIZE + x) * 4) as usize;
                shell[at..at + 4].copy_from_slice(&texel);
                if y == 0 {
                    // Fin rows run from the tips (row 0) down to the roots.
                    let row = layers - 1 - k;
                    let at = ((row * SIZE + x) * 4) as usize;
                    fin[at..at + 4].copy_from_slice(&texel);
                }
            }
        }
    }
    FurTextures { size: SIZE, layers, shell, fin_width: SIZE, fin_height: layers, fin }
}
