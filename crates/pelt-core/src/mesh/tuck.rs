//! Keeping a body under its garment: where a body drawn plain pokes through the cloth a furry
//! garment is grown on (the try-on scene's thighs press through the skirt's front), its skin
//! shows between the strands as pale specks. [`tuck_under`] moves those body vertices to just
//! under the garment's surface, as cloth pipelines hide the body under clothes.

use std::collections::HashSet;

use glam::Vec3;

use super::{Mesh, NO_FACE, smooth_normals};

/// Moves every vertex of `body` that lies outside `garment` (on the side its normals face) but
/// within `reach` of one of its faces, and whose nearest garment point is not on the garment's
/// border, to `margin` under that face; then recomputes the body's normals if any moved.
/// Returns how many vertices moved. Vertices beyond the border (legs below a hem, the waist above
/// it) are left alone.
pub fn tuck_under(body: &mut Mesh, garment: &Mesh, margin: f32, reach: f32) -> usize {
    let border: HashSet<[u32; 2]> = garment
        .edges
        .iter()
        .zip(&garment.edge_faces)
        .filter(|(_, faces)| faces[1] == NO_FACE)
        .map(|(&[a, b], _)| [a.min(b), a.max(b)])
        .collect();
    let on_border = |a: u32, b: u32| border.contains(&[a.min(b), a.max(b)]);
    let border_vertex: HashSet<u32> = border.iter().flatten().copied().collect();
    let faces: Vec<([Vec3; 3], Vec3, [u32; 3])> = garment
        .triangles
        .iter()
        .filter_map(|&t| {
            let p = t.map(|i| garment.positions[i as usize]);
            let normal = (p[1] - p[0]).cross(p[2] - p[0]).try_normalize()?;
            Some((p, normal, t))
        })
        .collect();
    let (low, high) = garment
        .positions
        .iter()
        .fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let (low, high) = (low - Vec3::splat(reach), high + Vec3::splat(reach));
    let mut moved = 0;
    for vertex in &mut body.positions {
        if vertex.cmplt(low).any() || vertex.cmpgt(high).any() {
            continue;
        }
        let mut nearest: Option<(f32, Vec3, Vec3, Region, [u32; 3])> = None;
        for (p, normal, t) in &faces {
            let (point, region) = closest_on_triangle(*vertex, p);
            let distance = point.distance_squared(*vertex);
            if nearest.is_none_or(|(d, ..)| distance < d) {
                nearest = Some((distance, point, *normal, region, *t));
            }
        }
        let Some((distance, point, normal, region, t)) = nearest else { continue };
        let touches_border = match region {
            Region::Inside => false,
            Region::Edge(i, j) => on_border(t[i], t[j]),
            Region::Corner(i) => border_vertex.contains(&t[i]),
        };
        let outside = (*vertex - point).dot(normal);
        if touches_border || distance.sqrt() > reach || outside <= -margin {
            continue;
        }
        *vertex = point - normal * margin;
        moved += 1;
    }
    if moved > 0 {
        body.normals = smooth_normals(&body.positions, &body.triangles);
    }
    moved
}

/// Where on a triangle the closest point lies: its inside, an edge (corner indices) or a corner.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Region {
    Inside,
    Edge(usize, usize),
    Corner(usize),
}

/// The point of triangle `p` nearest to `q` (Ericson, Real-Time Collision Detection 5.1.5).
fn closest_on_triangle(q: Vec3, p: &[Vec3; 3]) -> (Vec3, Region) {
    let [a, b, c] = *p;
    let (ab, ac, aq) = (b - a, c - a, q - a);
    let (d1, d2) = (ab.dot(aq), ac.dot(aq));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Region::Corner(0));
    }
    let bq = q - b;
    let (d3, d4) = (ab.dot(bq), ac.dot(bq));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Region::Corner(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return (a + ab * (d1 / (d1 - d3)), Region::Edge(0, 1));
    }
    let cq = q - c;
    let (d5, d6) = (ab.dot(cq), ac.dot(cq));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Region::Corner(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return (a + ac * (d2 / (d2 - d6)), Region::Edge(0, 2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), Region::Edge(1, 2));
    }
    let denominator = va + vb + vc;
    if denominator.abs() < f32::MIN_POSITIVE {
        return (a, Region::Corner(0));
    }
    let (v, w) = (vb / denominator, vc / denominator);
    (a + ab * v + ac * w, Region::Inside)
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::mesh::{ImportOptions, RawMesh};

    /// A flat grid of `n` x `n` quads over `[-1, 1]^2` at height `z(x, y)`, facing +Z.
    fn grid(n: u32, z: impl Fn(f32, f32) -> f32) -> Mesh {
        let mut raw = RawMesh::default();
        for j in 0..=n {
            for i in 0..=n {
                let (x, y) = (2.0 * i as f32 / n as f32 - 1.0, 2.0 * j as f32 / n as f32 - 1.0);
                raw.positions.push(Vec3::new(x, y, z(x, y)));
            }
        }
        let at = |i: u32, j: u32| j * (n + 1) + i;
        for j in 0..n {
            for i in 0..n {
                raw.triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                raw.triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        Mesh::from_raw(raw, Path::new("test grid"), &ImportOptions::default()).expect("grid").0
    }

    #[test]
    fn a_bump_through_the_cloth_goes_under_it_and_the_rest_stays() {
        // The cloth: z = 0 over [-1, 1]^2. The body: a wider sheet at z = -0.2 with a bump up to
        // z = +0.15 in the middle, poking through.
        let cloth = grid(4, |_, _| 0.0);
        let mut body = grid(20, |x, y| -0.2 + 0.35 * (-(x * x + y * y) * 20.0).exp());
        let (before, margin) = (body.positions.clone(), 0.01);
        let moved = tuck_under(&mut body, &cloth, margin, 0.5);
        assert!(moved > 0);
        for (old, new) in before.iter().zip(&body.positions) {
            let covered = old.x.abs() < 1.0 - 1e-4 && old.y.abs() < 1.0 - 1e-4;
            if covered && old.z > -margin {
                assert!((new.z + margin).abs() < 1e-5, "{old} went to {new}, not just under the cloth");
                assert!(new.truncate().distance(old.truncate()) < 1e-5, "moved sideways: {old} -> {new}");
            } else {
                assert_eq!(old, new, "a vertex not poking through (or beyond the border) moved");
            }
        }
        assert!(body.normals.iter().all(|n| n.is_finite()));
    }
}
