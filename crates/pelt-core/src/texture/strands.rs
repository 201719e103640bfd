//! The seeded strand field and its rasterisation into shell slices and the fin.

use std::f32::consts::TAU;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::{ImageRgba8, Style, TILT_STEP_TEXELS, TextureParams};
use crate::rng::{hash, mix64, unit_f32};

/// Heights below this fraction of the fur get the root blur, fading out toward it.
const ROOT_ZONE: f32 = 0.4;
/// The fin shows the strands rooted in a band this many root radii deep (a side view through
/// the whole tile would be solid).
const FIN_BAND_RADII: f32 = 3.0;
/// The fin shows the whole fur length in its rows, as if the fur were an eighth of the tile
/// tall, while it is half the tile high: sideways offsets (lean, curl, clumping) scale by 4.
const FIN_SIDEWAYS_SCALE: f32 = 4.0;
/// A strand's brightest pattern channel at or above this grows full density; black grows none.
const PATTERN_FULL_DENSITY: f32 = 0.25;

// Salts keep the independent random draws of one texel apart.
const SALT_ROOT: u64 = 0x726f_6f74;
const SALT_JITTER: u64 = 0x6a69_7474;
const SALT_LEAN: u64 = 0x6c65_616e;
const SALT_CURL: u64 = 0x6375_726c;
const SALT_LOOK: u64 = 0x6c6f_6f6b;
const SALT_CLUMP: u64 = 0x636c_756d;
const SALT_KEEP: u64 = 0x6b65_6570;
const SALT_EMPTY: u64 = 0x656d_7074;

/// One strand of the seeded field: where it roots in the tile and how it moves through the
/// layers (texel units). The shell slices and the fin are drawn from these, and the explicit
/// reference (`crate::reference`) places the very same strands on a mesh.
#[derive(Clone, Copy, Debug)]
pub struct Strand {
    root: Vec2,
    /// Offset of the tip from the root by lean alone.
    lean: Vec2,
    /// Offset toward the clump centre reached at the tip.
    pull: Vec2,
    curl_radius: f32,
    curl_phase: f32,
    curl_turns: f32,
    radius: f32,
    /// Height (fraction of the fur length) where this strand ends.
    length: f32,
    pub(super) brightness: f32,
    /// The pattern's colour at the root (white without a tinting pattern).
    pub(super) tint: Vec3,
    /// The strand's seeded value for a groom's density (`0..=254`): the shader keeps the strand
    /// where `(keep + 0.5) / 256` is below the density.
    pub(super) keep: u8,
}

impl Strand {
    /// Where the strand roots in the tile, texels (`0..size` on both axes).
    #[must_use]
    pub fn root(&self) -> Vec2 {
        self.root
    }

    /// The strand's length as a fraction of the fur's length (its height where it ends).
    #[must_use]
    pub fn length_factor(&self) -> f32 {
        self.length
    }

    /// The strand's seeded value for a groom's density, `0..1`: it is kept where this lies below
    /// the density (as the shader keeps it).
    #[must_use]
    pub fn keep_value(&self) -> f32 {
        (f32::from(self.keep) + 0.5) / 256.0
    }

    /// Radius of the cross-section at height `t` (texels), tapering toward the strand's end by
    /// `taper` ([`TextureParams::taper`]); the texture's soft edge and root blur are left out.
    #[must_use]
    pub fn radius_at(&self, t: f32, taper: f32) -> f32 {
        self.radius * (1.0 - taper * (t / self.length).clamp(0.0, 1.0))
    }

    /// The cross-section centre at height `t` (0 = root, 1 = the fur's tip layer), texels:
    /// lean, clumping pull and curl.
    #[must_use]
    pub fn centre(&self, t: f32) -> Vec2 {
        let mut centre = self.root + (self.lean + self.pull) * t;
        if self.curl_radius > 0.0 {
            let start = Vec2::from_angle(self.curl_phase);
            let now = Vec2::from_angle(self.curl_phase + TAU * self.curl_turns * t);
            // Subtracting the start keeps the root in place: the helix winds around the lean line.
            centre += (now - start) * self.curl_radius;
        }
        centre
    }

    /// How fast the cross-section moves at height `t`: `d centre / dt`, texels per fur length
    /// (the lean and pull, and the curl's turn). A strand's tangent tilts off its column by this.
    #[must_use]
    pub fn tilt(&self, t: f32) -> Vec2 {
        let mut tilt = self.lean + self.pull;
        if self.curl_radius > 0.0 {
            let rate = TAU * self.curl_turns;
            tilt += Vec2::from_angle(self.curl_phase + rate * t).perp() * (self.curl_radius * rate);
        }
        tilt
    }

    /// `(inner, outer)` radii at height `t`: full coverage inside `inner`, none beyond `outer`;
    /// `None` above the strand's end.
    fn profile(&self, t: f32, taper: f32, root_blur: f32) -> Option<(f32, f32)> {
        if t > self.length {
            return None;
        }
        let radius = self.radius * (1.0 - taper * t / self.length);
        let blur = root_blur * (1.0 - t / ROOT_ZONE).max(0.0);
        Some((radius - 0.5, radius + 0.5 + blur))
    }
}

/// Coverage of a texel centre `distance` away from a cross-section with these radii.
#[inline]
fn coverage(distance: f32, inner: f32, outer: f32) -> f32 {
    let c = ((outer - distance) / (outer - inner)).clamp(0.0, 1.0);
    c * c * (3.0 - 2.0 * c)
}

/// Seeds one strand per texel where the seed passes the density threshold, in row order.
pub(super) fn seed_strands(
    params: &TextureParams,
    pattern: Option<&ImageRgba8>,
    brightness_variation: f32,
) -> Vec<Strand> {
    let size = params.size;
    let extent = size as f32;
    let seed = params.seed;
    // Density is the share of the tile the root cross-sections cover (before overlaps).
    let root_area = std::f32::consts::PI * params.thickness * params.thickness;
    let probability = (params.density / root_area).min(1.0);
    let clumps = Clumps::new(params);
    (0..size)
        .into_par_iter()
        .flat_map_iter(|y| {
            let clumps = &clumps;
            (0..size).filter_map(move |x| {
                let (x64, y64) = (u64::from(x), u64::from(y));
                let jitter = hash(seed, x64, y64, SALT_JITTER);
                let root = Vec2::new(x as f32 + unit_f32(jitter), y as f32 + unit_f32(mix64(jitter)));
                let mut threshold = probability;
                let mut tint = Vec3::ONE;
                if let Some(image) = pattern {
                    let texel = image.sample_wrapped(root.x / extent, root.y / extent);
                    let value = texel.x.max(texel.y).max(texel.z);
                    threshold *= texel.w * (value / PATTERN_FULL_DENSITY).min(1.0);
                    if params.pattern_tint {
                        tint = texel.truncate();
                    }
                }
                if unit_f32(hash(seed, x64, y64, SALT_ROOT)) >= threshold {
                    return None;
                }
                Some(grow_strand(params, clumps, root, tint, brightness_variation, [x64, y64]))
            })
        })
        .collect()
}

fn grow_strand(
    params: &TextureParams,
    clumps: &Clumps,
    root: Vec2,
    tint: Vec3,
    brightness_variation: f32,
    [x, y]: [u64; 2],
) -> Strand {
    let seed = params.seed;
    let lean_bits = hash(seed, x, y, SALT_LEAN);
    let leans = match params.style {
        Style::Straight => false,
        Style::Random => true,
        Style::Mixed => unit_f32(lean_bits) < params.mixed_ratio,
    };
    let lean = if leans {
        let angle = unit_f32(mix64(lean_bits)) * TAU;
        Vec2::from_angle(angle) * params.lean * (0.5 + 0.5 * unit_f32(mix64(lean_bits ^ 1)))
    } else {
        Vec2::ZERO
    };
    let curl_bits = hash(seed, x, y, SALT_CURL);
    let look_bits = hash(seed, x, y, SALT_LOOK);
    // A quarter of the spread lies past the tip layer, so the outermost shell still catches tips.
    let length = 1.0 + params.length_variation * (1.0 / 3.0 - 4.0 / 3.0 * unit_f32(look_bits));
    Strand {
        root,
        lean,
        pull: clumps.pull(root) * params.clump,
        curl_radius: params.curl_radius * (0.75 + 0.5 * unit_f32(curl_bits)),
        curl_phase: unit_f32(mix64(curl_bits)) * TAU,
        curl_turns: params.curl_turns * (0.8 + 0.4 * unit_f32(mix64(curl_bits ^ 1))),
        radius: params.thickness * (0.8 + 0.4 * unit_f32(mix64(look_bits))),
        length: length.max(0.05),
        brightness: 1.0 - brightness_variation * unit_f32(mix64(look_bits ^ 1)),
        tint,
        keep: keep_byte(hash(seed, x, y, SALT_KEEP)),
    }
}

/// Clump centres on a jittered grid that divides the tile, so clumps wrap with it.
struct Clumps {
    cells: u32,
    cell_size: f32,
    seed: u64,
}

impl Clumps {
    fn new(params: &TextureParams) -> Self {
        let cells = ((params.size as f32 / params.clump_size).round() as u32).max(1);
        Self { cells, cell_size: params.size as f32 / cells as f32, seed: params.seed }
    }

    fn centre(&self, cx: i64, cy: i64) -> Vec2 {
        let n = i64::from(self.cells);
        let bits = hash(self.seed, cx.rem_euclid(n) as u64, cy.rem_euclid(n) as u64, SALT_CLUMP);
        let jitter = Vec2::new(unit_f32(bits), unit_f32(mix64(bits))) * 0.7 + 0.15;
        (Vec2::new(cx as f32, cy as f32) + jitter) * self.cell_size
    }

    /// From `root` to the nearest clump centre (measured on the torus, so it is short).
    fn pull(&self, root: Vec2) -> Vec2 {
        let cx = (root.x / self.cell_size).floor() as i64;
        let cy = (root.y / self.cell_size).floor() as i64;
        let mut best = Vec2::ZERO;
        let mut best_distance = f32::INFINITY;
        for dy in -1..=1 {
            for dx in -1..=1 {
                let to_centre = self.centre(cx + dx, cy + dy) - root;
                if to_centre.length_squared() < best_distance {
                    best_distance = to_centre.length_squared();
                    best = to_centre;
                }
            }
        }
        best
    }
}

/// Per-strand colour at height `t`, straight, `0..=1`.
pub(super) type ColourAt<'a> = &'a (dyn Fn(&Strand, f32) -> Vec3 + Sync);

/// Straight-alpha accumulation of overlapping strands: coverage unions as `1 - prod(1 - a)`,
/// colour is the coverage-weighted mean, so the result does not depend on drawing order.
#[derive(Clone, Copy, Default)]
struct Texel {
    transmission: f32,
    weight: f32,
    colour: Vec3,
    /// The largest coverage one strand gives the texel, and that strand's keep value.
    best: f32,
    /// That strand's index (its keep value and tilt), `u32::MAX` for none.
    strand: u32,
}

/// A uniform byte in `0..=254` from seed bits (255 would never pass a density of 1).
fn keep_byte(bits: u64) -> u8 {
    (unit_f32(bits) * 255.0).min(254.0) as u8
}

fn resolve(texels: &[Texel], out: &mut [u8]) {
    // Transparent texels carry the mean strand colour so bilinear filtering never bleeds black.
    let (sum, weight) = texels.iter().fold((Vec3::ZERO, 0.0), |(s, w), t| (s + t.colour, w + t.weight));
    let fallback = if weight > 0.0 { sum / weight } else { Vec3::ZERO };
    for (texel, rgba) in texels.iter().zip(out.chunks_exact_mut(4)) {
        let colour = if texel.weight > 0.0 { texel.colour / texel.weight } else { fallback };
        let alpha = 1.0 - texel.transmission;
        for (c, value) in colour.to_array().into_iter().chain([alpha]).enumerate() {
            rgba[c] = (value.clamp(0.0, 1.0) * 255.0).round() as u8;
        }
    }
}

/// Rasterises the cross-sections of every strand alive at height `t` into one `size x size`
/// RGBA8 slice, into `keep` (`size x size` bytes) the keep value of the strand covering each
/// texel most (empty texels get a seeded value of their own, so a minified fetch that lands on
/// one thins by the density too), and into `tilt` (two bytes a texel) that strand's tilt times
/// the texel's coverage ([`FurTextures::strand_tilt`]).
pub(super) fn draw_slice(
    params: &TextureParams,
    strands: &[Strand],
    (t, slice): (f32, u64),
    colour: ColourAt<'_>,
    (out, keep, tilt): (&mut [u8], &mut [u8], &mut [u8]),
) {
    let size = params.size as usize;
    let mask = size as i64 - 1;
    let mut texels = vec![Texel { transmission: 1.0, strand: u32::MAX, ..Texel::default() }; size * size];
    for (index, strand) in (0u32..).zip(strands) {
        let Some((inner, outer)) = strand.profile(t, params.taper, params.root_blur) else { continue };
        let centre = strand.centre(t);
        let rgb = colour(strand, t);
        let outer_squared = outer * outer;
        let (x0, x1) = ((centre.x - outer).floor() as i64, (centre.x + outer).ceil() as i64);
        let (y0, y1) = ((centre.y - outer).floor() as i64, (centre.y + outer).ceil() as i64);
        for y in y0..y1 {
            let dy = y as f32 + 0.5 - centre.y;
            // The size is a power of two, so masking wraps negative and large indices alike.
            let row = (y & mask) as usize * size;
            for x in x0..x1 {
                let dx = x as f32 + 0.5 - centre.x;
                let distance_squared = dx * dx + dy * dy;
                if distance_squared >= outer_squared {
                    continue;
                }
                let a = coverage(distance_squared.sqrt(), inner, outer);
                if a > 0.0 {
                    let texel = &mut texels[row + (x & mask) as usize];
                    texel.transmission *= 1.0 - a;
                    texel.weight += a;
                    texel.colour += rgb * a;
                    if a > texel.best {
                        texel.best = a;
                        texel.strand = index;
                    }
                }
            }
        }
    }
    resolve(&texels, out);
    let tilts: Vec<Vec2> = strands.iter().map(|strand| strand.tilt(t) / TILT_STEP_TEXELS).collect();
    for (k, ((texel, value), pair)) in texels.iter().zip(keep.iter_mut()).zip(tilt.chunks_exact_mut(2)).enumerate() {
        let Some(strand) = strands.get(texel.strand as usize) else {
            *value = keep_byte(hash(params.seed, k as u64, slice, SALT_EMPTY));
            pair.copy_from_slice(&[0, 0]);
            continue;
        };
        *value = strand.keep;
        // Premultiplied, so a bilinear fetch weighs each texel's tilt by its coverage.
        let steps = tilts[texel.strand as usize] * (1.0 - texel.transmission);
        pair.copy_from_slice(&[tilt_byte(steps.x), tilt_byte(steps.y)]);
    }
}

/// A tilt component in [`TILT_STEP_TEXELS`] steps as [`FurTextures::strand_tilt`] stores it: a
/// signed byte (two's complement, as an `Rg8Snorm` texel reads it).
fn tilt_byte(steps: f32) -> u8 {
    steps.round().clamp(-127.0, 127.0) as i8 as u8
}

/// The fin: a side view of the strands rooted in a thin band of the tile, `u` along the tile's
/// x axis (wrapping), row 0 at the tips.
pub(super) fn draw_fin(params: &TextureParams, strands: &[Strand], height: u32, colour: ColourAt<'_>, out: &mut [u8]) {
    let band = FIN_BAND_RADII * params.thickness;
    let in_band: Vec<&Strand> = strands.iter().filter(|s| s.root.y < band).collect();
    let width = params.size as usize;
    let mask = width as i64 - 1;
    out.par_chunks_mut(width * 4).enumerate().for_each(|(row, out_row)| {
        let t = 1.0 - (row as f32 + 0.5) / height as f32;
        let mut texels = vec![Texel { transmission: 1.0, ..Texel::default() }; width];
        for strand in &in_band {
            let Some((inner, outer)) = strand.profile(t, params.taper, params.root_blur) else { continue };
            let centre = strand.root.x + (strand.centre(t).x - strand.root.x) * FIN_SIDEWAYS_SCALE;
            let rgb = colour(strand, t);
            for x in (centre - outer).floor() as i64..(centre + outer).ceil() as i64 {
                let a = coverage((x as f32 + 0.5 - centre).abs(), inner, outer);
                if a > 0.0 {
                    let texel = &mut texels[(x & mask) as usize];
                    texel.transmission *= 1.0 - a;
                    texel.weight += a;
                    texel.colour += rgb * a;
                }
            }
        }
        resolve(&texels, out_row);
    });
}
