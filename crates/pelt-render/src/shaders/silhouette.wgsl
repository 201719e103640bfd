// The silhouette pass: once per edge per frame, decide whether the edge's fin shows (`fin_fade`
// in `unified.wgsl`) and list the shown ones, in edge order, as the fins' instances, counting them
// into an indexed indirect draw. Appended to `shading.wgsl`, `unified.wgsl` and `scan.wgsl`.
//
// Two dispatches, each over every copy in a pool (`object_pool.wgsl`). The first decides, one thread an edge over as many workgroups as it takes,
// and leaves each edge's fade in the edge's own slot of the list. The second, one workgroup,
// walks the slots `SCAN_WIDTH` at a time and moves each round's shown fins down to their places
// by a prefix sum: fins overlap along the silhouette and blend in instance order, so an order
// that followed the threads' timing (an atomic append) made the same frame differ from run to
// run. Deciding in the one workgroup too left the whole mesh to one thread on a CPU rasteriser.

// `wgpu::util::DrawIndexedIndirectArgs`.
struct FinDraw {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

// Group 2 holds textures in the render pipelines; the silhouette pass leaves it empty. Group 3
// holds every copy's list of its pool, slot by slot (`object_pool.wgsl`: workgroup z is the slot).
// Each slot's own draw, then in a pool of more than one as many gathered draws
// (`ObjectSlot::gather`).
@group(3) @binding(0) var<storage, read_write> fin_draws: array<FinDraw>;
// (edge, fade as f32 bits) per shown fin, in edge order: `fin_edge_count` slots a copy.
@group(3) @binding(1) var<storage, read_write> fin_instances: array<vec2<u32>>;

@compute @workgroup_size(64)
fn cs_fin_fades(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if !load_member(id.z, LIST_FINS) {
        return;
    }
    let edge = item_index(id, groups);
    if edge < object.fin_edge_count {
        fin_instances[id.z * object.fin_edge_count + edge] = vec2<u32>(edge, bitcast<u32>(fin_fade(edge)));
    }
}

@compute @workgroup_size(256)
fn cs_silhouette(@builtin(local_invocation_index) lane: u32, @builtin(workgroup_id) group: vec3<u32>) {
    // The whole workgroup returns or none of it, and walks the same rounds: both read the slot's
    // object straight from the pool (uniform across the workgroup), not the private copy.
    let slot = objects[group.z].object;
    if (slot.pool.w & LIST_FINS) == 0u {
        return;
    }
    object = slot;
    let first = group.z * slot.fin_edge_count;
    var listed = 0u;
    let rounds = (slot.fin_edge_count + SCAN_WIDTH - 1u) / SCAN_WIDTH;
    for (var round = 0u; round < rounds; round++) {
        let edge = round * SCAN_WIDTH + lane;
        var fade = 0.0;
        if edge < object.fin_edge_count {
            fade = bitcast<f32>(fin_instances[first + edge].y);
        }
        let scan = workgroup_scan(lane, u32(fade > 0.0));
        // Every thread has read its slot: a round writes only to slots below its end, and to
        // none a later round reads.
        storageBarrier();
        if fade > 0.0 {
            fin_instances[first + listed + scan.x - 1u] = vec2<u32>(edge, bitcast<u32>(fade));
        }
        listed += scan.y;
    }
    if lane == 0u {
        // The fins' segments at this frame's level of detail (6 indices each).
        fin_draws[group.z].index_count = 6u * object.lod_shells;
        fin_draws[group.z].instance_count = listed;
        // The gathered copy of the draw (after every slot's own) reads the whole instance
        // buffer from the slot's first instance, which names the copy (`vs_pool_fin_*`).
        let at = objects[group.z].gather.x;
        if at != NOT_GATHERED {
            let slots = arrayLength(&fin_draws) / 2u;
            fin_draws[slots + at] = FinDraw(6u * object.lod_shells, listed, 0u, 0, first);
        }
    }
}
