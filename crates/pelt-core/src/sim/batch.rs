//! [`bend_strand`](super::bend_strand) on [`LANES`] strands at once, structure of arrays, so the
//! compiler turns every operation into SIMD instructions (plain arrays, no `unsafe`, no
//! intrinsics: it vectorises the fixed-length lane loops).
//!
//! Same arithmetic as the scalar path, in the same order, with branches replaced by selects.

use glam::{Quat, Vec3};

use super::bend::{BEND_GAIN, PARALLEL_SINE, split_force};

/// Strands per batch.
pub(crate) const LANES: usize = 8;

/// One `f32` per strand of a batch.
pub(crate) type Lanes = [f32; LANES];

/// A vector per strand of a batch: `[x, y, z]` lanes.
pub(crate) type VecLanes = [Lanes; 3];

#[inline(always)]
fn map(f: impl Fn(usize) -> f32) -> Lanes {
    std::array::from_fn(f)
}

#[inline(always)]
fn dot(a: &VecLanes, b: &VecLanes) -> Lanes {
    map(|i| a[0][i] * b[0][i] + a[1][i] * b[1][i] + a[2][i] * b[2][i])
}

#[inline(always)]
fn cross(a: &VecLanes, b: &VecLanes) -> VecLanes {
    [
        map(|i| a[1][i] * b[2][i] - b[1][i] * a[2][i]),
        map(|i| a[2][i] * b[0][i] - b[2][i] * a[0][i]),
        map(|i| a[0][i] * b[1][i] - b[0][i] * a[1][i]),
    ]
}

/// `q * v` as glam computes it (`v + 2w (u x v) + 2 u x (u x v)`).
#[inline(always)]
fn rotate(q: &[Lanes; 4], v: &VecLanes) -> VecLanes {
    let u = [q[0], q[1], q[2]];
    let w = q[3];
    let uv = cross(&u, v);
    let uuv = cross(&u, &uv);
    std::array::from_fn(|c| map(|i| v[c][i] + ((uv[c][i] * w[i]) + uuv[c][i]) * 2.0))
}

/// Quaternion product `a * b` (glam's component formula).
#[inline(always)]
fn mul(a: &[Lanes; 4], b: &[Lanes; 4]) -> [Lanes; 4] {
    let [ax, ay, az, aw] = a;
    let [bx, by, bz, bw] = b;
    [
        map(|i| aw[i] * bx[i] + ax[i] * bw[i] + ay[i] * bz[i] - az[i] * by[i]),
        map(|i| aw[i] * by[i] - ax[i] * bz[i] + ay[i] * bw[i] + az[i] * bx[i]),
        map(|i| aw[i] * bz[i] + ax[i] * by[i] - ay[i] * bx[i] + az[i] * bw[i]),
        map(|i| aw[i] * bw[i] - ax[i] * bx[i] - ay[i] * by[i] - az[i] * bz[i]),
    ]
}

/// The same polynomial as `bend::angle_from_sin_cos`, written branch-free over lanes.
#[inline(always)]
fn angle(sine: &Lanes, cosine: &Lanes) -> Lanes {
    map(|i| super::bend::angle_from_sin_cos(sine[i], cosine[i]))
}

/// One rest segment of every strand of a batch, split into unit direction and length so the
/// kernel needs no square root or division for it.
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct RestSegment {
    pub direction: VecLanes,
    pub length: Lanes,
}

impl RestSegment {
    /// Sets the segment of strand `lane`.
    pub fn set(&mut self, lane: usize, segment: Vec3) {
        let direction = segment.normalize_or_zero();
        for c in 0..3 {
            self.direction[c][lane] = direction[c];
        }
        self.length[lane] = if direction == Vec3::ZERO { 0.0 } else { segment.length() };
    }
}

/// Per-strand inputs of one batch.
#[derive(Clone, Copy, Debug)]
pub(crate) struct StrandInputs {
    pub root: Vec3,
    pub frame: Quat,
    pub force: Vec3,
    pub stability: f32,
}

impl Default for StrandInputs {
    fn default() -> Self {
        Self { root: Vec3::ZERO, frame: Quat::IDENTITY, force: Vec3::ZERO, stability: 1.0 }
    }
}

/// Bends a batch of strands: `segments` holds the `L` rest segments, `nodes` receives the
/// `L + 1` nodes.
///
/// The running quaternion is the scalar path's; the turned segment itself is computed in the
/// plane of segment and force (`d cos(theta) + e sin(theta)`, `e` the unit normal to `d` toward
/// the force), which is cheaper than a second quaternion rotation and equal up to rounding.
pub(crate) fn bend_batch(inputs: &[StrandInputs; LANES], segments: &[RestSegment], nodes: &mut [VecLanes]) {
    debug_assert_eq!(nodes.len(), segments.len() + 1);
    let layers = segments.len() as u32;
    let l = layers as f32;
    let split: [(Vec3, f32); LANES] = std::array::from_fn(|i| split_force(inputs[i].force));
    let force: VecLanes = std::array::from_fn(|c| map(|i| split[i].0[c]));
    let magnitude = map(|i| split[i].1);
    let stability = map(|i| inputs[i].stability);
    let mut turned: [Lanes; 4] = std::array::from_fn(|c| map(|i| inputs[i].frame.to_array()[c]));
    let mut node: VecLanes = std::array::from_fn(|c| map(|i| inputs[i].root[c]));
    nodes[0] = node;
    for (k, (segment, out)) in segments.iter().zip(&mut nodes[1..]).enumerate() {
        let direction = rotate(&turned, &segment.direction);
        let length = segment.length;
        // bend_weight, in its operation order.
        let share = (layers - k as u32) as f32 * BEND_GAIN / (l * l);
        let weight = map(|i| {
            let w = magnitude[i] * share / stability[i];
            if w.is_nan() { 0.0 } else { w.clamp(0.0, 1.0) }
        });
        let axis = cross(&direction, &force);
        let sine_squared = dot(&axis, &axis);
        let sine = map(|i| sine_squared[i].sqrt());
        let cosine = dot(&direction, &force);
        let active: [bool; LANES] =
            std::array::from_fn(|i| sine[i] > PARALLEL_SINE && weight[i] > 0.0 && length[i] > 0.0);
        let turn = angle(&sine, &cosine);
        let half = map(|i| 0.5 * turn[i] * weight[i]);
        let half_sin = map(|i| super::bend::sin_cos_quarter_turn(half[i]).0);
        let half_cos = map(|i| super::bend::sin_cos_quarter_turn(half[i]).1);
        let scale = map(|i| if active[i] { half_sin[i] / sine[i] } else { 0.0 });
        let rotation = [
            map(|i| axis[0][i] * scale[i]),
            map(|i| axis[1][i] * scale[i]),
            map(|i| axis[2][i] * scale[i]),
            map(|i| if active[i] { half_cos[i] } else { 1.0 }),
        ];
        let product = mul(&rotation, &turned);
        let norm = map(|i| {
            let [x, y, z, w] = [product[0][i], product[1][i], product[2][i], product[3][i]];
            1.0 / (x * x + y * y + z * z + w * w).sqrt()
        });
        turned = std::array::from_fn(|c| map(|i| if active[i] { product[c][i] * norm[i] } else { turned[c][i] }));
        // Full-angle sine and cosine from the half angle; `sin / sine` scales `f - d cos(a)`
        // (length `sine`) to the unit normal `e`.
        let cos_full = map(|i| if active[i] { 1.0 - 2.0 * half_sin[i] * half_sin[i] } else { 1.0 });
        let toward = map(|i| 2.0 * half_cos[i] * scale[i]);
        node = std::array::from_fn(|c| {
            map(|i| {
                let d = direction[c][i];
                let turned_d = d * cos_full[i] + (force[c][i] - d * cosine[i]) * toward[i];
                node[c][i] + turned_d * length[i]
            })
        });
        *out = node;
    }
}
