// A herd's bases posed on the GPU (`HerdPosing`), skinned and placed where each member's fur
// reads them in one dispatch: x is the base vertex, y a row of the table (one member whose last
// pose is the GPU's). Appended to `skinning.wgsl`, whose bindings 0 to 3 (the rest pose, the
// influences and every member's joints) it reads; its `posed` output is not bound. The roots and
// frames go to the member's resident simulation inputs (the roots' w, its stability, is kept),
// the normals, packed, to its base normals.

struct PlaceParams {
    vertex_count: u32,
    rows: u32,
    padding: vec2<u32>,
}

@group(0) @binding(5) var<uniform> place_params: PlaceParams;
// Per row: the member's skin instance (its joints), its roots' first `vec4` in `strands` (its
// frames follow V on), its normals' first `f32` in `normals`.
@group(0) @binding(6) var<storage, read> table: array<vec4<u32>>;
@group(0) @binding(7) var<storage, read_write> strands: array<vec4<f32>>;
@group(0) @binding(8) var<storage, read_write> normals: array<f32>;

@compute @workgroup_size(64)
fn place(@builtin(global_invocation_id) id: vec3<u32>) {
    let vertex = id.x;
    let row = id.y;
    let v = place_params.vertex_count;
    if vertex >= v || row >= place_params.rows {
        return;
    }
    let entry = table[row];
    let pose = skinned(vertex, entry.x);
    let root = entry.y + vertex;
    strands[root] = vec4<f32>(pose.position, strands[root].w);
    strands[root + v] = pose.rotation;
    let at = entry.z + 3u * vertex;
    normals[at] = pose.normal.x;
    normals[at + 1u] = pose.normal.y;
    normals[at + 2u] = pose.normal.z;
}
