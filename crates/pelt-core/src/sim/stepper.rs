//! [`FurStepper`]: one fur's simulation driven through time. It poses the base (a skinned clip, a
//! script's rigid motion, or a pose the host supplies), plays the script's wind and touch keys,
//! and steps the strands: the CPU half of every host's frame, in one place.

use glam::{Mat4, Quat, Vec3};

use super::SimParams;
use super::contact::{Collider, Shape, StepCollider};
use super::herd::HerdInstance;
use super::scene::Scene;
use super::simulation::{SimError, Simulation};
use crate::anim::{Pose, Rig};
use crate::body::{BodyCapsules, Capsule};
use crate::fur::FurStructure;
use crate::mesh::Mesh;
use crate::wet::{WetParams, WetSurface, Wetness};

/// Where the base's pose comes from each step.
#[derive(Debug, Default)]
enum Posing {
    /// The rest mesh (moved only by a script's `[[motion]]`).
    #[default]
    Rest,
    /// A rig playing a clip (or its rest pose with no clip).
    Rig { rig: Box<Rig>, clip: Option<usize> },
    /// The host writes the pose ([`FurStepper::set_pose`]), e.g. from its own skinning.
    Host,
}

/// One fur's simulation with what moves it: the posed base and a scene script.
///
/// Each frame a host calls [`FurStepper::advance_to`] with the frame's time. The stepper applies
/// the script's keys, poses the base when anything moves it (a clip, the script's motion, a host
/// pose), restarts the simulation from the first pose (no fling from the rest pose), then
/// advances the [`Simulation`]. The pose's normals, for shading the skin, are
/// [`FurStepper::moved_pose`].
#[derive(Debug)]
pub struct FurStepper {
    simulation: Simulation,
    /// The rest base the rig poses and the script moves.
    mesh: Mesh,
    posing: Posing,
    scene: Option<Scene>,
    pose: Pose,
    world_from_model: Mat4,
    /// The base moved this step (the pose is new).
    moved: bool,
    /// The next pose jumps (a new clip, the first pose): restart the simulation from it.
    restart_pending: bool,
    /// The host set a pose since the last step.
    host_posed: bool,
    /// A body the fur collides with, posed with the clip.
    body: Option<BodyColliders>,
    /// A wetness per base vertex (rain, water, sponge, drying) and what it does.
    wetness: Wetness,
    wet: WetParams,
    /// The normals the wetness was last advanced with (the posed base's, world space).
    wet_normals: Vec<Vec3>,
    /// Where a herd's host placed this copy of the fur (after the script's motion).
    placement: Option<HerdInstance>,
    /// The host's GPU skins the base when it can ([`FurStepper::set_joint_posing`]).
    joint_posing: bool,
    /// The last advance posed the joints only: `world_from_model * world(joint) * inverse_bind`.
    joints: Option<Vec<Mat4>>,
}

/// Ids of the colliders a [`FurStepper`]'s body gives the simulation (capsule `k` is this plus
/// `k`), apart from a host's and a script's.
pub const BODY_COLLIDER_IDS: u32 = 0xb0d0_0000;

/// A skinned body beside the fur (the walking try-on's): its capsules collide with the fur.
#[derive(Clone, Debug)]
struct BodyColliders {
    mesh: Mesh,
    rig: Rig,
    capsules: BodyCapsules,
    pose: Pose,
}

impl FurStepper {
    /// The simulation of `structure` at rest, with nothing moving it yet.
    ///
    /// # Errors
    /// As [`Simulation::new`].
    pub fn new(structure: &FurStructure, params: &SimParams) -> Result<Self, SimError> {
        Ok(Self {
            simulation: Simulation::new(structure, params)?,
            mesh: structure.mesh.clone(),
            posing: Posing::Rest,
            scene: None,
            pose: Pose::default(),
            world_from_model: Mat4::IDENTITY,
            moved: false,
            restart_pending: true,
            host_posed: false,
            body: None,
            wetness: Wetness::new(structure.mesh.vertex_count(), 0.0),
            wet: WetParams::default(),
            wet_normals: Vec::new(),
            placement: None,
            joint_posing: false,
            joints: None,
        })
    }

    /// Places this fur as one member of a herd: each step its base is moved by
    /// [`HerdInstance::world_from_model`] at the step's time (after the script's `[[motion]]`)
    /// and simulated there, in the world; `None` leaves it where the script puts it. Restarts
    /// the simulation from the next pose. The clip's phase is the caller's
    /// ([`FurStepper::advance_herd`] plays each at [`HerdInstance::clip_time`]).
    pub fn set_placement(&mut self, placement: Option<HerdInstance>) {
        self.placement = placement;
        self.restart_pending = true;
    }

    /// Steps every member of a herd to `time_secs` in one parallel pass: `steppers[k]` (placed
    /// as `instances[k]`, [`FurStepper::set_placement`]) with its clip at
    /// `instances[k].clip_time(time_secs)`. Each ends as it would stepped alone, to the bit.
    ///
    /// # Errors
    /// The first stepper's error, as [`FurStepper::advance_to`].
    ///
    /// # Panics
    /// When the two slices differ in length (a host's bug).
    pub fn advance_herd(steppers: &mut [Self], instances: &[HerdInstance], time_secs: f64) -> Result<(), SimError> {
        use rayon::prelude::*;
        assert_eq!(steppers.len(), instances.len(), "one stepper per instance");
        steppers
            .par_iter_mut()
            .zip(instances)
            .try_for_each(|(stepper, instance)| stepper.advance_with_clip_at(time_secs, instance.clip_time(time_secs)))
    }

    /// Leaves the skinning of the base to the host's GPU (`pelt_render::HerdPosing`) whenever
    /// nothing on the CPU reads the posed vertices: a rig without morph targets poses its joints
    /// only ([`FurStepper::posed_joints`]) and the simulation takes the move unseen
    /// ([`Simulation::set_base_posed_elsewhere`]), while its strands are bent elsewhere, with no
    /// body, touch, grasp, collider or wetness. Otherwise (and when off) the CPU poses as before,
    /// the motion carrying on from the pose made elsewhere.
    pub fn set_joint_posing(&mut self, on: bool) {
        self.joint_posing = on;
    }

    /// The joint matrices of the last advance's pose, placed in the world
    /// (`world_from_model * world(joint) * inverse_bind`, in the rig's palette order), when that
    /// advance left the vertices to the host ([`FurStepper::set_joint_posing`]); `None` when it
    /// posed them here or did not pose.
    #[must_use]
    pub fn posed_joints(&self) -> Option<&[Mat4]> {
        self.joints.as_deref()
    }

    /// Whether this advance poses the joints only (see [`FurStepper::set_joint_posing`]).
    fn poses_joints_only(&self) -> bool {
        let simulation = &self.simulation;
        self.joint_posing
            && matches!(&self.posing, Posing::Rig { rig, .. } if rig.morph_target_count() == 0)
            && self.body.is_none()
            && !simulation.cpu_bending()
            && simulation.touch().is_none()
            && simulation.grasp().is_none()
            && simulation.colliders().is_empty()
            && self.wetness.is_dry()
            && self.scene.as_ref().is_none_or(|scene| scene.wet_sources().is_empty())
    }

    /// Steps this fur every `stride`-th fixed step (1, 2 or 4), interpolated between:
    /// [`Simulation::set_step_stride`]. A herd's host steps its far members less often.
    pub fn set_step_stride(&mut self, stride: u32) {
        self.simulation.set_step_stride(stride);
    }

    /// Makes `mesh` (skinned by `rig`, whose clips are the fur rig's) collide with the fur: every
    /// step its [`BodyCapsules`] are posed with the fur's clip and the script's motion and handed
    /// to the simulation as capsule colliders, beside any the script places. `None` removes it.
    pub fn set_body(&mut self, body: Option<(Mesh, Rig, BodyCapsules)>) {
        self.body = body.map(|(mesh, rig, capsules)| BodyColliders { mesh, rig, capsules, pose: Pose::default() });
    }

    /// Plays `clip` of `rig` (the rig's rest pose with `None`); the simulation restarts from the
    /// first pose. `rig` must pose this fur's mesh (it came with it from the same file).
    pub fn set_clip(&mut self, rig: Rig, clip: Option<usize>) {
        self.posing = Posing::Rig { rig: Box::new(rig), clip };
        self.restart_pending = true;
    }

    /// Changes the clip of the rig set with [`FurStepper::set_clip`]; the simulation restarts
    /// from its first pose. Does nothing without a rig.
    pub fn change_clip(&mut self, clip: Option<usize>) {
        if let Posing::Rig { clip: current, .. } = &mut self.posing {
            *current = clip;
            self.restart_pending = true;
        }
    }

    /// Back to the rest mesh: no rig poses the base (the simulation restarts from the next pose).
    pub fn clear_clip(&mut self) {
        self.posing = Posing::Rest;
        self.restart_pending = true;
    }

    /// The rig playing, if any.
    #[must_use]
    pub fn rig(&self) -> Option<&Rig> {
        match &self.posing {
            Posing::Rig { rig, .. } => Some(rig),
            _ => None,
        }
    }

    /// Plays `scene`'s wind, touch strokes and rigid motion from the next step on.
    pub fn set_scene(&mut self, scene: Option<Scene>) {
        self.scene = scene;
    }

    /// The scene script playing, if any.
    #[must_use]
    pub fn scene(&self) -> Option<&Scene> {
        self.scene.as_ref()
    }

    /// Whether anything moves the base: a clip, the script's motion or a host pose.
    #[must_use]
    pub fn moves(&self) -> bool {
        match &self.posing {
            _ if self.placement.is_some() => true,
            Posing::Rest => self.scene.as_ref().is_some_and(|s| !s.motion.is_empty()),
            Posing::Rig { clip, .. } => clip.is_some() || self.scene.as_ref().is_some_and(|s| !s.motion.is_empty()),
            Posing::Host => true,
        }
    }

    /// Steps to `time_secs`, with the clip at the same time.
    ///
    /// # Errors
    /// A pose or a script key the simulation refuses (non-finite values).
    pub fn advance_to(&mut self, time_secs: f64) -> Result<(), SimError> {
        self.advance_with_clip_at(time_secs, time_secs)
    }

    /// Steps to `time_secs` with the clip at `clip_time_secs` (a viewer that pauses or speeds up
    /// the animation keeps its own clock for it).
    ///
    /// # Errors
    /// As [`FurStepper::advance_to`].
    pub fn advance_with_clip_at(&mut self, time_secs: f64, clip_time_secs: f64) -> Result<(), SimError> {
        // The script's keys first: a restart below computes its states with this step's inputs,
        // as a GPU kernel replaying the steps does.
        if let Some(scene) = &self.scene {
            scene.apply(time_secs, &mut self.simulation)?;
        }
        let motion = self.scene.as_ref().and_then(|s| s.motion_at(time_secs)).unwrap_or(Mat4::IDENTITY);
        let world_from_model = match &self.placement {
            Some(placement) => placement.world_from_model(time_secs) * motion,
            None => motion,
        };
        self.world_from_model = world_from_model;
        self.moved = std::mem::take(&mut self.host_posed);
        self.joints = None;
        let joints_only = self.poses_joints_only();
        // A rig poses once after a change of clip even when nothing plays (back to its rest).
        let rig_jumps = matches!(self.posing, Posing::Rig { .. }) && self.restart_pending;
        // A fur stepped less often is posed only for its steps: between them nothing reads
        // the pose (the skin shows the interpolated roots; its normals stay the last step's).
        let between_steps = self.simulation.step_stride() > 1
            && !self.restart_pending
            && !self.moved
            && !self.simulation.steps_at(time_secs);
        if (self.moves() || rig_jumps) && !between_steps {
            match &self.posing {
                Posing::Rig { rig, clip } if joints_only => {
                    rig.pose_joints(*clip, clip_time_secs, &mut self.pose);
                    let placed = rig.joint_matrices(&self.pose).into_iter().map(|m| world_from_model * m);
                    self.joints = Some(placed.collect());
                    self.moved = true;
                }
                Posing::Rig { rig, clip } => {
                    rig.pose(&self.mesh, *clip, clip_time_secs, &mut self.pose);
                    transform_pose(&mut self.pose, world_from_model);
                    self.moved = true;
                }
                Posing::Rest => {
                    self.pose.positions.clone_from(&self.mesh.positions);
                    self.pose.normals.clone_from(&self.mesh.normals);
                    self.pose.rotations.clear();
                    self.pose.rotations.resize(self.mesh.vertex_count(), Quat::IDENTITY);
                    transform_pose(&mut self.pose, world_from_model);
                    self.moved = true;
                }
                // The host set the pose (and the simulation's base) in `set_pose`.
                Posing::Host => {}
            }
            if let (Some(body), Posing::Rig { clip, .. }) = (&mut self.body, &self.posing) {
                body.rig.pose(&body.mesh, *clip, clip_time_secs, &mut body.pose);
                let capsules = body.capsules.posed(&body.rig, &body.pose, world_from_model);
                let mut colliders: Vec<Collider> = self
                    .simulation
                    .colliders()
                    .iter()
                    .filter(|c| c.id.wrapping_sub(BODY_COLLIDER_IDS) >= capsules.len() as u32)
                    .cloned()
                    .collect();
                colliders.extend(capsules.iter().enumerate().map(|(k, c)| capsule_collider(k, c, time_secs)));
                self.simulation.set_colliders(&colliders)?;
            }
            if self.moved && !matches!(self.posing, Posing::Host) {
                if self.joints.is_some() {
                    self.simulation.set_base_posed_elsewhere();
                } else {
                    self.simulation.set_base_rotations(&self.pose.positions, &self.pose.rotations)?;
                }
                // The wetness on the new pose, before a restart computes its states with it.
                self.advance_wetness(time_secs)?;
                if std::mem::take(&mut self.restart_pending) {
                    self.simulation.restart();
                }
            }
        }
        self.advance_wetness(time_secs)?;
        self.simulation.advance_to(time_secs);
        Ok(())
    }

    /// Advances the wetness to `time_secs` on the posed base and hands it to the simulation.
    /// Wetness (rain, water, drying) up to `time_secs`. A dry coat's clock moves too (nothing
    /// else to do then), so a sponge on it later is not dried away by replayed ticks, nor reset
    /// as if time had begun.
    fn advance_wetness_clock(&mut self, time_secs: f64) {
        let sources = self.scene.as_ref().map(Scene::wet_sources).unwrap_or_default();
        let simulation = &self.simulation;
        if !sources.is_empty() || !self.wetness.is_dry() {
            self.wet_normals.clear();
            self.wet_normals.extend(simulation.frames().iter().zip(&self.mesh.normals).map(|(q, n)| *q * *n));
        }
        self.wetness.advance_to(
            time_secs,
            simulation.params().rate_hz,
            sources,
            &self.wet,
            WetSurface {
                positions: simulation.roots(),
                normals: &self.wet_normals,
                radius: simulation.bounding_radius(),
            },
        );
    }

    fn advance_wetness(&mut self, time_secs: f64) -> Result<(), SimError> {
        self.advance_wetness_clock(time_secs);
        let wet = (!self.wetness.is_dry()).then(|| self.wetness.values());
        if wet.is_some() || self.simulation.wetness().is_some() {
            self.simulation.set_wetness(wet, &self.wet)?;
        }
        Ok(())
    }

    /// What wetness does (the preset's `[wet]`); its `wetness` is every vertex's wetness at
    /// time 0 (and after a jump back in time, which replays from there).
    ///
    /// # Errors
    /// [`SimError::Params`] for values out of range (keys `wet.*`).
    pub fn set_wet(&mut self, params: &WetParams) -> Result<(), SimError> {
        params.validate()?;
        self.wet = params.clone();
        self.wetness.set_initial(params.wetness);
        Ok(())
    }

    /// What wetness does, as [`FurStepper::set_wet`] left it.
    #[must_use]
    pub fn wet(&self) -> &WetParams {
        &self.wet
    }

    /// The wetness per base vertex, as the last step left it.
    #[must_use]
    pub fn wetness(&self) -> &Wetness {
        &self.wetness
    }

    /// The wetness, for a host's sponge ([`Wetness::sponge`] at the simulation's
    /// [`roots`](Simulation::roots)) or a uniform setting; the next step takes it up.
    pub fn wetness_mut(&mut self) -> &mut Wetness {
        &mut self.wetness
    }

    /// Presses a sponge at `centre` (the posed base's space): the wetness within `radius` moves
    /// toward `amount` (0 dries, 1 soaks) with a smooth falloff.
    pub fn sponge(&mut self, centre: Vec3, radius: f32, amount: f32) {
        // The clock first comes to the last step's time, so the next step dries this water
        // for the time since then only (and a first step does not start the coat over it).
        self.advance_wetness_clock(self.simulation.time_secs());
        self.wetness.sponge(self.simulation.roots(), centre, radius, amount);
    }

    /// Sets the base's pose from the host's own skinning (world or model space, as the host
    /// draws the fur): positions, normals and each vertex's rotation from rest. The simulation
    /// restarts from the first such pose. Call before [`FurStepper::advance_to`].
    ///
    /// # Errors
    /// [`SimError::Size`] or [`SimError::NonFinite`]; the previous pose stays.
    pub fn set_pose(&mut self, positions: &[Vec3], normals: &[Vec3], rotations: &[Quat]) -> Result<(), SimError> {
        if normals.len() != positions.len() {
            return Err(SimError::Size { what: "the pose's normals", expected: positions.len(), got: normals.len() });
        }
        self.simulation.set_base_rotations(positions, rotations)?;
        self.posing = Posing::Host;
        if std::mem::take(&mut self.restart_pending) {
            self.simulation.restart();
        }
        self.pose.positions.clear();
        self.pose.positions.extend_from_slice(positions);
        self.pose.normals.clear();
        self.pose.normals.extend_from_slice(normals);
        self.pose.rotations.clear();
        self.pose.rotations.extend_from_slice(rotations);
        self.host_posed = true;
        Ok(())
    }

    /// The base's pose when it moved in the last step (its normals shade the skin), else `None`;
    /// `None` too when the host poses the vertices ([`FurStepper::posed_joints`]).
    #[must_use]
    pub fn moved_pose(&self) -> Option<&Pose> {
        (self.moved && self.joints.is_none()).then_some(&self.pose)
    }

    /// The script's rigid transform at the last step (identity without motion): plain meshes
    /// beside the fur move with it.
    #[must_use]
    pub fn world_from_model(&self) -> Mat4 {
        self.world_from_model
    }

    /// The simulation.
    #[must_use]
    pub fn simulation(&self) -> &Simulation {
        &self.simulation
    }

    /// The colliders a host draws at `time_secs` ([`Simulation::shown_colliders`]); the body's
    /// capsules only with `body`: the body is drawn as its mesh, and its capsules are a
    /// collision proxy that would hide it.
    #[must_use]
    pub fn shown_colliders(&self, time_secs: f64, body: bool) -> Vec<StepCollider> {
        let capsules = self.body.as_ref().map_or(0, |b| b.capsules.bones.len()) as u32;
        self.simulation.shown_colliders_where(time_secs, |c| body || c.id.wrapping_sub(BODY_COLLIDER_IDS) >= capsules)
    }

    /// The simulation, to change its parameters, wind or touch.
    pub fn simulation_mut(&mut self) -> &mut Simulation {
        &mut self.simulation
    }

    /// Takes a regroomed `structure`'s rest shape for `strands` (the vertices a length, comb or
    /// cut dab reshaped, [`FurStructure::changed_strands`]) in place: [`Simulation::regroom`],
    /// the cheap path for painting. The wetness, script, pose and clip stay.
    ///
    /// # Errors
    /// As [`Simulation::regroom`].
    pub fn regroom(&mut self, structure: &FurStructure, strands: &[u32]) -> Result<(), SimError> {
        self.simulation.regroom(structure, strands)
    }

    /// Replaces the simulation (a new structure); the next pose restarts it.
    ///
    /// # Errors
    /// As [`Simulation::new`].
    pub fn set_structure(&mut self, structure: &FurStructure, params: &SimParams) -> Result<(), SimError> {
        let bending = self.simulation.cpu_bending();
        self.simulation = Simulation::new(structure, params)?;
        self.simulation.set_cpu_bending(bending);
        self.mesh = structure.mesh.clone();
        self.wetness = Wetness::new(self.mesh.vertex_count(), self.wet.wetness);
        self.restart_pending = true;
        Ok(())
    }
}

/// Moves a pose rigidly by `world_from_model` (rotation and translation; a scale is ignored by
/// the frames and normals, as the script's motion keys hold none).
fn transform_pose(pose: &mut Pose, world_from_model: Mat4) {
    if world_from_model == Mat4::IDENTITY {
        return;
    }
    let (_, turn, _) = world_from_model.to_scale_rotation_translation();
    for p in &mut pose.positions {
        *p = world_from_model.transform_point3(*p);
    }
    for n in &mut pose.normals {
        *n = turn * *n;
    }
    for q in &mut pose.rotations {
        *q = (turn * *q).normalize();
    }
}

/// A body capsule as the simulation's collider, standing at `time_secs`.
fn capsule_collider(k: usize, capsule: &Capsule, time_secs: f64) -> Collider {
    let axis = capsule.b - capsule.a;
    let rotation = axis.try_normalize().map_or(Quat::IDENTITY, |d| Quat::from_rotation_arc(Vec3::Y, d));
    let shape = Shape::Capsule { radius: capsule.radius, half_length: 0.5 * axis.length() };
    Collider::at(BODY_COLLIDER_IDS + k as u32, shape, time_secs, 0.5 * (capsule.a + capsule.b), rotation)
}

#[cfg(test)]
mod tests {
    use std::path::Path;

    use super::*;
    use crate::body::walking_try_on;
    use crate::fur::{FurLength, FurParams, FurStructure};
    use crate::sim::{Scene, SimParams};

    /// The body's capsules collide with the skirt's fur but are drawn only when asked; a ball a
    /// script places is drawn either way.
    #[test]
    fn the_body_capsules_are_shown_only_when_asked() {
        let scene = walking_try_on(&crate::mesh::ImportOptions::default()).expect("walking try-on");
        let fur = FurStructure::new(
            scene.garment.clone(),
            &FurParams { layers: 4, length: FurLength::Constant(0.02), direction: Default::default() },
        )
        .expect("fur on the skirt");
        let mut stepper = FurStepper::new(&fur, &SimParams::default()).expect("stepper");
        stepper.set_clip(scene.garment_rig.clone(), Some(0));
        let capsules = scene.capsules.bones.len();
        stepper.set_body(Some((scene.body.clone(), scene.body_rig.clone(), scene.capsules.clone())));
        let script = "[[collider]]\nshape = { kind = \"sphere\", radius = 0.1 }\n\
                      keys = [{ time_secs = 0.0, position = [0.0, 3.0, 0.0] }]\n";
        stepper.set_scene(Some(Scene::from_toml_str(script, Path::new("ball.toml")).expect("script")));
        stepper.advance_to(0.5).expect("steps");
        let colliding = stepper.simulation().colliders();
        let body_ids = colliding.iter().filter(|c| c.id.wrapping_sub(BODY_COLLIDER_IDS) < capsules as u32).count();
        assert!(capsules >= 10 && body_ids == capsules, "{body_ids} of {capsules} capsules collide");
        let balls = |shown: &[crate::sim::StepCollider]| {
            shown.iter().filter(|c| c.kind == crate::sim::StepCollider::SPHERE && (c.radius - 0.1).abs() < 1e-6).count()
        };
        let hidden = stepper.shown_colliders(0.5, false);
        assert_eq!((hidden.len(), balls(&hidden)), (1, 1), "only the script's ball is drawn by default");
        let shown = stepper.shown_colliders(0.5, true);
        assert_eq!((shown.len(), balls(&shown)), (1 + capsules, 1), "asked, the capsules are drawn too");
    }
}
