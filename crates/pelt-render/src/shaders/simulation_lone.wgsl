// A fur's own step: its buffers bound at its own ranges, its step's uniform by dynamic offset.
// Appended to the simulation's files for `step_strands`, `weigh_touch` and contact's kernels.

@group(0) @binding(0) var<uniform> inputs: Step;
// The resident inputs, in sections of V entries: strand j's posed root (xyz) and stability (w)
// at j, its frame (the rotation of its rest frame, quaternion xyzw) at V + j, and the user
// field (xyz) at 2 V + j, with the touch's weight (w) where the CPU's weights are uploaded.
@group(0) @binding(2) var<storage, read> strands: array<vec4<f32>>;
// What the GPU carries from step to step, in sections of V entries: the root at the last step
// (xyz) and the touch's falloff weight (w, 0 outside it) at j, the root the step before at
// V + j, the inertial force at 2 V + j and its rate of change at 3 V + j.
@group(0) @binding(3) var<storage, read_write> strand_state: array<vec4<f32>>;
// The shared vertex array's state this step writes: NV[i * V + j] as packed xyz.
@group(0) @binding(4) var<storage, read_write> positions: array<f32>;
// Per strand, a wet strand's weight: x gravity's factor, y the mass on the inertial spring (both
// 1 + added_weight * wetness; 1 when dry).
@group(0) @binding(6) var<storage, read> wet_strands: array<vec2<f32>>;

// The ranges are bound where they start.
const member_base = vec4<u32>(0u, 0u, 0u, 0u);
// Mesh colliders' distance fields (`contact.rs`'s `upload_fields`).
@group(0) @binding(7) var<storage, read> sdf_fields: array<f32>;

fn sdf_at(i: u32) -> f32 {
    return sdf_fields[i];
}

// The fur's own contact buffer: the slots' headers, the grasp's weights, then the skin's planes,
// cones and triangles (`simulation_contact.wgsl`; none until the skin is found, which a step with
// the skin off never reads).
fn headers_first() -> u32 {
    return 0u;
}

fn weights_first(v: u32) -> u32 {
    return CONTACT_SKIN;
}

fn planes_first(v: u32) -> u32 {
    return CONTACT_SKIN + (v + 3u) / 4u;
}

fn surface_first(v: u32) -> u32 {
    return cones_first(v) + v;
}

// A listed strand's word: its first segment to solve (the list holds this fur's strands alone).
fn listed_word(segment: u32) -> u32 {
    return segment;
}

fn take_listed(word: u32) -> u32 {
    return word;
}
