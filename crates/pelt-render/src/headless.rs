//! Rendering without a window (the `headless` feature): a GPU, an offscreen target and a
//! readback into an image.

use glam::Vec3;

use crate::RenderError;
use crate::gpu::{Backend, Gpu};
use crate::renderer::FurRenderer;
use crate::requirements::ErrorScope;
use crate::targets::{FurTarget, RenderTargets};

/// Colour format of headless frames (sRGB: what PNGs hold).
pub const HEADLESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// A GPU with an offscreen `width x height` target ([`FurTarget::new`] of [`HEADLESS_FORMAT`]:
/// 4x MSAA, conventional depth) that reads frames back as RGBA8 images.
#[derive(Debug)]
pub struct Headless {
    /// The GPU frames are drawn on.
    pub gpu: Gpu,
    targets: RenderTargets,
    output: wgpu::Texture,
    output_view: wgpu::TextureView,
    readback: wgpu::Buffer,
    padded_row_bytes: u32,
}

impl Headless {
    /// Opens a GPU of `backend` and creates a `width x height` target.
    ///
    /// # Errors
    /// As [`Gpu::new`] and [`RenderTargets::new`].
    pub fn new(backend: Backend, width: u32, height: u32) -> Result<Self, RenderError> {
        Self::with_gpu(Gpu::new(backend)?, width, height)
    }

    /// Uses an existing GPU.
    ///
    /// # Errors
    /// [`RenderError::TargetSize`].
    pub fn with_gpu(gpu: Gpu, width: u32, height: u32) -> Result<Self, RenderError> {
        Self::with_target(gpu, FurTarget::new(HEADLESS_FORMAT), width, height)
    }

    /// Uses an existing GPU and another target description (e.g. reverse-Z depth or no MSAA);
    /// its colour format must be RGBA8 (`Rgba8UnormSrgb` or `Rgba8Unorm`).
    ///
    /// # Errors
    /// [`RenderError::TargetSize`], or [`RenderError::Target`] for another colour format.
    pub fn with_target(gpu: Gpu, target: FurTarget, width: u32, height: u32) -> Result<Self, RenderError> {
        if !matches!(target.colour_format, wgpu::TextureFormat::Rgba8UnormSrgb | wgpu::TextureFormat::Rgba8Unorm) {
            return Err(RenderError::Target(format!(
                "headless frames are read back as RGBA8, not {:?}",
                target.colour_format
            )));
        }
        let targets = RenderTargets::new(&gpu.device, target, width, height)?;
        let output = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("pelt headless output"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: target.colour_format,
            usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
            view_formats: &[],
        });
        let output_view = output.create_view(&wgpu::TextureViewDescriptor::default());
        let padded_row_bytes = (4 * width).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let readback = gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt readback"),
            size: u64::from(padded_row_bytes) * u64::from(height),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        Ok(Self { gpu, targets, output, output_view, readback, padded_row_bytes })
    }

    /// The target description renderers for this target must be built with.
    #[must_use]
    pub fn target(&self) -> FurTarget {
        self.targets.target()
    }

    /// `(width, height)`.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        self.targets.size()
    }

    /// Aspect ratio of the target.
    #[must_use]
    pub fn aspect_ratio(&self) -> f32 {
        self.targets.aspect_ratio()
    }

    /// A renderer for this target.
    ///
    /// # Errors
    /// As [`FurRenderer::new`].
    pub fn renderer(&self) -> Result<FurRenderer, RenderError> {
        FurRenderer::new(&self.gpu.device, self.target())
    }

    /// Renders one frame and reads it back: a pass cleared to `background` (linear RGB) and the
    /// far depth, in which `draw` records (after the `prepare` calls it relies on).
    ///
    /// # Errors
    /// [`RenderError::Readback`], or a GPU error raised while drawing.
    pub fn render(
        &self,
        background: Vec3,
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) -> Result<image::RgbaImage, RenderError> {
        self.render_with(background, |_| {}, draw)
    }

    /// [`Headless::render`] with work recorded into the frame's encoder before its pass: e.g.
    /// [`FurRenderer::prepare_fins`](crate::FurRenderer::prepare_fins).
    ///
    /// # Errors
    /// As [`Headless::render`].
    pub fn render_with(
        &self,
        background: Vec3,
        before: impl FnOnce(&mut wgpu::CommandEncoder),
        draw: impl FnOnce(&mut wgpu::RenderPass<'_>),
    ) -> Result<image::RgbaImage, RenderError> {
        let device = &self.gpu.device;
        let scope = ErrorScope::push(device);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pelt frame") });
        before(&mut encoder);
        {
            let mut pass = self.targets.begin_pass(&mut encoder, &self.output_view, background);
            draw(&mut pass);
        }
        let (width, height) = self.size();
        encoder.copy_texture_to_buffer(
            self.output.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &self.readback,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(self.padded_row_bytes),
                    rows_per_image: Some(height),
                },
            },
            wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        );
        self.gpu.queue.submit([encoder.finish()]);
        scope.pop("rendering a frame")?;
        self.read_back()
    }

    fn read_back(&self) -> Result<image::RgbaImage, RenderError> {
        let (width, height) = self.size();
        let slice = self.readback.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            // The receiver waits below; a send error would mean it is gone, and nothing is left to tell.
            let _ = sender.send(result);
        });
        self.gpu
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|error| RenderError::Readback(error.to_string()))?;
        receiver
            .recv()
            .map_err(|error| RenderError::Readback(error.to_string()))?
            .map_err(|error| RenderError::Readback(error.to_string()))?;
        let mut pixels = Vec::with_capacity((4 * width * height) as usize);
        {
            let mapped = slice.get_mapped_range().map_err(|error| RenderError::Readback(error.to_string()))?;
            for row in mapped.chunks_exact(self.padded_row_bytes as usize) {
                pixels.extend_from_slice(&row[..(4 * width) as usize]);
            }
        }
        self.readback.unmap();
        image::RgbaImage::from_raw(width, height, pixels)
            .ok_or_else(|| RenderError::Readback("the frame has the wrong size".to_owned()))
    }
}
