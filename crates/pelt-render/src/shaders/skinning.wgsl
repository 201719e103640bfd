// Linear blend skinning of a base mesh for many instances in one dispatch (`GpuSkin`): x is the
// base vertex, y the instance. The same blend as `pelt_core::anim` (positions by the joints'
// matrices, normals by their normal matrices, rotations by their quaternions, all weighted; the
// normal renormalised, the rotation corrected to take the rest normal onto it); morph targets
// stay on the CPU.

struct SkinParams {
    vertex_count: u32,
    joint_count: u32,
    instance_count: u32,
    padding: u32,
}

@group(0) @binding(0) var<uniform> params: SkinParams;
// Per vertex: the rest position (w = 1), the rest normal (w = 0).
@group(0) @binding(1) var<storage, read> rest: array<vec4<f32>>;
// Per vertex: four joints, then their four weights' bits.
@group(0) @binding(2) var<storage, read> influences: array<vec4<u32>>;
// Per instance and joint: its skinning matrix, then its normal matrix with the joint's rotation
// (a unit quaternion, xyzw) in the fourth column, which a normal (w = 0) never reads.
@group(0) @binding(3) var<storage, read> joints: array<mat4x4<f32>>;
// Per instance, three sections of a vec4 per vertex: the posed positions (w = 1), the posed unit
// normals (w = 0), the rotations from the rest frame (xyzw).
@group(0) @binding(4) var<storage, read_write> posed: array<vec4<f32>>;

// `glam::Quat`'s product `a * b`.
fn quat_mul(a: vec4<f32>, b: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(a.w * b.xyz + b.w * a.xyz + cross(a.xyz, b.xyz), a.w * b.w - dot(a.xyz, b.xyz));
}

// `glam::Quat::mul_vec3`.
fn quat_rotate(q: vec4<f32>, v: vec3<f32>) -> vec3<f32> {
    let t = 2.0 * cross(q.xyz, v);
    return v + q.w * t + cross(q.xyz, t);
}

// `glam::Quat::from_rotation_arc` for unit vectors: the shortest rotation from `start` to `end`.
fn rotation_arc(start: vec3<f32>, end: vec3<f32>) -> vec4<f32> {
    let one_minus_eps = 1.0 - 2.0 * 1.1920929e-7;
    let d = dot(start, end);
    if d > one_minus_eps {
        return vec4<f32>(0.0, 0.0, 0.0, 1.0);
    }
    if d < -one_minus_eps {
        // Half a turn about `Vec3::any_orthonormal_vector`.
        let sign = select(-1.0, 1.0, start.z >= 0.0);
        let a = -1.0 / (sign + start.z);
        let b = start.x * start.y * a;
        return vec4<f32>(b, sign + start.y * start.y * a, -start.y, 0.0);
    }
    return normalize(vec4<f32>(cross(start, end), 1.0 + d));
}

// One vertex of one instance, posed.
struct Skinned {
    position: vec3<f32>,
    // The unit normal.
    normal: vec3<f32>,
    // The rotation from the rest frame (xyzw).
    rotation: vec4<f32>,
}

@compute @workgroup_size(64)
fn skin(@builtin(global_invocation_id) id: vec3<u32>) {
    let vertex = id.x;
    let instance = id.y;
    if vertex >= params.vertex_count || instance >= params.instance_count {
        return;
    }
    let posed_vertex = skinned(vertex, instance);
    let v = params.vertex_count;
    let out = 3u * instance * v + vertex;
    posed[out] = vec4<f32>(posed_vertex.position, 1.0);
    posed[out + v] = vec4<f32>(posed_vertex.normal, 0.0);
    posed[out + 2u * v] = posed_vertex.rotation;
}

// Vertex `vertex` of instance `instance` posed by its joints.
fn skinned(vertex: u32, instance: u32) -> Skinned {
    let position = vec4<f32>(rest[2u * vertex].xyz, 1.0);
    let normal = vec4<f32>(rest[2u * vertex + 1u].xyz, 0.0);
    let joint = influences[2u * vertex];
    let weight = bitcast<vec4<f32>>(influences[2u * vertex + 1u]);
    let first = instance * params.joint_count;
    let first_rotation = joints[2u * (first + min(joint[0], params.joint_count - 1u)) + 1u][3];
    var blended_position = vec3<f32>(0.0);
    var blended_normal = vec3<f32>(0.0);
    var blended_rotation = vec4<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        // Unused slots weigh 0 and may name any joint: skip them, as the CPU does.
        let w = weight[k];
        if w != 0.0 {
            let at = 2u * (first + min(joint[k], params.joint_count - 1u));
            blended_position += (joints[at] * position).xyz * w;
            blended_normal += (joints[at + 1u] * normal).xyz * w;
            // q and -q are one rotation: blend on the first joint's side.
            let q = joints[at + 1u][3];
            blended_rotation += q * (w * select(1.0, -1.0, dot(q, first_rotation) < 0.0));
        }
    }
    let rotation_squared = dot(blended_rotation, blended_rotation);
    let q = select(vec4<f32>(0.0, 0.0, 0.0, 1.0), blended_rotation * inverseSqrt(rotation_squared), rotation_squared > 1e-24);
    let turned_rest = quat_rotate(q, normal.xyz);
    // A degenerate blend (opposed joints cancelling) keeps the turned rest normal.
    let length_squared = dot(blended_normal, blended_normal);
    let unit = select(turned_rest, blended_normal * inverseSqrt(length_squared), length_squared > 1e-24);
    // The blended rotation, corrected to take the rest normal exactly onto the posed normal.
    let turned_squared = dot(turned_rest, turned_rest);
    var rotation = q;
    if turned_squared > 1e-24 {
        rotation = normalize(quat_mul(rotation_arc(turned_rest * inverseSqrt(turned_squared), unit), q));
    }
    return Skinned(blended_position, unit, rotation);
}
