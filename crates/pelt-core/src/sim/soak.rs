//! A soak test for any simulation kernel: many steps under extreme, changing inputs, checking
//! after every step that every node is finite and every segment kept its rest length.
//!
//! The inputs are a pure function of the step index ([`SoakStep::at`]): gravity up to 1,000
//! times its default turning in every direction, both forms of Equation 1, stability from 1e-6
//! (the least allowed) to 1e3, gusty wind up to 1e4, inertia up to 100 (its maximum) with the
//! base teleported and turned every 307 steps, a force field switched between zero,
//! moderate and huge finite values (1e30, whose squared length overflows `f32`), a stability map,
//! the base turned and moved, and touches begun, dragged a million radii away and released. A
//! kernel is driven through [`SoakSubject`]; [`Simulation`] implements it, and a GPU kernel can
//! too.

use glam::{Quat, Vec3};

use super::{Equation, SimError, SimParams, Simulation, WindParams};
use crate::fur::FurStructure;

/// One step of the soak: everything a kernel needs to apply before simulating it.
#[derive(Clone, Debug, PartialEq)]
pub struct SoakStep {
    /// The step number, from 0.
    pub index: u64,
    /// Simulation time of the step (`index / 30` seconds).
    pub time_secs: f64,
    /// The parameters in force.
    pub params: SimParams,
    /// What the touch does this step.
    pub touch: SoakTouch,
    /// A new value for the whole force field, when it changes.
    pub field: Option<Vec3>,
    /// A new per-vertex stability map, when it changes (`Some(None)` removes it).
    pub stability_map: Option<Option<SoakStabilityMap>>,
    /// A new rotation and offset of the whole base, when it changes.
    pub base: Option<(Quat, Vec3)>,
}

/// A stability map as a rule: vertex `j` gets `low` when `j % period == 0`, else `high`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SoakStabilityMap {
    /// Stability of every `period`-th vertex.
    pub low: f32,
    /// Stability of the others.
    pub high: f32,
    /// Period of the pattern (at least 1).
    pub period: usize,
}

impl SoakStabilityMap {
    /// The map for `vertex_count` vertices.
    #[must_use]
    pub fn values(&self, vertex_count: usize) -> Vec<f32> {
        (0..vertex_count).map(|j| if j % self.period.max(1) == 0 { self.low } else { self.high }).collect()
    }
}

/// The touch's action in one soak step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SoakTouch {
    /// Nothing changes.
    Keep,
    /// Begin a touch at base vertex `vertex`'s root with this radius (world units).
    Begin {
        /// The touched base vertex.
        vertex: usize,
        /// Touch radius.
        radius: f32,
    },
    /// Drag the touch to this point.
    Drag(Vec3),
    /// Release the touch.
    End,
}

/// A simple, stateless hash to a number in `[0, 1)` for the schedule.
fn unit(index: u64, salt: u64) -> f32 {
    let bits = crate::rng::hash(0x50AC, index, salt, 0);
    crate::rng::unit_f32(bits)
}

impl SoakStep {
    /// The soak's inputs at step `index` on a base of `vertex_count` vertices and bounding
    /// radius `radius`. Parameters change every 37 steps, the field every 101, the stability
    /// map every 211, the base every 307; a touch begins every 90 steps, is dragged every step
    /// and released 50 steps later.
    #[must_use]
    pub fn at(index: u64, vertex_count: usize, radius: f32) -> Self {
        let epoch = index / 37;
        let r = |salt| unit(epoch, salt);
        let direction = Vec3::new(r(1) - 0.5, r(2) - 0.5, r(3) - 0.5);
        let direction = if direction.length_squared() > 1e-6 { direction } else { Vec3::NEG_Y };
        let gravity_strength = [0.0, 1.0, 1000.0, 1000.0 * r(4)][(epoch % 4) as usize];
        let stability = 10f32.powf(-6.0 + 9.0 * r(5));
        let wind = WindParams {
            direction: Vec3::new(r(6) - 0.5, r(7) - 0.5, r(8) - 0.5) + Vec3::X * 1e-3,
            strength: if epoch.is_multiple_of(3) { 0.0 } else { 10f32.powf(4.0 * r(9)) },
            gust_strength: r(10),
            gust_speed: 0.1 + 5.0 * r(11),
            jitter: r(12),
            seed: epoch,
            ..WindParams::default()
        };
        let params = SimParams {
            stability,
            equation: if epoch % 5 == 4 { Equation::Paper } else { Equation::Pelt },
            gravity_direction: direction,
            gravity_strength,
            interpolate: false,
            wind,
            inertia: [0.0, 0.05, 100.0][(epoch % 3) as usize],
            damping: 2.0 * r(13),
            ..SimParams::default()
        };
        let touch = match index % 90 {
            0 => SoakTouch::Begin {
                vertex: (unit(index, 20) * vertex_count as f32) as usize % vertex_count.max(1),
                radius: radius * (0.05 + 0.5 * unit(index, 21)),
            },
            50 => SoakTouch::End,
            phase if phase < 50 => {
                let reach = radius * 10f32.powf(6.0 * unit(index, 22) - 2.0);
                SoakTouch::Drag(Vec3::new(unit(index, 23) - 0.5, unit(index, 24) - 0.5, unit(index, 25) - 0.5) * reach)
            }
            _ => SoakTouch::Keep,
        };
        let field = index.is_multiple_of(101).then(|| {
            let e = index / 101;
            let v = Vec3::new(unit(e, 30) - 0.5, unit(e, 31) - 0.5, unit(e, 32) - 0.5);
            [Vec3::ZERO, v * 3.0, v * 1e30, Vec3::new(1e30, -1e30, 1e30), v * 1e-30][(e % 5) as usize]
        });
        let stability_map = index.is_multiple_of(211).then(|| {
            let e = index / 211;
            (e % 2 == 1).then_some(SoakStabilityMap { low: 1e-6, high: 10f32.powf(3.0 * unit(e, 40)), period: 3 })
        });
        let base = index.is_multiple_of(307).then(|| {
            let e = index / 307;
            let axis = Vec3::new(unit(e, 50) - 0.5, unit(e, 51) - 0.5, unit(e, 52) + 0.1).normalize();
            (Quat::from_axis_angle(axis, 6.0 * unit(e, 53)), axis * radius * 3.0 * unit(e, 54))
        });
        Self { index, time_secs: index as f64 / 30.0, params, touch, field, stability_map, base }
    }
}

/// A simulation kernel the soak can drive.
pub trait SoakSubject {
    /// Applies `step`'s inputs, then simulates the state at `step.time_secs`.
    ///
    /// # Errors
    /// Whatever the kernel rejects (the soak's inputs are all valid, so any error is a failure).
    fn step(&mut self, step: &SoakStep) -> Result<(), SimError>;

    /// Writes the newest state, layer-major like [`FurStructure::positions`], into `out`.
    ///
    /// # Errors
    /// A kernel that cannot read its state back (a GPU readback that failed).
    fn read_state(&mut self, out: &mut [Vec3]) -> Result<(), SimError>;
}

impl SoakSubject for Simulation {
    fn step(&mut self, step: &SoakStep) -> Result<(), SimError> {
        self.set_params(&step.params)?;
        if let Some(value) = step.field {
            self.field_mut().fill(value);
        }
        if let Some(map) = step.stability_map {
            let v = self.vertex_count();
            self.set_stability_map(map.map(|m| m.values(v)))?;
        }
        if let Some((rotation, offset)) = step.base {
            let rest = self.rest_roots().to_vec();
            let positions: Vec<Vec3> = rest.iter().map(|p| rotation * *p + offset).collect();
            self.set_base_rotations(&positions, &vec![rotation; positions.len()])?;
        }
        match step.touch {
            SoakTouch::Keep => {}
            SoakTouch::Begin { vertex, radius } => {
                let point = self.roots()[vertex];
                self.touch_begin(point, radius)?;
            }
            SoakTouch::Drag(offset) => {
                if let Some(point) = self.touch().map(|t| t.point) {
                    self.touch_drag(point + offset)?;
                }
            }
            SoakTouch::End => self.touch_end(),
        }
        self.step_at(step.time_secs);
        Ok(())
    }

    fn read_state(&mut self, out: &mut [Vec3]) -> Result<(), SimError> {
        self.write_lerp(1.0, out);
        Ok(())
    }
}

/// What a soak found.
#[derive(Clone, Debug, PartialEq)]
pub struct SoakReport {
    /// Steps run.
    pub steps: u64,
    /// The worst change of any segment's length over all checked steps, as a fraction of its
    /// strand's rest length.
    pub worst_length_error: f64,
    /// The step it happened at.
    pub worst_step: u64,
    /// Steps whose state had a NaN or infinite node (0 for a pass).
    pub non_finite_steps: u64,
    /// The first such step.
    pub first_non_finite_step: Option<u64>,
}

impl SoakReport {
    /// Whether the soak passed: every node finite and lengths kept to `tolerance` of their
    /// strand's length.
    #[must_use]
    pub fn passed(&self, tolerance: f64) -> bool {
        self.non_finite_steps == 0 && self.worst_length_error <= tolerance
    }
}

/// Runs `steps` soak steps of `subject`, which simulates `fur`, checking the state after each.
/// `progress` is called with the number of steps done every 1,000 steps.
///
/// # Errors
/// The first error the subject returns.
pub fn soak(
    fur: &FurStructure,
    subject: &mut dyn SoakSubject,
    steps: u64,
    mut progress: impl FnMut(u64),
) -> Result<SoakReport, SimError> {
    let v = fur.vertex_count();
    let layers = fur.layers as usize;
    let radius = bounding_radius(&fur.positions[..v]);
    let rest: Vec<f32> = (0..layers * v).map(|i| fur.positions[i + v].distance(fur.positions[i])).collect();
    let strand_lengths: Vec<f64> = (0..v).map(|j| (0..layers).map(|k| f64::from(rest[k * v + j])).sum()).collect();
    let mut state = vec![Vec3::ZERO; fur.positions.len()];
    let mut report = SoakReport {
        steps: 0,
        worst_length_error: 0.0,
        worst_step: 0,
        non_finite_steps: 0,
        first_non_finite_step: None,
    };
    for index in 0..steps {
        subject.step(&SoakStep::at(index, v, radius))?;
        subject.read_state(&mut state)?;
        let mut finite = true;
        for k in 0..layers {
            for j in 0..v {
                let (a, b) = (state[k * v + j], state[(k + 1) * v + j]);
                finite &= a.is_finite() && b.is_finite();
                let error =
                    (f64::from(b.distance(a)) - f64::from(rest[k * v + j])).abs() / strand_lengths[j].max(1e-30);
                if error > report.worst_length_error {
                    report.worst_length_error = error;
                    report.worst_step = index;
                }
            }
        }
        if !finite {
            report.non_finite_steps += 1;
            report.first_non_finite_step.get_or_insert(index);
        }
        report.steps = index + 1;
        if report.steps.is_multiple_of(1000) {
            progress(report.steps);
        }
    }
    Ok(report)
}

fn bounding_radius(points: &[Vec3]) -> f32 {
    let (min, max) =
        points.iter().fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), p| (lo.min(*p), hi.max(*p)));
    let centre = (min + max) * 0.5;
    points.iter().map(|p| p.distance(centre)).fold(1e-6, f32::max)
}
