// What the shell experiments (`shell_floor.wgsl`, `vertex_path.wgsl`) share; `profile/mod.rs`
// puts it before each. Not the product's shader.

struct Uniforms {
    clip_from_world: mat4x4<f32>,
    vertex_count: u32,
    layers: u32,
    tiles_per_world: f32,
    padding: u32,
}

@group(0) @binding(0) var<uniform> u: Uniforms;
// NV as packed xyz triples, layer-major (as the product keeps them).
@group(0) @binding(1) var<storage, read> positions: array<f32>;

fn load3(k: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * k], positions[3u * k + 1u], positions[3u * k + 2u]);
}
