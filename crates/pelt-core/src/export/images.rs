//! The fur's images as PNG, with what the renderer's fragment shaders add per layer and per fin
//! height baked in, so a plain glTF material draws them.

use super::ExportError;
use super::geometry::{linear_to_srgb, srgb_to_linear};
use crate::texture::FurTextures;

/// The renderer's darkening toward the roots (`occlusion` in `shading.wgsl`) at `height`.
pub(super) fn occlusion(root_occlusion: f32, height: f32) -> f32 {
    root_occlusion + (1.0 - root_occlusion) * height.clamp(0.0, 1.0).powf(0.7)
}

/// Slice `slice` as a PNG, its alpha raised to stand for `stride` layers (the renderer's level of
/// detail does the same: a drawn shell takes the opacity of the layers it replaces).
pub(super) fn slice_png(textures: &FurTextures, slice: u32, stride: f32) -> Result<Vec<u8>, ExportError> {
    let mut pixels = textures.slice(slice).to_vec();
    if stride > 1.0 {
        for texel in pixels.chunks_exact_mut(4) {
            let clear = 1.0 - f32::from(texel[3]) / 255.0;
            texel[3] = ((1.0 - clear.powf(stride)) * 255.0).round() as u8;
        }
    }
    png(&pixels, textures.size, textures.size)
}

/// The fin texture as a PNG with the fin shader's thinning (`mix(0.15, 0.6, height)` of alpha)
/// and its root darkening (the occlusion at `sqrt(height)`) baked into each row.
pub(super) fn fin_png(textures: &FurTextures, root_occlusion: f32) -> Result<Vec<u8>, ExportError> {
    let (width, height) = (textures.fin_width as usize, textures.fin_height as usize);
    let mut pixels = textures.fin.clone();
    for (row, texels) in pixels.chunks_exact_mut(width * 4).enumerate() {
        // Row 0 holds the tips.
        let h = 1.0 - row as f32 / (height.max(2) - 1) as f32;
        let thinning = 0.15 + 0.45 * h;
        let darkening = occlusion(root_occlusion, h.sqrt());
        for texel in texels.chunks_exact_mut(4) {
            for c in &mut texel[..3] {
                *c = (linear_to_srgb(srgb_to_linear(f32::from(*c) / 255.0) * darkening) * 255.0).round() as u8;
            }
            texel[3] = (f32::from(texel[3]) * thinning).round() as u8;
        }
    }
    png(&pixels, textures.fin_width, textures.fin_height)
}

/// RGBA8 pixels as PNG bytes.
pub(super) fn png(rgba: &[u8], width: u32, height: u32) -> Result<Vec<u8>, ExportError> {
    use image::ImageEncoder as _;
    let mut bytes = Vec::new();
    image::codecs::png::PngEncoder::new(&mut bytes)
        .write_image(rgba, width, height, image::ExtendedColorType::Rgba8)
        .map_err(|e| ExportError::Image(e.to_string()))?;
    Ok(bytes)
}
