// The silhouette pass: once per edge per frame, decide whether the edge's fin shows (`fin_fade`
// in `unified.wgsl`) and append the shown ones to the fins' instance list, counting them into an
// indexed indirect draw. Appended to `shading.wgsl` and `unified.wgsl`.

// `wgpu::util::DrawIndexedIndirectArgs`; the host's encoder zeroes `instance_count` first.
struct FinDraw {
    index_count: u32,
    instance_count: atomic<u32>,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

// Group 2 holds textures in the render pipelines; the silhouette pass leaves it empty.
@group(3) @binding(0) var<storage, read_write> fin_draw: FinDraw;
// (edge, fade as f32 bits) per shown fin, in no particular order.
@group(3) @binding(1) var<storage, read_write> fin_instances: array<vec2<u32>>;

@compute @workgroup_size(64)
fn cs_silhouette(@builtin(global_invocation_id) id: vec3<u32>) {
    let edge = id.x;
    if edge == 0u {
        // The fins' segments at this frame's level of detail (6 indices each).
        fin_draw.index_count = 6u * object.lod_shells;
    }
    if edge >= object.edge_count {
        return;
    }
    let fade = fin_fade(edge);
    if fade > 0.0 {
        let slot = atomicAdd(&fin_draw.instance_count, 1u);
        fin_instances[slot] = vec2<u32>(edge, bitcast<u32>(fade));
    }
}
