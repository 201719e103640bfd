//! Bending one strand toward a force: the paper's Equation 1 and its O(L) form.
//!
//! A strand has nodes `P_0..P_L` (`P_0` the root) and rest segments `S_k = P_(k+1) - P_k`. Root
//! first, at node `k`: `V` = the current direction of segment `k`, `F` = the force with unit
//! direction `f`, `a_k = angle(V, f)` (the paper's `acos(dot(V, V2))`), `RN = L - k` the nodes
//! not yet visited. The strand beyond `P_k` turns about `P_k`, around `V x f`, by
//!
//! ```text
//! theta_k = a_k * min(1, |F| * RN * BEND_GAIN / (L^2 * stability))
//! ```
//!
//! This is Equation 1 (`theta = acos(dot(V, V2)) * RN / stability`) with the force's magnitude
//! as a factor, the `min` so no segment ever turns past the force direction, and `RN / L^2` in
//! place of `RN` so the bend of a strand hardly depends on its layer count (the sum of the
//! factors over a strand is about `|F| * BEND_GAIN / (2 * stability)` for any `L`). A zero force
//! or a force parallel or opposite to a segment (zero cross product) turns nothing.
//!
//! This is [`Equation::Pelt`](super::Equation); [`Simulation`](super::Simulation) also offers the
//! paper's literal gain ([`Equation::Paper`](super::Equation)) and runs a batched SIMD form of the
//! same bend (`sim/kernel.rs`, with an exact closed form for straight strands).
//!
//! Since each rotation applies to every later segment, segment `k` ends up as
//! `R_k * R_(k-1) * ... * R_0 * S_k`: [`bend_strand`] keeps that product as a running
//! quaternion (O(L)); [`bend_strand_literal`] rotates the remaining nodes one by one (O(L^2)),
//! exactly as the paper describes, and serves as the oracle.

use glam::{Quat, Vec3};

/// Scales how far a force bends fur; see the module docs. With gravity strength 1, stability 8
/// and 16 layers, a strand growing sideways droops so that its tip turns about a third of the
/// way (roughly 35 degrees) toward the ground: clearly visible, not limp.
pub const BEND_GAIN: f32 = 8.0;

/// Below this sine of the angle between a segment and the force, the two count as parallel (or
/// opposite) and nothing turns: the rotation axis is undefined there.
pub(crate) const PARALLEL_SINE: f32 = 1e-7;

/// The fraction of the angle to the force that node `layers - remaining` turns by:
/// `min(1, force_magnitude * remaining * BEND_GAIN / (layers^2 * stability))`.
///
/// Always in `[0, 1]` for non-negative finite or infinite magnitudes and positive stability.
#[must_use]
#[inline]
pub fn bend_weight(force_magnitude: f32, remaining: u32, layers: u32, stability: f32) -> f32 {
    let l = layers as f32;
    let weight = force_magnitude * (remaining as f32 * BEND_GAIN / (l * l)) / stability;
    // A NaN (0 * infinity from a degenerate input) means no bend; clamp alone would keep it.
    if weight.is_nan() { 0.0 } else { weight.clamp(0.0, 1.0) }
}

/// Splits a force into its unit direction and magnitude without overflow: a finite force
/// whose length overflows `f32` still gets a direction. A zero or non-finite force has none.
#[must_use]
#[inline]
pub(crate) fn split_force(force: Vec3) -> (Vec3, f32) {
    let largest = force.abs().max_element();
    if largest == 0.0 || !largest.is_finite() {
        return (Vec3::ZERO, 0.0);
    }
    let scaled = force / largest;
    let length = scaled.length();
    (scaled / length, length * largest)
}

/// The rotation turning unit `direction` toward unit `force_direction` by `weight` of the angle
/// between them; `None` where they are parallel, opposite, or the force is zero.
#[inline]
fn rotation_toward(direction: Vec3, force_direction: Vec3, weight: f32) -> Option<Quat> {
    let axis = direction.cross(force_direction);
    let sine = axis.length();
    if sine <= PARALLEL_SINE || weight <= 0.0 {
        return None;
    }
    let angle = angle_from_sin_cos(sine, direction.dot(force_direction));
    let (half_sin, half_cos) = sin_cos_quarter_turn(0.5 * angle * weight);
    let axis = axis * (half_sin / sine);
    Some(Quat::from_xyzw(axis.x, axis.y, axis.z, half_cos))
}

/// The angle in `[0, pi]` with this sine (`>= 0`) and cosine: `atan2(sine, cosine)`, which is
/// the paper's `acos(dot)` with its argument clamp built in and accurate near 0 and pi.
///
/// A polynomial (Abramowitz and Stegun 4.4.49, error below 1e-7 rad) rather than libm: it is
/// branch-free arithmetic, so the batched kernel vectorises it, and the scalar and batched paths
/// share one definition.
#[must_use]
#[inline]
pub(crate) fn angle_from_sin_cos(sine: f32, cosine: f32) -> f32 {
    let (a, b) = (sine, cosine.abs());
    let steep = a > b;
    let (numerator, denominator) = if steep { (b, a) } else { (a, b) };
    let t = if denominator > 0.0 { numerator / denominator } else { 0.0 };
    let t2 = t * t;
    let mut p = 0.002_866_225_7_f32;
    for c in [-0.016_165_737, 0.042_909_614, -0.075_289_64, 0.106_562_64, -0.142_089, 0.199_935_51, -0.333_331_45] {
        p = p * t2 + c;
    }
    let mut angle = t + t * t2 * p;
    if steep {
        angle = std::f32::consts::FRAC_PI_2 - angle;
    }
    if cosine < 0.0 { std::f32::consts::PI - angle } else { angle }
}

/// `(sin x, cos x)` for `x` in `[0, pi/2]` by Taylor polynomials (error below 1e-7); branch
/// free for the same reason as [`angle_from_sin_cos`].
#[must_use]
#[inline]
pub(crate) fn sin_cos_quarter_turn(x: f32) -> (f32, f32) {
    let x2 = x * x;
    let sine = x
        * (1.0
            + x2 * (-1.0 / 6.0
                + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362_880.0 - x2 / 39_916_800.0)))));
    let cosine = 1.0
        + x2 * (-0.5
            + x2 * (1.0 / 24.0
                + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40320.0 + x2 * (-1.0 / 3_628_800.0 + x2 / 479_001_600.0)))));
    (sine, cosine)
}

/// Bends one strand in O(L) with a running quaternion; writes its `L + 1` nodes to `nodes`.
///
/// `rest_segments` are the strand's `L` rest segments in the rest frame; `frame` rotates them
/// into the current frame of a deforming base (identity for a static one); `root` is `P_0`.
/// `force` is the total force on the strand (gravity plus field). See the module docs for the
/// angle.
///
/// # Panics
/// If `nodes.len() != rest_segments.len() + 1`.
pub fn bend_strand(root: Vec3, frame: Quat, rest_segments: &[Vec3], force: Vec3, stability: f32, nodes: &mut [Vec3]) {
    assert_eq!(nodes.len(), rest_segments.len() + 1, "a strand has one node more than segments");
    let layers = rest_segments.len() as u32;
    let (force_direction, magnitude) = split_force(force);
    let mut turned = frame;
    let mut node = root;
    nodes[0] = root;
    for (k, (segment, out)) in rest_segments.iter().zip(&mut nodes[1..]).enumerate() {
        let mut current = turned * *segment;
        let length = current.length();
        if length > 0.0 {
            let weight = bend_weight(magnitude, layers - k as u32, layers, stability);
            if let Some(rotation) = rotation_toward(current / length, force_direction, weight) {
                // Renormalised so rounding never lets segment lengths drift over many layers.
                turned = (rotation * turned).normalize();
                current = turned * *segment;
            }
        }
        node += current;
        *out = node;
    }
}

/// The paper's literal loop, O(L^2): at every node, rotate all later nodes about it. Same
/// arguments and result as [`bend_strand`] (up to rounding); kept as the test oracle.
///
/// # Panics
/// If `nodes.len() != rest_segments.len() + 1`.
pub fn bend_strand_literal(
    root: Vec3,
    frame: Quat,
    rest_segments: &[Vec3],
    force: Vec3,
    stability: f32,
    nodes: &mut [Vec3],
) {
    assert_eq!(nodes.len(), rest_segments.len() + 1, "a strand has one node more than segments");
    let layers = rest_segments.len() as u32;
    let (force_direction, magnitude) = split_force(force);
    nodes[0] = root;
    for (k, segment) in rest_segments.iter().enumerate() {
        nodes[k + 1] = nodes[k] + frame * *segment;
    }
    for k in 0..rest_segments.len() {
        let pivot = nodes[k];
        let Some(direction) = (nodes[k + 1] - pivot).try_normalize() else { continue };
        let weight = bend_weight(magnitude, layers - k as u32, layers, stability);
        let Some(rotation) = rotation_toward(direction, force_direction, weight) else { continue };
        for node in &mut nodes[k + 1..] {
            *node = pivot + rotation * (*node - pivot);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn straight(layers: usize, direction: Vec3, length: f32) -> Vec<Vec3> {
        vec![direction * (length / layers as f32); layers]
    }

    #[test]
    fn default_gravity_droops_a_sideways_strand_visibly_but_not_limply() {
        let segments = straight(16, Vec3::X, 1.0);
        let mut nodes = vec![Vec3::ZERO; 17];
        bend_strand(Vec3::ZERO, Quat::IDENTITY, &segments, Vec3::NEG_Y, 8.0, &mut nodes);
        let tip_direction = (nodes[16] - nodes[15]).normalize();
        let turned_deg = tip_direction.angle_between(Vec3::X).to_degrees();
        assert!((25.0..50.0).contains(&turned_deg), "tip turned {turned_deg} degrees");
    }

    #[test]
    fn polynomial_trig_matches_libm() {
        for i in 0..=10_000 {
            let angle = i as f32 / 10_000.0 * std::f32::consts::PI;
            let (s, c) = angle.sin_cos();
            let got = angle_from_sin_cos(s.max(0.0), c);
            assert!((got - angle).abs() < 1e-6, "{angle}: {got}");
            let half = angle * 0.5;
            let (ps, pc) = sin_cos_quarter_turn(half);
            assert!((ps - half.sin()).abs() < 1e-6 && (pc - half.cos()).abs() < 1e-6, "{half}");
        }
        assert_eq!(angle_from_sin_cos(0.0, 1.0), 0.0);
        assert_eq!(angle_from_sin_cos(0.0, -1.0), std::f32::consts::PI);
        assert_eq!(angle_from_sin_cos(0.0, 0.0), 0.0);
    }

    #[test]
    fn split_force_survives_overflowing_lengths() {
        let (direction, magnitude) = split_force(Vec3::splat(f32::MAX));
        assert!((direction.length() - 1.0).abs() < 1e-6);
        assert!(magnitude.is_infinite() || magnitude > 1e38);
        assert_eq!(split_force(Vec3::ZERO), (Vec3::ZERO, 0.0));
        assert_eq!(split_force(Vec3::NAN), (Vec3::ZERO, 0.0));
        assert_eq!(bend_weight(f32::INFINITY, 3, 4, 1.0), 1.0);
    }
}
