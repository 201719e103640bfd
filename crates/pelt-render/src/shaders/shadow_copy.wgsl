// A host's shadow map (one layer of its depth, drawn by the host's own shadow pass) copied into a
// layer of Pelt's (`HostShadows`), a reverse-Z depth turned into Pelt's forward one, so the fur
// reads a host's shadows through the same `shadows.wgsl` lookups as its own.

@group(0) @binding(0) var source: texture_depth_2d;

// Set per pipeline: whether the host's depth is reverse-Z (Bevy's).
override REVERSE_Z: bool = true;

struct Copied {
    @builtin(position) position: vec4<f32>,
    // Where the fragment lies across the target (0..1, rows from the top).
    @location(0) uv: vec2<f32>,
}

// One triangle over the whole target.
@vertex
fn vs_copy(@builtin(vertex_index) index: u32) -> Copied {
    let corner = vec2<f32>(f32((index << 1u) & 2u), f32(index & 2u));
    return Copied(vec4<f32>(corner * 2.0 - 1.0, 0.0, 1.0), vec2<f32>(corner.x, 1.0 - corner.y));
}

// The source texel under the fragment: the same texel where the sizes match, the nearest where
// the host's map is smaller than Pelt's layers (a point light's beside a sun's).
@fragment
fn fs_copy(in: Copied) -> @builtin(frag_depth) f32 {
    let size = vec2<i32>(textureDimensions(source));
    let texel = vec2<i32>(floor(in.uv * vec2<f32>(size)));
    let depth = textureLoad(source, clamp(texel, vec2<i32>(0), size - 1), 0);
    return select(depth, 1.0 - depth, REVERSE_Z);
}
