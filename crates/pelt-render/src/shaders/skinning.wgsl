// Linear blend skinning of a base mesh for many instances in one dispatch (`GpuSkin`): x is the
// base vertex, y the instance. The same blend as `pelt_core::anim` (positions by the joints'
// matrices, normals by their normal matrices, both weighted, the normal renormalised); morph
// targets and the frames' rotations stay on the CPU.

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
// Per instance and joint: its skinning matrix, then its normal matrix.
@group(0) @binding(3) var<storage, read> joints: array<mat4x4<f32>>;
// Per instance and vertex: the posed position (w = 1), the posed unit normal (w = 0).
@group(0) @binding(4) var<storage, read_write> posed: array<vec4<f32>>;

@compute @workgroup_size(64)
fn skin(@builtin(global_invocation_id) id: vec3<u32>) {
    let vertex = id.x;
    let instance = id.y;
    if vertex >= params.vertex_count || instance >= params.instance_count {
        return;
    }
    let position = vec4<f32>(rest[2u * vertex].xyz, 1.0);
    let normal = vec4<f32>(rest[2u * vertex + 1u].xyz, 0.0);
    let joint = influences[2u * vertex];
    let weight = bitcast<vec4<f32>>(influences[2u * vertex + 1u]);
    let first = instance * params.joint_count;
    var blended_position = vec3<f32>(0.0);
    var blended_normal = vec3<f32>(0.0);
    for (var k = 0u; k < 4u; k++) {
        // Unused slots weigh 0 and may name any joint: skip them, as the CPU does.
        let w = weight[k];
        if w != 0.0 {
            let at = 2u * (first + min(joint[k], params.joint_count - 1u));
            blended_position += (joints[at] * position).xyz * w;
            blended_normal += (joints[at + 1u] * normal).xyz * w;
        }
    }
    // A degenerate blend (opposed joints cancelling) keeps the rest normal.
    let length_squared = dot(blended_normal, blended_normal);
    let unit = select(normal.xyz, blended_normal * inverseSqrt(length_squared), length_squared > 1e-24);
    let out = 2u * (instance * params.vertex_count + vertex);
    posed[out] = vec4<f32>(blended_position, 1.0);
    posed[out + 1u] = vec4<f32>(unit, 0.0);
}
