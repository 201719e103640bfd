//! The batched bend that [`Simulation`](super::Simulation) runs: [`LANES`] strands at once,
//! structure of arrays, in two forms.
//!
//! - **Straight strands** (every rest segment of a strand points the same way; the structure
//!   grows only these): all segments stay in the plane of the strand direction `d` and the force
//!   direction `f`, so the strand is described by one angle. With `a_0 = angle(d, f)` and the
//!   weights `w_k` below, segment `k` ends at angle `a_(k+1) = a_k * (1 - w_k)` from `f`, turned
//!   by `phi_k = a_0 - a_(k+1)` from `d`: direction `d cos(phi_k) + e sin(phi_k)`, `e` the unit
//!   normal to `d` toward `f`. Exact, one multiply and a sine/cosine polynomial per node.
//! - **General strands** (curved): the running quaternion of [`super::bend_strand`], each node
//!   turned toward the force by its weight of the angle between them.
//!
//! Both use the same weight, Equation 1 as Pelt defines it (see [`super::bend`]): the strand's
//! `scale = |F| * gain / stability` (`gain = BEND_GAIN / L^2` for [`Equation::Pelt`], `1` for
//! [`Equation::Paper`]), and at node `k`, with `RN = L - k`, `w_k = min(1, scale * RN)`. A
//! force below [`PARALLEL_SINE`] of a segment's direction, a zero or non-finite force, and a
//! zero-length segment turn nothing.
//!
//! Every function is `#[inline(always)]` over [`F`] lanes so that [`super::dispatch`] compiles it
//! twice, once with AVX2 + FMA enabled and once portable, from this one source.
//!
//! [`Equation::Pelt`]: super::Equation::Pelt
//! [`Equation::Paper`]: super::Equation::Paper

use std::f32::consts::{FRAC_PI_2, PI};

use glam::{Quat, Vec3};

use super::SimError;
use super::bend::PARALLEL_SINE;
use super::lanes::{F, M, V3};
use crate::fur::FurStructure;

/// Strands per batch (one AVX2 register of `f32`).
pub(crate) const LANES: usize = 8;

/// One `f32` per strand of a batch.
pub(crate) type Lanes = [f32; LANES];

/// A vector per strand of a batch: `[x, y, z]` lanes.
pub(crate) type VecLanes = [Lanes; 3];

/// One lane's (strand's) inputs of one step, as the bend reads them.
#[derive(Clone, Copy, Debug)]
pub(crate) struct LaneInputs {
    pub root: Vec3,
    /// Rotation of the rest frame into the current base frame.
    pub frame: Quat,
    /// Total force (gravity plus field); non-finite counts as none.
    pub force: Vec3,
    pub stability: f32,
}

impl Default for LaneInputs {
    fn default() -> Self {
        Self { root: Vec3::ZERO, frame: Quat::IDENTITY, force: Vec3::ZERO, stability: 1.0 }
    }
}

/// The rest shape of one batch, borrowed from the simulation's arrays.
#[derive(Clone, Copy, Debug)]
pub(crate) struct BatchRest<'a> {
    /// Segment lengths, `L` entries.
    pub lengths: &'a [Lanes],
    /// Unit segment directions in the rest frame, `L` entries (general batches).
    pub directions: &'a [VecLanes],
    /// The unit strand direction in the rest frame (straight batches).
    pub straight: &'a VecLanes,
}

/// The forces of `W` strands in lanes: unit direction, and `scale` (`|F| * gain / stability`,
/// 0 where the force is zero or not finite). The split avoids overflow: a finite force whose
/// length overflows `f32` still gets its direction.
#[inline(always)]
fn forces<const W: usize>(force: V3<W>, stability: F<W>, gain: f32) -> (V3<W>, F<W>) {
    let largest = force.x.abs().max(force.y.abs()).max(force.z.abs());
    let usable = largest.gt(F::splat(0.0)).and(largest.lt(F::splat(f32::INFINITY)));
    let divisor = usable.select(largest, F::splat(1.0));
    let scaled = V3 { x: force.x / divisor, y: force.y / divisor, z: force.z / divisor };
    let length = scaled.dot(scaled).sqrt();
    let length_divisor = usable.select(length, F::splat(1.0));
    let zero = V3::splat(0.0, 0.0, 0.0);
    let direction = V3::select(
        usable,
        V3 { x: scaled.x / length_divisor, y: scaled.y / length_divisor, z: scaled.z / length_divisor },
        zero,
    );
    let scale = usable.select((length * largest) * F::splat(gain) / stability, F::splat(0.0));
    (direction, scale)
}

/// `q * v` (unit `q`): `t = 2 (u x v)`, `v + w t + u x t`.
#[inline(always)]
fn rotate<const W: usize>(q: &[F<W>; 4], v: V3<W>) -> V3<W> {
    let u = V3 { x: q[0], y: q[1], z: q[2] };
    let t = u.cross(v).scale(F::splat(2.0));
    let ut = u.cross(t);
    t.mul_add(q[3], V3 { x: v.x + ut.x, y: v.y + ut.y, z: v.z + ut.z })
}

/// Quaternion product `a * b`.
#[inline(always)]
fn multiply<const W: usize>(a: &[F<W>; 4], b: &[F<W>; 4]) -> [F<W>; 4] {
    let [ax, ay, az, aw] = *a;
    let [bx, by, bz, bw] = *b;
    [
        aw.mul_add(bx, ax.mul_add(bw, ay.mul_add(bz, -(az * by)))),
        aw.mul_add(by, ay.mul_add(bw, az.mul_add(bx, -(ax * bz)))),
        aw.mul_add(bz, az.mul_add(bw, ax.mul_add(by, -(ay * bx)))),
        aw.mul_add(bw, -(ax.mul_add(bx, ay.mul_add(by, az * bz)))),
    ]
}

/// The angle in `[0, pi]` with this sine (`>= 0`) and cosine, `atan2(sine, cosine)`: the
/// paper's `acos(dot)` with its clamp built in and accurate near 0 and pi. The odd polynomial of
/// Abramowitz and Stegun 4.4.49 on the reduced argument (error below 1e-7 rad).
#[inline(always)]
fn angle<const W: usize>(sine: F<W>, cosine: F<W>) -> F<W> {
    let (a, b) = (sine, cosine.abs());
    let steep = a.gt(b);
    let numerator = steep.select(b, a);
    let denominator = steep.select(a, b);
    // Both are zero together; 0 / 1 = 0 then.
    let t = numerator / denominator.gt(F::splat(0.0)).select(denominator, F::splat(1.0));
    let t2 = t * t;
    let mut p = F::splat(0.002_866_225_7);
    for c in [-0.016_165_737, 0.042_909_614, -0.075_289_64, 0.106_562_64, -0.142_089, 0.199_935_51, -0.333_331_45] {
        p = p.mul_add(t2, F::splat(c));
    }
    let angle = (t * t2).mul_add(p, t);
    let angle = steep.select(F::splat(FRAC_PI_2) - angle, angle);
    cosine.lt(F::splat(0.0)).select(F::splat(PI) - angle, angle)
}

/// `(sin x, cos x)` for `x` in `[0, pi/2]`: Taylor polynomials to `x^11` and `x^12` (error
/// below 1e-7), coefficients as reciprocal constants.
#[inline(always)]
fn sin_cos<const W: usize>(x: F<W>) -> (F<W>, F<W>) {
    let x2 = x * x;
    let mut s = F::splat(-1.0 / 39_916_800.0);
    for c in [1.0 / 362_880.0, -1.0 / 5040.0, 1.0 / 120.0, -1.0 / 6.0, 1.0] {
        s = s.mul_add(x2, F::splat(c));
    }
    let mut c = F::splat(1.0 / 479_001_600.0);
    for k in [-1.0 / 3_628_800.0, 1.0 / 40_320.0, -1.0 / 720.0, 1.0 / 24.0, -0.5, 1.0] {
        c = c.mul_add(x2, F::splat(k));
    }
    (x * s, c)
}

/// The per-strand inputs of `N` batches as `W = N * LANES` lanes.
#[derive(Clone, Copy, Debug)]
struct Loaded<const W: usize> {
    root: V3<W>,
    frame: [F<W>; 4],
    force: V3<W>,
    stability: F<W>,
}

#[inline(always)]
fn load<const N: usize, const W: usize>(inputs: [&[LaneInputs; LANES]; N]) -> Loaded<W> {
    macro_rules! lane {
        ($($field:tt).+) => {
            F(std::array::from_fn(|i| inputs[i / LANES][i % LANES].$($field).+))
        };
    }
    Loaded {
        root: V3 { x: lane!(root.x), y: lane!(root.y), z: lane!(root.z) },
        frame: [lane!(frame.x), lane!(frame.y), lane!(frame.z), lane!(frame.w)],
        force: V3 { x: lane!(force.x), y: lane!(force.y), z: lane!(force.z) },
        stability: lane!(stability),
    }
}

#[inline(always)]
fn gather<const N: usize, const W: usize>(parts: [&Lanes; N]) -> F<W> {
    F(std::array::from_fn(|i| parts[i / LANES][i % LANES]))
}

#[inline(always)]
fn gather3<const N: usize, const W: usize>(parts: [&VecLanes; N]) -> V3<W> {
    V3 { x: gather(parts.map(|p| &p[0])), y: gather(parts.map(|p| &p[1])), z: gather(parts.map(|p| &p[2])) }
}

#[inline(always)]
#[allow(clippy::needless_range_loop)] // reason: lanes of two arrays by one index
fn store<const N: usize, const W: usize>(value: V3<W>, parts: &mut [&mut [VecLanes]; N], index: usize) {
    for (n, part) in parts.iter_mut().enumerate() {
        let out = &mut part[index];
        for i in 0..LANES {
            out[0][i] = value.x.0[n * LANES + i];
            out[1][i] = value.y.0[n * LANES + i];
            out[2][i] = value.z.0[n * LANES + i];
        }
    }
}

/// Bends one batch of straight strands (see the module docs); `nodes` receives `L + 1` nodes.
#[inline(always)]
pub(crate) fn bend_straight(inputs: &[LaneInputs; LANES], gain: f32, rest: BatchRest<'_>, nodes: &mut [VecLanes]) {
    const W: usize = LANES;
    let layers = rest.lengths.len();
    debug_assert_eq!(nodes.len(), layers + 1);
    let input: Loaded<W> = load([inputs]);
    let (force, scale) = forces(input.force, input.stability, gain);
    let d = rotate(&input.frame, gather3([rest.straight]));
    let axis = d.cross(force);
    let sine = axis.dot(axis).sqrt();
    let cosine = d.dot(force);
    let start = angle(sine, cosine);
    // e: the unit normal to d in the plane of d and f, toward f: `f - d cos a`, with what rounding
    // left along d taken out, over its own length. Not over `sine`: near an antiparallel force
    // both are tiny and `f - d cos a` carries ~1e-7 of rounding, so that `e` was off unit length
    // and off perpendicular by ~1e-7 / sin a, and stretched segments (1.5e-5 of the strand at
    // 179.97 degrees in the million-step soak). Unit and perpendicular, `e` keeps every length.
    let toward = d.mul_add(-cosine, force);
    let toward = d.mul_add(-d.dot(toward), toward);
    let norm = toward.dot(toward).sqrt();
    let active = sine.gt(F::splat(PARALLEL_SINE)).and(scale.gt(F::splat(0.0))).and(norm.gt(F::splat(0.0)));
    let scale = active.select(scale, F::splat(0.0));
    let inverse_norm = F::splat(1.0) / active.select(norm, F::splat(1.0));
    let e = V3::select(active, toward.scale(inverse_norm), V3::splat(0.0, 0.0, 0.0));
    let mut remaining = start;
    let mut node = input.root;
    let (first, rest_nodes) = nodes.split_at_mut(1);
    put(node, &mut first[0]);
    for (k, (length, out)) in rest.lengths.iter().zip(rest_nodes).enumerate() {
        let weight = (scale * F::splat((layers - k) as f32)).min(F::splat(1.0));
        remaining = remaining.mul_add(-weight, remaining);
        let (half_sin, half_cos) = sin_cos((start - remaining) * F::splat(0.5));
        let cos_turn = (half_sin * F::splat(-2.0)).mul_add(half_sin, F::splat(1.0));
        let sin_turn = (half_sin * half_cos) * F::splat(2.0);
        let direction = e.mul_add(sin_turn, d.scale(cos_turn));
        node = direction.mul_add(F(*length), node);
        put(node, out);
    }
}

#[inline(always)]
fn put(value: V3<LANES>, out: &mut VecLanes) {
    *out = [value.x.0, value.y.0, value.z.0];
}

/// Bends `N` batches of strands of any shape, interleaved (`W = N * LANES` lanes: independent
/// chains for the out-of-order core to overlap); `nodes[n]` receives batch `n`'s `L + 1` nodes.
#[inline(always)]
pub(crate) fn bend_general<const N: usize, const W: usize>(
    inputs: [&[LaneInputs; LANES]; N],
    gain: f32,
    rest: [BatchRest<'_>; N],
    mut nodes: [&mut [VecLanes]; N],
) {
    const { assert!(W == N * LANES) };
    let layers = rest[0].lengths.len();
    let input: Loaded<W> = load(inputs);
    let (force, scale) = forces(input.force, input.stability, gain);
    let mut turned = input.frame;
    let mut node = input.root;
    store(node, &mut nodes, 0);
    let (one, zero) = (F::splat(1.0), F::splat(0.0));
    for k in 0..layers {
        let length: F<W> = gather(rest.map(|r| &r.lengths[k]));
        let rest_direction = gather3(rest.map(|r| &r.directions[k]));
        let d = rotate(&turned, rest_direction);
        let weight = (scale * F::splat((layers - k) as f32)).min(one);
        let axis = d.cross(force);
        let sine = axis.dot(axis).sqrt();
        let cosine = d.dot(force);
        let active: M<W> = sine.gt(F::splat(PARALLEL_SINE)).and(weight.gt(zero)).and(length.gt(zero));
        let (half_sin, half_cos) = sin_cos(angle(sine, cosine) * weight * F::splat(0.5));
        let half_sin = active.select(half_sin, zero);
        let half_cos = active.select(half_cos, one);
        // The rotation's vector part is the unit axis times sin(half angle).
        let axis_scale = half_sin / active.select(sine, one);
        let rotation = [axis.x * axis_scale, axis.y * axis_scale, axis.z * axis_scale, half_cos];
        let product = multiply(&rotation, &turned);
        let norm = product[0].mul_add(
            product[0],
            product[1].mul_add(product[1], product[2].mul_add(product[2], product[3] * product[3])),
        );
        // Renormalised so rounding never lets segment lengths drift over many layers.
        let inverse = one / norm.sqrt();
        turned = std::array::from_fn(|c| active.select(product[c] * inverse, turned[c]));
        // The turned segment is the rest direction under the new unit rotation, which keeps its
        // length whatever the rounding of the axis (the closed form in the plane of d and f,
        // `d cos + (f - d cos) sin / sine`, loses it by ~1e-7 / sine near an antiparallel force).
        let direction = rotate(&turned, rest_direction);
        node = direction.mul_add(length, node);
        store(node, &mut nodes, k + 1);
    }
}

/// The rest shape of every strand, batch-major: batch `b` holds strands `8b..8b + 8` (padding
/// lanes past `V` have zero lengths and stay at the origin).
#[derive(Clone, Debug)]
pub(crate) struct RestBatches {
    /// Segment lengths at `b * L + k`.
    lengths: Vec<Lanes>,
    /// Unit segment directions (zero for a zero-length segment) at `b * L + k`.
    directions: Vec<VecLanes>,
    /// Each strand's unit direction (tip minus root), per batch.
    straight: Vec<VecLanes>,
    /// Whether every strand of the batch is straight, so the straight form bends it.
    is_straight: Vec<bool>,
}

impl RestBatches {
    /// From a shared vertex array of `v` strands and `layers` segments (`NV[i * V + j]`).
    pub fn new(positions: &[Vec3], v: usize, layers: usize) -> Self {
        let batches = v.div_ceil(LANES);
        let mut rest = Self {
            lengths: vec![[0.0; LANES]; batches * layers],
            directions: vec![[[0.0; LANES]; 3]; batches * layers],
            straight: vec![[[0.0; LANES], [1.0; LANES], [0.0; LANES]]; batches],
            is_straight: vec![true; batches],
        };
        for j in 0..v {
            rest.set_strand(positions, v, layers, j);
        }
        rest
    }

    /// Recomputes the batches holding `strands` from `positions` (a regroomed fur's shared array
    /// of the same `v` and `layers`), as [`RestBatches::new`] makes them.
    pub fn update(&mut self, positions: &[Vec3], v: usize, layers: usize, strands: &[u32]) {
        let mut batches: Vec<usize> = strands.iter().map(|&j| j as usize / LANES).collect();
        batches.sort_unstable();
        batches.dedup();
        for b in batches {
            // A batch's form is decided by all its strands: start it over.
            self.straight[b] = [[0.0; LANES], [1.0; LANES], [0.0; LANES]];
            self.is_straight[b] = true;
            for j in b * LANES..((b + 1) * LANES).min(v) {
                self.set_strand(positions, v, layers, j);
            }
        }
    }

    fn set_strand(&mut self, positions: &[Vec3], v: usize, layers: usize, j: usize) {
        let (b, lane) = (j / LANES, j % LANES);
        let segment = |k: usize| positions[(k + 1) * v + j] - positions[k * v + j];
        for k in 0..layers {
            let direction = segment(k).normalize_or_zero();
            self.lengths[b * layers + k][lane] = if direction == Vec3::ZERO { 0.0 } else { segment(k).length() };
            for c in 0..3 {
                self.directions[b * layers + k][c][lane] = direction[c];
            }
        }
        match straight_direction(positions[j], (0..layers).map(segment)) {
            Some(direction) => {
                for c in 0..3 {
                    self.straight[b][c][lane] = direction[c];
                }
            }
            None => self.is_straight[b] = false,
        }
    }

    /// Segment `k`'s rest length in lane `lane` of batch `b`.
    pub fn length(&self, b: usize, lane: usize, k: usize) -> f32 {
        self.lengths[b * (self.lengths.len() / self.is_straight.len().max(1)) + k][lane]
    }

    /// Batch `b`'s rest segment lengths, root first, a lane per strand.
    pub fn lengths_of(&self, b: usize) -> &[Lanes] {
        let layers = self.lengths.len() / self.is_straight.len().max(1);
        &self.lengths[b * layers..(b + 1) * layers]
    }

    /// Each lane's strand length in batch `b`: its rest segments summed root first.
    pub fn reach(&self, b: usize) -> Lanes {
        let mut reach = [0.0; LANES];
        for lengths in self.lengths_of(b) {
            for (r, l) in reach.iter_mut().zip(lengths) {
                *r += l;
            }
        }
        reach
    }

    /// The share of batches the straight form bends.
    pub fn straight_share(&self) -> f32 {
        if self.is_straight.is_empty() {
            return 1.0;
        }
        self.is_straight.iter().filter(|s| **s).count() as f32 / self.is_straight.len() as f32
    }
}

/// The rest shape of every strand as the CPU kernel bends it ([`kernel_rest`]): for another
/// kernel (the GPU's) that must bend each strand by the same form from the same numbers.
#[derive(Clone, Debug, PartialEq)]
pub struct KernelRest {
    /// Per segment, layer-major (`k * V + j`): its unit rest direction (zero for a zero-length
    /// segment) and its length.
    pub segments: Vec<(Vec3, f32)>,
    /// Per strand: its unit direction where the kernel bends it by the exact straight form,
    /// `None` where by the running quaternion (the 8 strands of a batch share one form).
    pub straight: Vec<Option<Vec3>>,
}

/// The rest shape of `fur`'s strands as [`Simulation`](super::Simulation)'s kernel holds it.
///
/// # Errors
/// [`SimError::Size`] if the shared vertex array is not `(L + 1) * V` long.
pub fn kernel_rest(fur: &FurStructure) -> Result<KernelRest, SimError> {
    let (v, layers) = (fur.vertex_count(), fur.layers as usize);
    if fur.positions.len() != v * (layers + 1) {
        return Err(SimError::Size {
            what: "the shared vertex array",
            expected: v * (layers + 1),
            got: fur.positions.len(),
        });
    }
    let rest = RestBatches::new(&fur.positions, v, layers);
    let lane = |j: usize, k: usize| ((j / LANES) * layers + k, j % LANES);
    let segments = (0..layers)
        .flat_map(|k| (0..v).map(move |j| (k, j)))
        .map(|(k, j)| {
            let (at, i) = lane(j, k);
            let d = &rest.directions[at];
            (Vec3::new(d[0][i], d[1][i], d[2][i]), rest.lengths[at][i])
        })
        .collect();
    let straight = (0..v)
        .map(|j| {
            let (b, i) = (j / LANES, j % LANES);
            let d = &rest.straight[b];
            rest.is_straight[b].then(|| Vec3::new(d[0][i], d[1][i], d[2][i]))
        })
        .collect();
    Ok(KernelRest { segments, straight })
}

/// The unit direction of a strand whose rest segments all point one way, or `None` if one
/// bends away (or has zero length). Straightness is judged against the rounding of the positions
/// the segments were computed from: a segment may deviate from the strand's direction by
/// `1e-6 * (|root| + strand length)`, well below anything a curved strand does, and the
/// straight form's result then differs from the general one by no more than that.
fn straight_direction(root: Vec3, mut segments: impl Iterator<Item = Vec3> + Clone) -> Option<Vec3> {
    let whole: Vec3 = segments.clone().sum();
    let direction = whole.try_normalize()?;
    let strand_length: f32 = segments.clone().map(Vec3::length).sum();
    let tolerance = 1e-6 * (root.length() + strand_length);
    segments
        .all(|segment| {
            let length = segment.length();
            length > 0.0 && (segment - direction * length).length() <= tolerance
        })
        .then_some(direction)
}

/// Everything one step needs to bend every strand; [`Step::bend_pair`] bends two batches.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Step<'a> {
    pub layers: usize,
    pub vertex_count: usize,
    /// `BEND_GAIN / L^2` or 1 (see the module docs).
    pub gain: f32,
    pub gravity: Vec3,
    pub stability: f32,
    pub stability_map: Option<&'a [f32]>,
    pub roots: &'a [Vec3],
    pub frames: &'a [Quat],
    /// The external field (wind, field, touch), one per strand.
    pub external: &'a [Vec3],
    /// The inertial force from the roots' acceleration, one per strand.
    pub inertial: &'a [Vec3],
    /// Every strand's wetness, gravity's factor and stability's loss per unit of it.
    pub wetness: Option<(&'a [f32], f32, f32)>,
    pub rest: &'a RestBatches,
}

impl Step<'_> {
    #[inline(always)]
    fn inputs(&self, batch: usize) -> [LaneInputs; LANES] {
        std::array::from_fn(|lane| {
            let j = batch * LANES + lane;
            if j < self.vertex_count {
                let stability = self.stability_map.map_or(self.stability, |m| m[j]);
                let (gravity, stability) = match self.wetness {
                    // A wet strand is heavier and limper (the same arithmetic as `StrandInputs`).
                    Some((wetness, weight, softening)) => {
                        (self.gravity * (1.0 + weight * wetness[j]), stability * (1.0 - softening * wetness[j]))
                    }
                    None => (self.gravity, stability),
                };
                LaneInputs {
                    root: self.roots[j],
                    frame: self.frames[j],
                    force: gravity + self.external[j] + self.inertial[j],
                    stability,
                }
            } else {
                LaneInputs::default()
            }
        })
    }

    #[inline(always)]
    fn rest(&self, batch: usize) -> BatchRest<'_> {
        let range = batch * self.layers..(batch + 1) * self.layers;
        BatchRest {
            lengths: &self.rest.lengths[range.clone()],
            directions: &self.rest.directions[range],
            straight: &self.rest.straight[batch],
        }
    }

    /// Bends batches `2 * pair` and `2 * pair + 1` (if any) into `nodes` (`L + 1` nodes each):
    /// straight batches by the straight form, two general ones interleaved.
    #[inline(always)]
    pub fn bend_pair(&self, pair: usize, nodes: &mut [VecLanes]) {
        let count = self.layers + 1;
        let first = 2 * pair;
        let batches = nodes.len() / count;
        debug_assert!(batches == 1 || batches == 2);
        let (a, b) = nodes.split_at_mut(count);
        let inputs_a = self.inputs(first);
        if batches == 2 && !self.rest.is_straight[first] && !self.rest.is_straight[first + 1] {
            let inputs_b = self.inputs(first + 1);
            bend_general::<2, { 2 * LANES }>(
                [&inputs_a, &inputs_b],
                self.gain,
                [self.rest(first), self.rest(first + 1)],
                [a, b],
            );
            return;
        }
        self.bend_one(first, &inputs_a, a);
        if batches == 2 {
            self.bend_one(first + 1, &self.inputs(first + 1), b);
        }
    }

    #[inline(always)]
    fn bend_one(&self, batch: usize, inputs: &[LaneInputs; LANES], nodes: &mut [VecLanes]) {
        if self.rest.is_straight[batch] {
            bend_straight(inputs, self.gain, self.rest(batch), nodes);
        } else {
            bend_general::<1, LANES>([inputs], self.gain, [self.rest(batch)], [nodes]);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const LAYERS: usize = 16;
    const SEGMENT: f32 = 0.033;

    /// Eight strands along `directions`, rooted near the origin (so node rounding stays far below
    /// what is measured), under forces `off[i]` radians from antiparallel to them; returns the
    /// worst `| |segment| - rest | / rest` of the straight and of the general form.
    #[allow(clippy::needless_range_loop)] // reason: a lane of two nodes by one index
    fn worst_stretch(off: [f32; LANES], stability: f32, frame: Quat) -> (f64, f64) {
        let directions: [Vec3; LANES] =
            std::array::from_fn(|i| Vec3::new(0.3 + 0.1 * i as f32, 0.8, -0.5 + 0.13 * i as f32).normalize());
        let inputs: [LaneInputs; LANES] = std::array::from_fn(|i| {
            let d = frame * directions[i];
            let side = d.any_orthonormal_vector();
            LaneInputs {
                root: Vec3::new(0.01, -0.02, 0.03) * i as f32,
                frame,
                force: (-d * off[i].cos() + side * off[i].sin()) * 1.7,
                stability,
            }
        });
        let lengths = vec![[SEGMENT; LANES]; LAYERS];
        let unit: VecLanes = std::array::from_fn(|c| std::array::from_fn(|i| directions[i][c]));
        let rest_directions = vec![unit; LAYERS];
        let rest = BatchRest { lengths: &lengths, directions: &rest_directions, straight: &unit };
        let worst = |nodes: &[VecLanes]| {
            let mut worst = 0.0_f64;
            for pair in nodes.windows(2) {
                for i in 0..LANES {
                    let length = (0..3)
                        .map(|c| (f64::from(pair[1][c][i]) - f64::from(pair[0][c][i])).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    worst = worst.max((length - f64::from(SEGMENT)).abs() / f64::from(SEGMENT));
                }
            }
            worst
        };
        let mut straight = vec![[[0.0; LANES]; 3]; LAYERS + 1];
        bend_straight(&inputs, 1.0, rest, &mut straight);
        let mut general = vec![[[0.0; LANES]; 3]; LAYERS + 1];
        bend_general::<1, LANES>([&inputs], 1.0, [rest], [&mut general]);
        (worst(&straight), worst(&general))
    }

    /// Forces from 2e-7 to 3e-3 radians short of antiparallel, bending the strands up to a
    /// right angle and past: segments keep their lengths to 1e-5 of themselves in both forms.
    /// (Before `e` was built from its own length, the straight form stretched them by up to 0.3
    /// here, and the general form, which built segments the same way, too.)
    #[test]
    fn nearly_antiparallel_forces_keep_segment_lengths() {
        let frame = Quat::from_axis_angle(Vec3::new(1.0, 2.0, 3.0).normalize(), 0.9);
        for stability in [20.0, 60.0, 200.0, 1000.0] {
            for decade in 0..4 {
                let off = std::array::from_fn(|i| 2e-7 * 10f32.powf(decade as f32 + i as f32 / 8.0));
                for frame in [Quat::IDENTITY, frame] {
                    let (straight, general) = worst_stretch(off, stability, frame);
                    assert!(straight <= 1e-5, "straight form: {straight:e} at stability {stability}, {off:?}");
                    assert!(general <= 1e-5, "general form: {general:e} at stability {stability}, {off:?}");
                }
            }
        }
    }
}
