// Every shadowing light's shadows (group 3, `ShadowMap`): per light view an opaque shadow map
// of the skin, plain meshes, colliders and ground, sampled with a few filtered taps, and a deep
// opacity map of the fur (Yuksel & Keyser 2008): the depth of the fur's first surface seen from
// the light (z0) and four cumulative opacity layers beyond it, from which a point's transmittance
// follows. A directional or spot light has one view, a point light six (a cube), each a layer of
// the maps' arrays. Appended to `shading.wgsl`; the shadow views' own fragments are here too.

// One view from a light: a layer of each map.
struct ShadowView {
    light_clip_from_world: mat4x4<f32>,
    // The light's position (w = 1), or the unit vector toward it (w = 0).
    light: vec4<f32>,
    // World units a shadow texel spans (the normal offset) and the depth bias (world units).
    texel_world: f32,
    bias_world: f32,
    // 1 for a perspective (spot, point) view, 0 for an orthographic (directional) one.
    perspective: f32,
    // The view's near and far planes (linear depth along the light, world units).
    near: f32,
    far: f32,
    // 1 / the map's size in texels.
    texel: f32,
    padding_0: f32,
    padding_1: f32,
}

// The most light views a `ShadowMap` holds (`MAX_SHADOW_VIEWS`).
const SHADOW_VIEWS = 12u;

struct Shadow {
    // How fast light dies in the fur: transmittance exp(-extinction * opacity).
    extinction: f32,
    // The view an opacity pass draws into (its caster group's own copy; unused when receiving).
    pass_view: u32,
    // The maps' layers (light views).
    layers: u32,
    padding_1: u32,
    // Where each opacity layer ends beyond z0 (world units); the last one's end is where the
    // interpolation stops (fur deeper still counts in full).
    layer_ends: vec4<f32>,
    // Per light of the view (`Lights`, or the key light of a view without them): its first
    // light view (x) and how many it has (y: 0 none, 1, or 6 for a point light's cube).
    light_views: array<vec4<u32>, 8>,
    views: array<ShadowView, SHADOW_VIEWS>,
}

@group(3) @binding(0) var<uniform> shadow: Shadow;
@group(3) @binding(1) var shadow_depth: texture_depth_2d_array;
@group(3) @binding(2) var shadow_compare: sampler_comparison;
@group(3) @binding(3) var fur_depth: texture_2d_array<f32>;
@group(3) @binding(4) var fur_opacity: texture_2d_array<f32>;
@group(3) @binding(5) var shadow_linear: sampler;

// Set per pipeline: only views with a shadow map compile the lookups (a software rasteriser runs
// every branch, taken or not).
override SHADOWS: bool = false;
// Set per pipeline with SHADOWS: the maps hold one light view, light 0's (Pelt's studio), so the
// lookups read view 0 at fixed offsets. A software rasteriser gathers a uniform read at a
// computed index lane by lane, which cost the default frame a tenth of its time.
override SHADOW_KEY_ONLY: bool = false;

// Light-space depth in world units from a depth-buffer value of view `v`. A `select`, not an
// `if`: lavapipe (Mesa 22.3) inlines uniforms that alone decide a branch and compiles the shader
// anew each time their buffer is bound, which made every fur of a herd cost a shader compile a
// draw.
fn shadow_linear_depth(v: u32, z: f32) -> f32 {
    let near = shadow.views[v].near;
    let far = shadow.views[v].far;
    let perspective = near * far / (far - z * (far - near));
    return select(near + z * (far - near), perspective, shadow.views[v].perspective > 0.5);
}

// The fur's opacity at `beyond` world units past its first surface: the four cumulative layers
// interpolated linearly, 0 at z0.
fn deep_opacity(layers: vec4<f32>, beyond: f32) -> f32 {
    let e = shadow.layer_ends;
    let o = max(layers, vec4<f32>(0.0));
    var opacity = o.x * clamp(beyond / e.x, 0.0, 1.0);
    opacity += (o.y - o.x) * clamp((beyond - e.x) / (e.y - e.x), 0.0, 1.0);
    opacity += (o.z - o.y) * clamp((beyond - e.y) / (e.z - e.y), 0.0, 1.0);
    opacity += (o.w - o.z) * clamp((beyond - e.z) / (e.w - e.z), 0.0, 1.0);
    return max(opacity, 0.0);
}

// The light view of light `light_index` that sees `world_position`, or SHADOW_VIEWS where the
// light has none: its one view, or the cube face of a point light that the point lies toward
// (+x, -x, +y, -y, +z, -z). Selects, no branches.
fn shadow_view_index(light_index: u32, world_position: vec3<f32>) -> u32 {
    if SHADOW_KEY_ONLY {
        return select(SHADOW_VIEWS, 0u, light_index == 0u);
    }
    let views = shadow.light_views[min(light_index, 7u)];
    let d = world_position - shadow.views[min(views.x, SHADOW_VIEWS - 1u)].light.xyz;
    let a = abs(d);
    let z_face = select(4u, 5u, d.z < 0.0);
    let y_face = select(2u, 3u, d.y < 0.0);
    let x_face = select(0u, 1u, d.x < 0.0);
    let face = select(select(z_face, y_face, a.y >= a.z), x_face, a.x >= a.y && a.x >= a.z);
    let index = views.x + select(0u, face, views.y == 6u);
    return select(SHADOW_VIEWS, index, views.y > 0u && light_index < 8u && index < SHADOW_VIEWS);
}

// The layer of view `index` to read: within the maps whatever `index` is, as a software
// rasteriser fetches for the lanes a branch has left too, and an out-of-range layer crashed
// lavapipe (Mesa 22.3).
fn shadow_layer(index: u32) -> i32 {
    return select(i32(min(index, max(shadow.layers, 1u) - 1u)), 0, SHADOW_KEY_ONLY);
}

// How much of light `light_index` reaches `world_position` (surface normal `world_normal`):
// 1 = unshadowed. The opaque map's filtered taps times the fur's transmittance. Without early
// returns: a software rasteriser runs every branch anyway, and lavapipe (Mesa 22.3) crashed on
// this function's returns once it read the light views' arrays.
fn light_visibility(light_index: u32, world_position: vec3<f32>, world_normal: vec3<f32>) -> f32 {
    if !SHADOWS {
        return 1.0;
    }
    let index = shadow_view_index(light_index, world_position);
    let v = select(min(index, SHADOW_VIEWS - 1u), 0u, SHADOW_KEY_ONLY);
    let light = shadow.views[v].light;
    let to_light = select(light.xyz, normalize(light.xyz - world_position), light.w > 0.5);
    // Slope-scaled: surfaces turning from the light move further off themselves.
    let n_dot_l = clamp(dot(world_normal, to_light), -1.0, 1.0);
    let slope = sqrt(max(1.0 - n_dot_l * n_dot_l, 0.0));
    let texel_world = shadow.views[v].texel_world;
    let p = world_position + world_normal * (texel_world * (0.5 + 1.5 * slope)) + to_light * shadow.views[v].bias_world;
    let clip = shadow.views[v].light_clip_from_world * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / max(clip.w, 1e-12);
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let seen = index < SHADOW_VIEWS && clip.w > 0.0 && all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0));
    // Receivers past the far plane (the ground below the casters) compare as at it.
    let z = clamp(ndc.z, 0.0, 1.0);
    let t = 0.75 * shadow.views[v].texel;
    let layer = shadow_layer(index);
    var lit = textureSampleCompareLevel(shadow_depth, shadow_compare, uv + vec2<f32>(-t, -t), layer, z);
    lit += textureSampleCompareLevel(shadow_depth, shadow_compare, uv + vec2<f32>(t, -t), layer, z);
    lit += textureSampleCompareLevel(shadow_depth, shadow_compare, uv + vec2<f32>(-t, t), layer, z);
    lit += textureSampleCompareLevel(shadow_depth, shadow_compare, uv + vec2<f32>(t, t), layer, z);
    let size = vec2<f32>(textureDimensions(fur_depth));
    let texel = clamp(vec2<i32>(uv * size), vec2<i32>(0), vec2<i32>(size) - 1);
    let z0 = textureLoad(fur_depth, texel, layer, 0).x;
    let beyond = shadow_linear_depth(v, z) - shadow_linear_depth(v, z0);
    let layers = textureSampleLevel(fur_opacity, shadow_linear, uv, layer, 0.0);
    return select(1.0, 0.25 * lit * exp(-shadow.extinction * deep_opacity(layers, beyond)), seen);
}

// The same for a strand's vertex (shells and fins): one filtered tap of the opaque map, as a
// strand vertex's light is interpolated over its triangle anyway (four taps cost a software
// rasteriser about 4 ms of the bunny's 256x256 frame). Its own copy of the projection, not a
// helper shared with `light_visibility`: lavapipe (Mesa 22.3) crashed drawing with that helper.
fn strand_visibility(light_index: u32, world_position: vec3<f32>, world_normal: vec3<f32>) -> f32 {
    if !SHADOWS {
        return 1.0;
    }
    let index = shadow_view_index(light_index, world_position);
    let v = select(min(index, SHADOW_VIEWS - 1u), 0u, SHADOW_KEY_ONLY);
    let light = shadow.views[v].light;
    let to_light = select(light.xyz, normalize(light.xyz - world_position), light.w > 0.5);
    // Slope-scaled: surfaces turning from the light move further off themselves.
    let n_dot_l = clamp(dot(world_normal, to_light), -1.0, 1.0);
    let slope = sqrt(max(1.0 - n_dot_l * n_dot_l, 0.0));
    let texel_world = shadow.views[v].texel_world;
    let p = world_position + world_normal * (texel_world * (0.5 + 1.5 * slope)) + to_light * shadow.views[v].bias_world;
    let clip = shadow.views[v].light_clip_from_world * vec4<f32>(p, 1.0);
    let ndc = clip.xyz / max(clip.w, 1e-12);
    let uv = vec2<f32>(ndc.x * 0.5 + 0.5, 0.5 - ndc.y * 0.5);
    let seen = index < SHADOW_VIEWS && clip.w > 0.0 && all(uv >= vec2<f32>(0.0)) && all(uv <= vec2<f32>(1.0));
    // Receivers past the far plane (the ground below the casters) compare as at it.
    let z = clamp(ndc.z, 0.0, 1.0);
    let layer = shadow_layer(index);
    let lit = textureSampleCompareLevel(shadow_depth, shadow_compare, uv, layer, z);
    let size = vec2<f32>(textureDimensions(fur_depth));
    let texel = clamp(vec2<i32>(uv * size), vec2<i32>(0), vec2<i32>(size) - 1);
    let z0 = textureLoad(fur_depth, texel, layer, 0).x;
    let beyond = shadow_linear_depth(v, z) - shadow_linear_depth(v, z0);
    let layers = textureSampleLevel(fur_opacity, shadow_linear, uv, layer, 0.0);
    return select(1.0, lit * exp(-shadow.extinction * deep_opacity(layers, beyond)), seen);
}

// The deep opacity pass draws at most OPACITY_SHELLS shells, evenly spaced, each the middle of
// a run of `opacity_stride()` shells and adding the opacity of the whole run (opacity adds up:
// the transmittance is exp(-extinction * the sum)). The map holds four opacity layers, so four shells fill them: a shadow needs the
// coat's density, not each shell.
const OPACITY_SHELLS = 4u;

fn opacity_stride() -> u32 {
    return (object.lod_shells + OPACITY_SHELLS - 1u) / OPACITY_SHELLS;
}

// A shadow view's opacity fragment of a shell that stands for `opacity_stride()` shells
// (`vs_opacity_shell_*`): their alpha, added to every layer that ends at or past the fragment's depth beyond z0 (the
// last layer takes every fragment), so each layer holds the opacity in front of its end.
fn opacity_layers(position: vec4<f32>, shell_alpha: f32) -> vec4<f32> {
    let alpha = clamp(shell_alpha, 0.0, 1.0) * f32(opacity_stride()) * object.coat_fade;
    let v = min(shadow.pass_view, SHADOW_VIEWS - 1u);
    let z0 = textureLoad(fur_depth, vec2<i32>(position.xy), shadow_layer(shadow.pass_view), 0).x;
    let beyond = shadow_linear_depth(v, position.z) - shadow_linear_depth(v, z0);
    let e = shadow.layer_ends;
    let inside = vec4<f32>(select(0.0, 1.0, beyond <= e.x), select(0.0, 1.0, beyond <= e.y), select(0.0, 1.0, beyond <= e.z), 1.0);
    return inside * alpha;
}

// The opacity of each shell kind's fragment: the entry points below, and a pool's
// (`pool_draws.wgsl`), which load their copy's object first.
fn opacity_tiles(in: ShellTileVaryings) -> vec4<f32> {
    let layer = varying_layer(in.fade_blend_layer.z);
    let texel = tile_texel(in.tile_position, in.tile_normal, layer);
    return opacity_layers(in.clip_position, lod_alpha(texel.a * in.fade_blend_layer.x, layer, in.fade_blend_layer.y));
}

fn opacity_uvs(in: ShellUvVaryings) -> vec4<f32> {
    let layer = varying_layer(in.fade_blend_layer.z);
    let texel = sample_shell(in.uvs.xy, shell_slice(layer));
    return opacity_layers(in.clip_position, lod_alpha(texel.a * in.fade_blend_layer.x, layer, in.fade_blend_layer.y));
}

fn opacity_tiles_groomed(in: GroomedShellTileVaryings) -> vec4<f32> {
    let layer = varying_layer(in.fade_blend_layer.z);
    let groom = shell_groom(in.fade_blend_layer, in.tint_density);
    let texel = coat_shell_texel(tile_uv(in.tile_position, in.tile_normal), layer, groom);
    return opacity_layers(in.clip_position, lod_alpha(texel.a * in.fade_blend_layer.x, layer, in.fade_blend_layer.y));
}

fn opacity_uvs_groomed(in: GroomedShellUvVaryings) -> vec4<f32> {
    let layer = varying_layer(in.fade_blend_layer.z);
    let groom = shell_groom(in.fade_blend_layer, in.tint_density);
    let texel = coat_shell_texel(in.uvs.xy, layer, groom);
    return opacity_layers(in.clip_position, lod_alpha(texel.a * in.fade_blend_layer.x, layer, in.fade_blend_layer.y));
}

@fragment
fn fs_opacity_tiles(in: ShellTileVaryings) -> @location(0) vec4<f32> {
    return opacity_tiles(in);
}

@fragment
fn fs_opacity_uvs(in: ShellUvVaryings) -> @location(0) vec4<f32> {
    return opacity_uvs(in);
}

@fragment
fn fs_opacity_tiles_groomed(in: GroomedShellTileVaryings) -> @location(0) vec4<f32> {
    return opacity_tiles_groomed(in);
}

@fragment
fn fs_opacity_uvs_groomed(in: GroomedShellUvVaryings) -> @location(0) vec4<f32> {
    return opacity_uvs_groomed(in);
}
