// Every copy of a pool stepping without contact, in one dispatch: workgroup z is the copy, whose
// step (with where its ranges start, `Step::pool`) the host copied to `pooled_steps[z]`. The
// buffers are the pool's whole; each range is laid out as `simulation_lone.wgsl` describes.
// Appended to the simulation's files in place of `simulation_lone.wgsl`.

// A step in a 256-byte slot, as the uniform ring holds it.
struct PooledStep {
    step: Step,
    padding: vec4<u32>,
}

@group(0) @binding(0) var<storage, read> pooled_steps: array<PooledStep>;
@group(0) @binding(2) var<storage, read> strands: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read_write> strand_state: array<vec4<f32>>;
// The pool's shared vertex arrays, every copy's states.
@group(0) @binding(4) var<storage, read_write> positions: array<f32>;
@group(0) @binding(6) var<storage, read> wet_strands: array<vec2<f32>>;

var<private> inputs: Step;
var<private> member_base: vec4<u32>;

@compute @workgroup_size(64)
fn step_pooled(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    inputs = pooled_steps[group.z].step;
    member_base = inputs.pool;
    let j = step_strand_index(group, lane);
    if j < inputs.next_tick_counts.z {
        bend_strand(j, false);
    }
}
