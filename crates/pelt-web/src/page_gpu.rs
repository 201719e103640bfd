//! The page's frame on a GPU device, apart from the canvas: the fur's [`FurDriver`] (the CPU
//! kernel: a page has one thread), the try-on body and one view, drawn with Pelt's [`Studio`]
//! and the model's key light (with its shadows and ground, [`Surroundings`]) into any colour
//! view. The canvas (`gpu`, on `wasm32`) gives it the canvas's sRGB view each
//! frame; a native test gives it a texture of the canvas's format and reads it back.

use glam::{Mat4, Vec3};
use pelt_core::FurTextures;
use pelt_core::sim::SceneGround;
use pelt_render::{
    FurDrawSettings, FurDriver, FurLook, FurRenderer, FurShading, FurTarget, FurView, KernelChoice, PlainMesh,
    RenderTargets, Studio, Surroundings,
};

use crate::herd::HerdGpu;
use crate::model::Model;

/// Colour of the try-on body, linear RGB (the viewer's).
const BODY_COLOUR: Vec3 = Vec3::new(0.6, 0.45, 0.38);

/// What the page draws: the fur as `pelt render` draws it (silhouette fins, Pelt's studio).
pub const PAGE_DRAW: FurDrawSettings = FurDrawSettings::SILHOUETTE;

/// The usages a canvas is configured with: the frame is copied into it.
pub const CANVAS_USAGE: wgpu::TextureUsages =
    wgpu::TextureUsages::RENDER_ATTACHMENT.union(wgpu::TextureUsages::COPY_DST);

/// The format the page draws in for a canvas of `canvas_format`: its sRGB twin. Canvases take
/// only non-sRGB formats, and the fur is shaded in linear light, as everywhere in Pelt; the frame
/// is drawn (and resolved) into a texture of the sRGB format, which encodes on write, and its
/// bytes are copied into the canvas. (Resolving into an sRGB view of the canvas instead, as
/// WebGPU allows, stored linear values in Chromium 156 (Dawn on SwiftShader): the page showed
/// its background at 12/13/15 instead of 60/63/69.)
#[must_use]
pub fn frame_format(canvas_format: wgpu::TextureFormat) -> wgpu::TextureFormat {
    canvas_format.add_srgb_suffix()
}

/// The page's fur, body and view on one device, for canvases of one format.
#[derive(Debug)]
pub struct PageGpu {
    renderer: FurRenderer,
    driver: FurDriver,
    body: Option<PlainMesh>,
    view: FurView,
    /// Depth (and MSAA colour) at the canvas's size; made by [`PageGpu::resize`].
    targets: Option<RenderTargets>,
    /// The frame in the sRGB format, resolved here and copied into the canvas.
    frame: Option<wgpu::Texture>,
    studio: Studio,
    /// The shadow map and ground, made for the (shadows, ground) switches they hold; dropped
    /// when the structure or the body changes.
    surroundings: Option<((bool, bool), Surroundings)>,
    /// The herd scene's other Foxes, made with the textures kept here.
    herd: Option<HerdGpu>,
    textures: FurTextures,
}

impl PageGpu {
    /// Uploads `model`'s fur with `textures` (made with a tile `tile_scale` times smaller than the
    /// preset's) for canvases of `canvas_format` (drawn with 4x MSAA).
    ///
    /// # Errors
    /// The renderer's message (e.g. a structure over the device's limits).
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        canvas_format: wgpu::TextureFormat,
        model: &Model,
        textures: &FurTextures,
        tile_scale: f32,
    ) -> Result<Self, String> {
        let target = FurTarget::new(frame_format(canvas_format));
        let renderer = FurRenderer::new(device, target).map_err(|e| e.to_string())?;
        let mut driver = FurDriver::new(
            device,
            queue,
            &renderer,
            &model.structure,
            textures,
            &model.preset.simulation,
            KernelChoice::Cpu,
        )
        .map_err(|e| e.to_string())?;
        driver.set_look(look(tile_scale));
        driver.prepare(queue);
        let view = FurView::new(device, &renderer);
        let mut gpu = Self {
            renderer,
            driver,
            body: None,
            view,
            targets: None,
            frame: None,
            studio: Studio::default(),
            surroundings: None,
            herd: None,
            textures: textures.clone(),
        };
        gpu.set_body(device, queue, model.body.as_ref())?;
        gpu.set_herd(device, queue, model)?;
        Ok(gpu)
    }

    /// A new rest pose (scene, length or preset changed): the model's structure and body.
    ///
    /// # Errors
    /// The renderer's message.
    pub fn set_structure(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, model: &Model) -> Result<(), String> {
        self.driver.set_structure(device, queue, &self.renderer, &model.structure).map_err(|e| e.to_string())?;
        self.set_body(device, queue, model.body.as_ref())?;
        self.set_herd(device, queue, model)
    }

    /// The herd's other Foxes anew (the herd scene), or none.
    fn set_herd(&mut self, device: &wgpu::Device, queue: &wgpu::Queue, model: &Model) -> Result<(), String> {
        self.herd = match &model.herd {
            Some(herd) => Some(HerdGpu::new(
                (device, queue),
                &self.renderer,
                (&model.structure, &self.textures),
                &model.preset,
                herd.others().len(),
            )?),
            None => None,
        };
        Ok(())
    }

    /// New textures, made with a tile `tile_scale` times smaller than the preset's; `model`'s
    /// herd (if any) is made again with them.
    ///
    /// # Errors
    /// The renderer's message.
    pub fn set_textures(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        model: &Model,
        textures: &FurTextures,
        tile_scale: f32,
    ) -> Result<(), String> {
        self.driver.set_look(look(tile_scale));
        self.driver.set_textures(device, queue, &self.renderer, textures).map_err(|e| e.to_string())?;
        self.textures = textures.clone();
        self.set_herd(device, queue, model)
    }

    fn set_body(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        body: Option<&pelt_core::Mesh>,
    ) -> Result<(), String> {
        self.surroundings = None;
        self.body = match body {
            Some(mesh) => {
                let plain = PlainMesh::new(device, &self.renderer, mesh, BODY_COLOUR).map_err(|e| e.to_string())?;
                plain.prepare(queue, Mat4::IDENTITY);
                Some(plain)
            }
            None => None,
        };
        Ok(())
    }

    /// Makes the attachments for a canvas of `width_px x height_px` (when the size changed).
    ///
    /// # Errors
    /// The renderer's message (a zero or over-limit size).
    pub fn resize(&mut self, device: &wgpu::Device, width_px: u32, height_px: u32) -> Result<(), String> {
        if self.targets.as_ref().is_some_and(|t| t.size() == (width_px, height_px)) {
            return Ok(());
        }
        let target = self.renderer.target();
        let targets = RenderTargets::new(device, target, width_px, height_px).map_err(|e| e.to_string())?;
        self.frame = Some(device.create_texture(&wgpu::TextureDescriptor {
            label: Some("pelt web frame"),
            size: wgpu::Extent3d { width: width_px, height: height_px, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: target.colour_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        }));
        self.targets = Some(targets);
        Ok(())
    }

    /// Advances the model by `frame_secs` of wall time: its clock and touches
    /// ([`Model::tick`]), then the fur through the driver (simulation step and upload) and the
    /// walking try-on body.
    ///
    /// # Errors
    /// The driver's message.
    pub fn advance(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        model: &mut Model,
        frame_secs: f64,
    ) -> Result<(), String> {
        let time_secs = model.tick(frame_secs).map_err(|e| e.to_string())?;
        // The preset's `[shading]`, as `pelt render` draws it.
        let shading = FurShading::from_params(&model.preset.shading);
        let look = self.driver.frame().look;
        if look.shading != shading {
            self.driver.set_look(FurLook { shading, ..look });
        }
        self.driver.advance_to(device, queue, &mut model.stepper, time_secs).map_err(|e| e.to_string())?;
        if let (Some(herd), Some(gpu_herd)) = (&mut model.herd, &mut self.herd) {
            herd.advance_to(time_secs).map_err(|e| e.to_string())?;
            gpu_herd.show(queue, herd.others(), self.driver.frame().look)?;
        }
        // The walking try-on body takes the skirt's clip at the same time.
        if let (Some(body), Some((positions, normals))) = (&self.body, model.pose_body()) {
            body.set_pose(queue, positions, normals).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// Draws `model` from its orbit, copies the frame into `canvas` (a texture of the size last
    /// given to [`PageGpu::resize`], of the canvas format, with [`CANVAS_USAGE`]) and submits.
    ///
    /// # Errors
    /// A message for a canvas of another size or before [`PageGpu::resize`], or the driver's.
    pub fn render(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        model: &Model,
        canvas: &wgpu::Texture,
    ) -> Result<(), String> {
        let (Some(targets), Some(frame)) = (&self.targets, &self.frame) else {
            return Err("the page's frame has no size yet".to_owned());
        };
        if frame.size() != canvas.size() {
            let (w, h) = (canvas.width(), canvas.height());
            return Err(format!("the canvas is {w}x{h}, the frame {}x{}", frame.width(), frame.height()));
        }
        let output = frame.create_view(&wgpu::TextureViewDescriptor::default());
        let switches = (model.light.shadows, model.light.ground);
        if self.surroundings.as_ref().is_none_or(|(made_for, _)| *made_for != switches) {
            let ground = switches.1.then(SceneGround::default);
            let plain: Vec<_> = model.body.iter().cloned().collect();
            let made = match &model.herd {
                // The herd's maps and ground take in the whole field.
                Some(herd) => {
                    let fur_length = model.structure.lengths.iter().copied().fold(0.0, f32::max);
                    let extent = herd.extent(&model.structure);
                    Surroundings::around_box(
                        device,
                        queue,
                        &self.renderer,
                        (switches.0, ground.as_ref()),
                        fur_length,
                        extent,
                    )
                }
                None => Surroundings::new(
                    device,
                    queue,
                    &self.renderer,
                    switches.0,
                    ground.as_ref(),
                    (&model.structure, &plain),
                ),
            }
            .map_err(|e| e.to_string())?;
            self.surroundings = Some((switches, made));
        }
        let Some((_, surroundings)) = &mut self.surroundings else { unreachable!("made just above") };
        surroundings
            .fit_to_frame(device, &self.renderer, (frame.width(), frame.height()))
            .map_err(|e| e.to_string())?;
        let camera = model.orbit.camera();
        self.studio = model.light.studio();
        let view_data = self.studio.view_data(&camera, targets.aspect_ratio());
        self.view.prepare(queue, &view_data);
        surroundings.prepare((device, queue), &self.renderer, &view_data, &mut self.view).map_err(|e| e.to_string())?;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        self.driver.record(&mut encoder).map_err(|e| e.to_string())?;
        self.driver.record_view(&mut encoder, &self.renderer, &self.view);
        if let Some(herd) = &self.herd {
            herd.record_view(&mut encoder, &self.renderer, &self.view);
        }
        let (renderer, driver, body, herd) = (&self.renderer, &self.driver, &self.body, &self.herd);
        // The herd's members farthest first (blended fur); the model's own fur is member 0.
        let mut order: Vec<usize> = (0..=herd.as_ref().map_or(0, HerdGpu::len)).collect();
        if let Some(members) = model.herd.as_ref().map(|h| &h.instances) {
            let distance = |k: usize| members[k].position.distance(camera.eye);
            order.sort_by(|&a, &b| distance(b).total_cmp(&distance(a)));
        }
        surroundings.record(&mut encoder, |pass, light| {
            surroundings.draw_ground(pass, renderer, light);
            if let Some(body) = body {
                renderer.draw_plain(pass, light, body);
            }
            driver.draw(pass, renderer, light, &FurDrawSettings::ALL);
            if let Some(herd) = herd {
                herd.draw_all(pass, (renderer, light));
            }
        });
        {
            let mut pass = targets.begin_pass(&mut encoder, &output, self.studio.background);
            surroundings.draw_ground(&mut pass, renderer, &self.view);
            if let Some(body) = body {
                renderer.draw_plain(&mut pass, &self.view, body);
            }
            for &member in &order {
                match (member, herd) {
                    (0, _) => driver.draw(&mut pass, renderer, &self.view, &PAGE_DRAW),
                    (k, Some(herd)) => herd.draw(k - 1, &mut pass, (renderer, &self.view), &PAGE_DRAW),
                    (_, None) => {}
                }
            }
        }
        // The encoded bytes as they are: the canvas shows its bytes as sRGB.
        encoder.copy_texture_to_texture(frame.as_image_copy(), canvas.as_image_copy(), frame.size());
        queue.submit([encoder.finish()]);
        Ok(())
    }
}

/// Pelt's look, with the shell tile repeated `tile_scale` times more often (the web's tile is
/// that many times smaller, so the strands keep their size on the mesh).
fn look(tile_scale: f32) -> FurLook {
    FurLook { tiles_per_radius: FurLook::default().tiles_per_radius * tile_scale, ..FurLook::default() }
}
