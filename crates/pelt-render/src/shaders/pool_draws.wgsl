// A pool's draws. Its shadow casters, every copy in one draw a pass (`FurRenderer::draw_herd`): the
// instance names the copy's slot (the opacity pass: its slot and its shell, OPACITY_SHELLS a
// copy), whose object the vertex loads before the unified structure's code runs as for a lone
// fur. Appended to the pooled shading (`object_pool.wgsl`), `unified.wgsl` and `shadows.wgsl`.

// The opaque pass: every copy's skin (instance = slot).
@vertex
fn vs_pool_skin_wedges(@builtin(vertex_index) wedge: u32, @builtin(instance_index) member: u32) -> Varyings {
    object = objects[member].object;
    return surface_varyings(wedge_vertex(wedge), wedge, 0u);
}

@vertex
fn vs_pool_skin_indexed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) member: u32) -> Varyings {
    object = objects[member].object;
    return surface_varyings(vertex, 0u, 0u);
}

// The fur depth pass: each copy's outermost shell (instance = slot; `draw_herd` pools only
// copies whose coat shows).
@vertex
fn vs_pool_fur_depth_wedges(@builtin(vertex_index) wedge: u32, @builtin(instance_index) member: u32) -> ShellUvVaryings {
    object = objects[member].object;
    return shell_wedge(wedge, object.lod_shells - 1u);
}

@vertex
fn vs_pool_fur_depth_indexed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) member: u32) -> ShellTileVaryings {
    object = objects[member].object;
    return shell_vertex(vertex, object.lod_shells - 1u);
}

// The opacity pass: instance `OPACITY_SHELLS * slot + k` draws the copy's opacity shell k (as
// `vs_opacity_shell_*`; `draw_herd` pools only copies that draw all four).
fn pool_opacity_shell(instance: u32) -> u32 {
    object = objects[instance / OPACITY_SHELLS].object;
    return opacity_shell(instance % OPACITY_SHELLS);
}

// The opacity shells' varyings with the copy's slot, whose object the fragment loads.
struct PoolShellTileVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) fade_blend_layer: vec3<f32>,
    @location(2) @interpolate(perspective, centroid) tile_position: vec3<f32>,
    @location(3) @interpolate(perspective, centroid) tile_normal: vec3<f32>,
    @location(5) @interpolate(flat) member: u32,
}

struct PoolShellUvVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) fade_blend_layer: vec3<f32>,
    @location(2) @interpolate(perspective, centroid) uvs: vec4<f32>,
    @location(5) @interpolate(flat) member: u32,
}

struct PoolGroomedShellTileVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) fade_blend_layer: vec4<f32>,
    @location(2) @interpolate(perspective, centroid) tile_position: vec3<f32>,
    @location(3) @interpolate(perspective, centroid) tile_normal: vec3<f32>,
    @location(4) @interpolate(perspective, centroid) tint_density: vec4<f32>,
    @location(5) @interpolate(perspective, centroid) column_wetness: vec4<f32>,
    @location(6) @interpolate(perspective, centroid) world_position: vec3<f32>,
    @location(7) @interpolate(perspective, centroid) key: vec4<f32>,
    @location(8) @interpolate(flat) member: u32,
}

struct PoolGroomedShellUvVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) fade_blend_layer: vec4<f32>,
    @location(2) @interpolate(perspective, centroid) uvs: vec4<f32>,
    @location(3) @interpolate(perspective, centroid) tint_density: vec4<f32>,
    @location(4) @interpolate(perspective, centroid) column_wetness: vec4<f32>,
    @location(5) @interpolate(perspective, centroid) world_position: vec3<f32>,
    @location(6) @interpolate(perspective, centroid) key: vec4<f32>,
    @location(8) @interpolate(flat) member: u32,
}

@vertex
fn vs_pool_opacity_shell_wedges(@builtin(vertex_index) wedge: u32, @builtin(instance_index) instance: u32) -> PoolShellUvVaryings {
    var out: PoolShellUvVaryings;
    out.member = instance / OPACITY_SHELLS;
    let shell = pool_opacity_shell(instance);
    let v = shell_wedge(wedge, shell);
    out.clip_position = v.clip_position;
    out.lighting = v.lighting;
    out.fade_blend_layer = v.fade_blend_layer;
    out.uvs = v.uvs;
    return out;
}

@vertex
fn vs_pool_opacity_shell_indexed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> PoolShellTileVaryings {
    var out: PoolShellTileVaryings;
    out.member = instance / OPACITY_SHELLS;
    let shell = pool_opacity_shell(instance);
    let v = shell_vertex(vertex, shell);
    out.clip_position = v.clip_position;
    out.lighting = v.lighting;
    out.fade_blend_layer = v.fade_blend_layer;
    out.tile_position = v.tile_position;
    out.tile_normal = v.tile_normal;
    return out;
}

@vertex
fn vs_pool_opacity_shell_wedges_groomed(@builtin(vertex_index) wedge: u32, @builtin(instance_index) instance: u32) -> PoolGroomedShellUvVaryings {
    var out: PoolGroomedShellUvVaryings;
    out.member = instance / OPACITY_SHELLS;
    let shell = pool_opacity_shell(instance);
    let v = groomed_shell_wedge(wedge, shell);
    out.clip_position = v.clip_position;
    out.lighting = v.lighting;
    out.fade_blend_layer = v.fade_blend_layer;
    out.uvs = v.uvs;
    out.tint_density = v.tint_density;
    return out;
}

@vertex
fn vs_pool_opacity_shell_indexed_groomed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> PoolGroomedShellTileVaryings {
    var out: PoolGroomedShellTileVaryings;
    out.member = instance / OPACITY_SHELLS;
    let shell = pool_opacity_shell(instance);
    let v = groomed_shell_vertex(vertex, shell);
    out.clip_position = v.clip_position;
    out.lighting = v.lighting;
    out.fade_blend_layer = v.fade_blend_layer;
    out.tile_position = v.tile_position;
    out.tile_normal = v.tile_normal;
    out.tint_density = v.tint_density;
    return out;
}

@fragment
fn fs_pool_opacity_uvs(in: PoolShellUvVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    return opacity_uvs(ShellUvVaryings(in.clip_position, in.lighting, in.fade_blend_layer, in.uvs));
}

@fragment
fn fs_pool_opacity_tiles(in: PoolShellTileVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    return opacity_tiles(ShellTileVaryings(in.clip_position, in.lighting, in.fade_blend_layer, in.tile_position, in.tile_normal));
}

@fragment
fn fs_pool_opacity_uvs_groomed(in: PoolGroomedShellUvVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    let shell = GroomedShellUvVaryings(in.clip_position, in.lighting, in.fade_blend_layer, in.uvs, in.tint_density, in.column_wetness, in.world_position, in.key);
    return opacity_uvs_groomed(shell);
}

@fragment
fn fs_pool_opacity_tiles_groomed(in: PoolGroomedShellTileVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    let shell = GroomedShellTileVaryings(in.clip_position, in.lighting, in.fade_blend_layer, in.tile_position, in.tile_normal, in.tint_density, in.column_wetness, in.world_position, in.key);
    return opacity_tiles_groomed(shell);
}

// The camera's view (`HerdDraws`): the copies of one level, which share no pixel, their skins in
// one draw and their shells in another. Each instance reads its entry from the plan's instance
// buffer: the copy's slot and, for the shells, its shell. The fragment loads the copy's object
// from the slot, handed on flat.

// `Varyings` with the copy's slot.
struct PoolVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) tangent: vec3<f32>,
    @location(3) tile_position: vec3<f32>,
    @location(4) uv: vec2<f32>,
    @location(5) @interpolate(flat) layer: u32,
    @location(6) height: f32,
    @location(7) fade: f32,
    @location(8) @interpolate(flat) slice: i32,
    @location(9) surface_uv: vec2<f32>,
    @location(10) tile_normal: vec3<f32>,
    @location(11) @interpolate(flat) light_count: u32,
    @location(12) @interpolate(flat) member: u32,
}

fn pooled_varyings(v: Varyings, member: u32) -> PoolVaryings {
    return PoolVaryings(v.clip_position, v.world_position, v.normal, v.tangent, v.tile_position, v.uv, v.layer, v.height, v.fade, v.slice, v.surface_uv, v.tile_normal, v.light_count, member);
}

@vertex
fn vs_pool_camera_skin_wedges(@builtin(vertex_index) wedge: u32, @location(0) entry: vec2<u32>) -> PoolVaryings {
    object = objects[entry.x].object;
    return pooled_varyings(surface_varyings(wedge_vertex(wedge), wedge, 0u), entry.x);
}

@vertex
fn vs_pool_camera_skin_indexed(@builtin(vertex_index) vertex: u32, @location(0) entry: vec2<u32>) -> PoolVaryings {
    object = objects[entry.x].object;
    return pooled_varyings(surface_varyings(vertex, 0u, 0u), entry.x);
}

@fragment
fn fs_pool_skin(in: PoolVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    let v = Varyings(in.clip_position, in.world_position, in.normal, in.tangent, in.tile_position, in.uv, in.layer, in.height, in.fade, in.slice, in.surface_uv, in.tile_normal, in.light_count);
    return skin_colour(v);
}

@vertex
fn vs_pool_shell_wedges(@builtin(vertex_index) wedge: u32, @location(0) entry: vec2<u32>) -> PoolShellUvVaryings {
    object = objects[entry.x].object;
    let v = shell_wedge(wedge, entry.y);
    return PoolShellUvVaryings(v.clip_position, v.lighting, v.fade_blend_layer, v.uvs, entry.x);
}

@vertex
fn vs_pool_shell_indexed(@builtin(vertex_index) vertex: u32, @location(0) entry: vec2<u32>) -> PoolShellTileVaryings {
    object = objects[entry.x].object;
    let v = shell_vertex(vertex, entry.y);
    return PoolShellTileVaryings(v.clip_position, v.lighting, v.fade_blend_layer, v.tile_position, v.tile_normal, entry.x);
}

@vertex
fn vs_pool_shell_wedges_groomed(@builtin(vertex_index) wedge: u32, @location(0) entry: vec2<u32>) -> PoolGroomedShellUvVaryings {
    object = objects[entry.x].object;
    let v = groomed_shell_wedge(wedge, entry.y);
    return PoolGroomedShellUvVaryings(v.clip_position, v.lighting, v.fade_blend_layer, v.uvs, v.tint_density, v.column_wetness, v.world_position, v.key, entry.x);
}

@vertex
fn vs_pool_shell_indexed_groomed(@builtin(vertex_index) vertex: u32, @location(0) entry: vec2<u32>) -> PoolGroomedShellTileVaryings {
    object = objects[entry.x].object;
    let v = groomed_shell_vertex(vertex, entry.y);
    return PoolGroomedShellTileVaryings(v.clip_position, v.lighting, v.fade_blend_layer, v.tile_position, v.tile_normal, v.tint_density, v.column_wetness, v.world_position, v.key, entry.x);
}

@fragment
fn fs_pool_shell_uvs(in: PoolShellUvVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    return shell_uvs_colour(ShellUvVaryings(in.clip_position, in.lighting, in.fade_blend_layer, in.uvs));
}

@fragment
fn fs_pool_shell_tiles(in: PoolShellTileVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    return shell_tiles_colour(ShellTileVaryings(in.clip_position, in.lighting, in.fade_blend_layer, in.tile_position, in.tile_normal));
}

@fragment
fn fs_pool_shell_uvs_groomed(in: PoolGroomedShellUvVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    let shell = GroomedShellUvVaryings(in.clip_position, in.lighting, in.fade_blend_layer, in.uvs, in.tint_density, in.column_wetness, in.world_position, in.key);
    return shell_uvs_groomed_colour(shell);
}

@fragment
fn fs_pool_shell_tiles_groomed(in: PoolGroomedShellTileVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    let shell = GroomedShellTileVaryings(in.clip_position, in.lighting, in.fade_blend_layer, in.tile_position, in.tile_normal, in.tint_density, in.column_wetness, in.world_position, in.key);
    return shell_tiles_groomed_colour(shell);
}

// A level's copies whose shells the view angle thins, gathered (`HerdDraws`): one indirect draw a
// shell a copy, all in one call, each with the copy's slot as its instance and base vertex
// `shell * N` (`cs_view_lod_draws`), so `vertex_index` carries the shell and the wedge (N = W) or
// base vertex (N = V), as `vs_shell_*_listed` read it.
@vertex
fn vs_pool_shell_wedges_listed(@builtin(vertex_index) index: u32, @builtin(instance_index) member: u32) -> PoolShellUvVaryings {
    object = objects[member].object;
    let v = shell_wedge(index % object.wedge_count, index / object.wedge_count);
    return PoolShellUvVaryings(v.clip_position, v.lighting, v.fade_blend_layer, v.uvs, member);
}

@vertex
fn vs_pool_shell_indexed_listed(@builtin(vertex_index) index: u32, @builtin(instance_index) member: u32) -> PoolShellTileVaryings {
    object = objects[member].object;
    let v = shell_vertex(index % object.vertex_count, index / object.vertex_count);
    return PoolShellTileVaryings(v.clip_position, v.lighting, v.fade_blend_layer, v.tile_position, v.tile_normal, member);
}

@vertex
fn vs_pool_shell_wedges_listed_groomed(@builtin(vertex_index) index: u32, @builtin(instance_index) member: u32) -> PoolGroomedShellUvVaryings {
    object = objects[member].object;
    let v = groomed_shell_wedge(index % object.wedge_count, index / object.wedge_count);
    return PoolGroomedShellUvVaryings(v.clip_position, v.lighting, v.fade_blend_layer, v.uvs, v.tint_density, v.column_wetness, v.world_position, v.key, member);
}

@vertex
fn vs_pool_shell_indexed_listed_groomed(@builtin(vertex_index) index: u32, @builtin(instance_index) member: u32) -> PoolGroomedShellTileVaryings {
    object = objects[member].object;
    let v = groomed_shell_vertex(index % object.vertex_count, index / object.vertex_count);
    return PoolGroomedShellTileVaryings(v.clip_position, v.lighting, v.fade_blend_layer, v.tile_position, v.tile_normal, v.tint_density, v.column_wetness, v.world_position, v.key, member);
}

// A level's fins, gathered: one indirect draw a copy, all in one call, over the whole instance
// buffer from the copy's first instance (`cs_silhouette`), so the instance names the copy.
struct PoolFinVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting_fade: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) uvs: vec4<f32>,
    @location(5) @interpolate(flat) member: u32,
}

struct PoolGroomedFinVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting_fade: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) uvs: vec4<f32>,
    @location(2) @interpolate(perspective, centroid) tint_density: vec4<f32>,
    @location(3) @interpolate(perspective, centroid) clump: f32,
    @location(5) @interpolate(flat) member: u32,
}

// The copy whose fins instance `instance` is: every copy holds `fin_edge_count` of them.
fn pool_fin_member(instance: u32) -> u32 {
    return instance / objects[0].object.fin_edge_count;
}

@vertex
fn vs_pool_fin_silhouette(@builtin(vertex_index) index: u32, @builtin(instance_index) instance: u32, @location(0) fin: vec2<u32>) -> PoolFinVaryings {
    let member = pool_fin_member(instance);
    object = objects[member].object;
    let v = fin_varyings(index, fin.x, bitcast<f32>(fin.y));
    return PoolFinVaryings(v.clip_position, v.lighting_fade, v.uvs, member);
}

@vertex
fn vs_pool_fin_silhouette_groomed(@builtin(vertex_index) index: u32, @builtin(instance_index) instance: u32, @location(0) fin: vec2<u32>) -> PoolGroomedFinVaryings {
    let member = pool_fin_member(instance);
    object = objects[member].object;
    let v = groomed_fin_varyings(index, fin.x, bitcast<f32>(fin.y));
    return PoolGroomedFinVaryings(v.clip_position, v.lighting_fade, v.uvs, v.tint_density, v.clump, member);
}

@fragment
fn fs_pool_fin(in: PoolFinVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    return fin_lean_colour(FinVaryings(in.clip_position, in.lighting_fade, in.uvs));
}

@fragment
fn fs_pool_fin_groomed(in: PoolGroomedFinVaryings) -> @location(0) vec4<f32> {
    object = objects[in.member].object;
    return fin_groomed_colour(GroomedFinVaryings(in.clip_position, in.lighting_fade, in.uvs, in.tint_density, in.clump));
}
