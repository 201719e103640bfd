//! The window and its frame loop (winit's `ApplicationHandler`).

use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::Context as _;
use glam::{Vec2, Vec3};
use pelt_core::mesh::builtin::{TRY_ON_NAME, TryOnScene, try_on_scene};
use pelt_core::sim::{Scene, Simulation};
use pelt_core::{Builtin, FurStructure, FurTextures, Mesh, Preset, PresetError, SeparatedStructure};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::ActiveEventLoop;
use winit::window::{Window, WindowId};

use super::Args;
use super::camera::OrbitCamera;
use super::capture::FrameCopy;
use super::fur::FurView;
use super::gpu::{self, Acquired, WindowSurface};
use super::panel::{self, Changes, MeshChoice, Requests, Settings};
use super::viewport::Viewport;
use crate::format::thousands;

/// Time step of `--screenshot-after` runs, so they repeat exactly.
const FIXED_FRAME_SECS: f64 = 1.0 / 60.0;
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
    fur: FurView,
    /// False while minimised or hidden: no redraws are asked for.
    visible: bool,
}

/// Everything that is not the window: settings, fur, camera, timings.
struct Model {
    settings: Settings,
    mesh_choices: Vec<MeshChoice>,
    /// The mesh from the command line, kept to switch back to.
    file_mesh: Option<Mesh>,
    structure: FurStructure,
    /// The try-on scene's body, drawn without fur under the furry garment.
    body: Option<Mesh>,
    /// GPU bytes of the separated structure while it is shown.
    separated_bytes: Option<u64>,
    camera: OrbitCamera,
    /// Frame the fur once the 3D view's size is known.
    frame_pending: bool,
    /// Size of the 3D view in physical pixels, from the last panel pass.
    viewport_px: [u32; 2],
    clock: Clock,
    frame_time_secs: f64,
    sim: Simulation,
    /// Scripted wind and touch strokes (`--script`), played on the simulation clock.
    scene: Option<Scene>,
    /// Simulation time: advances only while the simulation runs.
    sim_clock_secs: f64,
    /// Smoothed cost of one `advance_to`.
    sim_time_secs: f64,
    touch: Option<TouchDrag>,
    /// Wind strength W restores after turning the wind off.
    wind_strength_on: f32,
    /// Textures made and not yet uploaded.
    textures: Option<FurTextures>,
    /// Texture generation runs off the UI thread, so sliders stay smooth.
    texture_job: Option<std::thread::JoinHandle<Result<FurTextures, PresetError>>>,
    /// The preset changed while a job ran: start another when it ends.
    textures_stale: bool,
    frames_drawn: u32,
    skipped_frames: u32,
    screenshots_saved: u32,
    screenshot_pending: bool,
    quit: bool,
    panel_hidden: bool,
    status: String,
}

/// Wall-clock time, or exactly `FIXED_FRAME_SECS` per frame for repeatable runs.
struct Clock {
    fixed: bool,
    last: Instant,
}

impl Clock {
    /// `(wall seconds since the previous tick, seconds the scene advances)`.
    fn tick(&mut self) -> (f64, f64) {
        let now = Instant::now();
        let wall_secs = (now - self.last).as_secs_f64();
        self.last = now;
        // A long stall (a dragged window, a breakpoint) should not fast-forward the scene.
        (wall_secs, if self.fixed { FIXED_FRAME_SECS } else { wall_secs.min(0.25) })
    }
}

/// A touch in progress: the pointer drags the hit point across the plane facing the camera.
#[derive(Clone, Copy, Debug)]
struct TouchDrag {
    hit: Vec3,
    plane_normal: Vec3,
}

impl App {
    pub fn new(args: &Args, mesh: Mesh, mesh_source: String) -> anyhow::Result<Self> {
        let mut mesh_choices: Vec<MeshChoice> = Builtin::ALL.into_iter().map(MeshChoice::Builtin).collect();
        mesh_choices.push(MeshChoice::TryOn);
        let (choice, file_mesh) = match (&args.mesh.mesh, &args.mesh.builtin) {
            (Some(path), _) => {
                let name = path.file_name().map_or(mesh_source, |n| n.to_string_lossy().into_owned());
                mesh_choices.push(MeshChoice::File(name.clone()));
                (MeshChoice::File(name), Some(mesh.clone()))
            }
            (None, Some(name)) => (MeshChoice::Builtin(Builtin::from_name(name).unwrap_or(Builtin::Bunny)), None),
            (None, None) => (MeshChoice::Builtin(Builtin::Bunny), None),
        };
        let (preset, preset_path) = match &args.preset {
            Some(path) => (Preset::load(path)?, path.display().to_string()),
            None => (Preset::default(), "fur.toml".to_owned()),
        };
        let mut settings = Settings::new(choice, preset, preset_path);
        settings.overlay = !args.no_overlay;
        let structure = grow(mesh, &settings.preset)?;
        let sim = Simulation::new(&structure, &settings.preset.simulation)?;
        // The first textures are made before the window opens, so the first frame has them.
        let textures = settings.preset.generate_textures()?;
        let scene = match &args.script {
            Some(path) => Some(Scene::load(path)?),
            None => None,
        };
        let model = Model {
            settings,
            mesh_choices,
            file_mesh,
            structure,
            body: None,
            separated_bytes: None,
            camera: OrbitCamera::default(),
            frame_pending: true,
            viewport_px: [1, 1],
            clock: Clock { fixed: args.screenshot_after.is_some(), last: Instant::now() },
            frame_time_secs: 0.0,
            sim,
            scene,
            sim_clock_secs: 0.0,
            sim_time_secs: 0.0,
            touch: None,
            wind_strength_on: 1.0,
            textures: Some(textures),
            texture_job: None,
            textures_stale: false,
            frames_drawn: 0,
            skipped_frames: 0,
            screenshots_saved: 0,
            screenshot_pending: false,
            quit: false,
            panel_hidden: false,
            status: String::new(),
        };
        let mut model = model;
        if args.mesh.mesh.is_none() && args.mesh.builtin.as_deref() == Some(TRY_ON_NAME) {
            model.settings.mesh = MeshChoice::TryOn;
            model.apply(Changes { mesh: true, ..Changes::default() })?;
        }
        let screenshot_after = args.screenshot_after.zip(args.out.clone());
        Ok(Self { window_size: args.size, screenshot_after, model, running: None, error: None })
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
        let mut egui_renderer =
            egui_wgpu::Renderer::new(&gpu.device, surface.config.format, egui_wgpu::RendererOptions::default());
        let viewport = Viewport::new(&gpu.device, &mut egui_renderer, [1, 1])?;
        let textures = self.model.textures.take().context("the first textures were made before the window")?;
        let mut fur = FurView::new(&gpu, &self.model.structure, &textures)?;
        fur.set_body(&gpu, self.model.body.as_ref())?;
        Ok(Running { window, gpu, surface, egui_ctx, egui_state, egui_renderer, viewport, fur, visible: true })
    }

    /// One frame: the panel pass, the fur, egui on top, present; a screenshot when due.
    fn redraw(&mut self) -> anyhow::Result<()> {
        let Some(running) = self.running.as_mut() else { return Ok(()) };
        let model = &mut self.model;
        let (wall_secs, frame_secs) = model.clock.tick();
        model.frame_time_secs = smooth(model.frame_time_secs, wall_secs);

        let raw_input = running.egui_state.take_egui_input(&running.window);
        let texture_id = running.viewport.texture_id;
        let mut outcome = (Changes::default(), Requests::default(), Ok(()));
        let mut full_output = running.egui_ctx.run_ui(raw_input, |ui| outcome = model.ui(ui, texture_id));
        // egui's texture changes apply whether or not this frame gets drawn.
        let mut textures_delta = std::mem::take(&mut full_output.textures_delta);
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
        // A bad value from the panel is reported, not fatal: the previous fur stays.
        match model.apply(changes) {
            Ok(true) => {
                running.fur.set_structure(&running.gpu, &model.structure)?;
                running.fur.set_body(&running.gpu, model.body.as_ref())?;
            }
            Ok(false) => {}
            Err(error) => model.status = format!("{error:#}"),
        }
        if let Some(textures) = model.poll_textures() {
            running.fur.set_textures(&running.gpu, &textures)?;
        }
        model.simulate(frame_secs)?;
        running.fur.set_positions(&running.gpu, model.sim.positions())?;
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
        running.viewport.resize(&gpu.device, &mut running.egui_renderer, model.viewport_px)?;

        let mut encoder = gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("frame") });
        running.fur.settings.skin = model.settings.draw.skin;
        running.fur.settings.shells = model.settings.draw.shells;
        running.fur.settings.fins = model.settings.draw.fins;
        let separated = !model.settings.draw.unified;
        if separated {
            running.fur.prepare_separated(gpu, &model.structure)?;
        }
        model.separated_bytes = running.fur.separated_bytes();
        running.fur.draw(gpu, &mut encoder, &running.viewport, &model.camera, separated);

        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [frame.texture.width(), frame.texture.height()],
            pixels_per_point: full_output.pixels_per_point,
        };
        let paint_jobs = running.egui_ctx.tessellate(full_output.shapes, full_output.pixels_per_point);
        let callback_buffers =
            running.egui_renderer.update_buffers(&gpu.device, &gpu.queue, &mut encoder, &paint_jobs, &screen);

        let is_last_scripted_frame =
            self.screenshot_after.as_ref().is_some_and(|(after, _)| model.frames_drawn + 1 >= *after);
        let capture = model.screenshot_pending || is_last_scripted_frame;
        let frame_view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        draw_egui(&mut encoder, &running.egui_renderer, &frame_view, &paint_jobs, &screen);
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
            draw_egui(&mut encoder, &running.egui_renderer, &view, &paint_jobs, &screen);
            Some(FrameCopy::encode(&gpu.device, &mut encoder, &offscreen))
        };
        gpu.queue.submit(callback_buffers.into_iter().chain([encoder.finish()]));
        running.window.pre_present_notify();
        gpu.queue.present(frame);
        model.frames_drawn += 1;

        if let Some(copy) = copy {
            let image = copy.read(&gpu.device)?;
            if is_last_scripted_frame && let Some((_, path)) = &self.screenshot_after {
                image.save(path).with_context(|| format!("writing {}", path.display()))?;
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

impl Model {
    /// The panel, the 3D view with its overlay, and the shortcuts.
    fn ui(&mut self, ui: &mut egui::Ui, texture_id: egui::TextureId) -> (Changes, Requests, anyhow::Result<()>) {
        let mut outcome = (Changes::default(), Requests::default());
        let shortcuts = self.shortcuts(ui.ctx());
        outcome.1.frame |= shortcuts.frame;
        outcome.1.screenshot |= shortcuts.screenshot;
        outcome.1.save_preset |= shortcuts.save_preset;
        if !self.panel_hidden {
            egui::Panel::right("settings").resizable(true).default_size(320.0).min_size(260.0).show(ui, |ui| {
                let (changes, requests) = panel::show(ui, &mut self.settings, &self.mesh_choices, &self.status);
                outcome.0.merge(changes);
                outcome.1.merge(requests);
            });
        }
        outcome.0.simulation |= shortcuts.simulation;
        let view = egui::CentralPanel::no_frame().show(ui, |ui| self.view_3d(ui, texture_id));
        (outcome.0, outcome.1, view.inner)
    }

    /// Keys that act anywhere except while typing into a text field.
    fn shortcuts(&mut self, ctx: &egui::Context) -> ShortcutOutcome {
        let mut outcome = ShortcutOutcome::default();
        if ctx.egui_wants_keyboard_input() {
            return outcome;
        }
        let none = egui::Modifiers::NONE;
        let command = egui::Modifiers::COMMAND;
        ctx.input_mut(|input| {
            let settings = &mut self.settings;
            outcome.frame = input.consume_key(none, egui::Key::F);
            if input.consume_key(none, egui::Key::R) {
                self.camera = OrbitCamera::default();
                outcome.frame = true;
            }
            if input.consume_key(none, egui::Key::Space) {
                settings.simulate = !settings.simulate;
                outcome.simulation = true;
            }
            for (key, toggle) in [
                (egui::Key::Num1, &mut settings.draw.skin),
                (egui::Key::Num2, &mut settings.draw.shells),
                (egui::Key::Num3, &mut settings.draw.fins),
                (egui::Key::O, &mut settings.overlay),
            ] {
                if input.consume_key(none, key) {
                    *toggle = !*toggle;
                }
            }
            if input.consume_key(none, egui::Key::W) {
                let wind = &mut settings.preset.simulation.wind;
                if wind.strength > 0.0 {
                    self.wind_strength_on = wind.strength;
                    wind.strength = 0.0;
                } else {
                    wind.strength = self.wind_strength_on;
                }
                outcome.simulation = true;
            }
            if input.consume_key(none, egui::Key::OpenBracket) {
                settings.brush_per_radius = (settings.brush_per_radius / 1.25).max(0.02);
            }
            if input.consume_key(none, egui::Key::CloseBracket) {
                settings.brush_per_radius = (settings.brush_per_radius * 1.25).min(1.0);
            }
            if input.consume_key(none, egui::Key::U) {
                settings.draw.unified = !settings.draw.unified;
            }
            if input.consume_key(none, egui::Key::H) {
                self.panel_hidden = !self.panel_hidden;
            }
            outcome.screenshot = input.consume_key(command, egui::Key::P);
            outcome.save_preset = input.consume_key(command, egui::Key::S);
            self.quit |= input.consume_key(command, egui::Key::Q);
        });
        outcome
    }
}

#[derive(Debug, Default)]
struct ShortcutOutcome {
    frame: bool,
    screenshot: bool,
    save_preset: bool,
    simulation: bool,
}

impl Model {
    /// The fur image, camera controls and the overlay.
    fn view_3d(&mut self, ui: &mut egui::Ui, texture_id: egui::TextureId) -> anyhow::Result<()> {
        let rect = ui.max_rect();
        let pixels_per_point = ui.ctx().pixels_per_point();
        self.viewport_px =
            [rect.width(), rect.height()].map(|points| (points * pixels_per_point).round().max(1.0) as u32);
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        let painter = ui.painter_at(rect);
        let full_uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
        painter.image(texture_id, rect, full_uv, egui::Color32::WHITE);

        let size = Vec2::new(rect.width(), rect.height()).max(Vec2::ONE);
        if self.frame_pending {
            self.frame(size.x / size.y);
            self.frame_pending = false;
        }
        let modifiers = ui.input(|input| input.modifiers);
        let delta = response.drag_delta();
        let drag = Vec2::new(delta.x, delta.y);
        let primary = response.dragged_by(egui::PointerButton::Primary);
        let pointer = response.hover_pos().or_else(|| response.interact_pointer_pos());
        let ray = pointer.map(|p| self.camera.ray(Vec2::new(p.x - rect.left(), p.y - rect.top()), size));
        let brush_radius = self.settings.brush_per_radius * self.structure.mesh.bounding_sphere().1;
        let hover_hit = ray
            .filter(|_| self.touch.is_none() && !modifiers.alt && !modifiers.shift)
            .and_then(|ray| self.sim.pick(&self.structure.mesh.triangles, ray.origin, ray.direction));

        if response.drag_started_by(egui::PointerButton::Primary)
            && let Some(hit) = hover_hit
        {
            self.sim.touch_begin(hit.point, brush_radius)?;
            let plane_normal = (self.camera.target - self.camera.eye()).normalize_or(Vec3::NEG_Z);
            self.touch = Some(TouchDrag { hit: hit.point, plane_normal });
        }
        if let Some(touch) = self.touch {
            if primary && let Some(ray) = ray {
                let along = ray.direction.dot(touch.plane_normal);
                if along.abs() > 1e-6 {
                    let distance = (touch.hit - ray.origin).dot(touch.plane_normal) / along;
                    self.sim.touch_drag(ray.origin + ray.direction * distance.max(0.0))?;
                }
            } else {
                self.sim.touch_end();
                self.touch = None;
            }
        } else if response.dragged_by(egui::PointerButton::Middle) || (primary && modifiers.shift) {
            self.camera.pan(drag, size.y);
        } else if response.dragged_by(egui::PointerButton::Secondary) || primary {
            self.camera.orbit(drag);
        }
        if response.hovered() {
            let scroll = ui.input(|input| input.smooth_scroll_delta.y);
            if scroll != 0.0 {
                // egui reports about 50 points per wheel notch.
                self.camera.zoom(scroll / 50.0);
            }
        }
        if self.settings.overlay {
            self.brush(&painter, rect, pointer, hover_hit.map(|hit| hit.point), brush_radius);
            self.overlay(&painter, rect);
        }
        Ok(())
    }

    /// The brush under the pointer, sized to the touch radius at the fur it would touch; while
    /// patting, the drag from the hit point.
    fn brush(
        &self,
        painter: &egui::Painter,
        rect: egui::Rect,
        pointer: Option<egui::Pos2>,
        hover: Option<Vec3>,
        radius: f32,
    ) {
        let size = Vec2::new(rect.width(), rect.height()).max(Vec2::ONE);
        let to_screen = |point: Vec3| {
            let ndc = self.camera.clip_from_world(size.x / size.y).project_point3(point);
            egui::pos2(rect.left() + (ndc.x + 1.0) * 0.5 * size.x, rect.top() + (1.0 - ndc.y) * 0.5 * size.y)
        };
        let accent = egui::Color32::from_rgb(255, 190, 90);
        // The simulation's touch, so scripted strokes show as well as the pointer's.
        if let Some(touch) = self.sim.touch().filter(|t| t.released_at_secs.is_none()) {
            let centre = to_screen(touch.point);
            let radius_px = touch.radius * self.camera.px_per_world_at(touch.point, size.y);
            painter.circle_stroke(centre, radius_px, egui::Stroke::new(2.0, accent));
            let end = to_screen(touch.drag);
            painter.line_segment([centre, end], egui::Stroke::new(2.0, accent));
            painter.circle_filled(end, 3.0, accent);
        } else if let (Some(pointer), Some(point)) = (pointer, hover) {
            let radius_px = radius * self.camera.px_per_world_at(point, size.y);
            painter.circle_stroke(pointer, radius_px, egui::Stroke::new(1.5, egui::Color32::from_white_alpha(200)));
            painter.circle_filled(pointer, 2.0, egui::Color32::from_white_alpha(200));
        }
    }

    /// Frame time, simulation time, what is drawn and what it costs on the GPU.
    fn overlay(&self, painter: &egui::Painter, rect: egui::Rect) {
        let draw = self.settings.draw;
        let footprint = if draw.unified {
            self.structure.footprint()
        } else {
            SeparatedStructure { layers: self.structure.layers, fin_faces: 2 }.footprint(&self.structure.mesh)
        };
        let mesh = &self.structure.mesh;
        let base_vertices = mesh.vertex_count() as u64;
        let vertices = if draw.shells || draw.fins { footprint.vertices } else { base_vertices * u64::from(draw.skin) };
        let faces = mesh.triangles.len() as u64 * u64::from(draw.skin)
            + footprint.shell_faces * u64::from(draw.shells)
            + footprint.fin_faces * u64::from(draw.fins);
        // The separated renderer's own count once built (it also holds uvs and normals per vertex).
        let structure_bytes = match self.separated_bytes {
            Some(separated) if !draw.unified => separated,
            _ => footprint.total_bytes(),
        };
        let frame_ms = self.frame_time_secs * 1e3;
        let fps = if self.frame_time_secs > 0.0 { 1.0 / self.frame_time_secs } else { 0.0 };
        let text = format!(
            "frame    {frame_ms:6.2} ms  ({fps:.0} fps)\nsim      {:6.2} ms\nvertices {:>9}\nfaces    {:>9}\nGPU      {:>9}  {} structure\nmesh     {}  L = {}",
            self.sim_time_secs * 1e3,
            thousands(vertices),
            thousands(faces),
            bytes(structure_bytes),
            if draw.unified { "unified" } else { "separated" },
            self.settings.mesh.label(),
            self.structure.layers,
        );
        let galley = painter.layout_no_wrap(text, egui::FontId::monospace(12.0), egui::Color32::from_gray(225));
        let origin = rect.left_top() + egui::vec2(12.0, 12.0);
        painter.rect_filled(
            egui::Rect::from_min_size(origin, galley.size()).expand(6.0),
            4.0,
            egui::Color32::from_black_alpha(150),
        );
        painter.galley(origin, galley, egui::Color32::WHITE);
        let hint = "left-drag: pat  ·  right-drag: orbit  ·  middle or Shift: pan  ·  wheel: zoom  ·  F: frame";
        painter.text(
            rect.center_bottom() - egui::vec2(0.0, 12.0),
            egui::Align2::CENTER_BOTTOM,
            hint,
            egui::FontId::proportional(12.0),
            egui::Color32::from_gray(150),
        );
    }

    /// Looks at the whole fur (mesh plus its longest strand).
    fn frame(&mut self, aspect: f32) {
        let (center, radius) = self.structure.mesh.bounding_sphere();
        let longest = self.structure.lengths.iter().copied().fold(0.0, f32::max);
        // A garment is seen on the whole body wearing it.
        let (center, radius) = match &self.body {
            Some(body) => body.bounding_sphere(),
            None => (center, radius + longest),
        };
        self.camera.frame(center, radius, aspect);
    }

    /// Starts texture generation when the preset changed and none runs; hands over finished
    /// textures.
    fn poll_textures(&mut self) -> Option<FurTextures> {
        let mut done = None;
        if self.texture_job.as_ref().is_some_and(std::thread::JoinHandle::is_finished)
            && let Some(job) = self.texture_job.take()
        {
            match job.join() {
                Ok(Ok(textures)) => {
                    self.status.clear();
                    done = Some(textures);
                }
                Ok(Err(error)) => self.status = error.to_string(),
                Err(_) => self.status = "texture generation failed unexpectedly".to_owned(),
            }
        }
        if self.texture_job.is_none() && self.textures_stale {
            self.textures_stale = false;
            let preset = self.settings.preset.clone();
            self.texture_job = Some(std::thread::spawn(move || preset.generate_textures()));
            self.status = "making textures…".to_owned();
        }
        done
    }

    /// Reads the preset file named in the panel; everything it sets changes.
    fn load_preset(&mut self) -> Changes {
        match Preset::load(&self.settings.preset_path) {
            Ok(preset) => {
                self.settings.preset = preset;
                self.status = format!("loaded {}", self.settings.preset_path);
                Changes { structure: true, textures: true, simulation: true, ..Changes::default() }
            }
            Err(error) => {
                self.status = error.to_string();
                Changes::default()
            }
        }
    }

    fn save_preset(&mut self) {
        self.status = match self.settings.preset.save(&self.settings.preset_path) {
            Ok(()) => format!("saved {}", self.settings.preset_path),
            Err(error) => error.to_string(),
        };
    }

    /// Plays the script and steps the simulation to this frame's time.
    fn simulate(&mut self, frame_secs: f64) -> anyhow::Result<()> {
        if !self.settings.simulate {
            return Ok(());
        }
        self.sim_clock_secs += frame_secs;
        if let Some(scene) = &self.scene {
            scene.apply(self.sim_clock_secs, &mut self.sim)?;
        }
        let start = Instant::now();
        self.sim.advance_to(self.sim_clock_secs);
        self.sim_time_secs = smooth(self.sim_time_secs, start.elapsed().as_secs_f64());
        Ok(())
    }

    /// Rebuilds what the panel's changes touch; true when the structure is new.
    fn apply(&mut self, changes: Changes) -> anyhow::Result<bool> {
        if changes.mesh {
            self.body = None;
            let mesh = match &self.settings.mesh {
                MeshChoice::Builtin(builtin) => builtin.mesh().0,
                MeshChoice::TryOn => {
                    let TryOnScene { garment, body } = try_on_scene(&pelt_core::ImportOptions::default())?;
                    self.body = Some(body);
                    garment
                }
                MeshChoice::File(_) => self.file_mesh.clone().context("the command-line mesh is gone")?,
            };
            self.structure = grow(mesh, &self.settings.preset)?;
            self.frame_pending = true;
        } else if changes.structure {
            self.structure = grow(self.structure.mesh.clone(), &self.settings.preset)?;
        }
        let rebuilt = changes.mesh || changes.structure;
        if rebuilt {
            self.sim = Simulation::new(&self.structure, &self.settings.preset.simulation)?;
            self.touch = None;
        } else if changes.simulation {
            self.sim.set_params(&self.settings.preset.simulation)?;
        }
        if changes.textures {
            self.textures_stale = true;
        }
        Ok(rebuilt)
    }
}

/// Grows the rest pose of the fur on `mesh`.
fn grow(mesh: Mesh, preset: &Preset) -> anyhow::Result<FurStructure> {
    let params = preset.fur_params(&mesh);
    Ok(FurStructure::new(mesh, &params)?)
}

/// Exponential moving average, so the overlay's numbers are readable.
fn smooth(previous: f64, sample: f64) -> f64 {
    if previous == 0.0 { sample } else { previous * 0.9 + sample * 0.1 }
}

fn bytes(value: u64) -> String {
    let value = value as f64;
    if value >= 1024.0 * 1024.0 {
        format!("{:.2} MiB", value / (1024.0 * 1024.0))
    } else {
        format!("{:.1} KiB", value / 1024.0)
    }
}

/// Draws egui (panel, the 3D image, overlay) into `target`.
fn draw_egui(
    encoder: &mut wgpu::CommandEncoder,
    renderer: &egui_wgpu::Renderer,
    target: &wgpu::TextureView,
    paint_jobs: &[egui::ClippedPrimitive],
    screen: &egui_wgpu::ScreenDescriptor,
) {
    let mut pass = encoder
        .begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("egui"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        })
        .forget_lifetime();
    renderer.render(&mut pass, paint_jobs, screen);
}

#[cfg(test)]
mod tests {
    use super::*;

    fn model(args: &[&str]) -> Model {
        #[derive(clap::Parser)]
        struct Wrapper {
            #[command(flatten)]
            args: Args,
        }
        let wrapper = <Wrapper as clap::Parser>::parse_from([&["view"], args].concat());
        let (mesh, report) = wrapper.args.mesh.load(Builtin::Bunny).unwrap();
        App::new(&wrapper.args, mesh, report.source).unwrap().model
    }

    /// One panel pass with `key` pressed.
    fn press(model: &mut Model, key: egui::Key, modifiers: egui::Modifiers) -> (Changes, Requests) {
        let ctx = egui::Context::default();
        let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1000.0, 700.0));
        let events = vec![
            egui::Event::ModifiersChanged(modifiers),
            egui::Event::Key { key, physical_key: None, pressed: true, repeat: false, modifiers },
        ];
        let input = egui::RawInput { screen_rect: Some(screen), events, ..egui::RawInput::default() };
        let mut outcome = None;
        let mut output = ctx.run_ui(input, |ui| outcome = Some(model.ui(ui, egui::TextureId::default())));
        // No GPU here: the font atlas is not uploaded anywhere.
        output.textures_delta.clear();
        let (changes, requests, result) = outcome.unwrap();
        result.unwrap();
        (changes, requests)
    }

    #[test]
    fn shortcuts_reach_the_app_with_the_panel_shown() {
        let mut model = model(&["--builtin", "box"]);
        let none = egui::Modifiers::NONE;
        assert!(press(&mut model, egui::Key::S, egui::Modifiers::COMMAND).1.save_preset);
        assert!(press(&mut model, egui::Key::P, egui::Modifiers::COMMAND).1.screenshot);
        assert!(press(&mut model, egui::Key::F, none).1.frame);
        let (changes, _) = press(&mut model, egui::Key::Space, none);
        assert!(changes.simulation && !model.settings.simulate);
        press(&mut model, egui::Key::U, none);
        assert!(!model.settings.draw.unified);
        let (changes, _) = press(&mut model, egui::Key::W, none);
        assert!(changes.simulation && model.settings.preset.simulation.wind.strength > 0.0);
        press(&mut model, egui::Key::W, none);
        assert_eq!(model.settings.preset.simulation.wind.strength, 0.0);
        let brush = model.settings.brush_per_radius;
        press(&mut model, egui::Key::CloseBracket, none);
        assert!(model.settings.brush_per_radius > brush);
        press(&mut model, egui::Key::H, none);
        assert!(model.panel_hidden);
        // Plain keys do nothing while they type into a text field; here none is focused.
        press(&mut model, egui::Key::Q, egui::Modifiers::COMMAND);
        assert!(model.quit);
    }

    #[test]
    fn panel_changes_rebuild_only_what_they_touch() {
        let mut model = model(&["--builtin", "sphere"]);
        let before = model.structure.positions.clone();
        assert!(!model.apply(Changes { simulation: true, ..Changes::default() }).unwrap());
        assert!(!model.textures_stale, "a simulation change makes no textures");
        model.settings.preset.length *= 2.0;
        assert!(model.apply(Changes { structure: true, ..Changes::default() }).unwrap());
        assert_ne!(model.structure.positions, before);
        assert_eq!(model.sim.positions().len(), model.structure.positions.len());
        assert!(!model.apply(Changes { textures: true, ..Changes::default() }).unwrap());
        assert!(model.textures_stale);
        model.settings.mesh = MeshChoice::TryOn;
        assert!(model.apply(Changes { mesh: true, ..Changes::default() }).unwrap());
        assert!(model.body.is_some() && model.frame_pending);
    }

    #[test]
    fn overlay_numbers_read_well() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(5_032), "5,032");
        assert_eq!(thousands(1_234_567), "1,234,567");
        assert_eq!(bytes(2048), "2.0 KiB");
        assert_eq!(bytes(3 * 1024 * 1024), "3.00 MiB");
    }

    #[test]
    fn growing_scales_the_length_with_the_mesh() {
        let (mesh, _) = Builtin::Sphere.mesh();
        let radius = mesh.bounding_sphere().1;
        let mut preset = Preset::default();
        preset.length = 0.25;
        let fur = grow(mesh, &preset).unwrap();
        assert!(fur.lengths.iter().all(|l| (l - 0.25 * radius).abs() < 1e-5));
        assert_eq!(fur.layers, preset.layers);
    }
}
