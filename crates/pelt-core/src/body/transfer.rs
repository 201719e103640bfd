//! Skinning a garment to the body it is worn on: every garment vertex takes the joint weights
//! of the closest point on the body's surface (the barycentric blend of that triangle's three
//! vertices), the usual try-on transfer. Where the garment stands away from the body the closest
//! point can lie between bones (a skirt's hem between the legs finds the inner thighs of both),
//! and the vertex gets a blend of them: [`TransferReport`] says how far and how many. A garment
//! vertex farther than the allowed distance from the body (a strap or a hem standing off it)
//! follows the nearest garment vertex that is within it, and the report counts them; a garment
//! with no vertex within it is an error.

use glam::Vec3;
use rayon::prelude::*;

use crate::anim::{Influences, Rig};
use crate::mesh::Mesh;

/// Why a garment cannot be skinned to a body.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum TransferError {
    /// The rig was built for another mesh.
    #[error("the body's rig has {rig} vertices but the body mesh has {mesh}")]
    RigMismatch {
        /// Vertices the rig has influences for.
        rig: usize,
        /// Vertices of the body mesh.
        mesh: usize,
    },
    /// The body has no triangles.
    #[error("the body has no triangles to take weights from")]
    EmptyBody,
    /// No garment vertex has body surface within the allowed distance.
    #[error(
        "all {count} garment vertices are farther than the allowed {max_distance:.4} from the body's surface \
         (vertex {vertex} at {position:?} is {distance:.4} from it): the garment does not sit on this body \
         (place or scale it onto the body)"
    )]
    TooFar {
        /// The first such vertex.
        vertex: usize,
        /// Its position.
        position: Vec3,
        /// Its distance to the body's surface.
        distance: f32,
        /// The allowed distance.
        max_distance: f32,
        /// Garment vertices beyond the allowed distance.
        count: usize,
    },
    /// A garment or body position is NaN or infinite.
    #[error("{what} vertex {vertex} is not finite")]
    NonFinite {
        /// `"garment"` or `"body"`.
        what: &'static str,
        /// The vertex.
        vertex: usize,
    },
}

/// What a weight transfer found, for reports and docs.
#[derive(Clone, Debug, PartialEq)]
pub struct TransferReport {
    /// Garment vertices skinned.
    pub vertices: usize,
    /// The nearest and farthest any garment vertex is from the body's surface.
    pub distance_range: (f32, f32),
    /// Mean distance to the body's surface.
    pub mean_distance: f32,
    /// Vertices whose closest point lies on a triangle whose corners follow different
    /// dominant joints: they move with a blend of bones (between the legs, at the hip crease).
    pub blended: usize,
    /// Vertices that had more than four joints among their triangle's corners and kept the
    /// four heaviest.
    pub truncated: usize,
    /// Vertices farther than the allowed distance from the body: each takes the weights of the
    /// nearest garment vertex within it.
    pub far: usize,
    /// The allowed distance.
    pub max_distance: f32,
}

impl std::fmt::Display for TransferReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{} garment vertices skinned from the body's closest surface at {:.4} to {:.4} (mean {:.4}); {} take a \
             blend of bones, {} kept their 4 heaviest joints",
            self.vertices,
            self.distance_range.0,
            self.distance_range.1,
            self.mean_distance,
            self.blended,
            self.truncated
        )?;
        if self.far > 0 {
            write!(
                f,
                "; {} farther than {:.4} from the body follow their nearest garment vertex within it",
                self.far, self.max_distance
            )?;
        }
        Ok(())
    }
}

/// The closest point to `p` on triangle `abc`: its barycentric weights `(u, v, w)` for `a`, `b`,
/// `c`, each in `0..=1` summing to 1, exactly 1 on a vertex the point projects onto.
/// (Ericson, Real-Time Collision Detection, 5.1.5.)
#[must_use]
pub fn closest_on_triangle(p: Vec3, a: Vec3, b: Vec3, c: Vec3) -> [f32; 3] {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return [1.0, 0.0, 0.0];
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return [0.0, 1.0, 0.0];
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return [1.0 - v, v, 0.0];
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return [0.0, 0.0, 1.0];
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return [1.0 - w, 0.0, w];
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return [0.0, 1.0 - w, w];
    }
    let denominator = va + vb + vc;
    if denominator.abs() <= f32::MIN_POSITIVE {
        // A degenerate triangle: its nearest corner.
        let nearest = [a, b, c].map(|q| q.distance_squared(p));
        let k = (0..3).min_by(|&i, &j| nearest[i].total_cmp(&nearest[j])).unwrap_or(0);
        let mut weights = [0.0; 3];
        weights[k] = 1.0;
        return weights;
    }
    let (v, w) = (vb / denominator, vc / denominator);
    [1.0 - v - w, v, w]
}

/// The closest point on `mesh` to `p`: `(triangle, barycentric weights, distance)`. Ties go to
/// the lower triangle index, so the answer never depends on thread count.
pub(crate) fn closest_on_mesh(mesh: &Mesh, p: Vec3) -> Option<(usize, [f32; 3], f32)> {
    let mut best: Option<(usize, [f32; 3], f32)> = None;
    for (t, triangle) in mesh.triangles.iter().enumerate() {
        let [a, b, c] = triangle.map(|i| mesh.positions[i as usize]);
        let weights = closest_on_triangle(p, a, b, c);
        let q = a * weights[0] + b * weights[1] + c * weights[2];
        let distance_squared = q.distance_squared(p);
        if best.is_none_or(|(_, _, d)| distance_squared < d) {
            best = Some((t, weights, distance_squared));
        }
    }
    best.map(|(t, w, d)| (t, w, d.sqrt()))
}

/// Blends the influences of a triangle's corners by `barycentric`: weights of a joint add up,
/// the four heaviest are kept (ties to the lower joint) and renormalised. Returns whether more
/// than four joints had weight.
fn blend(corners: [&Influences; 3], barycentric: [f32; 3]) -> (Influences, bool) {
    let mut joints: Vec<(u32, f32)> = Vec::with_capacity(12);
    for (inf, &b) in corners.iter().zip(&barycentric) {
        if b == 0.0 {
            continue;
        }
        for (&joint, &weight) in inf.joints.iter().zip(&inf.weights) {
            if weight == 0.0 {
                continue;
            }
            match joints.iter_mut().find(|(j, _)| *j == joint) {
                Some((_, w)) => *w += weight * b,
                None => joints.push((joint, weight * b)),
            }
        }
    }
    joints.retain(|&(_, w)| w > 0.0);
    joints.sort_by(|x, y| y.1.total_cmp(&x.1).then(x.0.cmp(&y.0)));
    let truncated = joints.len() > 4;
    joints.truncate(4);
    let total: f32 = joints.iter().map(|(_, w)| w).sum();
    let mut out = Influences::default();
    if total > 0.0 {
        for (k, &(joint, weight)) in joints.iter().enumerate() {
            out.joints[k] = joint;
            out.weights[k] = weight / total;
        }
    } else {
        // Only reachable for corners without weight: follow the first corner's first joint.
        out.joints[0] = corners[0].joints[0];
        out.weights[0] = 1.0;
    }
    (out, truncated)
}

/// The joint with the largest weight.
fn dominant(inf: &Influences) -> u32 {
    let k = (0..4).max_by(|&i, &j| inf.weights[i].total_cmp(&inf.weights[j]).then(j.cmp(&i))).unwrap_or(0);
    inf.joints[k]
}

/// A rig for `garment` that follows `body`'s skeleton and clips: each garment vertex takes the
/// blended weights of the closest point on the body's surface (both meshes in the body's bind
/// pose). A vertex farther than `max_distance` from the body takes the weights of the nearest
/// garment vertex within it (the lowest index among equally near ones); the report counts them.
///
/// # Errors
/// [`TransferError`] for a rig of another mesh, an empty body, a non-finite position or a
/// garment with no vertex within `max_distance` of the body.
pub fn transfer_weights(
    body: &Mesh,
    body_rig: &Rig,
    garment: &Mesh,
    max_distance: f32,
) -> Result<(Rig, TransferReport), TransferError> {
    if body_rig.vertex_count() != body.vertex_count() {
        return Err(TransferError::RigMismatch { rig: body_rig.vertex_count(), mesh: body.vertex_count() });
    }
    if body.triangles.is_empty() {
        return Err(TransferError::EmptyBody);
    }
    for (what, mesh) in [("body", body), ("garment", garment)] {
        if let Some(vertex) = mesh.positions.iter().position(|p| !p.is_finite()) {
            return Err(TransferError::NonFinite { what, vertex });
        }
    }
    let source = body_rig.influences();
    let found: Vec<(Influences, f32, bool, bool)> = garment
        .positions
        .par_iter()
        .map(|&p| {
            let (t, barycentric, distance) = closest_on_mesh(body, p).unwrap_or((0, [1.0, 0.0, 0.0], f32::INFINITY));
            let corners = body.triangles[t].map(|i| &source[i as usize]);
            let (influences, truncated) = blend(corners, barycentric);
            let mixed = barycentric
                .iter()
                .zip(corners)
                .filter(|(b, _)| **b > 0.0)
                .map(|(_, inf)| dominant(inf))
                .collect::<Vec<_>>()
                .windows(2)
                .any(|w| w[0] != w[1]);
            (influences, distance, mixed, truncated)
        })
        .collect();
    let is_far = |v: usize| found[v].1.is_nan() || found[v].1 > max_distance;
    let near: Vec<usize> = (0..found.len()).filter(|&v| !is_far(v)).collect();
    let far: Vec<usize> = (0..found.len()).filter(|&v| is_far(v)).collect();
    if near.is_empty()
        && let Some(&vertex) = far.first()
    {
        return Err(TransferError::TooFar {
            vertex,
            position: garment.positions[vertex],
            distance: found[vertex].1,
            max_distance,
            count: far.len(),
        });
    }
    // Each far vertex follows the nearest near one (first index on ties: `min_by` keeps the first).
    let followed: Vec<(usize, usize)> = far
        .par_iter()
        .map(|&v| {
            let p = garment.positions[v];
            let nearest = near
                .iter()
                .copied()
                .min_by(|&a, &b| {
                    garment.positions[a].distance_squared(p).total_cmp(&garment.positions[b].distance_squared(p))
                })
                .expect("checked: one near vertex at least");
            (v, nearest)
        })
        .collect();
    let mut found = found;
    for &(v, nearest) in &followed {
        found[v].0 = found[nearest].0;
    }
    let distances = found.iter().map(|f| f.1);
    let report = TransferReport {
        vertices: found.len(),
        distance_range: distances.clone().fold((f32::INFINITY, 0.0), |(lo, hi), d| (lo.min(d), hi.max(d))),
        mean_distance: distances.sum::<f32>() / found.len().max(1) as f32,
        blended: found.iter().filter(|f| f.2).count(),
        truncated: found.iter().filter(|f| f.3).count(),
        far: far.len(),
        max_distance,
    };
    let influences = found.into_iter().map(|f| f.0).collect();
    Ok((body_rig.with_influences(influences), report))
}

#[cfg(test)]
mod tests {
    use std::collections::BTreeMap;

    use super::*;
    use crate::body::walking_try_on;
    use crate::mesh::ImportOptions;

    fn points(positions: Vec<Vec3>) -> Mesh {
        let n = positions.len();
        Mesh {
            positions,
            normals: vec![Vec3::Y; n],
            corner_uvs: None,
            triangles: Vec::new(),
            edges: Vec::new(),
            edge_faces: Vec::new(),
            colour_sets: Vec::new(),
        }
    }

    /// The oracle: a triangle's corner weights blended by `barycentric`, the four heaviest kept.
    fn expected(rig: &Rig, corners: [u32; 3], barycentric: [f32; 3]) -> BTreeMap<u32, f32> {
        let mut sum: BTreeMap<u32, f64> = BTreeMap::new();
        for (&v, &b) in corners.iter().zip(&barycentric) {
            let inf = rig.influences()[v as usize];
            for k in 0..4 {
                *sum.entry(inf.joints[k]).or_default() += f64::from(inf.weights[k]) * f64::from(b);
            }
        }
        let mut sorted: Vec<(u32, f64)> = sum.into_iter().filter(|e| e.1 > 0.0).collect();
        sorted.sort_by(|x, y| y.1.total_cmp(&x.1));
        sorted.truncate(4);
        let total: f64 = sorted.iter().map(|e| e.1).sum();
        sorted.into_iter().map(|(j, w)| (j, (w / total) as f32)).collect()
    }

    fn weights_of(rig: &Rig, v: usize) -> BTreeMap<u32, f32> {
        let inf = rig.influences()[v];
        (0..4).filter(|&k| inf.weights[k] > 0.0).map(|k| (inf.joints[k], inf.weights[k])).collect()
    }

    fn assert_close(got: &BTreeMap<u32, f32>, want: &BTreeMap<u32, f32>, what: &str) {
        assert_eq!(got.keys().collect::<Vec<_>>(), want.keys().collect::<Vec<_>>(), "{what}: joints");
        for (j, w) in want {
            assert!((got[j] - w).abs() < 1e-5, "{what}: joint {j} has {} not {w}", got[j]);
        }
    }

    #[test]
    fn a_point_on_the_body_takes_that_surface_s_weights() {
        let scene = walking_try_on(&ImportOptions::default()).unwrap();
        let (body, rig) = (&scene.body, &scene.body_rig);
        // Every 97th body vertex, and a point inside every 211th triangle.
        let vertices: Vec<usize> = (0..body.vertex_count()).step_by(97).collect();
        let triangles: Vec<usize> = (0..body.triangles.len()).step_by(211).collect();
        let barycentric = [0.2, 0.3, 0.5];
        let mut positions: Vec<Vec3> = vertices.iter().map(|&v| body.positions[v]).collect();
        positions.extend(triangles.iter().map(|&t| {
            let [a, b, c] = body.triangles[t].map(|i| body.positions[i as usize]);
            a * barycentric[0] + b * barycentric[1] + c * barycentric[2]
        }));
        let (garment_rig, report) = transfer_weights(body, rig, &points(positions), 1e-3).unwrap();
        assert!(report.distance_range.1 < 1e-5, "{report}");
        for (k, &v) in vertices.iter().enumerate() {
            assert_close(&weights_of(&garment_rig, k), &weights_of(rig, v), &format!("body vertex {v}"));
        }
        for (k, &t) in triangles.iter().enumerate() {
            let want = expected(rig, body.triangles[t], barycentric);
            assert_close(&weights_of(&garment_rig, vertices.len() + k), &want, &format!("triangle {t}"));
        }
    }

    #[test]
    fn transferred_weights_sum_to_one_and_do_not_depend_on_threads() {
        let scene = walking_try_on(&ImportOptions::default()).unwrap();
        for v in 0..scene.garment.vertex_count() {
            let total: f32 = scene.garment_rig.influences()[v].weights.iter().sum();
            assert!((total - 1.0).abs() < 1e-5, "vertex {v}: {total}");
            assert!(scene.garment_rig.influences()[v].weights.iter().all(|w| (0.0..=1.0).contains(w)));
        }
        let run = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                transfer_weights(&scene.body, &scene.body_rig, &scene.garment, 1.0).unwrap().0.influences().to_vec()
            })
        };
        let one = run(1);
        assert_eq!(one, run(3));
        assert_eq!(one, scene.garment_rig.influences());
    }

    #[test]
    fn a_garment_away_from_the_body_is_a_clear_error() {
        let scene = walking_try_on(&ImportOptions::default()).unwrap();
        let mut far = scene.garment.clone();
        far.transform(glam::Mat4::from_translation(Vec3::new(5.0, 0.0, 0.0)));
        let error = transfer_weights(&scene.body, &scene.body_rig, &far, 0.2).unwrap_err();
        let TransferError::TooFar { count, distance, .. } = error else { panic!("{error}") };
        assert_eq!(count, far.vertex_count());
        assert!(distance > 4.0);
        assert!(error.to_string().contains("does not sit on this body"), "{error}");
        assert!(error.to_string().starts_with(&format!("all {} garment vertices", far.vertex_count())), "{error}");
        let nan = points(vec![Vec3::NAN]);
        assert!(matches!(
            transfer_weights(&scene.body, &scene.body_rig, &nan, 1.0),
            Err(TransferError::NonFinite { what: "garment", vertex: 0 })
        ));
    }

    #[test]
    fn far_garment_vertices_follow_their_nearest_near_neighbour_and_are_reported() {
        let scene = walking_try_on(&ImportOptions::default()).unwrap();
        let body = &scene.body;
        let on_body = |v: usize| body.positions[v];
        // Two points on the body and a strap hanging off the second: 1 and 2 far away from it.
        let near_a = on_body(0);
        let near_b = on_body(body.vertex_count() / 2);
        let off = Vec3::new(0.0, 0.0, 3.0);
        let garment = points(vec![near_a, near_b + off, near_b, near_b + off * 1.5]);
        let (rig, report) = transfer_weights(body, &scene.body_rig, &garment, 0.1).unwrap();
        assert_eq!(report.far, 2, "{report}");
        assert!(report.to_string().contains("2 farther than 0.1000 from the body follow"), "{report}");
        assert_eq!(rig.influences()[1], rig.influences()[2], "the strap follows the vertex it hangs from");
        assert_eq!(rig.influences()[3], rig.influences()[2]);
        assert_close(&weights_of(&rig, 2), &weights_of(&scene.body_rig, body.vertex_count() / 2), "on the body");
        let (_, all_near) = transfer_weights(body, &scene.body_rig, &points(vec![near_a]), 0.1).unwrap();
        assert!(all_near.far == 0 && !all_near.to_string().contains("farther"), "{all_near}");
    }

    #[test]
    fn closest_point_on_a_triangle_matches_a_dense_search() {
        let (a, b, c) = (Vec3::ZERO, Vec3::X, Vec3::new(0.3, 1.0, 0.0));
        let mut state = 12_345_u32;
        let mut next = || {
            state = state.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            (state >> 8) as f32 / (1 << 24) as f32 * 4.0 - 2.0
        };
        for _ in 0..200 {
            let p = Vec3::new(next(), next(), next());
            let w = closest_on_triangle(p, a, b, c);
            let got = (a * w[0] + b * w[1] + c * w[2]).distance(p);
            // The oracle: the nearest of a dense barycentric grid over the triangle.
            let n = 200;
            let mut best = f32::INFINITY;
            for i in 0..=n {
                for j in 0..=n - i {
                    let (u, v) = (i as f32 / n as f32, j as f32 / n as f32);
                    best = best.min((a * (1.0 - u - v) + b * u + c * v).distance(p));
                }
            }
            assert!(got <= best + 1e-5 && got >= best - 0.01, "{p}: {got} vs {best}");
        }
    }
}
