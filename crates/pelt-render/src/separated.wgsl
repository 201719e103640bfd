// The separated structure of Lengyel et al. 2001: shells and fins as their own static vertex
// buffers (position, normal, uv: 32 bytes a vertex). Appended to `shading.wgsl`.

struct Separated {
    // World units -> tiles.
    tiles_per_world: f32,
    // L.
    layers: u32,
    shell_slices: u32,
    has_uvs: u32,
    // World units per uv unit: recovers the mesh uv for surface colour.
    world_per_uv: f32,
    padding_0: u32,
    padding_1: u32,
    padding_2: u32,
}

@group(1) @binding(0) var<uniform> separated: Separated;

fn uses_mesh_uvs() -> bool {
    return separated.has_uvs != 0u;
}

struct VertexIn {
    @location(0) position: vec3<f32>,
    // Shells: the growing vector. Fins: the fin's plane normal.
    @location(1) normal: vec3<f32>,
    // Shells: mesh uv scaled to world units on the CPU. Fins: (world units along the edge, height).
    @location(2) uv: vec2<f32>,
}

// Shells: one draw per layer with a base-vertex offset; the instance index carries the layer.
@vertex
fn vs_separated_shell(in: VertexIn, @builtin(instance_index) layer: u32) -> Varyings {
    var out: Varyings;
    out.clip_position = globals.clip_from_world * vec4<f32>(in.position, 1.0);
    out.world_position = in.position;
    out.normal = in.normal;
    out.tangent = in.normal;
    out.tile_position = in.position * separated.tiles_per_world;
    out.uv = in.uv * separated.tiles_per_world;
    out.surface_uv = in.uv / separated.world_per_uv;
    out.layer = layer;
    out.slice = i32(((max(layer, 1u) - 1u) * separated.shell_slices) / max(separated.layers, 1u));
    out.height = f32(layer) / f32(max(separated.layers, 1u));
    out.fade = shell_fade(in.normal, in.position);
    return out;
}

@vertex
fn vs_separated_fin(in: VertexIn) -> Varyings {
    var out: Varyings;
    out.clip_position = globals.clip_from_world * vec4<f32>(in.position, 1.0);
    out.world_position = in.position;
    out.normal = in.normal;
    out.tangent = in.normal;
    out.tile_position = vec3<f32>(0.0);
    out.uv = vec2<f32>(in.uv.x * separated.tiles_per_world, in.uv.y);
    out.layer = 0u;
    out.slice = 0;
    // Separated fins keep no mesh uv: surface colour mode tints them with the texture's corner.
    out.surface_uv = vec2<f32>(0.0);
    out.height = in.uv.y;
    // Lengyel's fade: a fin shows where it faces the viewer, i.e. stands on a silhouette edge.
    let to_camera = safe_normalize(globals.camera_position - in.position, in.normal);
    out.fade = smoothstep(1.0 - globals.fin_fade_cos, 1.0, abs(dot(in.normal, to_camera)));
    return out;
}

// Fins store no strand direction: it is the direction of growing height across the fin, from the
// screen-space derivatives of position and uv.
@fragment
fn fs_separated_fin(in: Varyings) -> @location(0) vec4<f32> {
    let dp_dx = dpdx(in.world_position);
    let dp_dy = dpdy(in.world_position);
    let duv_dx = dpdx(in.uv);
    let duv_dy = dpdy(in.uv);
    let determinant = duv_dx.x * duv_dy.y - duv_dy.x * duv_dx.y;
    let up = (duv_dx.x * dp_dy - duv_dy.x * dp_dx) * sign(determinant);
    let texel = textureSample(fin_texture, fin_sampler, vec2<f32>(in.uv.x, 1.0 - in.uv.y));
    let normal = normalize(in.normal);
    let tangent = safe_normalize(up, normal);
    let colour = hair_lighting(texel.rgb * surface_tint(in.surface_uv), tangent, tangent, in.world_position, in.height);
    return fur_output(colour, texel.a * in.fade);
}
