//! The panel's contact section and what it drives: a ball dragged through the fur (a collider
//! the simulation pushes the fur out of) and a grab (press on the fur: a hand closes on it;
//! drag: the grip follows the pointer; release: it lets go and the tuft springs back).

use glam::{Quat, Vec3};
use pelt_core::sim::{Collider, GraspParams, Shape, SimError, Simulation};

/// The viewer's ball's collider id, apart from a script's (`SCENE_COLLIDER_IDS`).
pub const BALL_ID: u32 = 0x7669_0001;

/// What left-drag on the fur does besides patting it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ContactTool {
    #[default]
    Off,
    /// Press puts a ball in the fur under the pointer, drag moves it; it stays where let go.
    Ball,
    /// Press closes a hand on the fur, drag lifts the tuft, release lets go.
    Grab,
}

/// The contact section's settings.
#[derive(Clone, Debug, PartialEq)]
pub struct ContactControls {
    pub tool: ContactTool,
    /// The ball's radius as a share of the mesh's bounding radius.
    pub ball_per_radius: f32,
    /// How much of the ball's sliding the touching fur follows.
    pub friction: f32,
    /// The grab's reach (strands rooted within it are held), a share of the mesh's radius.
    pub grab_per_radius: f32,
}

impl Default for ContactControls {
    fn default() -> Self {
        Self { tool: ContactTool::Off, ball_per_radius: 0.12, friction: 0.3, grab_per_radius: 0.1 }
    }
}

/// The size the pointer's circle shows for the tool: the ball's radius, or the grab's reach;
/// `None` when left-drag pats (the touch's size shows then).
pub fn tool_radius(controls: &ContactControls, mesh_radius: f32) -> Option<f32> {
    match controls.tool {
        ContactTool::Off => None,
        ContactTool::Ball => Some(controls.ball_per_radius * mesh_radius),
        ContactTool::Grab => Some(controls.grab_per_radius * mesh_radius),
    }
}

/// The contact section of the panel; true when the ball is to go (another tool, or removed).
pub fn contact_ui(ui: &mut egui::Ui, controls: &mut ContactControls) -> bool {
    let before = controls.tool;
    ui.horizontal(|ui| {
        ui.label("left-drag");
        ui.selectable_value(&mut controls.tool, ContactTool::Off, "pats");
        ui.selectable_value(&mut controls.tool, ContactTool::Ball, "moves a ball");
        ui.selectable_value(&mut controls.tool, ContactTool::Grab, "grabs");
    });
    ui.add(egui::Slider::new(&mut controls.ball_per_radius, 0.02..=0.5).logarithmic(true).text("ball size"));
    ui.add(egui::Slider::new(&mut controls.friction, 0.0..=1.0).text("ball friction"));
    ui.add(egui::Slider::new(&mut controls.grab_per_radius, 0.02..=0.5).logarithmic(true).text("grab reach"));
    let removed = ui.button("remove the ball").clicked();
    removed || (before == ContactTool::Ball && controls.tool != ContactTool::Ball)
}

/// The pointer in the 3D view, as the contact tools read it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum PointerEvent {
    /// The primary button went down over the fur at `hit`, looking along `view_direction`.
    Press { hit: Vec3, view_direction: Vec3 },
    /// The pointer's ray while the button is held.
    Move { origin: Vec3, direction: Vec3 },
    /// The button came up.
    Release,
}

/// A drag in progress: the pointer moves the ball or the grip on the plane through the press
/// point facing the camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ContactDrag {
    tool: ContactTool,
    anchor: Vec3,
    plane_normal: Vec3,
}

impl ContactDrag {
    /// Where the ray meets the drag's plane (`None` along it or behind the eye).
    fn point(&self, origin: Vec3, direction: Vec3) -> Option<Vec3> {
        let along = direction.dot(self.plane_normal);
        if along.abs() <= 1e-6 {
            return None;
        }
        let distance = (self.anchor - origin).dot(self.plane_normal) / along;
        (distance >= 0.0 && distance.is_finite()).then(|| origin + direction * distance)
    }
}

/// The viewer's ball at `centre` at simulation time `time_secs`.
fn ball(controls: &ContactControls, mesh_radius: f32, centre: Vec3, time_secs: f64) -> Collider {
    let shape = Shape::Sphere { radius: controls.ball_per_radius * mesh_radius };
    Collider { friction: controls.friction, ..Collider::at(BALL_ID, shape, time_secs, centre, Quat::IDENTITY) }
}

/// Sets the simulation's colliders to its others and `ball` (none: removed).
fn set_ball(sim: &mut Simulation, ball: Option<Collider>) -> Result<(), SimError> {
    let mut colliders: Vec<Collider> = sim.colliders().iter().filter(|c| c.id != BALL_ID).cloned().collect();
    colliders.extend(ball);
    sim.set_colliders(&colliders)
}

/// Removes the viewer's ball, if there is one.
pub fn remove_ball(sim: &mut Simulation) -> Result<(), SimError> {
    if sim.colliders().iter().any(|c| c.id == BALL_ID) {
        set_ball(sim, None)?;
    }
    Ok(())
}

/// Drives the simulation from one pointer event with the tool `controls` selects; `drag` holds
/// the drag between events. Returns whether a drag is in progress (it takes the pointer from
/// the camera).
pub fn handle(
    sim: &mut Simulation,
    controls: &ContactControls,
    mesh_radius: f32,
    drag: &mut Option<ContactDrag>,
    event: PointerEvent,
) -> Result<bool, SimError> {
    let time_secs = sim.time_secs();
    match (event, *drag) {
        (PointerEvent::Press { hit, view_direction }, None) if controls.tool != ContactTool::Off => {
            let plane_normal = view_direction.normalize_or(Vec3::NEG_Z);
            *drag = Some(ContactDrag { tool: controls.tool, anchor: hit, plane_normal });
            match controls.tool {
                ContactTool::Ball => set_ball(sim, Some(ball(controls, mesh_radius, hit, time_secs)))?,
                _ => {
                    let reach = controls.grab_per_radius * mesh_radius;
                    sim.grasp_begin(hit, reach, 0.35 * reach, GraspParams::default(), time_secs)?;
                }
            }
        }
        (PointerEvent::Move { origin, direction }, Some(held)) => {
            if let Some(point) = held.point(origin, direction) {
                match held.tool {
                    ContactTool::Ball => set_ball(sim, Some(ball(controls, mesh_radius, point, time_secs)))?,
                    _ => sim.grasp_move(point)?,
                }
            }
        }
        (PointerEvent::Release, Some(held)) => {
            if held.tool == ContactTool::Grab {
                sim.grasp_end(time_secs);
            }
            *drag = None;
        }
        _ => {}
    }
    Ok(drag.is_some())
}

#[cfg(test)]
mod tests {
    use pelt_core::fur::FurLength;
    use pelt_core::{Builtin, FurParams, FurStructure, GrowthDirection, SimParams};

    use super::*;

    fn simulation() -> Simulation {
        let (mesh, _) = Builtin::Sphere.mesh();
        let params = FurParams { layers: 4, length: FurLength::Constant(0.2), direction: GrowthDirection::default() };
        let structure = FurStructure::new(mesh, &params).expect("a sphere grows fur");
        Simulation::new(&structure, &SimParams::default()).expect("default parameters")
    }

    /// Looking down -Z at the sphere's front.
    fn press() -> PointerEvent {
        PointerEvent::Press { hit: Vec3::new(0.0, 0.0, 1.0), view_direction: Vec3::NEG_Z }
    }

    fn ray_through(x: f32, y: f32) -> PointerEvent {
        PointerEvent::Move { origin: Vec3::new(x, y, 5.0), direction: Vec3::NEG_Z }
    }

    #[test]
    fn the_ball_follows_the_pointer_and_stays_where_let_go() {
        let mut sim = simulation();
        let controls = ContactControls { tool: ContactTool::Ball, ..ContactControls::default() };
        let mut drag = None;
        assert!(handle(&mut sim, &controls, 2.0, &mut drag, press()).unwrap());
        let ball = |sim: &Simulation| sim.colliders().iter().find(|c| c.id == BALL_ID).cloned().expect("a ball");
        let placed = ball(&sim);
        assert_eq!(placed.shape, Shape::Sphere { radius: 0.24 });
        assert_eq!(placed.pose_at(sim.time_secs()).0, Vec3::new(0.0, 0.0, 1.0), "in the fur where pressed");
        sim.advance_to(0.1);
        assert!(handle(&mut sim, &controls, 2.0, &mut drag, ray_through(0.4, -0.2)).unwrap());
        let moved = ball(&sim).pose_at(0.1).0;
        assert!(moved.distance(Vec3::new(0.4, -0.2, 1.0)) < 1e-6, "on the plane through the press: {moved}");
        assert!(!handle(&mut sim, &controls, 2.0, &mut drag, PointerEvent::Release).unwrap());
        sim.advance_to(0.5);
        assert!(ball(&sim).pose_at(0.5).0.distance(moved) < 1e-6, "stays where let go");
        remove_ball(&mut sim).unwrap();
        assert!(sim.colliders().is_empty());
    }

    #[test]
    fn a_grab_closes_lifts_and_lets_go() {
        let mut sim = simulation();
        let controls = ContactControls { tool: ContactTool::Grab, ..ContactControls::default() };
        let mut drag = None;
        sim.advance_to(0.2);
        assert!(handle(&mut sim, &controls, 2.0, &mut drag, press()).unwrap());
        let grasp = sim.grasp().expect("the hand closed").clone();
        assert_eq!((grasp.point, grasp.radius, grasp.closed_at_secs), (Vec3::new(0.0, 0.0, 1.0), 0.2, 0.2));
        assert!(grasp.hand_radius > 0.0 && grasp.released_at_secs.is_none());
        sim.advance_to(0.3);
        handle(&mut sim, &controls, 2.0, &mut drag, ray_through(0.1, 0.3)).unwrap();
        assert!(sim.grasp().unwrap().grip.distance(Vec3::new(0.1, 0.3, 1.0)) < 1e-6, "the grip follows");
        sim.advance_to(0.4);
        assert!(!handle(&mut sim, &controls, 2.0, &mut drag, PointerEvent::Release).unwrap());
        assert_eq!(sim.grasp().unwrap().released_at_secs, Some(0.4), "let go on release");
        assert!(sim.colliders().is_empty(), "a grab places no ball");
    }

    #[test]
    fn the_circle_shows_the_ball_or_the_grab_reach() {
        let mut controls =
            ContactControls { ball_per_radius: 0.2, grab_per_radius: 0.05, ..ContactControls::default() };
        assert_eq!(tool_radius(&controls, 2.0), None, "patting shows the touch's size");
        controls.tool = ContactTool::Ball;
        assert_eq!(tool_radius(&controls, 2.0), Some(0.4));
        let mut sim = simulation();
        let mut drag = None;
        handle(&mut sim, &controls, 2.0, &mut drag, press()).unwrap();
        assert_eq!(sim.colliders()[0].shape, Shape::Sphere { radius: tool_radius(&controls, 2.0).unwrap() });
        controls.tool = ContactTool::Grab;
        assert_eq!(tool_radius(&controls, 2.0), Some(0.1));
    }

    /// Paused (the clock stands), a dragged ball is drawn where it is dragged at once.
    #[test]
    fn a_ball_dragged_while_paused_shows_where_dragged() {
        let mut sim = simulation();
        let controls = ContactControls { tool: ContactTool::Ball, ..ContactControls::default() };
        let mut drag = None;
        sim.advance_to(0.1);
        handle(&mut sim, &controls, 2.0, &mut drag, press()).unwrap();
        sim.advance_to(0.5);
        handle(&mut sim, &controls, 2.0, &mut drag, ray_through(0.3, 0.1)).unwrap();
        handle(&mut sim, &controls, 2.0, &mut drag, ray_through(0.6, 0.2)).unwrap();
        let shown = sim.shown_colliders(sim.time_secs());
        assert_eq!(shown.len(), 1);
        assert!(shown[0].centre.distance(Vec3::new(0.6, 0.2, 1.0)) < 1e-6, "{}", shown[0].centre);
        assert!((shown[0].radius - controls.ball_per_radius * 2.0).abs() < 1e-6, "at full size");
    }

    #[test]
    fn off_does_nothing_and_a_ray_along_the_plane_is_ignored() {
        let mut sim = simulation();
        let mut drag = None;
        assert!(!handle(&mut sim, &ContactControls::default(), 2.0, &mut drag, press()).unwrap());
        assert!(sim.colliders().is_empty() && sim.grasp().is_none());
        let controls = ContactControls { tool: ContactTool::Ball, ..ContactControls::default() };
        handle(&mut sim, &controls, 2.0, &mut drag, press()).unwrap();
        let sideways = PointerEvent::Move { origin: Vec3::new(0.0, 0.0, 5.0), direction: Vec3::X };
        handle(&mut sim, &controls, 2.0, &mut drag, sideways).unwrap();
        assert_eq!(sim.colliders()[0].pose_at(0.0).0, Vec3::new(0.0, 0.0, 1.0));
    }
}
