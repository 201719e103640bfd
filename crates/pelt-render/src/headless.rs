//! Rendering without a window: a GPU, an offscreen target and a readback into an image.

use pelt_core::FurStructure;
use pelt_core::texture::FurTextures;

use crate::RenderError;
use crate::camera::Camera;
use crate::gpu::{Backend, Gpu};
use crate::renderer::{ErrorScope, RenderSettings, Renderer};
use crate::targets::{RenderTargets, TargetFormat};

/// Colour format of headless frames (sRGB: what PNGs hold).
pub const HEADLESS_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;

/// A GPU with an offscreen `width x height` target that reads frames back as RGBA8 images.
#[derive(Debug)]
pub struct Headless {
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
        let targets = RenderTargets::new(&gpu.device, TargetFormat::msaa(HEADLESS_FORMAT), width, height)?;
        let output = gpu.device.create_texture(&wgpu::TextureDescriptor {
            label: Some("pelt headless output"),
            size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
            mip_level_count: 1,
            sample_count: 1,
            dimension: wgpu::TextureDimension::D2,
            format: HEADLESS_FORMAT,
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

    /// The target format renderers for this target must be built with.
    #[must_use]
    pub fn format(&self) -> TargetFormat {
        self.targets.format
    }

    /// `(width, height)`.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        (self.targets.width, self.targets.height)
    }

    /// Aspect ratio of the target.
    #[must_use]
    pub fn aspect_ratio(&self) -> f32 {
        self.targets.aspect_ratio()
    }

    /// A renderer for this target.
    ///
    /// # Errors
    /// As [`Renderer::new`].
    pub fn renderer(&self, fur: &FurStructure, textures: &FurTextures) -> Result<Renderer, RenderError> {
        Renderer::new(&self.gpu.device, &self.gpu.queue, self.format(), fur, textures)
    }

    /// Renders one frame with `renderer` and reads it back.
    ///
    /// # Errors
    /// [`RenderError::Readback`], or a GPU error raised while drawing.
    pub fn render(
        &self,
        renderer: &Renderer,
        camera: &Camera,
        settings: &RenderSettings,
    ) -> Result<image::RgbaImage, RenderError> {
        self.render_with(|queue, encoder, targets, output| {
            renderer.render(queue, encoder, targets, output, camera, settings);
        })
    }

    /// Renders one frame recorded by `record(queue, encoder, targets, output)` (e.g. a
    /// [`crate::SeparatedRenderer`]) and reads it back.
    ///
    /// # Errors
    /// [`RenderError::Readback`], or a GPU error raised while drawing.
    pub fn render_with(
        &self,
        record: impl FnOnce(&wgpu::Queue, &mut wgpu::CommandEncoder, &RenderTargets, &wgpu::TextureView),
    ) -> Result<image::RgbaImage, RenderError> {
        let device = &self.gpu.device;
        let scope = ErrorScope::push(device);
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("pelt frame") });
        record(&self.gpu.queue, &mut encoder, &self.targets, &self.output_view);
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
