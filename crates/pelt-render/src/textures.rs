//! Uploading [`FurTextures`]: the shell slices as one 2D array texture and the fin texture, both
//! with mipmaps so distant fur averages out instead of sparkling.

use pelt_core::texture::FurTextures;

use crate::RenderError;

/// The fur textures on the GPU.
#[derive(Debug)]
pub(crate) struct GpuTextures {
    pub shell: wgpu::TextureView,
    pub fin: wgpu::TextureView,
    pub shell_slices: u32,
    /// Alpha-weighted mean strand colour of the root slice, linear RGB.
    pub root_colour: glam::Vec3,
}

impl GpuTextures {
    pub fn new(device: &wgpu::Device, queue: &wgpu::Queue, textures: &FurTextures) -> Result<Self, RenderError> {
        validate(textures)?;
        let slice_bytes = textures.size as usize * textures.size as usize * 4;
        let shell = upload(
            device,
            queue,
            "pelt shell slices",
            (textures.size, textures.size),
            textures.shell.chunks_exact(slice_bytes).collect(),
        );
        let fin = upload(device, queue, "pelt fin", (textures.fin_width, textures.fin_height), vec![&textures.fin]);
        let shell = shell.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..wgpu::TextureViewDescriptor::default()
        });
        let fin = fin.create_view(&wgpu::TextureViewDescriptor::default());
        Ok(Self { shell, fin, shell_slices: textures.layers, root_colour: root_colour(textures, slice_bytes) })
    }
}

fn validate(textures: &FurTextures) -> Result<(), RenderError> {
    let bad = |message: String| Err(RenderError::Textures(message));
    if textures.size == 0 || textures.layers == 0 || textures.fin_width == 0 || textures.fin_height == 0 {
        return bad(format!(
            "empty texture: shell {0}x{0}x{1}, fin {2}x{3}",
            textures.size, textures.layers, textures.fin_width, textures.fin_height
        ));
    }
    let shell_bytes = textures.size as usize * textures.size as usize * textures.layers as usize * 4;
    if textures.shell.len() != shell_bytes {
        return bad(format!("shell has {} bytes, expected {shell_bytes}", textures.shell.len()));
    }
    let fin_bytes = textures.fin_width as usize * textures.fin_height as usize * 4;
    if textures.fin.len() != fin_bytes {
        return bad(format!("fin has {} bytes, expected {fin_bytes}", textures.fin.len()));
    }
    Ok(())
}

/// Creates an sRGB texture with one array layer per slice and a full mip chain.
fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    (width, height): (u32, u32),
    slices: Vec<&[u8]>,
) -> wgpu::Texture {
    let mip_level_count = 32 - width.max(height).leading_zeros();
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: slices.len() as u32 },
        mip_level_count,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (layer, slice) in slices.into_iter().enumerate() {
        let mut level = slice.to_vec();
        let (mut w, mut h) = (width, height);
        for mip_level in 0..mip_level_count {
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: layer as u32 },
                    aspect: wgpu::TextureAspect::All,
                },
                &level,
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * w), rows_per_image: Some(h) },
                wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            );
            (level, w, h) = downsample(&level, w, h);
        }
    }
    texture
}

/// Halves an RGBA8 image (wrapping, as the tiles do). Colour is averaged weighted by alpha so
/// the empty space between strands does not darken them.
fn downsample(texels: &[u8], width: u32, height: u32) -> (Vec<u8>, u32, u32) {
    let (w, h) = ((width / 2).max(1), (height / 2).max(1));
    let mut out = Vec::with_capacity((w * h * 4) as usize);
    for y in 0..h {
        for x in 0..w {
            let mut sum = [0.0_f32; 4];
            for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                let (sx, sy) = ((2 * x + dx) % width, (2 * y + dy) % height);
                let k = ((sy * width + sx) * 4) as usize;
                let alpha = f32::from(texels[k + 3]);
                for c in 0..3 {
                    sum[c] += f32::from(texels[k + c]) * alpha;
                }
                sum[3] += alpha;
            }
            for c in 0..3 {
                out.push(if sum[3] > 0.0 { (sum[c] / sum[3]).round() as u8 } else { 0 });
            }
            out.push((sum[3] / 4.0).round() as u8);
        }
    }
    (out, w, h)
}

fn srgb_to_linear(value: f32) -> f32 {
    if value <= 0.04045 { value / 12.92 } else { ((value + 0.055) / 1.055).powf(2.4) }
}

/// The colour of the fur at the roots: the first slice's strands, weighted by coverage.
fn root_colour(textures: &FurTextures, slice_bytes: usize) -> glam::Vec3 {
    for slice in textures.shell.chunks_exact(slice_bytes) {
        let (mut sum, mut weight) = (glam::Vec3::ZERO, 0.0);
        for texel in slice.chunks_exact(4) {
            let alpha = f32::from(texel[3]) / 255.0;
            let rgb = glam::Vec3::new(texel[0].into(), texel[1].into(), texel[2].into()) / 255.0;
            sum += rgb.map(srgb_to_linear) * alpha;
            weight += alpha;
        }
        if weight > 0.0 {
            return sum / weight;
        }
    }
    glam::Vec3::splat(0.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn downsampling_keeps_strand_colour_and_mean_coverage() {
        // One opaque red texel among three transparent black ones.
        let texels = [255, 0, 0, 255, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0];
        let (out, w, h) = downsample(&texels, 2, 2);
        assert_eq!((w, h), (1, 1));
        assert_eq!(out, vec![255, 0, 0, 64]);
    }

    #[test]
    fn wrong_sizes_are_errors() {
        let textures = FurTextures {
            size: 4,
            layers: 2,
            shell: vec![0; 4 * 4 * 4],
            fin_width: 2,
            fin_height: 2,
            fin: vec![0; 16],
        };
        assert!(matches!(validate(&textures), Err(RenderError::Textures(_))));
        let textures = FurTextures { shell: vec![0; 4 * 4 * 4 * 2], ..textures };
        assert!(validate(&textures).is_ok());
    }
}
