// A host's shadow map (one layer of its depth, drawn by the host's own shadow pass) copied into a
// layer of Pelt's (`HostShadows`), a reverse-Z depth turned into Pelt's forward one, so the fur
// reads a host's shadows through the same `shadows.wgsl` lookups as its own.

@group(0) @binding(0) var source: texture_depth_2d;

// Set per pipeline: whether the host's depth is reverse-Z (Bevy's).
override REVERSE_Z: bool = true;

// One triangle over the whole target.
@vertex
fn vs_copy(@builtin(vertex_index) index: u32) -> @builtin(position) vec4<f32> {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0);
}

@fragment
fn fs_copy(@builtin(position) position: vec4<f32>) -> @builtin(frag_depth) f32 {
    let size = vec2<i32>(textureDimensions(source));
    let depth = textureLoad(source, clamp(vec2<i32>(position.xy), vec2<i32>(0), size - 1), 0);
    return select(depth, 1.0 - depth, REVERSE_Z);
}
