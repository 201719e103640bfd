//! The viewer's state apart from the window: settings, the fur structure and its simulation, the
//! camera, timings and textures in the making, and how the panel's changes rebuild them.

use std::time::Instant;

use anyhow::Context as _;
use glam::Vec3;
use pelt_core::anim::{Pose, Rig};
use pelt_core::sim::{FurStepper, Scene};
use pelt_core::stage::StageBody;
use pelt_core::{Builtin, FurStructure, FurTextures, Mesh, Preset, PresetError, Stage, StageSource};

use super::Args;
use super::camera::OrbitCamera;
use super::herd::Herd;
use super::panel::{AnimationSettings, Changes, MeshChoice, Settings};
use pelt_render::SimKernel;

use crate::sim_kernel::SimChoice;

/// Time step of `--screenshot-after` runs, so they repeat exactly.
const FIXED_FRAME_SECS: f64 = 1.0 / 60.0;

/// Everything that is not the window: settings, fur, camera, timings.
pub(super) struct Model {
    pub(super) settings: Settings,
    pub(super) mesh_choices: Vec<MeshChoice>,
    /// The mesh from the command line, kept to switch back to.
    pub(super) file_mesh: Option<Mesh>,
    pub(super) structure: FurStructure,
    /// `structure`'s unified footprint, taken when it is grown (the overlay reads it every
    /// frame; counting a mesh's wedges is a pass over its corners).
    pub(super) footprint: pelt_core::fur::Footprint,
    /// The try-on scene's body, drawn without fur under the furry garment.
    pub(super) body: Option<Mesh>,
    /// GPU bytes of the unified structure as the renderer holds it.
    pub(super) unified_bytes: Option<u64>,
    /// `--no-lod`: every shell whatever the preset says.
    pub(super) no_lod: bool,
    /// The level of detail of the last frame drawn (the overlay shows it).
    pub(super) level: pelt_render::FurLevel,
    /// The share of shell triangles the last counted frame drew (view-angle LOD), if known.
    pub(super) shell_share: Option<f64>,
    /// GPU bytes of the separated structure while it is shown.
    pub(super) separated_bytes: Option<u64>,
    pub(super) camera: OrbitCamera,
    /// Frame the fur once the 3D view's size is known.
    pub(super) frame_pending: bool,
    /// Size of the 3D view in physical pixels, from the last panel pass.
    pub(super) viewport_px: [u32; 2],
    /// Where the 3D view's top-left corner lies in the window, in pixels.
    pub(super) viewport_origin_px: [u32; 2],
    pub(super) clock: Clock,
    pub(super) frame_time_secs: f64,
    /// The simulation with its posing (the file's clip) and script (`--script`: wind, touch
    /// strokes and motion, played on the simulation clock).
    pub(super) stepper: FurStepper,
    /// The command line's script, which the panel's rain and water are added to.
    pub(super) script: Option<Scene>,
    /// Simulation time: advances only while the simulation runs.
    pub(super) sim_clock_secs: f64,
    /// Smoothed cost of one `advance_to`.
    pub(super) sim_time_secs: f64,
    /// The frame and simulation times the overlay shows, and when they were taken from the live
    /// figures: twice a second, so that between edits egui's output, and with it the picture
    /// `UiLayer` keeps, stays the same.
    pub(super) shown_times_secs: [f64; 2],
    pub(super) shown_at: Option<Instant>,
    /// `--sim`, resolved once the GPU is open.
    pub(super) sim_choice: SimChoice,
    /// How a herd's copies share the GPU's work (`--pooling`).
    pub(super) pooling: crate::herd::Pooling,
    /// Why the kernel in use was chosen (the overlay shows it).
    pub(super) kernel_reason: String,
    pub(super) touch: Option<TouchDrag>,
    /// The ball or the grab being dragged.
    pub(super) contact_drag: Option<super::contact::ContactDrag>,
    /// The groom being painted (the structure's groom, with its strokes' history).
    pub(super) groom_editor: pelt_core::groom::GroomEditor,
    /// A paint stroke is in progress.
    pub(super) painting: bool,
    /// A stroke regrew the structure: the GPU's vertex buffers are to be replaced.
    pub(super) structure_regrown: bool,
    /// A stroke changed density, clump or tint: the GPU's per-vertex groom is to be updated.
    pub(super) groom_attributes_changed: bool,
    /// Wind strength W restores after turning the wind off.
    pub(super) wind_strength_on: f32,
    /// Textures made and not yet uploaded.
    pub(super) textures: Option<FurTextures>,
    /// Texture generation runs off the UI thread, so sliders stay smooth.
    pub(super) texture_job: Option<std::thread::JoinHandle<Result<FurTextures, PresetError>>>,
    /// The preset changed while a job ran: start another when it ends.
    pub(super) textures_stale: bool,
    pub(super) frames_drawn: u32,
    pub(super) skipped_frames: u32,
    pub(super) screenshots_saved: u32,
    pub(super) screenshot_pending: bool,
    pub(super) quit: bool,
    pub(super) panel_hidden: bool,
    pub(super) status: String,
    /// The command line's file's rig, when it moves (the stepper plays it while that file's
    /// mesh is shown).
    pub(super) rig: Option<Rig>,
    /// While the try-on is shown: the skirt's rig and the walking body's, with the body's pose.
    pub(super) walking: Option<(Rig, StageBody, Pose)>,
    /// A herd (`--herd N`, the script's `[[instance]]`s): this fur is its first member.
    pub(super) herd: Option<Herd>,
    /// How many of the herd's members the last frame drew.
    pub(super) herd_in_view: usize,
}

/// The panel's clips for `rig`: the first one playing.
fn animation_settings(rig: Option<&Rig>) -> AnimationSettings {
    let Some(rig) = rig else { return AnimationSettings::default() };
    let clips: Vec<(String, f32)> = rig
        .animations()
        .iter()
        .enumerate()
        .map(|(k, a)| (a.name.clone().unwrap_or_else(|| format!("animation {k}")), a.duration_secs()))
        .collect();
    let clip = (!clips.is_empty()).then_some(0);
    AnimationSettings { clips, clip, playing: true, speed: 1.0, time_secs: 0.0 }
}

/// Wall-clock time, or exactly `FIXED_FRAME_SECS` per frame for repeatable runs.
pub(super) struct Clock {
    pub(super) fixed: bool,
    pub(super) last: Instant,
}

impl Clock {
    /// `(wall seconds since the previous tick, seconds the scene advances)`.
    pub(super) fn tick(&mut self) -> (f64, f64) {
        let now = Instant::now();
        let wall_secs = (now - self.last).as_secs_f64();
        self.last = now;
        // A long stall (a dragged window, a breakpoint) should not fast-forward the scene.
        (wall_secs, if self.fixed { FIXED_FRAME_SECS } else { wall_secs.min(0.25) })
    }
}

/// A touch in progress: the pointer drags the hit point across the plane facing the camera.
#[derive(Clone, Copy, Debug)]
pub(super) struct TouchDrag {
    pub(super) hit: Vec3,
    pub(super) plane_normal: Vec3,
}

impl Model {
    /// The model for `args`, with `stage` loaded from its mesh arguments.
    pub(super) fn new(args: &Args, stage: Stage) -> anyhow::Result<Self> {
        let mut mesh_choices: Vec<MeshChoice> = Builtin::ALL.into_iter().map(MeshChoice::Builtin).collect();
        mesh_choices.push(MeshChoice::TryOn);
        let Stage { fur_mesh: mesh, report, mut rig, plain, body } = stage;
        let choice = match args.mesh.source(Builtin::Bunny)? {
            StageSource::File(path) => {
                let name = path.file_name().map_or(report.source, |n| n.to_string_lossy().into_owned());
                mesh_choices.push(MeshChoice::File(name.clone()));
                MeshChoice::File(name)
            }
            StageSource::Builtin(builtin) => MeshChoice::Builtin(builtin),
            StageSource::TryOn => MeshChoice::TryOn,
        };
        let file_mesh = matches!(choice, MeshChoice::File(_)).then(|| mesh.clone());
        let choice_is_try_on = choice == MeshChoice::TryOn;
        let (preset, preset_path) = match &args.preset {
            Some(path) => (Preset::load(path)?, path.display().to_string()),
            None => (Preset::default(), "fur.toml".to_owned()),
        };
        let default_camera = OrbitCamera::default();
        let camera = OrbitCamera {
            yaw_rad: preset.render.camera_azimuth_deg.map_or(default_camera.yaw_rad, f32::to_radians),
            pitch_rad: preset.render.camera_elevation_deg.map_or(default_camera.pitch_rad, f32::to_radians),
            ..default_camera
        };
        let mut settings = Settings::new(choice, preset, preset_path);
        settings.overlay = !args.no_overlay;
        settings.draw.ground = args.shadows.ground;
        settings.draw.shadows = !args.shadows.no_shadows;
        settings.lights = super::lights::LightSettings::from_args(&args.lights)?;
        settings.animation = animation_settings(rig.as_ref());
        let structure = grow(mesh, &settings.preset, &settings.mesh)?;
        let mut stepper = FurStepper::new(&structure, &settings.preset.simulation)?;
        // The first textures are made before the window opens, so the first frame has them.
        let textures = settings.preset.generate_textures()?;
        let scene = match &args.script {
            Some(path) => Some(Scene::load(path)?),
            None => None,
        };
        // A script's ground is drawn, as in `pelt render` (the panel's switch turns it off).
        settings.draw.ground |= scene.as_ref().is_some_and(|s| s.ground.is_some());
        let instances = crate::herd::instances(
            args.herd,
            scene.as_ref(),
            &structure.mesh,
            (rig.as_ref(), settings.animation.clip),
        )?;
        let mut herd = None;
        if !instances.is_empty() {
            // The viewer's herd is posed on the CPU in one parallel pass, its clip on the viewer's
            // clock, and bent on the edited fur's kernel.
            let clips =
                pelt_core::sim::herd::resolve_clips(&instances, rig.as_ref(), None).map_err(|(key, problem)| {
                    let file = args.script.as_deref().map_or_else(|| "--herd".to_owned(), |p| p.display().to_string());
                    anyhow::anyhow!("{file}: {key}: {problem}")
                })?;
            let made = Herd::new(instances, clips);
            // This fur is the first member; the herd stands on a ground, as in `pelt render`.
            stepper.set_placement(Some(made.first()));
            settings.animation.clip = made.clip(0, settings.animation.clip);
            settings.draw.ground = true;
            herd = Some(made);
        }
        stepper.set_wet(&settings.preset.wet)?;
        stepper.set_scene(scene.clone());
        if let Some(rig) = &rig {
            stepper.set_clip(rig.clone(), settings.animation.clip);
        }
        if let Some(herd) = &mut herd {
            herd.rebuild(
                (&structure, &settings.preset),
                stepper.scene(),
                (rig.as_ref(), settings.animation.clip),
                None,
            )?;
        }
        let groom_editor = super::paint::editor(&structure, &settings.preset)?;
        // The try-on's rig is the skirt's, kept with the body (not as the file's).
        let walking = match body {
            Some(body) if choice_is_try_on => rig.take().map(|rig| (rig, body, Pose::default())),
            _ => None,
        };
        if let (Some((_, body, _)), Some(mesh)) = (&walking, plain.first()) {
            stepper.set_body(Some((mesh.clone(), body.rig.clone(), body.capsules.clone())));
        }
        let model = Self {
            groom_editor,
            painting: false,
            structure_regrown: false,
            groom_attributes_changed: false,
            settings,
            mesh_choices,
            file_mesh,
            footprint: structure.footprint(),
            structure,
            body: plain.into_iter().next(),
            unified_bytes: None,
            no_lod: args.no_lod,
            level: pelt_render::FurLevel::FULL,
            shell_share: None,
            separated_bytes: None,
            camera,
            frame_pending: true,
            viewport_px: [1, 1],
            viewport_origin_px: [0, 0],
            clock: Clock { fixed: args.screenshot_after.is_some(), last: Instant::now() },
            frame_time_secs: 0.0,
            stepper,
            script: scene,
            sim_clock_secs: 0.0,
            sim_time_secs: 0.0,
            shown_times_secs: [0.0; 2],
            shown_at: None,
            // Auto times one fur; a herd bends on the CPU unless asked otherwise.
            pooling: args.pooling,
            sim_choice: if herd.is_some() && args.sim == SimChoice::Auto { SimChoice::Cpu } else { args.sim },
            kernel_reason: String::new(),
            touch: None,
            contact_drag: None,
            wind_strength_on: 1.0,
            textures: Some(textures),
            texture_job: None,
            textures_stale: false,
            frames_drawn: 0,
            skipped_frames: 0,
            screenshots_saved: 0,
            screenshot_pending: false,
            quit: false,
            panel_hidden: false,
            status: String::new(),
            rig,
            walking,
            herd,
            herd_in_view: 0,
        };
        Ok(model)
    }

    /// Looks at the whole fur (mesh plus its longest strand), or the whole herd where it stands.
    pub(super) fn frame(&mut self, aspect: f32) {
        let now = self.stepper.simulation().time_secs();
        if let Some((low, high)) =
            self.herd.as_ref().and_then(|h| pelt_core::sim::herd::extent(&self.structure, &h.instances, &[now]))
        {
            self.camera.frame(0.5 * (low + high), 0.5 * (high - low).length(), aspect);
            return;
        }
        let (center, radius) = self.structure.mesh.bounding_sphere();
        let longest = self.structure.lengths.iter().copied().fold(0.0, f32::max);
        // A garment is seen on the whole body wearing it.
        let (center, radius) = match &self.body {
            Some(body) => body.bounding_sphere(),
            None => (center, radius + longest),
        };
        self.camera.frame(center, radius, aspect);
    }

    /// Starts texture generation when the preset changed and none runs; hands over finished
    /// textures.
    pub(super) fn poll_textures(&mut self) -> Option<FurTextures> {
        let mut done = None;
        if self.texture_job.as_ref().is_some_and(std::thread::JoinHandle::is_finished)
            && let Some(job) = self.texture_job.take()
        {
            match job.join() {
                Ok(Ok(textures)) => {
                    self.status.clear();
                    done = Some(textures);
                }
                Ok(Err(error)) => self.status = error.to_string(),
                Err(_) => self.status = "texture generation failed unexpectedly".to_owned(),
            }
        }
        if self.texture_job.is_none() && self.textures_stale {
            self.textures_stale = false;
            let preset = self.settings.preset.clone();
            self.texture_job = Some(std::thread::spawn(move || preset.generate_textures()));
            self.status = "making textures…".to_owned();
        }
        done
    }

    /// Reads the preset file named in the panel; everything it sets changes.
    pub(super) fn load_preset(&mut self) -> Changes {
        match Preset::load(&self.settings.preset_path) {
            Ok(preset) => {
                self.settings.preset = preset;
                self.status = format!("loaded {}", self.settings.preset_path);
                Changes { structure: true, groom: true, textures: true, simulation: true, ..Changes::default() }
            }
            Err(error) => {
                self.status = error.to_string();
                Changes::default()
            }
        }
    }

    /// Writes the preset, and the painted groom beside it (`<preset>.groom`) when there is one.
    pub(super) fn save_preset(&mut self) {
        let groom = Some(self.groom_editor.groom()).filter(|g| !g.is_uniform());
        let saved = self.settings.preset.save_with_groom(&self.settings.preset_path, groom, &self.structure.mesh);
        self.status = match saved {
            Ok(()) if groom.is_some() => format!("saved {} with its groom", self.settings.preset_path),
            Ok(()) => format!("saved {}", self.settings.preset_path),
            Err(error) => error.to_string(),
        };
    }

    /// Moves the simulation's and the animation's clocks on by `frame_secs`: the times the
    /// fur is to be stepped to (simulation, clip), or `None` while the simulation is paused.
    pub(super) fn simulate(&mut self, frame_secs: f64) -> Option<(f64, f64)> {
        if !self.settings.simulate {
            return None;
        }
        self.sim_clock_secs += frame_secs;
        let animation = &mut self.settings.animation;
        let rig = match self.settings.mesh {
            MeshChoice::TryOn => self.walking.as_ref().map(|w| &w.0),
            _ => self.rig.as_ref(),
        };
        let duration = match (rig, animation.clip) {
            (Some(rig), Some(k)) => rig.animations()[k].duration_secs(),
            _ => 0.0,
        };
        if animation.playing && duration > 0.0 {
            animation.time_secs = (animation.time_secs + frame_secs as f32 * animation.speed).rem_euclid(duration);
        }
        animation.time_secs = animation.time_secs.clamp(0.0, duration);
        Some((self.sim_clock_secs, f64::from(animation.time_secs)))
    }

    /// Poses the walking try-on body with the skirt's clip at `clip_secs`: its positions and
    /// normals, and where the script's motion puts it; `None` without one.
    pub(super) fn pose_body(&mut self, clip_secs: f64) -> Option<(&[Vec3], &[Vec3], glam::Mat4)> {
        let (Some((_, body, pose)), Some(mesh)) = (&mut self.walking, &self.body) else { return None };
        body.rig.pose(mesh, self.settings.animation.clip, clip_secs, pose);
        Some((&pose.positions, &pose.normals, self.stepper.world_from_model()))
    }

    /// Smooths the measured cost of one step into the overlay's figure.
    pub(super) fn took(&mut self, step_secs: f64) {
        self.sim_time_secs = smooth(self.sim_time_secs, step_secs);
    }

    /// Rebuilds what the panel's changes touch; true when the structure is new.
    pub(super) fn apply(&mut self, changes: Changes) -> anyhow::Result<bool> {
        if changes.mesh {
            self.body = None;
            self.walking = None;
            let mesh = match &self.settings.mesh {
                MeshChoice::Builtin(builtin) => builtin.mesh().0,
                MeshChoice::TryOn => {
                    let stage = Stage::load(&StageSource::TryOn, &[], &pelt_core::ImportOptions::default())?;
                    self.body = stage.plain.into_iter().next();
                    self.walking = stage.rig.zip(stage.body).map(|(rig, body)| (rig, body, Pose::default()));
                    stage.fur_mesh
                }
                MeshChoice::File(_) => self.file_mesh.clone().context("the command-line mesh is gone")?,
            };
            self.structure = grow(mesh, &self.settings.preset, &self.settings.mesh)?;
            self.frame_pending = true;
        } else if changes.groom {
            self.structure = grow(self.structure.mesh.clone(), &self.settings.preset, &self.settings.mesh)?;
        } else if changes.structure {
            // A new shape keeps the groom painted so far.
            self.structure =
                super::paint::regrow(self.structure.mesh.clone(), &self.settings.preset, &self.groom_editor)?;
        }
        if changes.mesh || changes.groom {
            self.groom_editor = super::paint::editor(&self.structure, &self.settings.preset)?;
            self.settings.paint.history = self.groom_editor.history();
            self.painting = false;
        }
        if changes.mesh {
            let rig = match self.settings.mesh {
                MeshChoice::TryOn => self.walking.as_ref().map(|w| &w.0),
                MeshChoice::File(_) => self.rig.as_ref(),
                MeshChoice::Builtin(_) => None,
            };
            self.settings.animation = animation_settings(rig);
        }
        let rebuilt = changes.mesh || changes.structure || changes.groom;
        if changes.animation {
            self.settings.animation.time_secs = 0.0;
            self.stepper.change_clip(self.settings.animation.clip);
        }
        if rebuilt {
            self.footprint = self.structure.footprint();
            self.stepper.set_structure(&self.structure, &self.settings.preset.simulation)?;
            // The file's clip poses only the file's mesh.
            match (&self.rig, &self.walking, &self.settings.mesh) {
                (Some(rig), _, MeshChoice::File(_)) | (_, Some((rig, ..)), MeshChoice::TryOn) => {
                    self.stepper.set_clip(rig.clone(), self.settings.animation.clip);
                }
                _ => self.stepper.clear_clip(),
            }
            let body = match (&self.walking, &self.body, &self.settings.mesh) {
                (Some((_, body, _)), Some(mesh), MeshChoice::TryOn) => {
                    Some((mesh.clone(), body.rig.clone(), body.capsules.clone()))
                }
                _ => None,
            };
            self.stepper.set_body(body);
            self.touch = None;
        } else if changes.simulation {
            self.stepper.simulation_mut().set_params(&self.settings.preset.simulation)?;
        }
        if changes.kernel {
            self.kernel_reason = "panel".to_owned();
        }
        if rebuilt || changes.wet.any() {
            self.apply_wet(changes.wet)?;
        }
        if changes.textures {
            self.textures_stale = true;
        }
        self.apply_to_herd(&changes, rebuilt)?;
        Ok(rebuilt)
    }

    /// The rig playing on the mesh shown: the file's, the try-on skirt's, or none.
    pub(super) fn shown_rig(&self) -> Option<&Rig> {
        match self.settings.mesh {
            MeshChoice::TryOn => self.walking.as_ref().map(|w| &w.0),
            MeshChoice::File(_) => self.rig.as_ref(),
            MeshChoice::Builtin(_) => None,
        }
    }
}

impl Model {
    /// The panel's wet changes: `[wet]`, the coat set to one wetness, the scene's rain and water.
    fn apply_wet(&mut self, changes: super::wet::WetChanges) -> anyhow::Result<()> {
        let wet = &self.settings.preset.wet;
        self.stepper.set_wet(wet)?;
        if changes.uniform {
            self.stepper.wetness_mut().set_uniform(wet.wetness);
        }
        let positions = &self.structure.mesh.positions;
        let heights = positions.iter().fold([f32::MAX, f32::MIN], |[lo, hi], p| [lo.min(p.y), hi.max(p.y)]);
        let scene = super::wet::scene_with_sources(self.script.as_ref(), &self.settings.wet, heights);
        self.stepper.set_scene(scene);
        Ok(())
    }

    /// The coat's mean and largest wetness, for the panel.
    pub(super) fn show_wetness(&mut self) {
        let values = self.stepper.wetness().values();
        let largest = values.iter().copied().fold(0.0, f32::max);
        let mean = values.iter().sum::<f32>() / values.len().max(1) as f32;
        self.settings.wet.shown = [mean, largest];
    }

    /// The kernel the panel's toggle selects.
    pub(super) fn kernel(&self) -> SimKernel {
        if self.settings.gpu_sim { SimKernel::Gpu } else { SimKernel::Cpu }
    }
}

/// Grows the rest pose of the fur on `mesh` (the panel's `choice`), groomed as the preset says.
fn grow(mesh: Mesh, preset: &Preset, choice: &MeshChoice) -> anyhow::Result<FurStructure> {
    Ok(preset.grow(mesh, &choice.label())?)
}

/// Exponential moving average, so the overlay's numbers are readable.
/// How often the overlay's timings refresh.
const SHOWN_TIMES_REFRESH_SECS: f64 = 0.5;

impl Model {
    /// Takes the live frame and simulation times for the overlay when `SHOWN_TIMES_REFRESH_SECS`
    /// have passed since they were last taken.
    pub(super) fn refresh_shown_times(&mut self, now: Instant) {
        let due = self.shown_at.is_none_or(|at| now.duration_since(at).as_secs_f64() >= SHOWN_TIMES_REFRESH_SECS);
        if due {
            self.shown_times_secs = [self.frame_time_secs, self.sim_time_secs];
            self.shown_at = Some(now);
        }
    }
}

pub(super) fn smooth(previous: f64, sample: f64) -> f64 {
    if previous == 0.0 { sample } else { previous * 0.9 + sample * 0.1 }
}

/// A model from `pelt view` arguments, as the tests of the viewer's modules need one.
#[cfg(test)]
pub(super) fn test_model(args: &[&str]) -> Model {
    #[derive(clap::Parser)]
    struct Wrapper {
        #[command(flatten)]
        args: Args,
    }
    let wrapper = <Wrapper as clap::Parser>::parse_from([&["view"], args].concat());
    let stage = wrapper.args.mesh.stage(Builtin::Bunny, &[]).unwrap();
    Model::new(&wrapper.args, stage).unwrap()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn panel_changes_rebuild_only_what_they_touch() {
        let mut model = test_model(&["--builtin", "sphere"]);
        let before = model.structure.positions.clone();
        assert!(!model.apply(Changes { simulation: true, ..Changes::default() }).unwrap());
        assert!(!model.textures_stale, "a simulation change makes no textures");
        model.settings.preset.length *= 2.0;
        assert!(model.apply(Changes { structure: true, ..Changes::default() }).unwrap());
        assert_ne!(model.structure.positions, before);
        assert_eq!(model.stepper.simulation().positions().len(), model.structure.positions.len());
        assert!(!model.apply(Changes { textures: true, ..Changes::default() }).unwrap());
        assert!(model.textures_stale);
        model.settings.mesh = MeshChoice::TryOn;
        assert!(model.apply(Changes { mesh: true, ..Changes::default() }).unwrap());
        assert!(model.body.is_some() && model.frame_pending);
    }

    #[test]
    fn an_animated_file_plays_pauses_and_a_new_clip_restarts() {
        let fox = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes/Fox.glb");
        let mut model = test_model(&[fox]);
        assert_eq!(model.settings.animation.clips.len(), 3);
        assert_eq!(model.settings.animation.clip, Some(0), "the first clip plays by default");
        model.settings.animation.clip = Some(1);
        assert!(!model.apply(Changes { animation: true, ..Changes::default() }).unwrap());
        let step = |model: &mut Model| {
            let (time_secs, clip_secs) = model.simulate(0.1).expect("the simulation runs");
            model.stepper.advance_with_clip_at(time_secs, clip_secs).unwrap();
        };
        step(&mut model);
        assert!(model.stepper.moved_pose().is_some());
        let first = model.stepper.simulation().roots().to_vec();
        step(&mut model);
        assert!((model.settings.animation.time_secs - 0.2).abs() < 1e-5);
        assert_ne!(model.stepper.simulation().roots(), &first[..], "the walk moves the roots");
        model.settings.animation.playing = false;
        step(&mut model);
        assert!((model.settings.animation.time_secs - 0.2).abs() < 1e-5, "paused");
        model.settings.mesh = MeshChoice::Builtin(Builtin::Sphere);
        model.apply(Changes { mesh: true, ..Changes::default() }).unwrap();
        step(&mut model);
        assert!(model.stepper.moved_pose().is_none(), "a built-in mesh does not take the file's rig");
    }

    #[test]
    fn growing_scales_the_length_with_the_mesh() {
        let (mesh, _) = Builtin::Sphere.mesh();
        let radius = mesh.bounding_sphere().1;
        let mut preset = Preset::default();
        preset.length = 0.25;
        let fur = grow(mesh, &preset, &MeshChoice::Builtin(Builtin::Sphere)).unwrap();
        assert!(fur.lengths.iter().all(|l| (l - 0.25 * radius).abs() < 1e-5));
        assert_eq!(fur.layers, preset.layers);
    }
}
