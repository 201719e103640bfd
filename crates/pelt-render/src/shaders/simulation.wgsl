// One step of pelt-core's `Simulation` on the GPU: per strand (one invocation each) the force
// (gravity + wind + the user field with the touch blended over it + inertia), then the bend of Equation 1 as
// `pelt_core::sim::bend` defines it, in the CPU kernel's two forms (the exact straight form,
// the running quaternion for curved strands, O(L) both), written layer-major into the
// shared vertex array the renderer draws from. Appended to `simulation_wind.wgsl`; the
// per-strand inputs are `simulation_inputs.wgsl`'s.

// One step's inputs (a 256-byte slot of a uniform buffer, chosen by dynamic offset; a pooled
// step's copied into its pool's array). The bindings are `simulation_lone.wgsl`'s (a fur's own
// step) or `simulation_pooled.wgsl`'s (every copy of a pool in one dispatch), and every index
// into a fur's own buffers adds `member_base`.
struct Step {
    // xyz: gravity direction times strength.
    gravity: vec4<f32>,
    // xyz: unit wind direction; w: wind strength (0: no wind).
    wind_direction: vec4<f32>,
    // x: gust strength, y: jitter force (strength * jitter; 0: none), z: jitter blend,
    // w: 1 / gust size (world units to noise cells).
    wind_shape: vec4<f32>,
    // xyz: fractional part of how far the gusts travelled (cells); w: Equation 1's gain
    // (`pelt_core::sim::Equation::gain`: 8 / L^2 for Pelt's form, 1 for the paper's).
    travelled_fraction: vec4<f32>,
    // Minus the whole cells travelled, as wrapping i64 (low, high) per axis: x, y here ...
    travelled_xy: vec4<u32>,
    // ... and z here; zw: the noise seed, already mixed once.
    travelled_z_seed: vec4<u32>,
    // xy: the jitter seed; zw: this step's jitter tick.
    jitter_seed_tick: vec4<u32>,
    // xy: the next jitter tick; z: V (strands); w: L (layers).
    next_tick_counts: vec4<u32>,
    // xyz: the touch force; w: its presence (0: no touch).
    touch: vec4<f32>,
    // x: workgroups per row of the dispatch grid; y: the step's slot (its contact data); z: its
    // block in its pool's contact buffer; w: the most workgroups a contact list asks to solve it.
    grid: vec4<u32>,
    // xyz: the touch's centre; w: its radius (read by the `weigh_touch` pass).
    touch_centre: vec4<f32>,
    // The inertia's spring step (`SpringStep`): x dt, y dt before, z scale, w omega^2 dt.
    inertia: vec4<f32>,
    // x: the spring's damping factor.
    inertia_damp: vec4<f32>,
    // x: the `InertiaStep` kind (`INERTIA_*`); y: 1 where the touch's weights are the CPU's
    // (in the field's w), 0 where the `weigh_touch` pass's.
    inertia_kind: vec4<u32>,
    // Where the fur's ranges start in its pool's buffers (`member_base`, read by a pooled step
    // only): x the state this step writes (f32s), y the strands (vec4s), z the strand state
    // (vec4s), w the wet strands (vec2s).
    pool: vec4<u32>,
}

// Rest segment k of strand j at k * V + j: unit direction (xyz, zero for a zero-length segment)
// and length (w), as `sim/kernel.rs` keeps them. Then per strand j at L * V + j: the strand's unit
// direction (xyz) and w = 1 where the CPU bends it by the straight form (`sim::straight_directions`),
// 0 where by the running quaternion, so both kernels bend every strand the same way.
@group(0) @binding(1) var<storage, read> rest_segments: array<vec4<f32>>;

const PARALLEL_SINE: f32 = 1e-7;
const WORKGROUP: u32 = 64u;

fn is_finite(x: f32) -> bool {
    // Exponent bits all set: infinity or NaN (compilers may fold `x != x` away).
    return (bitcast<u32>(x) & 0x7f800000u) != 0x7f800000u;
}

// `q * v` for a unit `q` as `sim/kernel.rs` computes it: `t = 2 (u x v)`, `v + w t + u x t`.
fn rotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let t = cross(q.xyz, v) * 2.0;
    return v + t * q.w + cross(q.xyz, t);
}

// `glam::Quat * Quat` (Hamilton product).
fn quat_mul(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(
        a.w * b.x + a.x * b.w + a.y * b.z - a.z * b.y,
        a.w * b.y - a.x * b.z + a.y * b.w + a.z * b.x,
        a.w * b.z + a.x * b.y - a.y * b.x + a.z * b.w,
        a.w * b.w - a.x * b.x - a.y * b.y - a.z * b.z,
    );
}

// `bend::angle_from_sin_cos`: atan2(sine, cosine) in [0, pi] by the same polynomial.
fn angle_from_sin_cos(sine: f32, cosine: f32) -> f32 {
    let a = sine;
    let b = abs(cosine);
    let steep = a > b;
    let numerator = select(a, b, steep);
    let denominator = select(b, a, steep);
    var t = 0.0;
    if denominator > 0.0 {
        t = numerator / denominator;
    }
    let t2 = t * t;
    var p = 0.0028662257;
    p = p * t2 - 0.016165737;
    p = p * t2 + 0.042909614;
    p = p * t2 - 0.07528964;
    p = p * t2 + 0.10656264;
    p = p * t2 - 0.142089;
    p = p * t2 + 0.19993551;
    p = p * t2 - 0.33333145;
    var angle = t + t * t2 * p;
    if steep {
        angle = 1.5707964 - angle;
    }
    return select(angle, 3.1415927 - angle, cosine < 0.0);
}

// `bend::sin_cos_quarter_turn`: (sin x, cos x) for x in [0, pi/2].
fn sin_cos_quarter_turn(x: f32) -> vec2<f32> {
    let x2 = x * x;
    let sine = x * (1.0 + x2 * (-1.0 / 6.0 + x2 * (1.0 / 120.0 + x2 * (-1.0 / 5040.0 + x2 * (1.0 / 362880.0 - x2 / 39916800.0)))));
    let cosine = 1.0 + x2 * (-0.5 + x2 * (1.0 / 24.0 + x2 * (-1.0 / 720.0 + x2 * (1.0 / 40320.0 + x2 * (-1.0 / 3628800.0 + x2 / 479001600.0)))));
    return vec2<f32>(sine, cosine);
}

// The wind on strand `j` at `root` (`WindParams::sample`).
fn wind(j: u32, root: vec3<f32>) -> vec3<f32> {
    let strength = inputs.wind_direction.w;
    if strength == 0.0 {
        return vec3<f32>(0.0);
    }
    let direction = inputs.wind_direction.xyz;
    let gust = value_noise3(
        inputs.travelled_z_seed.zw,
        root * inputs.wind_shape.w,
        inputs.travelled_fraction.xyz,
        inputs.travelled_xy.xy,
        inputs.travelled_xy.zw,
        inputs.travelled_z_seed.xy,
    );
    var force = direction * (strength * (1.0 + inputs.wind_shape.x * gust));
    let jitter = inputs.wind_shape.y;
    if jitter > 0.0 {
        let mixed = mix64(inputs.jitter_seed_tick.xy ^ mix64(vec2<u32>(j, 0u)));
        let a = random_vector(mixed, inputs.jitter_seed_tick.zw);
        let b = random_vector(mixed, inputs.next_tick_counts.xy);
        let blend = inputs.wind_shape.z;
        force += (a * (1.0 - blend) + b * blend) * jitter;
    }
    return force;
}

// The strand a thread of a step's dispatch steps (V or more threads, rows of workgroups).
fn step_strand_index(group: vec3<u32>, lane: u32) -> u32 {
    return (group.y * inputs.grid.x + group.x) * WORKGROUP + lane;
}

// A step without contact. Steps with contact run `step_strands_with_contact`
// (`simulation_contact.wgsl`) instead: a pipeline of its own, so this kernel carries none of
// contact's registers (on lavapipe it ran 1.7 times as fast apart).
@compute @workgroup_size(64)
fn step_strands(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    let j = step_strand_index(group, lane);
    if j < inputs.next_tick_counts.z {
        bend_strand(j, false);
    }
}

// Strand j's nodes bent by the step's forces (Equation 1), written to `positions`; with
// `screening`, each node also goes to contact's `screen_node` as it is made (`step_strands`
// passes false, so it compiles without it).
fn bend_strand(j: u32, screening: bool) {
    let v = inputs.next_tick_counts.z;
    let layers = inputs.next_tick_counts.w;
    let root_stability = strand_root(j);
    let root = root_stability.xyz;
    let stability = root_stability.w;
    let frame = strand_frame(j, v);
    let inertial = inertial_force(j, v, root);

    // The external field (wind + user field) with the touch over it (`evaluate_field`), then gravity.
    var field_force = wind(j, root) + user_field(j, v);
    let touch = touch_weight(j, v) * inputs.touch.w;
    if touch > 0.0 {
        field_force = field_force * (1.0 - touch) + inputs.touch.xyz * touch;
    }
    let force = inputs.gravity.xyz * wet_strands[member_base.w + j].x + field_force + inertial;

    // `bend::split_force`: unit direction and magnitude without overflow; a non-finite force
    // has neither.
    var force_direction = vec3<f32>(0.0);
    var magnitude = 0.0;
    let largest = max(max(abs(force.x), abs(force.y)), abs(force.z));
    if is_finite(force.x) && is_finite(force.y) && is_finite(force.z) && largest > 0.0 {
        let scaled = force / largest;
        let scaled_length = length(scaled);
        force_direction = scaled / scaled_length;
        magnitude = scaled_length * largest;
    }

    // Equation 1's factor per remaining node (`sim/kernel.rs`'s `scale`).
    let scale = magnitude * inputs.travelled_fraction.w / stability;

    positions[member_base.x + j * 3u] = root.x;
    positions[member_base.x + j * 3u + 1u] = root.y;
    positions[member_base.x + j * 3u + 2u] = root.z;
    let straight = rest_segments[layers * v + j];
    if straight.w > 0.0 {
        bend_straight(j, v, layers, root, frame, straight.xyz, force_direction, scale, screening);
    } else {
        bend_general(j, v, layers, root, frame, force_direction, scale, screening);
    }
}

// The fraction of the angle to the force that a node with `remaining` nodes to go turns by.
fn weight_of(scale: f32, remaining: u32) -> f32 {
    let weight = scale * f32(remaining);
    if !is_finite(weight) {
        // Infinity (an overflowing force) bends fully; NaN (0 * infinity) not at all.
        return select(0.0, 1.0, weight > 0.0);
    }
    return clamp(weight, 0.0, 1.0);
}

fn write_node(j: u32, v: u32, k: u32, node: vec3<f32>) {
    let index = (k * v + j) * 3u;
    positions[member_base.x + index] = node.x;
    positions[member_base.x + index + 1u] = node.y;
    positions[member_base.x + index + 2u] = node.z;
}

// `sim/kernel.rs`'s `bend_straight`: a strand whose rest segments all point along `rest_direction`
// stays in the plane of its direction `d` and the force `f`: segment k ends at the angle
// `a_(k+1) = a_k (1 - w_k)` from f, turned by `a_0 - a_(k+1)` from d toward `e`, the unit normal
// to d in that plane (built from its own length, so lengths hold near an antiparallel force).
fn bend_straight(
    j: u32,
    v: u32,
    layers: u32,
    root: vec3<f32>,
    frame: vec4<f32>,
    rest_direction: vec3<f32>,
    f: vec3<f32>,
    scale: f32,
    screening: bool,
) {
    let d = rotate(frame, rest_direction);
    let axis = cross(d, f);
    let sine = length(axis);
    let cosine = dot(d, f);
    let start = angle_from_sin_cos(sine, cosine);
    let toward_f = f - d * cosine;
    let toward = toward_f - d * dot(d, toward_f);
    let norm = length(toward);
    var e = vec3<f32>(0.0);
    var strand_scale = 0.0;
    if sine > PARALLEL_SINE && scale > 0.0 && norm > 0.0 {
        e = toward * (1.0 / norm);
        strand_scale = scale;
    }
    var remaining = start;
    var node = root;
    for (var k = 0u; k < layers; k++) {
        let weight = weight_of(strand_scale, layers - k);
        remaining = remaining - remaining * weight;
        let half = sin_cos_quarter_turn((start - remaining) * 0.5);
        let cos_turn = 1.0 - 2.0 * half.x * half.x;
        let sin_turn = 2.0 * half.x * half.y;
        let segment_length = rest_segments[k * v + j].w;
        node += (e * sin_turn + d * cos_turn) * segment_length;
        write_node(j, v, k + 1u, node);
        if screening {
            screen_node(k, node, root);
        }
    }
}

// `sim/kernel.rs`'s `bend_general` (and `bend::bend_strand`): any strand, by a running
// quaternion; each segment is its rest direction under the turned frame, so it keeps its length.
fn bend_general(
    j: u32,
    v: u32,
    layers: u32,
    root: vec3<f32>,
    frame: vec4<f32>,
    f: vec3<f32>,
    scale: f32,
    screening: bool,
) {
    var turned = frame;
    var node = root;
    for (var k = 0u; k < layers; k++) {
        let rest = rest_segments[k * v + j];
        let d = rotate(turned, rest.xyz);
        let weight = weight_of(scale, layers - k);
        let axis = cross(d, f);
        let sine = length(axis);
        if sine > PARALLEL_SINE && weight > 0.0 && rest.w > 0.0 {
            let angle = angle_from_sin_cos(sine, dot(d, f));
            let half = sin_cos_quarter_turn(angle * weight * 0.5);
            let rotation = vec4<f32>(axis * (half.x / sine), half.y);
            // Renormalised so rounding never lets segment lengths drift over many layers.
            let product = quat_mul(rotation, turned);
            turned = product * (1.0 / length(product));
        }
        node += rotate(turned, rest.xyz) * rest.w;
        write_node(j, v, k + 1u, node);
        if screening {
            screen_node(k, node, root);
        }
    }
}
