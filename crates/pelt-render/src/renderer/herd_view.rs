//! A herd through the camera in a few draws ([`HerdDraws`]). Blending needs the order only
//! where copies overlap, so the copies are put in levels: a copy goes one level above the
//! highest level holding a farther copy whose screen rectangle (from the sphere the host says
//! holds it) overlaps its own, and the copies of one level share no pixel. A level's copies of
//! one pool then draw their skins in one draw and their shells in another (`pool_draws.wgsl`:
//! an instance buffer names each instance's slot and shell), and the picture has the bytes of
//! every copy drawn alone, farthest first. The draws grow with how many copies stand behind one
//! another on screen, not with the herd. Fins stay a draw a copy: only copies near enough to show
//! them draw any (`FurLevel::fins`).

use std::ops::Range;
use std::sync::{Arc, OnceLock};

use glam::{Mat4, Vec3};

use super::pipeline::{PassKind, PipelineSource, Transparency, create_pipeline};
use super::{CoatBuilder, FurDrawSettings, FurRenderer, WALKS};
use crate::fur::{Coat, GpuFur};
use crate::view::{FurView, ShadowLookups, ViewData, ViewRole};

/// One instance of a pooled draw: the copy's slot and its shell (0 for a skin).
const ENTRY_BYTES: u64 = 8;

const ENTRY_LAYOUT: wgpu::VertexBufferLayout<'static> = wgpu::VertexBufferLayout {
    array_stride: ENTRY_BYTES,
    step_mode: wgpu::VertexStepMode::Instance,
    attributes: &[wgpu::VertexAttribute { format: wgpu::VertexFormat::Uint32x2, offset: 0, shader_location: 0 }],
};

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
}

#[derive(Clone, Debug, PartialEq, Eq)]
enum Step {
    /// The member drawn as a lone fur.
    Alone(usize),
    /// Members of one pool (`pooled[members]`), none overlapping another: their skins over
    /// `entries[skins]`, their shells over `entries[shells]`, then each one's fins.
    Pooled { members: Range<usize>, skins: Range<u32>, shells: Range<u32> },
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
    /// instance buffer (it takes effect at the next submission).
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
        if !renderer.pooled_drawing() {
            self.levels = members.len();
            self.steps.extend((0..members.len()).map(Step::Alone));
            return;
        }
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
                if !poolable(fur) {
                    self.steps.push(Step::Alone(member));
                    continue;
                }
                match runs.iter_mut().find(|run| draw_together(members[run[0]].0, fur)) {
                    Some(run) => run.push(member),
                    None => runs.push(vec![member]),
                }
            }
            for run in runs {
                if let [member] = run[..] {
                    self.steps.push(Step::Alone(member));
                    continue;
                }
                let start = self.pooled.len();
                let skins = self.entries.len() as u32;
                self.entries.extend(run.iter().map(|&member| [members[member].0.slot(), 0]));
                let shells = self.entries.len() as u32;
                for &member in &run {
                    let fur = members[member].0;
                    self.entries.extend((0..coat_shells(fur)).map(|shell| [fur.slot(), shell]));
                }
                self.pooled.extend(run);
                self.steps.push(Step::Pooled {
                    members: start..self.pooled.len(),
                    skins: skins..shells,
                    shells: shells..self.entries.len() as u32,
                });
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
}

/// Whether a copy can draw in a pooled step: dry (the pool binds no copy's wetness) and not
/// thinned by the view angle (its shells follow its own list).
fn poolable(fur: &GpuFur) -> bool {
    !fur.coat().wet && !fur.prepared_level().by_view()
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

/// The camera's pooled pipelines, each built the first time a herd draws with it.
#[derive(Debug, Default)]
pub(super) struct PoolCameraPipelines {
    /// By shadow lookups, then walk.
    skins: [OnceLock<[wgpu::RenderPipeline; 2]>; 3],
    /// By coat, then walk and transparency.
    shells: [OnceLock<[[wgpu::RenderPipeline; 2]; 2]>; Coat::COUNT],
}

impl CoatBuilder {
    fn pool_camera(
        &self,
        (module, layout): (&wgpu::ShaderModule, &wgpu::PipelineLayout),
        target: &crate::targets::FurTarget,
        (vertex, fragment): (&str, &str),
        (mesh_uvs, coat, kind): (bool, Coat, PassKind),
    ) -> wgpu::RenderPipeline {
        let buffers = [Some(ENTRY_LAYOUT)];
        let source = PipelineSource {
            mesh_uvs: Some(mesh_uvs),
            coat: Some(coat),
            layout,
            module,
            vertex_entry: vertex,
            fragment_entry: fragment,
            buffers: &buffers,
        };
        create_pipeline(&self.device, target, "pelt pool camera", &source, kind)
    }
}

impl FurRenderer {
    /// Whether [`HerdDraws`] pools the camera's draws of a herd's copies: by default on a
    /// discrete or integrated GPU, as [`FurRenderer::pooled_casting`] (a CPU rasteriser reads
    /// each vertex's object from storage, which costs it more than the draws save).
    #[must_use]
    pub fn pooled_drawing(&self) -> bool {
        self.pooled_drawing
    }

    /// Sets [`FurRenderer::pooled_drawing`] for the plans made after; the pictures are the same
    /// either way.
    pub fn set_pooled_drawing(&mut self, pooled: bool) {
        self.pooled_drawing = pooled;
    }

    /// Draws the members `furs` of a [`HerdDraws::prepare`] (the same furs in the same order)
    /// through `view` as its plan says; through a shadow map's view as
    /// [`FurRenderer::draw_herd`]. Furs that are not the plan's draw each alone, in order.
    /// Returns the draws recorded.
    pub fn draw_herd_planned(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        view: &FurView,
        plan: &HerdDraws,
        furs: &[&GpuFur],
        settings: &FurDrawSettings,
    ) -> usize {
        let shadowed = match view.role() {
            ViewRole::Camera { shadows } if furs.len() == plan.members => shadows,
            _ => return self.draw_herd(pass, view, furs.iter().copied(), settings),
        };
        let mut draws = 0;
        for step in &plan.steps {
            draws += match step {
                Step::Alone(member) => self.draw_counted(pass, view, furs[*member], settings),
                Step::Pooled { members, skins, shells } => {
                    let run: Vec<&GpuFur> = plan.pooled[members.clone()].iter().map(|&k| furs[k]).collect();
                    let Some(buffer) = &plan.buffer else { continue };
                    self.draw_pooled(pass, (view, shadowed), (&run, buffer), (skins.clone(), shells.clone()), settings)
                }
            };
        }
        draws
    }

    /// One pooled step: the run's skins, shells and each one's fins.
    fn draw_pooled(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        (view, shadowed): (&FurView, ShadowLookups),
        (run, buffer): (&[&GpuFur], &wgpu::Buffer),
        (skins, shells): (Range<u32>, Range<u32>),
        settings: &FurDrawSettings,
    ) -> usize {
        let first = run[0];
        let geometry = first.geometry();
        let walk = usize::from(!geometry.shape.has_uvs);
        let mut draws = 0;
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, first.pool().draw_group(), &[]);
        pass.set_bind_group(2, first.textures_bind_group(), &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        // Each draw's entries bound from their first and its instances counted from 0, so no
        // backend needs a first instance for instance-rate attributes.
        let entries =
            |range: &Range<u32>| buffer.slice(ENTRY_BYTES * u64::from(range.start)..ENTRY_BYTES * u64::from(range.end));
        if settings.skin {
            pass.set_pipeline(&self.pool_camera_skins(shadowed)[walk]);
            pass.set_vertex_buffer(0, entries(&skins));
            geometry.draw_skins(pass, 0..skins.len() as u32);
            draws += 1;
        }
        if settings.shells && !shells.is_empty() {
            let which = Transparency::index(settings.alpha_to_coverage);
            pass.set_pipeline(&self.pool_camera_shells(first.coat().shadowed(shadowed))[walk][which]);
            pass.set_vertex_buffer(0, entries(&shells));
            geometry.draw_shells(pass, 0..shells.len() as u32);
            draws += 1;
        }
        // Fins after the shells, as a lone fur draws them (its own object in group 1).
        if settings.fins {
            for fur in run {
                if coat_shells(fur) > 0 && fur.prepared_level().fins_shown() {
                    pass.set_bind_group(1, fur.geometry().bind_group(), &[]);
                    draws += self.draw_fins_of(pass, fur, shadowed, settings);
                }
            }
        }
        draws
    }

    fn pool_camera_skins(&self, shadowed: ShadowLookups) -> &[wgpu::RenderPipeline; 2] {
        self.pool_camera.skins[shadowed as usize].get_or_init(|| {
            let casters = self.pool_casters();
            let coat = Coat::PLAIN.shadowed(shadowed);
            WALKS.map(|(walk, uvs)| {
                self.coat_builder.pool_camera(
                    (&casters.module, &casters.layout),
                    &self.target,
                    (&format!("vs_pool_camera_skin_{walk}"), "fs_pool_skin"),
                    (uvs, coat, PassKind::Opaque),
                )
            })
        })
    }

    fn pool_camera_shells(&self, coat: Coat) -> &[[wgpu::RenderPipeline; 2]; 2] {
        self.pool_camera.shells[coat.index()].get_or_init(|| {
            let casters = self.pool_casters();
            WALKS.map(|(walk, uvs)| {
                let fragment = coat.entry(if uvs { "fs_pool_shell_uvs" } else { "fs_pool_shell_tiles" });
                let vertex = coat.entry(&format!("vs_pool_shell_{walk}"));
                Transparency::BOTH.map(|t| {
                    self.coat_builder.pool_camera(
                        (&casters.module, &casters.layout),
                        &self.target,
                        (&vertex, &fragment),
                        (uvs, coat, PassKind::Shells(t)),
                    )
                })
            })
        })
    }
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
