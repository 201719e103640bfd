// Shells by view angle, the culling half: once per triangle per frame, list the triangles that
// still show in the layers the next coarser stride drops (where `lod_view_weight` is below 1 at
// any corner: elsewhere those layers' alpha is 0 at all three corners, so everywhere between),
// then write one indexed indirect draw per shell over that list. Appended to `shading.wgsl`,
// `unified.wgsl` and `scan.wgsl`: the list keeps triangle order, since triangles of one shell
// overlap near the outline and blend in list order.

// `wgpu::util::DrawIndexedIndirectArgs`.
struct ShellDraw {
    index_count: u32,
    instance_count: u32,
    first_index: u32,
    base_vertex: i32,
    first_instance: u32,
}

// Group 2 holds textures in the render pipelines; this pass leaves it empty. Group 3 holds
// every copy's list of its pool, slot by slot (`object_pool.wgsl`: workgroup z is the slot).
// Indices listed (3 a triangle), one count a copy.
@group(3) @binding(0) var<storage, read_write> listed: array<u32>;
// In a pool of more than one, every furred triangle's corners' wedges (meshes with uvs) or base
// vertices (meshes without); then each copy's listed ones in triangle order,
// `3 * furred_triangle_count` slots a copy.
@group(3) @binding(1) var<storage, read_write> listed_indices: array<u32>;
// One draw per layer a copy (only the dropped shells' are used), then in a pool of more than one
// as many gathered draws (`ObjectSlot::gather`).
@group(3) @binding(2) var<storage, read_write> shell_draws: array<ShellDraw>;

// Whether triangle `triangle` still shows in the layers the next coarser stride drops.
fn view_lod_shows(triangle: u32) -> bool {
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
    return shows;
}

// The first of slot `member`'s indices in `listed_indices`. The copies of a pool of more than
// one keep every furred triangle's corners first (the head), which their gathered draws of the
// shells kept whole read.
fn first_listed(member: u32) -> u32 {
    let head = u32(arrayLength(&listed) > 1u);
    return 3u * (member + head) * object.furred_triangle_count;
}

// First, one thread a triangle over as many workgroups as it takes: whether it shows, in the
// first of its own three slots of the list (deciding inside the one listing workgroup left the
// whole mesh to one thread of a CPU rasteriser).
@compute @workgroup_size(64)
fn cs_view_lod_flags(@builtin(global_invocation_id) id: vec3<u32>, @builtin(num_workgroups) groups: vec3<u32>) {
    if !load_member(id.z, LIST_SHELLS) {
        return;
    }
    let triangle = item_index(id, groups);
    if triangle < object.furred_triangle_count {
        listed_indices[first_listed(id.z) + 3u * triangle] = u32(view_lod_shows(triangle));
    }
}

// Then one workgroup a copy walks its triangles `SCAN_WIDTH` at a time (as `cs_silhouette` walks
// the edges) and moves the shown ones down to their places, in place: a round writes only below
// its own end, and every thread has read its flag before any writes.
@compute @workgroup_size(256)
fn cs_view_lod_list(@builtin(local_invocation_index) lane: u32, @builtin(workgroup_id) group: vec3<u32>) {
    // The whole workgroup returns or none of it, and walks the same rounds: both read the slot's
    // object straight from the pool (uniform across the workgroup), not the private copy.
    let slot = objects[group.z].object;
    if (slot.pool.w & LIST_SHELLS) == 0u {
        return;
    }
    object = slot;
    let base = first_listed(group.z);
    var count = 0u;
    let rounds = (slot.furred_triangle_count + SCAN_WIDTH - 1u) / SCAN_WIDTH;
    for (var round = 0u; round < rounds; round++) {
        let triangle = round * SCAN_WIDTH + lane;
        let shows = triangle < object.furred_triangle_count && listed_indices[base + 3u * triangle] != 0u;
        let scan = workgroup_scan(lane, u32(shows));
        storageBarrier();
        if shows {
            let first = base + 3u * (count + scan.x - 1u);
            for (var k = 0u; k < 3u; k++) {
                let corner = 3u * triangle + k;
                listed_indices[first + k] = select(topology[corner], corner_wedge(corner), object.has_uvs != 0u);
            }
        }
        count += scan.y;
    }
    if lane == 0u {
        listed[group.z] = 3u * count;
    }
}

// After the list (a second dispatch): shell k's draw covers the copy's listed indices with base
// vertex k * N, which `vs_shell_*_listed` read back as the shell. A copy a herd's camera draws
// gathered (`HerdDraws`) also gets all `L` of its draws in order at its gathered place: the
// shells the view angle thins over its list, the others over every furred triangle, each with
// the copy's slot as its first instance (`vs_pool_shell_*_listed`), none past its level's shells.
@compute @workgroup_size(64)
fn cs_view_lod_draws(@builtin(global_invocation_id) id: vec3<u32>) {
    if !load_member(id.z, LIST_SHELLS) {
        return;
    }
    let shell = id.x;
    if shell >= object.layers {
        return;
    }
    let per_shell = select(object.vertex_count, object.wedge_count, object.has_uvs != 0u);
    if shell < object.lod_shells {
        shell_draws[id.z * object.layers + shell] = ShellDraw(listed[id.z], 1u, first_listed(id.z), i32(shell * per_shell), 0u);
    }
    let at = objects[id.z].gather.y;
    if at == NOT_GATHERED {
        return;
    }
    var draw = ShellDraw(0u, 0u, 0u, 0, 0u);
    if shell < object.lod_shells {
        // As `FurLevel::dropped_shell`.
        let dropped = ((object.lod_shells - 1u - shell) & 1u) == 1u;
        let count = select(3u * object.furred_triangle_count, listed[id.z], dropped);
        draw = ShellDraw(count, 1u, select(0u, first_listed(id.z), dropped), i32(shell * per_shell), id.z);
    }
    shell_draws[(arrayLength(&listed) + at) * object.layers + shell] = draw;
}
