//! One step's uniform: `simulation.wgsl`'s `Step`, packed from the simulation's `StepInputs`
//! and the inertia's step.

use pelt_core::sim::{InertiaStep, StepInputs};

/// Bytes per step's uniform slot: the largest `min_uniform_buffer_offset_alignment` allowed.
pub(super) const STEP_SLOT_BYTES: u64 = 256;

/// One step's inputs; the layout of `Step` in `simulation.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub(super) struct StepUniform {
    gravity: [f32; 4],
    wind_direction: [f32; 4],
    wind_shape: [f32; 4],
    travelled_fraction: [f32; 4],
    travelled_xy: [u32; 4],
    travelled_z_seed: [u32; 4],
    jitter_seed_tick: [u32; 4],
    next_tick_counts: [u32; 4],
    touch: [f32; 4],
    /// x: workgroups per row of the dispatch grid; y: the step's slot (its contact data); z: its
    /// block in its pool's contact buffer; w: the most workgroups its contact list asks for.
    pub grid: [u32; 4],
    touch_centre: [f32; 4],
    inertia: [f32; 4],
    inertia_damp: [f32; 4],
    /// x: the inertia's kind (`INERTIA_*`); y: 1 where the touch's weights are the CPU's.
    pub inertia_kind: [u32; 4],
    /// Where the fur's ranges start in its pool's buffers, for a pooled step: the state the step
    /// writes (f32s), the strands (vec4s), the strand state (vec4s), the wet strands (vec2s).
    pub pool: [u32; 4],
}

/// `InertiaStep`'s kinds as `simulation_inputs.wgsl` numbers them.
const INERTIA_START: u32 = 0;
const INERTIA_SHIFT: u32 = 1;
const INERTIA_SHIFT_ZERO: u32 = 2;
const INERTIA_SPRING: u32 = 3;

// A slot holds one step, in the 16-byte units WGSL lays `Step` out in; the shared layout binds
// that many bytes.
const _: () =
    assert!(size_of::<StepUniform>() as u64 <= STEP_SLOT_BYTES && (size_of::<StepUniform>() as u64).is_multiple_of(16));
const _: () = assert!(size_of::<StepUniform>() as u64 == crate::sim_pipelines::STEP_UNIFORM_BYTES);

/// A u64 as WGSL's `vec2<u32>` (low word, high word).
fn words(value: u64) -> [u32; 2] {
    [value as u32, (value >> 32) as u32]
}

/// The uniform of one step: `inputs` repacked into `Step`'s layout (the gust travel's whole
/// cells negated, as the shader adds them; 64-bit values as two words), with the inertia's step
/// and the touch's centre and radius.
pub(super) fn step_uniform(
    inputs: &StepInputs,
    inertia: InertiaStep,
    touch_centre: [f32; 4],
    counts: [u32; 2],
    grid_x: u32,
) -> StepUniform {
    let wind = &inputs.wind;
    let [x, y, z] = wind.gust_travel_cells.map(|cells| words(cells.wrapping_neg() as u64));
    let seed = words(wind.noise_seed);
    let [tick_a, tick_b] = wind.jitter_ticks.map(words);
    let jitter_seed = words(wind.jitter_seed);
    StepUniform {
        gravity: inputs.gravity.extend(0.0).to_array(),
        wind_direction: wind.direction.extend(wind.strength).to_array(),
        wind_shape: [
            wind.gust_strength,
            wind.jitter_force.unwrap_or(0.0),
            wind.jitter_blend,
            (1.0 / wind.gust_size) as f32,
        ],
        travelled_fraction: wind.gust_travel_fraction.extend(inputs.gain).to_array(),
        travelled_xy: [x[0], x[1], y[0], y[1]],
        travelled_z_seed: [z[0], z[1], seed[0], seed[1]],
        jitter_seed_tick: [jitter_seed[0], jitter_seed[1], tick_a[0], tick_a[1]],
        next_tick_counts: [tick_b[0], tick_b[1], counts[0], counts[1]],
        touch: inputs.touch_force.extend(inputs.touch_presence).to_array(),
        grid: [grid_x, 0, 0, grid_x],
        touch_centre,
        inertia: match inertia {
            InertiaStep::Spring(spring) => [spring.dt, spring.dt_before, spring.scale, spring.stiffness_dt],
            _ => [0.0; 4],
        },
        inertia_damp: match inertia {
            InertiaStep::Spring(spring) => [spring.damp, 0.0, 0.0, 0.0],
            _ => [0.0; 4],
        },
        inertia_kind: [
            match inertia {
                InertiaStep::Start => INERTIA_START,
                InertiaStep::Shift { zero: false } => INERTIA_SHIFT,
                InertiaStep::Shift { zero: true } => INERTIA_SHIFT_ZERO,
                InertiaStep::Spring(_) => INERTIA_SPRING,
            },
            0,
            0,
            0,
        ],
        pool: [0; 4],
    }
}

/// Makes a run of steps' inertia kinds one the GPU's state can follow, from `history` (how
/// many steps the state has seen since it started, up to 2: 0 when it never started or missed
/// steps): the first step after a gap starts over, a spring needs two steps of history.
/// Returns the history after the run.
pub(super) fn settle_inertia(pending: &mut [StepUniform], mut history: u8) -> u8 {
    for uniform in pending {
        let kind = &mut uniform.inertia_kind[0];
        if history == 0 {
            *kind = INERTIA_START;
        } else if *kind == INERTIA_SPRING && history < 2 {
            *kind = INERTIA_SHIFT;
        }
        history = if *kind == INERTIA_START { 1 } else { (history + 1).min(2) };
    }
    history
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn u64_splits_into_low_and_high_words() {
        assert_eq!(words(0x0123_4567_89AB_CDEF), [0x89AB_CDEF, 0x0123_4567]);
        assert_eq!(words(1_i64.wrapping_neg() as u64), [u32::MAX, u32::MAX]);
    }
}

#[cfg(test)]
mod mirror_tests {
    use super::StepUniform;
    use crate::shaders::{assert_mirrors, rust_layout, simulation_shader_source};

    /// Member by member as naga lays `Step` out, not only the size.
    #[test]
    fn step_uniform_mirrors_step() {
        let rust = rust_layout!(StepUniform {
            gravity,
            wind_direction,
            wind_shape,
            travelled_fraction,
            travelled_xy,
            travelled_z_seed,
            jitter_seed_tick,
            next_tick_counts,
            touch,
            grid,
            touch_centre,
            inertia,
            inertia_damp,
            inertia_kind,
            pool
        });
        assert_mirrors(&simulation_shader_source(), "Step", &rust);
    }
}
