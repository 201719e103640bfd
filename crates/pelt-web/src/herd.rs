//! The herd scene: sixteen Foxes walking on the spot on a ground, each at its own phase of the
//! Fox's Walk and heading its own way (`pelt_core::sim::herd::scatter`, as `pelt render --herd`).
//! The model's own stepper is the first member (the one the pointer pats); the others are copies
//! of its fur, each simulated on its own, drawn from one shared asset ([`HerdGpu`]).

use glam::Vec3;
use pelt_core::FurStructure;
use pelt_core::Preset;
use pelt_core::anim::Rig;
use pelt_core::sim::FurStepper;
use pelt_core::sim::herd::{self, HerdInstance};
use pelt_render::{FurAsset, FurDrawSettings, FurDriver, FurLook, FurRenderer, FurView, KernelChoice};

use crate::model::ModelError;

/// How many Foxes the herd scene shows: a field a page's single thread steps at a walking pace.
pub const HERD_SIZE: usize = 16;

/// The herd's members apart from the model's own stepper.
#[derive(Debug)]
pub struct Herd {
    /// Where each member stands (the first is the model's stepper).
    pub instances: Vec<HerdInstance>,
    /// Members 1.. of `instances`.
    others: Vec<FurStepper>,
    /// The walk's length: every member walks on the spot, so its pose repeats with this period.
    cycle_secs: f64,
}

impl Herd {
    /// [`HERD_SIZE`] Foxes about the origin, a body length and a half apart, each somewhere in
    /// `rig`'s clip `clip`; `first` (the model's stepper of `structure`) is placed as the first,
    /// the others simulated with `preset`'s `[simulation]` and `[wet]`.
    ///
    /// # Errors
    /// [`ModelError::Sim`] for settings the simulation refuses.
    pub fn new(
        (structure, preset): (&FurStructure, &Preset),
        (rig, clip): (&Rig, usize),
        first: &mut FurStepper,
    ) -> Result<Self, ModelError> {
        let (low, high) = structure.mesh.bounds();
        let spacing = 1.5 * (high - low).max_element();
        let cycle = f64::from(rig.animations()[clip].duration_secs());
        let instances = herd::scatter(HERD_SIZE, spacing, cycle, 0).map_err(ModelError::Control)?;
        let place = |stepper: &mut FurStepper, instance: &HerdInstance| {
            stepper.set_clip(rig.clone(), Some(clip));
            stepper.set_placement(Some(instance.clone()));
        };
        place(first, &instances[0]);
        let others = instances[1..]
            .iter()
            .map(|instance| {
                let mut stepper = FurStepper::new(structure, &preset.simulation)?;
                stepper.set_wet(&preset.wet)?;
                place(&mut stepper, instance);
                Ok(stepper)
            })
            .collect::<Result<Vec<_>, ModelError>>()?;
        Ok(Self { instances, others, cycle_secs: cycle })
    }

    /// The members after the first.
    #[must_use]
    pub fn others(&self) -> &[FurStepper] {
        &self.others
    }

    /// The walk cycle's length in seconds: each member's pose repeats with it.
    #[must_use]
    pub fn cycle_secs(&self) -> f64 {
        self.cycle_secs
    }

    /// The wind on every other member (the first's is the model's).
    ///
    /// # Errors
    /// [`ModelError::Sim`] for a wind the simulation refuses.
    pub fn set_wind(&mut self, wind: &pelt_core::sim::WindParams) -> Result<(), ModelError> {
        for stepper in &mut self.others {
            stepper.simulation_mut().set_wind(wind)?;
        }
        Ok(())
    }

    /// Steps the other members to `time_secs`, each at its own phase of the walk. One after
    /// another: a page has one thread.
    ///
    /// # Errors
    /// [`ModelError::Sim`] for a step the simulation refuses.
    pub fn advance_to(&mut self, time_secs: f64) -> Result<(), ModelError> {
        for (stepper, instance) in self.others.iter_mut().zip(&self.instances[1..]) {
            stepper.advance_with_clip_at(time_secs, instance.clip_time(time_secs))?;
        }
        Ok(())
    }

    /// The box every member's fur stands in (walking on the spot, where they stand).
    #[must_use]
    pub fn extent(&self, structure: &FurStructure) -> (Vec3, Vec3) {
        herd::extent(structure, &self.instances, &[0.0]).unwrap_or((Vec3::ZERO, Vec3::ZERO))
    }
}

/// The other members on the GPU: one asset, a driver each.
#[derive(Debug)]
pub struct HerdGpu {
    /// Kept so the copies share one upload of the topology and textures.
    _asset: FurAsset,
    drivers: Vec<FurDriver>,
}

impl HerdGpu {
    /// `count` copies of `structure` with `textures`, shown from the CPU's states.
    ///
    /// # Errors
    /// The renderer's message.
    pub fn new(
        (device, queue): (&wgpu::Device, &wgpu::Queue),
        renderer: &FurRenderer,
        (structure, textures): (&FurStructure, &pelt_core::FurTextures),
        preset: &Preset,
        count: usize,
    ) -> Result<Self, String> {
        let asset = FurAsset::new(device, queue, renderer, structure, textures).map_err(|e| e.to_string())?;
        let herd = (&asset, structure);
        let drivers =
            FurDriver::herd_with_asset(device, queue, renderer, herd, &preset.simulation, KernelChoice::Cpu, count)
                .map_err(|e| e.to_string())?;
        Ok(Self { _asset: asset, drivers })
    }

    /// Shows each copy what its stepper stepped, with `look`.
    ///
    /// # Errors
    /// The renderer's message.
    pub fn show(&mut self, queue: &wgpu::Queue, others: &[FurStepper], look: FurLook) -> Result<(), String> {
        for (driver, stepper) in self.drivers.iter_mut().zip(others) {
            driver.set_look(look);
            driver.show_stepped(queue, stepper).map_err(|e| e.to_string())?;
        }
        Ok(())
    }

    /// The copies' silhouette listings for `view`.
    pub fn record_view(&self, encoder: &mut wgpu::CommandEncoder, renderer: &FurRenderer, view: &FurView) {
        FurDriver::record_views(encoder, renderer, view, &self.drivers);
    }

    /// Draws copy `k` (0 is the herd's second member).
    pub fn draw(
        &self,
        k: usize,
        pass: &mut wgpu::RenderPass<'_>,
        (renderer, view): (&FurRenderer, &FurView),
        settings: &FurDrawSettings,
    ) {
        self.drivers[k].draw(pass, renderer, view, settings);
    }

    /// Draws every copy into `view` (a shadow map's: those made together cast in one draw a
    /// pass).
    pub fn draw_all(&self, pass: &mut wgpu::RenderPass<'_>, (renderer, view): (&FurRenderer, &FurView)) {
        FurDriver::draw_herd(pass, renderer, view, &self.drivers, &FurDrawSettings::ALL);
    }

    /// How many copies.
    #[must_use]
    pub fn len(&self) -> usize {
        self.drivers.len()
    }

    /// Whether there are none.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.drivers.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use crate::model::{Model, SceneChoice};

    /// Sixteen Foxes, each walking at its own phase: member k steps as a Fox stepped alone with
    /// member k's place and phase does, to the bit, and two members' poses differ.
    #[test]
    fn the_herd_scene_walks_sixteen_foxes_each_as_it_would_alone() {
        let mut model = Model::new(SceneChoice::Herd, pelt_core::Preset::default(), 1.5).expect("the herd scene");
        assert!(model.light.ground, "the herd stands on a ground");
        let herd = model.herd.as_ref().expect("a herd");
        assert_eq!(herd.instances.len(), super::HERD_SIZE);
        let k = 3;
        let instance = herd.instances[k].clone();
        let (mesh, _, rig) = crate::scene::load_scene(SceneChoice::Herd).unwrap();
        let rig = rig.unwrap();
        let structure = crate::scene::grow(mesh, SceneChoice::Herd, &model.preset).unwrap();
        let mut alone = pelt_core::sim::FurStepper::new(&structure, &model.preset.simulation).unwrap();
        alone.set_wet(&model.preset.wet).unwrap();
        let walk = rig.find_animation("Walk").unwrap();
        // The page's checks time the walk by its cycle: the clip's length, where the page's clock is in it.
        let cycle = f64::from(rig.animations()[walk].duration_secs());
        assert_eq!(model.walk_cycle_secs(), Some(cycle));
        alone.set_clip(rig.clone(), Some(walk));
        alone.set_placement(Some(instance.clone()));
        // The same frames, the same inputs.
        let mut time_secs = 0.0;
        for _ in 0..12 {
            model.simulate(1.0 / 30.0).unwrap();
            time_secs = model.stepper.simulation().time_secs();
            alone.advance_with_clip_at(time_secs, instance.clip_time(time_secs)).unwrap();
        }
        assert!((model.walk_secs().unwrap() - (12.0 / 30.0) % cycle).abs() < 1e-9);
        let herd = model.herd.as_ref().unwrap();
        let member = herd.others()[k - 1].simulation().positions();
        assert!(member.iter().all(|p| p.is_finite()));
        assert!(member == alone.simulation().positions(), "member {k} differs from the Fox stepped alone");
        // In its own model space, member 1 stands in another phase of the walk than member 2.
        let local = |m: usize| {
            let model_from_world = herd.instances[m].world_from_model(time_secs).inverse();
            herd.others()[m - 1].simulation().positions().iter().map(move |p| model_from_world.transform_point3(*p))
        };
        let apart = local(1).zip(local(2)).map(|(a, b)| a.distance(b)).fold(0.0, f32::max);
        assert!(apart > 1.0, "members 1 and 2 stand in the same pose (at most {apart} apart)");
    }
}
