// The per-strand inputs of a step as the GPU keeps and computes them, so no step needs the CPU
// to touch every strand: the resident inputs (posed roots, frames, stability, the user field:
// written only when they change), the inertial force (pelt-core's `sim::inertia`, stepped here
// from the step's shared numbers) and the touch's weights (`sim::field::Touch`, computed by the
// `weigh_touch` pass when a touch begins). Appended after `simulation.wgsl`; the
// bindings are `simulation_lone.wgsl`'s or `simulation_pooled.wgsl`'s.

// `InertiaStep`'s kinds, in `Step::inertia_kind.x`.
const INERTIA_START: u32 = 0u;
const INERTIA_SHIFT: u32 = 1u;
const INERTIA_SHIFT_ZERO: u32 = 2u;
const INERTIA_SPRING: u32 = 3u;
// `inertia::MAX_INERTIAL_FORCE`.
const MAX_INERTIAL_FORCE: f32 = 10.0;

fn strand_root(j: u32) -> vec4<f32> {
    return strands[member_base.y + j];
}

fn strand_frame(j: u32, v: u32) -> vec4<f32> {
    return strands[member_base.y + v + j];
}

fn user_field(j: u32, v: u32) -> vec3<f32> {
    return strands[member_base.y + 2u * v + j].xyz;
}

// The touch's weight on strand j: the `weigh_touch` pass's, or the CPU's where the touch began
// on roots no step used (`Step::inertia_kind.y` = 1).
fn touch_weight(j: u32, v: u32) -> f32 {
    if inputs.inertia_kind.y == 1u {
        return strands[member_base.y + 2u * v + j].w;
    }
    return strand_state[member_base.z + j].w;
}

// Strand j's inertial force at this step, its state advanced by the step's `InertiaStep`
// (`Inertia::apply`, `SpringStep::force`) with its root now.
fn inertial_force(j: u32, v: u32, root: vec3<f32>) -> vec3<f32> {
    let kind = inputs.inertia_kind.x;
    let last = strand_state[member_base.z + j];
    if kind == INERTIA_START {
        strand_state[member_base.z + j] = vec4<f32>(root, last.w);
        strand_state[member_base.z + v + j] = vec4<f32>(root, 0.0);
        strand_state[member_base.z + 2u * v + j] = vec4<f32>(0.0);
        strand_state[member_base.z + 3u * v + j] = vec4<f32>(0.0);
        return vec3<f32>(0.0);
    }
    let before = strand_state[member_base.z + v + j].xyz;
    strand_state[member_base.z + j] = vec4<f32>(root, last.w);
    strand_state[member_base.z + v + j] = vec4<f32>(last.xyz, 0.0);
    if kind == INERTIA_SHIFT_ZERO {
        strand_state[member_base.z + 2u * v + j] = vec4<f32>(0.0);
        strand_state[member_base.z + 3u * v + j] = vec4<f32>(0.0);
        return vec3<f32>(0.0);
    }
    let force = strand_state[member_base.z + 2u * v + j].xyz;
    if kind != INERTIA_SPRING {
        return force;
    }
    let dt = inputs.inertia.x;
    let acceleration = (root - last.xyz) / dt - (last.xyz - before) / inputs.inertia.y;
    // `Vec3::clamp_length_max`.
    var pull = acceleration * inputs.inertia.z;
    let length_squared = dot(pull, pull);
    if length_squared > MAX_INERTIAL_FORCE * MAX_INERTIAL_FORCE {
        pull = MAX_INERTIAL_FORCE * (pull / sqrt(length_squared));
    }
    // A wet strand is heavier on the same spring (`SpringStep::heavier`).
    let mass = wet_strands[member_base.w + j].y;
    var stiffness_dt = inputs.inertia.w;
    var damp = inputs.inertia_damp.x;
    if mass > 1.0 {
        stiffness_dt = stiffness_dt / mass;
        damp = 1.0 / (1.0 + (1.0 / damp - 1.0) / sqrt(mass));
    }
    let velocity = (strand_state[member_base.z + 3u * v + j].xyz + (pull - force) * stiffness_dt) * damp;
    let new_force = force + velocity * dt;
    strand_state[member_base.z + 2u * v + j] = vec4<f32>(new_force, 0.0);
    strand_state[member_base.z + 3u * v + j] = vec4<f32>(velocity, 0.0);
    return new_force;
}

// The touch's weights as `Touch::new` computes them (`falloff(|root - centre| / radius)`) from
// the roots the touch began on: those of the state the last step wrote, bound as `positions`.
@compute @workgroup_size(64)
fn weigh_touch(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let v = inputs.next_tick_counts.z;
    let j = (group.y * inputs.grid.x + group.x) * WORKGROUP + lane;
    if j >= v {
        return;
    }
    let root = vec3<f32>(positions[member_base.x + j * 3u], positions[member_base.x + j * 3u + 1u], positions[member_base.x + j * 3u + 2u]);
    let distance = length(root - inputs.touch_centre.xyz) / inputs.touch_centre.w;
    // NaN compares false: no weight, as `falloff` gives.
    var weight = 0.0;
    if distance < 1.0 {
        let t = 1.0 - distance * distance;
        weight = t * t;
    }
    strand_state[member_base.z + j].w = weight;
}
