// An ordered compaction's building block for the compute passes that list what shows this frame
// (`silhouette.wgsl`, `view_lod.wgsl`): one workgroup of `SCAN_WIDTH` threads walks the items a
// round at a time, and each round's shown items take their places by a prefix sum, so the list
// keeps the items' order whatever the threads' timing.

const SCAN_WIDTH: u32 = 256u;
// Per thread, the sum of the values of the threads up to and including it (an inclusive prefix sum).
var<workgroup> sums_up_to: array<u32, SCAN_WIDTH>;

// The inclusive prefix sum of `value` over the workgroup's threads, and the round's total.
// Every thread must call it (it holds barriers).
fn workgroup_scan(lane: u32, value: u32) -> vec2<u32> {
    sums_up_to[lane] = value;
    workgroupBarrier();
    for (var offset = 1u; offset < SCAN_WIDTH; offset *= 2u) {
        var before = 0u;
        if lane >= offset {
            before = sums_up_to[lane - offset];
        }
        workgroupBarrier();
        sums_up_to[lane] += before;
        workgroupBarrier();
    }
    let result = vec2<u32>(sums_up_to[lane], sums_up_to[SCAN_WIDTH - 1u]);
    // Nobody writes the next round's values before everyone has read these.
    workgroupBarrier();
    return result;
}

// Threads a workgroup of the one-thread-an-item dispatches that come before a listing.
const ITEMS_WIDTH: u32 = 64u;

// The item of thread `id` in such a dispatch: rows of workgroups where one row would pass the
// dispatch limit (65,535 workgroups).
fn item_index(id: vec3<u32>, groups: vec3<u32>) -> u32 {
    return id.y * groups.x * ITEMS_WIDTH + id.x;
}
