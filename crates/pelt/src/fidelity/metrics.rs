//! What `pelt fidelity` measures between two renders of the same fur: SSIM (image-compare's
//! MSSIM over 8x8 windows, on luma) averaged over a mask, and the mean colour difference; plus
//! the masks (the fur, the silhouette band), the supersampling filter and the heat map.

use image::{GrayImage, Luma, Rgba, RgbaImage};
use image_compare::Algorithm;

/// A per-pixel mask.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Mask {
    pub width: u32,
    pub height: u32,
    pub bits: Vec<bool>,
}

impl Mask {
    /// Pixels where `a` and `b` differ by more than `threshold` (0..=255) in any colour channel.
    pub fn differing(a: &RgbaImage, b: &RgbaImage, threshold: u8) -> Self {
        let bits = a.pixels().zip(b.pixels()).map(|(p, q)| (0..3).any(|c| p[c].abs_diff(q[c]) > threshold)).collect();
        Self { width: a.width(), height: a.height(), bits }
    }

    /// Pixels set in either.
    pub fn union(&self, other: &Self) -> Self {
        let bits = self.bits.iter().zip(&other.bits).map(|(a, b)| *a || *b).collect();
        Self { bits, ..*self }
    }

    /// Pixels set in this and not in `other`.
    pub fn minus(&self, other: &Self) -> Self {
        let bits = self.bits.iter().zip(&other.bits).map(|(a, b)| *a && !*b).collect();
        Self { bits, ..*self }
    }

    /// Grown by `radius` pixels (a square neighbourhood).
    pub fn dilate(&self, radius: u32) -> Self {
        let (w, h, r) = (i64::from(self.width), i64::from(self.height), i64::from(radius));
        let mut bits = vec![false; self.bits.len()];
        for y in 0..h {
            for x in 0..w {
                if self.bits[(y * w + x) as usize] {
                    for yy in (y - r).max(0)..=(y + r).min(h - 1) {
                        for xx in (x - r).max(0)..=(x + r).min(w - 1) {
                            bits[(yy * w + xx) as usize] = true;
                        }
                    }
                }
            }
        }
        Self { bits, ..*self }
    }

    /// Shrunk by `radius` pixels.
    pub fn erode(&self, radius: u32) -> Self {
        let inverted = Self { bits: self.bits.iter().map(|b| !b).collect(), ..*self };
        let grown = inverted.dilate(radius);
        Self { bits: grown.bits.iter().map(|b| !b).collect(), ..*self }
    }

    /// The share of this mask's pixels that `other` holds too (0 for an empty mask).
    pub fn share_of(&self, other: &Self) -> f64 {
        let total = self.count();
        if total == 0 {
            return 0.0;
        }
        self.minus(&self.minus(other)).count() as f64 / total as f64
    }

    pub fn count(&self) -> usize {
        self.bits.iter().filter(|b| **b).count()
    }
}

fn luma(image: &RgbaImage) -> GrayImage {
    GrayImage::from_fn(image.width(), image.height(), |x, y| {
        let p = image.get_pixel(x, y);
        // Rec. 601 weights on the stored (sRGB) values, as image's own conversion does.
        let value = 0.299 * f32::from(p[0]) + 0.587 * f32::from(p[1]) + 0.114 * f32::from(p[2]);
        Luma([value.round().clamp(0.0, 255.0) as u8])
    })
}

/// Side of image-compare's SSIM windows (its MSSIM averages SSIM over 8x8 windows).
const WINDOW: u32 = 8;

/// SSIM of `a` against `b` on luma over the pixels of `mask`: image-compare's SSIM of each 8x8
/// window that holds masked pixels, weighted by how many it holds; `None` for an empty mask.
pub fn masked_ssim(a: &RgbaImage, b: &RgbaImage, mask: &Mask) -> anyhow::Result<Option<f64>> {
    let (luma_a, luma_b) = (luma(a), luma(b));
    let (mut sum, mut weight) = (0.0, 0usize);
    for top in (0..a.height()).step_by(WINDOW as usize) {
        for left in (0..a.width()).step_by(WINDOW as usize) {
            let (w, h) = (WINDOW.min(a.width() - left), WINDOW.min(a.height() - top));
            let inside = (top..top + h)
                .flat_map(|y| (left..left + w).map(move |x| (x, y)))
                .filter(|(x, y)| mask.bits[(y * mask.width + x) as usize])
                .count();
            if inside == 0 {
                continue;
            }
            let crop = |image: &GrayImage| image::imageops::crop_imm(image, left, top, w, h).to_image();
            let window =
                image_compare::gray_similarity_structure(&Algorithm::MSSIMSimple, &crop(&luma_a), &crop(&luma_b))?;
            sum += window.score * inside as f64;
            weight += inside;
        }
    }
    Ok((weight > 0).then(|| sum / weight as f64))
}

/// Over the 8x8 windows holding masked pixels (weighted as in [`masked_ssim`]): the mean luma and
/// the mean standard deviation of luma in a window (the local contrast SSIM compares), 0..=255.
pub fn luma_statistics(image: &RgbaImage, mask: &Mask) -> (f64, f64) {
    let luma = luma(image);
    let (mut mean_sum, mut deviation_sum, mut weight) = (0.0, 0.0, 0usize);
    for top in (0..image.height()).step_by(WINDOW as usize) {
        for left in (0..image.width()).step_by(WINDOW as usize) {
            let pixels: Vec<(u32, u32)> = (top..(top + WINDOW).min(image.height()))
                .flat_map(|y| (left..(left + WINDOW).min(image.width())).map(move |x| (x, y)))
                .collect();
            let inside = pixels.iter().filter(|(x, y)| mask.bits[(y * mask.width + x) as usize]).count();
            if inside == 0 {
                continue;
            }
            let values: Vec<f64> = pixels.iter().map(|(x, y)| f64::from(luma.get_pixel(*x, *y)[0])).collect();
            let mean = values.iter().sum::<f64>() / values.len() as f64;
            let variance = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64;
            mean_sum += mean * inside as f64;
            deviation_sum += variance.sqrt() * inside as f64;
            weight += inside;
        }
    }
    if weight == 0 { (0.0, 0.0) } else { (mean_sum / weight as f64, deviation_sum / weight as f64) }
}

/// Mean over `mask` of the distance between the sRGB colours, scaled to `0..=1` (black against
/// white is 1); `None` for an empty mask.
pub fn mean_colour_difference(a: &RgbaImage, b: &RgbaImage, mask: &Mask) -> Option<f64> {
    let (mut sum, mut count) = (0.0, 0usize);
    for ((p, q), inside) in a.pixels().zip(b.pixels()).zip(&mask.bits) {
        if *inside {
            let squared: f64 = (0..3).map(|c| (f64::from(p[c]) - f64::from(q[c])).powi(2)).sum();
            sum += squared.sqrt() / (255.0 * 3f64.sqrt());
            count += 1;
        }
    }
    (count > 0).then(|| sum / count as f64)
}

fn srgb_to_linear(value: f32) -> f32 {
    if value <= 0.04045 { value / 12.92 } else { ((value + 0.055) / 1.055).powf(2.4) }
}

fn linear_to_srgb(value: f32) -> f32 {
    if value <= 0.003_130_8 { value * 12.92 } else { 1.055 * value.powf(1.0 / 2.4) - 0.055 }
}

/// A supersampled frame filtered down by `factor` on each axis: a box filter in linear light.
pub fn downsample(image: &RgbaImage, factor: u32) -> RgbaImage {
    let (width, height) = (image.width() / factor, image.height() / factor);
    let samples = (factor * factor) as f32;
    RgbaImage::from_fn(width, height, |x, y| {
        let mut sum = [0.0f32; 4];
        for dy in 0..factor {
            for dx in 0..factor {
                let p = image.get_pixel(x * factor + dx, y * factor + dy);
                for c in 0..3 {
                    sum[c] += srgb_to_linear(f32::from(p[c]) / 255.0);
                }
                sum[3] += f32::from(p[3]) / 255.0;
            }
        }
        let encode = |c: usize, v: f32| {
            let v = if c < 3 { linear_to_srgb(v / samples) } else { v / samples };
            (v.clamp(0.0, 1.0) * 255.0).round() as u8
        };
        Rgba([encode(0, sum[0]), encode(1, sum[1]), encode(2, sum[2]), encode(3, sum[3])])
    })
}

/// `image` moved `offset` pixels left and up (the right and bottom edges repeat): the
/// supersampled reference moved by a fraction of an output pixel, to measure how much of SSIM's
/// loss sub-pixel placement alone costs.
pub fn shifted(image: &RgbaImage, offset: u32) -> RgbaImage {
    let (width, height) = image.dimensions();
    RgbaImage::from_fn(width, height, |x, y| {
        *image.get_pixel((x + offset).min(width - 1), (y + offset).min(height - 1))
    })
}

/// A heat map of `a` against `b`: black where they agree, through red and yellow to white at a
/// colour distance of `full` (0..=1) or more.
pub fn heat_map(a: &RgbaImage, b: &RgbaImage, full: f32) -> RgbaImage {
    RgbaImage::from_fn(a.width(), a.height(), |x, y| {
        let (p, q) = (a.get_pixel(x, y), b.get_pixel(x, y));
        let squared: f32 = (0..3).map(|c| (f32::from(p[c]) - f32::from(q[c])).powi(2)).sum();
        let t = (squared.sqrt() / (255.0 * 3f32.sqrt()) / full).clamp(0.0, 1.0);
        let channel = |start: f32| ((t * 3.0 - start).clamp(0.0, 1.0) * 255.0).round() as u8;
        Rgba([channel(0.0), channel(1.0), channel(2.0), 255])
    })
}

/// Images side by side with `gap` pixels of `background` between them.
pub fn side_by_side(images: &[&RgbaImage], gap: u32, background: [u8; 3]) -> RgbaImage {
    let height = images.iter().map(|i| i.height()).max().unwrap_or(0);
    let width = images.iter().map(|i| i.width()).sum::<u32>() + gap * images.len().saturating_sub(1) as u32;
    let [r, g, b] = background;
    let mut out = RgbaImage::from_pixel(width, height, Rgba([r, g, b, 255]));
    let mut left = 0;
    for image in images {
        image::imageops::replace(&mut out, *image, i64::from(left), 0);
        left += image.width() + gap;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn pattern(width: u32, height: u32) -> RgbaImage {
        RgbaImage::from_fn(width, height, |x, y| {
            let v = ((x * 37 + y * 91 + (x * y) % 17) % 256) as u8;
            Rgba([v, v.wrapping_mul(3), 255 - v, 255])
        })
    }

    fn everything(image: &RgbaImage) -> Mask {
        Mask {
            width: image.width(),
            height: image.height(),
            bits: vec![true; (image.width() * image.height()) as usize],
        }
    }

    #[test]
    fn ssim_of_an_image_with_itself_is_one_and_with_blank_is_low() {
        let image = pattern(64, 48);
        let all = everything(&image);
        let same = masked_ssim(&image, &image, &all).unwrap().unwrap();
        assert!((same - 1.0).abs() < 1e-9, "SSIM with itself {same}");
        let blank = RgbaImage::from_pixel(64, 48, Rgba([40, 40, 40, 255]));
        let against_blank = masked_ssim(&image, &blank, &all).unwrap().unwrap();
        assert!(against_blank < 0.2, "SSIM against a blank image {against_blank}");
        assert_eq!(mean_colour_difference(&image, &image, &all), Some(0.0));
        assert!(mean_colour_difference(&image, &blank, &all).unwrap() > 0.1);
        // An empty mask measures nothing rather than dividing by zero.
        let none = Mask { bits: vec![false; all.bits.len()], ..all };
        assert_eq!(masked_ssim(&image, &blank, &none).unwrap(), None);
    }

    #[test]
    fn masks_grow_shrink_and_combine() {
        let mut mask = Mask { width: 9, height: 9, bits: vec![false; 81] };
        mask.bits[4 * 9 + 4] = true;
        assert_eq!(mask.dilate(1).count(), 9);
        assert_eq!(mask.dilate(1).erode(1).count(), 1);
        assert_eq!(mask.dilate(2).minus(&mask.dilate(1)).count(), 16);
        assert_eq!(mask.union(&mask.dilate(1)).count(), 9);
    }

    #[test]
    fn shifting_moves_the_picture_and_repeats_the_edge() {
        let image = RgbaImage::from_fn(3, 2, |x, y| Rgba([x as u8, y as u8, 7, 255]));
        let moved = shifted(&image, 1);
        assert_eq!(moved.dimensions(), (3, 2));
        assert_eq!(moved.get_pixel(0, 0).0, [1, 1, 7, 255]);
        assert_eq!(moved.get_pixel(2, 1).0, [2, 1, 7, 255]);
        assert_eq!(shifted(&image, 0), image);
    }

    #[test]
    fn downsampling_averages_in_linear_light() {
        // Half black, half white: the mean in linear light is 0.5, which is 188 in sRGB.
        let image =
            RgbaImage::from_fn(4, 4, |x, _| if x < 2 { Rgba([0, 0, 0, 255]) } else { Rgba([255, 255, 255, 255]) });
        let small = downsample(&image, 4);
        assert_eq!(small.dimensions(), (1, 1));
        assert_eq!(small.get_pixel(0, 0).0, [188, 188, 188, 255]);
    }
}
