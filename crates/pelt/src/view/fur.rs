//! The fur on the GPU: the structure, its textures and the renderer, kept in step with the
//! panel (a new mesh or layer count rebuilds the structure, a texture setting the textures).

use glam::Vec3;
use pelt_core::FurStructure;
use pelt_core::texture::FurTextures;
use pelt_render::{Camera, RenderSettings, Renderer};

use super::camera::OrbitCamera;
use super::viewport::{Viewport, target_format};

/// The renderer with what it draws.
#[derive(Debug)]
pub struct FurView {
    renderer: Renderer,
    pub settings: RenderSettings,
}

#[allow(dead_code, reason = "touch and the simulation use it as they land in this branch")]
impl FurView {
    pub fn new(gpu: &pelt_render::Gpu, structure: &FurStructure, textures: &FurTextures) -> anyhow::Result<Self> {
        let renderer = Renderer::new(&gpu.device, &gpu.queue, target_format(), structure, textures)?;
        Ok(Self { renderer, settings: RenderSettings::default() })
    }

    pub fn set_structure(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        Ok(self.renderer.set_structure(&gpu.device, structure)?)
    }

    pub fn set_textures(&mut self, gpu: &pelt_render::Gpu, textures: &FurTextures) -> anyhow::Result<()> {
        Ok(self.renderer.set_textures(&gpu.device, &gpu.queue, textures)?)
    }

    /// Uploads this frame's shared vertex array (the simulation's output).
    pub fn set_positions(&self, gpu: &pelt_render::Gpu, positions: &[Vec3]) -> anyhow::Result<()> {
        Ok(self.renderer.update_positions(&gpu.queue, positions)?)
    }

    pub fn draw(
        &self,
        gpu: &pelt_render::Gpu,
        encoder: &mut wgpu::CommandEncoder,
        viewport: &Viewport,
        camera: &OrbitCamera,
    ) {
        let (near, far) = camera.near_far();
        let camera =
            Camera { eye: camera.eye(), target: camera.target, up: Vec3::Y, fov_y_rad: camera.fov_y_rad, near, far };
        self.renderer.render(&gpu.queue, encoder, &viewport.targets, &viewport.colour_view, &camera, &self.settings);
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
