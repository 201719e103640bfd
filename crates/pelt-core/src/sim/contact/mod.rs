//! Contact: the fur against its own skin ([`skin`] planes, and [`surface`] triangles where the
//! planes fall short), colliders a host or a script places ([`Collider`]) and a grasping hand
//! ([`Grasp`]).
//!
//! Contact runs after the bend, on its result, per strand, root first: segment `k` keeps the
//! direction the bend gave it (turned toward the grip for held strands), is turned by the least
//! angle that puts its end outside every collider, above every skin plane and in front of the
//! strand's skin triangles (the plane tangent to the collider or skin at the end's closest
//! point, or where that cannot be reached, at the segment's start's; where the segment points
//! into that plane nearly along its normal, it leans the way the strand ran, see `turn_above`),
//! and the strand beyond moves with it. Each segment keeps its rest length exactly (a unit
//! direction times the length), roots never move, and the skin is enforced last, so no
//! force or collider pushes a node below it. A strand that touches nothing is left as the bend
//! made it, bit for bit.
//!
//! - Friction: a node inside a moving collider is first carried up to `friction` times the
//!   collider's motion over the step along its surface (all of it from a quarter segment in,
//!   less nearer the surface, so the response has no jump there).
//! - At rest: the result is a function of the step's inputs, so still inputs give the same
//!   nodes every step: no jitter.
//! - No tunnelling: a collider's path within the step is sampled at most one thickness (a
//!   sphere's or capsule's radius, a box's or a mesh's box's smallest half extent) apart, up to
//!   [`SWEEP_RADII_PER_STEP`] thicknesses per step, and the fur is pushed out of every sample:
//!   nothing the collider passed over in the step is left inside its path.
//! - Continuity: the response has no jump the kernels' last-bit differences could flip (see
//!   `turn_above` and the grip's segment), except where an end lies on the medial axis of a
//!   concave spot of the skin.
//! - Cost: a batch's eight strands are screened at once first (`screen`) against their skin
//!   planes and the colliders; those it clears are then tested against their skin triangles,
//!   if they keep any, and only strands that may touch something, or are held, are solved.
//!   Within a strand, a node a clearance away from everything leaves the nodes within that
//!   distance untested (a node moves at most a segment's length from the one before), and a
//!   touching strand's walk starts testing at the first segment whose end may touch. Contact
//!   runs in the bend's parallel tasks, on each batch while it is in cache.
//! - No fling: a collider grows in over [`Collider::appear_secs`] after it appears (or jumps
//!   faster than the sweep), so fur it appears in is pushed out over a few steps.
//!
//! [`ContactStep`] (what every strand shares) and [`ContactStrands`] (per strand) are the inputs
//! every kernel reads, as [`StepInputs`](super::StepInputs) and [`StrandInputs`](super::StrandInputs).

mod bvh;
mod collider;
mod grasp;
pub(crate) mod screen;
mod setup;
pub mod skin;
pub mod surface;

use glam::{Quat, Vec3, Vec4};

pub use collider::{Collider, ColliderKey, ColliderMesh, SWEEP_RADII_PER_STEP, Shape, StepCollider};
pub use grasp::{Grasp, GraspParams, HAND_PARTS};
pub use setup::{SkinSetup, skin_setup};
pub use skin::{SKIN_PLANES, skin_cone, skin_planes};
pub use surface::{SURFACE_WORDS, SkinSurface, skin_surface};

pub(crate) use screen::{BatchPlanes, skin_lanes};

use super::dispatch::{self, CpuKernel};
use super::kernel::{LANES, RestBatches, VecLanes};

/// Most collider samples one step holds (after the sweep); more are dropped, last first.
pub const MAX_STEP_COLLIDERS: usize = 128;

/// Contact parameters; the `[simulation.contact]` table of a preset.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ContactParams {
    /// Keep every node above the skin the fur grows from. Default false.
    pub skin: bool,
}

/// What every strand shares in one step's contact, from
/// [`Simulation::contact_step`](super::Simulation::contact_step).
#[derive(Clone, Debug, Default, PartialEq)]
#[non_exhaustive]
pub struct ContactStep {
    /// Whether the skin planes apply.
    pub skin: bool,
    /// The colliders as the step reads them (the grasp's hand included), at most
    /// [`MAX_STEP_COLLIDERS`].
    pub colliders: Vec<StepCollider>,
    /// Where the grip is.
    pub grip: Vec3,
    /// How far held strands turn toward the grip (see [`Grasp::presence`]); 0 without a grasp.
    pub grip_presence: f32,
}

impl ContactStep {
    /// Whether anything would touch the fur.
    #[must_use]
    pub fn is_active(&self) -> bool {
        self.skin || !self.colliders.is_empty() || self.grip_presence != 0.0
    }
}

/// Per-strand contact inputs, from [`Simulation::contact_strands`](super::Simulation::contact_strands).
#[derive(Clone, Copy, Debug)]
#[non_exhaustive]
pub struct ContactStrands<'a> {
    /// Each strand's skin planes `(n, h)`, in its rest frame: the node `x` keeps
    /// `(frame * n) . (x - root) >= -h`.
    pub skin: &'a [[Vec4; SKIN_PLANES]],
    /// How far each strand is held by the grasp (empty without one).
    pub grasp_weights: &'a [f32],
    /// The skin triangles strands test where their planes do not suffice, in the rest mesh's space.
    pub surface: &'a SkinSurface,
    /// Each strand's root in the rest mesh (where its node is taken to test `surface`).
    pub rest_roots: &'a [Vec3],
}

/// The colliders of a step near a batch: a bit per collider (a step holds at most
/// [`MAX_STEP_COLLIDERS`]), so finding them allocates nothing.
#[derive(Clone, Copy)]
pub(crate) struct Near<'a> {
    colliders: &'a [StepCollider],
    bits: u128,
}

const _: () = assert!(MAX_STEP_COLLIDERS <= u128::BITS as usize);

impl<'a> Near<'a> {
    fn within(colliders: &'a [StepCollider], near: impl Fn(&StepCollider) -> bool) -> Self {
        let bits = colliders
            .iter()
            .take(MAX_STEP_COLLIDERS)
            .enumerate()
            .fold(0_u128, |bits, (i, c)| if near(c) { bits | (1 << i) } else { bits });
        Self { colliders, bits }
    }

    /// The near colliders, in the step's order.
    pub(crate) fn iter(self) -> impl Iterator<Item = &'a StepCollider> {
        self.colliders.iter().enumerate().filter(move |(i, _)| self.bits & (1 << i) != 0).map(|(_, c)| c)
    }
}

/// Everything the CPU pass reads.
pub(crate) struct Resolve<'a> {
    pub step: &'a ContactStep,
    pub strands: ContactStrands<'a>,
    /// The skin planes batch by batch (see [`skin_lanes`]).
    pub skin_lanes: &'a [BatchPlanes],
    /// Which instructions the screen runs with.
    pub kernel: CpuKernel,
    /// Whether to screen (else every strand within reach of anything is solved).
    pub screen: bool,
    pub roots: &'a [Vec3],
    pub frames: &'a [Quat],
    pub rest: &'a RestBatches,
    pub layers: usize,
    pub vertex_count: usize,
}

/// A little beyond a surface, relative to the segment's length, so rounding leaves nodes outside.
const MARGIN: f32 = 1e-5;

/// A little more than a segment's length is taken off a clearance per segment, for rounding.
const SKIP_SLACK: f32 = 1.001;

/// How deep, relative to the segment's length, a node's end takes a collider's full friction.
const FRICTION_DEPTH: f32 = 0.25;

/// How much a turn's hint (the way the segment before went) weighs against the side `u`
/// leans to, per unit of how far `u` lies below the cone it is turned onto (see `turn_above`).
const SIDE_BIAS: f32 = 1.0;

impl Resolve<'_> {
    /// Applies contact to batch `b`'s nodes (`L + 1` of them, as the bend left them).
    pub fn batch(&self, b: usize, batch: &mut [VecLanes]) {
        let lanes = LANES.min(self.vertex_count - b * LANES);
        // A collider can reach a strand when its bound comes within the strand's length of the
        // root (every node, moved or not, lies within that); the GPU kernel tests the same.
        let reach = self.rest.reach(b);
        let roots = &self.roots[b * LANES..b * LANES + lanes];
        let (lo, hi) =
            roots.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(l, h), r| (l.min(*r), h.max(*r)));
        let batch_reach = reach[..lanes].iter().copied().fold(0.0, f32::max);
        let near = Near::within(&self.step.colliders, |c| {
            let gap = (lo - c.centre).max(c.centre - hi).max(Vec3::ZERO);
            gap.length() <= c.bound + batch_reach
        });
        let held: [f32; LANES] = std::array::from_fn(|lane| {
            let weight = self.strands.grasp_weights.get(b * LANES + lane).copied().unwrap_or(0.0);
            if lane < lanes { weight * self.step.grip_presence } else { 0.0 }
        });
        let screened =
            screen::Batch { b, lanes, nodes: batch, lengths: self.rest.lengths_of(b), reach: &reach, held: &held };
        let skin = self.step.skin.then(|| &self.skin_lanes[b]);
        let mut solve = if self.screen {
            dispatch::screen(self.kernel, &screened, skin, self.roots, self.frames, near)
        } else {
            (1 << lanes) - 1
        };
        if self.step.skin && self.screen {
            // The screen cleared these of the planes and colliders: their triangles remain.
            let cleared = !solve;
            for lane in (0..lanes).filter(|lane| cleared & (1 << lane) != 0) {
                if self.touches_triangles(b * LANES + lane, b, lane, batch) {
                    solve |= 1 << lane;
                }
            }
        }
        if solve == 0 {
            return;
        }
        let mut strand = Vec::with_capacity(batch.len());
        let mut reaching = Vec::new();
        for lane in (0..lanes).filter(|lane| solve & (1 << lane) != 0) {
            let j = b * LANES + lane;
            let held = held[lane];
            reaching.clear();
            // Strands the grasp holds pass through its hand.
            reaching.extend(near.iter().filter(|c| {
                !(c.grasp_hand && held != 0.0) && self.roots[j].distance(c.centre) <= c.bound + reach[lane]
            }));
            if !self.step.skin && reaching.is_empty() && held == 0.0 {
                continue;
            }
            strand.clear();
            strand.extend(batch.iter().map(|n| Vec3::new(n[0][lane], n[1][lane], n[2][lane])));
            if self.solve_strand(j, b, lane, held, &reaching, &mut strand) {
                for (node, p) in batch.iter_mut().zip(&strand) {
                    node[0][lane] = p.x;
                    node[1][lane] = p.y;
                    node[2][lane] = p.z;
                }
            }
        }
    }

    /// Strand `j`'s skin triangles, posed.
    fn surface(&self, j: usize) -> Surface<'_> {
        Surface {
            j,
            root: self.roots[j],
            frame: self.frames[j],
            rest_root: self.strands.rest_roots.get(j).copied().unwrap_or(self.roots[j]),
            on: self.step.skin && !self.strands.surface.strand(j).is_empty(),
            triangles: self.strands.surface,
        }
    }

    /// Whether a node of strand `j` (lane `lane` of batch `b`, clear of its planes and the
    /// colliders) may lie behind its skin triangles.
    fn touches_triangles(&self, j: usize, b: usize, lane: usize, batch: &[VecLanes]) -> bool {
        let surface = self.surface(j);
        if !surface.on {
            return false;
        }
        // Nothing else is within reach (the screen showed it), so only the triangles bound.
        let node = |i: usize| Vec3::new(batch[i][0][lane], batch[i][1][lane], batch[i][2][lane]);
        self.first_touch(b, lane, node, |x| surface.clearance(x, f32::MAX)).is_some()
    }

    /// The first segment (`k`, ending at node `k + 1`) of lane `lane` of batch `b` whose end's
    /// `clearance` is negative, `None` where none is. A node is at most a segment's length
    /// nearer anything than the node before, so after one `clearance` away the nodes within it
    /// need no evaluation.
    fn first_touch(
        &self,
        b: usize,
        lane: usize,
        node: impl Fn(usize) -> Vec3,
        clearance: impl Fn(Vec3) -> f32,
    ) -> Option<usize> {
        let mut budget = 0.0_f32;
        for k in 0..self.layers {
            budget -= self.rest.length(b, lane, k) * SKIP_SLACK;
            if budget > 0.0 {
                continue;
            }
            budget = clearance(node(k + 1));
            if budget < 0.0 {
                return Some(k);
            }
        }
        None
    }

    /// Solves one strand in place; false when nothing touched it (left as it was).
    fn solve_strand(
        &self,
        j: usize,
        b: usize,
        lane: usize,
        held: f32,
        near: &[&StepCollider],
        nodes: &mut [Vec3],
    ) -> bool {
        let root = self.roots[j];
        let frame = self.frames[j];
        let mut planes = [(Vec3::ZERO, 0.0_f32); SKIN_PLANES];
        let mut plane_count = 0;
        if self.step.skin {
            for plane in &self.strands.skin[j] {
                let n = plane.truncate();
                if n != Vec3::ZERO {
                    planes[plane_count] = (frame * n, plane.w);
                    plane_count += 1;
                }
            }
        }
        let planes = &planes[..plane_count];
        let surface = self.surface(j);
        let colliders = near.iter();
        // The first segment whose end may touch: the ends before it are clear, so the walk
        // below leaves them as the bend made them.
        let first_touch = if held == 0.0 {
            let clearance = |x: Vec3| surface.clearance(x, cheap_clearance(x, root, planes, colliders.clone()));
            match self.first_touch(b, lane, |i| nodes[i], clearance) {
                Some(k) => k,
                None => return false,
            }
        } else {
            0
        };
        let mut budget = 0.0_f32;
        let grip = self.step.grip - root;
        let grip_distance = grip.length();
        let grip_direction = grip.try_normalize();
        let mut arc = 0.0;
        let mut previous_bent = nodes[0];
        // Which way a segment turns where every way is as near (see `turn_above`): the way the
        // segment before went, and the strand's own X axis where that points into the surface.
        let across = frame * Vec3::X;
        let mut hint = across;
        for k in 0..self.layers {
            let length = self.rest.length(b, lane, k);
            let bent = nodes[k + 1];
            let p = nodes[k];
            if length <= 0.0 {
                nodes[k + 1] = p;
                previous_bent = bent;
                continue;
            }
            let mut u = (bent - previous_bent).try_normalize().unwrap_or(Vec3::Y);
            previous_bent = bent;
            if held != 0.0
                && let Some(toward) = grip_direction
            {
                // Up to the grip the strand runs to it; the rest sticks out of the hand. The
                // segment the grip falls in turns in part, so no rounding of `arc` flips it.
                let before_grip = ((grip_distance - arc) / length).clamp(0.0, 1.0);
                if before_grip > 0.0 {
                    u = (u + (toward - u) * (held * before_grip)).try_normalize().unwrap_or(u);
                }
            }
            arc += length;
            // Where the start is clear by more than the segment, no end can touch anything.
            let step = length * SKIP_SLACK;
            if k < first_touch {
                // The bend's node stands: a segment clear of everything is not rewritten.
                hint = u + across * 0.5;
                continue;
            }
            if budget <= step {
                let cheap = cheap_clearance(p, root, planes, colliders.clone());
                budget = match k {
                    // The root lies on its skin: no nearer than 0 to its triangles.
                    0 if surface.on => cheap.min(0.0),
                    _ => surface.clearance(p, cheap),
                };
            }
            budget -= step;
            let u = if budget > 0.0 {
                u
            } else {
                self.constrain(p, u, length, root, planes, &surface, hint, colliders.clone())
            };
            hint = u + across * 0.5;
            nodes[k + 1] = p + u * length;
        }
        true
    }

    /// The direction nearest `u` whose segment from `p` ends outside every collider, above
    /// every skin plane and in front of the skin's triangles (skin last).
    #[allow(clippy::too_many_arguments)]
    fn constrain<'c>(
        &self,
        p: Vec3,
        mut u: Vec3,
        length: f32,
        root: Vec3,
        planes: &[(Vec3, f32)],
        surface: &Surface<'_>,
        hint: Vec3,
        colliders: impl Iterator<Item = &'c &'c StepCollider> + Clone,
    ) -> Vec3 {
        for pass in 0..8 {
            let mut moved = false;
            for c in colliders.clone() {
                let q = p + u * length;
                let (s, n, distance) = c.closest(q);
                if distance >= 0.0 {
                    continue;
                }
                if pass == 0 && c.friction > 0.0 {
                    // Full friction from FRICTION_DEPTH in, none at the surface: no jump where
                    // a node's end crosses it.
                    let slide = c.travel - n * n.dot(c.travel);
                    let depth = (-distance / (FRICTION_DEPTH * length)).min(1.0);
                    u = (u * length + slide * (c.friction * depth)).try_normalize().unwrap_or(u);
                }
                let mut floor = n.dot(s - p) / length;
                let mut normal = n;
                if floor > 1.0 - MARGIN {
                    // The tangent plane at the end's closest point is out of reach: take the one
                    // at the segment's start, which it is above when the start is outside.
                    let (s, n, _) = c.closest(p);
                    floor = n.dot(s - p) / length;
                    normal = n;
                }
                u = turn_above(u, normal, floor + MARGIN, hint);
                moved = true;
            }
            for &(n, h) in planes {
                let floor = (-h - n.dot(p - root)) / length;
                if n.dot(u) < floor {
                    u = turn_above(u, n, floor + MARGIN, hint);
                    moved = true;
                }
            }
            if let Some((s, n, distance)) = surface.closest(p + u * length)
                && distance < 0.0
            {
                let mut floor = n.dot(s - p) / length;
                let mut normal = n;
                if floor > 1.0 - MARGIN
                    && let Some((s, n, _)) = surface.closest(p)
                {
                    floor = n.dot(s - p) / length;
                    normal = n;
                }
                u = turn_above(u, normal, floor + MARGIN, hint);
                moved = true;
            }
            if !moved {
                break;
            }
        }
        u
    }
}

/// How far `x` is from touching a skin plane or a collider: the least of its heights above the
/// planes and its distances outside the colliders (negative: touching). Each moves by at most
/// as much as `x` does; the skin's triangles add theirs through [`Surface::clearance`].
fn cheap_clearance<'c>(
    x: Vec3,
    root: Vec3,
    planes: &[(Vec3, f32)],
    colliders: impl Iterator<Item = &'c &'c StepCollider>,
) -> f32 {
    let mut least = f32::MAX;
    for &(n, h) in planes {
        least = least.min(n.dot(x - root) + h);
    }
    for c in colliders {
        least = least.min(c.closest(x).2);
    }
    least
}

/// One strand's skin triangles, posed with its root and frame.
struct Surface<'a> {
    j: usize,
    root: Vec3,
    frame: Quat,
    rest_root: Vec3,
    on: bool,
    triangles: &'a SkinSurface,
}

impl Surface<'_> {
    /// The closest point, pseudonormal and signed distance of the strand's triangles to world
    /// point `x`; `None` where the strand has none or the skin is off.
    fn closest(&self, x: Vec3) -> Option<(Vec3, Vec3, f32)> {
        if !self.on {
            return None;
        }
        self.triangles.closest_posed(self.j, x, self.root, self.frame, self.rest_root)
    }

    /// The least of `cheap` (a node's clearance from everything else) and its distance in front
    /// of the triangles.
    fn clearance(&self, x: Vec3, cheap: f32) -> f32 {
        match self.closest(x) {
            Some((_, _, d)) => cheap.min(d),
            None => cheap,
        }
    }
}

/// A unit direction near unit `u` with `n . result >= floor` (`n` unit): `u` itself when it
/// already is, else on the cone `n . result = floor`, to the side of `u` plus a part of `hint`.
///
/// The least turn (to the side of `u` alone) is ill-conditioned where `u` points into the plane
/// nearly along `-n`: every side is nearly as near, and the side follows `u`'s small tangential
/// part, which swings from one segment to the next (a strand pressed into a crease folded back
/// and forth) and with each kernel's rounding. So `hint` joins `u`'s side weighed by how far `u`
/// lies below the cone ([`SIDE_BIAS`] times `floor - n . u`): a strand pressed in steeply lies
/// down the way it ran, one that grazes the cone turns by nearly the least angle, and the
/// result is continuous where `u` crosses the cone (the weight is 0 there).
fn turn_above(u: Vec3, n: Vec3, floor: f32, hint: Vec3) -> Vec3 {
    let floor = floor.clamp(-1.0, 1.0);
    let along = n.dot(u);
    if along >= floor {
        return u;
    }
    let side = ((u - n * along) + (hint - n * n.dot(hint)) * (SIDE_BIAS * (floor - along)))
        .try_normalize()
        .unwrap_or_else(|| n.any_orthonormal_vector());
    (n * floor + side * (1.0 - floor * floor).max(0.0).sqrt()).normalize()
}
