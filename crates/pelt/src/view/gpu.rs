//! The window's GPU: the device (opened by the renderer's rules) and the surface, with the resize, minimise and
//! surface-lost handling a desktop window needs.

use std::sync::Arc;

use anyhow::Context as _;
use pelt_render::Gpu;
use winit::event_loop::OwnedDisplayHandle;
use winit::window::Window;

/// The window's swap chain.
#[derive(Debug)]
pub struct WindowSurface {
    window: Arc<Window>,
    surface: wgpu::Surface<'static>,
    pub config: wgpu::SurfaceConfiguration,
    /// Zero-sized (minimised or collapsed) windows have no swap chain; frames are skipped.
    configured: bool,
}

/// One frame's swap-chain texture, or why there is none this time.
#[derive(Debug)]
pub enum Acquired {
    Frame(wgpu::SurfaceTexture),
    /// Nothing to draw into now (zero size, occluded, timed out); try again on the next redraw.
    Skip,
}

/// Opens a device that can present to `window`, with the limits the fur renderer needs.
pub fn open(window: &Arc<Window>, display: OwnedDisplayHandle) -> anyhow::Result<(Gpu, WindowSurface)> {
    let descriptor = wgpu::InstanceDescriptor::new_with_display_handle_from_env(Box::new(display));
    let instance = wgpu::Instance::new(descriptor);
    let surface = instance.create_surface(Arc::clone(window)).context("creating the window surface")?;
    let adapter = pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
        power_preference: wgpu::PowerPreference::HighPerformance,
        force_fallback_adapter: false,
        compatible_surface: Some(&surface),
        ..wgpu::RequestAdapterOptions::default()
    }))
    .context("no GPU adapter can present to this window (without a GPU: apt-get install mesa-vulkan-drivers)")?;
    let gpu = Gpu::from_adapter(instance, adapter)?;
    let surface = WindowSurface::new(&gpu, Arc::clone(window), surface)?;
    Ok((gpu, surface))
}

impl WindowSurface {
    fn new(gpu: &Gpu, window: Arc<Window>, surface: wgpu::Surface<'static>) -> anyhow::Result<Self> {
        let caps = surface.get_capabilities(&gpu.adapter);
        // egui blends in gamma space, so it prefers a non-sRGB swap chain.
        let format = caps
            .formats
            .iter()
            .copied()
            .find(|f| matches!(f, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Rgba8Unorm))
            .or_else(|| caps.formats.first().copied())
            .context("the window surface supports no texture format")?;
        // Reading the frame back for screenshots needs COPY_SRC; without it screenshots draw the
        // same frame into an offscreen copy.
        let usage = wgpu::TextureUsages::RENDER_ATTACHMENT | (caps.usages & wgpu::TextureUsages::COPY_SRC);
        let size = window.inner_size();
        let config = wgpu::SurfaceConfiguration {
            usage,
            format,
            color_space: wgpu::SurfaceColorSpace::Auto,
            width: size.width.max(1),
            height: size.height.max(1),
            present_mode: wgpu::PresentMode::AutoVsync,
            desired_maximum_frame_latency: 2,
            alpha_mode: caps.alpha_modes.first().copied().unwrap_or(wgpu::CompositeAlphaMode::Auto),
            view_formats: vec![],
        };
        let mut this = Self { window, surface, config, configured: false };
        this.resize(gpu, size.width, size.height);
        Ok(this)
    }

    /// Whether frames can be read back straight from the swap chain.
    pub fn can_copy_frame(&self) -> bool {
        self.config.usage.contains(wgpu::TextureUsages::COPY_SRC)
    }

    /// Follows the window's size; a zero width or height leaves the surface unconfigured.
    pub fn resize(&mut self, gpu: &Gpu, width_px: u32, height_px: u32) {
        if width_px == 0 || height_px == 0 {
            self.configured = false;
            return;
        }
        self.config.width = width_px;
        self.config.height = height_px;
        self.surface.configure(&gpu.device, &self.config);
        self.configured = true;
    }

    /// The next swap-chain texture, reconfiguring or recreating the surface when the platform
    /// says it is outdated or lost.
    pub fn acquire(&mut self, gpu: &Gpu) -> anyhow::Result<Acquired> {
        let size = self.window.inner_size();
        if size.width != self.config.width || size.height != self.config.height || !self.configured {
            self.resize(gpu, size.width, size.height);
        }
        if !self.configured {
            return Ok(Acquired::Skip);
        }
        for _attempt in 0..2 {
            match self.surface.get_current_texture() {
                wgpu::CurrentSurfaceTexture::Success(frame) => return Ok(Acquired::Frame(frame)),
                wgpu::CurrentSurfaceTexture::Suboptimal(frame) => {
                    // Draw this one; the next acquire reconfigures (after the texture is dropped).
                    self.configured = false;
                    return Ok(Acquired::Frame(frame));
                }
                wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                    return Ok(Acquired::Skip);
                }
                wgpu::CurrentSurfaceTexture::Outdated => self.surface.configure(&gpu.device, &self.config),
                wgpu::CurrentSurfaceTexture::Lost => {
                    self.surface = gpu
                        .instance
                        .create_surface(Arc::clone(&self.window))
                        .context("recreating the lost window surface")?;
                    self.surface.configure(&gpu.device, &self.config);
                }
                wgpu::CurrentSurfaceTexture::Validation => {
                    anyhow::bail!("the GPU rejected the window surface (validation error)")
                }
            }
        }
        Ok(Acquired::Skip)
    }
}
