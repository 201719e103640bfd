//! A herd in the viewer (`--herd N`, a script's `[[instance]]`s). The fur the panel edits is the
//! first member, placed as the first instance; the others are copies of it, each simulated on its
//! own (posed on the CPU in one parallel pass, or on a GPU there when they bend on the GPU kernel;
//! bent on the edited fur's kernel) and drawn from one
//! shared asset, rebuilt from the edited fur whenever its structure, textures, groom, simulation
//! or kernel change.

use super::model::Model;
use super::panel::{Changes, MeshChoice};
use glam::{Mat4, Vec3};
use pelt_core::anim::Rig;
use pelt_core::sim::herd::HerdInstance;
use pelt_core::sim::{FurStepper, Scene};
use pelt_core::{FurStructure, FurTextures, Preset};
use pelt_render::{
    FurAsset, FurDrawSettings, FurDriver, FurLevel, FurLook, FurRenderer, FurView, HerdPosing, KernelChoice, SimKernel,
    ViewData,
};

/// The CPU half: where the members stand and the others' simulations.
pub(super) struct Herd {
    pub(super) instances: Vec<HerdInstance>,
    /// Each member's clip in the rig (`None`: the panel's).
    clips: Vec<Option<usize>>,
    /// Members 1.. (member 0 is the model's own stepper).
    followers: Vec<FurStepper>,
}

impl Herd {
    /// A herd of `instances` (at least one) with their clips resolved; the followers are built by
    /// [`Herd::rebuild`].
    pub(super) fn new(instances: Vec<HerdInstance>, clips: Vec<Option<usize>>) -> Self {
        Self { instances, clips, followers: Vec::new() }
    }

    pub(super) fn len(&self) -> usize {
        self.instances.len()
    }

    /// The first member's place: the model's own stepper stands there.
    pub(super) fn first(&self) -> HerdInstance {
        self.instances[0].clone()
    }

    /// Member `k`'s clip: its own, else `panel_clip`.
    pub(super) fn clip(&self, k: usize, panel_clip: Option<usize>) -> Option<usize> {
        self.clips.get(k).copied().flatten().or(panel_clip)
    }

    /// Every member plays the panel's clip from now on (a mesh without the instances' clips).
    pub(super) fn forget_clips(&mut self) {
        self.clips.iter_mut().for_each(|clip| *clip = None);
    }

    pub(super) fn followers(&self) -> &[FurStepper] {
        &self.followers
    }

    fn followers_mut(&mut self) -> &mut [FurStepper] {
        &mut self.followers
    }

    /// Makes the others anew as copies of the edited fur: `structure` (each grown to its own
    /// length scale), the preset's simulation and `[wet]`, the model's script, `rig` playing
    /// each member's clip (`None` for a mesh without one). A coat set to one wetness is set on
    /// every copy (`uniform_wetness`).
    ///
    /// # Errors
    /// The simulation's errors for a preset it refuses.
    pub(super) fn rebuild(
        &mut self,
        (structure, preset): (&FurStructure, &Preset),
        scene: Option<&Scene>,
        (rig, panel_clip): (Option<&Rig>, Option<usize>),
        uniform_wetness: Option<f32>,
    ) -> anyhow::Result<()> {
        self.followers = (1..self.instances.len())
            .map(|k| {
                let instance = &self.instances[k];
                let grown;
                let structure = if instance.length_scale == 1.0 {
                    structure
                } else {
                    grown = structure.with_length_scale(instance.length_scale);
                    &grown
                };
                let mut stepper = FurStepper::new(structure, &preset.simulation)?;
                stepper.set_wet(&preset.wet)?;
                if let Some(wetness) = uniform_wetness {
                    stepper.wetness_mut().set_uniform(wetness);
                }
                if let Some(rig) = rig {
                    stepper.set_clip(rig.clone(), self.clip(k, panel_clip));
                }
                stepper.set_scene(scene.cloned());
                stepper.set_placement(Some(instance.clone()));
                Ok(stepper)
            })
            .collect::<anyhow::Result<_>>()?;
        Ok(())
    }

    /// The preset's new simulation settings on every copy (their states kept).
    ///
    /// # Errors
    /// The simulation's errors for settings it refuses.
    pub(super) fn set_params(&mut self, params: &pelt_core::sim::SimParams) -> anyhow::Result<()> {
        for stepper in &mut self.followers {
            stepper.simulation_mut().set_params(params)?;
        }
        Ok(())
    }

    /// The edited fur's `[wet]`, a coat set to one wetness (`uniform_wetness`) and the script
    /// with the panel's rain and water, on every copy.
    ///
    /// # Errors
    /// The simulation's errors for `[wet]` settings it refuses.
    pub(super) fn set_wet(
        &mut self,
        wet: &pelt_core::wet::WetParams,
        uniform_wetness: Option<f32>,
        scene: Option<&Scene>,
    ) -> anyhow::Result<()> {
        for stepper in &mut self.followers {
            stepper.set_wet(wet)?;
            if let Some(wetness) = uniform_wetness {
                stepper.wetness_mut().set_uniform(wetness);
            }
            stepper.set_scene(scene.cloned());
        }
        Ok(())
    }

    /// Steps the others to `time_secs` in one parallel pass, each with its clip at `clip_secs`
    /// plus its own offset and every `strides[k - 1]`-th step (far members less often).
    ///
    /// # Errors
    /// The first member's simulation error.
    pub(super) fn advance(&mut self, time_secs: f64, clip_secs: f64, strides: &[u32]) -> anyhow::Result<()> {
        use rayon::prelude::*;
        for (stepper, &stride) in self.followers.iter_mut().zip(strides) {
            stepper.set_step_stride(stride);
        }
        self.followers.par_iter_mut().zip(&self.instances[1..]).try_for_each(|(stepper, instance)| {
            stepper.advance_with_clip_at(time_secs, clip_secs + instance.time_offset_secs)
        })?;
        Ok(())
    }

    /// Where member `k`'s model stands in the world at `time_secs`.
    pub(super) fn world_from_model(&self, k: usize, time_secs: f64) -> Mat4 {
        self.instances[k].world_from_model(time_secs)
    }
}

impl Model {
    /// Each herd member's level of detail, whether it is in view and how far, at `time_secs`;
    /// empty for one fur.
    pub(super) fn member_frames(&self, time_secs: f64) -> Vec<super::herd::MemberFrame> {
        let Some(herd) = &self.herd else { return Vec::new() };
        let lod = crate::lod::settings(&self.settings.preset.render.lod, self.no_lod);
        let camera = self.camera.camera();
        let [width, height] = self.viewport_px;
        let view = self.settings.lights.studio().view_data(&camera, width as f32 / height.max(1) as f32);
        let fov_y_rad = self.camera.fov_y_rad;
        super::herd::member_frames(herd, (&self.structure, time_secs), (camera.eye, &view), |structure, eye| {
            crate::lod::level(&lod, structure, eye, fov_y_rad, height)
        })
    }

    /// The panel's changes on the herd's other members: made anew for a new fur or clip, given
    /// the new settings otherwise (their states kept).
    pub(super) fn apply_to_herd(&mut self, changes: &Changes, rebuilt: bool) -> anyhow::Result<()> {
        let Some(mut herd) = self.herd.take() else { return Ok(()) };
        let wet = &self.settings.preset.wet;
        let uniform = changes.wet.uniform.then_some(wet.wetness);
        let result = if rebuilt || changes.animation {
            // The instances' own clips name the file's clips; on another mesh they play the panel's.
            let rig = self.shown_rig();
            let own_clips = matches!(self.settings.mesh, MeshChoice::File(_));
            let panel_clip = self.settings.animation.clip;
            if !own_clips {
                herd.forget_clips();
            }
            herd.rebuild((&self.structure, &self.settings.preset), self.stepper.scene(), (rig, panel_clip), uniform)
        } else {
            let params = if changes.simulation { herd.set_params(&self.settings.preset.simulation) } else { Ok(()) };
            params.and_then(|()| match changes.wet.any() {
                true => herd.set_wet(wet, uniform, self.stepper.scene()),
                false => Ok(()),
            })
        };
        self.herd = Some(herd);
        result
    }
}

/// One member as drawn this frame.
#[derive(Clone, Copy, Debug)]
pub(super) struct MemberFrame {
    pub(super) level: FurLevel,
    /// Its model's centre is within the view (with the fur's reach about it).
    pub(super) seen: bool,
    /// From the eye, for drawing blended fur farthest first.
    pub(super) distance: f32,
    /// A world-space sphere (centre, radius) holding what it draws, for the camera's plan.
    pub(super) sphere: (Vec3, f32),
}

/// Each member's level of detail, whether it is seen and how far it stands, at `time_secs`:
/// `level_of(structure_k, eye in member k's model space)` gives the level.
pub(super) fn member_frames(
    herd: &Herd,
    (structure, time_secs): (&FurStructure, f64),
    (eye, view): (Vec3, &ViewData),
    level_of: impl Fn(&FurStructure, Vec3) -> FurLevel,
) -> Vec<MemberFrame> {
    let (centre, radius) = structure.mesh.bounding_sphere();
    let reach = radius + structure.lengths.iter().copied().fold(0.0, f32::max);
    (0..herd.len())
        .map(|k| {
            let world_from_model = herd.world_from_model(k, time_secs);
            let world_centre = world_from_model.transform_point3(centre);
            MemberFrame {
                level: level_of(structure, world_from_model.inverse().transform_point3(eye)),
                seen: view.sees_sphere(world_centre, reach),
                distance: world_centre.distance(eye),
                sphere: (world_centre, reach),
            }
        })
        .collect()
}

/// The GPU half: the others' drivers over one asset.
#[derive(Debug)]
pub(super) struct HerdDrivers {
    /// Kept so the copies share one upload of the topology and textures.
    _asset: FurAsset,
    drivers: Vec<FurDriver>,
    /// Their bases skinned on the GPU (`FurRenderer::herd_posing`, on the GPU kernel).
    posing: Option<HerdPosing>,
}

impl HerdDrivers {
    /// `count` copies of `structure` with `textures`, bent on `kernel`, skinned by `rig` (the
    /// copies' rig, if any).
    ///
    /// # Errors
    /// The upload's errors.
    pub(super) fn new(
        gpu: &pelt_render::Gpu,
        renderer: &FurRenderer,
        (structure, textures, rig): (&FurStructure, &FurTextures, Option<&Rig>),
        (params, kernel): (&pelt_core::sim::SimParams, SimKernel),
        count: usize,
    ) -> anyhow::Result<Self> {
        let (device, queue) = (&gpu.device, &gpu.queue);
        let asset = FurAsset::new(device, queue, renderer, structure, textures)?;
        let choice = KernelChoice::from(kernel);
        let drivers = FurDriver::herd_with_asset(device, queue, renderer, (&asset, structure), params, choice, count)?;
        let posing = rig
            .filter(|rig| {
                kernel == SimKernel::Gpu
                    && renderer.herd_posing()
                    && rig.vertex_count() == structure.mesh.vertex_count()
            })
            .map(|rig| HerdPosing::new(device, &structure.mesh, rig, count))
            .transpose()?;
        Ok(Self { _asset: asset, drivers, posing })
    }

    pub(super) fn len(&self) -> usize {
        self.drivers.len()
    }

    /// How many copies bend on the GPU kernel now (a copy whose steps went unrecorded falls
    /// back to the CPU).
    pub(super) fn on_gpu(&self) -> usize {
        self.drivers.iter().filter(|driver| driver.kernel() == SimKernel::Gpu).count()
    }

    /// How many copies the GPU posed last (`HerdPosing`).
    pub(super) fn posed_on_gpu(&self) -> usize {
        self.posing.as_ref().map_or(0, HerdPosing::members_on_gpu)
    }

    /// Before the copies' steppers step: each bends on its driver's kernel.
    pub(super) fn claim(&mut self, herd: &mut Herd) {
        for (driver, stepper) in self.drivers.iter_mut().zip(herd.followers_mut()) {
            driver.claim_stepper(stepper);
            stepper.set_joint_posing(self.posing.is_some());
        }
    }

    /// Shows each copy what its stepper stepped (on the GPU kernel: its steps, recorded into one
    /// submission here), at its level and with `look` tinted by its instance's tint.
    pub(super) fn show(
        &mut self,
        gpu: &pelt_render::Gpu,
        herd: &Herd,
        frames: &[MemberFrame],
        look: FurLook,
    ) -> anyhow::Result<()> {
        for (k, (driver, stepper)) in self.drivers.iter_mut().zip(herd.followers()).enumerate() {
            driver.show_claimed(&gpu.device, &gpu.queue, stepper)?;
            let member = k + 1;
            if let Some(frame) = frames.get(member) {
                driver.set_level(frame.level);
            }
            driver.set_look(FurLook { tint: herd.instances[member].tint, ..look });
            driver.prepare(&gpu.queue);
        }
        if let Some(posing) = &mut self.posing {
            posing.prepare((&gpu.device, &gpu.queue), &self.drivers, herd.followers())?;
        }
        let posed = self.posing.as_ref().is_some_and(|posing| posing.members_on_gpu() > 0);
        if posed || self.drivers.iter().any(FurDriver::has_steps_to_record) {
            let mut encoder =
                gpu.device.create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some("herd simulation") });
            if let Some(posing) = &self.posing {
                posing.record(&mut encoder);
            }
            FurDriver::record_herd(&mut encoder, &mut self.drivers)?;
            gpu.queue.submit([encoder.finish()]);
        }
        Ok(())
    }

    /// The silhouette listings of the copies `drawn` lists (member indices, 1..).
    pub(super) fn record_view(
        &self,
        encoder: &mut wgpu::CommandEncoder,
        renderer: &FurRenderer,
        view: &FurView,
        drawn: &[usize],
    ) {
        FurDriver::record_views(encoder, renderer, view, drawn.iter().map(|&member| &self.drivers[member - 1]));
    }

    /// Member `member`'s fur (1..: the main fur is member 0).
    pub(super) fn fur(&self, member: usize) -> &pelt_render::GpuFur {
        self.drivers[member - 1].fur()
    }

    /// Draws the copies `drawn` lists (member indices, 1..; every copy into a shadow map, where
    /// those made together cast in one draw a pass).
    pub(super) fn draw(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        renderer: &FurRenderer,
        view: &FurView,
        (drawn, settings): (&[usize], &FurDrawSettings),
    ) {
        let members = drawn.iter().map(|&member| &self.drivers[member - 1]);
        FurDriver::draw_herd(pass, renderer, view, members, settings);
    }
}

/// How far ahead a herd's shadow maps reach: made about where the members walk over this long,
/// made again when one walks out.
const SHADOW_SPAN_SECS: f64 = 8.0;

/// The box the herd's shadow maps and ground cover at `time_secs`: `made` (the box they were made
/// about) while every member stands inside it, else where the members walk next.
pub(super) fn shadow_extent(
    structure: &FurStructure,
    herd: &Herd,
    time_secs: f64,
    made: Option<(Vec3, Vec3)>,
) -> Option<(Vec3, Vec3)> {
    let (low, high) = pelt_core::sim::herd::extent(structure, &herd.instances, &[time_secs])?;
    match made {
        Some((made_low, made_high)) if made_low.cmple(low).all() && high.cmple(made_high).all() => made,
        _ => pelt_core::sim::herd::extent(structure, &herd.instances, &[time_secs, time_secs + SHADOW_SPAN_SECS]),
    }
}

#[cfg(test)]
mod tests {
    use super::super::model::test_model;
    use super::super::panel::{Changes, MeshChoice};

    /// The herd follows the panel: a new shape or mesh makes the others anew from the edited fur,
    /// a simulation change keeps their states; the first member stands where its instance does
    /// and every member steps at its own phase.
    #[test]
    fn the_viewers_herd_follows_the_panels_edits() {
        let fox = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes/Fox.glb");
        let mut model = test_model(&[fox, "--herd", "4"]);
        let herd = model.herd.as_ref().expect("a herd of 4");
        assert_eq!((herd.len(), herd.followers().len()), (4, 3));
        assert!(model.settings.draw.ground, "the herd stands on a ground");
        let (time_secs, clip_secs) = model.simulate(0.1).unwrap();
        model.stepper.advance_with_clip_at(time_secs, clip_secs).unwrap();
        let herd = model.herd.as_mut().unwrap();
        herd.advance(time_secs, clip_secs, &[1, 1, 1]).unwrap();
        // The first member (the model's stepper) stands at its instance's place.
        let first = herd.instances[0].position_at(time_secs);
        let roots = model.stepper.simulation().roots();
        let centre = roots.iter().fold(glam::Vec3::ZERO, |sum, r| sum + *r) / roots.len() as f32;
        let size = model.structure.mesh.bounding_sphere().1;
        assert!((centre - first).length() < 2.0 * size, "the first member stands {centre} from {first}");
        let state = |model: &super::super::model::Model, k: usize| {
            model.herd.as_ref().unwrap().followers()[k].simulation().positions().to_vec()
        };
        let before = state(&model, 0);
        assert!(
            model.herd.as_ref().unwrap().followers().iter().all(|s| s.simulation().positions().len() == before.len())
        );
        // A simulation change keeps the others' states; a new shape makes them anew at its size.
        model.settings.preset.simulation.damping *= 0.5;
        model.apply(Changes { simulation: true, ..Changes::default() }).unwrap();
        assert_eq!(state(&model, 0), before, "a simulation change restarted the others");
        model.settings.preset.layers = 8;
        assert!(model.apply(Changes { structure: true, ..Changes::default() }).unwrap());
        let expected = model.structure.positions.len();
        assert!(model.herd.as_ref().unwrap().followers().iter().all(|s| s.simulation().positions().len() == expected));
        assert_ne!(expected, before.len(), "the others kept the old shape");
        // Another mesh: the others take it and the panel's clip (the file's clips are gone).
        model.settings.mesh = MeshChoice::Builtin(pelt_core::Builtin::Sphere);
        assert!(model.apply(Changes { mesh: true, ..Changes::default() }).unwrap());
        let expected = model.structure.positions.len();
        assert!(model.herd.as_ref().unwrap().followers().iter().all(|s| s.simulation().positions().len() == expected));
    }
}
