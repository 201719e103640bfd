// Depth-only and motion-vector draws of a fur for a host's prepass and shadow views. Appended to
// `shading.wgsl`, `wet.wgsl` and `unified.wgsl`: the same shared vertex array, shells and fins,
// with the skin opaque and shells and fins alpha-tested against their textures.
//
// Group 0 is the prepass or shadow view (its `clip_from_world` places the depth, its camera
// position fades the shells and fins as seen from it), group 3 this fur in that view.

struct Motion {
    // The view's projection without the sub-pixel jitter (TAA), this frame and the last: motion
    // vectors compare where a point is, not where the jitter drew it.
    unjittered_clip_from_world: mat4x4<f32>,
    // Last frame's unjittered projection times last frame's model transform.
    previous_clip_from_model: mat4x4<f32>,
    // 1: clamp depth to the near plane instead of clipping (directional shadow cascades, whose
    // casters may stand in front of the cascade).
    clamp_depth: u32,
    padding_0: u32,
    padding_1: u32,
    padding_2: u32,
}

@group(3) @binding(0) var<uniform> motion: Motion;
// Last frame's drawn positions, packed xyz like `current_positions` (the current ones for a view
// without motion vectors).
@group(3) @binding(1) var<storage, read> motion_previous_positions: array<f32>;

// A shell or fin fragment is drawn where its strand covers at least this much.
const PREPASS_ALPHA_CUTOFF: f32 = 0.5;

fn previous_model_vertex(layer: u32, vertex: u32) -> vec3<f32> {
    let k = 3u * (layer * object.vertex_count + vertex);
    return vec3<f32>(motion_previous_positions[k], motion_previous_positions[k + 1u], motion_previous_positions[k + 2u]);
}

fn prepass_clip(clip: vec4<f32>) -> vec4<f32> {
    var out = clip;
    if motion.clamp_depth != 0u {
        out.z = min(out.z, out.w);
    }
    return out;
}

// The screen-space motion from last frame to this one, in the host's (Bevy's) convention: uv
// offset, y down.
fn motion_vector(current: vec4<f32>, previous: vec4<f32>) -> vec2<f32> {
    return (current.xy / current.w - previous.xy / previous.w) * vec2<f32>(0.5, -0.5);
}

struct DepthSkin {
    @builtin(position) clip_position: vec4<f32>,
}

struct MotionSkin {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) current: vec4<f32>,
    @location(1) previous: vec4<f32>,
}

// Shells: the fade, the level of detail's blend and the layer; the uv in tiles (xy, meshes with
// uvs) or the root in tiles with its projection's normal (meshes without).
struct PrepassShell {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) fade_blend_layer: vec3<f32>,
    @location(1) tile_position: vec3<f32>,
    @location(2) tile_normal: vec3<f32>,
    @location(3) current: vec4<f32>,
    @location(4) previous: vec4<f32>,
}

struct PrepassFin {
    @builtin(position) clip_position: vec4<f32>,
    // Along the edge in tiles, the height, the fade.
    @location(0) along_height_fade: vec3<f32>,
    @location(1) current: vec4<f32>,
    @location(2) previous: vec4<f32>,
}

fn skin_motion(vertex: u32, wedge: u32) -> MotionSkin {
    let v = surface_varyings(vertex, wedge, 0u);
    let previous = motion.previous_clip_from_model * vec4<f32>(previous_model_vertex(0u, vertex), 1.0);
    return MotionSkin(prepass_clip(v.clip_position), motion.unjittered_clip_from_world * vec4<f32>(v.world_position, 1.0), previous);
}

@vertex
fn vs_prepass_skin_wedges(@builtin(vertex_index) wedge: u32) -> MotionSkin {
    return skin_motion(wedge_vertex(wedge), wedge);
}

@vertex
fn vs_prepass_skin_indexed(@builtin(vertex_index) vertex: u32) -> MotionSkin {
    return skin_motion(vertex, 0u);
}

fn prepass_shell(vertex: u32, wedge: u32, shell: u32) -> PrepassShell {
    let layer = lod_shell_layer(shell);
    let v = surface_varyings(vertex, wedge, layer);
    var out: PrepassShell;
    out.clip_position = prepass_clip(v.clip_position);
    out.fade_blend_layer = vec3<f32>(shell_fade(v.normal, v.world_position), lod_shell_blend(vertex, v.normal), f32(layer));
    if uses_mesh_uvs() {
        out.tile_position = vec3<f32>(v.uv, 0.0);
    } else {
        out.tile_position = v.tile_position;
    }
    out.tile_normal = v.tile_normal;
    out.current = motion.unjittered_clip_from_world * vec4<f32>(v.world_position, 1.0);
    out.previous = motion.previous_clip_from_model * vec4<f32>(previous_model_vertex(layer, vertex), 1.0);
    return out;
}

@vertex
fn vs_prepass_shell_wedges(@builtin(vertex_index) wedge: u32, @builtin(instance_index) shell: u32) -> PrepassShell {
    return prepass_shell(wedge_vertex(wedge), wedge, shell);
}

@vertex
fn vs_prepass_shell_indexed(@builtin(vertex_index) vertex: u32, @builtin(instance_index) shell: u32) -> PrepassShell {
    return prepass_shell(vertex, 0u, shell);
}

@vertex
fn vs_prepass_fin(@builtin(vertex_index) index: u32, @builtin(instance_index) edge: u32) -> PrepassFin {
    var out: PrepassFin;
    let fade = fin_fade(edge);
    if fade <= 0.0 {
        out.clip_position = HIDDEN_FIN_CORNER;
        return out;
    }
    // The fin's geometry only: its lighting would read the colour pass's shadow maps (group 3).
    let g = fin_geometry(index, edge);
    let layer = lod_fin_layer(index / 2u);
    let vertex = fin_vertex(index, edge);
    out.clip_position = prepass_clip(g.clip_position);
    out.along_height_fade = vec3<f32>(g.uvs.xy, fade);
    out.current = motion.unjittered_clip_from_world * vec4<f32>(g.world_position, 1.0);
    out.previous = motion.previous_clip_from_model * vec4<f32>(previous_model_vertex(layer, vertex), 1.0);
    return out;
}

// How much of a shell fragment its strand covers (before the blended draw's thinning).
fn prepass_shell_coverage(in: PrepassShell) -> f32 {
    let layer = varying_layer(in.fade_blend_layer.z);
    var texel: vec4<f32>;
    if uses_mesh_uvs() {
        texel = sample_shell(in.tile_position.xy, shell_slice(layer));
    } else {
        texel = tile_texel(in.tile_position, in.tile_normal, layer);
    }
    return lod_alpha(texel.a * in.fade_blend_layer.x, layer, in.fade_blend_layer.y);
}

fn prepass_fin_coverage(in: PrepassFin) -> f32 {
    let uv = vec2<f32>(in.along_height_fade.x, 1.0 - in.along_height_fade.y);
    return textureSample(fin_texture, fin_sampler, uv).a * in.along_height_fade.z;
}

@fragment
fn fs_prepass_shell_depth(in: PrepassShell) {
    if prepass_shell_coverage(in) < PREPASS_ALPHA_CUTOFF {
        discard;
    }
}

@fragment
fn fs_prepass_fin_depth(in: PrepassFin) {
    if prepass_fin_coverage(in) < PREPASS_ALPHA_CUTOFF {
        discard;
    }
}

@fragment
fn fs_prepass_skin_motion(in: MotionSkin) -> @location(0) vec2<f32> {
    return motion_vector(in.current, in.previous);
}

@fragment
fn fs_prepass_shell_motion(in: PrepassShell) -> @location(0) vec2<f32> {
    if prepass_shell_coverage(in) < PREPASS_ALPHA_CUTOFF {
        discard;
    }
    return motion_vector(in.current, in.previous);
}

@fragment
fn fs_prepass_fin_motion(in: PrepassFin) -> @location(0) vec2<f32> {
    if prepass_fin_coverage(in) < PREPASS_ALPHA_CUTOFF {
        discard;
    }
    return motion_vector(in.current, in.previous);
}
