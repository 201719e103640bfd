//! The fur on the GPU: the renderers, the fur, the body and the view, kept in step with the panel
//! (a new mesh or layer count rebuilds the structure, a texture setting the textures).

use glam::{Mat4, Vec3};
use pelt_core::sim::{FurStepper, SceneGround, SimParams};
use pelt_core::texture::FurTextures;
use pelt_core::{FurStructure, Mesh};
use pelt_render::{
    ColliderMeshes, FurDrawSettings, FurDriver, FurFrame, FurLevel, FurRenderer, FurView, HerdDraws, KernelChoice,
    PlainMesh, SeparatedFur, SeparatedRenderer, SimKernel, Studio, Surroundings,
};

use super::camera::OrbitCamera;
use super::herd::{Herd, HerdDrivers, MemberFrame};
use super::shell_share::ShellShare;
use super::viewport::{Viewport, target};
use crate::shadows::ShadowArgs;

/// Colour of a plain (furless) body, linear RGB.
const BODY_COLOUR: Vec3 = Vec3::new(0.6, 0.45, 0.38);
/// Faces per fin of the separated structure (Lengyel's quads).
const SEPARATED_FIN_FACES: u32 = 2;

/// The renderers with what they draw.
#[derive(Debug)]
pub struct FurScene {
    renderer: FurRenderer,
    /// The unified structure on the GPU and the kernel bending it.
    driver: FurDriver,
    /// The separated structure of Lengyel et al. and its pipelines, built when first shown; it
    /// holds the rest pose (its fins are geometry of their own and do not follow the simulation).
    separated: Option<(SeparatedRenderer, SeparatedFur)>,
    /// The furless body both structures are drawn with (the try-on scene's).
    body: Option<PlainMesh>,
    /// The simulation's colliders and the grasp's hand, as they stand.
    colliders: ColliderMeshes,
    view: FurView,
    textures: FurTextures,
    pub settings: FurDrawSettings,
    /// Whether a body's collision capsules are drawn (they would hide the body they stand for).
    pub body_colliders: bool,
    /// The view-angle pass's count, read back for the overlay.
    shell_share: ShellShare,
    /// The camera's plan of a herd's draws (levels of members sharing no pixel).
    herd_plan: HerdDraws,
    /// The shadow maps and the ground, with the (shadows, ground) switches and the herd's box
    /// they were made for; `None` until asked for, and again after a new structure or body.
    surroundings: Option<(SurroundingsFor, Surroundings)>,
    /// A herd's other members (the main fur is the first), and whether the edited fur changed
    /// since they were made.
    herd: Option<HerdDrivers>,
    herd_stale: bool,
}

/// What the surroundings were made for: the shadows and ground switches and a herd's box.
type SurroundingsFor = (bool, bool, Option<(Vec3, Vec3)>);

impl FurScene {
    /// The fur on `gpu`, simulated on the kernel `choice` picks (`auto` times both here), a
    /// herd's copies sharing the GPU's work as `pooling` says.
    pub fn new(
        gpu: &pelt_render::Gpu,
        structure: &FurStructure,
        textures: &FurTextures,
        params: &SimParams,
        (choice, pooling): (KernelChoice, crate::herd::Pooling),
    ) -> anyhow::Result<Self> {
        let mut renderer = FurRenderer::new(&gpu.device, target(&gpu.adapter.get_info()))?;
        pooling.apply(&mut renderer);
        let driver = FurDriver::new(&gpu.device, &gpu.queue, &renderer, structure, textures, params, choice)?;
        let view = FurView::new(&gpu.device, &renderer);
        Ok(Self {
            renderer,
            driver,
            separated: None,
            body: None,
            colliders: ColliderMeshes::new(),
            view,
            textures: textures.clone(),
            settings: FurDrawSettings::SILHOUETTE,
            body_colliders: false,
            shell_share: ShellShare::new(&gpu.device),
            herd_plan: HerdDraws::new(),
            surroundings: None,
            herd: None,
            herd_stale: false,
        })
    }

    /// The kernel bending the fur, and why.
    pub fn kernel(&self) -> (SimKernel, &str) {
        (self.driver.kernel(), self.driver.kernel_reason())
    }

    pub fn set_structure(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        self.separated = None;
        self.surroundings = None;
        self.herd_stale = true;
        self.driver.set_structure(&gpu.device, &gpu.queue, &self.renderer, structure)?;
        Ok(())
    }

    /// Rewrites the painted density, clump and tint in place; a fur first uploaded without a
    /// groom (or textures without keep values) is uploaded groomed once, textures as they are.
    pub fn set_groom(&mut self, gpu: &pelt_render::Gpu, structure: &FurStructure) -> anyhow::Result<()> {
        let Some(groom) = &structure.groom else { return self.set_structure(gpu, structure) };
        self.herd_stale = true;
        if self.driver.set_groom(&gpu.queue, groom).is_err() {
            self.set_structure(gpu, structure)?;
            self.driver.set_textures(&gpu.device, &gpu.queue, &self.renderer, &self.textures)?;
            self.driver.set_groom(&gpu.queue, groom)?;
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
        let kernel = if on { SimKernel::Gpu } else { SimKernel::Cpu };
        if kernel == self.driver.kernel() {
            return Ok(());
        }
        self.driver.set_kernel(&gpu.device, &gpu.queue, &self.renderer, structure, &self.textures, kernel)?;
        // The herd's copies bend on the edited fur's kernel.
        self.herd_stale = true;
        Ok(())
    }

    /// Draws with the preset's `[shading]` from the next frame on (its other looks stay).
    pub fn set_shading(&mut self, preset: &pelt_core::Preset) {
        let look = crate::light_args::preset_look(preset);
        let frame = self.driver.frame();
        if frame.look.shading != look.shading {
            self.driver.set_look(pelt_render::FurLook { shading: look.shading, ..frame.look });
        }
    }

    /// Steps the fur to `time_secs` (its clip at `clip_time_secs`) and writes this frame's state:
    /// the GPU simulation's new steps (a compute pass, submitted now) or the CPU's interpolated
    /// output.
    pub fn advance(
        &mut self,
        gpu: &pelt_render::Gpu,
        stepper: &mut FurStepper,
        time_secs: f64,
        clip_time_secs: f64,
    ) -> anyhow::Result<()> {
        self.driver.advance_with_clip_at(&gpu.device, &gpu.queue, stepper, time_secs, clip_time_secs)?;
        if self.driver.has_steps_to_record() {
            let mut encoder =
                gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("simulation") });
            self.driver.record(&mut encoder)?;
            gpu.queue.submit([encoder.finish()]);
        }
        self.show_colliders(gpu, stepper, time_secs)
    }

    /// Poses the drawn colliders as they stand at `time_secs` (also while paused, so a dragged
    /// ball moves on screen at once).
    pub fn show_colliders(
        &mut self,
        gpu: &pelt_render::Gpu,
        stepper: &FurStepper,
        time_secs: f64,
    ) -> anyhow::Result<()> {
        let simulation = stepper.simulation();
        let shown = stepper.shown_colliders(time_secs, self.body_colliders);
        let plane_half_size = 1.5 * simulation.bounding_radius();
        // The simulation runs in the world (the stepper poses the base with the script's
        // motion), so its colliders are drawn where they are.
        self.colliders.update(&gpu.device, &gpu.queue, &self.renderer, &shown, Mat4::IDENTITY, plane_half_size)?;
        Ok(())
    }

    pub fn set_textures(&mut self, gpu: &pelt_render::Gpu, textures: &FurTextures) -> anyhow::Result<()> {
        self.separated = None;
        self.herd_stale = true;
        self.textures = textures.clone();
        self.driver.set_textures(&gpu.device, &gpu.queue, &self.renderer, textures)?;
        Ok(())
    }

    /// The shadow maps and ground the switches ask for (the script's ground where it has one),
    /// around `structure` and `body`, or about
    /// a herd's box `extent` (made again when a switch or the box changes, or after a new
    /// structure or body).
    pub fn set_surroundings(
        &mut self,
        gpu: &pelt_render::Gpu,
        (structure, body): (&FurStructure, Option<&Mesh>),
        (shadows, ground, scene_ground): (bool, bool, Option<&SceneGround>),
        extent: Option<(Vec3, Vec3)>,
    ) -> anyhow::Result<()> {
        let wanted = (shadows, ground, extent);
        if self.surroundings.as_ref().is_some_and(|(made_for, _)| *made_for == wanted) {
            return Ok(());
        }
        let args = ShadowArgs { shadows, no_shadows: !shadows, ground };
        let plain: Vec<Mesh> = body.into_iter().cloned().collect();
        let surroundings = args.surroundings(
            (&gpu.device, &gpu.queue, &self.renderer),
            scene_ground.filter(|_| ground),
            (structure, &plain),
            extent.as_ref(),
        )?;
        self.surroundings = Some((wanted, surroundings));
        Ok(())
    }

    /// The herd's box the shadow maps were made about, if any.
    pub fn surroundings_extent(&self) -> Option<(Vec3, Vec3)> {
        self.surroundings.as_ref().and_then(|((_, _, extent), _)| *extent)
    }

    /// Makes the herd's other copies (`others` of them; none for one fur) anew when their count
    /// or the edited fur changed.
    pub fn sync_herd(
        &mut self,
        gpu: &pelt_render::Gpu,
        (structure, rig): (&FurStructure, Option<&pelt_core::anim::Rig>),
        params: &SimParams,
        others: usize,
    ) -> anyhow::Result<()> {
        if others == 0 {
            self.herd = None;
        } else if self.herd_stale || self.herd.as_ref().is_none_or(|h| h.len() != others) {
            let kernel = self.driver.kernel();
            let fur = (structure, &self.textures, rig);
            self.herd = Some(HerdDrivers::new(gpu, &self.renderer, fur, (params, kernel), others)?);
        }
        self.herd_stale = false;
        Ok(())
    }

    /// Before the herd's other members step: each bends on its copy's kernel.
    pub fn claim_herd(&mut self, herd: &mut Herd) {
        if let Some(drivers) = &mut self.herd {
            drivers.claim(herd);
        }
    }

    /// Whether a herd bending on the GPU kernel is posed there too.
    pub fn herd_posing(&self) -> bool {
        self.renderer.herd_posing()
    }

    /// The herd's copies on the GPU kernel, of how many, and how many of them the GPU posed.
    pub fn herd_on_gpu(&self) -> (usize, usize, usize) {
        self.herd.as_ref().map_or((0, 0, 0), |drivers| (drivers.on_gpu(), drivers.len(), drivers.posed_on_gpu()))
    }

    /// Shows the herd's members as they stepped this frame: the main fur takes the first
    /// member's tint, the others their steppers' state, level and tint.
    pub fn show_herd(&mut self, gpu: &pelt_render::Gpu, herd: &Herd, frames: &[MemberFrame]) -> anyhow::Result<()> {
        let look = pelt_render::FurLook { tint: herd.instances[0].tint, ..self.driver.frame().look };
        self.driver.set_look(look);
        if let Some(drivers) = &mut self.herd {
            drivers.show(gpu, herd, frames, look)?;
        }
        Ok(())
    }

    /// Replaces the furless body drawn with the fur (the try-on scene's), if any.
    pub fn set_body(&mut self, gpu: &pelt_render::Gpu, body: Option<&Mesh>) -> anyhow::Result<()> {
        self.surroundings = None;
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

    /// Moves the body (the walking try-on's) to this frame's pose and place.
    pub fn pose_body(
        &self,
        gpu: &pelt_render::Gpu,
        positions: &[Vec3],
        normals: &[Vec3],
        world_from_model: Mat4,
    ) -> anyhow::Result<()> {
        if let Some(body) = &self.body {
            body.set_pose(&gpu.queue, positions, normals)?;
            body.prepare(&gpu.queue, world_from_model);
        }
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
        self.driver.fur().gpu_bytes().structure()
    }

    /// GPU bytes of the separated geometry, once built.
    pub fn separated_bytes(&self) -> Option<u64> {
        self.separated.as_ref().map(|(_, fur)| fur.gpu_bytes().structure())
    }

    /// Draws the body and the unified structure, or the separated one when `separated` and it is
    /// built, into the viewport, lit by `studio`, at the level of detail `level`; a herd's
    /// members (`members`, the main fur first; empty for one fur) where seen, farthest first.
    pub fn draw(
        &mut self,
        gpu: &pelt_render::Gpu,
        encoder: &mut wgpu::CommandEncoder,
        viewport: &Viewport,
        (camera, studio): (&OrbitCamera, &Studio),
        (separated, level): (bool, FurLevel),
        members: &[MemberFrame],
    ) {
        let camera = camera.camera();
        let view_data = studio.view_data(&camera, viewport.targets.aspect_ratio());
        self.view.prepare(&gpu.queue, &view_data);
        if let Some((_, surroundings)) = &mut self.surroundings {
            // The window's size: a small window draws small shadow maps. A failure keeps the maps.
            if let Err(problem) = surroundings.fit_to_frame(&gpu.device, &self.renderer, viewport.targets.size()) {
                eprintln!("pelt view: keeping the shadow maps: {problem}");
            }
        }
        let separated = self.separated.as_ref().filter(|_| separated);
        // The separated structure draws with pipelines of its own, which read no shadow maps.
        match self.surroundings.as_mut().map(|(_, s)| s).filter(|_| separated.is_none()) {
            Some(s) => {
                // A failure (more light views than the device holds) draws without shadows.
                if let Err(problem) = s.prepare((&gpu.device, &gpu.queue), &self.renderer, &view_data, &mut self.view) {
                    eprintln!("pelt view: drawing without shadows: {problem}");
                    self.view.set_shadows(None);
                }
            }
            None => self.view.set_shadows(None),
        }
        let surroundings = self.surroundings.as_ref().map(|(_, s)| s).filter(|_| separated.is_none());
        // A herd's members in view, farthest first (blended fur); the main fur is member 0.
        let mut order: Vec<usize> = (0..members.len()).filter(|&k| members[k].seen).collect();
        order.sort_by(|&a, &b| members[b].distance.total_cmp(&members[a].distance));
        let others: Vec<usize> = order.iter().copied().filter(|&k| k > 0).collect();
        let main_drawn = members.is_empty() || order.contains(&0);
        let every_other: Vec<usize> = (1..=self.herd.as_ref().map_or(0, HerdDrivers::len)).collect();
        let herd = self.herd.as_ref().filter(|_| separated.is_none());
        match separated {
            Some((_, fur)) => fur.prepare(&gpu.queue, &FurFrame { level, ..*self.driver.frame() }),
            None => {
                self.driver.set_level(members.first().map_or(level, |m| m.level));
                self.driver.prepare(&gpu.queue);
                self.driver.record_view(encoder, &self.renderer, &self.view);
                if let Some(herd) = herd {
                    herd.record_view(encoder, &self.renderer, &self.view, &others);
                    let planned: Vec<_> = order
                        .iter()
                        .map(|&member| {
                            let fur = if member == 0 { self.driver.fur() } else { herd.fur(member) };
                            (fur, members[member].sphere)
                        })
                        .collect();
                    self.herd_plan.prepare((&gpu.device, &gpu.queue), &self.renderer, &view_data, &planned);
                }
            }
        }
        if let Some(s) = surroundings {
            s.record(encoder, |pass, light| {
                s.draw_ground(pass, &self.renderer, light);
                if let Some(body) = &self.body {
                    self.renderer.draw_plain(pass, light, body);
                }
                self.colliders.draw(pass, &self.renderer, light);
                self.driver.draw(pass, &self.renderer, light, &FurDrawSettings::ALL);
                // Members out of view still cast their shadows.
                if let Some(herd) = herd {
                    herd.draw(pass, &self.renderer, light, (&every_other, &FurDrawSettings::ALL));
                }
            });
        }
        {
            let mut pass = viewport.targets.begin_pass(encoder, &viewport.colour_view, studio.background);
            if let Some(s) = surroundings {
                s.draw_ground(&mut pass, &self.renderer, &self.view);
            }
            if let Some(body) = &self.body {
                self.renderer.draw_plain(&mut pass, &self.view, body);
            }
            self.colliders.draw(&mut pass, &self.renderer, &self.view);
            match (separated, herd) {
                (Some((renderer, fur)), _) => renderer.draw(&mut pass, &self.view, fur, &self.settings),
                (None, Some(herd)) => {
                    let furs: Vec<_> = order
                        .iter()
                        .map(|&member| if member == 0 { self.driver.fur() } else { herd.fur(member) })
                        .collect();
                    self.renderer.draw_herd_planned(&mut pass, &self.view, &self.herd_plan, &furs, &self.settings);
                }
                (None, None) if main_drawn => {
                    self.driver.draw(&mut pass, &self.renderer, &self.view, &self.settings);
                }
                (None, None) => {}
            }
        }
        if separated.is_none() {
            self.shell_share.record(encoder, self.driver.fur());
        }
    }

    /// After the frame's submission: moves the overlay's shell count readback along.
    pub fn after_submit(&mut self) {
        self.shell_share.after_submit();
    }

    /// The share of shell triangles the unified fur drew lately (view-angle LOD), for a mesh of
    /// `faces` triangles; `None` without view-angle LOD.
    pub fn shell_share(&self, faces: u32) -> Option<f64> {
        self.shell_share.share(self.driver.fur(), faces)
    }
}
