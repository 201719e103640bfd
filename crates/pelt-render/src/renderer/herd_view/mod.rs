//! A herd through the camera in a few draws ([`HerdDraws`]). Blending needs the order only
//! where copies overlap, so the copies are put in levels: a copy goes one level above the
//! highest level holding a farther copy whose screen rectangle (from the sphere the host says
//! holds it) overlaps its own, and the copies of one level share no pixel. A level's copies of
//! one pool then draw their skins in one draw and their shells in another (`pool_draws.wgsl`:
//! an instance buffer names each instance's slot and shell), and the picture has the bytes of
//! every copy drawn alone, farthest first. The draws grow with how many copies stand behind one
//! another on screen, not with the herd.
//!
//! Copies whose shells the view angle thins, and the fins, follow lists the listing passes make
//! on the GPU. Where the device takes an indirect draw's first instance, the plan gives each
//! such copy a place, and the listing passes write its draws there too (`ObjectSlot::gather`),
//! so a level's thinned shells take one indirect call and its fins another, the first instance
//! naming the copy. Elsewhere those copies draw alone.

use std::ops::Range;
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};

use glam::{Mat4, Vec3};

use super::FurRenderer;
use crate::fur::GpuFur;
use crate::pool::{LIST_FINS, LIST_SHELLS, MemberPool, NOT_GATHERED};
use crate::view::ViewData;

mod draws;

pub(super) use draws::PoolCameraPipelines;

/// One instance of a pooled draw: the copy's slot and its shell (0 for a skin).
const ENTRY_BYTES: u64 = 8;

const ENTRY_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: ENTRY_BYTES,
    step_mode: wgpu::VertexStepMode::Instance,
    attributes: &[wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32x2, offset: 0, shader_location: 0 }],
};

/// The numbers plans take, so a pool knows which plan its gathered draws are for.
static PLANS: AtomicU64 = AtomicU64::new(1);

/// How far apart two screen rectangles must stand (in normalized device coordinates, about a
/// pixel at 1280x720) to count as apart: the GPU's projection rounds as the CPU's need not.
const RECT_MARGIN: f32 = 2e-3;

/// The plan of a herd's draws through one camera view, made each frame
/// ([`HerdDraws::prepare`]) after the members' [`GpuFur::prepare`] and drawn by
/// [`FurRenderer::draw_herd_planned`]. Where the renderer does not pool the camera's draws
/// ([`FurRenderer::pooled_drawing`]) the plan draws each member alone, in order.
#[derive(Debug, Default)]
pub struct HerdDraws {
    /// The instance buffer's entries: `[slot, shell]`.
    entries: Vec<[u32; 2]>,
    buffer: Option<wgpu::Buffer>,
    steps: Vec<Step>,
    /// The members of the pooled steps, run by run.
    pooled: Vec<usize>,
    members: usize,
    levels: usize,
    /// This plan's number (0 until its first `prepare`), which the pools it gathers keep.
    id: u64,
    /// The members whose thinned shells the last plan gathered.
    gathered: usize,
}

#[derive(Clone, Debug, PartialEq, Eq)]
enum Step {
    /// The member drawn as a lone fur.
    Alone(usize),
    /// Members of one pool (`pooled[members]`), none overlapping another: their skins over
    /// `entries[skins]`; the shells of those before `pooled[thinned]` over `entries[shells]`,
    /// and of the rest (thinned by the view angle) through the gathered draws `shell_places`;
    /// then the fins, through the gathered draws `fin_places` where there are any, else each
    /// one's own.
    Pooled {
        members: Range<usize>,
        thinned: usize,
        skins: Range<u32>,
        shells: Range<u32>,
        shell_places: Range<u32>,
        fin_places: Range<u32>,
    },
}

/// Where a pool's copies gather this plan: the next free fin and shell places, and each
/// gathered slot's places.
struct PoolPlaces<'a> {
    pool: &'a Arc<MemberPool>,
    next: [u32; 2],
    places: Vec<(u32, [u32; 2])>,
}

impl HerdDraws {
    /// An empty plan; its instance buffer grows as herds need.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// Plans the draws of `members` (in the order drawing each alone takes: farthest first),
    /// each with a world-space sphere (`centre`, `radius`) that holds all it draws; a member that
    /// reaches outside its sphere may blend out of order where it overlaps another. Writes the
    /// instance buffer and the gathered places (they take effect at the next submission, whose
    /// listing passes, [`FurRenderer::prepare_fins_of`], write the gathered draws). A pool gathers
    /// for the plan prepared last: another plan drawing its copies then draws their thinned
    /// shells and fins each alone.
    pub fn prepare(
        &mut self,
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        renderer: &FurRenderer,
        view: &ViewData,
        members: &[(&GpuFur, (Vec3, f32))],
    ) {
        self.entries.clear();
        self.steps.clear();
        self.pooled.clear();
        self.members = members.len();
        self.gathered = 0;
        if self.id == 0 {
            self.id = PLANS.fetch_add(1, Ordering::Relaxed);
        }
        if !renderer.pooled_drawing() {
            self.levels = members.len();
            self.steps.extend((0..members.len()).map(Step::Alone));
            return;
        }
        let gathers = renderer.first_instance;
        let mut pools: Vec<PoolPlaces<'_>> = Vec::new();
        let levels = levels(members.iter().map(|(_, sphere)| screen_rect(view.clip_from_world, *sphere)));
        self.levels = levels.iter().max().map_or(0, |top| top + 1);
        let mut by_level: Vec<Vec<usize>> = vec![Vec::new(); self.levels];
        for (member, &level) in levels.iter().enumerate() {
            by_level[level].push(member);
        }
        for level in by_level {
            // Runs of one pool, coat and textures, in the order first met.
            let mut runs: Vec<Vec<usize>> = Vec::new();
            for member in level {
                let fur = members[member].0;
                if !poolable(fur, gathers) {
                    self.steps.push(Step::Alone(member));
                    continue;
                }
                match runs.iter_mut().find(|run| draw_together(members[run[0]].0, fur)) {
                    Some(run) => run.push(member),
                    None => runs.push(vec![member]),
                }
            }
            for mut run in runs {
                if let [member] = run[..] {
                    self.steps.push(Step::Alone(member));
                    continue;
                }
                // The thinned copies last, their shells gathered.
                run.sort_by_key(|&member| thinned(members[member].0));
                let start = self.pooled.len();
                let skins = self.entries.len() as u32;
                self.entries.extend(run.iter().map(|&member| [members[member].0.slot(), 0]));
                let shells = self.entries.len() as u32;
                let whole = run.iter().filter(|&&member| !thinned(members[member].0)).count();
                for &member in &run[..whole] {
                    let fur = members[member].0;
                    self.entries.extend((0..coat_shells(fur)).map(|shell| [fur.slot(), shell]));
                }
                let pool = members[run[0]].0.pool();
                let at = match pools.iter().position(|p| Arc::ptr_eq(p.pool, pool)) {
                    Some(at) => at,
                    None => {
                        pools.push(PoolPlaces { pool, next: [0; 2], places: Vec::new() });
                        pools.len() - 1
                    }
                };
                let places = &mut pools[at];
                let first = places.next;
                for (k, &member) in run.iter().enumerate() {
                    let fur = members[member].0;
                    let lists = fur.lists();
                    let mut place = [NOT_GATHERED; 2];
                    if gathers && lists & LIST_FINS != 0 {
                        place[0] = places.next[0];
                        places.next[0] += 1;
                    }
                    if k >= whole {
                        place[1] = places.next[1];
                        places.next[1] += 1;
                    }
                    if place != [NOT_GATHERED; 2] {
                        places.places.push((fur.slot(), place));
                    }
                }
                self.gathered += run.len() - whole;
                self.pooled.extend(run);
                self.steps.push(Step::Pooled {
                    members: start..self.pooled.len(),
                    thinned: start + whole,
                    skins: skins..shells,
                    shells: shells..self.entries.len() as u32,
                    shell_places: first[1]..places.next[1],
                    fin_places: first[0]..places.next[0],
                });
            }
        }
        if gathers {
            for places in pools {
                places.pool.gather(queue, self.id, &places.places);
            }
        }
        if self.entries.is_empty() {
            return;
        }
        let bytes = ENTRY_BYTES * self.entries.len() as u64;
        if self.buffer.as_ref().is_none_or(|buffer| buffer.size() < bytes) {
            self.buffer = Some(device.create_buffer(&wgpu::BufferDescriptor {
                label: Some("pelt herd draws"),
                size: bytes.next_power_of_two(),
                usage: wgpu::BufferUsages::VERTEX | wgpu::BufferUsages::COPY_DST,
                mapped_at_creation: false,
            }));
        }
        if let Some(buffer) = &self.buffer {
            queue.write_buffer(buffer, 0, bytemuck::cast_slice(&self.entries));
        }
    }

    /// How many levels the last plan put its members in (each member its own where the renderer
    /// draws them alone): the draws a pool's skins and shells take.
    #[must_use]
    pub fn levels(&self) -> usize {
        self.levels
    }

    /// How many members the last plan draws with others.
    #[must_use]
    pub fn pooled_members(&self) -> usize {
        self.pooled.len()
    }

    /// How many of those thin their shells by the view angle, drawn through gathered draws.
    #[must_use]
    pub fn gathered_members(&self) -> usize {
        self.gathered
    }
}

/// Whether a copy can draw in a pooled step: dry (the pool binds no copy's wetness), and unless
/// the plan `gathers`, not thinned by the view angle (its shells follow its own list).
fn poolable(fur: &GpuFur, gathers: bool) -> bool {
    !fur.coat().wet && (gathers || !thinned(fur))
}

/// Whether a copy's shells follow its view-angle list this frame.
fn thinned(fur: &GpuFur) -> bool {
    fur.lists() & LIST_SHELLS != 0
}

/// Whether `next` draws in the same pooled step as `first`: the same pool, coat and textures.
fn draw_together(first: &GpuFur, next: &GpuFur) -> bool {
    Arc::ptr_eq(first.pool(), next.pool())
        && first.coat() == next.coat()
        && first.textures_bind_group() == next.textures_bind_group()
}

/// The shells a copy draws as a lone fur does: none when its coat is hidden.
fn coat_shells(fur: &GpuFur) -> u32 {
    if fur.geometry().shape.layers > 0 && fur.prepared_level().coat_shown() { fur.drawn_shells() } else { 0 }
}

/// The rectangle (normalized device x and y: min, max) of the sphere's projection, exact: for
/// each axis the two values `t` whose plane `clip.axis = t * clip.w` touches the sphere.
/// Everywhere when some of the sphere is at or behind the eye, or it is not finite.
fn screen_rect(clip_from_world: Mat4, (centre, radius): (Vec3, f32)) -> [f32; 4] {
    const EVERYWHERE: [f32; 4] = [f32::NEG_INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::INFINITY];
    let (c, r) = (centre.as_dvec3(), f64::from(radius));
    let row = |k: usize| clip_from_world.row(k).as_dvec4();
    let (w, w0) = (row(3).truncate(), row(3).w);
    let centre_w = w.dot(c) + w0;
    if !(c.is_finite() && r.is_finite() && r >= 0.0 && centre_w - r * w.length() > 1e-9 * centre_w.abs().max(1e-9)) {
        return EVERYWHERE;
    }
    let bounds = |k: usize| {
        let (a, a0) = (row(k).truncate(), row(k).w);
        let centre_a = a.dot(c) + a0;
        let quadratic = centre_w * centre_w - r * r * w.length_squared();
        let half = centre_a * centre_w - r * r * a.dot(w);
        let constant = centre_a * centre_a - r * r * a.length_squared();
        let root = (half * half - quadratic * constant).max(0.0).sqrt();
        ((half - root) / quadratic, (half + root) / quadratic)
    };
    let ((x0, x1), (y0, y1)) = (bounds(0), bounds(1));
    let rect = [x0, y0, x1, y1].map(|v| v as f32);
    if rect.iter().all(|v| v.is_finite()) { rect } else { EVERYWHERE }
}

fn overlap(a: &[f32; 4], b: &[f32; 4]) -> bool {
    a[0] <= b[2] + RECT_MARGIN && b[0] <= a[2] + RECT_MARGIN && a[1] <= b[3] + RECT_MARGIN && b[1] <= a[3] + RECT_MARGIN
}

/// Each rectangle's level, in order: one above the highest level holding an earlier rectangle
/// it overlaps, else 0. A level's rectangles overlap none of each other.
fn levels(rects: impl Iterator<Item = [f32; 4]>) -> Vec<usize> {
    // Per level: the union of its rectangles (a quick rejection), then the rectangles.
    let mut held: Vec<([f32; 4], Vec<[f32; 4]>)> = Vec::new();
    rects
        .map(|rect| {
            let level = held
                .iter()
                .rposition(|(union, rects)| overlap(union, &rect) && rects.iter().any(|r| overlap(r, &rect)))
                .map_or(0, |below| below + 1);
            if level == held.len() {
                held.push((rect, Vec::new()));
            }
            let (union, rects) = &mut held[level];
            *union = [union[0].min(rect[0]), union[1].min(rect[1]), union[2].max(rect[2]), union[3].max(rect[3])];
            rects.push(rect);
            level
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The rectangle holds every projected point of the sphere and no more: its edges are
    /// within a thousandth of the extremes of 20,000 points on the sphere, seen off-axis.
    #[test]
    fn the_rectangle_is_the_spheres_projection() {
        let clip_from_world = glam::camera::rh::proj::directx::perspective(0.9, 1.6, 0.1, 100.0)
            * glam::camera::rh::view::look_at_mat4(Vec3::new(1.0, 2.0, 3.0), Vec3::new(-2.0, 0.5, -6.0), Vec3::Y);
        for (centre, radius) in [(Vec3::new(-4.0, 1.0, -9.0), 1.5), (Vec3::new(0.5, -1.0, -4.0), 0.7)] {
            let rect = screen_rect(clip_from_world, (centre, radius));
            let mut seen = [f32::INFINITY, f32::INFINITY, f32::NEG_INFINITY, f32::NEG_INFINITY];
            let n = 20_000;
            for i in 0..n {
                // A Fibonacci sphere.
                let z = 1.0 - 2.0 * (i as f32 + 0.5) / n as f32;
                let angle = i as f32 * 2.399_963;
                let ring = (1.0 - z * z).sqrt();
                let p = centre + radius * Vec3::new(ring * angle.cos(), ring * angle.sin(), z);
                let clip = clip_from_world * p.extend(1.0);
                let (x, y) = (clip.x / clip.w, clip.y / clip.w);
                seen = [seen[0].min(x), seen[1].min(y), seen[2].max(x), seen[3].max(y)];
            }
            for k in 0..4 {
                let outside = if k < 2 { rect[k] - seen[k] } else { seen[k] - rect[k] };
                assert!((-1e-3..=1e-5).contains(&outside), "edge {k}: {rect:?} against {seen:?}");
            }
        }
    }

    #[test]
    fn levels_separate_only_what_overlaps() {
        let at = |x: f32| [x, 0.0, x + 1.0, 1.0];
        // 0 and 1 apart; 2 overlaps 0; 3 overlaps 2 and 1; 4 apart from all.
        let rects = [at(0.0), at(2.0), at(0.5), at(1.4), at(5.0)];
        assert_eq!(levels(rects.into_iter()), [0, 0, 1, 2, 0]);
        // Everywhere overlaps everything before and after it.
        let everywhere = [f32::NEG_INFINITY, f32::NEG_INFINITY, f32::INFINITY, f32::INFINITY];
        assert_eq!(levels([at(0.0), everywhere, at(5.0)].into_iter()), [0, 1, 2]);
    }

    #[test]
    fn a_sphere_behind_the_eye_covers_the_screen() {
        let clip_from_world = glam::camera::rh::proj::directx::perspective(1.0, 1.0, 0.1, 100.0)
            * glam::camera::rh::view::look_at_mat4(Vec3::ZERO, -Vec3::Z, Vec3::Y);
        let ahead = screen_rect(clip_from_world, (Vec3::new(0.0, 0.0, -10.0), 1.0));
        assert!(ahead[0] < 0.0 && ahead[2] > 0.0 && ahead[2] - ahead[0] < 0.5, "{ahead:?}");
        let left = screen_rect(clip_from_world, (Vec3::new(-5.0, 0.0, -10.0), 1.0));
        assert!(!overlap(&ahead, &left), "{ahead:?} {left:?}");
        assert_eq!(screen_rect(clip_from_world, (Vec3::new(0.0, 0.0, 1.0), 2.0))[0], f32::NEG_INFINITY);
        assert_eq!(screen_rect(clip_from_world, (Vec3::new(0.0, 0.0, -1.0), 1.5))[0], f32::NEG_INFINITY);
        assert_eq!(screen_rect(clip_from_world, (Vec3::new(0.0, 0.0, -10.0), f32::NAN))[2], f32::INFINITY);
    }
}
