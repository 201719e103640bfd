// The 3D view's texture drawn into the window texel for texel (`viewport.rs`): one triangle over
// the viewport rectangle. A plain load and store, because on software rasterisers egui's own
// textured quad (filtering and gamma work per pixel) cost the viewer a quarter of its frame.

@group(0) @binding(0) var view_texture: texture_2d<f32>;

struct Corner {
    @builtin(position) clip_position: vec4<f32>,
    // 0..1 across the viewport, y down.
    @location(0) uv: vec2<f32>,
}

@vertex
fn vs_cover(@builtin(vertex_index) index: u32) -> Corner {
    // (-1, -1), (3, -1), (-1, 3): covers the viewport.
    let x = f32(i32(index & 1u) * 4 - 1);
    let y = f32(i32(index >> 1u) * 4 - 1);
    return Corner(vec4<f32>(x, y, 0.0, 1.0), vec2<f32>(0.5 * x + 0.5, 0.5 - 0.5 * y));
}

@fragment
fn fs_copy(in: Corner) -> @location(0) vec4<f32> {
    let size = vec2<f32>(textureDimensions(view_texture));
    let texel = vec2<i32>(clamp(in.uv * size, vec2<f32>(0.0), size - 1.0));
    return textureLoad(view_texture, texel, 0);
}
