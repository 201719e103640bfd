//! [`Simulation`]: the strands of a [`FurStructure`] under gravity, wind and touch, stepped at a
//! fixed rate and drawn as `lerp(previous, current, alpha)` in between.

#[cfg(not(target_arch = "wasm32"))]
use std::time::Instant;

// wasm32-unknown-unknown has no clock in std (`Instant::now` panics there); web-time reads the
// browser's `performance.now()`.
#[cfg(target_arch = "wasm32")]
use web_time::Instant;

use glam::{Quat, Vec3, Vec4};
use rayon::prelude::*;

use super::contact::skin::skin_planes_of;
use super::contact::{
    BatchPlanes, Collider, ContactStep, ContactStrands, Grasp, GraspParams, MAX_STEP_COLLIDERS, Resolve, SKIN_PLANES,
    SkinSurface, skin_lanes,
};
use super::dispatch::{self, CpuKernel};
use super::field::{ForceField, Touch};
use super::inertia::{Inertia, InertiaStep};
use super::inputs::{InputVersions, StepInputs, StrandInputs};
use super::kernel::{LANES, RestBatches, Step, VecLanes};
use super::pick::{Hit, pick};
use super::{ParamError, SimParams, WindParams};
use crate::fur::FurStructure;

mod regroom;

/// Errors from building or driving a [`Simulation`].
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum SimError {
    /// Invalid simulation parameters.
    #[error(transparent)]
    Params(#[from] ParamError),
    /// An array of the wrong length.
    #[error("{what} has {got} entries but the fur has {expected}")]
    Size {
        /// Which array.
        what: &'static str,
        /// The length the fur needs.
        expected: usize,
        /// The length given.
        got: usize,
    },
    /// A NaN or infinite input.
    #[error("{what} must be finite, got {value}")]
    NonFinite {
        /// Which input.
        what: &'static str,
        /// The value given.
        value: String,
    },
    /// A touch radius that is not finite and positive.
    #[error("touch radius must be finite and positive, got {0}")]
    TouchRadius(f32),
    /// Another kernel bending the strands (a GPU pass driven through `sim::soak`, a `lab`
    /// feature) failed.
    #[error("the {kernel} simulation kernel failed: {message}")]
    Kernel {
        /// Which kernel, e.g. `GPU`.
        kernel: String,
        /// What went wrong.
        message: String,
    },
    /// A collider that fails its checks.
    #[error("collider {index} (id {id}): {key}: {problem}")]
    Collider {
        /// Its place in the list given.
        index: usize,
        /// Its id.
        id: u32,
        /// The bad key.
        key: String,
        /// What is wrong with it.
        problem: String,
    },
    /// A stability map entry out of range.
    #[error("stability map entry {vertex} is {value}: must be between 1e-6 and 1e9")]
    Stability {
        /// The vertex.
        vertex: usize,
        /// Its value.
        value: f32,
    },
}

/// Strands per parallel task of the interpolation (a multiple of [`LANES`]).
const LERP_STRANDS_PER_TASK: usize = 32 * LANES;

/// The fur simulation over the shared vertex array of one [`FurStructure`].
///
/// Internally strands go in batches of 8, structure of arrays (node `i` of batch `b` is one
/// `[x, y, z]` of 8 lanes at `b * (L + 1) + i`) so the bend runs as SIMD over 8 strands and each
/// batch is one contiguous run; [`Simulation::positions`] is layer-major like
/// [`FurStructure::positions`] (`NV[i * V + j]`), ready to upload.
///
/// Time: state `n` is the pose at `n / rate_hz` seconds. With interpolation, at render time `t`
/// the simulation holds states `n - 1` and `n` for `n = floor(t * rate_hz)` and draws
/// `lerp(state(n - 1), state(n), t * rate_hz - n)`: one step of latency buys a smooth picture at
/// any frame rate for the cost of a lerp per frame. As the model is quasi-static, a jump in time
/// costs at most two steps.
#[derive(Debug)]
pub struct Simulation {
    params: SimParams,
    layers: u32,
    vertex_count: usize,
    /// The rest shape, batch-major, in the kernel's layout.
    rest: RestBatches,
    cpu_kernel: CpuKernel,
    /// Whether contact screens batches before solving strands (off only to test that the
    /// screen changes nothing).
    pub(crate) contact_screen: bool,
    rest_normals: Vec<Vec3>,
    rest_roots: Vec<Vec3>,
    roots: Vec<Vec3>,
    /// Rotation of each strand's rest frame into the current base frame (from `set_base`).
    frames: Vec<Quat>,
    stability_map: Option<Vec<f32>>,
    /// Each strand's wetness, with gravity's factor and stability's loss per unit of it; `None`
    /// while the fur is dry.
    wetness: Option<Vec<f32>>,
    wet_weight: f32,
    wet_softening: f32,
    /// Bounding radius of the base at rest: the unit of wind gust sizes and speeds.
    radius: f32,
    field: ForceField,
    touch: Option<Touch>,
    /// The external field (wind + field + touch) of the newest state.
    external: Vec<Vec3>,
    /// The force from the roots' acceleration (the one state carried from step to step).
    inertia: Inertia,
    /// States, batch-major like `rest_segments` with `L + 1` nodes per batch.
    previous: Vec<VecLanes>,
    current: Vec<VecLanes>,
    /// Layer-major `lerp(previous, current, alpha)` for the last render time.
    output: Vec<Vec3>,
    step_index: i64,
    /// Fixed steps between the ones taken (1 = every step; `set_step_stride`).
    step_stride: u32,
    time_secs: f64,
    alpha: f32,
    last_step_secs: f64,
    steps_taken: u64,
    /// Whether steps bend the strands here; off when another kernel (a GPU pass) does.
    cpu_bending: bool,
    /// Times of the last (up to) two steps, oldest first.
    recent_step_times: Vec<f64>,
    /// What those steps did to the inertial state, oldest first.
    recent_inertia_steps: Vec<InertiaStep>,
    /// Counters of the per-strand inputs' changes.
    versions: InputVersions,
    /// The roots changed since the last step.
    roots_moved: bool,
    /// The base last moved through [`Simulation::set_base_posed_elsewhere`].
    posed_elsewhere: bool,
    /// The touch began on the roots of the newest step.
    touch_on_step_roots: bool,
    /// Each strand's skin planes (see `contact::skin`).
    skin: Vec<[Vec4; SKIN_PLANES]>,
    /// The same planes batch by batch, for the CPU's contact screen.
    skin_lanes: Vec<BatchPlanes>,
    /// The skin triangles where the planes do not suffice (see `contact::surface`).
    surface: SkinSurface,
    /// The grid cell the skin planes were found in (the longest strand's reach).
    skin_cell: f32,
    /// While skin contact has been off since the start: the rest shape the skin planes and
    /// triangles are found from when it turns on (`skin`, `skin_lanes` and `surface` hold none
    /// until then). Finding them is most of the setup on a dense mesh, so a coat that never
    /// touches its skin never pays for it.
    skin_source: Option<Box<FurStructure>>,
    /// Colliders the host or a script placed.
    colliders: Vec<Collider>,
    /// The grasp holding (or springing back), if any.
    grasp: Option<Grasp>,
}

/// What the skin setup reads of `fur` (`contact::skin`, `contact::surface`): its mesh, layers and
/// rest shape, kept while skin contact is off.
fn skin_source_of(fur: &FurStructure) -> FurStructure {
    FurStructure {
        mesh: fur.mesh.clone(),
        layers: fur.layers,
        directions: Vec::new(),
        lengths: Vec::new(),
        positions: fur.positions.clone(),
        groom: None,
    }
}

/// Simulations made so far: each one's [`InputVersions::id`].
static SIMULATIONS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

impl Simulation {
    /// Sets up the simulation of `fur` and computes the state at time 0.
    ///
    /// # Errors
    /// [`SimError::Params`] if `params` fail [`SimParams::validate`]; [`SimError::Size`] if the
    /// structure's arrays disagree with its mesh.
    pub fn new(fur: &FurStructure, params: &SimParams) -> Result<Self, SimError> {
        params.validate()?;
        let v = fur.vertex_count();
        let layers = fur.layers as usize;
        if fur.positions.len() != v * (layers + 1) {
            return Err(SimError::Size {
                what: "the shared vertex array",
                expected: v * (layers + 1),
                got: fur.positions.len(),
            });
        }
        if fur.mesh.normals.len() != v {
            return Err(SimError::Size { what: "the base normals", expected: v, got: fur.mesh.normals.len() });
        }
        let batches = v.div_ceil(LANES);
        let roots = fur.positions[..v].to_vec();
        let (centre, radius) = bounding_sphere(&roots);
        debug_assert!(centre.is_finite());
        let nodes = v * (layers + 1);
        let batch_nodes = batches * (layers + 1);
        let (skin_cell, skin, surface, skin_source) = if params.contact.skin {
            let setup = super::contact::skin_setup(fur);
            (setup.cell, setup.planes.clone(), setup.surface.clone(), None)
        } else {
            (0.0, vec![[Vec4::ZERO; SKIN_PLANES]; v], SkinSurface::default(), Some(Box::new(skin_source_of(fur))))
        };
        let mut simulation = Self {
            params: params.clone(),
            layers: fur.layers,
            vertex_count: v,
            rest: RestBatches::new(&fur.positions, v, layers),
            cpu_kernel: CpuKernel::Auto,
            contact_screen: true,
            rest_normals: fur.mesh.normals.clone(),
            rest_roots: roots.clone(),
            roots,
            frames: vec![Quat::IDENTITY; v],
            stability_map: None,
            wetness: None,
            wet_weight: 0.0,
            wet_softening: 0.0,
            radius,
            field: ForceField::new(v),
            touch: None,
            external: vec![Vec3::ZERO; v],
            inertia: Inertia::new(v),
            previous: vec![[[0.0; LANES]; 3]; batch_nodes],
            current: vec![[[0.0; LANES]; 3]; batch_nodes],
            output: vec![Vec3::ZERO; nodes],
            step_index: 0,
            step_stride: 1,
            time_secs: 0.0,
            alpha: 0.0,
            last_step_secs: 0.0,
            steps_taken: 0,
            cpu_bending: true,
            recent_step_times: Vec::with_capacity(3),
            recent_inertia_steps: Vec::with_capacity(3),
            versions: InputVersions {
                id: SIMULATIONS.fetch_add(1, std::sync::atomic::Ordering::Relaxed),
                ..InputVersions::default()
            },
            roots_moved: false,
            posed_elsewhere: false,
            touch_on_step_roots: false,
            surface,
            skin_lanes: skin_lanes(&skin),
            skin,
            skin_cell,
            skin_source,
            colliders: Vec::new(),
            grasp: None,
        };
        simulation.jump_to_step(0);
        simulation.update_output();
        Ok(simulation)
    }

    /// The parameters in use.
    #[must_use]
    pub fn params(&self) -> &SimParams {
        &self.params
    }

    /// Replaces the parameters (gravity, stability, wind, rate, ...). Takes effect from the next
    /// step; a new rate re-times the states at the next [`Simulation::advance_to`].
    ///
    /// # Errors
    /// [`SimError::Params`]; the old parameters stay.
    pub fn set_params(&mut self, params: &SimParams) -> Result<(), SimError> {
        params.validate()?;
        if params.rate_hz != self.params.rate_hz {
            // Force a full recompute at the next advance: old step indices mean other times.
            self.step_index = i64::MIN;
        }
        if params.stability != self.params.stability {
            self.versions.stability += 1;
        }
        if params.contact.skin {
            self.find_skin_setup();
        }
        self.params = params.clone();
        Ok(())
    }

    /// Finds the skin planes and triangles if skin contact has been off until now.
    fn find_skin_setup(&mut self) {
        if let Some(fur) = self.skin_source.take() {
            let setup = super::contact::skin_setup(&fur);
            self.skin_cell = setup.cell;
            self.skin.clone_from(&setup.planes);
            self.surface.clone_from(&setup.surface);
            self.skin_lanes = skin_lanes(&self.skin);
        }
    }

    /// Whether the skin planes and triangles are found ([`Simulation::contact_strands`] holds
    /// them): from the start with skin contact on, else from the first
    /// [`Simulation::set_params`] that turns it on.
    #[must_use]
    pub fn has_skin_setup(&self) -> bool {
        self.skin_source.is_none()
    }

    /// Sets the wind from the next step on.
    ///
    /// # Errors
    /// [`SimError::Params`] naming the bad `simulation.wind` key.
    pub fn set_wind(&mut self, wind: &WindParams) -> Result<(), SimError> {
        let params = SimParams { wind: wind.clone(), ..self.params.clone() };
        params.validate()?;
        self.params = params;
        Ok(())
    }

    /// One stability per base vertex (`None` goes back to `SimParams::stability` everywhere).
    ///
    /// # Errors
    /// [`SimError::Size`] for a map of the wrong length; [`SimError::Stability`] for a value
    /// outside `1e-6..=1e9`.
    pub fn set_stability_map(&mut self, map: Option<Vec<f32>>) -> Result<(), SimError> {
        if let Some(map) = &map {
            if map.len() != self.vertex_count {
                return Err(SimError::Size { what: "the stability map", expected: self.vertex_count, got: map.len() });
            }
            if let Some((vertex, &value)) =
                map.iter().enumerate().find(|(_, s)| !(s.is_finite() && (1e-6..=1e9).contains(*s)))
            {
                return Err(SimError::Stability { vertex, value });
            }
        }
        self.stability_map = map;
        self.versions.stability += 1;
        Ok(())
    }

    /// Moves the roots with a deforming base mesh: new base positions and normals (one per base
    /// vertex). Each strand's rest shape turns with the shortest rotation from its rest normal
    /// to the new normal, so fur stays attached at the same angle to the surface. A normal alone
    /// cannot say how the surface twisted about it: fur that leans (random or combed growth)
    /// keeps its lean's world heading; use [`Simulation::set_base_rotations`] when the full
    /// rotation is known (skinning). Takes effect from the next step.
    ///
    /// # Errors
    /// [`SimError::Size`] for arrays of the wrong length, [`SimError::NonFinite`] for NaN or
    /// infinite entries; nothing changes then.
    pub fn set_base(&mut self, positions: &[Vec3], normals: &[Vec3]) -> Result<(), SimError> {
        self.check_base(positions, normals, "the base normals")?;
        self.moved_base();
        self.rebase_after_elsewhere(positions);
        self.roots.copy_from_slice(positions);
        for ((frame, rest), normal) in self.frames.iter_mut().zip(&self.rest_normals).zip(normals) {
            *frame = match (rest.try_normalize(), normal.try_normalize()) {
                (Some(rest), Some(normal)) => Quat::from_rotation_arc(rest, normal),
                _ => Quat::IDENTITY,
            };
        }
        Ok(())
    }

    /// Like [`Simulation::set_base`], with each strand's full rotation from its rest frame (for
    /// a skinned base: the rotation part of each vertex's skinning transform).
    ///
    /// # Errors
    /// As [`Simulation::set_base`]; zero-length rotations are errors too.
    pub fn set_base_rotations(&mut self, positions: &[Vec3], rotations: &[Quat]) -> Result<(), SimError> {
        let as_vectors: Vec<Vec3> = rotations.iter().map(|q| Vec3::new(q.x, q.y, q.z) + Vec3::splat(q.w)).collect();
        self.check_base(positions, &as_vectors, "the base rotations")?;
        if let Some(bad) = rotations.iter().find(|q| q.length_squared() == 0.0) {
            return Err(SimError::NonFinite { what: "the base rotations", value: bad.to_string() });
        }
        self.moved_base();
        self.rebase_after_elsewhere(positions);
        self.roots.copy_from_slice(positions);
        for (frame, rotation) in self.frames.iter_mut().zip(rotations) {
            *frame = rotation.normalize();
        }
        Ok(())
    }

    /// Marks the base as moved by a pose this simulation never sees: a kernel that bends
    /// elsewhere (`pelt_render::GpuSimulation`) reads roots and frames posed on its own device
    /// (`pelt_render::HerdPosing`). The steps take the move as [`Simulation::set_base_rotations`]
    /// does, but [`Simulation::roots`] and [`Simulation::frames`] keep the last pose given here,
    /// so what reads them on the CPU (the CPU's bending, a touch's weights, wetness, the inertia's
    /// teleport check) must not run meanwhile.
    pub fn set_base_posed_elsewhere(&mut self) {
        self.moved_base();
        self.posed_elsewhere = true;
    }

    /// Whether the base last moved through [`Simulation::set_base_posed_elsewhere`]: the roots
    /// and frames here are not the current ones.
    #[must_use]
    pub fn base_posed_elsewhere(&self) -> bool {
        self.posed_elsewhere
    }

    /// The first pose given here after poses made elsewhere: the roots the inertia last saw are
    /// those of a pose long gone, so it takes the new ones as the last step's (the kernel that
    /// bent meanwhile had every pose; a jump against the stale ones would start the motion over).
    fn rebase_after_elsewhere(&mut self, positions: &[Vec3]) {
        if std::mem::take(&mut self.posed_elsewhere) {
            self.inertia.rebase(positions);
        }
    }

    fn moved_base(&mut self) {
        self.versions.base += 1;
        self.roots_moved = true;
    }

    fn check_base(&self, positions: &[Vec3], frames: &[Vec3], what_frames: &'static str) -> Result<(), SimError> {
        let v = self.vertex_count;
        for (what, values) in [("the base positions", positions), (what_frames, frames)] {
            if values.len() != v {
                return Err(SimError::Size { what, expected: v, got: values.len() });
            }
            if let Some(bad) = values.iter().find(|p| !p.is_finite()) {
                return Err(SimError::NonFinite { what, value: bad.to_string() });
            }
        }
        Ok(())
    }

    /// The user force field (added to wind; the touch overrides it near the hit).
    #[must_use]
    pub fn field(&self) -> &ForceField {
        &self.field
    }

    /// The user force field, to edit; takes effect from the next step.
    pub fn field_mut(&mut self) -> &mut ForceField {
        self.versions.field += 1;
        &mut self.field
    }

    /// The external field (wind + field + touch, gravity not included) the newest state used.
    #[must_use]
    pub fn external_field(&self) -> &[Vec3] {
        &self.external
    }

    /// Computes the external field (wind + field + touch, without gravity) at `time_secs` into
    /// `out`, without stepping.
    ///
    /// # Panics
    /// If `out.len()` is not the base vertex count.
    pub fn evaluate_field(&self, time_secs: f64, out: &mut [Vec3]) {
        assert_eq!(out.len(), self.vertex_count, "one force per base vertex");
        self.external_field_into(&self.step_inputs(time_secs), out);
    }

    fn external_field_into(&self, inputs: &StepInputs, out: &mut [Vec3]) {
        let (wind, field, roots) = (&inputs.wind, self.field.values(), &self.roots);
        out.par_iter_mut().enumerate().with_min_len(256).for_each(|(j, force)| {
            *force = wind.force(j, roots[j]) + field[j];
        });
        if let Some(touch) = &self.touch {
            touch.blend(inputs.touch_force, inputs.touch_presence, out);
        }
    }

    /// The inputs every strand shares in the step at `time_secs` (gravity, the wind's step, the
    /// touch, Equation 1's gain), with the parameters and touch as they are now: what the CPU
    /// kernel bends with, for another kernel to take as they are.
    #[must_use]
    pub fn step_inputs(&self, time_secs: f64) -> StepInputs {
        StepInputs::new(&self.params, self.layers, self.radius, self.touch.as_ref(), time_secs)
    }

    /// The per-strand inputs as they are now (posed roots and frames, stability, the user field,
    /// the touch's weights, the inertial force of the newest step: zero while another kernel
    /// bends, see [`Simulation::set_cpu_bending`]).
    #[must_use]
    pub fn strand_inputs(&self) -> StrandInputs<'_> {
        StrandInputs {
            roots: &self.roots,
            frames: &self.frames,
            stability: self.params.stability,
            stability_map: self.stability_map.as_deref(),
            field: self.field.values(),
            touch_weights: self.touch.as_ref().map_or(&[], |touch| touch.weights()),
            inertial: self.inertia.forces(),
            wetness: self.wetness.as_deref(),
            wet_weight: self.wet_weight,
            wet_softening: self.wet_softening,
        }
    }

    /// Each strand's wetness in `[0, 1]` (`None`, or all zero: dry, the bytes of a fur that was
    /// never wet), from the next step on: a wet strand's gravity is `1 + params.added_weight * w`
    /// times stronger, its stability `1 - params.softening * w` times lower, and its swing after
    /// the body's motion slower (the inertial spring's frequency over `sqrt(1 + added_weight * w)`,
    /// a heavier mass on the same spring).
    ///
    /// # Errors
    /// [`SimError::Size`] unless there is one value per strand; [`SimError::Params`] for a value
    /// outside `[0, 1]` or parameters out of range.
    pub fn set_wetness(&mut self, wetness: Option<&[f32]>, params: &crate::wet::WetParams) -> Result<(), SimError> {
        params.validate()?;
        let wetness = wetness.filter(|w| w.iter().any(|&x| x != 0.0));
        if let Some(values) = wetness {
            if values.len() != self.vertex_count {
                return Err(SimError::Size { what: "the wetness", expected: self.vertex_count, got: values.len() });
            }
            if let Some(bad) = values.iter().find(|w| !(0.0..=1.0).contains(*w)) {
                return Err(ParamError {
                    key: "wetness".into(),
                    problem: format!("must be between 0 and 1, got {bad}"),
                }
                .into());
            }
        }
        let same = match (wetness, &self.wetness) {
            (Some(values), Some(kept)) => values == &kept[..],
            (None, None) => true,
            _ => false,
        };
        if same && self.wet_weight == params.added_weight && self.wet_softening == params.softening {
            return Ok(());
        }
        // The stabilities a GPU kernel keeps resident change with the wetness.
        self.versions.stability += 1;
        match (wetness, &mut self.wetness) {
            (Some(values), Some(kept)) => kept.copy_from_slice(values),
            (values, kept) => *kept = values.map(<[f32]>::to_vec),
        }
        self.wet_weight = params.added_weight;
        self.wet_softening = params.softening;
        let masses: Option<Vec<f32>> =
            self.wetness.as_ref().map(|w| w.iter().map(|&x| params.gravity_scale(x)).collect());
        self.inertia.set_masses(masses);
        Ok(())
    }

    /// Each strand's wetness, if any is wet.
    #[must_use]
    pub fn wetness(&self) -> Option<&[f32]> {
        self.wetness.as_deref()
    }

    /// Begins a touch at `point` (on or near the base surface; see [`Simulation::pick`]) with
    /// radius `radius` (world units). Replaces any touch in progress.
    ///
    /// # Errors
    /// [`SimError::NonFinite`] for a non-finite point, [`SimError::TouchRadius`] for a radius
    /// that is not finite and positive.
    pub fn touch_begin(&mut self, point: Vec3, radius: f32) -> Result<(), SimError> {
        if !point.is_finite() {
            return Err(SimError::NonFinite { what: "the touch point", value: point.to_string() });
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(SimError::TouchRadius(radius));
        }
        self.touch = Some(Touch::new(point, radius, &self.roots));
        self.touch_on_step_roots = !self.roots_moved;
        self.versions.touch += 1;
        Ok(())
    }

    /// Picks the base mesh (current roots, `triangles` from [`FurStructure::mesh`]) with a ray
    /// and begins a touch of `radius` at the hit; `None` (and no touch) on a miss.
    ///
    /// # Errors
    /// [`SimError::TouchRadius`] for a radius that is not finite and positive.
    pub fn touch_ray(
        &mut self,
        triangles: &[[u32; 3]],
        ray_origin: Vec3,
        ray_direction: Vec3,
        radius: f32,
    ) -> Result<Option<Hit>, SimError> {
        let Some(hit) = self.pick(triangles, ray_origin, ray_direction) else { return Ok(None) };
        self.touch_begin(hit.point, radius)?;
        Ok(Some(hit))
    }

    /// Drags the touch in progress to `point`: the interaction vector becomes `point - hit`.
    /// Does nothing without a touch in progress.
    ///
    /// # Errors
    /// [`SimError::NonFinite`] for a non-finite point.
    pub fn touch_drag(&mut self, point: Vec3) -> Result<(), SimError> {
        if !point.is_finite() {
            return Err(SimError::NonFinite { what: "the drag point", value: point.to_string() });
        }
        if let Some(touch) = self.touch.as_mut().filter(|t| t.released_at_secs.is_none()) {
            touch.drag = point;
        }
        Ok(())
    }

    /// Ends the touch at the current time. The field's original values come back at once, or
    /// fade back over `SimParams::touch.release_secs`; either way exactly.
    pub fn touch_end(&mut self) {
        if self.params.touch.release_secs <= 0.0 {
            self.touch = None;
        } else if let Some(touch) = self.touch.as_mut().filter(|t| t.released_at_secs.is_none()) {
            touch.released_at_secs = Some(self.time_secs);
        }
    }

    /// The touch in progress (or fading out), if any.
    #[must_use]
    pub fn touch(&self) -> Option<&Touch> {
        self.touch.as_ref()
    }

    /// Whether the touch in progress began on the roots of the newest step (the base did not
    /// move between that step and the touch): a kernel that keeps each step's roots can weigh
    /// the touch from them. A host posing the base between steps can begin one on roots no step
    /// used.
    #[must_use]
    pub fn touch_began_on_step_roots(&self) -> bool {
        self.touch.is_some() && self.touch_on_step_roots
    }

    /// Replaces the colliders (a host may call it every frame). A collider whose `id` was in the
    /// last list and that has one key continues the old one's motion from its last key (so the
    /// step sweeps the path between and friction sees the motion) and keeps its appearance time;
    /// a new id appears now and grows in.
    ///
    /// # Errors
    /// [`SimError::Collider`] naming the first bad collider and key; nothing changes then.
    pub fn set_colliders(&mut self, colliders: &[Collider]) -> Result<(), SimError> {
        for (index, collider) in colliders.iter().enumerate() {
            collider.validate().map_err(|(key, problem)| SimError::Collider {
                index,
                id: collider.id,
                key,
                problem,
            })?;
        }
        let now = self.recent_step_times.last().copied().unwrap_or(self.time_secs);
        let joined = colliders
            .iter()
            .map(|collider| {
                let mut collider = collider.clone();
                let old = self.colliders.iter().find(|c| c.id == collider.id);
                match old {
                    Some(old) if collider.keys.len() == 1 => {
                        let last = *old.keys.last().expect("validated: one key at least");
                        if last.time_secs < collider.keys[0].time_secs {
                            collider.keys.insert(0, last);
                        }
                        let step_secs = 1.0 / f64::from(self.params.rate_hz);
                        collider.appeared_secs = old.appeared_at(f64::MAX, step_secs);
                        if collider.appeared_at(f64::MAX, step_secs) != collider.appeared_secs {
                            // It jumped: it grows in again from its new place.
                            collider.keys.remove(0);
                            collider.appeared_secs = Some(now.min(collider.keys[0].time_secs));
                        }
                    }
                    None if collider.appeared_secs.is_none() && collider.keys.len() == 1 => {
                        collider.appeared_secs = Some(now.min(collider.keys[0].time_secs));
                    }
                    _ => {}
                }
                collider
            })
            .collect();
        self.colliders = joined;
        Ok(())
    }

    /// The colliders in use.
    #[must_use]
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// Closes a hand at `point` at `time_secs` (simulation time): the strands rooted within `radius` are gathered toward the grip
    /// (moved by [`Simulation::grasp_move`]); a hand of `hand_radius` (0: none; see
    /// [`Grasp::hand`]) about the grip pushes the strands it does not hold. Replaces a grasp in
    /// progress.
    ///
    /// # Errors
    /// [`SimError::NonFinite`] for a non-finite point; [`SimError::TouchRadius`] for a radius
    /// that is not finite and positive or a hand radius that is negative; [`SimError::Params`]
    /// for bad `params`.
    pub fn grasp_begin(
        &mut self,
        point: Vec3,
        radius: f32,
        hand_radius: f32,
        params: GraspParams,
        time_secs: f64,
    ) -> Result<(), SimError> {
        if !point.is_finite() {
            return Err(SimError::NonFinite { what: "the grasp point", value: point.to_string() });
        }
        if !(radius.is_finite() && radius > 0.0) {
            return Err(SimError::TouchRadius(radius));
        }
        if !(hand_radius.is_finite() && hand_radius >= 0.0) {
            return Err(SimError::TouchRadius(hand_radius));
        }
        params.validate().map_err(|(key, problem)| ParamError { key: format!("grasp.{key}"), problem })?;
        if !time_secs.is_finite() {
            return Err(SimError::NonFinite { what: "the grasp time", value: time_secs.to_string() });
        }
        let normals: Vec<Vec3> = self.frames.iter().zip(&self.rest_normals).map(|(frame, n)| *frame * *n).collect();
        self.grasp = Some(Grasp::new(point, radius, hand_radius, time_secs, params, &self.roots, &normals));
        Ok(())
    }

    /// Moves the grip of the grasp in progress to `point`. Does nothing without one.
    ///
    /// # Errors
    /// [`SimError::NonFinite`] for a non-finite point.
    pub fn grasp_move(&mut self, point: Vec3) -> Result<(), SimError> {
        if !point.is_finite() {
            return Err(SimError::NonFinite { what: "the grip point", value: point.to_string() });
        }
        if let Some(grasp) = self.grasp.as_mut().filter(|g| g.released_at_secs.is_none()) {
            grasp.grip = point;
        }
        Ok(())
    }

    /// Opens the hand at `time_secs`: the held strands spring back and settle.
    pub fn grasp_end(&mut self, time_secs: f64) {
        if let Some(grasp) = self.grasp.as_mut().filter(|g| g.released_at_secs.is_none()) {
            grasp.released_at_secs = Some(time_secs);
        }
    }

    /// The grasp holding or springing back, if any.
    #[must_use]
    pub fn grasp(&self) -> Option<&Grasp> {
        self.grasp.as_ref()
    }

    /// What every strand shares in the contact of the step at `time_secs`: the skin switch, the
    /// colliders there (the grasp's hand first, then the colliders sampled along their paths
    /// within the step, grown since they appeared), the grip and its presence. Read by every kernel.
    #[must_use]
    pub fn contact_step(&self, time_secs: f64) -> ContactStep {
        let step_secs = 1.0 / f64::from(self.params.rate_hz);
        let mut colliders = Vec::new();
        for collider in &self.colliders {
            collider.push_step(time_secs, step_secs, self.radius, &mut colliders);
        }
        let mut step = ContactStep { skin: self.params.contact.skin, ..ContactStep::default() };
        if let Some(grasp) = &self.grasp {
            colliders.splice(0..0, grasp.hand(time_secs));
            step.grip = grasp.grip;
            step.grip_presence = grasp.presence(time_secs);
        }
        colliders.truncate(MAX_STEP_COLLIDERS);
        step.colliders = colliders;
        step
    }

    /// The per-strand contact inputs: skin planes and the grasp's weights.
    #[must_use]
    pub fn contact_strands(&self) -> ContactStrands<'_> {
        ContactStrands {
            skin: &self.skin,
            grasp_weights: self.grasp.as_ref().map_or(&[], |g| g.weights()),
            surface: &self.surface,
            rest_roots: &self.rest_roots,
        }
    }

    /// The nearest hit of a ray with the base mesh at its current root positions.
    #[must_use]
    pub fn pick(&self, triangles: &[[u32; 3]], ray_origin: Vec3, ray_direction: Vec3) -> Option<Hit> {
        pick(&self.roots, triangles, ray_origin, ray_direction)
    }

    /// Advances to render time `time_secs`: runs the fixed steps needed (at most two, whatever
    /// the jump) and updates [`Simulation::positions`]. Without interpolation it simulates at
    /// `time_secs` itself, every call. A non-finite time does nothing.
    pub fn advance_to(&mut self, time_secs: f64) {
        if !time_secs.is_finite() {
            return;
        }
        self.time_secs = time_secs;
        if self.params.interpolate {
            let stride = i64::from(self.step_stride);
            let steps = time_secs * f64::from(self.params.rate_hz);
            let index = self.step_index_at(time_secs);
            if index != self.step_index {
                if index.checked_sub(stride) == Some(self.step_index) {
                    std::mem::swap(&mut self.previous, &mut self.current);
                    self.step_into_current(index as f64 / f64::from(self.params.rate_hz));
                    self.step_index = index;
                } else {
                    self.jump_to_step(index);
                }
            }
            self.alpha = ((steps - index as f64) / stride as f64).clamp(0.0, 1.0) as f32;
        } else {
            std::mem::swap(&mut self.previous, &mut self.current);
            self.step_into_current(time_secs);
            self.alpha = 1.0;
        }
        self.drop_faded_touch();
        if self.grasp.as_ref().is_some_and(|g| g.settled(self.time_secs)) {
            self.grasp = None;
        }
        if self.cpu_bending {
            self.update_output();
        }
    }

    /// The positions to draw, layer-major like [`FurStructure::positions`]:
    /// `lerp(previous, current, alpha)` for the last [`Simulation::advance_to`] time.
    #[must_use]
    pub fn positions(&self) -> &[Vec3] {
        &self.output
    }

    /// Writes `previous * (1 - alpha) + current * alpha`, layer-major, to `out`: exactly the
    /// previous state at `alpha = 0` and exactly the current one at `alpha = 1`.
    ///
    /// # Panics
    /// If `out` is not `(L + 1) * V` long.
    pub fn write_lerp(&self, alpha: f32, out: &mut [Vec3]) {
        let v = self.vertex_count;
        let nodes = self.layers as usize + 1;
        assert_eq!(out.len(), v * nodes, "the shared vertex array has (L + 1) * V entries");
        if v == 0 {
            return;
        }
        let (previous, current) = (&self.previous, &self.current);
        // Each task owns a run of whole batches and writes their slice of every layer row, so it
        // reads its batches' memory once, front to back, instead of once per row.
        let mut pieces: Vec<Vec<&mut [Vec3]>> =
            (0..v.div_ceil(LERP_STRANDS_PER_TASK)).map(|_| Vec::with_capacity(nodes)).collect();
        for row in out.chunks_mut(v) {
            for (piece, task) in row.chunks_mut(LERP_STRANDS_PER_TASK).zip(&mut pieces) {
                task.push(piece);
            }
        }
        pieces.into_par_iter().enumerate().for_each(|(t, rows)| {
            let first_batch = t * LERP_STRANDS_PER_TASK / LANES;
            for (i, row) in rows.into_iter().enumerate() {
                for (bb, positions) in row.chunks_mut(LANES).enumerate() {
                    let k = (first_batch + bb) * nodes + i;
                    let (a, c) = (&previous[k], &current[k]);
                    for (lane, position) in positions.iter_mut().enumerate() {
                        let lerp = |axis: usize| a[axis][lane] * (1.0 - alpha) + c[axis][lane] * alpha;
                        *position = Vec3::new(lerp(0), lerp(1), lerp(2));
                    }
                }
            }
        });
    }

    /// Chooses the CPU kernel's instructions (AVX2 + FMA or portable; both give the same bytes).
    /// [`CpuKernel::Auto`], the default, takes the best the CPU has; asking for AVX2 on a CPU
    /// without it runs the portable kernel ([`Simulation::cpu_kernel`] says which runs).
    pub fn set_cpu_kernel(&mut self, kernel: CpuKernel) {
        self.cpu_kernel = kernel;
    }

    /// The CPU kernel that runs the steps ([`CpuKernel::Avx2Fma`] or [`CpuKernel::Portable`]).
    #[must_use]
    pub fn cpu_kernel(&self) -> CpuKernel {
        self.cpu_kernel.resolve()
    }

    /// The share of strands the straight (cheaper, exact) form of the kernel bends, in `[0, 1]`:
    /// batches of 8 strands that are all straight. Fur grown by [`FurStructure::new`] is
    /// straight; a structure whose positions were edited to curve takes the general form.
    #[must_use]
    pub fn straight_share(&self) -> f32 {
        self.rest.straight_share()
    }

    /// Runs one step at `time_secs` into the newest state (the newest becomes the previous)
    /// without updating [`Simulation::positions`]: the simulation's whole per-step work (field,
    /// then the bend of every strand) and nothing else, for benchmarks and soak tests. Read the
    /// state with [`Simulation::write_lerp`] at alpha 1. The next [`Simulation::advance_to`]
    /// recomputes its states from scratch. A non-finite time does nothing.
    pub fn step_at(&mut self, time_secs: f64) {
        if !time_secs.is_finite() {
            return;
        }
        std::mem::swap(&mut self.previous, &mut self.current);
        self.step_into_current(time_secs);
        self.time_secs = time_secs;
        self.step_index = i64::MIN;
    }

    /// The interpolation weight of the current state at the last render time.
    #[must_use]
    pub fn alpha(&self) -> f32 {
        self.alpha
    }

    /// The last render time given to [`Simulation::advance_to`].
    #[must_use]
    pub fn time_secs(&self) -> f64 {
        self.time_secs
    }

    /// Wall-clock seconds the last step took (the viewer shows it).
    #[must_use]
    pub fn last_step_secs(&self) -> f64 {
        self.last_step_secs
    }

    /// Takes every `stride`-th fixed step only (1, 2 or 4; others are rounded down to one of
    /// them), the frames between interpolated as ever: a host steps a fur far from the camera
    /// less often, where its strands' motion spans less than a pixel. With inertia the swing
    /// follows the longer steps; without it a step's state depends only on its time, so the
    /// states taken equal the full rate's. Takes effect at the next step.
    pub fn set_step_stride(&mut self, stride: u32) {
        self.step_stride = match stride {
            0..=1 => 1,
            2..=3 => 2,
            _ => 4,
        };
    }

    /// Whether [`Simulation::advance_to`] at `time_secs` takes a step (else it only
    /// interpolates): a host can skip posing a base that no step reads.
    #[must_use]
    pub fn steps_at(&self, time_secs: f64) -> bool {
        !self.params.interpolate || !time_secs.is_finite() || self.step_index_at(time_secs) != self.step_index
    }

    /// The last step at or before `time_secs`, numbered at the full rate; a stride of k takes
    /// every k-th of them.
    fn step_index_at(&self, time_secs: f64) -> i64 {
        let stride = i64::from(self.step_stride);
        let steps = time_secs * f64::from(self.params.rate_hz);
        (steps / stride as f64).floor() as i64 * stride
    }

    /// The stride [`Simulation::set_step_stride`] set.
    #[must_use]
    pub fn step_stride(&self) -> u32 {
        self.step_stride
    }

    /// Steps run since construction.
    #[must_use]
    pub fn steps_taken(&self) -> u64 {
        self.steps_taken
    }

    /// `L`, the number of layers above the base.
    #[must_use]
    pub fn layers(&self) -> u32 {
        self.layers
    }

    /// `V`, the number of strands (base vertices).
    #[must_use]
    pub fn vertex_count(&self) -> usize {
        self.vertex_count
    }

    /// The root positions at rest (the base mesh's vertices).
    #[must_use]
    pub fn rest_roots(&self) -> &[Vec3] {
        &self.rest_roots
    }

    /// The current root positions.
    #[must_use]
    pub fn roots(&self) -> &[Vec3] {
        &self.roots
    }

    /// Turns the bending of strands on this CPU on or off. Off, [`Simulation::advance_to`] still
    /// keeps the time, the steps ([`Simulation::recent_step_times`]), the touch and every input,
    /// but bends nothing and leaves [`Simulation::positions`] and
    /// [`Simulation::external_field`] as they were: for a host whose strands are bent by another
    /// kernel (`pelt_render::GpuSimulation`) from this simulation's inputs. Off, the inertia's
    /// steps are only decided ([`Simulation::recent_inertia_steps`]) and
    /// [`Simulation::inertial_forces`] stays zero: the kernel that bends keeps the forces.
    /// Either way the next `advance_to` recomputes both states and the motion so far is
    /// forgotten, so switching never mixes kernels in one pair.
    pub fn set_cpu_bending(&mut self, on: bool) {
        if on != self.cpu_bending {
            self.cpu_bending = on;
            self.step_index = i64::MIN;
            self.inertia.reset();
        }
    }

    /// Whether steps bend the strands on this CPU (see [`Simulation::set_cpu_bending`]).
    #[must_use]
    pub fn cpu_bending(&self) -> bool {
        self.cpu_bending
    }

    /// The simulation times of the last two steps (fewer before two were taken), oldest first.
    /// Every step makes the current state the previous one and computes the new current state
    /// at its time; with [`Simulation::steps_taken`] another kernel can replay the steps it has
    /// not seen (only the last two matter: a step depends on its inputs, not on earlier states).
    #[must_use]
    pub fn recent_step_times(&self) -> &[f64] {
        &self.recent_step_times
    }

    /// What each of [`Simulation::recent_step_times`]' steps did to the inertial state (one
    /// entry per step, oldest first): with the CPU's bending off the simulation only decides
    /// them, and the kernel that bends applies them to every strand.
    #[must_use]
    pub fn recent_inertia_steps(&self) -> &[InertiaStep] {
        &self.recent_inertia_steps
    }

    /// Counters of the per-strand inputs' changes (roots, stability, field, touch).
    #[must_use]
    pub fn input_versions(&self) -> InputVersions {
        self.versions
    }

    /// Each strand's rotation from its rest frame into the current base frame (identity until
    /// [`Simulation::set_base`] or [`Simulation::set_base_rotations`]).
    #[must_use]
    pub fn frames(&self) -> &[Quat] {
        &self.frames
    }

    /// The per-vertex stability map, if one is set.
    #[must_use]
    pub fn stability_map(&self) -> Option<&[f32]> {
        self.stability_map.as_deref()
    }

    /// The bounding radius of the base at rest (from the box centre): the unit of the wind's
    /// gust sizes and speeds ([`WindParams::sample`]'s `radius`).
    #[must_use]
    pub fn bounding_radius(&self) -> f32 {
        self.radius
    }

    /// The inertial force per strand at the newest step (see [`Inertia`]).
    #[must_use]
    pub fn inertial_forces(&self) -> &[Vec3] {
        self.inertia.forces()
    }

    /// The inertial state, e.g. to count teleports.
    #[must_use]
    pub fn inertia(&self) -> &Inertia {
        &self.inertia
    }

    /// Forgets the base's motion so far (call it when a new animation starts or the body is
    /// moved somewhere else): the fur is not flung by the jump.
    pub fn reset_motion(&mut self) {
        self.inertia.reset();
    }

    /// Recomputes both kept states for the current base and time, forgetting the motion so far:
    /// for a base that jumped (the first pose of an animation, a new animation, a scrubbed
    /// timeline), so the fur starts from it at rest instead of flying to it.
    pub fn restart(&mut self) {
        self.inertia.reset();
        let index = if self.step_index == i64::MIN { 0 } else { self.step_index };
        self.jump_to_step(index);
        if self.cpu_bending {
            self.update_output();
        }
    }

    fn jump_to_step(&mut self, index: i64) {
        // The inertia sees the two steps' times: a short skip forward keeps the swing going (the
        // acceleration is taken over the uneven steps), a jump back or far ahead starts it over.
        let rate = f64::from(self.params.rate_hz);
        self.step_into_current((index as f64 - f64::from(self.step_stride)) / rate);
        std::mem::swap(&mut self.previous, &mut self.current);
        self.step_into_current(index as f64 / rate);
        self.step_index = index;
    }

    /// Computes the state at `time_secs` into `current`.
    fn step_into_current(&mut self, time_secs: f64) {
        self.steps_taken += 1;
        self.recent_step_times.push(time_secs);
        if self.recent_step_times.len() > 2 {
            self.recent_step_times.remove(0);
        }
        // The inertia is state carried from step to step. Its step is decided here whichever
        // kernel bends; the kernel that bends applies it to every strand.
        let (inertia, damping) = (self.params.inertia, self.params.damping);
        let roots_moved = std::mem::take(&mut self.roots_moved);
        let inertia_step = if self.cpu_bending {
            self.inertia.update(&self.roots, time_secs, inertia, damping, self.radius)
        } else {
            self.inertia.advance(&self.roots, roots_moved, time_secs, inertia, damping, self.radius)
        };
        self.recent_inertia_steps.push(inertia_step);
        if self.recent_inertia_steps.len() > 2 {
            self.recent_inertia_steps.remove(0);
        }
        if !self.cpu_bending {
            return;
        }
        let started = Instant::now();
        let inputs = self.step_inputs(time_secs);
        let mut external = std::mem::take(&mut self.external);
        self.external_field_into(&inputs, &mut external);
        self.external = external;
        // Taken out while `strands` borrows the simulation.
        let mut current = std::mem::take(&mut self.current);
        let strands = self.strand_inputs();
        let step = Step {
            layers: self.layers as usize,
            vertex_count: self.vertex_count,
            gain: inputs.gain,
            gravity: inputs.gravity,
            stability: strands.stability,
            stability_map: strands.stability_map,
            roots: strands.roots,
            frames: strands.frames,
            external: &self.external,
            inertial: strands.inertial,
            wetness: strands.wetness.map(|w| (w, strands.wet_weight, strands.wet_softening)),
            rest: &self.rest,
        };
        let contact = self.contact_step(time_secs);
        let resolve = Resolve {
            step: &contact,
            strands: self.contact_strands(),
            skin_lanes: &self.skin_lanes,
            kernel: self.cpu_kernel,
            screen: self.contact_screen,
            roots: strands.roots,
            frames: strands.frames,
            rest: &self.rest,
            layers: self.layers as usize,
            vertex_count: self.vertex_count,
        };
        dispatch::bend_all(self.cpu_kernel, &step, Some(&resolve), &mut current);
        self.current = current;
        self.last_step_secs = started.elapsed().as_secs_f64();
    }

    fn drop_faded_touch(&mut self) {
        let release_secs = self.params.touch.release_secs;
        if self
            .touch
            .as_ref()
            .is_some_and(|t| t.released_at_secs.is_some() && t.presence(self.time_secs, release_secs) == 0.0)
        {
            self.touch = None;
        }
    }

    fn update_output(&mut self) {
        let mut output = std::mem::take(&mut self.output);
        self.write_lerp(self.alpha, &mut output);
        self.output = output;
    }
}

/// Centre and radius of a bounding sphere (box centre, farthest point); radius at least a tiny
/// positive value so relative sizes stay finite on a degenerate base.
fn bounding_sphere(points: &[Vec3]) -> (Vec3, f32) {
    let (min, max) =
        points.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let centre = if points.is_empty() { Vec3::ZERO } else { (min + max) * 0.5 };
    let radius = points.iter().map(|p| p.distance(centre)).fold(0.0, f32::max);
    (centre, radius.max(1e-6))
}
