//! The multisampled colour and depth attachments a frame is drawn into before it is resolved
//! into the caller's view (a window's surface texture or the headless readback texture).

use crate::RenderError;

/// Depth format of every fur pipeline.
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// MSAA sample count Pelt draws with.
pub const SAMPLE_COUNT: u32 = 4;

/// The colour format and sample count the pipelines are built for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TargetFormat {
    /// Format of the view frames resolve into (e.g. the surface's format).
    pub colour: wgpu::TextureFormat,
    /// 1 (no MSAA) or 4.
    pub sample_count: u32,
}

impl TargetFormat {
    /// `colour` with 4x MSAA.
    #[must_use]
    pub fn msaa(colour: wgpu::TextureFormat) -> Self {
        Self { colour, sample_count: SAMPLE_COUNT }
    }
}

/// Multisampled colour (when `sample_count > 1`) and depth for one frame size.
#[derive(Debug)]
pub struct RenderTargets {
    pub format: TargetFormat,
    pub width: u32,
    pub height: u32,
    msaa_colour: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
}

impl RenderTargets {
    /// Creates the attachments; call again when the window is resized.
    ///
    /// # Errors
    /// [`RenderError::TargetSize`] for a zero or over-limit size.
    pub fn new(device: &wgpu::Device, format: TargetFormat, width: u32, height: u32) -> Result<Self, RenderError> {
        let limit = device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > limit || height > limit {
            return Err(RenderError::TargetSize { width, height, limit });
        }
        let size = wgpu::Extent3d { width, height, depth_or_array_layers: 1 };
        let create = |label, texture_format| {
            device
                .create_texture(&wgpu::TextureDescriptor {
                    label: Some(label),
                    size,
                    mip_level_count: 1,
                    sample_count: format.sample_count,
                    dimension: wgpu::TextureDimension::D2,
                    format: texture_format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                    view_formats: &[],
                })
                .create_view(&wgpu::TextureViewDescriptor::default())
        };
        let msaa_colour = (format.sample_count > 1).then(|| create("pelt msaa colour", format.colour));
        let depth = create("pelt depth", DEPTH_FORMAT);
        Ok(Self { format, width, height, msaa_colour, depth })
    }

    /// Aspect ratio (width / height).
    #[must_use]
    pub fn aspect_ratio(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// The colour attachment for a frame resolving into `output` (which must have this size
    /// and `format.colour`).
    #[must_use]
    pub fn colour_attachment<'a>(
        &'a self,
        output: &'a wgpu::TextureView,
        clear: wgpu::Color,
    ) -> wgpu::RenderPassColorAttachment<'a> {
        let ops = wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store };
        match &self.msaa_colour {
            Some(msaa) => wgpu::RenderPassColorAttachment {
                view: msaa,
                depth_slice: None,
                resolve_target: Some(output),
                // The samples are resolved into `output`; keeping them would only cost bandwidth.
                ops: wgpu::Operations { store: wgpu::StoreOp::Discard, ..ops },
            },
            None => wgpu::RenderPassColorAttachment { view: output, depth_slice: None, resolve_target: None, ops },
        }
    }

    /// The depth attachment, cleared to the far plane.
    #[must_use]
    pub fn depth_attachment(&self) -> wgpu::RenderPassDepthStencilAttachment<'_> {
        wgpu::RenderPassDepthStencilAttachment {
            view: &self.depth,
            depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Clear(1.0), store: wgpu::StoreOp::Discard }),
            stencil_ops: None,
        }
    }
}
