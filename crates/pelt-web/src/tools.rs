//! The page's tools besides patting: a finger (a capsule collider along the pointer's ray), a
//! grab (press and hold grasps the fur, dragging moves the grip) and a sponge (wets the fur
//! under the pointer; it dries as the preset's `[wet]` says). Each pointer that lands on the fur
//! holds one; nothing here touches a browser API.

use glam::{Quat, Vec3};
use pelt_core::sim::{Collider, FurStepper, GraspParams, Shape};

use crate::model::ModelError;

/// The finger's radius, as a fraction of the furred mesh's bounding radius.
const FINGER_PER_RADIUS: f32 = 0.1;
/// Half the finger's straight part (its tip at the skin, the rest toward the eye), same unit.
const FINGER_HALF_LENGTH_PER_RADIUS: f32 = 0.3;
/// Strands rooted within this of the grip are grasped, same unit.
const GRAB_PER_RADIUS: f32 = 0.15;
/// The sponge's reach, same unit.
const SPONGE_PER_RADIUS: f32 = 0.2;
/// Collider ids of the fingers: this plus the pointer's id (the stepper's body uses its own).
const FINGER_COLLIDER_IDS: u32 = 0xf1_0000;

/// What a pointer that lands on the fur does.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Tool {
    /// Pats: a touch pushing the fur along the drag.
    #[default]
    Touch,
    /// A finger (capsule) over the fur: it pushes the fur aside where the pointer is.
    Finger,
    /// Press and hold grasps the fur; dragging moves the grip; release lets it spring back.
    Grab,
    /// Wets the fur under the pointer while pressed.
    Sponge,
}

impl Tool {
    /// Every tool, in the page's order.
    pub const ALL: [Self; 4] = [Self::Touch, Self::Finger, Self::Grab, Self::Sponge];

    /// `"touch"`, `"finger"`, `"grab"` or `"sponge"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Touch => "touch",
            Self::Finger => "finger",
            Self::Grab => "grab",
            Self::Sponge => "sponge",
        }
    }

    /// The tool called `name`.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|t| t.name() == name)
    }
}

/// A finger: where its pointer's ray meets the skin, and the ray's direction.
#[derive(Clone, Copy, Debug)]
struct Finger {
    pointer_id: i32,
    hit: Vec3,
    direction: Vec3,
}

/// The grasp held by one pointer: the plane facing the camera through the grasp point, which
/// the grip moves across.
#[derive(Clone, Copy, Debug)]
struct Grab {
    pointer_id: i32,
    point: Vec3,
    plane_normal: Vec3,
}

/// A sponge pressed by one pointer, where its ray meets the skin (`None` off the fur).
#[derive(Clone, Copy, Debug)]
struct Sponge {
    pointer_id: i32,
    point: Option<Vec3>,
}

/// Fingers, the grab and sponges on the fur now.
#[derive(Debug, Default)]
pub(crate) struct Tools {
    fingers: Vec<Finger>,
    grab: Option<Grab>,
    sponges: Vec<Sponge>,
    /// Whether the simulation was last given fingers (so lifting the last one removes it).
    fingers_given: bool,
}

impl Tools {
    /// A finger for `pointer_id` where its ray `(origin, direction)` meets the skin at `hit`
    /// (`None`: off the fur, the finger lifts). Returns whether it is on the fur.
    pub fn finger(&mut self, pointer_id: i32, direction: Vec3, hit: Option<Vec3>) -> bool {
        self.fingers.retain(|f| f.pointer_id != pointer_id);
        if let Some(hit) = hit {
            self.fingers.push(Finger { pointer_id, hit, direction });
        }
        hit.is_some()
    }

    /// Starts a grasp at `hit` for `pointer_id` (one at a time: false while another pointer holds
    /// one), dragged across the plane facing `direction`.
    ///
    /// # Errors
    /// [`ModelError::Sim`] for values the simulation refuses.
    pub fn grab_begin(
        &mut self,
        stepper: &mut FurStepper,
        pointer_id: i32,
        hit: Vec3,
        direction: Vec3,
        mesh_radius: f32,
        time_secs: f64,
    ) -> Result<bool, ModelError> {
        if self.grab.is_some_and(|g| g.pointer_id != pointer_id) {
            return Ok(false);
        }
        let radius = GRAB_PER_RADIUS * mesh_radius;
        stepper.simulation_mut().grasp_begin(hit, radius, 0.0, GraspParams::default(), time_secs)?;
        self.grab = Some(Grab { pointer_id, point: hit, plane_normal: -direction });
        Ok(true)
    }

    /// Moves the grip of `pointer_id`'s grasp to where the ray `(origin, direction)` crosses its
    /// plane. False when that pointer holds no grasp.
    ///
    /// # Errors
    /// [`ModelError::Sim`] for a point the simulation refuses.
    pub fn grab_move(
        &mut self,
        stepper: &mut FurStepper,
        pointer_id: i32,
        origin: Vec3,
        direction: Vec3,
    ) -> Result<bool, ModelError> {
        let Some(grab) = self.grab.filter(|g| g.pointer_id == pointer_id) else { return Ok(false) };
        let along = direction.dot(grab.plane_normal);
        if along.abs() > 1e-6 {
            let t = (grab.point - origin).dot(grab.plane_normal) / along;
            let grip = origin + direction * t;
            if t > 0.0 && grip.is_finite() {
                stepper.simulation_mut().grasp_move(grip)?;
            }
        }
        Ok(true)
    }

    /// Presses (or moves) `pointer_id`'s sponge to `hit` (`None`: off the fur, it wets nothing).
    pub fn sponge(&mut self, pointer_id: i32, hit: Option<Vec3>) {
        match self.sponges.iter_mut().find(|s| s.pointer_id == pointer_id) {
            Some(sponge) => sponge.point = hit,
            None => self.sponges.push(Sponge { pointer_id, point: hit }),
        }
    }

    /// Whether `pointer_id` holds a sponge.
    pub fn has_sponge(&self, pointer_id: i32) -> bool {
        self.sponges.iter().any(|s| s.pointer_id == pointer_id)
    }

    /// Whether `pointer_id` holds the grasp.
    pub fn has_grab(&self, pointer_id: i32) -> bool {
        self.grab.is_some_and(|g| g.pointer_id == pointer_id)
    }

    /// `pointer_id` went up or left: its finger lifts, its grasp opens at `time_secs`, its
    /// sponge comes off.
    pub fn release(&mut self, stepper: &mut FurStepper, pointer_id: i32, time_secs: f64) {
        self.fingers.retain(|f| f.pointer_id != pointer_id);
        self.sponges.retain(|s| s.pointer_id != pointer_id);
        if self.grab.is_some_and(|g| g.pointer_id == pointer_id) {
            stepper.simulation_mut().grasp_end(time_secs);
            self.grab = None;
        }
    }

    /// Every pointer lets go (the tool changed).
    pub fn release_all(&mut self, stepper: &mut FurStepper, time_secs: f64) {
        let ids: Vec<i32> = (self.fingers.iter().map(|f| f.pointer_id))
            .chain(self.grab.map(|g| g.pointer_id))
            .chain(self.sponges.iter().map(|s| s.pointer_id))
            .collect();
        for id in ids {
            self.release(stepper, id, time_secs);
        }
    }

    /// Fingers on the fur now.
    pub fn fingers(&self) -> usize {
        self.fingers.len()
    }

    /// Whether a pointer holds a grasp.
    pub fn grabbing(&self) -> bool {
        self.grab.is_some()
    }

    /// Before the step at `time_secs`: the fingers become the simulation's colliders there, and
    /// each pressed sponge wets the fur under it.
    ///
    /// # Errors
    /// [`ModelError::Sim`] for a collider the simulation refuses.
    pub fn apply(&mut self, stepper: &mut FurStepper, mesh_radius: f32, time_secs: f64) -> Result<(), ModelError> {
        if !self.fingers.is_empty() || self.fingers_given {
            // Others' colliders (the walking body's capsules) stay.
            let mut colliders: Vec<Collider> =
                stepper.simulation().colliders().iter().filter(|c| !is_finger(c.id)).cloned().collect();
            colliders.extend(self.fingers.iter().map(|f| finger_collider(f, mesh_radius, time_secs)));
            stepper.simulation_mut().set_colliders(&colliders)?;
            self.fingers_given = !self.fingers.is_empty();
        }
        let points = self.sponges.iter().filter_map(|s| s.point);
        for point in points {
            stepper.sponge(point, SPONGE_PER_RADIUS * mesh_radius, 1.0);
        }
        Ok(())
    }
}

/// Whether collider `id` is one of the fingers'.
fn is_finger(id: u32) -> bool {
    id.wrapping_sub(FINGER_COLLIDER_IDS) <= 0xffff
}

/// The finger as a capsule along its ray: the tip's centre at the skin, the rest toward the eye.
fn finger_collider(finger: &Finger, mesh_radius: f32, time_secs: f64) -> Collider {
    let half_length = FINGER_HALF_LENGTH_PER_RADIUS * mesh_radius;
    let toward_eye = -finger.direction;
    let rotation = Quat::from_rotation_arc(Vec3::Y, toward_eye);
    let shape = Shape::Capsule { radius: FINGER_PER_RADIUS * mesh_radius, half_length };
    let id = FINGER_COLLIDER_IDS.wrapping_add(finger.pointer_id as u32 & 0xffff);
    Collider::at(id, shape, time_secs, finger.hit + toward_eye * half_length, rotation)
}

#[cfg(test)]
mod tests {
    use glam::Vec2;
    use pelt_core::Preset;

    use super::*;
    use crate::model::{Model, SceneChoice};

    const SIZE: Vec2 = Vec2::new(800.0, 600.0);
    const FRAME_SECS: f64 = 1.0 / 30.0;

    fn bunny(tool: Tool) -> Model {
        let mut model = Model::new(SceneChoice::Bunny, Preset::default(), SIZE.x / SIZE.y).unwrap();
        model.set_tool(tool);
        model
    }

    fn tips(model: &Model) -> Vec<Vec3> {
        let v = model.structure.vertex_count();
        model.stepper.simulation().positions()[model.structure.layers as usize * v..].to_vec()
    }

    /// The view's centre pixel and where its ray meets the bunny.
    fn centre_hit(model: &Model) -> (Vec2, Vec3, Vec3) {
        let pixel = SIZE * 0.5;
        let (origin, direction) = model.orbit.ray(pixel, SIZE);
        let hit = model.stepper.simulation().pick(&model.structure.mesh.triangles, origin, direction).unwrap();
        (pixel, hit.point, direction)
    }

    /// Distance from `p` to the segment `a..b` (its own closest-point formula).
    fn to_segment(p: Vec3, a: Vec3, b: Vec3) -> f32 {
        let ab = b - a;
        let t = ((p - a).dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        p.distance(a + ab * t)
    }

    #[test]
    fn the_finger_parts_the_fur_along_the_ray_and_lifting_it_lets_the_fur_return() {
        let mut model = bunny(Tool::Finger);
        let mut untouched = bunny(Tool::Touch);
        let (pixel, hit, direction) = centre_hit(&model);
        assert!(model.pointer_move(4, pixel, SIZE), "hovering over the bunny places the finger");
        for _ in 0..20 {
            model.simulate(FRAME_SECS).unwrap();
            untouched.simulate(FRAME_SECS).unwrap();
        }
        assert_eq!(model.stats().fingers, 1);
        let mesh_radius = model.structure.mesh.bounding_sphere().1;
        let radius = FINGER_PER_RADIUS * mesh_radius;
        let (a, b) = (hit, hit - direction * 2.0 * FINGER_HALF_LENGTH_PER_RADIUS * mesh_radius);
        let (pushed, free) = (tips(&model), tips(&untouched));
        let mut inside_before = 0;
        for (j, (p, q)) in pushed.iter().zip(&free).enumerate() {
            if to_segment(*q, a, b) < 0.8 * radius {
                inside_before += 1;
            }
            assert!(to_segment(*p, a, b) > 0.9 * radius, "tip {j} lies inside the finger");
            let root = model.structure.mesh.positions[j];
            if root.distance(hit) > radius + 2.0 * model.structure.lengths[j] {
                assert_eq!(p, q, "strand {j} far from the finger moved");
            }
        }
        assert!(inside_before > 0, "no tip stood where the finger went: the test proves nothing");
        // Off the fur the finger lifts, and the fur stands as if it had never been there.
        assert!(!model.pointer_move(4, Vec2::new(2.0, 2.0), SIZE));
        for _ in 0..30 {
            model.simulate(FRAME_SECS).unwrap();
            untouched.simulate(FRAME_SECS).unwrap();
        }
        assert_eq!(model.stats().fingers, 0);
        let (after, free) = (tips(&model), tips(&untouched));
        let worst = after.iter().zip(&free).map(|(p, q)| p.distance(*q)).fold(0.0, f32::max);
        assert!(worst < 1e-3 * mesh_radius, "the fur is still {worst} from rest after the finger lifted");
    }

    #[test]
    fn a_grab_holds_the_fur_and_drags_it_toward_the_grip_and_release_lets_go() {
        let mut model = bunny(Tool::Grab);
        let (pixel, hit, _) = centre_hit(&model);
        assert!(model.pointer_down(9, pixel, SIZE));
        assert!(!model.pointer_down(10, pixel, SIZE), "a second pointer takes no second grasp");
        assert!(model.pointer_move(9, pixel + Vec2::new(0.0, -60.0), SIZE));
        for _ in 0..20 {
            model.simulate(FRAME_SECS).unwrap();
        }
        let grip = model.stepper.simulation().grasp().expect("a grasp").grip;
        assert!(grip.distance(hit) > 0.0, "the grip did not move with the pointer");
        let grasp_radius = GRAB_PER_RADIUS * model.structure.mesh.bounding_sphere().1;
        let mut rest = bunny(Tool::Touch);
        for _ in 0..20 {
            rest.simulate(FRAME_SECS).unwrap();
        }
        let (held, free) = (tips(&model), tips(&rest));
        let mut closer = 0;
        let mut near = 0;
        for (j, root) in model.structure.mesh.positions.iter().enumerate() {
            if root.distance(hit) < 0.5 * grasp_radius {
                near += 1;
                if held[j].distance(grip) < free[j].distance(grip) - 0.1 * model.structure.lengths[j] {
                    closer += 1;
                }
            }
        }
        assert!(near > 0 && closer == near, "{closer} of {near} grasped tips came toward the grip");
        assert!(model.stats().grabbing);
        model.pointer_up(9);
        assert!(!model.stats().grabbing);
        let released = model.stepper.simulation().grasp().expect("springing back").released_at_secs;
        assert!(released.is_some());
        assert!(model.stepper.simulation().positions().iter().all(|p| p.is_finite()));
    }

    #[test]
    fn the_sponge_wets_the_fur_under_it_only_and_the_fur_dries_at_the_presets_rate() {
        let mut model = bunny(Tool::Sponge);
        let (pixel, hit, _) = centre_hit(&model);
        // A tap (one frame) on a coat dry since the start wets it.
        assert!(model.pointer_down(2, pixel, SIZE));
        model.simulate(FRAME_SECS).unwrap();
        model.pointer_up(2);
        let reach = SPONGE_PER_RADIUS * model.structure.mesh.bounding_sphere().1;
        let wet = model.stepper.wetness().values().to_vec();
        for (j, root) in model.structure.mesh.positions.iter().enumerate() {
            let d = root.distance(hit);
            if d > reach * 1.001 {
                assert_eq!(wet[j], 0.0, "vertex {j} outside the sponge got wet");
            } else if d < 0.2 * reach {
                assert!(wet[j] > 0.8, "vertex {j} under the sponge has wetness {}", wet[j]);
            }
        }
        // The default preset dries 0.05 a second: two seconds later the wettest is 0.1 drier.
        let wettest = wet.iter().copied().fold(0.0, f32::max);
        for _ in 0..60 {
            model.simulate(FRAME_SECS).unwrap();
        }
        let dried = model.stepper.wetness().values().iter().copied().fold(0.0, f32::max);
        let drying = model.preset.wet.drying_per_sec;
        assert!((wettest - dried - 2.0 * drying).abs() < 0.02, "{wettest} dried to {dried} in 2 s");
        // Dried at once, then left dry a while: a new tap still wets (no drying replayed over it).
        model.dry();
        for _ in 0..60 {
            model.simulate(FRAME_SECS).unwrap();
        }
        assert!(model.pointer_down(2, pixel, SIZE));
        model.simulate(FRAME_SECS).unwrap();
        model.pointer_up(2);
        assert!(model.stats().wettest > 0.95, "a tap after a dry spell wets only {}", model.stats().wettest);
    }

    #[test]
    fn tool_names_round_trip_and_a_tool_change_lets_every_pointer_go() {
        for tool in Tool::ALL {
            assert_eq!(Tool::from_name(tool.name()), Some(tool));
        }
        assert_eq!(Tool::from_name("hammer"), None);
        let mut model = bunny(Tool::Grab);
        let (pixel, _, _) = centre_hit(&model);
        assert!(model.pointer_down(1, pixel, SIZE));
        model.set_tool(Tool::Finger);
        assert!(!model.stats().grabbing);
        assert!(model.pointer_down(1, pixel, SIZE));
        assert_eq!(model.stats().fingers, 1);
        model.set_tool(Tool::Touch);
        assert_eq!(model.stats().fingers, 0);
    }
}
