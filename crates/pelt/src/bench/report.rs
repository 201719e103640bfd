//! The report: its JSON shape (stable keys, documented in BENCHMARKS.md) and its Markdown form.

use std::fmt::Write as _;

use super::table2::{PAPER_SAVINGS_VS_2_PERCENT, PAPER_SAVINGS_VS_30_PERCENT, Table2Row, savings_percent};
use crate::format::thousands;

/// Everything one `pelt bench` run measured.
#[derive(Debug, serde::Serialize)]
pub struct Report {
    pub pelt_version: &'static str,
    pub date_utc: String,
    /// The command line as run.
    pub command: String,
    pub quick: bool,
    /// `release` or `debug`: timings from a debug build are not comparable.
    pub build_profile: &'static str,
    pub machine: Machine,
    /// The GPU adapter the frame times were taken on; null when none was found.
    pub adapter: Option<Adapter>,
    pub adapter_unavailable_reason: Option<String>,
    /// The paper's claims, for the savings to be read against (constants, not measured).
    pub paper_savings_vs_2_percent: f64,
    pub paper_savings_vs_30_percent: f64,
    /// The CPU kernel the simulation figures were taken with (`avx2+fma` or `portable`).
    pub sim_cpu_kernel: &'static str,
    /// Simulation throughput on a 35,000-vertex mesh; null with `--quick`.
    pub sim_large_mesh: Option<LargeMeshFigures>,
    /// One object per model and layer count.
    pub results: Vec<ResultRow>,
    /// Models whose meshes could not be loaded.
    pub skipped_models: Vec<SkippedModel>,
    /// Peak resident memory of the whole run (`VmHWM`); null where the OS does not say.
    pub peak_rss_bytes: Option<u64>,
    pub wall_time_s: f64,
}

#[derive(Debug, serde::Serialize)]
pub struct Machine {
    pub cpu: String,
    pub cpu_threads: usize,
    pub memory_bytes: Option<u64>,
    pub os: &'static str,
}

#[derive(Debug, Clone, serde::Serialize)]
pub struct Adapter {
    pub name: String,
    pub backend: String,
    pub device_type: String,
    pub driver: String,
    /// MSAA samples every frame is drawn with (`pelt_render::default_sample_count`).
    pub msaa_samples: u32,
}

#[derive(Debug, serde::Serialize)]
pub struct SkippedModel {
    pub model: &'static str,
    pub reason: String,
}

/// One model at one layer count.
#[derive(Debug, serde::Serialize)]
pub struct ResultRow {
    pub model: &'static str,
    pub paper_model: &'static str,
    pub mesh: String,
    pub layers: u32,
    #[serde(flatten)]
    pub table2: Table2Figures,
    #[serde(flatten)]
    pub render: RenderFigures,
    #[serde(flatten)]
    pub sim: SimFigures,
    #[serde(flatten)]
    pub texture: TextureFigures,
    #[serde(flatten)]
    pub gpu_sim: GpuSimFigures,
    #[serde(flatten)]
    pub anim: AnimFigures,
}

/// The Table 2 part: counts and bytes, all computed.
#[derive(Debug, serde::Serialize)]
pub struct Table2Figures {
    /// Base vertices of everything drawn (the paper's "vertices").
    pub vertices: u64,
    /// Base triangles of everything drawn (the paper's "faces").
    pub faces: u64,
    /// Base vertices and edges of the furred mesh (a body, if any, grows no fur).
    pub fur_vertices: u64,
    pub fur_edges: u64,
    /// The unified structure's vertices: `V(L+1)` (plus the body's).
    pub unified_vertices: u64,
    /// The separated structure's: `V(L+1) + 2E` and `V(L+1) + 30E` (plus the body's).
    pub separated2_vertices: u64,
    pub separated30_vertices: u64,
    pub unified_faces: u64,
    pub separated2_faces: u64,
    pub separated30_faces: u64,
    /// GPU bytes (positions, attributes, indices; the layouts in `pelt_core::fur::Footprint`).
    pub unified_bytes: u64,
    pub separated2_bytes: u64,
    pub separated30_bytes: u64,
    /// Vertices saved, the paper's measure (its claim: about 25% and 85%).
    pub savings_vs_2_percent: f64,
    pub savings_vs_30_percent: f64,
    /// GPU bytes saved.
    pub bytes_savings_vs_2_percent: f64,
    pub bytes_savings_vs_30_percent: f64,
}

impl From<&Table2Row> for Table2Figures {
    fn from(row: &Table2Row) -> Self {
        let body_faces = row.body_faces;
        Self {
            vertices: row.vertices,
            faces: row.faces,
            fur_vertices: row.fur_vertices,
            fur_edges: row.fur_edges,
            unified_vertices: row.unified_vertices(),
            separated2_vertices: row.separated2_vertices(),
            separated30_vertices: row.separated30_vertices(),
            unified_faces: row.unified.faces + body_faces,
            separated2_faces: row.separated2.faces + body_faces,
            separated30_faces: row.separated30.faces + body_faces,
            unified_bytes: row.unified_bytes(),
            separated2_bytes: row.separated2_bytes(),
            separated30_bytes: row.separated30_bytes(),
            savings_vs_2_percent: savings_percent(row.unified_vertices(), row.separated2_vertices()),
            savings_vs_30_percent: savings_percent(row.unified_vertices(), row.separated30_vertices()),
            bytes_savings_vs_2_percent: savings_percent(row.unified_bytes(), row.separated2_bytes()),
            bytes_savings_vs_30_percent: savings_percent(row.unified_bytes(), row.separated30_bytes()),
        }
    }
}

/// Median GPU frame times in milliseconds, same scene, three structures, two sizes.
#[derive(Debug, Default, serde::Serialize)]
pub struct RenderFigures {
    pub frame_ms_unified_1280x720: Option<f64>,
    pub frame_ms_separated2_1280x720: Option<f64>,
    pub frame_ms_separated30_1280x720: Option<f64>,
    pub frame_ms_unified_256x256: Option<f64>,
    pub frame_ms_separated2_256x256: Option<f64>,
    pub frame_ms_separated30_256x256: Option<f64>,
    /// `--shadows`: the unified fur with the key light's shadow maps (the shadow passes and the
    /// picture), timed in turn with the three above.
    pub frame_ms_unified_shadows_1280x720: Option<f64>,
    pub frame_ms_unified_shadows_256x256: Option<f64>,
    /// Frames each median was taken over.
    pub render_frames: Option<u32>,
    /// Fins the unified structure drew at 1280x720: the edges the silhouette pass kept, of
    /// `fur_edges`.
    pub fin_edges_drawn: Option<u64>,
    /// Uploading the unified shared vertex array (what a simulated fur sends every frame),
    /// submitted and waited for.
    pub upload_ms_per_frame: Option<f64>,
    /// The level of detail, unified structure, per size (1280x720, then 256x256): at the
    /// default framing and at 4x its distance, with LOD on and off (the columns above are off).
    pub lod: Vec<LodFigures>,
    /// The sizes `--size` asked for (empty without it), each with frames per second.
    pub extra_sizes: Vec<SizeFigures>,
    pub render_unavailable_reason: Option<String>,
}

/// One `--size` frame size: the three structures' median frame times (each frame waited for,
/// as in the table of the two standard sizes) and their frames per second with frames
/// submitted back to back, two in flight, as a game loop without vsync draws them.
#[derive(Debug, Default, serde::Serialize)]
pub struct SizeFigures {
    /// `WIDTHxHEIGHT`.
    pub size: String,
    pub frame_ms_unified: f64,
    pub frame_ms_separated2: f64,
    pub frame_ms_separated30: f64,
    pub fps_unified: f64,
    pub fps_separated2: f64,
    pub fps_separated30: f64,
    /// The unified fur's level of detail at the default framing, e.g. `8/16 shells` (null under
    /// `--no-lod`), and its frames per second there.
    pub level: Option<String>,
    pub fps_unified_lod: Option<f64>,
    /// Frames in each timed run of the frames-per-second figures.
    pub fps_frames: u32,
}

/// One size's level-of-detail figures (unified structure, the default preset's `[render.lod]`).
#[derive(Debug, Default, serde::Serialize)]
pub struct LodFigures {
    /// `WIDTHxHEIGHT`.
    pub size: String,
    /// The level at the default framing, e.g. `8/16 shells`.
    pub level_near: String,
    /// Every shell at the default framing (LOD off), then at its level.
    pub frame_ms_near_full: f64,
    pub frame_ms_near_lod: f64,
    /// Triangles drawn at the default framing, full and at the level (the shells the view
    /// angle thins drawn over the view-angle pass's list only).
    pub triangles_near_full: u64,
    pub triangles_near_lod: u64,
    /// The level at 4x the distance.
    pub level_far: String,
    pub frame_ms_far_full: f64,
    pub frame_ms_far_lod: f64,
    /// Triangles drawn at 4x the distance (skin, shells, fins on the silhouette pass's edges),
    /// full and at the level of detail.
    pub triangles_far_full: u64,
    pub triangles_far_lod: u64,
}

/// The simulation's throughput on a mesh larger than the paper's.
#[derive(Debug, serde::Serialize)]
pub struct LargeMeshFigures {
    pub mesh: String,
    pub vertices: u64,
    pub layers: u32,
    pub sim_node_updates_per_sec: f64,
    pub sim_node_updates_per_sec_all_threads: f64,
    /// The GPU kernel (`--sim gpu`) with wind, as `gpu_sim_node_updates_per_sec`; null without an
    /// adapter (`adapter_unavailable_reason`).
    pub gpu_sim_node_updates_per_sec: Option<f64>,
}

/// Simulation throughput and its CPU cost per drawn frame.
#[derive(Debug, Default, serde::Serialize)]
pub struct SimFigures {
    /// Non-root nodes moved per second (`V * L` per step) by `Simulation`'s steps, one thread.
    pub sim_node_updates_per_sec: Option<f64>,
    /// The same on all threads.
    pub sim_node_updates_per_sec_all_threads: Option<f64>,
    /// The paper's literal O(L^2) loop, one thread, timed the same way.
    pub sim_literal_node_updates_per_sec: Option<f64>,
    /// CPU per drawn frame at 120 Hz drawing: 30 Hz simulation plus interpolation ...
    pub sim_cpu_ms_per_frame_interpolated: Option<f64>,
    /// ... against simulating every drawn frame.
    pub sim_cpu_ms_per_frame_every_frame: Option<f64>,
    pub sim_unavailable_reason: Option<String>,
}

/// An animated model's CPU cost per frame at 30 Hz (null for the static models).
#[derive(Debug, Default, serde::Serialize)]
pub struct AnimFigures {
    /// The animation posed.
    pub anim_clip: Option<String>,
    /// `Rig::pose`: skinning of positions, normals and vertex frames.
    pub anim_pose_ms_per_frame: Option<f64>,
    /// The simulation following the pose: `set_base_rotations` and `advance_to` (all threads), as `pelt render` runs it.
    pub anim_sim_ms_per_frame: Option<f64>,
    /// Both: the CPU's part of an animated frame (the GPU's is `frame_ms`).
    pub anim_cpu_ms_per_frame: Option<f64>,
    pub anim_unavailable_reason: Option<String>,
}

/// The GPU simulation (`pelt_render::GpuSimulation`) on the report's adapter.
#[derive(Debug, Default, serde::Serialize)]
pub struct GpuSimFigures {
    /// Non-root nodes moved per second (`V * L` per step) by the compute pass: the median of
    /// repeated runs, each a batch of steps in one submission waited for with a fence.
    pub gpu_sim_node_updates_per_sec: Option<f64>,
    /// Steps per timed run.
    pub gpu_sim_steps_per_run: Option<u32>,
    /// CPU ms per drawn frame at 120 Hz drawing with the GPU simulating at 30 Hz (time, steps,
    /// prepare, recording and submission; no interpolation or upload), to set beside
    /// `sim_cpu_ms_per_frame_interpolated`.
    pub gpu_sim_cpu_ms_per_frame: Option<f64>,
    pub gpu_sim_unavailable_reason: Option<String>,
}

/// Shell and fin texture generation.
#[derive(Debug, Default, serde::Serialize)]
pub struct TextureFigures {
    pub texture_generation_ms: Option<f64>,
    /// Shell tile size `S` (texels per side) the time is for.
    pub texture_size_texels: Option<u32>,
    pub texture_unavailable_reason: Option<String>,
}

/// The paper's Table 2 (GeForce 8800 GTX, 16 layers), quoted for the side-by-side table:
/// model, vertices, faces, unified, separated 2-face, separated 30-face, fps.
const PAPER_TABLE_2: [(&str, &str, &str, &str, &str, &str, &str); 5] = [
    ("Box", "296", "588", "5,032", "6,796", "31,492", "10,993 (as printed)"),
    ("Bunny", "2,520", "5,036", "42,840", "57,948", "275,460", "14.4"),
    ("Boar", "2,976", "5,688", "31,632", "42,174", "189,762", "20.42"),
    ("Shawl", "261", "420", "4,176", "5,536", "24,576", "149.72"),
    ("Women (with shawl)", "18,324", "35,639", "22,500", "23,860", "42,900", "64.87"),
];

impl Report {
    /// The report as Markdown: run facts, Table 2 beside the paper's, timings, and why any
    /// figure is missing.
    pub fn to_markdown(&self) -> String {
        let mut md = String::new();
        let _ = writeln!(md, "- date: {}", self.date_utc);
        let _ = writeln!(md, "- command: `{}`", self.command);
        let _ =
            writeln!(md, "- build: {}{}", self.build_profile, if self.quick { " (--quick: reduced set)" } else { "" });
        let memory = self.machine.memory_bytes.map_or(String::new(), |b| format!(", {}", gib(b)));
        let _ = writeln!(
            md,
            "- machine: {} ({} threads{memory}, {})",
            self.machine.cpu, self.machine.cpu_threads, self.machine.os
        );
        match (&self.adapter, &self.adapter_unavailable_reason) {
            (Some(a), _) => {
                let _ = writeln!(
                    md,
                    "- adapter: {} ({}, {}, driver {}), {}x MSAA",
                    a.name, a.backend, a.device_type, a.driver, a.msaa_samples
                );
            }
            (None, reason) => {
                let _ = writeln!(md, "- adapter: none ({})", reason.as_deref().unwrap_or("not searched"));
            }
        }
        let peak = self.peak_rss_bytes.map_or_else(|| "not reported by this OS".to_owned(), mib);
        let _ = writeln!(md, "- peak resident memory: {peak}; wall time {:.1} s", self.wall_time_s);
        for skipped in &self.skipped_models {
            let _ = writeln!(md, "- skipped {}: {}", skipped.model, skipped.reason);
        }

        let _ = writeln!(md, "\n### Memory: the paper's Table 2, measured\n");
        let _ = writeln!(
            md,
            "| model | paper's | L | vertices | faces | fin edges | unified (shared) | separated, 2-face fins | separated, 30-face fins | saved vs 2 (paper ~{PAPER_SAVINGS_VS_2_PERCENT}%) | saved vs 30 (paper ~{PAPER_SAVINGS_VS_30_PERCENT}%) | GPU bytes unified / sep-2 / sep-30 | bytes saved vs 2 / vs 30 |"
        );
        let _ = writeln!(md, "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
        for r in &self.results {
            let t = &r.table2;
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {:.1}% | {:.1}% | {} / {} / {} | {:.1}% / {:.1}% |",
                r.model,
                r.paper_model,
                r.layers,
                thousands(t.vertices),
                thousands(t.faces),
                thousands(t.fur_edges),
                thousands(t.unified_vertices),
                thousands(t.separated2_vertices),
                thousands(t.separated30_vertices),
                t.savings_vs_2_percent,
                t.savings_vs_30_percent,
                kib(t.unified_bytes),
                kib(t.separated2_bytes),
                kib(t.separated30_bytes),
                t.bytes_savings_vs_2_percent,
                t.bytes_savings_vs_30_percent,
            );
        }
        let _ = writeln!(md, "\nThe paper's Table 2 (GeForce 8800 GTX, L = 16), for comparison:\n");
        let _ = writeln!(
            md,
            "| model | vertices | faces | unified (shared) | separated, 2-face fins | separated, 30-face fins | fps |"
        );
        let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|");
        for (model, v, f, unified, two, thirty, fps) in PAPER_TABLE_2 {
            let _ = writeln!(md, "| {model} | {v} | {f} | {unified} | {two} | {thirty} | {fps} |");
        }

        let _ = writeln!(md, "\n### Frame time (median ms, GPU work waited for)\n");
        let _ = writeln!(
            md,
            "| model | L | unified 1280x720 | sep-2 1280x720 | sep-30 1280x720 | unified 256x256 | sep-2 256x256 | sep-30 256x256 | upload of the shared array | fin edges drawn (unified) | frames |"
        );
        let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|");
        for r in &self.results {
            let f = &r.render;
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} | {} | {} | {} |",
                r.model,
                r.layers,
                ms(f.frame_ms_unified_1280x720),
                ms(f.frame_ms_separated2_1280x720),
                ms(f.frame_ms_separated30_1280x720),
                ms(f.frame_ms_unified_256x256),
                ms(f.frame_ms_separated2_256x256),
                ms(f.frame_ms_separated30_256x256),
                ms(f.upload_ms_per_frame),
                f.fin_edges_drawn.map_or_else(
                    || "-".to_owned(),
                    |n| format!("{} of {}", thousands(n), thousands(r.table2.fur_edges))
                ),
                f.render_frames.map_or_else(|| "-".to_owned(), |n| n.to_string()),
            );
        }
        notes(&mut md, self.results.iter().map(|r| (r, r.render.render_unavailable_reason.as_deref())));

        if self.results.iter().any(|r| r.render.frame_ms_unified_shadows_1280x720.is_some()) {
            let _ = writeln!(md, "\n### Shadows (unified, median ms, timed in turn with the table above)\n");
            let _ = writeln!(md, "| model | L | 1280x720 | with shadows | ratio | 256x256 | with shadows | ratio |");
            let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|");
            let ratio = |with: Option<f64>, without: Option<f64>| match (with, without) {
                (Some(with), Some(without)) if without > 0.0 => format!("{:.2}x", with / without),
                _ => "-".to_owned(),
            };
            for r in &self.results {
                let f = &r.render;
                let _ = writeln!(
                    md,
                    "| {} | {} | {} | {} | {} | {} | {} | {} |",
                    r.model,
                    r.layers,
                    ms(f.frame_ms_unified_1280x720),
                    ms(f.frame_ms_unified_shadows_1280x720),
                    ratio(f.frame_ms_unified_shadows_1280x720, f.frame_ms_unified_1280x720),
                    ms(f.frame_ms_unified_256x256),
                    ms(f.frame_ms_unified_shadows_256x256),
                    ratio(f.frame_ms_unified_shadows_256x256, f.frame_ms_unified_256x256),
                );
            }
        }

        if self.results.iter().any(|r| !r.render.lod.is_empty()) {
            let _ = writeln!(md, "\n### Level of detail (unified, median ms; the table above draws every shell)\n");
            let _ = writeln!(
                md,
                "| model | L | size | level, default framing | LOD off | LOD on | triangles off / on | level, 4x distance | LOD off, 4x | LOD on, 4x | triangles off / on, 4x |"
            );
            let _ = writeln!(md, "|---|---:|---|---|---:|---:|---:|---|---:|---:|---:|");
            for r in &self.results {
                for f in &r.render.lod {
                    let _ = writeln!(
                        md,
                        "| {} | {} | {} | {} | {} | {} | {} / {} | {} | {} | {} | {} / {} |",
                        r.model,
                        r.layers,
                        f.size,
                        f.level_near,
                        ms(Some(f.frame_ms_near_full)),
                        ms(Some(f.frame_ms_near_lod)),
                        thousands(f.triangles_near_full),
                        thousands(f.triangles_near_lod),
                        f.level_far,
                        ms(Some(f.frame_ms_far_full)),
                        ms(Some(f.frame_ms_far_lod)),
                        thousands(f.triangles_far_full),
                        thousands(f.triangles_far_lod),
                    );
                }
            }
        }

        if self.results.iter().any(|r| !r.render.extra_sizes.is_empty()) {
            let _ = writeln!(
                md,
                "\n### Frames per second at other sizes (frames submitted back to back, two in flight; median ms with each frame waited for in brackets)\n"
            );
            let _ = writeln!(
                md,
                "| model | L | size | unified | sep-2 | sep-30 | unified, LOD on (level) | frames a run | the paper's fps (its Table 2, L = 16, GeForce 8800 GTX) |"
            );
            let _ = writeln!(md, "|---|---:|---|---:|---:|---:|---:|---:|---:|");
            for r in &self.results {
                let paper_fps =
                    PAPER_TABLE_2.iter().find(|row| row.0 == r.paper_model && r.layers == 16).map_or("-", |row| row.6);
                for f in &r.render.extra_sizes {
                    let lod = match (&f.level, f.fps_unified_lod) {
                        (Some(level), Some(fps)) => format!("{} ({level})", fps_text(fps)),
                        _ => "-".to_owned(),
                    };
                    let _ = writeln!(
                        md,
                        "| {} | {} | {} | {} ({}) | {} ({}) | {} ({}) | {lod} | {} | {paper_fps} |",
                        r.model,
                        r.layers,
                        f.size,
                        fps_text(f.fps_unified),
                        ms(Some(f.frame_ms_unified)),
                        fps_text(f.fps_separated2),
                        ms(Some(f.frame_ms_separated2)),
                        fps_text(f.fps_separated30),
                        ms(Some(f.frame_ms_separated30)),
                        f.fps_frames,
                    );
                }
            }
        }

        let _ = writeln!(md, "\n### Simulation (CPU) and texture generation\n");
        let _ = writeln!(
            md,
            "| model | L | node updates/s, 1 thread | node updates/s, all threads | literal O(L^2), 1 thread | CPU ms per drawn frame, 30 Hz sim + interpolation | CPU ms per drawn frame, sim every frame | texture generation ms |"
        );
        let _ = writeln!(md, "|---|---:|---:|---:|---:|---:|---:|---:|");
        for r in &self.results {
            let s = &r.sim;
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | {} | {} | {} | {} |",
                r.model,
                r.layers,
                rate(s.sim_node_updates_per_sec),
                rate(s.sim_node_updates_per_sec_all_threads),
                rate(s.sim_literal_node_updates_per_sec),
                ms(s.sim_cpu_ms_per_frame_interpolated),
                ms(s.sim_cpu_ms_per_frame_every_frame),
                ms(r.texture.texture_generation_ms),
            );
        }
        let _ = writeln!(md, "\nSimulation kernel: {}.", self.sim_cpu_kernel);
        if let Some(large) = &self.sim_large_mesh {
            let _ = writeln!(
                md,
                "Large mesh ({}, {} vertices, L = {}): {} node updates/s on 1 thread, {} on all threads, {} on the GPU.",
                large.mesh,
                thousands(large.vertices),
                large.layers,
                rate(Some(large.sim_node_updates_per_sec)),
                rate(Some(large.sim_node_updates_per_sec_all_threads)),
                rate(large.gpu_sim_node_updates_per_sec),
            );
        }
        notes(
            &mut md,
            self.results.iter().flat_map(|r| {
                [(r, r.sim.sim_unavailable_reason.as_deref()), (r, r.texture.texture_unavailable_reason.as_deref())]
            }),
        );
        self.gpu_sim_markdown(&mut md);
        self.anim_markdown(&mut md);
        md
    }

    /// The animated models' CPU cost per frame: posing (skinning) and the simulation following it.
    fn anim_markdown(&self, md: &mut String) {
        let animated: Vec<&ResultRow> = self.results.iter().filter(|r| r.anim.anim_clip.is_some()).collect();
        if animated.is_empty() {
            return;
        }
        let _ =
            writeln!(md, "\n### Animated models (CPU per frame at 30 Hz; the GPU's part is the frame time above)\n");
        let _ = writeln!(md, "| model | L | animation | pose (skinning) ms | simulation ms | CPU ms per frame |");
        let _ = writeln!(md, "|---|---:|---|---:|---:|---:|");
        for r in animated {
            let a = &r.anim;
            let clip = a.anim_clip.as_deref().unwrap_or("-");
            let (pose, sim, cpu) =
                (ms(a.anim_pose_ms_per_frame), ms(a.anim_sim_ms_per_frame), ms(a.anim_cpu_ms_per_frame));
            let _ = writeln!(md, "| {} | {} | {clip} | {pose} | {sim} | {cpu} |", r.model, r.layers);
        }
    }

    /// The GPU simulation's table: which kernel ran where, and how fast.
    fn gpu_sim_markdown(&self, md: &mut String) {
        let adapter =
            self.adapter.as_ref().map_or_else(|| "no adapter".to_owned(), |a| format!("{} ({})", a.name, a.backend));
        let _ = writeln!(md, "\n### Simulation on the GPU (compute pass on {adapter})\n");
        let _ = writeln!(
            md,
            "| model | L | node updates/s | steps per timed run | CPU ms per drawn frame, GPU sim at 30 Hz |"
        );
        let _ = writeln!(md, "|---|---:|---:|---:|---:|");
        for r in &self.results {
            let g = &r.gpu_sim;
            let steps = g.gpu_sim_steps_per_run.map_or_else(|| "-".to_owned(), |n| n.to_string());
            let (updates, cpu) = (rate(g.gpu_sim_node_updates_per_sec), ms(g.gpu_sim_cpu_ms_per_frame));
            let _ = writeln!(md, "| {} | {} | {updates} | {steps} | {cpu} |", r.model, r.layers);
        }
        notes(md, self.results.iter().map(|r| (r, r.gpu_sim.gpu_sim_unavailable_reason.as_deref())));
    }
}

/// Lists why figures are missing, each reason once, with the rows it applies to.
fn notes<'a>(md: &mut String, reasons: impl Iterator<Item = (&'a ResultRow, Option<&'a str>)>) {
    let mut grouped: Vec<(&str, Vec<String>)> = Vec::new();
    for (row, reason) in reasons {
        let Some(reason) = reason else { continue };
        let label = format!("{} L={}", row.model, row.layers);
        match grouped.iter_mut().find(|(r, _)| *r == reason) {
            Some((_, rows)) if !rows.contains(&label) => rows.push(label),
            Some(_) => {}
            None => grouped.push((reason, vec![label])),
        }
    }
    if !grouped.is_empty() {
        md.push('\n');
    }
    for (reason, rows) in grouped {
        let _ = writeln!(md, "- not measured ({}): {reason}", rows.join(", "));
    }
}

fn ms(value: Option<f64>) -> String {
    value.map_or_else(|| "-".to_owned(), |v| if v < 1.0 { format!("{v:.3}") } else { format!("{v:.2}") })
}

fn fps_text(fps: f64) -> String {
    if fps < 10.0 { format!("{fps:.2}") } else { format!("{fps:.0}") }
}

fn rate(value: Option<f64>) -> String {
    value.map_or_else(|| "-".to_owned(), |v| format!("{:.1} M", v / 1e6))
}

fn kib(bytes: u64) -> String {
    format!("{:.1} KiB", bytes as f64 / 1024.0)
}

fn mib(bytes: u64) -> String {
    format!("{:.1} MiB", bytes as f64 / (1024.0 * 1024.0))
}

fn gib(bytes: u64) -> String {
    format!("{:.1} GiB", bytes as f64 / (1024.0 * 1024.0 * 1024.0))
}
