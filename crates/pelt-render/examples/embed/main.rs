//! Pelt inside a host app: a winit 0.30 + wgpu window with the host's own scene (ground, box),
//! camera and reverse-Z depth buffer, drawing a simulated furry bunny into its own render pass.
//!
//! ```sh
//! cargo run -p pelt-render --example embed                              # a window
//! cargo run -p pelt-render --example embed -- --screenshot embed.png   # one frame, no window
//! ```

mod scene;

use std::sync::Arc;
use std::time::Instant;

use scene::{Scene, SceneOptions};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::window::{Window, WindowId};

type Error = Box<dyn std::error::Error>;

/// The device a host asks for: Pelt's features and limits on top of its own needs.
fn open_device(adapter: &wgpu::Adapter) -> Result<(wgpu::Device, wgpu::Queue), Error> {
    pelt_render::check_adapter(adapter)?;
    let descriptor = wgpu::DeviceDescriptor {
        label: Some("embed"),
        required_features: pelt_render::required_features() | pelt_render::optional_features(adapter.features()),
        required_limits: pelt_render::required_limits(&wgpu::Limits::default()),
        ..wgpu::DeviceDescriptor::default()
    };
    Ok(pollster::block_on(adapter.request_device(&descriptor))?)
}

/// One frame offscreen, one second into the wind, written as a PNG.
fn screenshot(path: &str) -> Result<(), Error> {
    let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle());
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions::default()))?;
    let (device, queue) = open_device(&adapter)?;
    let format = wgpu::TextureFormat::Rgba8UnormSrgb;
    let mut scene = Scene::new(&device, &queue, format, SceneOptions::default())?;
    scene.advance(&device, &queue, 1.0)?;
    scene.screenshot(&device, &queue, (800, 600), 30.0)?.save(path)?;
    println!("wrote {path}");
    Ok(())
}

struct Running {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    config: wgpu::SurfaceConfiguration,
    device: wgpu::Device,
    queue: wgpu::Queue,
    scene: Scene,
}

struct App {
    started: Instant,
    running: Option<Running>,
    error: Option<Error>,
}

impl App {
    fn start(&self, event_loop: &ActiveEventLoop) -> Result<Running, Error> {
        let attributes = Window::default_attributes().with_title("Pelt embedded in a wgpu app");
        let window = Arc::new(event_loop.create_window(attributes)?);
        let instance = wgpu::Instance::new(wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(
            event_loop.owned_display_handle(),
        )));
        let surface = instance.create_surface(Arc::clone(&window))?;
        let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
            compatible_surface: Some(&surface),
            ..wgpu::RequestAdapterOptions::default()
        }))?;
        let (device, queue) = open_device(&adapter)?;
        let caps = surface.get_capabilities(&adapter);
        let format = caps.formats.iter().copied().find(wgpu::TextureFormat::is_srgb).unwrap_or(caps.formats[0]);
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes[0],
            view_formats: vec![],
        };
        surface.configure(&device, &config);
        let scene = Scene::new(&device, &queue, format, SceneOptions::default())?;
        Ok(Running { window, surface, config, device, queue, scene })
    }

    fn redraw(&mut self) -> Result<(), Error> {
        let Some(running) = self.running.as_mut() else { return Ok(()) };
        let time_secs = self.started.elapsed().as_secs_f64();
        running.scene.advance(&running.device, &running.queue, time_secs)?;
        let frame = match running.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(frame) | wgpu::CurrentSurfaceTexture::Suboptimal(frame) => frame,
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                running.surface.configure(&running.device, &running.config);
                return Ok(());
            }
            _ => return Ok(()),
        };
        let view = frame.texture.create_view(&wgpu::TextureViewDescriptor::default());
        let mut encoder = running.device.create_command_encoder(&wgpu::CommandEncoderDescriptor::default());
        let size = (running.config.width, running.config.height);
        // The camera circles the bunny slowly.
        let azimuth_deg = 30.0 + 12.0 * time_secs as f32;
        running.scene.render(&running.device, &running.queue, &mut encoder, &view, size, azimuth_deg);
        running.queue.submit([encoder.finish()]);
        running.window.pre_present_notify();
        running.queue.present(frame);
        running.window.request_redraw();
        Ok(())
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_none() {
            match self.start(event_loop) {
                Ok(running) => self.running = Some(running),
                Err(error) => {
                    self.error = Some(error);
                    event_loop.exit();
                }
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _window: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(running) = self.running.as_mut()
                    && size.width > 0
                    && size.height > 0
                {
                    running.config.width = size.width;
                    running.config.height = size.height;
                    running.surface.configure(&running.device, &running.config);
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(error) = self.redraw() {
                    self.error = Some(error);
                    event_loop.exit();
                }
            }
            _ => {}
        }
    }
}

fn main() -> Result<(), Error> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [flag, path] if flag == "--screenshot" => return screenshot(path),
        [] => {}
        _ => return Err("usage: embed [--screenshot FILE.png]".into()),
    }
    let mut app = App { started: Instant::now(), running: None, error: None };
    EventLoop::new()?.run_app(&mut app)?;
    app.error.map_or(Ok(()), Err)
}
