// The separated structure of Lengyel et al. 2001: shells and fins as their own static vertex
// buffers (position, normal, uv: 32 bytes a vertex, model space). Appended to `shading.wgsl`;
// group 1 holds the object uniform, the fin vertices again as storage (`vs_separated_fin`), and
// a groom's per-vertex attributes with the base vertices at each fin's ends.

// A groomed fur's shading terms per base vertex (V entries; one unused entry without a groom).
@group(1) @binding(2) var<storage, read> groom_attributes: array<GroomAttributes>;
// The base vertices at the ends of fin `f`: entries 2f and 2f + 1.
@group(1) @binding(3) var<storage, read> fin_ends: array<u32>;

fn separated_groom(vertex: u32) -> GroomShade {
    // A uniform branch: ungroomed furs read nothing.
    if !groom_on() {
        return GROOM_NONE;
    }
    return groom_shade(groom_attributes[vertex]);
}

struct VertexIn {
    @location(0) position: vec3<f32>,
    // Layer 0 (the skin): the base normal. Shells: the growing vector. Fins: the fin's plane normal.
    @location(1) normal: vec3<f32>,
    // Shells: mesh uv scaled to model units on the CPU. Fins: (model units along the edge, height).
    @location(2) uv: vec2<f32>,
}

// Layer 0 of the shell vertices, opaque, as the unified skin.
@vertex
fn vs_separated_skin(in: VertexIn) -> Varyings {
    var out: Varyings;
    let position = world_from_model_point(in.position);
    out.clip_position = view.clip_from_world * vec4<f32>(position, 1.0);
    out.world_position = position;
    out.normal = world_from_model_normal(in.normal);
    out.tangent = out.normal;
    out.tile_position = vec3<f32>(0.0);
    out.tile_normal = vec3<f32>(0.0);
    out.uv = vec2<f32>(0.0);
    out.surface_uv = in.uv / object.world_per_uv;
    out.layer = 0u;
    out.slice = 0;
    out.height = 0.0;
    out.fade = 1.0;
    return out;
}

// Shells: one draw per layer with a base-vertex offset; the instance index carries the layer.
// Meshes without uvs and with them pass on what `fs_shell_tiles` and `fs_shell_uvs` read, as
// the unified shells do; a groomed fur's `_groomed` twins add the groom's terms.
@vertex
fn vs_separated_shell_tiles(in: VertexIn, @builtin(instance_index) layer: u32) -> ShellTileVaryings {
    let v = separated_shell(in, layer);
    return shell_tile_varyings(v, v.fade, separated_lod_blend(v));
}

@vertex
fn vs_separated_shell_uvs(in: VertexIn, @builtin(instance_index) layer: u32) -> ShellUvVaryings {
    let v = separated_shell(in, layer);
    return shell_uv_varyings(v, v.fade, separated_lod_blend(v));
}

@vertex
fn vs_separated_shell_tiles_groomed(in: VertexIn, @builtin(instance_index) layer: u32, @builtin(vertex_index) index: u32) -> GroomedShellTileVaryings {
    let v = separated_shell(in, layer);
    return groomed_shell_tile_varyings(v, v.fade, separated_lod_blend(v), separated_shell_groom(index), 0.0);
}

@vertex
fn vs_separated_shell_uvs_groomed(in: VertexIn, @builtin(instance_index) layer: u32, @builtin(vertex_index) index: u32) -> GroomedShellUvVaryings {
    let v = separated_shell(in, layer);
    return groomed_shell_uv_varyings(v, v.fade, separated_lod_blend(v), separated_shell_groom(index), 0.0);
}

// Each layer is drawn with base vertex `layer * V`, so the base vertex is the index modulo V.
fn separated_shell_groom(index: u32) -> GroomShade {
    return separated_groom(index % max(object.vertex_count, 1u));
}

// Shells by view angle as the unified shells fade them, from the shell vertex itself (these
// vertices do not know their root; the difference is the strand's length against the camera's
// distance). Nothing is culled here: every layer's triangles are drawn.
fn separated_lod_blend(v: Varyings) -> f32 {
    var weight = 0.0;
    if object.lod_view > 0.0 {
        weight = lod_view_weight(v.normal, v.world_position);
    }
    return lod_vertex_blend(weight);
}

fn separated_shell(in: VertexIn, layer: u32) -> Varyings {
    var out: Varyings;
    let position = world_from_model_point(in.position);
    out.clip_position = view.clip_from_world * vec4<f32>(position, 1.0);
    out.world_position = position;
    out.normal = world_from_model_normal(in.normal);
    out.tangent = out.normal;
    out.tile_position = in.position * object.tiles_per_world;
    out.tile_normal = in.normal;
    out.uv = in.uv * object.tiles_per_world;
    out.surface_uv = in.uv / object.world_per_uv;
    out.layer = layer;
    out.slice = shell_slice(layer);
    out.height = layer_height(layer);
    out.fade = shell_fade(out.normal, position);
    return out;
}

// The fin vertices as 8 floats each (position, normal, uv): fin `f` is vertices
// `f * n .. (f + 1) * n`, its first two the roots of its edge's ends.
@group(1) @binding(1) var<storage, read> fin_vertex_floats: array<f32>;

// Lengyel's fade of the fin that vertex `index` belongs to, decided once for the fin (at the
// middle of its edge, with its plane normal `normal`, world space), so all its vertices agree.
fn separated_fin_fade(index: u32, normal: vec3<f32>) -> f32 {
    let per_fin = (arrayLength(&fin_vertex_floats) / 8u) / max(object.edge_count, 1u);
    let first = (index / max(per_fin, 1u)) * per_fin * 8u;
    let root_a = vec3<f32>(fin_vertex_floats[first], fin_vertex_floats[first + 1u], fin_vertex_floats[first + 2u]);
    let root_b = vec3<f32>(fin_vertex_floats[first + 8u], fin_vertex_floats[first + 9u], fin_vertex_floats[first + 10u]);
    let middle = world_from_model_point(0.5 * (root_a + root_b));
    let to_camera = safe_normalize(view.camera_position - middle, normal);
    return smoothstep(1.0 - object.fin_fade_cos, 1.0, abs(dot(normal, to_camera)));
}

// What a separated fin fragment reads of `Varyings`.
struct SeparatedFinVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) height: f32,
    @location(4) fade: f32,
    @location(5) surface_uv: vec2<f32>,
}

// The same and the groom's terms (a fin vertex's end of the edge), for a groomed fur.
struct GroomedSeparatedFinVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) uv: vec2<f32>,
    @location(3) height: f32,
    @location(4) fade: f32,
    @location(5) surface_uv: vec2<f32>,
    @location(6) tint_density: vec4<f32>,
    @location(7) clump: f32,
}

@vertex
fn vs_separated_fin(in: VertexIn, @builtin(vertex_index) index: u32) -> SeparatedFinVaryings {
    let v = separated_fin(in, index);
    return SeparatedFinVaryings(v.clip_position, v.world_position, v.normal, v.uv, v.height, v.fade, v.surface_uv);
}

@vertex
fn vs_separated_fin_groomed(in: VertexIn, @builtin(vertex_index) index: u32) -> GroomedSeparatedFinVaryings {
    let v = separated_fin(in, index);
    var out = GroomedSeparatedFinVaryings(v.clip_position, v.world_position, v.normal, v.uv, v.height, v.fade, v.surface_uv, vec4<f32>(1.0), 0.0);
    if groom_on() && v.fade > 0.0 {
        let per_fin = max((arrayLength(&fin_vertex_floats) / 8u) / max(object.edge_count, 1u), 1u);
        // Side b of the edge sits at u > 0.
        let side = select(0u, 1u, in.uv.x > 0.0);
        let groom = separated_groom(fin_ends[2u * (index / per_fin) + side]);
        out.tint_density = vec4<f32>(groom.tint, groom.density);
        out.clump = groom.clump;
    }
    return out;
}

fn separated_fin(in: VertexIn, index: u32) -> Varyings {
    var out: Varyings;
    out.normal = world_from_model_normal(in.normal);
    // Lengyel's fade: a fin shows where it faces the viewer, i.e. stands on a silhouette edge.
    // Culled as the unified fins are: a fin that does not show lands outside the clip volume,
    // every vertex of it, so it costs no rasterisation (`vs_fin` in `unified.wgsl`).
    out.fade = separated_fin_fade(index, out.normal);
    if out.fade <= 0.0 {
        out.clip_position = vec4<f32>(2.0, 2.0, 2.0, 1.0);
        return out;
    }
    let position = world_from_model_point(in.position);
    out.clip_position = view.clip_from_world * vec4<f32>(position, 1.0);
    out.world_position = position;
    out.tangent = out.normal;
    out.tile_position = vec3<f32>(0.0);
    out.tile_normal = vec3<f32>(0.0);
    out.uv = vec2<f32>(in.uv.x * object.tiles_per_world, in.uv.y);
    out.layer = 0u;
    out.slice = 0;
    // Separated fins keep no mesh uv: surface colour mode tints them with the texture's corner.
    out.surface_uv = vec2<f32>(0.0);
    out.height = in.uv.y;
    return out;
}

// Fins store no strand direction: it is the direction of growing height across the fin, from the
// screen-space derivatives of position and uv.
fn separated_fin_colour(world_position: vec3<f32>, normal: vec3<f32>, uv: vec2<f32>, height: f32, albedo: vec3<f32>, alpha: f32) -> vec4<f32> {
    let dp_dx = dpdx(world_position);
    let dp_dy = dpdy(world_position);
    let duv_dx = dpdx(uv);
    let duv_dy = dpdy(uv);
    let determinant = duv_dx.x * duv_dy.y - duv_dy.x * duv_dx.y;
    let up = (duv_dx.x * dp_dy - duv_dy.x * dp_dx) * sign(determinant);
    let tangent = safe_normalize(up, normalize(normal));
    let colour = hair_lighting(albedo, tangent, tangent, world_position, height);
    return fur_output(colour, alpha);
}

@fragment
fn fs_separated_fin(in: SeparatedFinVaryings) -> @location(0) vec4<f32> {
    let texel = textureSample(fin_texture, fin_sampler, vec2<f32>(in.uv.x, 1.0 - in.uv.y));
    let albedo = texel.rgb * surface_tint(in.surface_uv);
    return separated_fin_colour(in.world_position, in.normal, in.uv, in.height, albedo, texel.a * in.fade);
}

// The unified fins' groom shading (`fs_fin_groomed`).
@fragment
fn fs_separated_fin_groomed(in: GroomedSeparatedFinVaryings) -> @location(0) vec4<f32> {
    let fin_uv = vec2<f32>(in.uv.x, 1.0 - in.uv.y);
    let cells = clump_cells_per_tile();
    let along = clump_uv(vec2<f32>(fin_uv.x, 0.5 / cells), cells, groom_clump_amount(in.clump, in.height)).x;
    let texel = textureSampleGrad(fin_texture, fin_sampler, vec2<f32>(along, fin_uv.y), dpdx(fin_uv), dpdy(fin_uv));
    let albedo = texel.rgb * surface_tint(in.surface_uv) * in.tint_density.rgb;
    let alpha = texel.a * in.fade * clamp(in.tint_density.a, 0.0, 1.0);
    return separated_fin_colour(in.world_position, in.normal, in.uv, in.height, albedo, alpha);
}
