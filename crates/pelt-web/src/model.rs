//! The page's state apart from the browser: the scene, the preset with the page's overrides,
//! the fur and its simulation, the pointers on it (patting, or the other [`Tool`]s) and the
//! orbit camera. Nothing here touches a browser API, so it is tested natively.

use glam::{Vec2, Vec3};
use pelt_core::anim::Rig;
use pelt_core::sim::{FurStepper, Touch};
use pelt_core::texture::Rgb;
use pelt_core::{FurStructure, Mesh, Preset};
use pelt_render::Camera;

use crate::herd::Herd;
use crate::light::PageLight;
pub use crate::orbit::Orbit;
pub use crate::scene::{FOX_NAME, SceneChoice, WalkingBody};
use crate::scene::{grow, load_scene, stepper};
use crate::tools::{Tool, Tools};

/// Touch radius as a fraction of the furred mesh's bounding radius (the viewer's default brush).
const BRUSH_PER_RADIUS: f32 = 0.25;
/// A long stall (a tab in the background) must not fast-forward the scene.
const MAX_FRAME_SECS: f64 = 0.25;

/// Why the page's state could not change; the page shows the message and keeps what it had.
#[derive(Debug, thiserror::Error)]
pub enum ModelError {
    /// A preset that does not fit (bad value, image the page cannot read).
    #[error(transparent)]
    Preset(#[from] pelt_core::PresetError),
    /// The fur could not be grown on the mesh.
    #[error(transparent)]
    Fur(#[from] pelt_core::fur::FurError),
    /// The shipped try-on meshes did not load.
    #[error(transparent)]
    Mesh(#[from] pelt_core::MeshError),
    /// The simulation rejected its parameters.
    #[error(transparent)]
    Sim(#[from] pelt_core::SimError),
    /// A value from a control out of its range.
    #[error("{0}")]
    Control(String),
}

/// One pointer patting the fur: the touch, and the plane facing the camera it drags across.
#[derive(Debug)]
struct PointerTouch {
    pointer_id: i32,
    touch: Touch,
    plane_normal: Vec3,
}

/// What the pointers do now, for the page's figures and its tests.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PointerStats {
    /// The tool a pointer landing on the fur takes.
    pub tool: Tool,
    /// Pointers patting (held, not fading).
    pub touches: usize,
    /// Fingers on the fur.
    pub fingers: usize,
    /// Whether a pointer holds a grasp.
    pub grabbing: bool,
    /// The wettest base vertex's wetness, `0..=1`.
    pub wettest: f32,
}

/// Everything the page shows, without the GPU.
#[derive(Debug)]
pub struct Model {
    /// The scene shown.
    pub scene: SceneChoice,
    /// The preset with the page's overrides (length, colour, wind).
    pub preset: Preset,
    /// The fur's rest pose.
    pub structure: FurStructure,
    /// The try-on body, drawn plain (its bind pose; [`Model::pose_body`] walks it).
    pub body: Option<Mesh>,
    /// The try-on body's walk: its rig, the skirt's and the capsules the fur collides with.
    walking: Option<WalkingBody>,
    /// The herd scene's other Foxes (`stepper` is the first) and the rig they walk with.
    pub herd: Option<Herd>,
    herd_rig: Option<Rig>,
    /// The simulation of `structure`, stepped by the page's frame driver (or by
    /// [`Model::simulate`] without a GPU).
    pub stepper: FurStepper,
    /// The camera.
    pub orbit: Orbit,
    /// The key light, its shadows and the ground.
    pub light: PageLight,
    /// The distance that frames the scene (zoom is bounded around it).
    framed_distance: f32,
    /// Pointers on the fur, held or fading after release. Several at once: each is a `Touch`
    /// written into the simulation's user force field, which the core leaves to applications.
    touches: Vec<PointerTouch>,
    /// What a pointer landing on the fur does.
    tool: Tool,
    /// Fingers, the grab and sponges.
    tools: Tools,
    /// Simulation time (seconds).
    clock_secs: f64,
}

impl Model {
    /// The scene with `preset`, framed for a view of `aspect` (width / height).
    ///
    /// # Errors
    /// [`ModelError`] if the preset does not fit the mesh.
    pub fn new(scene: SceneChoice, preset: Preset, aspect: f32) -> Result<Self, ModelError> {
        let (mesh, walking, herd_rig) = load_scene(scene)?;
        let structure = grow(mesh, scene, &preset)?;
        let mut stepper = stepper(&structure, &preset, walking.as_ref())?;
        let herd = herd_rig.as_ref().map(|rig| make_herd(&structure, &preset, rig, &mut stepper)).transpose()?;
        let body = walking.as_ref().map(|w| w.mesh.clone());
        let orbit = Orbit { target: Vec3::ZERO, azimuth_deg: 35.0, elevation_deg: 15.0, distance: 1.0 };
        let mut model = Self {
            scene,
            preset,
            structure,
            body,
            walking,
            herd,
            herd_rig,
            stepper,
            orbit,
            light: PageLight::default(),
            framed_distance: 1.0,
            touches: Vec::new(),
            tool: Tool::default(),
            tools: Tools::default(),
            clock_secs: 0.0,
        };
        // The herd stands on a ground.
        model.light.ground |= model.herd.is_some();
        model.frame(aspect);
        Ok(model)
    }

    /// Looks at the whole scene (the body for the try-on, else the fur) from the current angles.
    pub fn frame(&mut self, aspect: f32) {
        let longest = self.structure.lengths.iter().copied().fold(0.0, f32::max);
        let (centre, radius) = match (&self.body, &self.herd) {
            (Some(body), _) => body.bounding_sphere(),
            (None, Some(herd)) => {
                let (low, high) = herd.extent(&self.structure);
                (0.5 * (low + high), 0.5 * (high - low).length())
            }
            (None, None) => {
                let (centre, radius) = self.structure.mesh.bounding_sphere();
                (centre, radius + longest)
            }
        };
        let framed = Camera::framing_distance(radius, Camera::DEFAULT_FOV_Y_RAD, aspect);
        self.orbit.target = centre;
        self.orbit.distance = framed;
        self.framed_distance = framed;
    }

    /// Zooms by `factor` (below 1 comes closer).
    pub fn zoom(&mut self, factor: f32) {
        self.orbit.zoom(factor, self.framed_distance);
    }

    /// Switches the scene; the fur, simulation and touches start anew.
    ///
    /// # Errors
    /// [`ModelError`]; the previous scene stays.
    pub fn set_scene(&mut self, scene: SceneChoice, aspect: f32) -> Result<(), ModelError> {
        self.set_scene_and_preset(scene, self.preset.clone(), aspect)
    }

    /// Switches the scene and the preset at once (a groomed preset fits one mesh only),
    /// keeping the page's wind and tool; the fur, simulation and pointers start anew.
    ///
    /// # Errors
    /// [`ModelError`]; the previous scene and preset stay.
    pub fn set_scene_and_preset(
        &mut self,
        scene: SceneChoice,
        mut preset: Preset,
        aspect: f32,
    ) -> Result<(), ModelError> {
        preset.simulation.wind = self.preset.simulation.wind.clone();
        *self = Self { orbit: self.orbit, light: self.light, tool: self.tool, ..Self::new(scene, preset, aspect)? };
        self.light.ground |= self.herd.is_some();
        self.frame(aspect);
        Ok(())
    }

    /// Replaces the preset (keeping the page's wind); the structure and simulation are rebuilt.
    ///
    /// # Errors
    /// [`ModelError`]; the previous preset stays.
    pub fn set_preset(&mut self, mut preset: Preset) -> Result<(), ModelError> {
        preset.simulation.wind = self.preset.simulation.wind.clone();
        self.rebuild(preset)
    }

    /// Fur length as a fraction of the mesh's bounding radius (the preset's `length`).
    ///
    /// # Errors
    /// [`ModelError`] outside `(0, 2]`; the previous length stays.
    pub fn set_length(&mut self, length: f32) -> Result<(), ModelError> {
        let mut preset = self.preset.clone();
        preset.length = length;
        self.rebuild(preset)
    }

    /// One colour for every strand (`#rrggbb`); textures must be remade after this.
    ///
    /// # Errors
    /// [`ModelError::Control`] for text that is not a colour.
    pub fn set_colour(&mut self, hex: &str) -> Result<(), ModelError> {
        let colour = Rgb::parse(hex).map_err(ModelError::Control)?;
        self.preset.colour.mode = pelt_core::texture::ColourMode::Single;
        self.preset.colour.colour = colour;
        Ok(())
    }

    /// Wind of `strength` (gravity units) blowing toward `direction_deg` in the ground plane
    /// (0 = +X, 90 = +Z).
    ///
    /// # Errors
    /// [`ModelError`] for a negative or non-finite strength or angle; the wind stays.
    pub fn set_wind(&mut self, strength: f32, direction_deg: f32) -> Result<(), ModelError> {
        if !direction_deg.is_finite() {
            return Err(ModelError::Control(format!("wind direction must be finite, got {direction_deg}")));
        }
        let mut wind = self.preset.simulation.wind.clone();
        let angle = direction_deg.to_radians();
        wind.direction = Vec3::new(angle.cos(), 0.0, angle.sin());
        wind.strength = strength;
        self.stepper.simulation_mut().set_wind(&wind)?;
        if let Some(herd) = &mut self.herd {
            herd.set_wind(&wind)?;
        }
        self.preset.simulation.wind = wind;
        Ok(())
    }

    fn rebuild(&mut self, preset: Preset) -> Result<(), ModelError> {
        preset.validate()?;
        let structure = grow(self.structure.mesh.clone(), self.scene, &preset)?;
        let mut stepper = stepper(&structure, &preset, self.walking.as_ref())?;
        let herd = self.herd_rig.as_ref().map(|rig| make_herd(&structure, &preset, rig, &mut stepper)).transpose()?;
        self.herd = herd;
        self.preset = preset;
        self.structure = structure;
        self.stepper = stepper;
        self.touches.clear();
        self.tools = Tools::default();
        Ok(())
    }

    /// What a pointer landing on the fur does from now on; every pointer on the fur lets go.
    pub fn set_tool(&mut self, tool: Tool) {
        for held in &mut self.touches {
            held.touch.released_at_secs.get_or_insert(self.clock_secs);
        }
        self.tools.release_all(&mut self.stepper, self.clock_secs);
        self.tool = tool;
    }

    /// The tool in use.
    #[must_use]
    pub fn tool(&self) -> Tool {
        self.tool
    }

    /// Dries the whole coat at once.
    pub fn dry(&mut self) {
        self.stepper.wetness_mut().set_uniform(0.0);
    }

    /// What the pointers do now.
    #[must_use]
    pub fn stats(&self) -> PointerStats {
        PointerStats {
            tool: self.tool,
            touches: self.touches_held(),
            fingers: self.tools.fingers(),
            grabbing: self.tools.grabbing(),
            wettest: self.stepper.wetness().values().iter().copied().fold(0.0, f32::max),
        }
    }

    /// Where the ray through `pixel` of a view of `size` meets the skin, and the ray's direction.
    fn pick(&self, pixel: Vec2, size: Vec2) -> (Vec3, Vec3, Option<Vec3>) {
        let (origin, direction) = self.orbit.ray(pixel, size);
        let hit = self.stepper.simulation().pick(&self.structure.mesh.triangles, origin, direction);
        (origin, direction, hit.map(|h| h.point))
    }

    fn mesh_radius(&self) -> f32 {
        self.structure.mesh.bounding_sphere().1
    }

    /// A pointer went down at `pixel` of a view of `size`: on the fur it takes the tool (true),
    /// elsewhere it does nothing (false: the page orbits with it instead).
    pub fn pointer_down(&mut self, pointer_id: i32, pixel: Vec2, size: Vec2) -> bool {
        let (_, direction, hit) = self.pick(pixel, size);
        let Some(hit) = hit else { return false };
        match self.tool {
            Tool::Touch => self.touch_down(pointer_id, pixel, size),
            Tool::Finger => self.tools.finger(pointer_id, direction, Some(hit)),
            Tool::Grab => {
                let (radius, now) = (self.mesh_radius(), self.clock_secs);
                // The grasp's values are finite and positive by construction; a refusal is no grasp.
                self.tools.grab_begin(&mut self.stepper, pointer_id, hit, direction, radius, now).unwrap_or(false)
            }
            Tool::Sponge => {
                self.tools.sponge(pointer_id, Some(hit));
                true
            }
        }
    }

    /// A pointer moved, pressed or (for the finger) hovering: true when it acts on the fur.
    pub fn pointer_move(&mut self, pointer_id: i32, pixel: Vec2, size: Vec2) -> bool {
        match self.tool {
            Tool::Touch => self.touch_move(pointer_id, pixel, size),
            Tool::Finger => {
                let (_, direction, hit) = self.pick(pixel, size);
                self.tools.finger(pointer_id, direction, hit)
            }
            Tool::Grab => {
                let (origin, direction) = self.orbit.ray(pixel, size);
                self.tools.grab_move(&mut self.stepper, pointer_id, origin, direction).unwrap_or(false)
            }
            Tool::Sponge => {
                if !self.tools.has_sponge(pointer_id) {
                    return false;
                }
                let (_, _, hit) = self.pick(pixel, size);
                self.tools.sponge(pointer_id, hit);
                true
            }
        }
    }

    /// Whether `pointer_id` acts on the fur now (patting, a finger, the grasp or a sponge).
    #[must_use]
    pub fn pointer_held(&self, pointer_id: i32) -> bool {
        self.touches.iter().any(|t| t.pointer_id == pointer_id && t.touch.released_at_secs.is_none())
            || self.tools.has_grab(pointer_id)
            || self.tools.has_sponge(pointer_id)
    }

    fn touch_down(&mut self, pointer_id: i32, pixel: Vec2, size: Vec2) -> bool {
        let (origin, direction) = self.orbit.ray(pixel, size);
        let simulation = self.stepper.simulation();
        let Some(hit) = simulation.pick(&self.structure.mesh.triangles, origin, direction) else { return false };
        let radius = BRUSH_PER_RADIUS * self.structure.mesh.bounding_sphere().1;
        self.touches.retain(|t| t.pointer_id != pointer_id);
        let touch = Touch::new(hit.point, radius, simulation.roots());
        self.touches.push(PointerTouch { pointer_id, touch, plane_normal: -direction });
        true
    }

    /// A patting pointer moved: the fur under it is pushed along the drag. False when the
    /// pointer is not patting.
    fn touch_move(&mut self, pointer_id: i32, pixel: Vec2, size: Vec2) -> bool {
        let (origin, direction) = self.orbit.ray(pixel, size);
        let Some(held) =
            self.touches.iter_mut().find(|t| t.pointer_id == pointer_id && t.touch.released_at_secs.is_none())
        else {
            return false;
        };
        let denominator = direction.dot(held.plane_normal);
        if denominator.abs() > 1e-6 {
            let t = (held.touch.point - origin).dot(held.plane_normal) / denominator;
            let point = origin + direction * t;
            if t > 0.0 && point.is_finite() {
                held.touch.drag = point;
            }
        }
        true
    }

    /// A pointer went up, was cancelled or left: its touch fades out as the preset says, its
    /// finger lifts, its grasp opens, its sponge comes off.
    pub fn pointer_up(&mut self, pointer_id: i32) {
        let now = self.clock_secs;
        for held in self.touches.iter_mut().filter(|t| t.pointer_id == pointer_id) {
            held.touch.released_at_secs.get_or_insert(now);
        }
        self.tools.release(&mut self.stepper, pointer_id, now);
    }

    /// Pointers patting now (held, not fading).
    #[must_use]
    pub fn touches_held(&self) -> usize {
        self.touches.iter().filter(|t| t.touch.released_at_secs.is_none()).count()
    }

    /// Moves the page's clock by `frame_secs` of wall time (capped, so a tab coming back from
    /// the background does not fast-forward), writes the pointers' touches into the
    /// simulation's force field, its fingers into its colliders and its sponges into the
    /// wetness: the time the frame driver then advances the stepper to.
    ///
    /// # Errors
    /// [`ModelError::Sim`] for a finger the simulation refuses.
    pub fn tick(&mut self, frame_secs: f64) -> Result<f64, ModelError> {
        if frame_secs.is_finite() && frame_secs > 0.0 {
            self.clock_secs += frame_secs.min(MAX_FRAME_SECS);
        }
        let params = &self.preset.simulation.touch;
        let (strength, release_secs, now) = (params.strength, params.release_secs, self.clock_secs);
        self.touches.retain(|t| t.touch.presence(now, release_secs) > 0.0);
        let field = self.stepper.simulation_mut().field_mut();
        field.fill(Vec3::ZERO);
        for held in &self.touches {
            held.touch.apply(strength, held.touch.presence(now, release_secs), field.values_mut());
        }
        let radius = self.mesh_radius();
        self.tools.apply(&mut self.stepper, radius, now)?;
        Ok(self.clock_secs)
    }

    /// A frame without a GPU: [`Model::tick`], then the stepper (and the herd's) on the CPU.
    ///
    /// # Errors
    /// [`ModelError::Sim`] for a step the simulation refuses.
    pub fn simulate(&mut self, frame_secs: f64) -> Result<(), ModelError> {
        let time_secs = self.tick(frame_secs)?;
        self.stepper.advance_to(time_secs)?;
        if let Some(herd) = &mut self.herd {
            herd.advance_to(time_secs)?;
        }
        Ok(())
    }

    /// The try-on body posed at the page's clock, where the stepper poses the skirt (the walk's
    /// clock is the simulation's): its positions and normals; `None` on other scenes.
    pub fn pose_body(&mut self) -> Option<(&[Vec3], &[Vec3])> {
        let clock_secs = self.clock_secs;
        self.walking.as_mut().map(|w| w.pose(clock_secs))
    }

    /// Where the walk is in its cycle (seconds from its start; a herd's members each add their
    /// own phase), `None` without a walking body or herd.
    #[must_use]
    pub fn walk_secs(&self) -> Option<f64> {
        let cycle = self.walk_cycle_secs()?;
        Some(if cycle > 0.0 { self.clock_secs.rem_euclid(cycle) } else { 0.0 })
    }

    /// The walk cycle's length in seconds, `None` without a walking body or herd.
    #[must_use]
    pub fn walk_cycle_secs(&self) -> Option<f64> {
        match (&self.walking, &self.herd) {
            (Some(walking), _) => Some(f64::from(walking.cycle_secs())),
            (None, Some(herd)) => Some(herd.cycle_secs()),
            (None, None) => None,
        }
    }
}

/// The herd scene's Foxes walking `rig`'s Walk, `first` the first of them.
fn make_herd(structure: &FurStructure, preset: &Preset, rig: &Rig, first: &mut FurStepper) -> Result<Herd, ModelError> {
    let walk = rig.find_animation("Walk").map_err(|e| ModelError::Control(format!("{FOX_NAME}: {e}")))?;
    Herd::new((structure, preset), (rig, walk), first)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SIZE: Vec2 = Vec2::new(800.0, 600.0);
    const FRAME_SECS: f64 = 1.0 / 30.0;

    fn bunny() -> Model {
        Model::new(SceneChoice::Bunny, Preset::default(), SIZE.x / SIZE.y).unwrap()
    }

    /// Tip of every strand.
    fn tips(model: &Model) -> Vec<Vec3> {
        let v = model.structure.vertex_count();
        model.stepper.simulation().positions()[model.structure.layers as usize * v..].to_vec()
    }

    /// The pixel of a base vertex that faces the camera and is the first thing its pixel's ray
    /// meets, so a pointer there pats that vertex's fur.
    fn pixel_of_visible_vertex(model: &Model, pick_from: usize) -> (usize, Vec2) {
        let camera = model.orbit.camera();
        let clip_from_world = camera.clip_from_world(SIZE.x / SIZE.y);
        let mesh = &model.structure.mesh;
        (pick_from..mesh.positions.len())
            .find_map(|j| {
                let root = mesh.positions[j];
                let facing = mesh.normals[j].dot((camera.eye - root).normalize()) > 0.7;
                let ndc = clip_from_world.project_point3(root);
                let pixel = Vec2::new((ndc.x + 1.0) * 0.5 * SIZE.x, (1.0 - ndc.y) * 0.5 * SIZE.y);
                let (origin, direction) = model.orbit.ray(pixel, SIZE);
                let hit = model.stepper.simulation().pick(&mesh.triangles, origin, direction)?;
                (facing && hit.point.distance(root) < 1e-3 * mesh.bounding_sphere().1).then_some((j, pixel))
            })
            .expect("a visible vertex")
    }

    #[test]
    fn a_pat_moves_the_fur_near_the_pointer_and_nothing_elsewhere_and_release_restores_it() {
        let mut patted = bunny();
        let mut untouched = bunny();
        let (j, pixel) = pixel_of_visible_vertex(&patted, 0);
        assert!(patted.pointer_down(7, pixel, SIZE));
        assert!(patted.pointer_move(7, pixel + Vec2::new(60.0, 0.0), SIZE));
        assert_eq!(patted.touches_held(), 1);
        for _ in 0..10 {
            patted.simulate(FRAME_SECS).unwrap();
            untouched.simulate(FRAME_SECS).unwrap();
        }
        let radius = BRUSH_PER_RADIUS * patted.structure.mesh.bounding_sphere().1;
        let root = patted.structure.mesh.positions[j];
        let (a, b) = (tips(&patted), tips(&untouched));
        let moved = a[j].distance(b[j]);
        assert!(moved > 0.1 * patted.structure.lengths[j], "the patted strand moved only {moved}");
        for (k, root_k) in patted.structure.mesh.positions.iter().enumerate() {
            if root_k.distance(root) > radius * 1.001 {
                assert_eq!(a[k], b[k], "strand {k} outside the touch moved");
            }
        }
        patted.pointer_up(7);
        assert_eq!(patted.touches_held(), 0);
        for _ in 0..3 {
            patted.simulate(FRAME_SECS).unwrap();
            untouched.simulate(FRAME_SECS).unwrap();
        }
        // The default preset restores at once on release; the fur is exactly the untouched fur.
        assert_eq!(tips(&patted), tips(&untouched));
    }

    #[test]
    fn two_pointers_pat_two_places_at_once_and_a_miss_pats_nothing() {
        let mut model = bunny();
        let (first, first_px) = pixel_of_visible_vertex(&model, 0);
        let far = model.structure.mesh.positions[first];
        let radius = BRUSH_PER_RADIUS * model.structure.mesh.bounding_sphere().1;
        let mut from = 0;
        let (second, second_px) = loop {
            let (k, px) = pixel_of_visible_vertex(&model, from);
            if model.structure.mesh.positions[k].distance(far) > 3.0 * radius {
                break (k, px);
            }
            from = k + 1;
        };
        let mut untouched = bunny();
        assert!(!model.pointer_down(3, Vec2::new(2.0, 2.0), SIZE), "the corner of the view misses the bunny");
        assert!(!model.pointer_move(3, Vec2::new(40.0, 2.0), SIZE));
        assert!(model.pointer_down(1, first_px, SIZE) && model.pointer_down(2, second_px, SIZE));
        model.pointer_move(1, first_px + Vec2::new(0.0, 50.0), SIZE);
        model.pointer_move(2, second_px + Vec2::new(50.0, 0.0), SIZE);
        assert_eq!(model.touches_held(), 2);
        for _ in 0..10 {
            model.simulate(FRAME_SECS).unwrap();
            untouched.simulate(FRAME_SECS).unwrap();
        }
        let (a, b) = (tips(&model), tips(&untouched));
        for j in [first, second] {
            assert!(a[j].distance(b[j]) > 0.1 * model.structure.lengths[j], "strand {j} was not patted");
        }
        assert!(a.iter().chain(model.stepper.simulation().positions()).all(|p| p.is_finite()));
    }

    #[test]
    fn bad_control_values_are_messages_and_keep_the_fur() {
        let mut model = bunny();
        let before = model.structure.positions.clone();
        assert!(model.set_length(0.0).unwrap_err().to_string().contains("length"));
        assert!(model.set_length(f32::NAN).is_err());
        assert_eq!(model.structure.positions, before);
        assert!(model.set_wind(-1.0, 0.0).is_err());
        assert!(model.set_wind(1.0, f32::INFINITY).is_err());
        assert!(model.set_colour("not a colour").is_err());
        model.set_length(0.2).unwrap();
        assert_ne!(model.structure.positions, before);
        let lengths = &model.structure.lengths;
        let radius = model.structure.mesh.bounding_sphere().1;
        assert!(lengths.iter().all(|l| (l - 0.2 * radius).abs() < 1e-4 * radius));
    }

    #[test]
    fn wind_blows_the_tips_its_way_and_the_try_on_has_a_body_and_a_furred_skirt() {
        let mut calm = bunny();
        let mut windy = bunny();
        windy.set_wind(3.0, 90.0).unwrap();
        for _ in 0..20 {
            calm.simulate(FRAME_SECS).unwrap();
            windy.simulate(FRAME_SECS).unwrap();
        }
        let push: Vec3 = tips(&windy).iter().zip(tips(&calm)).map(|(w, c)| *w - c).sum();
        assert!(push.z > push.x.abs() && push.z > 0.0, "wind toward +Z pushed {push}");

        let mut model = bunny();
        let bunny_vertices = model.structure.vertex_count();
        model.set_wind(2.0, 0.0).unwrap();
        model.set_scene(SceneChoice::TryOn, 1.0).unwrap();
        assert!(model.body.is_some());
        assert_ne!(model.structure.vertex_count(), bunny_vertices);
        assert_eq!(model.preset.simulation.wind.strength, 2.0, "the wind stays across scenes");
        model.simulate(FRAME_SECS).unwrap();
        assert!(model.stepper.simulation().positions().iter().all(|p| p.is_finite()));
        assert_eq!(SceneChoice::from_name("tryon"), Some(SceneChoice::TryOn));
        assert_eq!(SceneChoice::from_name("cat"), None);
    }

    #[test]
    fn the_try_on_body_walks_and_the_skirt_and_its_colliders_walk_with_it() {
        let mut model = Model::new(SceneChoice::TryOn, Preset::default(), 1.0).unwrap();
        let body = model.body.clone().expect("a body");
        let height = body.bounds().1.y - body.bounds().0.y;
        let v = model.structure.vertex_count();
        let capsule = |c: &pelt_core::sim::contact::Collider| {
            c.id.wrapping_sub(pelt_core::sim::stepper::BODY_COLLIDER_IDS) < 0x1_0000
        };
        model.simulate(FRAME_SECS).unwrap();
        let colliders = model.stepper.simulation().colliders().to_vec();
        assert!(colliders.iter().filter(|c| capsule(c)).count() >= 10, "the body's capsules collide with the fur");
        let legs = model.pose_body().unwrap().0.to_vec();
        let skirt = model.stepper.simulation().positions()[..v].to_vec();
        // Half a step on (the walk's clock is the page's).
        for _ in 0..15 {
            model.simulate(FRAME_SECS).unwrap();
        }
        assert!((model.walk_secs().unwrap() - 16.0 * FRAME_SECS).abs() < 1e-9);
        let moved = |a: &[Vec3], b: &[Vec3]| a.iter().zip(b).map(|(p, q)| p.distance(*q)).fold(0.0, f32::max);
        let legs_moved = moved(&legs, model.pose_body().unwrap().0);
        let skirt_moved = moved(&skirt, &model.stepper.simulation().positions()[..v]);
        let capsules_moved = model
            .stepper
            .simulation()
            .colliders()
            .iter()
            .filter(|c| capsule(c))
            .zip(colliders.iter().filter(|c| capsule(c)))
            .any(|(now, before)| now != before);
        assert!(legs_moved > 0.1 * height, "the body walks: a vertex moved {legs_moved}");
        assert!(skirt_moved > 0.03 * height, "the skirt walks with it: a vertex moved {skirt_moved}");
        assert!(capsules_moved, "the capsules walk with the body");
        // A rebuilt coat (new length) keeps the walk and the colliders.
        model.set_length(0.1).unwrap();
        model.simulate(FRAME_SECS).unwrap();
        assert!(model.stepper.moves() && model.stepper.simulation().colliders().iter().any(capsule));
        assert!(model.stepper.simulation().positions().iter().all(|p| p.is_finite()));
    }

    #[test]
    fn a_background_tab_does_not_fast_forward_and_zoom_stays_bounded() {
        let mut model = bunny();
        model.simulate(3600.0).unwrap();
        assert!(model.clock_secs <= MAX_FRAME_SECS);
        model.simulate(f64::NAN).unwrap();
        assert!(model.stepper.simulation().positions().iter().all(|p| p.is_finite()));
        let framed = model.orbit.distance;
        for _ in 0..100 {
            model.zoom(0.5);
        }
        assert!(model.orbit.distance >= framed * 0.1);
        model.zoom(f32::NAN);
        assert!(model.orbit.distance.is_finite());
    }
}
