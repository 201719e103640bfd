// The shell-floor experiment (`shell_floor.rs`): the bunny's L shells with a growing number of
// interpolated components and fragment work, to find what a shell triangle and fragment cost on
// this adapter. Not the product's shader. Follows `profile/shells.wgsl` (the uniform `u`, the
// positions and `load3`).

@group(0) @binding(2) var tiles: texture_2d<f32>;
@group(0) @binding(3) var tiles_sampler: sampler;

fn here(vertex: u32, instance: u32) -> vec3<f32> {
    return load3((instance + 1u) * u.vertex_count + vertex);
}

struct Bare {
    @builtin(position) clip_position: vec4<f32>,
}

@vertex
fn vs_bare(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> Bare {
    return Bare(u.clip_from_world * vec4<f32>(here(vertex, instance), 1.0));
}

@fragment
fn fs_bare() -> @location(0) vec4<f32> {
    return vec4<f32>(0.2, 0.15, 0.1, 0.5);
}

struct Four {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) a: vec4<f32>,
}

@vertex
fn vs_four(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> Four {
    let p = here(vertex, instance);
    return Four(u.clip_from_world * vec4<f32>(p, 1.0), vec4<f32>(p, 1.0));
}

@fragment
fn fs_four(v: Four) -> @location(0) vec4<f32> {
    return vec4<f32>(0.05 * fract(v.a.xyz + v.a.w), 0.5);
}

struct Eight {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) a: vec4<f32>,
    @location(1) b: vec4<f32>,
}

@vertex
fn vs_eight(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> Eight {
    let p = here(vertex, instance);
    return Eight(u.clip_from_world * vec4<f32>(p, 1.0), vec4<f32>(p, 1.0), vec4<f32>(p.yzx, 2.0));
}

@fragment
fn fs_eight(v: Eight) -> @location(0) vec4<f32> {
    return vec4<f32>(0.05 * fract(v.a.xyz + v.a.w + v.b.xyz + v.b.w), 0.5);
}

struct Sixteen {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) a: vec4<f32>,
    @location(1) b: vec4<f32>,
    @location(2) c: vec4<f32>,
    @location(3) d: vec4<f32>,
}

fn sixteen(vertex: u32, instance: u32) -> Sixteen {
    let p = here(vertex, instance);
    return Sixteen(u.clip_from_world * vec4<f32>(p, 1.0), vec4<f32>(p, 1.0), vec4<f32>(p.yzx, 2.0), vec4<f32>(p.zxy, 3.0), vec4<f32>(p * u.tiles_per_world, 4.0));
}

@vertex
fn vs_sixteen(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> Sixteen {
    return sixteen(vertex, instance);
}

@fragment
fn fs_sixteen(v: Sixteen) -> @location(0) vec4<f32> {
    return vec4<f32>(0.05 * fract(v.a.xyz + v.a.w + v.b.xyz + v.b.w + v.c.xyz + v.c.w + v.d.xyz + v.d.w), 0.5);
}

// Sixteen components and one texture sample (the shell's texel, through tile coordinates).
@fragment
fn fs_sixteen_texture(v: Sixteen) -> @location(0) vec4<f32> {
    let texel = textureSample(tiles, tiles_sampler, v.d.xy);
    let c = 0.05 * fract(v.a.xyz + v.a.w + v.b.xyz + v.b.w + v.c.xyz + v.c.w + v.d.w) + texel.rgb;
    return vec4<f32>(c * texel.a, texel.a);
}

// Four components and the texture sample (what a shell with per-vertex lighting would need).
@fragment
fn fs_four_texture(v: Four) -> @location(0) vec4<f32> {
    let texel = textureSample(tiles, tiles_sampler, v.a.xy * u.tiles_per_world);
    let c = 0.05 * fract(v.a.zzz + v.a.w) + texel.rgb;
    return vec4<f32>(c * texel.a, texel.a);
}
