// Shells by view angle, the culling half: once per triangle per frame, list the triangles that
// still show in the layers the next coarser stride drops (where `lod_view_weight` is below 1 at
// any corner: elsewhere those layers' alpha is 0 at all three corners, so everywhere between),
// then write one indexed indirect draw per shell over that list. Appended to `shading.wgsl` and
// `unified.wgsl`.

// `wgpu::util::DrawIndexedIndirectArgs`.
struct ShellDraw {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

// Group 2 holds textures in the render pipelines; this pass leaves it empty.
// Indices listed so far (3 a triangle); the host's encoder zeroes it first.
@group(3) @binding(0) var<storage, read_write> listed: atomic<u32>;
// The listed triangles' corners (meshes with uvs) or base vertices (meshes without), in no
// particular order.
@group(3) @binding(1) var<storage, read_write> listed_indices: array<u32>;
// One draw per shell of the level (only the dropped shells' are used).
@group(3) @binding(2) var<storage, read_write> shell_draws: array<ShellDraw>;

@compute @workgroup_size(64)
fn cs_view_lod_list(@builtin(global_invocation_id) id: vec3<u32>) {
    let triangle = id.x;
    if triangle >= object.triangle_count {
        return;
    }
    var shows = false;
    for (var k = 0u; k < 3u; k++) {
        let vertex = topology[3u * triangle + k];
        let normal = world_from_model_normal(model_normal(vertex));
        let root = world_from_model_point(model_vertex(0u, vertex));
        // Exactly what `lod_shell_blend` weighs in the vertex shader.
        if lod_view_weight(normal, root) < 1.0 {
            shows = true;
        }
    }
    if shows {
        let first = atomicAdd(&listed, 3u);
        for (var k = 0u; k < 3u; k++) {
            let corner = 3u * triangle + k;
            listed_indices[first + k] = select(topology[corner], corner, object.has_uvs != 0u);
        }
    }
}

// After the list (a second dispatch): shell k's draw covers the listed indices with base vertex
// k * N, which `vs_shell_*_listed` read back as the shell.
@compute @workgroup_size(64)
fn cs_view_lod_draws(@builtin(global_invocation_id) id: vec3<u32>) {
    let shell = id.x;
    if shell >= object.lod_shells {
        return;
    }
    let per_shell = select(object.vertex_count, 3u * object.triangle_count, object.has_uvs != 0u);
    shell_draws[shell] = ShellDraw(atomicLoad(&listed), 1u, 0u, i32(shell * per_shell), 0u);
}
