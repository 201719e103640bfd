//! Inertia: fur on a moving body lags when the body starts, swings past when it stops, and
//! settles.
//!
//! Each root's acceleration comes from its positions at the last three steps,
//! `a = (r_n - 2 r_n-1 + r_n-2) / dt^2` (the uneven-step form when a step was skipped). In the body's frame that is a force `-a` on the strand;
//! in the preset's force units (gravity's default strength is 1) it is
//! `target = -inertia * a / radius`, so the same motion relative to the body's size bends fur
//! the same way on any mesh scale. The force on each strand follows its target as a damped
//! spring (natural frequency [`INERTIA_FREQUENCY_HZ`], damping ratio `damping`): it builds up
//! over a few steps, overshoots when the motion stops (the swing) and settles. This is the only
//! state the simulation carries from step to step.
//!
//! Teleports must not fling the fur: a root that moves more than [`TELEPORT_RADII_PER_STEP`]
//! bounding radii in one step, a jump in time or a host's [`Inertia::reset`] (a new animation)
//! start over from rest, and the target is clamped to [`MAX_INERTIAL_FORCE`].

use glam::Vec3;
use rayon::prelude::*;

/// Natural frequency of the fur's swing, in hertz.
pub const INERTIA_FREQUENCY_HZ: f32 = 2.0;

/// A root moving farther than this many bounding radii in one step is a teleport: the inertial
/// state starts over instead of seeing a huge acceleration.
pub const TELEPORT_RADII_PER_STEP: f32 = 0.5;

/// The largest inertial force (in gravity's units; the default gravity is 1).
pub const MAX_INERTIAL_FORCE: f32 = 10.0;

/// Steps further apart than this (seconds) are unrelated: the state starts over.
const MAX_STEP_GAP_SECS: f64 = 1.0;

/// Strands per parallel task.
const STRANDS_PER_TASK: usize = 1024;

/// The inertial force per strand and what it needs from earlier steps.
#[derive(Clone, Debug)]
pub struct Inertia {
    /// Roots at the last two steps (`[n - 1, n - 2]`), valid for `history` of them.
    previous_roots: Vec<[Vec3; 2]>,
    history: u8,
    last_time_secs: Option<f64>,
    /// Seconds between the last two steps.
    last_dt: f32,
    force: Vec<Vec3>,
    force_velocity: Vec<Vec3>,
    /// Per strand, the mass on the spring relative to a dry strand's (empty: all 1).
    masses: Vec<f32>,
    resets: u64,
}

impl Inertia {
    /// At rest, for `strands` strands.
    #[must_use]
    pub fn new(strands: usize) -> Self {
        Self {
            previous_roots: vec![[Vec3::ZERO; 2]; strands],
            history: 0,
            last_time_secs: None,
            last_dt: 0.0,
            force: vec![Vec3::ZERO; strands],
            force_velocity: vec![Vec3::ZERO; strands],
            masses: Vec::new(),
            resets: 0,
        }
    }

    /// Each strand's mass relative to a dry one (`None`: all 1): a heavier strand swings at
    /// `1 / sqrt(mass)` of the natural frequency ([`SpringStep::heavier`]). Values up to 1 count
    /// as 1.
    ///
    /// # Panics
    /// If `masses` has not one entry per strand.
    pub fn set_masses(&mut self, masses: Option<Vec<f32>>) {
        self.masses = masses.unwrap_or_default();
        assert!(self.masses.is_empty() || self.masses.len() == self.force.len(), "one mass per strand");
    }

    /// Takes `roots` as where the strands stood at the last step, whose pose this never saw (it
    /// was made elsewhere): the next step judges a teleport from there, the motion carrying on.
    pub fn rebase(&mut self, roots: &[Vec3]) {
        for (p, r) in self.previous_roots.iter_mut().zip(roots) {
            *p = [*r, *r];
        }
    }

    /// Forgets the motion: no force until two more steps have been seen.
    pub fn reset(&mut self) {
        self.history = 0;
        self.last_time_secs = None;
        self.force.fill(Vec3::ZERO);
        self.force_velocity.fill(Vec3::ZERO);
    }

    /// The inertial force per strand for the newest step.
    #[must_use]
    pub fn forces(&self) -> &[Vec3] {
        &self.force
    }

    /// How many times a teleport or a time jump started the state over (not counting
    /// [`Inertia::reset`]).
    #[must_use]
    pub fn teleports(&self) -> u64 {
        self.resets
    }

    /// Takes the roots of the step at `time_secs` and updates the forces. `inertia` scales the
    /// force, `damping` is the spring's damping ratio and `radius` the body's bounding radius.
    pub fn update(&mut self, roots: &[Vec3], time_secs: f64, inertia: f32, damping: f32, radius: f32) -> InertiaStep {
        assert_eq!(roots.len(), self.force.len(), "one root per strand");
        let step = self.decide(roots, true, time_secs, inertia, damping, radius);
        self.apply(step, roots);
        step
    }

    /// The step at `time_secs` decided as [`Inertia::update`] decides it, for another kernel
    /// (a GPU pass) to apply to every strand; the forces here stay as they were. Only the roots
    /// are kept, for the teleport check: `roots_moved` says whether they changed since the last
    /// step (when not, no root can have teleported and none is read).
    pub fn advance(
        &mut self,
        roots: &[Vec3],
        roots_moved: bool,
        time_secs: f64,
        inertia: f32,
        damping: f32,
        radius: f32,
    ) -> InertiaStep {
        assert_eq!(roots.len(), self.force.len(), "one root per strand");
        let step = self.decide(roots, roots_moved, time_secs, inertia, damping, radius);
        if step == InertiaStep::Start || roots_moved {
            for (p, r) in self.previous_roots.iter_mut().zip(roots) {
                *p = [*r, *r];
            }
        }
        step
    }

    /// What the step at `time_secs` does to every strand (the per-strand work is
    /// [`Inertia::apply`]'s).
    fn decide(
        &mut self,
        roots: &[Vec3],
        roots_moved: bool,
        time_secs: f64,
        inertia: f32,
        damping: f32,
        radius: f32,
    ) -> InertiaStep {
        let dt = self.last_time_secs.map(|last| time_secs - last);
        self.last_time_secs = Some(time_secs);
        let Some(dt) = dt.filter(|&dt| dt > 0.0 && dt <= MAX_STEP_GAP_SECS) else {
            if self.history > 0 {
                self.resets += 1;
            }
            self.history = 1;
            return InertiaStep::Start;
        };
        let teleport = TELEPORT_RADII_PER_STEP * radius;
        if self.history > 0
            && roots_moved
            && roots.iter().zip(&self.previous_roots).any(|(r, p)| r.distance(p[0]) > teleport)
        {
            self.resets += 1;
            self.history = 1;
            return InertiaStep::Start;
        }
        let (dt, dt_before) = (dt as f32, self.last_dt);
        self.last_dt = dt;
        if self.history < 2 || inertia == 0.0 {
            self.history = (self.history + 1).min(2);
            return InertiaStep::Shift { zero: inertia == 0.0 };
        }
        // The spring is stepped semi-implicitly (damping implicit) and its frequency kept below
        // the step rate, so it is stable at any rate and damping.
        let omega = (std::f32::consts::TAU * INERTIA_FREQUENCY_HZ).min(1.0 / dt);
        InertiaStep::Spring(SpringStep {
            dt,
            dt_before,
            // a = 2 ((r - r1) / dt - (r1 - r2) / dt_before) / (dt + dt_before).
            scale: -inertia * 2.0 / (radius * (dt + dt_before)),
            stiffness_dt: omega * omega * dt,
            damp: 1.0 / (1.0 + 2.0 * damping * omega * dt),
        })
    }

    /// Applies `step` to every strand at `roots`.
    fn apply(&mut self, step: InertiaStep, roots: &[Vec3]) {
        match step {
            InertiaStep::Start => {
                self.force.fill(Vec3::ZERO);
                self.force_velocity.fill(Vec3::ZERO);
                for (p, r) in self.previous_roots.iter_mut().zip(roots) {
                    *p = [*r, *r];
                }
            }
            InertiaStep::Shift { zero } => {
                if zero {
                    self.force.fill(Vec3::ZERO);
                    self.force_velocity.fill(Vec3::ZERO);
                }
                for (p, r) in self.previous_roots.iter_mut().zip(roots) {
                    *p = [*r, p[0]];
                }
            }
            InertiaStep::Spring(spring) => {
                let masses = &self.masses;
                self.previous_roots
                    .par_iter_mut()
                    .zip(self.force.par_iter_mut())
                    .zip(self.force_velocity.par_iter_mut())
                    .zip(roots.par_iter())
                    .enumerate()
                    .with_min_len(STRANDS_PER_TASK)
                    .for_each(|(j, (((previous, force), velocity), root))| {
                        let spring = match masses.get(j) {
                            Some(&mass) if mass > 1.0 => spring.heavier(mass),
                            _ => spring,
                        };
                        *force = spring.force(*previous, *root, force, velocity);
                        *previous = [*root, previous[0]];
                    });
            }
        }
    }
}

/// What one step does to every strand's inertial state: decided once per step from its time,
/// the history and the teleport check ([`Inertia::update`], [`Inertia::advance`]), then applied
/// to each strand by [`SpringStep::force`] or its GPU twin.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum InertiaStep {
    /// Start over from rest: no force, no velocity, both earlier roots set to this step's.
    Start,
    /// Too little history (or no inertia): the roots move down the history; with `zero` the
    /// force and its velocity become zero, else they stay.
    Shift {
        /// Inertia is off: the force and its velocity become zero.
        zero: bool,
    },
    /// The damped spring toward `target = -inertia * a / radius`.
    Spring(SpringStep),
}

/// The shared numbers of one spring step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpringStep {
    /// Seconds since the last step.
    pub dt: f32,
    /// Seconds between the two steps before.
    pub dt_before: f32,
    /// `-inertia * 2 / (radius * (dt + dt_before))`: the acceleration's factor.
    pub scale: f32,
    /// `omega^2 * dt` with `omega` the spring's angular frequency.
    pub stiffness_dt: f32,
    /// The implicit damping's factor `1 / (1 + 2 * damping * omega * dt)`.
    pub damp: f32,
}

impl SpringStep {
    /// The same step for a strand `mass` times heavier on the same spring: `omega` over
    /// `sqrt(mass)` (the GPU kernel does the same arithmetic).
    #[must_use]
    pub fn heavier(self, mass: f32) -> Self {
        Self {
            stiffness_dt: self.stiffness_dt / mass,
            damp: 1.0 / (1.0 + (1.0 / self.damp - 1.0) / mass.sqrt()),
            ..self
        }
    }

    /// One strand's new force from its earlier roots `[n - 1, n - 2]`, its root now, and its
    /// force and velocity (the velocity is updated in place).
    #[must_use]
    pub fn force(&self, previous: [Vec3; 2], root: Vec3, force: &Vec3, velocity: &mut Vec3) -> Vec3 {
        let acceleration = (root - previous[0]) / self.dt - (previous[0] - previous[1]) / self.dt_before;
        let target = (acceleration * self.scale).clamp_length_max(MAX_INERTIAL_FORCE);
        *velocity = (*velocity + (target - *force) * self.stiffness_dt) * self.damp;
        *force + *velocity * self.dt
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_steady_acceleration_gives_the_steady_force() {
        // Roots accelerating at 2 radii/s^2 along +X: the force settles at -inertia * 2 along X.
        let (rate, inertia, radius) = (30.0_f64, 0.5, 3.0);
        let mut state = Inertia::new(1);
        for n in 0..150 {
            let t = n as f64 / rate;
            let x = 0.5 * 2.0 * radius * (t * t) as f32;
            state.update(&[Vec3::new(x, 0.0, 0.0)], t, inertia, 0.7, radius);
        }
        let f = state.forces()[0];
        assert!((f.x + 1.0).abs() < 1e-2 && f.y == 0.0 && f.z == 0.0, "{f}");
    }

    #[test]
    fn a_heavier_strand_swings_slower() {
        // The time the force first passes 90% of a steady target: sqrt(4) = 2 times later at
        // four times the mass (damping ratio 1: no overshoot to confuse the count).
        let rise = |mass: f32| {
            let mut state = Inertia::new(1);
            state.set_masses(Some(vec![mass]));
            (0..600)
                .find(|&n| {
                    let t = f64::from(n) / 120.0;
                    state.update(&[Vec3::new((t * t) as f32, 0.0, 0.0)], t, 0.5, 1.0, 1.0);
                    state.forces()[0].x < -0.9
                })
                .expect("rises")
        };
        let (dry, wet) = (rise(1.0), rise(4.0));
        let ratio = wet as f32 / dry as f32;
        assert!((1.8..=2.2).contains(&ratio), "dry {dry} steps, wet {wet}: {ratio}");
    }

    #[test]
    fn a_teleport_and_a_time_jump_start_over() {
        let mut state = Inertia::new(2);
        let at = |x: f32| [Vec3::new(x, 0.0, 0.0), Vec3::new(x, 1.0, 0.0)];
        for (n, x) in [0.0, 0.01, 0.03, 0.06].into_iter().enumerate() {
            state.update(&at(x), n as f64 / 30.0, 1.0, 0.5, 1.0);
        }
        assert!(state.forces()[0].x < 0.0);
        state.update(&at(5.0), 4.0 / 30.0, 1.0, 0.5, 1.0);
        assert_eq!(state.forces(), &[Vec3::ZERO; 2], "a jump of 5 radii is a teleport");
        assert_eq!(state.teleports(), 1);
        state.update(&at(5.1), 60.0, 1.0, 0.5, 1.0);
        assert_eq!(state.forces(), &[Vec3::ZERO; 2], "a minute later is unrelated");
        assert_eq!(state.teleports(), 2);
    }
}
