//! Reading a frame back from the GPU into an RGBA image.

use anyhow::Context as _;

/// A pending copy of one texture into a mappable buffer.
#[derive(Debug)]
pub struct FrameCopy {
    buffer: wgpu::Buffer,
    width_px: u32,
    height_px: u32,
    padded_bytes_per_row: u32,
    format: wgpu::TextureFormat,
}

impl FrameCopy {
    /// Records the copy of `texture` (4 bytes per texel, RGBA or BGRA) into `encoder`.
    pub fn encode(device: &wgpu::Device, encoder: &mut wgpu::CommandEncoder, texture: &wgpu::Texture) -> Self {
        let (width_px, height_px) = (texture.width(), texture.height());
        let padded_bytes_per_row = (width_px * 4).next_multiple_of(wgpu::COPY_BYTES_PER_ROW_ALIGNMENT);
        let buffer = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("frame readback"),
            size: u64::from(padded_bytes_per_row) * u64::from(height_px),
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        encoder.copy_texture_to_buffer(
            texture.as_image_copy(),
            wgpu::TexelCopyBufferInfo {
                buffer: &buffer,
                layout: wgpu::TexelCopyBufferLayout {
                    offset: 0,
                    bytes_per_row: Some(padded_bytes_per_row),
                    rows_per_image: Some(height_px),
                },
            },
            texture.size(),
        );
        Self { buffer, width_px, height_px, padded_bytes_per_row, format: texture.format() }
    }

    /// Waits for the copy (after its encoder was submitted) and returns the frame as stored
    /// (sRGB-encoded bytes), alpha forced opaque as the window shows it.
    pub fn read(self, device: &wgpu::Device) -> anyhow::Result<image::RgbaImage> {
        let slice = self.buffer.slice(..);
        let (sender, receiver) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |result| {
            // The receiver waits below; a closed channel only means that wait already failed.
            let _sent = sender.send(result);
        });
        device.poll(wgpu::PollType::wait_indefinitely()).context("waiting for the frame copy")?;
        receiver.recv().context("the frame copy was dropped")?.context("mapping the frame copy")?;
        let swap_red_blue =
            matches!(self.format, wgpu::TextureFormat::Bgra8Unorm | wgpu::TextureFormat::Bgra8UnormSrgb);
        let row_bytes = (self.width_px * 4) as usize;
        let mut pixels = Vec::with_capacity(row_bytes * self.height_px as usize);
        {
            let mapped = slice.get_mapped_range().context("reading the frame copy")?;
            for row in mapped.chunks(self.padded_bytes_per_row as usize).take(self.height_px as usize) {
                for texel in row[..row_bytes].chunks_exact(4) {
                    let [r, g, b] =
                        if swap_red_blue { [texel[2], texel[1], texel[0]] } else { [texel[0], texel[1], texel[2]] };
                    pixels.extend_from_slice(&[r, g, b, 255]);
                }
            }
        }
        self.buffer.unmap();
        image::RgbaImage::from_raw(self.width_px, self.height_px, pixels).context("frame size mismatch")
    }
}
