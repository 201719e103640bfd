//! egui's picture kept in a texture of its own, drawn again only when egui's output changes, and
//! laid over the window each frame in `TILE_PX` squares where egui drew anything.
//!
//! Why: on software rasterisers egui's pass (its filtering and gamma work per pixel over the
//! panel) is about a fifth of the viewer's frame (BENCHMARKS.md), while from one frame to the
//! next its output is mostly the same picture: the overlay's timings refresh twice a second
//! (`Model::refresh_shown_times`), and the panel changes only when used. The layer is blended as
//! egui blends (premultiplied "over", which composes), so the window gets the picture egui would
//! have drawn into it directly, up to the rounding of one 8-bit store.

use egui::epaint::{ClippedPrimitive, Mesh, Primitive};

/// Side of the squares the layer is laid over the window in, in pixels.
const TILE_PX: u32 = 32;

/// `ui_layer.wgsl`.
pub const SHADER: &str = include_str!("ui_layer.wgsl");

/// One tile as the vertex stage reads it: `[x0, y0, x1, y1]` in normalised device coordinates.
const TILE_BYTES: u64 = 16;

#[derive(Debug)]
pub struct UiLayer {
    format: wgpu::TextureFormat,
    layout: wgpu::BindGroupLayout,
    pipeline: wgpu::RenderPipeline,
    /// The picture egui drew last; `None` before the first.
    picture: Option<Picture>,
    /// What that picture is of: compared with each frame's output.
    kept: Vec<(egui::Rect, Mesh)>,
    kept_pixels_per_point: f32,
    tiles: wgpu::Buffer,
    tile_count: u32,
}

#[derive(Debug)]
struct Picture {
    texture: wgpu::Texture,
    view: wgpu::TextureView,
    bind_group: wgpu::BindGroup,
}

impl UiLayer {
    /// A layer for windows of `format` (egui draws into it in the window's format).
    pub fn new(device: &wgpu::Device, format: wgpu::TextureFormat) -> Self {
        let (layout, module, pipeline_layout) = super::viewport::texel_pass(device, "pelt ui layer", SHADER);
        let over = wgpu::BlendComponent {
            src_factor: wgpu::BlendFactor::One,
            dst_factor: wgpu::BlendFactor::OneMinusSrcAlpha,
            operation: wgpu::BlendOperation::Add,
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("pelt ui layer"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_tile"),
                compilation_options: Default::default(),
                buffers: &[Some(wgpu::VertexBufferLayout {
                    array_stride: TILE_BYTES,
                    step_mode: wgpu::VertexStepMode::Instance,
                    attributes: &wgpu::vertex_attr_array![0 => Float32x4],
                })],
            },
            primitive: wgpu::PrimitiveState::default(),
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some("fs_tile"),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format,
                    blend: Some(wgpu::BlendState { color: over, alpha: over }),
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        let tiles = tile_buffer(device, 64);
        Self {
            format,
            layout,
            pipeline,
            picture: None,
            kept: Vec::new(),
            kept_pixels_per_point: 0.0,
            tiles,
            tile_count: 0,
        }
    }

    /// Whether the picture already shows `jobs` in a window of `size_px` at `pixels_per_point`
    /// (egui's textures unchanged: the caller checks those).
    pub fn holds(&self, jobs: &[ClippedPrimitive], size_px: [u32; 2], pixels_per_point: f32) -> bool {
        let Some(picture) = &self.picture else { return false };
        [picture.texture.width(), picture.texture.height()] == size_px
            && pixels_per_point == self.kept_pixels_per_point
            && jobs.len() == self.kept.len()
            && jobs.iter().zip(&self.kept).all(|(job, (clip, mesh))| {
                job.clip_rect == *clip && matches!(&job.primitive, Primitive::Mesh(m) if m == mesh)
            })
    }

    /// The texture for egui to draw this frame's output into, cleared by the caller's pass,
    /// `size_px` large; then `keep` what was drawn.
    pub fn target(&mut self, device: &wgpu::Device, size_px: [u32; 2]) -> &wgpu::TextureView {
        let [width, height] = size_px.map(|s| s.max(1));
        let stale = self.picture.as_ref().is_none_or(|p| p.texture.width() != width || p.texture.height() != height);
        if stale {
            let texture = device.create_texture(&wgpu::TextureDescriptor {
                label: Some("pelt ui layer"),
                size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format: self.format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::TEXTURE_BINDING,
                view_formats: &[],
            });
            let view = texture.create_view(&wgpu::TextureViewDescriptor::default());
            let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
                label: Some("pelt ui layer"),
                layout: &self.layout,
                entries: &[wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(&view) }],
            });
            self.kept.clear();
            self.picture = Some(Picture { texture, view, bind_group });
        }
        &self.picture.as_ref().expect("made above").view
    }

    /// Records that the picture now shows `jobs`, and which tiles of it hold anything.
    pub fn keep(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        jobs: &[ClippedPrimitive],
        size_px: [u32; 2],
        pixels_per_point: f32,
    ) {
        // A paint callback is not kept, so the next frame's comparison fails and draws again.
        self.kept = jobs
            .iter()
            .filter_map(|job| match &job.primitive {
                Primitive::Mesh(mesh) => Some((job.clip_rect, mesh.clone())),
                Primitive::Callback(_) => None,
            })
            .collect();
        self.kept_pixels_per_point = pixels_per_point;
        let meshes = self.kept.iter().map(|(clip, mesh)| (*clip, mesh));
        let tiles = covered_tiles(meshes, pixels_per_point, size_px);
        let [width, height] = size_px.map(|s| s.max(1) as f32);
        let ndc: Vec<f32> = tiles
            .iter()
            .flat_map(|&[x0, y0, x1, y1]| {
                let (x0, y0, x1, y1) = (x0 as f32, y0 as f32, x1 as f32, y1 as f32);
                [x0 / width * 2.0 - 1.0, 1.0 - y0 / height * 2.0, x1 / width * 2.0 - 1.0, 1.0 - y1 / height * 2.0]
            })
            .collect();
        if (self.tiles.size() / TILE_BYTES) < tiles.len() as u64 {
            self.tiles = tile_buffer(device, tiles.len().next_power_of_two() as u64);
        }
        let bytes: Vec<u8> = ndc.iter().flat_map(|v| v.to_ne_bytes()).collect();
        if !bytes.is_empty() {
            queue.write_buffer(&self.tiles, 0, &bytes);
        }
        self.tile_count = tiles.len() as u32;
    }

    /// Lays the picture over `target` (a window of the picture's size), loading what is there.
    pub fn draw_over(&self, encoder: &mut wgpu::CommandEncoder, target: &wgpu::TextureView) {
        let Some(picture) = &self.picture else { return };
        if self.tile_count == 0 {
            return;
        }
        let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
            label: Some("pelt ui layer"),
            color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                view: target,
                depth_slice: None,
                resolve_target: None,
                ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
            })],
            depth_stencil_attachment: None,
            timestamp_writes: None,
            occlusion_query_set: None,
            multiview_mask: None,
        });
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, &picture.bind_group, &[]);
        pass.set_vertex_buffer(0, self.tiles.slice(..u64::from(self.tile_count) * TILE_BYTES));
        pass.draw(0..6, 0..self.tile_count);
    }
}

fn tile_buffer(device: &wgpu::Device, tiles: u64) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("pelt ui layer tiles"),
        size: tiles.max(1) * TILE_BYTES,
        usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

/// The `TILE_PX` squares of a `size_px` window that any of `meshes` touches (each mesh cut to
/// its clip rectangle, both in points), as pixel rectangles `[x0, y0, x1, y1)` cut to the
/// window, each square once, so laying them over the window blends every pixel at most once.
fn covered_tiles<'a>(
    meshes: impl IntoIterator<Item = (egui::Rect, &'a Mesh)>,
    pixels_per_point: f32,
    size_px: [u32; 2],
) -> Vec<[u32; 4]> {
    let [width, height] = size_px;
    let (columns, rows) = (width.div_ceil(TILE_PX), height.div_ceil(TILE_PX));
    let mut covered = vec![false; (columns * rows) as usize];
    for (clip, mesh) in meshes {
        if mesh.indices.is_empty() {
            continue;
        }
        // Triangles lie inside their vertices' bounds, and egui cuts them to the clip rectangle.
        let mut bounds = egui::Rect::NOTHING;
        for vertex in &mesh.vertices {
            bounds.extend_with(vertex.pos);
        }
        let bounds = bounds.intersect(clip);
        // A pixel beyond the bounds each way, for the clip rectangle's rounding to pixels.
        let span = |low: f32, high: f32, size: u32| {
            let low = ((low * pixels_per_point).floor() - 1.0).max(0.0);
            let high = ((high * pixels_per_point).ceil() + 1.0).min(size as f32);
            (low < high).then_some((low as u32, high as u32))
        };
        let (Some((x0, x1)), Some((y0, y1))) =
            (span(bounds.min.x, bounds.max.x, width), span(bounds.min.y, bounds.max.y, height))
        else {
            continue;
        };
        for row in y0 / TILE_PX..=(y1 - 1) / TILE_PX {
            for column in x0 / TILE_PX..=(x1 - 1) / TILE_PX {
                covered[(row * columns + column) as usize] = true;
            }
        }
    }
    (0..rows)
        .flat_map(|row| (0..columns).map(move |column| (row, column)))
        .filter(|&(row, column)| covered[(row * columns + column) as usize])
        .map(|(row, column)| {
            let (x0, y0) = (column * TILE_PX, row * TILE_PX);
            [x0, y0, (x0 + TILE_PX).min(width), (y0 + TILE_PX).min(height)]
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layer_shader_validates() {
        let module = naga::front::wgsl::parse_str(SHADER).unwrap_or_else(|e| panic!("{}", e.emit_to_string(SHADER)));
        naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::empty())
            .validate(&module)
            .unwrap_or_else(|e| panic!("{}", e.emit_to_string(SHADER)));
    }

    fn quad(min: egui::Pos2, max: egui::Pos2) -> Mesh {
        let mut mesh = Mesh::default();
        mesh.add_colored_rect(egui::Rect::from_min_max(min, max), egui::Color32::WHITE);
        mesh
    }

    #[test]
    fn tiles_cover_every_mesh_once_and_nothing_far_from_them() {
        let size = [100, 70];
        let everything = egui::Rect::EVERYTHING;
        // At 2 pixels a point: x 20..24 px (tile column 0), y 50..54 px (row 1); and a mesh cut by
        // its clip rectangle to x 0..10 points (0..20 px: column 0), y 0..5 (0..10 px: row 0).
        let small = quad(egui::pos2(10.0, 25.0), egui::pos2(12.0, 27.0));
        let wide = quad(egui::pos2(0.0, 0.0), egui::pos2(50.0, 5.0));
        let clip = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(10.0, 5.0));
        let empty = Mesh::default();
        let tiles = covered_tiles([(everything, &small), (clip, &wide), (everything, &empty)], 2.0, size);
        assert_eq!(tiles, vec![[0, 0, 32, 32], [0, 32, 32, 64]]);

        // Anything reaching past the window is cut to it; overlapping meshes give each tile once.
        let big = quad(egui::pos2(-10.0, -10.0), egui::pos2(500.0, 500.0));
        let tiles = covered_tiles([(everything, &big), (everything, &big)], 1.0, size);
        assert_eq!(tiles.len(), 4 * 3);
        let mut hits = vec![0; 100 * 70];
        for [x0, y0, x1, y1] in tiles {
            assert!(x1 <= 100 && y1 <= 70);
            for y in y0..y1 {
                for x in x0..x1 {
                    hits[(y * 100 + x) as usize] += 1;
                }
            }
        }
        assert!(hits.iter().all(|&h| h == 1), "every pixel covered exactly once");
    }

    /// egui drawn straight into a window over a 3D view, and drawn into the layer and laid over
    /// the same view, give the same window to within one level per channel; a second frame with
    /// the same output is held, one with other output is not.
    #[test]
    fn the_layer_gives_the_window_egui_would_have_drawn() {
        let gpu = pelt_render::Gpu::new(pelt_render::Backend::Auto).expect("a GPU adapter (lavapipe in CI)");
        let (device, queue) = (&gpu.device, &gpu.queue);
        let size = [160u32, 96u32];
        let format = wgpu::TextureFormat::Rgba8Unorm;
        let ctx = egui::Context::default();
        let run = |label: &str| {
            let input = egui::RawInput {
                screen_rect: Some(egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(160.0, 96.0))),
                ..Default::default()
            };
            let output = ctx.run_ui(input, |ui| {
                egui::Panel::right("panel").default_size(60.0).show(ui, |ui| {
                    ui.label(label);
                    let _ = ui.button("button");
                });
                egui::CentralPanel::no_frame().show(ui, |ui| {
                    ui.painter().rect_filled(
                        egui::Rect::from_min_size(egui::pos2(8.0, 8.0), egui::vec2(40.0, 20.0)),
                        4.0,
                        egui::Color32::from_black_alpha(150),
                    );
                    // Translucent and coloured: a layer blended as straight alpha would darken it.
                    ui.painter().rect_filled(
                        egui::Rect::from_min_size(egui::pos2(20.0, 40.0), egui::vec2(50.0, 30.0)),
                        0.0,
                        egui::Color32::from_rgba_unmultiplied(255, 200, 0, 120),
                    );
                });
            });
            let jobs = ctx.tessellate(output.shapes, output.pixels_per_point);
            (jobs, output.textures_delta)
        };
        let mut renderer = egui_wgpu::Renderer::new(device, format, egui_wgpu::RendererOptions::default());
        let screen = egui_wgpu::ScreenDescriptor { size_in_pixels: size, pixels_per_point: 1.0 };
        let window = |label| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size: wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage: wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
                view_formats: &[],
            })
        };
        // A "3D view" under the ui: a gradient, so blending over it shows.
        let clear_to_gradient = |encoder: &mut wgpu::CommandEncoder, view: &wgpu::TextureView| {
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: None,
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color { r: 0.2, g: 0.6, b: 0.9, a: 1.0 }),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            drop(pass);
        };

        // A few frames first: egui sizes its panels on the first and may differ on the second.
        let mut renderer_textures = Vec::new();
        for _ in 0..3 {
            renderer_textures.push(run("first").1);
        }
        let (jobs, textures) = run("first");
        renderer_textures.push(textures);
        for textures in &mut renderer_textures {
            for (id, deltas) in &textures.set {
                for delta in deltas {
                    renderer.update_texture(device, queue, *id, delta);
                }
            }
            textures.clear();
        }
        let (direct, layered) = (window("direct"), window("layered"));
        let mut layer = UiLayer::new(device, format);
        assert!(!layer.holds(&jobs, size, 1.0), "nothing is held before the first draw");
        let mut encoder = device.create_command_encoder(&Default::default());
        let buffers = renderer.update_buffers(device, queue, &mut encoder, &jobs, &screen);
        assert!(buffers.is_empty());
        let direct_view = direct.create_view(&Default::default());
        clear_to_gradient(&mut encoder, &direct_view);
        super::super::app::draw_egui(&mut encoder, &renderer, &direct_view, &jobs, &screen, wgpu::LoadOp::Load);
        let target = layer.target(device, size).clone();
        super::super::app::draw_egui(
            &mut encoder,
            &renderer,
            &target,
            &jobs,
            &screen,
            wgpu::LoadOp::Clear(wgpu::Color::TRANSPARENT),
        );
        layer.keep(device, queue, &jobs, size, 1.0);
        let layered_view = layered.create_view(&Default::default());
        clear_to_gradient(&mut encoder, &layered_view);
        layer.draw_over(&mut encoder, &layered_view);
        queue.submit([encoder.finish()]);

        let read = |texture: &wgpu::Texture| -> Vec<u8> {
            let row = (4 * size[0]).div_ceil(256) * 256;
            let buffer = device.create_buffer(&wgpu::BufferDescriptor {
                label: None,
                size: (row * size[1]) as u64,
                usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
                mapped_at_creation: false,
            });
            let mut encoder = device.create_command_encoder(&Default::default());
            encoder.copy_texture_to_buffer(
                texture.as_image_copy(),
                wgpu::TexelCopyBufferInfo {
                    buffer: &buffer,
                    layout: wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(row), rows_per_image: None },
                },
                wgpu::Extent3d { width: size[0], height: size[1], depth_or_array_layers: 1 },
            );
            queue.submit([encoder.finish()]);
            buffer.slice(..).map_async(wgpu::MapMode::Read, |r| r.expect("map"));
            device.poll(wgpu::PollType::wait_indefinitely()).unwrap();
            let data = buffer.slice(..).get_mapped_range().unwrap().to_vec();
            (0..size[1] as usize).flat_map(|y| data[y * row as usize..][..4 * size[0] as usize].to_vec()).collect()
        };
        let (direct_px, layered_px) = (read(&direct), read(&layered));
        let background = [51u8, 153, 230];
        let mut ui_pixels = 0;
        for (i, (d, l)) in direct_px.chunks_exact(4).zip(layered_px.chunks_exact(4)).enumerate() {
            let (x, y) = (i % size[0] as usize, i / size[0] as usize);
            for c in 0..3 {
                assert!(d[c].abs_diff(l[c]) <= 1, "pixel ({x}, {y}) channel {c}: direct {d:?}, layered {l:?}");
            }
            if d[..3].iter().zip(background).any(|(&v, b)| v.abs_diff(b) > 2) {
                ui_pixels += 1;
            }
        }
        // The comparison means something: the panel and the overlay box changed many pixels.
        assert!(ui_pixels > 3000, "only {ui_pixels} pixels show the ui");

        let (same, mut textures) = run("first");
        textures.clear();
        assert!(layer.holds(&same, size, 1.0), "the same output is held");
        assert!(!layer.holds(&same, [size[0], size[1] + 1], 1.0), "another window size is not");
        assert!(!layer.holds(&same, size, 2.0), "another scale is not");
        let (other, mut textures) = run("second");
        textures.clear();
        assert!(!layer.holds(&other, size, 1.0), "other output is not");
    }
}
