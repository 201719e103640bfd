//! What the pipelines draw into: [`FurTarget`] describes the host's attachments (formats, depth
//! comparison, MSAA); [`RenderTargets`] are attachments for hosts that have none of their own
//! (Pelt's viewer and headless rendering).

use crate::RenderError;

/// Depth format of [`FurTarget::new`] and [`RenderTargets`].
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// MSAA sample count of [`FurTarget::new`].
pub const SAMPLE_COUNT: u32 = 4;

/// MSAA samples worth their cost on `adapter`: 1 on CPU rasterisers (lavapipe, llvmpipe, WARP),
/// where every sample is shaded and blended in software and fur strands are filtered textures
/// anyway; [`SAMPLE_COUNT`] on GPUs, whose silhouettes and fins alias without it.
#[must_use]
pub fn default_sample_count(adapter: &wgpu::AdapterInfo) -> u32 {
    if adapter.device_type == wgpu::DeviceType::Cpu { 1 } else { SAMPLE_COUNT }
}

/// The clear colour of Pelt's own pictures (linear RGB): a dark blue-grey.
pub const DEFAULT_BACKGROUND: glam::Vec3 = glam::Vec3::new(0.045, 0.05, 0.06);

/// The attachments a [`crate::FurRenderer`]'s pipelines are built for: one renderer per target
/// description, shared by every fur drawn into passes of that description.
///
/// The host owns the attachments and their clear values: a conventional depth buffer clears to
/// 1 and compares `Less`/`LessEqual`; a reverse-Z one clears to 0 and compares
/// `Greater`/`GreaterEqual` ([`FurTarget::reverse_z`]). [`FurTarget::depth_clear_value`] gives the
/// far value for the compare function.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FurTarget {
    /// Format of the colour attachment (or its MSAA texture).
    pub colour_format: wgpu::TextureFormat,
    /// Format of the depth attachment (a depth or depth-stencil format).
    pub depth_format: wgpu::TextureFormat,
    /// How fragments are tested against the host's depth; the fur's opaque skin and its
    /// alpha-to-coverage layers write depth, blended layers only test.
    pub depth_compare: wgpu::CompareFunction,
    /// MSAA samples of the attachments (1 for none). Alpha-to-coverage needs more than 1.
    pub sample_count: u32,
}

impl FurTarget {
    /// `colour_format` with [`DEPTH_FORMAT`], conventional depth (`LessEqual`, clear to 1) and 4x MSAA:
    /// Pelt's own look (headless rendering and the viewer).
    #[must_use]
    pub fn new(colour_format: wgpu::TextureFormat) -> Self {
        Self {
            colour_format,
            depth_format: DEPTH_FORMAT,
            depth_compare: wgpu::CompareFunction::LessEqual,
            sample_count: SAMPLE_COUNT,
        }
    }

    /// The same target with reverse-Z depth: `GreaterEqual`, cleared to 0.
    #[must_use]
    pub fn reverse_z(self) -> Self {
        Self { depth_compare: wgpu::CompareFunction::GreaterEqual, ..self }
    }

    /// The same target with `sample_count` MSAA samples.
    #[must_use]
    pub fn with_sample_count(self, sample_count: u32) -> Self {
        Self { sample_count, ..self }
    }

    /// The same target with another depth format and comparison.
    #[must_use]
    pub fn with_depth(self, depth_format: wgpu::TextureFormat, depth_compare: wgpu::CompareFunction) -> Self {
        Self { depth_format, depth_compare, ..self }
    }

    /// Whether nearer fragments have larger depth (`Greater`, `GreaterEqual`).
    #[must_use]
    pub fn is_reverse_z(&self) -> bool {
        matches!(self.depth_compare, wgpu::CompareFunction::Greater | wgpu::CompareFunction::GreaterEqual)
    }

    /// The far plane's depth for this comparison: 0 for reverse-Z, else 1.
    #[must_use]
    pub fn depth_clear_value(&self) -> f32 {
        if self.is_reverse_z() { 0.0 } else { 1.0 }
    }

    /// Checks what can be checked without the adapter.
    pub(crate) fn validate(&self) -> Result<(), RenderError> {
        let bad = |message: String| Err(RenderError::Target(message));
        if !self.depth_format.has_depth_aspect() {
            return bad(format!("{:?} is not a depth format", self.depth_format));
        }
        if self.colour_format.has_depth_aspect() || self.colour_format.has_stencil_aspect() {
            return bad(format!("{:?} is not a colour format", self.colour_format));
        }
        if ![1, 2, 4, 8, 16].contains(&self.sample_count) {
            return bad(format!("sample count {} (use 1, 2, 4, 8 or 16)", self.sample_count));
        }
        Ok(())
    }
}

/// Multisampled colour (when `sample_count > 1`) and depth attachments of one size, for hosts
/// without attachments of their own; frames resolve into the caller's view.
#[derive(Debug)]
pub struct RenderTargets {
    target: FurTarget,
    width: u32,
    height: u32,
    msaa_colour: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
}

impl RenderTargets {
    /// Creates the attachments; call again when the window is resized.
    ///
    /// # Errors
    /// [`RenderError::TargetSize`] for a zero or over-limit size, [`RenderError::Target`] for a
    /// malformed target.
    pub fn new(device: &wgpu::Device, target: FurTarget, width: u32, height: u32) -> Result<Self, RenderError> {
        target.validate()?;
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
                    sample_count: target.sample_count,
                    dimension: wgpu::TextureDimension::D2,
                    format: texture_format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
                    view_formats: &[],
                })
                .create_view(&wgpu::TextureViewDescriptor::default())
        };
        let msaa_colour = (target.sample_count > 1).then(|| create("pelt msaa colour", target.colour_format));
        let depth = create("pelt depth", target.depth_format);
        Ok(Self { target, width, height, msaa_colour, depth })
    }

    /// The target description the attachments follow.
    #[must_use]
    pub fn target(&self) -> FurTarget {
        self.target
    }

    /// `(width, height)` in pixels.
    #[must_use]
    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    /// Aspect ratio (width / height).
    #[must_use]
    pub fn aspect_ratio(&self) -> f32 {
        self.width as f32 / self.height as f32
    }

    /// Begins a pass that clears colour to `background` (linear RGB) and depth to the target's far
    /// value, resolving into `output` (a view of this size and the target's colour format).
    pub fn begin_pass<'e>(
        &self,
        encoder: &'e mut wgpu::CommandEncoder,
        output: &wgpu::TextureView,
        background: glam::Vec3,
    ) -> wgpu::RenderPass<'e> {
        let background = background.as_dvec3();
        let clear = wgpu::Color { r: background.x, g: background.y, b: background.z, a: 1.0 };
        let ops = wgpu::Operations { load: wgpu::LoadOp::Clear(clear), store: wgpu::StoreOp::Store };
        let colour = match &self.msaa_colour {
            Some(msaa) => wgpu::RenderPassColorAttachment {
                view: msaa,
                depth_slice: None,
                resolve_target: Some(output),
                // The samples are resolved into `output`; keeping them would only cost bandwidth.
                ops: wgpu::Operations { store: wgpu::StoreOp::Discard, ..ops },
            },
            None => wgpu::RenderPassColorAttachment { view: output, depth_slice: None, resolve_target: None, ops },
        };
        let depth = wgpu::RenderPassDepthStencilAttachment {
            view: &self.depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(self.target.depth_clear_value()),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        };
        encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("pelt frame"),
            color_attachments: &[Some(colour)],
            depth_stencil_attachment: Some(depth),
            ..wgpu::RenderPassDescriptor::default()
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reverse_z_clears_to_zero_and_bad_targets_are_errors() {
        let target = FurTarget::new(wgpu::TextureFormat::Rgba8UnormSrgb);
        assert_eq!(target.depth_clear_value(), 1.0);
        assert!(!target.is_reverse_z());
        let reverse = target.reverse_z();
        assert_eq!(reverse.depth_clear_value(), 0.0);
        assert_eq!(reverse.depth_compare, wgpu::CompareFunction::GreaterEqual);
        assert!(target.validate().is_ok());
        let depth_as_colour = FurTarget { colour_format: wgpu::TextureFormat::Depth32Float, ..target };
        assert!(depth_as_colour.validate().unwrap_err().to_string().contains("not a colour format"));
        let colour_as_depth = FurTarget { depth_format: wgpu::TextureFormat::Rgba8Unorm, ..target };
        assert!(colour_as_depth.validate().unwrap_err().to_string().contains("not a depth format"));
        assert!(target.with_sample_count(3).validate().is_err());
    }
}
