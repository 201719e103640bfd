//! The 3D view: an offscreen colour target the fur is drawn into, shown by egui as an image in
//! the central panel. Drawing it offscreen gives the camera the true aspect of the area beside
//! the panel and lets egui lay the overlay and the brush on top.

use pelt_render::{FurTarget, RenderTargets};

/// Format the 3D view is drawn in: sRGB, so shading stays linear.
pub const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// egui samples gamma-encoded textures, so it reads the same texels through a non-sRGB view.
const EGUI_VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// What the fur renderer draws the view into (MSAA as suits the adapter, resolved into the
/// texture; conventional depth).
pub fn target(adapter: &wgpu::AdapterInfo) -> FurTarget {
    FurTarget::new(COLOUR_FORMAT).with_sample_count(pelt_render::default_sample_count(adapter))
}

/// The offscreen target, its MSAA and depth attachments, and its egui texture.
#[derive(Debug)]
pub struct Viewport {
    texture: wgpu::Texture,
    /// `COLOUR_FORMAT` view the renderer resolves into.
    pub colour_view: wgpu::TextureView,
    pub targets: RenderTargets,
    pub texture_id: egui::TextureId,
    target: FurTarget,
}

impl Viewport {
    pub fn new(
        device: &wgpu::Device,
        egui_renderer: &mut egui_wgpu::Renderer,
        size_px: [u32; 2],
        target: FurTarget,
    ) -> anyhow::Result<Self> {
        let size_px = clamp_size(device, size_px);
        let (texture, colour_view, egui_view) = create_target(device, size_px);
        let targets = RenderTargets::new(device, target, size_px[0], size_px[1])?;
        let texture_id = egui_renderer.register_native_texture(device, &egui_view, wgpu::FilterMode::Linear);
        Ok(Self { texture, colour_view, targets, texture_id, target })
    }

    pub fn size_px(&self) -> [u32; 2] {
        [self.texture.width(), self.texture.height()]
    }

    /// Follows the central panel's size (at least one pixel each way).
    pub fn resize(
        &mut self,
        device: &wgpu::Device,
        egui_renderer: &mut egui_wgpu::Renderer,
        size_px: [u32; 2],
    ) -> anyhow::Result<()> {
        let size_px = clamp_size(device, size_px);
        if size_px == self.size_px() {
            return Ok(());
        }
        let (texture, colour_view, egui_view) = create_target(device, size_px);
        self.targets = RenderTargets::new(device, self.target, size_px[0], size_px[1])?;
        egui_renderer.update_egui_texture_from_wgpu_texture(
            device,
            &egui_view,
            wgpu::FilterMode::Linear,
            self.texture_id,
        );
        self.texture = texture;
        self.colour_view = colour_view;
        Ok(())
    }
}

fn clamp_size(device: &wgpu::Device, size_px: [u32; 2]) -> [u32; 2] {
    size_px.map(|s| s.clamp(1, device.limits().max_texture_dimension_2d))
}

fn create_target(
    device: &wgpu::Device,
    [width, height]: [u32; 2],
) -> (wgpu::Texture, wgpu::TextureView, wgpu::TextureView) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("3d view"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: COLOUR_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[EGUI_VIEW_FORMAT],
    });
    let colour_view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    let egui_view =
        texture.create_view(&wgpu::TextureViewDescriptor { format: Some(EGUI_VIEW_FORMAT), ..Default::default() });
    (texture, colour_view, egui_view)
}
