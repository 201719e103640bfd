//! The fur on the GPU: the renderers, the fur, the body and the view, kept in step with the panel
//! (a new mesh or layer count rebuilds the structure, a texture setting the textures).

use glam::{Mat4, Vec3};
use pelt_core::sim::Simulation;
use pelt_core::texture::FurTextures;
use pelt_core::{FurStructure, Mesh};
use pelt_render::{
    Camera, DEFAULT_BACKGROUND, FurDrawSettings, FurFrame, FurLevel, FurRenderer, FurStates, FurView, GpuFur,
    GpuSimulation, Light, PlainMesh, SeparatedFur, SeparatedRenderer,
};

use super::camera::OrbitCamera;
use super::shell_share::ShellShare;
use super::viewport::{Viewport, target};

/// Colour of a plain (furless) body, linear RGB.
const BODY_COLOUR: Vec3 = Vec3::new(0.6, 0.45, 0.38);
/// Faces per fin of the separated structure (Lengyel's quads).
const SEPARATED_FIN_FACES: u32 = 2;

/// The renderers with what they draw.
#[derive(Debug)]
pub struct FurScene {
    renderer: FurRenderer,
    /// The unified structure: with the CPU simulation one state, its interpolated output
    /// uploaded per frame; with the GPU one two states, written by `gpu_sim`'s compute pass and
    /// interpolated in the vertex shader (nothing uploaded per frame).
    fur: GpuFur,
    gpu_sim: Option<GpuSimulation>,
    /// The separated structure of Lengyel et al. and its pipelines, built when first shown; it
    /// holds the rest pose (its fins are geometry of their own and do not follow the simulation).
    separated: Option<(SeparatedRenderer, SeparatedFur)>,
    /// The furless body both structures are drawn with (the try-on scene's).
    body: Option<PlainMesh>,
    view: FurView,
    textures: FurTextures,
    pub settings: FurDrawSettings,
    /// Where this frame falls between the GPU simulation's two states (1 with one state).
    interpolation: f32,
    /// The view-angle pass's count, read back for the overlay.
    shell_share: ShellShare,
}

impl FurScene {
    pub fn new(gpu: &pelt_render::Gpu, structure: &FurStructure, textures: &FurTextures) -> anyhow::Result<Self> {
        let renderer = FurRenderer::new(&gpu.device, target(&gpu.adapter.get_info()))?;
        let fur = GpuFur::new(&gpu.device, &gpu.queue, &renderer, structure, textures, FurStates::One)?;
        fur.prepare(&gpu.queue, &FurFrame::default());
        let view = FurView::new(&gpu.device, &renderer);
        Ok(Self {
            renderer,
            fur,
            gpu_sim: None,
            separated: None,
            body: None,
            view,
            textures: textures.clone(),
            settings: FurDrawSettings::SILHOUETTE,
            interpolation: 1.0,
            shell_share: ShellShare::new(&gpu.device),
        })
    }

    pub fn set_structure(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        self.separated = None;
        self.fur.set_structure(&gpu.device, &self.renderer, structure)?;
        self.fur.prepare(&gpu.queue, &FurFrame::default());
        if self.gpu_sim.is_some() {
            self.gpu_sim = Some(GpuSimulation::new(&gpu.device, &self.fur, structure)?);
        }
        Ok(())
    }

    /// Simulates on the GPU (two states and a compute pass) or not (one state, uploaded).
    pub fn set_gpu_simulation(
        &mut self,
        gpu: &pelt_render::Gpu,
        structure: &FurStructure,
        on: bool,
    ) -> anyhow::Result<()> {
        if on == self.gpu_sim.is_some() {
            return Ok(());
        }
        let states = if on { FurStates::Two } else { FurStates::One };
        self.fur = GpuFur::new(&gpu.device, &gpu.queue, &self.renderer, structure, &self.textures, states)?;
        self.fur.prepare(&gpu.queue, &FurFrame::default());
        self.gpu_sim = if on { Some(GpuSimulation::new(&gpu.device, &self.fur, structure)?) } else { None };
        Ok(())
    }

    /// This frame's shared array: the GPU simulation's new steps (a compute pass, submitted now)
    /// and the interpolation weight, or the CPU simulation's interpolated output uploaded.
    pub fn update(&mut self, gpu: &pelt_render::Gpu, sim: &Simulation) -> anyhow::Result<()> {
        match &mut self.gpu_sim {
            Some(gpu_sim) => {
                gpu_sim.prepare(&gpu.device, &gpu.queue, sim, &self.fur)?;
                if gpu_sim.pending_steps() > 0 {
                    let mut encoder = gpu
                        .device
                        .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("simulation") });
                    gpu_sim.dispatch(&mut encoder, &mut self.fur)?;
                    gpu.queue.submit([encoder.finish()]);
                }
                self.interpolation = sim.alpha();
            }
            None => {
                self.interpolation = 1.0;
                self.fur.set_positions(&gpu.queue, sim.positions())?;
            }
        }
        Ok(())
    }

    pub fn set_textures(&mut self, gpu: &pelt_render::Gpu, textures: &FurTextures) -> anyhow::Result<()> {
        self.separated = None;
        self.textures = textures.clone();
        self.fur.set_textures(&gpu.device, &gpu.queue, &self.renderer, textures)?;
        // The root colour (the skin's) and the slice count live in the fur's uniform.
        self.fur.prepare(&gpu.queue, &FurFrame::default());
        Ok(())
    }

    /// Replaces the furless body drawn with the fur (the try-on scene's), if any.
    pub fn set_body(&mut self, gpu: &pelt_render::Gpu, body: Option<&Mesh>) -> anyhow::Result<()> {
        self.body = match body {
            Some(mesh) => {
                let body = PlainMesh::new(&gpu.device, &self.renderer, mesh, BODY_COLOUR)?;
                body.prepare(&gpu.queue, Mat4::IDENTITY);
                Some(body)
            }
            None => None,
        };
        Ok(())
    }

    /// Builds the separated structure if it is to be drawn and is not there yet.
    pub fn prepare_separated(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        if self.separated.is_none() {
            let renderer = SeparatedRenderer::new(&gpu.device, &self.renderer)?;
            let fur = SeparatedFur::new(
                &gpu.device,
                &gpu.queue,
                &self.renderer,
                structure,
                &self.textures,
                SEPARATED_FIN_FACES,
            )?;
            fur.prepare(&gpu.queue, &FurFrame::default());
            self.separated = Some((renderer, fur));
        }
        Ok(())
    }

    /// GPU bytes of the unified structure as the renderer holds it.
    pub fn unified_bytes(&self) -> u64 {
        self.fur.gpu_bytes().structure()
    }

    /// GPU bytes of the separated geometry, once built.
    pub fn separated_bytes(&self) -> Option<u64> {
        self.separated.as_ref().map(|(_, fur)| fur.gpu_bytes().structure())
    }

    /// Uploads the posed base normals (skin shading of an animated mesh).
    pub fn set_base_normals(&self, gpu: &pelt_render::Gpu, normals: &[Vec3]) -> anyhow::Result<()> {
        Ok(self.fur.set_base_normals(&gpu.queue, normals)?)
    }

    /// Draws the body and the unified structure, or the separated one when `separated` and it is
    /// built, into the viewport, at the level of detail `level`.
    pub fn draw(
        &self,
        gpu: &pelt_render::Gpu,
        encoder: &mut wgpu::CommandEncoder,
        viewport: &Viewport,
        camera: &OrbitCamera,
        separated: bool,
        level: FurLevel,
    ) {
        let (near, far) = camera.near_far();
        let camera =
            Camera { eye: camera.eye(), target: camera.target, up: Vec3::Y, fov_y_rad: camera.fov_y_rad, near, far };
        self.view.prepare(&gpu.queue, &camera.view_data(viewport.targets.aspect_ratio(), &Light::default()));
        let separated = self.separated.as_ref().filter(|_| separated);
        let frame = FurFrame { interpolation: self.interpolation, level, ..FurFrame::default() };
        match separated {
            Some((_, fur)) => fur.prepare(&gpu.queue, &frame),
            None => self.fur.prepare(&gpu.queue, &frame),
        }
        if separated.is_none() {
            self.renderer.prepare_fins(encoder, &self.view, &self.fur);
        }
        {
            let mut pass = viewport.targets.begin_pass(encoder, &viewport.colour_view, DEFAULT_BACKGROUND);
            if let Some(body) = &self.body {
                self.renderer.draw_plain(&mut pass, &self.view, body);
            }
            match separated {
                Some((renderer, fur)) => renderer.draw(&mut pass, &self.view, fur, &self.settings),
                None => self.renderer.draw(&mut pass, &self.view, &self.fur, &self.settings),
            }
        }
        if separated.is_none() {
            self.shell_share.record(encoder, &self.fur);
        }
    }

    /// After the frame's submission: moves the overlay's shell count readback along.
    pub fn after_submit(&mut self) {
        self.shell_share.after_submit();
    }

    /// The share of shell triangles the unified fur drew lately (view-angle LOD), for a mesh of
    /// `faces` triangles; `None` without view-angle LOD.
    pub fn shell_share(&self, faces: u32) -> Option<f64> {
        self.shell_share.share(&self.fur, faces)
    }
}
