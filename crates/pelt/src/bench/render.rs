//! Frame time of the unified structure against the separated one (2-face and 30-face fins) on
//! the same scene, on whatever adapter is found.

use std::time::{Duration, Instant};

use anyhow::Context as _;
use pelt_core::texture::FurTextures;
use pelt_core::{FurStructure, Mesh};
use pelt_render::{
    Backend, Camera, DEFAULT_BACKGROUND, FurDrawSettings, FurFrame, FurRenderer, FurStates, FurTarget, FurView, Gpu,
    GpuFur, HEADLESS_FORMAT, PlainMesh, RenderTargets, SeparatedFur, SeparatedRenderer, Surroundings,
    default_sample_count,
};

use super::report::{Adapter, GpuSimFigures, LodFigures, RenderFigures, SizeFigures};
use super::table2::MANY_FIN_FACES;
use crate::render::PLAIN_COLOUR;

/// The two frame sizes: a typical window and a small one where vertex work dominates.
pub const SIZES: [(u32, u32); 2] = [(1280, 720), (256, 256)];

/// Frames a game loop keeps in flight (a swapchain's usual depth): the frames-per-second
/// measurement waits for frame `n - FRAMES_IN_FLIGHT` before it submits frame `n`.
const FRAMES_IN_FLIGHT: usize = 2;

/// About how long one structure's frames-per-second run lasts, and its frame count's bounds.
const FPS_RUN_SECS: f64 = 0.4;
const FPS_FRAMES: std::ops::RangeInclusive<u32> = 3..=240;
const FPS_ROUNDS: usize = 3;

/// How many frames each median is taken over.
#[derive(Clone, Copy, Debug)]
pub struct RenderBudget {
    /// Frames drawn and thrown away first (pipeline compilation, first uploads).
    pub warmup_frames: u32,
    pub min_frames: u32,
    pub max_frames: u32,
    /// Stop after `min_frames` once this much time is spent on one structure at one size.
    pub max_secs_per_case: f64,
}

/// A GPU opened once for the whole run.
#[derive(Debug)]
pub struct Bench {
    gpu: Gpu,
    /// The lights every timed frame is drawn with (`--light`, `--environment`).
    studio: pelt_render::Studio,
}

impl Bench {
    /// Opens the best adapter (`WGPU_BACKEND` chooses the API when set).
    pub fn open(studio: pelt_render::Studio) -> anyhow::Result<Self> {
        Ok(Self { gpu: Gpu::new(Backend::Auto)?, studio })
    }

    pub fn adapter(&self) -> Adapter {
        let info = self.gpu.adapter.get_info();
        let msaa_samples = default_sample_count(&info);
        Adapter {
            msaa_samples,
            name: info.name,
            backend: format!("{:?}", info.backend),
            device_type: format!("{:?}", info.device_type),
            driver: format!("{} {}", info.driver, info.driver_info).trim().to_owned(),
        }
    }

    /// The GPU simulation's node updates per second on `fur` under `params` with wind (so the
    /// noise is evaluated, as in a windy scene): the median of `runs` runs of `steps` steps
    /// (`pelt_render::gpu_secs_per_step`, through the driver `--sim gpu` runs); and the CPU cost
    /// per drawn frame over `drawn_frames` frames at 120 Hz with the simulation at 30 Hz.
    pub fn measure_simulation(
        &self,
        fur: &FurStructure,
        params: &pelt_core::sim::SimParams,
        steps: u32,
        runs: usize,
        drawn_frames: u32,
    ) -> anyhow::Result<GpuSimFigures> {
        let updates_per_sec = self.node_updates_per_sec(fur, params, steps, runs)?;
        let (device, queue) = (&self.gpu.device, &self.gpu.queue);
        let mut windy = windy(params);
        windy.rate_hz = super::sim::SIM_RATE_HZ;
        let cpu_ms = crate::sim_kernel::gpu_cpu_ms_per_drawn_frame(
            device,
            queue,
            fur,
            &windy,
            super::sim::DRAW_RATE_HZ,
            drawn_frames,
        )?;
        Ok(GpuSimFigures {
            gpu_sim_node_updates_per_sec: Some(updates_per_sec),
            gpu_sim_steps_per_run: Some(steps),
            gpu_sim_cpu_ms_per_frame: Some(cpu_ms),
            gpu_sim_unavailable_reason: None,
        })
    }

    /// The GPU kernel's node updates per second on `fur` under `params` with wind (the figure
    /// `measure_simulation` reports, alone): the median of `runs` runs of `steps` steps.
    pub fn node_updates_per_sec(
        &self,
        fur: &FurStructure,
        params: &pelt_core::sim::SimParams,
        steps: u32,
        runs: usize,
    ) -> anyhow::Result<f64> {
        let renderer = crate::sim_kernel::timing_renderer(&self.gpu.device)?;
        let secs = pelt_render::gpu_secs_per_step(
            &self.gpu.device,
            &self.gpu.queue,
            &renderer,
            fur,
            &windy(params),
            steps,
            runs,
        )?;
        Ok(fur.vertex_count() as f64 * f64::from(fur.layers) / secs)
    }

    /// Median frame times of the three structures at both sizes, each drawing the same scene:
    /// the fur and, for the try-on model, the plain `body` under it; at `extra_sizes` also
    /// frames per second (`SizeFigures`). With `shadows`, the unified fur is also timed with the
    /// key light's shadow maps (interleaved with the rest, at the two standard sizes). Every fur
    /// draws in `look` (the preset's).
    #[allow(clippy::too_many_arguments)]
    pub fn measure(
        &self,
        fur: &FurStructure,
        body_mesh: Option<&Mesh>,
        textures: &FurTextures,
        budget: RenderBudget,
        lod: pelt_render::LodSettings,
        extra_sizes: &[(u32, u32)],
        (shadows, look): (bool, pelt_render::FurLook),
    ) -> anyhow::Result<RenderFigures> {
        let (device, queue) = (&self.gpu.device, &self.gpu.queue);
        // The samples `pelt render` and the viewer use on this adapter.
        let samples = default_sample_count(&self.gpu.adapter.get_info());
        let target = FurTarget::new(HEADLESS_FORMAT).with_sample_count(samples);
        let renderer = FurRenderer::new(device, target).context("building the unified renderer")?;
        let separated_renderer =
            SeparatedRenderer::new(device, &renderer).context("building the separated renderer")?;
        // One state, uploaded per frame, as `pelt render` and the viewer draw it.
        let unified = GpuFur::new(device, queue, &renderer, fur, textures, FurStates::One)
            .context("uploading the unified structure")?;
        let separated2 = SeparatedFur::new(device, queue, &renderer, fur, textures, 2)
            .context("building the separated structure (2-face fins)")?;
        let separated30 = SeparatedFur::new(device, queue, &renderer, fur, textures, MANY_FIN_FACES)
            .context("building the separated structure (30-face fins)")?;
        // Every structure in the preset's look.
        let base = FurFrame { look, ..FurFrame::default() };
        unified.prepare(queue, &base);
        separated2.prepare(queue, &base);
        separated30.prepare(queue, &base);
        let body = body_mesh.map(|body| PlainMesh::new(device, &renderer, body, PLAIN_COLOUR)).transpose()?;
        if let Some(body) = &body {
            body.prepare(queue, glam::Mat4::IDENTITY);
        }
        let view = FurView::new(device, &renderer);
        // What `pelt render` and the viewer draw: the unified fur with the silhouette pass (the
        // separated structures draw their fins as geometry and ignore it).
        let settings = FurDrawSettings::SILHOUETTE;
        // Frame the whole scene: the body where there is one (the garment sits on it).
        let (centre, radius) = body_mesh.map_or_else(|| fur.mesh.bounding_sphere(), Mesh::bounding_sphere);
        let radius = radius + fur.lengths.iter().copied().fold(0.0, f32::max);
        // The shadowed case: the key light's maps as `pelt render --shadows` draws them.
        let plain: Vec<Mesh> = body_mesh.into_iter().cloned().collect();
        let mut surroundings = shadows
            .then(|| Surroundings::new(device, queue, &renderer, true, None, (fur, &plain)))
            .transpose()
            .context("making the shadow maps")?;
        let mut shadowed_view = FurView::new(device, &renderer);

        let mut medians = [[0.0; 3]; SIZES.len()];
        let mut shadowed_medians = [None; SIZES.len()];
        let mut frames_measured = u32::MAX;
        let mut fin_edges_drawn = None;
        let mut lod_figures = Vec::new();
        let mut size_figures = Vec::new();
        for (index, (width, height)) in SIZES.into_iter().chain(extra_sizes.iter().copied()).enumerate() {
            let targets = RenderTargets::new(device, target, width, height)?;
            let output = device.create_texture(&wgpu_output_descriptor(width, height));
            let output_view = output.create_view(&Default::default());
            let camera = Camera::framing(centre, radius, 35.0, 20.0, targets.aspect_ratio());
            let view_data = self.studio.view_data(&camera, targets.aspect_ratio());
            if let Some(surroundings) = &mut surroundings {
                surroundings.fit_to_frame(device, &renderer, (width, height))?;
                surroundings.prepare((device, queue), &renderer, &view_data, &mut shadowed_view)?;
            }
            // Every structure draws the same scene the same way: the view written, the body
            // (if any), then the fur, in one pass.
            let frame = |encoder: &mut wgpu::CommandEncoder,
                         before: &dyn Fn(&mut wgpu::CommandEncoder),
                         draw_fur: &dyn Fn(&mut wgpu::RenderPass<'_>)| {
                view.prepare(queue, &view_data);
                before(encoder);
                let mut pass = targets.begin_pass(encoder, &output_view, DEFAULT_BACKGROUND);
                if let Some(body) = &body {
                    renderer.draw_plain(&mut pass, &view, body);
                }
                draw_fur(&mut pass);
            };
            let shadowed = |encoder: &mut wgpu::CommandEncoder| {
                let Some(surroundings) = &surroundings else { return };
                shadowed_view.prepare(queue, &view_data);
                surroundings.record(encoder, |pass, light| {
                    if let Some(body) = &body {
                        renderer.draw_plain(pass, light, body);
                    }
                    renderer.draw(pass, light, &unified, &settings);
                });
                renderer.prepare_fins(encoder, &shadowed_view, &unified);
                let mut pass = targets.begin_pass(encoder, &output_view, DEFAULT_BACKGROUND);
                if let Some(body) = &body {
                    renderer.draw_plain(&mut pass, &shadowed_view, body);
                }
                renderer.draw(&mut pass, &shadowed_view, &unified, &settings);
            };
            let cases: [&dyn Fn(&mut wgpu::CommandEncoder); 4] = [
                &|encoder| {
                    let silhouette =
                        |encoder: &mut wgpu::CommandEncoder| renderer.prepare_fins(encoder, &view, &unified);
                    frame(encoder, &silhouette, &|pass| renderer.draw(pass, &view, &unified, &settings));
                },
                &|encoder| {
                    frame(encoder, &|_| {}, &|pass| separated_renderer.draw(pass, &view, &separated2, &settings))
                },
                &|encoder| {
                    frame(encoder, &|_| {}, &|pass| separated_renderer.draw(pass, &view, &separated30, &settings))
                },
                &shadowed,
            ];
            // Frame by frame in turn, so the machine's slow spells (10-20% on a shared VM) fall
            // on the three structures (and the shadowed fur) alike and their ratios hold.
            let timed_cases = if surroundings.is_some() && index < SIZES.len() { &cases[..] } else { &cases[..3] };
            let times = self.time_interleaved(timed_cases, budget)?;
            let cases = &cases[..3];
            let Some(row) = medians.get_mut(index) else {
                // A `--size`: the medians, then frames per second, the unified fur also at its
                // level of detail for this framing (as `pelt render` and the viewer draw it).
                let [unified_ms, separated2_ms, separated30_ms] = [0, 1, 2].map(|case| median_ms(&times[case]));
                let slowest_ms = unified_ms.max(separated2_ms).max(separated30_ms);
                let frames =
                    ((FPS_RUN_SECS * 1000.0 / slowest_ms).ceil() as u32).clamp(*FPS_FRAMES.start(), *FPS_FRAMES.end());
                let [fps_unified, fps_separated2, fps_separated30] =
                    <[f64; 3]>::try_from(self.frames_per_second(cases, frames)?).expect("one rate per case");
                let (level, fps_unified_lod) = if lod.enabled {
                    let level = crate::lod::level(&lod, fur, camera.eye, camera.fov_y_rad, height);
                    unified.prepare(queue, &FurFrame { level, ..base });
                    let fps = self.frames_per_second(&cases[..1], frames);
                    unified.prepare(queue, &base);
                    (Some(level.describe(fur.layers)), Some(fps?[0]))
                } else {
                    (None, None)
                };
                size_figures.push(SizeFigures {
                    size: format!("{width}x{height}"),
                    frame_ms_unified: unified_ms,
                    frame_ms_separated2: separated2_ms,
                    frame_ms_separated30: separated30_ms,
                    fps_unified,
                    fps_separated2,
                    fps_separated30,
                    level,
                    fps_unified_lod,
                    fps_frames: frames,
                });
                continue;
            };
            for (times, median) in times.iter().zip(row.iter_mut()) {
                frames_measured = frames_measured.min(times.len() as u32);
                *median = median_ms(times);
            }
            shadowed_medians[index] = times.get(3).map(|times| median_ms(times));
            if lod.enabled {
                // The unified fur alone (as above) at its level of detail, near and at 4x the
                // distance, then far with every shell; the counts from the silhouette pass.
                let far_camera = Camera { eye: centre + (camera.eye - centre) * 4.0, ..camera };
                let far_view = self.studio.view_data(&far_camera, targets.aspect_ratio());
                let level = |camera: &Camera| crate::lod::level(&lod, fur, camera.eye, camera.fov_y_rad, height);
                let (near_level, far_level) = (level(&camera), level(&far_camera));
                let timed = |view_data: &pelt_render::ViewData, level: pelt_render::FurLevel| {
                    unified.prepare(queue, &FurFrame { level, ..base });
                    let record = |encoder: &mut wgpu::CommandEncoder| {
                        view.prepare(queue, view_data);
                        renderer.prepare_fins(encoder, &view, &unified);
                        let mut pass = targets.begin_pass(encoder, &output_view, DEFAULT_BACKGROUND);
                        if let Some(body) = &body {
                            renderer.draw_plain(&mut pass, &view, body);
                        }
                        renderer.draw(&mut pass, &view, &unified, &settings);
                    };
                    let times = self.time_frames(&record, budget)?;
                    let triangles = self.triangles_drawn(fur, &unified)?;
                    anyhow::Ok((median_ms(&times), triangles))
                };
                let (near_full_ms, near_full_triangles) = timed(&view_data, pelt_render::FurLevel::FULL)?;
                let (near_ms, near_triangles) = timed(&view_data, near_level)?;
                let (far_lod_ms, far_lod_triangles) = timed(&far_view, far_level)?;
                let (far_full_ms, far_full_triangles) = timed(&far_view, pelt_render::FurLevel::FULL)?;
                unified.prepare(queue, &base);
                lod_figures.push(LodFigures {
                    size: format!("{width}x{height}"),
                    level_near: near_level.describe(fur.layers),
                    frame_ms_near_full: near_full_ms,
                    frame_ms_near_lod: near_ms,
                    triangles_near_full: near_full_triangles,
                    triangles_near_lod: near_triangles,
                    level_far: far_level.describe(fur.layers),
                    frame_ms_far_full: far_full_ms,
                    frame_ms_far_lod: far_lod_ms,
                    triangles_far_full: far_full_triangles,
                    triangles_far_lod: far_lod_triangles,
                });
            }
            if fin_edges_drawn.is_none() {
                // The first size: the silhouette pass's count from the last unified frame.
                if let Some(draw) = unified.silhouette_draw() {
                    self.time_frames(
                        cases[0],
                        RenderBudget { warmup_frames: 0, min_frames: 1, max_frames: 1, ..budget },
                    )?;
                    fin_edges_drawn = Some(u64::from(self.read_u32(draw, 1)?));
                }
            }
        }
        // The per-frame upload an animated unified fur adds: the whole shared vertex array.
        unified.set_positions(queue, &fur.positions)?;
        let upload_times =
            self.time_frames(&|_| unified.set_positions(queue, &fur.positions).expect("checked just above"), budget)?;
        let [[u_large, s2_large, s30_large], [u_small, s2_small, s30_small]] = medians;
        let [shadowed_large, shadowed_small] = shadowed_medians;
        Ok(RenderFigures {
            frame_ms_unified_1280x720: Some(u_large),
            frame_ms_separated2_1280x720: Some(s2_large),
            frame_ms_separated30_1280x720: Some(s30_large),
            frame_ms_unified_256x256: Some(u_small),
            frame_ms_separated2_256x256: Some(s2_small),
            frame_ms_separated30_256x256: Some(s30_small),
            frame_ms_unified_shadows_1280x720: shadowed_large,
            frame_ms_unified_shadows_256x256: shadowed_small,
            render_frames: Some(frames_measured),
            fin_edges_drawn,
            upload_ms_per_frame: Some(median_ms(&upload_times)),
            lod: lod_figures,
            extra_sizes: size_figures,
            render_unavailable_reason: None,
        })
    }

    /// Records, submits and waits for frames one at a time: each time is one frame's CPU
    /// recording plus all of its GPU work.
    fn time_frames(
        &self,
        record: &dyn Fn(&mut wgpu::CommandEncoder),
        budget: RenderBudget,
    ) -> anyhow::Result<Vec<Duration>> {
        let device = &self.gpu.device;
        let frame = || -> anyhow::Result<Duration> {
            let started = Instant::now();
            let mut encoder = device.create_command_encoder(&Default::default());
            record(&mut encoder);
            self.gpu.queue.submit([encoder.finish()]);
            device.poll(wgpu::PollType::wait_indefinitely()).context("waiting for the GPU")?;
            Ok(started.elapsed())
        };
        for _ in 0..budget.warmup_frames {
            frame()?;
        }
        let started = Instant::now();
        let mut times = Vec::new();
        while times.len() < budget.max_frames as usize
            && (times.len() < budget.min_frames as usize || started.elapsed().as_secs_f64() < budget.max_secs_per_case)
        {
            times.push(frame()?);
        }
        Ok(times)
    }
}

impl Bench {
    /// [`Bench::time_frames`] for several cases at once, one frame of each in turn (after each
    /// one's warm-up), for `budget`'s frames or time per case: one list of times per case.
    fn time_interleaved(
        &self,
        cases: &[&dyn Fn(&mut wgpu::CommandEncoder)],
        budget: RenderBudget,
    ) -> anyhow::Result<Vec<Vec<Duration>>> {
        let one = RenderBudget { warmup_frames: 0, min_frames: 1, max_frames: 1, ..budget };
        for case in cases {
            for _ in 0..budget.warmup_frames {
                self.time_frames(case, one)?;
            }
        }
        let started = Instant::now();
        let mut times = vec![Vec::new(); cases.len()];
        let seconds = budget.max_secs_per_case * cases.len() as f64;
        let mut rounds = 0;
        while rounds < budget.max_frames && (rounds < budget.min_frames || started.elapsed().as_secs_f64() < seconds) {
            for (case, times) in cases.iter().zip(&mut times) {
                times.extend(self.time_frames(case, one)?);
            }
            rounds += 1;
        }
        Ok(times)
    }

    /// Frames per second of each case as a game loop draws them: `frames` frames recorded and
    /// submitted back to back, at most `FRAMES_IN_FLIGHT` unfinished, the last waited for; the
    /// cases in turn for `FPS_ROUNDS` rounds, each case's median round. Whichever of the CPU's
    /// recording and submission or the GPU's work is slower sets the rate, as in an app.
    fn frames_per_second(&self, cases: &[&dyn Fn(&mut wgpu::CommandEncoder)], frames: u32) -> anyhow::Result<Vec<f64>> {
        let device = &self.gpu.device;
        let run = |record: &dyn Fn(&mut wgpu::CommandEncoder)| -> anyhow::Result<f64> {
            let started = Instant::now();
            let mut in_flight = std::collections::VecDeque::with_capacity(FRAMES_IN_FLIGHT + 1);
            for _ in 0..frames {
                if in_flight.len() == FRAMES_IN_FLIGHT {
                    let oldest = in_flight.pop_front();
                    let wait = wgpu::PollType::Wait { submission_index: oldest, timeout: None };
                    device.poll(wait).context("waiting for the GPU")?;
                }
                let mut encoder = device.create_command_encoder(&Default::default());
                record(&mut encoder);
                in_flight.push_back(self.gpu.queue.submit([encoder.finish()]));
            }
            device.poll(wgpu::PollType::wait_indefinitely()).context("waiting for the GPU")?;
            Ok(f64::from(frames) / started.elapsed().as_secs_f64())
        };
        // A first run of each unmeasured: its queue starts empty and its pipelines warm.
        for case in cases {
            run(case)?;
        }
        let mut rates = vec![Vec::with_capacity(FPS_ROUNDS); cases.len()];
        for _ in 0..FPS_ROUNDS {
            for (case, rates) in cases.iter().zip(&mut rates) {
                rates.push(run(case)?);
            }
        }
        Ok(rates
            .into_iter()
            .map(|mut rates| {
                rates.sort_by(f64::total_cmp);
                rates[rates.len() / 2]
            })
            .collect())
    }

    /// Triangles the last unified frame drew: the skin, the shells (those thinned by view angle
    /// over the triangles the view-angle pass listed) and the fins the silhouette pass kept, at
    /// the level `unified` was prepared with.
    fn triangles_drawn(&self, fur: &FurStructure, unified: &GpuFur) -> anyhow::Result<u64> {
        let faces = fur.mesh.triangles.len() as u64;
        let shells = u64::from(unified.drawn_shells());
        let fin_edges = match unified.silhouette_draw() {
            Some(draw) if unified.fins_drawn() => u64::from(self.read_u32(draw, 1)?),
            _ => 0,
        };
        let thinned = u64::from(unified.shells_thinned());
        let listed = match unified.view_lod_count() {
            Some(count) if thinned > 0 => u64::from(self.read_u32(count, 0)?) / 3,
            _ => 0,
        };
        Ok(faces * (1 + shells - thinned) + listed * thinned + fin_edges * 2 * shells)
    }

    /// Word `index` of a small range of a `COPY_SRC` buffer, read back (waits for the GPU).
    fn read_u32(&self, buffer: wgpu::BufferSlice<'_>, index: u64) -> anyhow::Result<u32> {
        let device = &self.gpu.device;
        let staging = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt bench readback"),
            size: 4,
            usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
            mapped_at_creation: false,
        });
        let mut encoder = device.create_command_encoder(&Default::default());
        encoder.copy_buffer_to_buffer(buffer.buffer(), buffer.offset() + 4 * index, &staging, 0, 4);
        self.gpu.queue.submit([encoder.finish()]);
        let (sender, receiver) = std::sync::mpsc::channel();
        staging.slice(..).map_async(wgpu::MapMode::Read, move |result| {
            // The receiver waits below.
            let _ = sender.send(result);
        });
        device.poll(wgpu::PollType::wait_indefinitely()).context("waiting for the GPU")?;
        receiver.recv().context("reading back")?.context("mapping the readback")?;
        let word = {
            let bytes = staging.slice(..).get_mapped_range().context("reading the readback")?;
            u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]])
        };
        staging.unmap();
        Ok(word)
    }
}

/// `params` with wind where it has none, so the kernel's timings include the noise it evaluates
/// in a windy scene.
fn windy(params: &pelt_core::sim::SimParams) -> pelt_core::sim::SimParams {
    let mut windy = params.clone();
    if windy.wind.strength == 0.0 {
        windy.wind.strength = 0.5;
    }
    windy
}

fn wgpu_output_descriptor(width: u32, height: u32) -> wgpu::TextureDescriptor<'static> {
    wgpu::TextureDescriptor {
        label: Some("pelt bench output"),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: 1 },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: HEADLESS_FORMAT,
        usage: wgpu::TextureUsages::RENDER_ATTACHMENT,
        view_formats: &[],
    }
}

/// The median of `times` in milliseconds (the mean of the middle two for an even count).
fn median_ms(times: &[Duration]) -> f64 {
    let mut ms: Vec<f64> = times.iter().map(|t| t.as_secs_f64() * 1000.0).collect();
    ms.sort_by(f64::total_cmp);
    let n = ms.len();
    if n == 0 {
        f64::NAN
    } else if n % 2 == 1 {
        ms[n / 2]
    } else {
        0.5 * (ms[n / 2 - 1] + ms[n / 2])
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_of_odd_and_even_counts() {
        let ms = |v: &[u64]| v.iter().map(|&m| Duration::from_millis(m)).collect::<Vec<_>>();
        assert!((median_ms(&ms(&[9, 1, 5])) - 5.0).abs() < 1e-9);
        assert!((median_ms(&ms(&[4, 1, 3, 100])) - 3.5).abs() < 1e-9);
        assert!(median_ms(&[]).is_nan());
    }
}
