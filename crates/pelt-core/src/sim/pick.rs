//! Ray picking of the base mesh (Möller–Trumbore), so a pointer or a script can touch the fur.

use glam::Vec3;
use rayon::prelude::*;

/// Where a ray first meets the mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Index of the triangle hit.
    pub triangle: u32,
    /// The hit point (world units).
    pub point: Vec3,
    /// Distance along the ray, in units of `ray_direction`'s length.
    pub distance: f32,
    /// Barycentric weights of the triangle's three corners at the hit (they sum to 1).
    pub barycentric: Vec3,
}

/// Triangles per parallel task; below a few thousand, threads cost more than they save.
const CHUNK: usize = 2048;

/// The nearest hit of the ray `origin + t * direction` (`t > 0`) with the triangles, both sides
/// counted. Ties go to the lower triangle index, so the answer never depends on thread count.
/// `None` for a miss, a zero or non-finite direction, or no triangles.
///
/// # Panics
/// If a triangle indexes past `positions`.
#[must_use]
pub fn pick(positions: &[Vec3], triangles: &[[u32; 3]], ray_origin: Vec3, ray_direction: Vec3) -> Option<Hit> {
    if !ray_origin.is_finite() || !ray_direction.is_finite() || ray_direction.length_squared() == 0.0 {
        return None;
    }
    let nearest = |a: Option<Hit>, b: Option<Hit>| match (a, b) {
        (Some(a), Some(b)) => Some(if (b.distance, b.triangle) < (a.distance, a.triangle) { b } else { a }),
        (a, b) => a.or(b),
    };
    triangles
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(c, chunk)| {
            chunk.iter().enumerate().fold(None, |best, (i, corners)| {
                let [a, b, c2] = corners.map(|k| positions[k as usize]);
                let hit = intersect(ray_origin, ray_direction, a, b, c2).map(|(distance, u, v)| Hit {
                    triangle: (c * CHUNK + i) as u32,
                    point: ray_origin + ray_direction * distance,
                    distance,
                    barycentric: Vec3::new(1.0 - u - v, u, v),
                });
                nearest(best, hit)
            })
        })
        .reduce(|| None, nearest)
}

/// Möller–Trumbore: `(t, u, v)` of the hit with triangle `(a, b, c)`, or `None`.
fn intersect(origin: Vec3, direction: Vec3, a: Vec3, b: Vec3, c: Vec3) -> Option<(f32, f32, f32)> {
    let edge1 = b - a;
    let edge2 = c - a;
    let p = direction.cross(edge2);
    let determinant = edge1.dot(p);
    // Relative threshold: parallel rays (and degenerate triangles) miss at any scale.
    if determinant.abs() <= 1e-12 * edge1.length() * edge2.length() * direction.length() || determinant == 0.0 {
        return None;
    }
    let inverse = 1.0 / determinant;
    let s = origin - a;
    let u = s.dot(p) * inverse;
    if !(0.0..=1.0).contains(&u) {
        return None;
    }
    let q = s.cross(edge1);
    let v = direction.dot(q) * inverse;
    if v < 0.0 || u + v > 1.0 {
        return None;
    }
    let t = edge2.dot(q) * inverse;
    (t > 0.0 && t.is_finite()).then_some((t, u, v))
}
