//! The 3D view: an offscreen colour target the fur is drawn into, then copied into the window
//! where egui's central panel lies (`viewport.wgsl`), before egui draws the panel, the overlay
//! and the brush on top. Drawing it offscreen gives the camera the true aspect of the area beside
//! the panel; copying it with a pass of its own instead of as an egui image saves egui's
//! per-pixel filtering and gamma work (BENCHMARKS.md: 26 ms of a 1280x800 frame on lavapipe).

use pelt_render::{FurTarget, RenderTargets};

/// Format the 3D view is drawn in: sRGB, so shading stays linear.
pub const COLOUR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8UnormSrgb;
/// The same texels, gamma-encoded, for windows whose format is not sRGB (egui's choice).
const ENCODED_VIEW_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;

/// What the fur renderer draws the view into (MSAA as suits the adapter, resolved into the
/// texture; conventional depth).
pub fn target(adapter: &wgpu::AdapterInfo) -> FurTarget {
    FurTarget::new(COLOUR_FORMAT).with_sample_count(pelt_render::default_sample_count(adapter))
}

/// The offscreen target, its MSAA and depth attachments, and the pass that copies it into the
/// window.
#[derive(Debug)]
pub struct Viewport {
    texture: wgpu::Texture,
    /// `COLOUR_FORMAT` view the renderer resolves into.
    pub colour_view: wgpu::TextureView,
    pub targets: RenderTargets,
    target: FurTarget,
    copy: CopyPass,
    /// The copy's bind group: the texture as the window's format wants it.
    copy_source: wgpu::BindGroup,
}

/// The pipeline that copies the view into a window of one format.
#[derive(Debug)]
struct CopyPass {
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    /// Whether the window's format is sRGB: it then reads the linear texels, else the encoded ones.
    srgb_window: bool,
}

impl CopyPass {
    fn new(device: &wgpu::Device, window_format: wgpu::TextureFormat) -> Self {
        let (layout, module, pipeline_layout) = texel_pass(device, "pelt view copy", SHADER);
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("pelt view copy"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_cover"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_copy"),
                compilation_options: Default::default(),
                targets: &[Some(window_format.into())],
            }),
            multiview_mask: None,
            cache: None,
        });
        Self { layout, pipeline, srgb_window: window_format.is_srgb() }
    }

    fn bind_group(&self, device: &wgpu::Device, texture: &wgpu::Texture) -> wgpu::BindGroup {
        let format = if self.srgb_window { COLOUR_FORMAT } else { ENCODED_VIEW_FORMAT };
        let view = texture.create_view(&wgpu::TextureViewDescriptor { format: Some(format), ..Default::default() });
        device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt view copy"),
            layout: &self.layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) }],
        })
    }
}

/// `viewport.wgsl`.
pub const SHADER: &str = include_str!("viewport.wgsl");

impl Viewport {
    /// A one-pixel view, for windows of `window_format`.
    pub fn new(device: &wgpu::Device, window_format: wgpu::TextureFormat, target: FurTarget) -> anyhow::Result<Self> {
        let size_px = [1, 1];
        let (texture, colour_view) = create_target(device, size_px);
        let targets = RenderTargets::new(device, target, size_px[0], size_px[1])?;
        let copy = CopyPass::new(device, window_format);
        let copy_source = copy.bind_group(device, &texture);
        Ok(Self { texture, colour_view, targets, target, copy, copy_source })
    }

    pub fn size_px(&self) -> [u32; 2] {
        [self.texture.width(), self.texture.height()]
    }

    /// Follows the central panel's size (at least one pixel each way).
    pub fn resize(&mut self, device: &wgpu::Device, size_px: [u32; 2]) -> anyhow::Result<()> {
        let size_px = clamp_size(device, size_px);
        if size_px == self.size_px() {
            return Ok(());
        }
        let (texture, colour_view) = create_target(device, size_px);
        self.targets = RenderTargets::new(device, self.target, size_px[0], size_px[1])?;
        self.copy_source = self.copy.bind_group(device, &texture);
        self.texture = texture;
        self.colour_view = colour_view;
        Ok(())
    }

    /// Clears `window` (of `window_size_px`) and copies the view into it with its top-left
    /// corner at `origin_px`, cut to the window. egui then draws on top, loading what is there.
    pub fn copy_into(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        window: &wgpu::TextureView,
        window_size_px: [u32; 2],
        origin_px: [u32; 2],
    ) {
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("pelt view copy"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: window,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Clear(wgpu::Color::BLACK), store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        let [width, height] = self.size_px();
        let [x, y] = [0, 1].map(|axis| origin_px[axis].min(window_size_px[axis].saturating_sub(1)));
        // Cut to the window, keeping the scale: the copy maps the whole texture onto the rectangle.
        let (visible_width, visible_height) = (width.min(window_size_px[0] - x), height.min(window_size_px[1] - y));
        if visible_width == 0 || visible_height == 0 {
            return;
        }
        pass.set_viewport(x as f32, y as f32, width as f32, height as f32, 0.0, 1.0);
        pass.set_scissor_rect(x, y, visible_width, visible_height);
        pass.set_pipeline(&self.copy.pipeline);
        pass.set_bind_group(0, &self.copy_source, &[]);
        pass.draw(0..3, 0..1);
    }
}

/// The bind group layout (one texture, read with `textureLoad`), the shader module and the
/// pipeline layout of a pass that draws a texture into the window texel for texel: the view's
/// copy here, egui's layer in `ui_layer.rs`.
pub(super) fn texel_pass(
    device: &wgpu::Device,
    label: &str,
    shader: &str,
) -> (wgpu::BindGroupLayout, wgpu::ShaderModule, wgpu::PipelineLayout) {
    let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some(label),
        entries: &[wgpu::BindGroupLayoutEntry {
            binding: 0,
            visibility: wgpu::ShaderStages::FRAGMENT,
            ty: wgpu::BindingType::Texture {
                sample_type: wgpu::TextureSampleType::Float { filterable: false },
                view_dimension: wgpu::TextureViewDimension::D2,
                multisampled: false,
            },
            count: None,
        }],
    });
    let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(shader.into()),
    });
    let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some(label),
        bind_group_layouts: &[Some(&layout)],
        immediate_size: 0,
    });
    (layout, module, pipeline_layout)
}

fn clamp_size(device: &wgpu::Device, size_px: [u32; 2]) -> [u32; 2] {
    size_px.map(|s| s.clamp(1, device.limits().max_texture_dimension_2d))
}

fn create_target(device: &wgpu::Device, [width, height]: [u32; 2]) -> (wgpu::Texture, wgpu::TextureView) {
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some("3d view"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: COLOUR_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
        view_formats: &[ENCODED_VIEW_FORMAT],
    });
    let colour_view = texture.create_view(&wgpu::TextureViewDescriptor::default());
    (texture, colour_view)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn copy_shader_validates() {
        let module = naga::front::wgsl::parse_str(SHADER).unwrap_or_else(|e| panic!("{}", e.emit_to_string(SHADER)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(SHADER)));
    }

    /// A 5x3 view with distinct texels copied into an 8x6 window: every texel lands at the origin
    /// plus its own position, byte for byte, whether the window is sRGB or not; the rest of the
    /// window is cleared to black; a view hanging over the window's edge is cut, not squeezed.
    #[test]
    fn copy_puts_every_texel_at_the_origin_plus_its_position() {
        let gpu = pelt_render::Gpu::new(pelt_render::Backend::Auto).expect("a GPU adapter (lavapipe in CI)");
        let (device, queue) = (&gpu.device, &gpu.queue);
        let (view_w, view_h) = (5u32, 3u32);
        let texel = |x: u32, y: u32| [(40 * x + 7) as u8, (60 * y + 20) as u8, (x * 3 + y * 11) as u8 * 5, 255];
        for window_format in [wgpu::TextureFormat::Rgba8Unorm, wgpu::TextureFormat::Rgba8UnormSrgb] {
            for origin in [[2u32, 1u32], [6, 4]] {
                let mut viewport = Viewport::new(device, window_format, target(&gpu.adapter.get_info())).unwrap();
                viewport.resize(device, [view_w, view_h]).unwrap();
                // The view's texture as the renderer draws it, plus COPY_DST to be written here.
                viewport.texture = device.create_texture(&wgpu::TextureDescriptor {
                    label: None,
                    size: viewport.texture.size(),
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: COLOUR_FORMAT,
                    usage: viewport.texture.usage() | wgpu::TextureUsages::COPY_DST,
                    view_formats: &[ENCODED_VIEW_FORMAT],
                });
                viewport.copy_source = viewport.copy.bind_group(device, &viewport.texture);
                let bytes: Vec<u8> = (0..view_h).flat_map(|y| (0..view_w).flat_map(move |x| texel(x, y))).collect();
                queue.write_texture(
                    viewport.texture.as_image_copy(),
                    &bytes,
                    wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * view_w), rows_per_image: None },
                    wgpu::Extent3d { width: view_w, height: view_h, depth_or_array_layers: 1 },
                );
                let (window_w, window_h) = (8u32, 6u32);
                let window = device.create_texture(&wgpu::TextureDescriptor {
                    label: None,
                    size: wgpu::Extent3d { width: window_w, height: window_h, depth_or_array_layers: 1 },
                    mip_level_count: 1,
                    sample_count: 1,
                    dimension: wgpu::TextureDimension::D2,
                    format: window_format,
                    usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                    view_formats: &[],
                });
                let readback = device.create_buffer(&wgpu::BufferDescriptor {
                    label: None,
                    size: 256 * u64::from(window_h),
                    usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                    mapped_at_creation: false,
                });
                let mut encoder = device.create_command_encoder(&Default::default());
                viewport.copy_into(
                    &mut encoder,
                    &window.create_view(&Default::default()),
                    [window_w, window_h],
                    origin,
                );
                encoder.copy_texture_to_buffer(
                    window.as_image_copy(),
                    wgpu::TexelCopyBufferInfo {
                        buffer: &readback,
                        layout: wgpu::TexelCopyBufferLayout {
                            offset: 0,
                            bytes_per_row: Some(256),
                            rows_per_image: None,
                        },
                    },
                    wgpu::Extent3d { width: window_w, height: window_h, depth_or_array_layers: 1 },
                );
                queue.submit([encoder.finish()]);
                readback.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("map"));
                device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
                let data = readback.slice(..).get_mapped_range().unwrap().to_vec();
                for y in 0..window_h {
                    for x in 0..window_w {
                        let at = (256 * y + 4 * x) as usize;
                        let got = &data[at..at + 4];
                        let inside =
                            x >= origin[0] && y >= origin[1] && x - origin[0] < view_w && y - origin[1] < view_h;
                        let expected = if inside { texel(x - origin[0], y - origin[1]) } else { [0, 0, 0, 255] };
                        assert_eq!(got, expected, "{window_format:?}, origin {origin:?}, window pixel ({x}, {y})");
                    }
                }
            }
        }
    }
}
