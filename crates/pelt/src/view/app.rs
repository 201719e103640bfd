//! The window and its frame loop (winit's `ApplicationHandler`): the GPU, the surface, egui's
//! passes and the fur drawn each frame; the state lives in `model`, the panel in `ui`.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::Context as _;
use pelt_core::Stage;
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::ActiveEventLoop;
use winit::window::{Window, WindowId};

use super::Args;
use super::capture::FrameCopy;
use super::fur::FurScene;
use super::gpu::{self, Acquired, WindowSurface};
use super::model::{Model, smooth};
use super::panel::{Changes, Requests};
use super::ui_layer::UiLayer;
use super::viewport::Viewport;
use pelt_render::SimKernel;

/// Consecutive frames without a swap-chain texture before a scripted run gives up.
const MAX_SKIPPED_FRAMES: u32 = 600;

/// The application: created before the event loop, the window and GPU once it resumes.
pub struct App {
    window_size: [u32; 2],
    screenshot_after: Option<(u32, PathBuf)>,
    model: Model,
    running: Option<Running>,
    error: Option<anyhow::Error>,
}

impl std::fmt::Debug for App {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("App").field("running", &self.running.is_some()).finish_non_exhaustive()
    }
}

/// What needs the window: the GPU, egui's input state and renderer, the 3D target.
struct Running {
    window: Arc<Window>,
    gpu: pelt_render::Gpu,
    surface: WindowSurface,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    egui_renderer: egui_wgpu::Renderer,
    viewport: Viewport,
    /// egui's picture, drawn again only when its output changes.
    ui_layer: UiLayer,
    fur: FurScene,
    /// False while minimised or hidden: no redraws are asked for.
    visible: bool,
}

impl App {
    pub fn new(args: &Args, stage: Stage) -> anyhow::Result<Self> {
        let model = Model::new(args, stage)?;
        let screenshot_after = args.screenshot_after.zip(args.out.clone());
        Ok(Self { window_size: [args.size.0, args.size.1], screenshot_after, model, running: None, error: None })
    }

    /// The error that ended the event loop, if any.
    pub fn finish(self) -> anyhow::Result<()> {
        match self.error {
            Some(error) => Err(error),
            None => Ok(()),
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, error: anyhow::Error) {
        self.error.get_or_insert(error);
        event_loop.exit();
    }

    fn start(&mut self, event_loop: &ActiveEventLoop) -> anyhow::Result<Running> {
        let [width, height] = self.window_size;
        let attributes = Window::default_attributes()
            .with_title("Pelt")
            .with_inner_size(winit::dpi::LogicalSize::new(width, height))
            .with_min_inner_size(winit::dpi::LogicalSize::new(320, 240));
        let window = Arc::new(event_loop.create_window(attributes).context("creating the window")?);
        let (gpu, surface) = gpu::open(&window, event_loop.owned_display_handle())?;
        let egui_ctx = egui::Context::default();
        egui_ctx.set_visuals(egui::Visuals::dark());
        let max_texture_side = gpu.device.limits().max_texture_dimension_2d as usize;
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(max_texture_side),
        );
        let egui_renderer =
            egui_wgpu::Renderer::new(&gpu.device, surface.config.format, egui_wgpu::RendererOptions::default());
        let target = super::viewport::target(&gpu.adapter.get_info());
        let viewport = Viewport::new(&gpu.device, surface.config.format, target)?;
        let ui_layer = UiLayer::new(&gpu.device, surface.config.format);
        let textures = self.model.textures.take().context("the first textures were made before the window")?;
        let model = &mut self.model;
        let params = model.stepper.simulation().params().clone();
        let mut fur =
            FurScene::new(&gpu, &model.structure, &textures, &params, (model.sim_choice.into(), model.pooling))?;
        fur.set_body(&gpu, model.body.as_ref())?;
        let (kernel, reason) = fur.kernel();
        model.settings.gpu_sim = kernel == SimKernel::Gpu;
        model.kernel_reason = match &model.herd {
            Some(_) if kernel == SimKernel::Gpu && fur.herd_posing() => {
                format!("{reason}; a herd posed on the GPU, each copy bent on this kernel")
            }
            Some(_) => format!("{reason}; a herd posed in one parallel pass, each copy bent on this kernel"),
            None => reason.to_owned(),
        };
        Ok(Running {
            window,
            gpu,
            surface,
            egui_ctx,
            egui_state,
            egui_renderer,
            viewport,
            ui_layer,
            fur,
            visible: true,
        })
    }

    /// One frame: the panel pass, the fur, egui on top, present; a screenshot when due.
    fn redraw(&mut self) -> anyhow::Result<()> {
        let Some(running) = self.running.as_mut() else { return Ok(()) };
        let model = &mut self.model;
        let (wall_secs, frame_secs) = model.clock.tick();
        model.frame_time_secs = smooth(model.frame_time_secs, wall_secs);
        model.refresh_shown_times(std::time::Instant::now());

        let raw_input = running.egui_state.take_egui_input(&running.window);
        let mut outcome = (Changes::default(), Requests::default(), Ok(()));
        let mut full_output = running.egui_ctx.run_ui(raw_input, |ui| outcome = model.ui(ui));
        // egui's texture changes apply whether or not this frame gets drawn.
        let mut textures_delta = std::mem::take(&mut full_output.textures_delta);
        let egui_textures_changed = !textures_delta.set.is_empty() || !textures_delta.free.is_empty();
        for (id, deltas) in &textures_delta.set {
            for delta in deltas {
                running.egui_renderer.update_texture(&running.gpu.device, &running.gpu.queue, *id, delta);
            }
        }
        for id in &textures_delta.free {
            running.egui_renderer.free_texture(id);
        }
        textures_delta.clear();
        running.egui_state.handle_platform_output(&running.window, full_output.platform_output);
        outcome.2?;
        let (mut changes, requests) = (outcome.0, outcome.1);
        if requests.load_preset {
            changes.merge(model.load_preset());
        }
        if requests.save_preset {
            model.save_preset();
        }
        if requests.remove_ball
            && let Err(error) = super::contact::remove_ball(model.stepper.simulation_mut())
        {
            model.status = format!("{error:#}");
        }
        if (requests.undo || requests.redo)
            && let Err(error) = model.undo_groom(requests.redo)
        {
            model.status = format!("{error:#}");
        }
        // A bad value from the panel is reported, not fatal: the previous fur stays.
        match model.apply(changes) {
            Ok(true) => {
                running.fur.set_structure(&running.gpu, &model.structure)?;
                running.fur.set_body(&running.gpu, model.body.as_ref())?;
            }
            Ok(false) => {}
            Err(error) => model.status = format!("{error:#}"),
        }
        // A length or direction stroke regrew the rest positions: new vertex buffers, same textures.
        if std::mem::take(&mut model.structure_regrown) {
            running.fur.set_structure(&running.gpu, &model.structure)?;
        }
        if std::mem::take(&mut model.groom_attributes_changed) {
            running.fur.set_groom(&running.gpu, &model.structure)?;
        }
        running.fur.set_gpu_simulation(&running.gpu, &model.structure, model.settings.gpu_sim)?;
        if let Some(textures) = model.poll_textures() {
            running.fur.set_textures(&running.gpu, &textures)?;
        }
        running.fur.set_shading(&model.settings.preset);
        running.fur.body_colliders = model.settings.draw.body_colliders;
        let draw = model.settings.draw;
        let now = model.stepper.simulation().time_secs();
        let extent = model.herd.as_ref().and_then(|herd| {
            super::herd::shadow_extent(&model.structure, herd, now, running.fur.surroundings_extent())
        });
        running.fur.set_surroundings(
            &running.gpu,
            (&model.structure, model.body.as_ref()),
            (draw.shadows, draw.ground, model.stepper.scene().and_then(|s| s.ground.as_ref())),
            extent,
        )?;
        let others = model.herd.as_ref().map_or(0, |herd| herd.len() - 1);
        let rig = model.herd.as_ref().and_then(|herd| herd.followers().first()).and_then(|stepper| stepper.rig());
        let params = model.stepper.simulation().params();
        running.fur.sync_herd(&running.gpu, (&model.structure, rig), params, others)?;
        let members = if let Some((time_secs, clip_secs)) = model.simulate(frame_secs) {
            let members = model.member_frames(time_secs);
            let started = std::time::Instant::now();
            let offset = model.herd.as_ref().map_or(0.0, |herd| herd.instances[0].time_offset_secs);
            running.fur.advance(&running.gpu, &mut model.stepper, time_secs, clip_secs + offset)?;
            if let Some(herd) = &mut model.herd {
                // Far members are stepped less often, as in `pelt render`.
                let strides: Vec<u32> = members[1..].iter().map(|m| m.level.step_stride()).collect();
                running.fur.claim_herd(herd);
                herd.advance(time_secs, clip_secs, &strides)?;
                running.fur.show_herd(&running.gpu, herd, &members)?;
            }
            if let Some((positions, normals, world_from_model)) = model.pose_body(clip_secs) {
                running.fur.pose_body(&running.gpu, positions, normals, world_from_model)?;
            }
            model.took(started.elapsed().as_secs_f64());
            members
        } else {
            // Paused: the colliders still follow what the pointer does to them.
            running.fur.show_colliders(&running.gpu, &model.stepper, now)?;
            model.member_frames(now)
        };
        model.herd_in_view = members.iter().filter(|m| m.seen).count();
        if requests.screenshot {
            model.screenshot_pending = true;
        }
        if requests.frame {
            model.frame_pending = true;
        }

        let frame = match running.surface.acquire(&running.gpu)? {
            Acquired::Frame(frame) => frame,
            Acquired::Skip => {
                model.skipped_frames += 1;
                if self.screenshot_after.is_some() && model.skipped_frames > MAX_SKIPPED_FRAMES {
                    anyhow::bail!("the window gave no frame to draw into {MAX_SKIPPED_FRAMES} times in a row");
                }
                return Ok(());
            }
        };
        model.skipped_frames = 0;
        let gpu = &running.gpu;
        running.viewport.resize(&gpu.device, model.viewport_px)?;

        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        running.fur.settings.skin = model.settings.draw.skin;
        running.fur.settings.shells = model.settings.draw.shells;
        running.fur.settings.fins = model.settings.draw.fins;
        let separated = !model.settings.draw.unified;
        if separated {
            running.fur.prepare_separated(gpu, &model.structure)?;
        }
        model.unified_bytes = Some(running.fur.unified_bytes());
        model.separated_bytes = running.fur.separated_bytes();
        let lod = crate::lod::settings(&model.settings.preset.render.lod, model.no_lod);
        let (eye, fov_y_rad) = (model.camera.eye(), model.camera.fov_y_rad);
        model.level = match members.first() {
            Some(first) => first.level,
            None => crate::lod::level(&lod, &model.structure, eye, fov_y_rad, model.viewport_px[1]),
        };
        let studio = model.settings.lights.studio();
        let shown = (separated, model.level);
        running.fur.draw(gpu, &mut encoder, &running.viewport, (&model.camera, &studio), shown, &members);

        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [frame.texture.width(), frame.texture.height()],
            pixels_per_point: full_output.pixels_per_point,
        };
        let paint_jobs = running.egui_ctx.tessellate(full_output.shapes, full_output.pixels_per_point);
        // egui draws into its layer only when its output differs from the picture there.
        let mut callback_buffers = Vec::new();
        let (size_px, pixels_per_point) = (screen.size_in_pixels, screen.pixels_per_point);
        if egui_textures_changed || !running.ui_layer.holds(&paint_jobs, size_px, pixels_per_point) {
            callback_buffers =
                running.egui_renderer.update_buffers(&gpu.device, &gpu.queue, &mut encoder, &paint_jobs, &screen);
            let layer = running.ui_layer.target(&gpu.device, size_px);
            let clear = wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT);
            draw_egui(&mut encoder, &running.egui_renderer, layer, &paint_jobs, &screen, clear);
            running.ui_layer.keep(&gpu.device, &gpu.queue, &paint_jobs, size_px, pixels_per_point);
        }

        let is_last_scripted_frame =
            self.screenshot_after.as_ref().is_some_and(|(after, _)| model.frames_drawn + 1 >= *after);
        let capture = model.screenshot_pending || is_last_scripted_frame;
        let frame_view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        let compose = |encoder: &mut wgpu::CommandEncoder, target: &wgpu::TextureView| {
            running.viewport.copy_into(encoder, target, screen.size_in_pixels, model.viewport_origin_px);
            running.ui_layer.draw_over(encoder, target);
        };
        compose(&mut encoder, &frame_view);
        let copy = if !capture {
            None
        } else if running.surface.can_copy_frame() {
            Some(FrameCopy::encode(&gpu.device, &mut encoder, &frame.texture))
        } else {
            // The swap chain cannot be read: draw the same frame again into a readable copy.
            let offscreen = gpu.device.create_texture(&wgpu::TextureDescriptor {
                label: Some("screenshot"),
                size: frame.texture.size(),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: frame.texture.format(),
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            });
            let view = offscreen.create_view(&wgpu::TextureViewDescriptor::default());
            compose(&mut encoder, &view);
            Some(FrameCopy::encode(&gpu.device, &mut encoder, &offscreen))
        };
        gpu.queue.submit(callback_buffers.into_iter().chain([encoder.finish()]));
        running.fur.after_submit();
        model.shell_share =
            if separated { None } else { running.fur.shell_share(model.structure.mesh.triangles.len() as u32) };
        running.window.pre_present_notify();
        gpu.queue.present(frame);
        model.frames_drawn += 1;

        if let Some(copy) = copy {
            let image = copy.read(&gpu.device)?;
            if is_last_scripted_frame && let Some((_, path)) = &self.screenshot_after {
                image.save(path).with_context(|| format!("writing {}", path.display()))?;
                // The overlay's figure, for scripts that time the viewer (BENCHMARKS.md).
                let frame_ms = model.frame_time_secs * 1e3;
                println!(
                    "wrote {} after {} frames: frame {frame_ms:.1} ms ({:.1} fps)",
                    path.display(),
                    model.frames_drawn,
                    1e3 / frame_ms
                );
                // Which kernel bent the fur (and a herd's copies): scripts check it.
                let (kernel, _) = running.fur.kernel();
                let (copies_on_gpu, copies, posed) = running.fur.herd_on_gpu();
                println!(
                    "bent on the {kernel} kernel; {copies_on_gpu} of the herd's {copies} other copies on the GPU, \
                     {posed} posed there"
                );
                model.quit = true;
            }
            if model.screenshot_pending {
                model.screenshot_pending = false;
                model.screenshots_saved += 1;
                let path = PathBuf::from(format!("pelt-view-{:03}.png", model.screenshots_saved));
                model.status = match image.save(&path) {
                    Ok(()) => format!("saved {}", path.display()),
                    Err(error) => format!("could not save {}: {error}", path.display()),
                };
            }
        }
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(running) => {
                running.window.request_redraw();
                self.running = Some(running);
            }
            Err(error) => self.fail(event_loop, error),
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _window_id: WindowId, event: WindowEvent) {
        let Some(running) = self.running.as_mut() else { return };
        let response = running.egui_state.on_window_event(&running.window, &event);
        match event {
            WindowEvent::CloseRequested | WindowEvent::Destroyed => {
                // Let go of the surface now: no frame may touch a window that is going away.
                self.running = None;
                event_loop.exit();
            }
            WindowEvent::Resized(size) => {
                running.surface.resize(&running.gpu, size.width, size.height);
                running.visible = size.width > 0 && size.height > 0;
                running.window.request_redraw();
            }
            WindowEvent::Occluded(occluded) => {
                running.visible = !occluded;
                if running.visible {
                    running.window.request_redraw();
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(error) = self.redraw() {
                    self.fail(event_loop, error);
                } else if self.model.quit {
                    event_loop.exit();
                }
            }
            _ => {
                if response.repaint {
                    running.window.request_redraw();
                }
            }
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        // The fur moves all the time (gravity settles, wind blows): draw continuously while
        // visible; scripted runs draw regardless, since Xvfb windows may report as occluded.
        if let Some(running) = &self.running
            && (running.visible || self.screenshot_after.is_some())
        {
            running.window.request_redraw();
        }
    }

    fn exiting(&mut self, _event_loop: &ActiveEventLoop) {
        // Drop GPU resources while the window (and display connection) still exists.
        self.running = None;
    }
}

/// Draws egui (panel, overlay, brush) into `target`, over what `load` leaves there.
pub(super) fn draw_egui(
    encoder: &mut wgpu::CommandEncoder,
    renderer: &egui_wgpu::Renderer,
    target: &wgpu::TextureView,
    paint_jobs: &[egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
    load: wgpu::LoadOp<wgpu::Color>,
) {
    let mut pass = encoder
        .begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
        .forget_lifetime();
    renderer.render(&mut pass, paint_jobs, screen);
}
