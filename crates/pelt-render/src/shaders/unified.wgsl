// The unified structure: every vertex shader fetches the one shared vertex array NV[i*V + j].
// Appended to `shading.wgsl`.
//
// Positions are read in model space, as `mix(previous, current, interpolation)` of the two
// simulation states, then taken to world space: lighting, fading and the fins' silhouette test
// all work in world space (face normals through `world_normal_from_model`, so any affine model
// transform, non-uniform scale included, gives the right answer).

// NV as packed xyz triples ((L + 1) * V of them, model space): the older and the newer simulation
// state (the same buffer twice when the fur keeps one state).
@group(1) @binding(1) var<storage, read> previous_positions: array<f32>;
@group(1) @binding(2) var<storage, read> current_positions: array<f32>;
// Base normals of the base vertices, packed xyz, model space: the rest normals, or the posed ones
// of an animated mesh.
@group(1) @binding(3) var<storage, read> base_normals: array<f32>;
// Meshes with uvs: the uv of each wedge (a base vertex with one uv; a vertex on a uv seam has
// one wedge per side), or one dummy entry.
@group(1) @binding(4) var<storage, read> wedge_uvs: array<vec2<f32>>;
// Triangles (3F), then edges (2E), then the two faces beside each edge (2E); with uvs, then each
// wedge's base vertex (W) and each triangle corner's wedge (3F, the shells' index buffer).
@group(1) @binding(5) var<storage, read> topology: array<u32>;
// A groomed fur's per-vertex shading terms (V entries; one unused entry without a groom),
// rewritten in place when a groom is painted (`GpuFur::set_groom`).
@group(1) @binding(6) var<storage, read> groom_attributes: array<GroomAttributes>;

// A wetness per base vertex, read only by the wet coats' pipelines (`wet_on`).
@group(1) @binding(7) var<storage, read> wetness: array<f32>;

// The groom's terms at base vertex `vertex` (the uniform fur's without groom shading), wet
// where the fur is.
fn vertex_groom(vertex: u32) -> GroomShade {
    var groom = GROOM_NONE;
    if groom_on() {
        groom = groom_shade(groom_attributes[vertex]);
    }
    if wet_on() {
        groom = wet_groom(groom, wetness[vertex]);
    }
    return groom;
}

const NO_FACE: u32 = 0xffffffffu;

// NV[layer * V + vertex] in model space, between the two states.
fn model_vertex(layer: u32, vertex: u32) -> vec3<f32> {
    let k = 3u * (layer * object.vertex_count + vertex);
    let c = current_base() + k;
    let current = vec3<f32>(current_positions[c], current_positions[c + 1u], current_positions[c + 2u]);
    // One state (or a frame on a step): one fetch. The branch is uniform.
    let t = object.interpolation;
    if t >= 1.0 {
        return current;
    }
    let p = previous_base() + k;
    let previous = vec3<f32>(previous_positions[p], previous_positions[p + 1u], previous_positions[p + 2u]);
    // The form of `Simulation::write_lerp`: exactly one state at 0 and the other at 1.
    return previous * (1.0 - t) + current * t;
}

fn model_normal(vertex: u32) -> vec3<f32> {
    let k = normals_base() + 3u * vertex;
    return vec3<f32>(base_normals[k], base_normals[k + 1u], base_normals[k + 2u]);
}

// The strand direction at NV[layer*V + vertex] = `here` in world space: NV[(i+1)V+j] - NV[iV+j]
// (the last segment at the tips). `here` is passed in so the vertex fetches one more position,
// not two. Furs only (L >= 1).
fn strand_tangent(layer: u32, vertex: u32, here: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    var segment: vec3<f32>;
    if layer < object.layers {
        segment = model_vertex(layer + 1u, vertex) - here;
    } else {
        segment = here - model_vertex(layer - 1u, vertex);
    }
    return safe_normalize(world_from_model_direction(segment), fallback);
}

fn wedges_start() -> u32 {
    return 3u * object.triangle_count + 4u * object.edge_count;
}

fn wedge_vertex(wedge: u32) -> u32 {
    return topology[wedges_start() + wedge];
}

// The wedge of triangle corner `corner` (3 * triangle + k).
fn corner_wedge(corner: u32) -> u32 {
    return topology[wedges_start() + object.wedge_count + corner];
}

// World-space face normal of a base triangle (unit, or zero for a degenerate one).
fn face_normal(face: u32) -> vec3<f32> {
    let a = model_vertex(0u, topology[3u * face]);
    let b = model_vertex(0u, topology[3u * face + 1u]);
    let c = model_vertex(0u, topology[3u * face + 2u]);
    return world_from_model_normal(cross(b - a, c - a));
}

// `wedge` indexes the wedge uvs; it is only read when the mesh has uvs. Every branch here is on
// the object uniform, so whole draws take one side: a vertex fetches only what its draw uses
// (the tangent for shells, the root for the triplanar projection without uvs).
fn surface_varyings(vertex: u32, wedge: u32, layer: u32) -> Varyings {
    let here = model_vertex(layer, vertex);
    let position = world_from_model_point(here);
    let rest_normal = model_normal(vertex);
    var out: Varyings;
    out.clip_position = view.clip_from_world * vec4<f32>(position, 1.0);
    out.world_position = position;
    out.normal = world_from_model_normal(rest_normal);
    // The skin and plain meshes are lit by the normal alone.
    out.tangent = out.normal;
    if layer > 0u {
        out.tangent = strand_tangent(layer, vertex, here, out.normal);
    }
    out.tile_normal = rest_normal;
    out.light_count = lights.count;
    if uses_mesh_uvs() {
        out.tile_position = vec3<f32>(0.0);
        out.surface_uv = wedge_uvs[wedge];
        out.uv = out.surface_uv * object.tiles_per_uv;
    } else {
        // Shells are textured from their strand's root, the skin from itself.
        var root = here;
        if layer > 0u {
            root = model_vertex(0u, vertex);
        }
        out.tile_position = root * object.tiles_per_world;
        out.surface_uv = vec2<f32>(0.0);
        out.uv = vec2<f32>(0.0);
    }
    out.layer = layer;
    out.slice = shell_slice(layer);
    out.height = layer_height(layer);
    out.fade = 1.0;
    return out;
}

// Two ways to walk the base triangles, both indexed so that each index is shaded once a layer
// (as long as the vertex cache holds it). Meshes with uvs: by the corners' wedges
// (`vertex_index` = wedge, so seams keep their own uvs). Meshes without: by the base triangles
// themselves (`vertex_index` = base vertex).

// The opaque skin (and plain meshes): layer 0.
@vertex
fn vs_skin_wedges(@builtin(vertex_index) wedge: u32) -> Varyings {
    return surface_varyings(wedge_vertex(wedge), wedge, 0u);
}

@vertex
fn vs_skin_indexed(@builtin(vertex_index) vertex: u32) -> Varyings {
    return surface_varyings(vertex, 0u, 0u);
}

// Shells: instance k draws the level of detail's shell k (layer k + 1 at full detail), passing
// on only what their fragments read (the rest of `surface_varyings` is compiled away). Each
// entry point has a `_groomed` twin for the groomed or wet coats, which adds the groom's terms.
@vertex
fn vs_shell_wedges(@builtin(vertex_index) wedge: u32, @builtin(instance_index) instance: u32) -> ShellUvVaryings {
    return shell_wedge(wedge, instance);
}

@vertex
fn vs_shell_indexed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> ShellTileVaryings {
    return shell_vertex(vertex, instance);
}

@vertex
fn vs_shell_wedges_groomed(@builtin(vertex_index) wedge: u32, @builtin(instance_index) instance: u32) -> GroomedShellUvVaryings {
    return groomed_shell_wedge(wedge, instance);
}

@vertex
fn vs_shell_indexed_groomed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> GroomedShellTileVaryings {
    return groomed_shell_vertex(vertex, instance);
}

// Shells through the view-angle list (`view_lod.wgsl`): one indirect draw per shell the view
// angle thins, over the listed triangles, with base vertex `shell * N`, so `vertex_index`
// carries the shell and the wedge (N = W) or base vertex (N = V).
@vertex
fn vs_shell_wedges_listed(@builtin(vertex_index) index: u32) -> ShellUvVaryings {
    return shell_wedge(index % object.wedge_count, index / object.wedge_count);
}

@vertex
fn vs_shell_indexed_listed(@builtin(vertex_index) index: u32) -> ShellTileVaryings {
    return shell_vertex(index % object.vertex_count, index / object.vertex_count);
}

@vertex
fn vs_shell_wedges_listed_groomed(@builtin(vertex_index) index: u32) -> GroomedShellUvVaryings {
    return groomed_shell_wedge(index % object.wedge_count, index / object.wedge_count);
}

@vertex
fn vs_shell_indexed_listed_groomed(@builtin(vertex_index) index: u32) -> GroomedShellTileVaryings {
    return groomed_shell_vertex(index % object.vertex_count, index / object.vertex_count);
}

// The deep opacity pass's shell `instance` (`opacity_stride` in `shadows.wgsl`).
fn opacity_shell(instance: u32) -> u32 {
    let stride = opacity_stride();
    return min(stride * instance + stride / 2u, object.lod_shells - 1u);
}

@vertex
fn vs_opacity_shell_wedges(@builtin(vertex_index) wedge: u32, @builtin(instance_index) instance: u32) -> ShellUvVaryings {
    return shell_wedge(wedge, opacity_shell(instance));
}

@vertex
fn vs_opacity_shell_indexed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> ShellTileVaryings {
    return shell_vertex(vertex, opacity_shell(instance));
}

@vertex
fn vs_opacity_shell_wedges_groomed(@builtin(vertex_index) wedge: u32, @builtin(instance_index) instance: u32) -> GroomedShellUvVaryings {
    return groomed_shell_wedge(wedge, opacity_shell(instance));
}

@vertex
fn vs_opacity_shell_indexed_groomed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> GroomedShellTileVaryings {
    return groomed_shell_vertex(vertex, opacity_shell(instance));
}

fn shell_wedge(wedge: u32, shell: u32) -> ShellUvVaryings {
    let vertex = wedge_vertex(wedge);
    let v = surface_varyings(vertex, wedge, lod_shell_layer(shell));
    return shell_uv_varyings(v, shell_fade(v.normal, v.world_position), lod_shell_blend(vertex, v.normal));
}

fn shell_vertex(vertex: u32, shell: u32) -> ShellTileVaryings {
    let v = surface_varyings(vertex, 0u, lod_shell_layer(shell));
    return shell_tile_varyings(v, shell_fade(v.normal, v.world_position), lod_shell_blend(vertex, v.normal));
}

fn groomed_shell_wedge(wedge: u32, shell: u32) -> GroomedShellUvVaryings {
    let vertex = wedge_vertex(wedge);
    let v = surface_varyings(vertex, wedge, lod_shell_layer(shell));
    return groomed_shell_uv_varyings(v, shell_fade(v.normal, v.world_position), lod_shell_blend(vertex, v.normal), vertex_groom(vertex), fur_length(vertex));
}

fn groomed_shell_vertex(vertex: u32, shell: u32) -> GroomedShellTileVaryings {
    let v = surface_varyings(vertex, 0u, lod_shell_layer(shell));
    return groomed_shell_tile_varyings(v, shell_fade(v.normal, v.world_position), lod_shell_blend(vertex, v.normal), vertex_groom(vertex), fur_length(vertex));
}

// A wet coat's strand length in the world at base vertex `vertex` (`WetStrand`; 0 for a dry
// coat, which fetches nothing for it): its first segment times `L` (the simulation keeps every
// segment's length).
fn fur_length(vertex: u32) -> f32 {
    if !wet_on() {
        return 0.0;
    }
    let segment = model_vertex(1u, vertex) - model_vertex(0u, vertex);
    return length(world_from_model_direction(segment)) * f32(object.layers);
}

// The level of detail's blend at base vertex `vertex` (world normal `normal`): the view angle
// weighed at the strand's root, the same for every layer (what the culling pass decides on).
fn lod_shell_blend(vertex: u32, normal: vec3<f32>) -> f32 {
    var weight = 0.0;
    // A uniform branch: without view-angle LOD no root is fetched.
    if object.lod_view > 0.0 {
        weight = lod_view_weight(normal, world_from_model_point(model_vertex(0u, vertex)));
    }
    return lod_vertex_blend(weight);
}

fn hash(x: u32) -> u32 {
    var h = x * 0x9e3779b9u;
    h = (h ^ (h >> 16u)) * 0x85ebca6bu;
    h = (h ^ (h >> 13u)) * 0xc2b2ae35u;
    return h ^ (h >> 16u);
}

// Fins: one per edge; vertex 2i + s is strand node i on side s (0 = a, 1 = b) of the edge, and a
// shared index buffer joins them into two triangles per layer step, L steps up the strands.
// Each corner is a shared vertex, so fins bend with the simulated fur.

// How much of an edge's fin shows: 1 on the silhouette, fading to 0 where the faces beside the
// edge turn toward the camera (both in front, or both behind).
fn fin_fade(edge: u32) -> f32 {
    let edges_start = 3u * object.triangle_count;
    let a = topology[edges_start + 2u * edge];
    let b = topology[edges_start + 2u * edge + 1u];
    let faces_start = edges_start + 2u * object.edge_count;
    let face_a = topology[faces_start + 2u * edge];
    let face_b = topology[faces_start + 2u * edge + 1u];
    let middle = world_from_model_point(0.5 * (model_vertex(0u, a) + model_vertex(0u, b)));
    let to_camera = safe_normalize(view.camera_position - middle, vec3<f32>(0.0, 0.0, 1.0));
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
    return 1.0 - smoothstep(0.0, object.fin_fade_cos, edge_on);
}

// Where a fin's strand node is drawn: the shared vertex, or, for a node the next coarser level
// drops, moved toward the line between its neighbours by `lod_blend` (so segments merge smoothly).
fn fin_node(layer: u32, vertex: u32) -> vec3<f32> {
    let here = model_vertex(layer, vertex);
    if object.lod_blend > 0.0 && layer > 0u && lod_dropped(layer) {
        let between = 0.5 * (model_vertex(layer - object.lod_stride, vertex) + model_vertex(layer + object.lod_stride, vertex));
        return mix(here, between, object.lod_blend);
    }
    return here;
}

// The base vertex fin vertex `index` of `edge` stands on.
fn fin_vertex(index: u32, edge: u32) -> u32 {
    let edges_start = 3u * object.triangle_count;
    return topology[edges_start + 2u * edge + index % 2u];
}

// The fin vertex `index` of a shown `edge` (fade > 0): node `index / 2` of the level of detail.
fn fin_varyings(index: u32, edge: u32, fade: f32) -> FinVaryings {
    return wet_fin_varyings(index, edge, fade, 0.0);
}

// Where a fin vertex lies and how its strand runs, without its lighting: the colour pass lights
// it (`wet_fin_varyings`), the prepass and shadow views only place it.
struct FinGeometry {
    world_position: vec3<f32>,
    clip_position: vec4<f32>,
    normal: vec3<f32>,
    tangent: vec3<f32>,
    // Along the edge in tiles, the height, the surface uv.
    uvs: vec4<f32>,
}

fn fin_geometry(index: u32, edge: u32) -> FinGeometry {
    let side = index % 2u;
    let layer = lod_fin_layer(index / 2u);
    let edges_start = 3u * object.triangle_count;
    let a = topology[edges_start + 2u * edge];
    let b = topology[edges_start + 2u * edge + 1u];
    let vertex = select(a, b, side == 1u);

    var out: FinGeometry;
    let here = fin_node(layer, vertex);
    out.world_position = world_from_model_point(here);
    out.clip_position = view.clip_from_world * vec4<f32>(out.world_position, 1.0);
    let normal_a = world_from_model_normal(model_normal(a));
    out.normal = safe_normalize(normal_a + world_from_model_normal(model_normal(b)), normal_a);
    out.tangent = strand_tangent(layer, vertex, here, out.normal);
    let offset = f32(hash(edge) & 0xffffu) / 65536.0;
    let along = f32(side) * distance(model_vertex(0u, a), model_vertex(0u, b)) * object.tiles_per_world;
    // The surface uv of this end of the edge, from its corner in the first face.
    var surface_uv = vec2<f32>(0.0);
    if uses_mesh_uvs() && object.has_surface != 0u {
        let face_a = topology[edges_start + 2u * object.edge_count + 2u * edge];
        for (var k = 0u; k < 3u; k++) {
            if topology[3u * face_a + k] == vertex {
                surface_uv = wedge_uvs[corner_wedge(3u * face_a + k)];
            }
        }
    }
    out.uvs = vec4<f32>(offset + along, layer_height(layer), surface_uv);
    return out;
}

// `fin_varyings` for a strand of wetness `wetness`.
fn wet_fin_varyings(index: u32, edge: u32, fade: f32, wetness: f32) -> FinVaryings {
    let g = fin_geometry(index, edge);
    var out: FinVaryings;
    out.clip_position = g.clip_position;
    // The occlusion (`w`) is the fragment's, from the interpolated height.
    out.lighting_fade = vec4<f32>(coat_terms(g.tangent, g.normal, g.world_position, 0.0, wetness).xyz, fade);
    out.uvs = g.uvs;
    return out;
}

// A groomed or wet coat's fin vertex: the lean one's, its highlight wet, and the groom's terms.
fn groomed_fin_varyings(index: u32, edge: u32, fade: f32) -> GroomedFinVaryings {
    let groom = vertex_groom(fin_vertex(index, edge));
    let lean = wet_fin_varyings(index, edge, fade, groom.wetness);
    let lighting = lean.lighting_fade.xyz;
    let tint_density = vec4<f32>(groom.tint, groom.density);
    return GroomedFinVaryings(lean.clip_position, vec4<f32>(lighting, fade), lean.uvs, tint_density, groom.clump);
}

// Where an edge's fin shows not at all (most of them): every vertex of it lands outside the
// clip volume, so it costs no rasterisation, and returning early skips the rest of the shading.
const HIDDEN_FIN_CORNER = vec4<f32>(2.0, 2.0, 2.0, 1.0);

// Every edge (instance = edge), each vertex deciding whether its edge shows: for hosts that
// record no silhouette pass.
@vertex
fn vs_fin(@builtin(vertex_index) index: u32, @builtin(instance_index) edge: u32) -> FinVaryings {
    let fade = fin_fade(edge);
    if fade <= 0.0 {
        var out: FinVaryings;
        out.clip_position = HIDDEN_FIN_CORNER;
        return out;
    }
    return fin_varyings(index, edge, fade);
}

@vertex
fn vs_fin_groomed(@builtin(vertex_index) index: u32, @builtin(instance_index) edge: u32) -> GroomedFinVaryings {
    let fade = fin_fade(edge);
    if fade <= 0.0 {
        var out: GroomedFinVaryings;
        out.clip_position = HIDDEN_FIN_CORNER;
        return out;
    }
    return groomed_fin_varyings(index, edge, fade);
}

// Silhouette edges only: `fin` = (edge, fade bits), one instance per edge the silhouette pass
// (`silhouette.wgsl`) kept this frame.
@vertex
fn vs_fin_silhouette(@builtin(vertex_index) index: u32, @location(0) fin: vec2<u32>) -> FinVaryings {
    return fin_varyings(index, fin.x, bitcast<f32>(fin.y));
}

@vertex
fn vs_fin_silhouette_groomed(@builtin(vertex_index) index: u32, @location(0) fin: vec2<u32>) -> GroomedFinVaryings {
    return groomed_fin_varyings(index, fin.x, bitcast<f32>(fin.y));
}
