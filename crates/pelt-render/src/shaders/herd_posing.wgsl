// A herd's bases posed on the GPU (`HerdPosing`), placed where each member's fur reads them: x is
// the base vertex, y a row of the table (one member whose last pose is the GPU's). The roots and
// frames go to the member's resident simulation inputs (the roots' w, its stability, is kept),
// the normals, packed, to its base normals.

struct PlaceParams {
    vertex_count: u32,
    rows: u32,
    padding: vec2<u32>,
}

@group(0) @binding(0) var<uniform> params: PlaceParams;
// `GpuSkin`'s output: per instance the positions, normals and rotations, V `vec4`s each.
@group(0) @binding(1) var<storage, read> posed: array<vec4<f32>>;
// Per row: the member's skin instance, its roots' first `vec4` in `strands` (its frames follow
// V on), its normals' first `f32` in `normals`.
@group(0) @binding(2) var<storage, read> table: array<vec4<u32>>;
@group(0) @binding(3) var<storage, read_write> strands: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read_write> normals: array<f32>;

@compute @workgroup_size(64)
fn place(@builtin(global_invocation_id) id: vec3<u32>) {
    let vertex = id.x;
    let row = id.y;
    let v = params.vertex_count;
    if vertex >= v || row >= params.rows {
        return;
    }
    let entry = table[row];
    let skinned = 3u * entry.x * v + vertex;
    let root = entry.y + vertex;
    strands[root] = vec4<f32>(posed[skinned].xyz, strands[root].w);
    strands[root + v] = posed[skinned + 2u * v];
    let normal = posed[skinned + v].xyz;
    let at = entry.z + 3u * vertex;
    normals[at] = normal.x;
    normals[at + 1u] = normal.y;
    normals[at + 2u] = normal.z;
}
