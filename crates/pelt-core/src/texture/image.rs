//! A small RGBA8 image: the pattern, gradient and surface inputs, and the mip helper.

use std::path::Path;

use glam::Vec4;

/// An RGBA8 image, rows top to bottom, straight (not premultiplied) alpha.
#[derive(Clone, PartialEq, Eq)]
pub struct ImageRgba8 {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// `width * height * 4` bytes.
    pub pixels: Vec<u8>,
}

impl std::fmt::Debug for ImageRgba8 {
    // The pixels would flood every debug print of a preset or a texture set.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "ImageRgba8 {{ {} x {} }}", self.width, self.height)
    }
}

impl ImageRgba8 {
    /// A `width x height` image filled with one colour.
    #[must_use]
    pub fn filled(width: u32, height: u32, rgba: [u8; 4]) -> Self {
        Self { width, height, pixels: rgba.repeat(width as usize * height as usize) }
    }

    /// Decodes a PNG (or GIF) file.
    ///
    /// # Errors
    /// The decoder's message (a missing file, a bad format, an empty image).
    pub fn load(path: &Path) -> Result<Self, String> {
        let decoded = image::open(path).map_err(|e| e.to_string())?.to_rgba8();
        let (width, height) = decoded.dimensions();
        if width == 0 || height == 0 {
            return Err("the image is empty".to_owned());
        }
        Ok(Self { width, height, pixels: decoded.into_raw() })
    }

    /// Encodes as PNG.
    ///
    /// # Errors
    /// The encoder's or the file system's message.
    pub fn save_png(&self, path: &Path) -> Result<(), String> {
        image::save_buffer(path, &self.pixels, self.width, self.height, image::ColorType::Rgba8)
            .map_err(|e| e.to_string())
    }

    /// The texel at `(x, y)` as `0..=1` floats.
    ///
    /// # Panics
    /// If `(x, y)` is outside the image.
    #[must_use]
    pub fn texel(&self, x: u32, y: u32) -> Vec4 {
        assert!(x < self.width && y < self.height, "texel ({x}, {y}) outside {} x {}", self.width, self.height);
        let i = (y as usize * self.width as usize + x as usize) * 4;
        let p = &self.pixels[i..i + 4];
        Vec4::new(f32::from(p[0]), f32::from(p[1]), f32::from(p[2]), f32::from(p[3])) / 255.0
    }

    /// Bilinear sample with wrapping at normalised `(u, v)` (`v = 0` is the top row).
    #[must_use]
    pub fn sample_wrapped(&self, u: f32, v: f32) -> Vec4 {
        let x = u.rem_euclid(1.0) * self.width as f32 - 0.5;
        let y = v.rem_euclid(1.0) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let wrap = |c: f32, n: u32| (c as i64).rem_euclid(i64::from(n)) as u32;
        let (xa, xb) = (wrap(x0, self.width), wrap(x0 + 1.0, self.width));
        let (ya, yb) = (wrap(y0, self.height), wrap(y0 + 1.0, self.height));
        let top = self.texel(xa, ya).lerp(self.texel(xb, ya), fx);
        let bottom = self.texel(xa, yb).lerp(self.texel(xb, yb), fx);
        top.lerp(bottom, fy)
    }
}

/// Halves `count` stacked `width x height` RGBA8 images (straight alpha, sRGB-encoded colour, as
/// the renderer uploads them) with an alpha-weighted 2x2 box filter, so transparent texels do
/// not darken the colour of their neighbours. Colour is averaged in linear light: averaging the
/// encoded bytes darkened every level (a black and white checker came out 128, not 188), so
/// distant fur, sampled from the smaller levels, lost brightness where strands and gaps mix.
///
/// Odd sizes keep their last row or column out of the average; a size of 1 stays 1.
///
/// # Panics
/// If `rgba` is not `count * width * height * 4` bytes.
#[must_use]
pub fn downsample_rgba8(rgba: &[u8], width: u32, height: u32, count: u32) -> Vec<u8> {
    let (w, h) = (width as usize, height as usize);
    assert_eq!(rgba.len(), count as usize * w * h * 4, "image stack size");
    let linear = srgb_to_linear_table();
    let (half_w, half_h) = ((w / 2).max(1), (h / 2).max(1));
    let mut out = Vec::with_capacity(count as usize * half_w * half_h * 4);
    for image in rgba.chunks_exact(w * h * 4) {
        for y in 0..half_h {
            for x in 0..half_w {
                let mut colour = [0.0f32; 3];
                let mut alpha = 0u32;
                let mut plain = [0.0f32; 3];
                for (dx, dy) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    let (sx, sy) = ((2 * x + dx).min(w - 1), (2 * y + dy).min(h - 1));
                    let p = &image[(sy * w + sx) * 4..(sy * w + sx) * 4 + 4];
                    let a = u32::from(p[3]);
                    for c in 0..3 {
                        let value = linear[usize::from(p[c])];
                        colour[c] += value * a as f32;
                        plain[c] += value;
                    }
                    alpha += a;
                }
                for c in 0..3 {
                    // Fully transparent blocks keep their plain mean so filtering never bleeds black.
                    let mean = if alpha > 0 { colour[c] / alpha as f32 } else { plain[c] / 4.0 };
                    out.push(linear_to_srgb_byte(mean, linear));
                }
                out.push(((alpha + 2) / 4) as u8);
            }
        }
    }
    out
}

/// Linear light of each sRGB-encoded byte (IEC 61966-2-1).
fn srgb_to_linear_table() -> &'static [f32; 256] {
    static TABLE: std::sync::OnceLock<[f32; 256]> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        std::array::from_fn(|byte| {
            let v = byte as f32 / 255.0;
            if v <= 0.04045 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
        })
    })
}

/// Buckets of linear light for [`linear_to_srgb_byte`]'s first guess: narrower than the step
/// between any two bytes, so the nearest byte is the guess or one beside it.
const ENCODE_BUCKETS: usize = 4096;

/// The sRGB byte whose linear light is nearest `value`: the table's inverse, so a block of equal
/// texels keeps its byte exactly. A bucket table gives the guess (a mip chain encodes millions of
/// channels; searching the 256 bytes each time added a quarter to `pelt render`'s start).
fn linear_to_srgb_byte(value: f32, linear: &[f32; 256]) -> u8 {
    static GUESS: std::sync::OnceLock<Vec<u8>> = std::sync::OnceLock::new();
    let guess = GUESS.get_or_init(|| {
        (0..ENCODE_BUCKETS).map(|i| nearest_byte((i as f32 + 0.5) / ENCODE_BUCKETS as f32, linear)).collect()
    });
    let value = value.clamp(0.0, 1.0);
    let byte = guess[((value * ENCODE_BUCKETS as f32) as usize).min(ENCODE_BUCKETS - 1)];
    let distance = |b: u8| (linear[usize::from(b)] - value).abs();
    [byte.saturating_sub(1), byte.saturating_add(1)]
        .into_iter()
        .fold(byte, |best, b| if distance(b) < distance(best) { b } else { best })
}

/// The byte nearest `value` by search (ties to the darker byte).
fn nearest_byte(value: f32, linear: &[f32; 256]) -> u8 {
    let above = linear.partition_point(|&l| l < value).min(255);
    if above > 0 && value - linear[above - 1] <= linear[above] - value { (above - 1) as u8 } else { above as u8 }
}

/// Number of levels in a full mip chain of a `size x size` image (`size` a power of two).
#[must_use]
pub fn mip_level_count(size: u32) -> u32 {
    u32::BITS - size.max(1).leading_zeros()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn downsample_weights_colour_by_alpha() {
        // One opaque red texel among three transparent green ones stays pure red, quarter alpha.
        let mut rgba = [0, 255, 0, 0].repeat(4);
        rgba[0..4].copy_from_slice(&[255, 0, 0, 255]);
        assert_eq!(downsample_rgba8(&rgba, 2, 2, 1), vec![255, 0, 0, 64]);
        let transparent = [0, 255, 0, 0].repeat(4);
        assert_eq!(downsample_rgba8(&transparent, 2, 2, 1), vec![0, 255, 0, 0]);
    }

    #[test]
    fn downsample_averages_light_not_bytes() {
        // A black and white checker is half the light: sRGB 188, where the bytes' mean is 128.
        let checker = [[0, 0, 0, 255], [255, 255, 255, 255], [255, 255, 255, 255], [0, 0, 0, 255]].concat();
        assert_eq!(downsample_rgba8(&checker, 2, 2, 1), vec![188, 188, 188, 255]);
        // Equal texels keep their byte, every byte.
        for byte in 0..=255u8 {
            let block = [byte, byte, byte, 255].repeat(4);
            assert_eq!(downsample_rgba8(&block, 2, 2, 1), vec![byte, byte, byte, 255]);
        }
    }

    #[test]
    fn the_bucketed_encoding_is_the_nearest_byte() {
        let linear = srgb_to_linear_table();
        for i in 0..=100_000 {
            let value = i as f32 / 100_000.0;
            let distance = |b: u8| (linear[usize::from(b)] - value).abs();
            // Every byte tried, the first nearest kept.
            let nearest = (0..=255u8).fold(0, |best, b| if distance(b) < distance(best) { b } else { best });
            let fast = linear_to_srgb_byte(value, linear);
            // Equal distance either way is a tie, which the two may break differently.
            assert!(fast == nearest || distance(fast) == distance(nearest), "{value}: {fast} against {nearest}");
        }
    }

    #[test]
    fn mip_counts() {
        assert_eq!(mip_level_count(1), 1);
        assert_eq!(mip_level_count(32), 6);
        assert_eq!(mip_level_count(1024), 11);
    }

    #[test]
    fn sampling_wraps() {
        let mut image = ImageRgba8::filled(4, 4, [0, 0, 0, 255]);
        image.pixels[0] = 255;
        let inside = image.sample_wrapped(0.125, 0.125).x;
        let wrapped = image.sample_wrapped(1.125, -0.875).x;
        assert!((inside - 1.0).abs() < 1e-6 && (wrapped - 1.0).abs() < 1e-6);
        // Halfway between texel 0 and the last texel (across the seam) is half red.
        assert!((image.sample_wrapped(0.0, 0.125).x - 0.5).abs() < 1e-6);
    }
}
