//! Wet clumps of the strand reference: the gathering `wet.wgsl` draws on the shells
//! (`clump_parting`), made geometry. Clump centres are the jittered centres of square cells of
//! `clump_size` shell texels (`clump_jitter` in `shading.wgsl`, the same hash); a strand gathers
//! toward the centre nearest its root, its cross-section at height `t` moved to
//! `centre + (q - centre) * (1 - a)` with `a = CLUMP_PARTING * clump * mix(0.35, 1, t)`, so the
//! roots part a little and the tips most, and the skin shows along the partings.

use glam::Vec2;

/// The most a soaked strand gathers toward its clump's centre (at the tips), as in `wet.wgsl`.
pub const CLUMP_PARTING: f32 = 0.6;

/// How a wet coat clumps the reference's strands (the preset's `[wet]` and the coat's wetness).
#[derive(Clone, Debug, PartialEq)]
pub struct WetClumps {
    /// Wetness per base vertex, `0..=1`.
    pub wetness: Vec<f32>,
    /// Clump cells, in shell texels (`[wet] clump_size`, the shells' `clump_cell_texels`).
    pub clump_size: f32,
    /// The clump amount a soaked strand adds to its groom's (`[wet] clump_strength`).
    pub clump_strength: f32,
    /// The groom's clump map per base vertex, if it has one.
    pub groom_clump: Option<Vec<f32>>,
}

impl WetClumps {
    /// A vertex's clump amount: its groom's plus `clump_strength` times its wetness, at most 1
    /// (`wet_groom` in `wet.wgsl`).
    pub(crate) fn vertex_clump(&self, vertex: usize) -> f32 {
        let groom = self.groom_clump.as_ref().map_or(0.0, |c| c[vertex]);
        (groom + self.clump_strength.clamp(0.0, 1.0) * self.wetness[vertex].clamp(0.0, 1.0)).min(1.0)
    }
}

/// How far a strand of clump amount `clump` gathers at `height` (0 root, 1 tip).
#[must_use]
pub fn gather_amount(clump: f32, height: f32) -> f32 {
    let h = height.clamp(0.0, 1.0);
    CLUMP_PARTING * clump.clamp(0.0, 1.0) * (0.35 * (1.0 - h) + h)
}

/// The centre of the clump nearest `p` (cell units: texels over the cell size) among the 3x3
/// cells around it, as `clump_uv` picks it.
#[must_use]
pub fn nearest_centre(p: Vec2) -> Vec2 {
    let cell = p.floor();
    let mut best = (f32::INFINITY, cell + 0.5);
    for dy in -1..=1 {
        for dx in -1..=1 {
            let c = cell + Vec2::new(dx as f32, dy as f32);
            let centre = c + jitter(c);
            let d = (centre - p).length_squared();
            if d < best.0 {
                best = (d, centre);
            }
        }
    }
    best.1
}

/// A clump cell's centre within it (0.15..0.85 on each axis), seeded by the cell.
fn jitter(cell: Vec2) -> Vec2 {
    let (x, y) = ((cell.x as i32) as u32, (cell.y as i32) as u32);
    let bits = hash(x.wrapping_mul(0x8da6_b343) ^ hash(y ^ 0x68e3_1da4));
    let unit = Vec2::new((bits & 0xffff) as f32, (bits >> 16) as f32) / 65536.0;
    Vec2::splat(0.15) + unit * 0.7
}

fn hash(x: u32) -> u32 {
    let mut h = x.wrapping_mul(0x9e37_79b9);
    h = (h ^ (h >> 16)).wrapping_mul(0x85eb_ca6b);
    h = (h ^ (h >> 13)).wrapping_mul(0xc2b2_ae35);
    h ^ (h >> 16)
}

/// Where the cross-section `q` (texels) of a strand rooted at `root` stands once gathered by
/// `amount` toward the clump centre nearest the root, in cells of `cell_texels`.
#[must_use]
pub fn gathered(root: Vec2, q: Vec2, amount: f32, cell_texels: f32) -> Vec2 {
    if amount <= 0.0 {
        return q;
    }
    let centre = nearest_centre(root / cell_texels) * cell_texels;
    centre + (q - centre) * (1.0 - amount)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn centres_lie_inside_their_cells_and_vary() {
        let mut seen = Vec::new();
        for y in -3..3 {
            for x in -3..3 {
                let cell = Vec2::new(x as f32, y as f32);
                let c = cell + jitter(cell);
                assert!((c - cell).min_element() >= 0.15 && (c - cell).max_element() <= 0.85, "{cell}: {c}");
                seen.push(c - cell);
            }
        }
        seen.dedup();
        assert!(seen.len() > 30, "jitter repeats: {seen:?}");
    }

    #[test]
    fn gathering_moves_toward_the_root_centre_by_the_amount() {
        let root = Vec2::new(30.0, 41.0);
        let centre = nearest_centre(root / 12.0) * 12.0;
        let q = root + Vec2::new(2.0, -1.0);
        let moved = gathered(root, q, 0.5, 12.0);
        assert!((moved.distance(centre) - 0.5 * q.distance(centre)).abs() < 1e-4);
        assert_eq!(gathered(root, q, 0.0, 12.0), q);
    }
}
