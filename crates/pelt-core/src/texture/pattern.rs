//! A procedural, seamless leopard-rosette pattern (the shipped `assets/patterns/leopard.png`).

use std::f32::consts::TAU;

use glam::{Vec2, Vec3};

use super::ImageRgba8;
use crate::rng::{hash, mix64, unit_f32};

const GROUND: Vec3 = Vec3::new(0.84, 0.62, 0.31);
const PALE: Vec3 = Vec3::new(0.93, 0.80, 0.55);
const INSIDE: Vec3 = Vec3::new(0.72, 0.46, 0.20);
const SPOT: Vec3 = Vec3::new(0.24, 0.15, 0.08);

/// A seamless `size x size` leopard pattern: rosettes (broken rings of dark blobs around a
/// darker centre) on a jittered grid, a few solid spots between them, on a tawny ground.
///
/// The dark spots stay just bright enough (brightest channel about 24 %) to grow nearly full
/// fur, so a tinting preset shows dark fur there rather than bald patches.
#[must_use]
pub fn leopard_pattern(size: u32, seed: u64) -> ImageRgba8 {
    let cells = (size / 40).max(2);
    let cell = size as f32 / cells as f32;
    let extent = size as f32;
    let mut pixels = Vec::with_capacity(size as usize * size as usize * 4);
    for y in 0..size {
        for x in 0..size {
            let p = Vec2::new(x as f32 + 0.5, y as f32 + 0.5);
            // A slow, tiling variation of the ground (integer frequencies wrap with the tile).
            let (u, v) = (p.x / extent * TAU, p.y / extent * TAU);
            let shade = 0.5 + 0.25 * (u + 2.0 * v).sin() + 0.25 * (2.0 * u - v).cos();
            let mut colour = GROUND.lerp(PALE, shade * 0.5);
            let (cx, cy) = ((p.x / cell).floor() as i64, (p.y / cell).floor() as i64);
            for dy in -1..=1 {
                for dx in -1..=1 {
                    colour = rosette(seed, cells, cell, cx + dx, cy + dy, p, colour);
                }
            }
            let [r, g, b] = colour.to_array().map(|c| (c.clamp(0.0, 1.0) * 255.0).round() as u8);
            pixels.extend_from_slice(&[r, g, b, 255]);
        }
    }
    ImageRgba8 { width: size, height: size, pixels }
}

/// Paints rosette `(cx, cy)` (cell indices, wrapped) over `colour` at point `p`.
fn rosette(seed: u64, cells: u32, cell: f32, cx: i64, cy: i64, p: Vec2, colour: Vec3) -> Vec3 {
    let n = i64::from(cells);
    let bits = hash(seed, cx.rem_euclid(n) as u64, cy.rem_euclid(n) as u64, 0x726f_7365);
    let draw = |k: u64| unit_f32(mix64(bits ^ k));
    let centre = (Vec2::new(cx as f32, cy as f32) + Vec2::new(draw(1), draw(2)) * 0.5 + 0.25) * cell;
    let radius = cell * (0.2 + 0.08 * draw(3));
    let offset = p - centre;
    let distance = offset.length();
    if distance > radius * 1.8 {
        return colour;
    }
    // Every fourth rosette is a solid spot instead of a ring.
    if draw(4) < 0.25 {
        let wobble = 1.0 + 0.15 * (3.0 * offset.to_angle() + TAU * draw(5)).sin();
        return if distance < radius * 0.7 * wobble { SPOT } else { colour };
    }
    let mut result = if distance < radius { INSIDE } else { colour };
    let blobs = 5 + (draw(6) * 3.0) as u32;
    let gap = (draw(7) * blobs as f32) as u32;
    for k in 0..blobs {
        if k == gap {
            continue; // Rosettes are broken rings.
        }
        let angle = (k as f32 + 0.3 * draw(10 + u64::from(k))) / blobs as f32 * TAU + draw(8) * TAU;
        let blob = Vec2::from_angle(angle) * radius;
        let stretch = Vec2::from_angle(angle + std::f32::consts::FRAC_PI_2);
        // Blobs are stretched along the ring, like the crescents of a real rosette.
        let local = offset - blob;
        let along = local.dot(stretch) / 1.6;
        let across = local.dot(Vec2::from_angle(angle));
        if along * along + across * across < (radius * 0.32) * (radius * 0.32) {
            result = SPOT;
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn leopard_has_spots_and_follows_its_seed() {
        let image = leopard_pattern(96, 3);
        let dark = image.pixels.chunks_exact(4).filter(|p| p[0] < 100).count();
        let share = dark as f32 / (96.0 * 96.0);
        assert!((0.03..0.4).contains(&share), "spot share {share}");
        assert_eq!(leopard_pattern(96, 3), image);
        assert_ne!(leopard_pattern(96, 4), image);
    }
}
