//! Writes `assets/presets/fox_length.png`, the length map of `fox_groomed.toml`, from the Fox's
//! geometry: bald at the nose and eyes, half length over the body, growing to full length along
//! the tail. Each texel takes the value of the Fox's surface it maps to: the triangle its uv lies
//! in, or outside every uv island the one it is nearest to inside (by barycentric weight), so
//! bilinear sampling at island edges and corners stays true.
//!
//! `cargo run -p pelt-core --example fox_groom` (deterministic: same bytes every run).

use std::path::Path;

use glam::{Vec2, Vec3};
use pelt_core::{ImportOptions, Mesh};

/// Map size in texels.
const SIZE: u32 = 256;

/// The Fox's nose tip and eyes in its bind pose (located from its texture's eye mark through the
/// uvs; the model is symmetric in x) and the radii around them that grow no fur.
const NOSE: Vec3 = Vec3::new(0.0, 53.7, 66.6);
const EYES: [Vec3; 2] = [Vec3::new(-10.0, 57.5, 44.7), Vec3::new(10.0, 57.5, 44.7)];
const NOSE_RADIUS: f32 = 12.0;
const EYE_RADIUS: f32 = 7.0;
/// The tail runs toward -z: full length from `TAIL_FULL_Z` on, from half at `TAIL_START_Z`.
const TAIL_START_Z: f32 = -40.0;
const TAIL_FULL_Z: f32 = -70.0;

fn length_factor(p: Vec3) -> f32 {
    if p.distance(NOSE) < NOSE_RADIUS || EYES.iter().any(|e| p.distance(*e) < EYE_RADIUS) {
        return 0.0;
    }
    let t = ((p.z - TAIL_START_Z) / (TAIL_FULL_Z - TAIL_START_Z)).clamp(0.0, 1.0);
    0.5 + 0.5 * t * t * (3.0 - 2.0 * t)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let (mesh, _) = Mesh::load(&root.join("assets/meshes/Fox.glb"), &ImportOptions::default())?;
    let uvs = mesh.corner_uvs.as_ref().ok_or("the Fox has no uvs")?;
    let values: Vec<f32> = mesh.positions.iter().map(|p| length_factor(*p)).collect();
    let mut pixels = Vec::with_capacity((SIZE * SIZE) as usize);
    for y in 0..SIZE {
        for x in 0..SIZE {
            let target = Vec2::new((x as f32 + 0.5) / SIZE as f32, (y as f32 + 0.5) / SIZE as f32);
            // The triangle the texel lies deepest inside (by its least barycentric weight).
            let mut best: Option<(f32, [f32; 3], usize)> = None;
            for (t, [a, b, c]) in uvs.iter().enumerate() {
                let area = (*b - *a).perp_dot(*c - *a);
                if area.abs() < 1e-12 {
                    continue;
                }
                let w1 = (target - *a).perp_dot(*c - *a) / area;
                let w2 = (*b - *a).perp_dot(target - *a) / area;
                let w = [1.0 - w1 - w2, w1, w2];
                let inside = w.iter().copied().fold(f32::MAX, f32::min);
                if best.is_none_or(|(depth, _, _)| inside > depth) {
                    best = Some((inside, w, t));
                }
            }
            let value = match best {
                Some((_, w, t)) => {
                    let w = w.map(|w| w.max(0.0));
                    let sum: f32 = w.iter().sum();
                    let corners = mesh.triangles[t].map(|j| values[j as usize]);
                    (0..3).map(|k| corners[k] * w[k]).sum::<f32>() / sum
                }
                None => 0.5,
            };
            pixels.push((value * 255.0).round() as u8);
        }
    }
    let out = root.join("assets/presets/fox_length.png");
    image::GrayImage::from_raw(SIZE, SIZE, pixels).ok_or("size")?.save(&out)?;
    let bald = values.iter().filter(|v| **v == 0.0).count();
    println!("wrote {} ({bald} of {} vertices bald)", out.display(), values.len());
    Ok(())
}
