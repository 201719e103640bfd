// Every copy of a pool stepping in one dispatch: workgroup z is the copy, whose step (with where
// its ranges start, `Step::pool`) the host copied to `pooled_steps[z]`. The buffers are the
// pool's whole; each range is laid out as `simulation_lone.wgsl` describes. Appended to the
// simulation's files in place of `simulation_lone.wgsl`.
//
// A step with contact reads the pool's contact buffer (`simulation/pool_contact.rs`), in vec4s:
//   [0]: (a copy's block in vec4s, where the blocks begin, where the fields begin, -) as bits;
//   from 1: the skin's planes, cones and triangles, as in a fur's own buffer, without weights;
//   from the fields: the mesh colliders' distance fields (f32s, as `sdf_fields`);
//   from the blocks: copy `grid.z`'s block: its slots' headers, its grasp weights, its slots'
//     colliders (the headers say where they begin).
// Its list holds every copy's strands, each word saying whose (`listed_word`).

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
// The copy's place in the dispatch, and where its contact block and the fields begin.
var<private> pooled_member: u32;
var<private> contact_block: u32;
var<private> contact_fields: u32;

@compute @workgroup_size(64)
fn step_pooled(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    inputs = pooled_steps[group.z].step;
    member_base = inputs.pool;
    let j = step_strand_index(group, lane);
    if j < inputs.next_tick_counts.z {
        bend_strand(j, false);
    }
}

// Copy z's inputs, ranges and contact block.
fn load_member(z: u32) {
    inputs = pooled_steps[z].step;
    member_base = inputs.pool;
    pooled_member = z;
    let parts = bitcast<vec4<u32>>(contact[0]);
    contact_block = parts.y + inputs.grid.z * parts.x;
    contact_fields = parts.z;
}

// `step_strands_with_contact` for every copy of the pool whose step has contact.
@compute @workgroup_size(64)
fn step_pooled_with_contact(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    load_member(group.z);
    bend_and_screen(step_strand_index(group, lane));
}

// `solve_contact` over the pool's list.
@compute @workgroup_size(64)
fn solve_pooled_contact(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    load_member(0u);
    solve_listed_strands(group, lane, groups);
}

fn sdf_at(i: u32) -> f32 {
    let at = contact_fields * 4u + i;
    return contact[at / 4u][at % 4u];
}

fn headers_first() -> u32 {
    return contact_block;
}

fn planes_first(v: u32) -> u32 {
    return 1u;
}

fn weights_first(v: u32) -> u32 {
    return contact_block + 2u * CONTACT_SLOTS;
}

fn surface_first(v: u32) -> u32 {
    return cones_first(v) + v;
}

// A listed strand's word: its copy (above 8 bits) and its first segment to solve (layers are at
// most 128).
fn listed_word(segment: u32) -> u32 {
    return (pooled_member << 8u) | segment;
}

// Reads the copy's inputs for the word's strand; its segment.
fn take_listed(word: u32) -> u32 {
    load_member(word >> 8u);
    return word & 255u;
}
