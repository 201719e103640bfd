//! Helpers the contact tests share.

use pelt_core::fur::FurStructure;

/// A vertex on the bunny's back: facing up, nearest the middle of its box across X and Z.
pub fn back(fur: &FurStructure) -> usize {
    let p = &fur.mesh.positions;
    let (lo, hi) = fur.mesh.bounds();
    let middle = (lo + hi) * 0.5;
    (0..p.len())
        .filter(|&j| fur.mesh.normals[j].y > 0.9)
        .min_by(|&a, &b| {
            let d = |j: usize| (p[j] - middle).with_y(0.0).length();
            d(a).total_cmp(&d(b))
        })
        .expect("a vertex facing up")
}
