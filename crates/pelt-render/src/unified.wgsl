// The unified structure: every vertex shader fetches the one shared vertex array NV[i*V + j].
// Appended to `shading.wgsl`.

struct Object {
    // Plain meshes: their colour (linear RGB).
    colour: vec4<f32>,
    // V: base vertices, the stride between layers.
    vertex_count: u32,
    // L: shells above the base (0 for a plain mesh).
    layers: u32,
    triangle_count: u32,
    edge_count: u32,
    has_uvs: u32,
    // Mesh uv -> tiles.
    tiles_per_uv: f32,
    // World units -> tiles (triplanar projection and fins).
    tiles_per_world: f32,
    // Slices in the shell texture (may differ from `layers` while a viewer edits them).
    shell_slices: u32,
}

@group(1) @binding(0) var<uniform> object: Object;
// NV as packed xyz triples ((L + 1) * V of them): updated every frame from the simulation.
@group(1) @binding(1) var<storage, read> positions: array<f32>;
// Rest normals of the base vertices, packed xyz.
@group(1) @binding(2) var<storage, read> normals: array<f32>;
// Mesh uvs per triangle corner (3F), or one dummy entry.
@group(1) @binding(3) var<storage, read> corner_uvs: array<vec2<f32>>;
// Triangles (3F), then edges (2E), then the two faces beside each edge (2E).
@group(1) @binding(4) var<storage, read> topology: array<u32>;

fn uses_mesh_uvs() -> bool {
    return object.has_uvs != 0u;
}

const NO_FACE: u32 = 0xffffffffu;

fn shared_vertex(layer: u32, vertex: u32) -> vec3<f32> {
    let k = 3u * (layer * object.vertex_count + vertex);
    return vec3<f32>(positions[k], positions[k + 1u], positions[k + 2u]);
}

fn rest_normal(vertex: u32) -> vec3<f32> {
    let k = 3u * vertex;
    return vec3<f32>(normals[k], normals[k + 1u], normals[k + 2u]);
}

// The strand direction at NV[layer*V + vertex]: NV[(i+1)V+j] - NV[iV+j] (the last segment at the tips).
fn strand_tangent(layer: u32, vertex: u32) -> vec3<f32> {
    let lower = min(layer, max(object.layers, 1u) - 1u);
    let segment = shared_vertex(lower + 1u, vertex) - shared_vertex(lower, vertex);
    return safe_normalize(segment, rest_normal(vertex));
}

fn triangle_vertex(corner: u32) -> u32 {
    return topology[corner];
}

fn face_normal(face: u32) -> vec3<f32> {
    let a = shared_vertex(0u, topology[3u * face]);
    let b = shared_vertex(0u, topology[3u * face + 1u]);
    let c = shared_vertex(0u, topology[3u * face + 2u]);
    return safe_normalize(cross(b - a, c - a), vec3<f32>(0.0));
}

// `corner` indexes the per-corner uvs; it is only read when the mesh has uvs.
fn surface_varyings(vertex: u32, corner: u32, layer: u32) -> Varyings {
    let position = shared_vertex(layer, vertex);
    var out: Varyings;
    out.clip_position = globals.clip_from_world * vec4<f32>(position, 1.0);
    out.world_position = position;
    out.normal = rest_normal(vertex);
    out.tangent = strand_tangent(layer, vertex);
    out.tile_position = shared_vertex(0u, vertex) * object.tiles_per_world;
    if object.has_uvs != 0u {
        out.surface_uv = corner_uvs[corner];
        out.uv = out.surface_uv * object.tiles_per_uv;
    } else {
        out.surface_uv = vec2<f32>(0.0);
        out.uv = vec2<f32>(0.0);
    }
    out.layer = layer;
    // Shell layer i (1..=L) shows slice i - 1, scaled when the texture has another count.
    out.slice = i32(((max(layer, 1u) - 1u) * object.shell_slices) / max(object.layers, 1u));
    out.height = f32(layer) / f32(max(object.layers, 1u));
    out.fade = 1.0;
    return out;
}

// Two ways to walk the base triangles. Meshes with uvs: non-indexed over the 3F corners
// (`vertex_index` = corner, so seams keep their own uvs). Meshes without: indexed by the base
// triangles themselves (`vertex_index` = base vertex), so each vertex is shaded once a layer.

// The opaque skin: layer 0.
@vertex
fn vs_skin_corners(@builtin(vertex_index) corner: u32) -> Varyings {
    return surface_varyings(triangle_vertex(corner), corner, 0u);
}

@vertex
fn vs_skin_indexed(@builtin(vertex_index) vertex: u32) -> Varyings {
    return surface_varyings(vertex, 0u, 0u);
}

// Shells: instance i draws layer i + 1.
@vertex
fn vs_shell_corners(@builtin(vertex_index) corner: u32, @builtin(instance_index) instance: u32) -> Varyings {
    var out = surface_varyings(triangle_vertex(corner), corner, instance + 1u);
    out.fade = shell_fade(out.normal, out.world_position);
    return out;
}

@vertex
fn vs_shell_indexed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> Varyings {
    var out = surface_varyings(vertex, 0u, instance + 1u);
    out.fade = shell_fade(out.normal, out.world_position);
    return out;
}

fn hash(x: u32) -> u32 {
    var h = x * 0x9e3779b9u;
    h = (h ^ (h >> 16u)) * 0x85ebca6bu;
    h = (h ^ (h >> 13u)) * 0xc2b2ae35u;
    return h ^ (h >> 16u);
}

// Fins: instance = edge; vertex 2i + s is strand node i on side s (0 = a, 1 = b) of the edge, and
// a shared index buffer joins them into two triangles per layer step, L steps up the strands.
// Each corner is a shared vertex, so fins bend with the simulated fur.
@vertex
fn vs_fin(@builtin(vertex_index) index: u32, @builtin(instance_index) edge: u32) -> Varyings {
    let side = index % 2u;
    let layer = index / 2u;

    let edges_start = 3u * object.triangle_count;
    let a = topology[edges_start + 2u * edge];
    let b = topology[edges_start + 2u * edge + 1u];
    let vertex = select(a, b, side == 1u);

    // Fade in near the silhouette: where the faces beside the edge turn edge-on, or one faces
    // the camera and the other away.
    let faces_start = edges_start + 2u * object.edge_count;
    let face_a = topology[faces_start + 2u * edge];
    let face_b = topology[faces_start + 2u * edge + 1u];
    let root_a = shared_vertex(0u, a);
    let root_b = shared_vertex(0u, b);
    let to_camera = safe_normalize(globals.camera_position - 0.5 * (root_a + root_b), vec3<f32>(0.0, 0.0, 1.0));
    let facing_a = dot(face_normal(face_a), to_camera);
    var edge_on = abs(facing_a);
    if face_b != NO_FACE {
        let facing_b = dot(face_normal(face_b), to_camera);
        edge_on = min(edge_on, abs(facing_b));
        if facing_a * facing_b <= 0.0 {
            // A true silhouette edge: one face toward the camera, one away.
            edge_on = 0.0;
        }
    }
    let fade = 1.0 - smoothstep(0.0, globals.fin_fade_cos, edge_on);
    var out: Varyings;
    if fade <= 0.0 {
        // Invisible fin (most of them): every vertex of the edge lands outside the clip volume,
        // so it costs no rasterisation, and returning now skips the rest of the shading.
        out.clip_position = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }

    let position = shared_vertex(layer, vertex);
    out.clip_position = globals.clip_from_world * vec4<f32>(position, 1.0);
    out.world_position = position;
    out.normal = safe_normalize(rest_normal(a) + rest_normal(b), rest_normal(a));
    out.tangent = strand_tangent(layer, vertex);
    out.tile_position = vec3<f32>(0.0);
    let offset = f32(hash(edge) & 0xffffu) / 65536.0;
    out.uv = vec2<f32>(offset + f32(side) * distance(root_a, root_b) * object.tiles_per_world, f32(layer) / f32(max(object.layers, 1u)));
    out.layer = 0u;
    out.slice = 0;
    // The surface uv of this end of the edge, from its corner in the first face.
    out.surface_uv = vec2<f32>(0.0);
    if object.has_uvs != 0u && globals.has_surface != 0u {
        for (var k = 0u; k < 3u; k++) {
            if topology[3u * face_a + k] == vertex {
                out.surface_uv = corner_uvs[3u * face_a + k];
            }
        }
    }
    out.height = out.uv.y;
    out.fade = fade;
    return out;
}

// Plain meshes (no fur, e.g. the body under a furry garment): layer 0 in the object's colour.
@fragment
fn fs_plain(in: Varyings) -> @location(0) vec4<f32> {
    return vec4<f32>(surface_lighting(object.colour.rgb, normalize(in.normal)), 1.0);
}
