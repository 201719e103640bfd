// egui's picture, kept in a texture of its own (`ui_layer.rs`), laid over the window one tile at
// a time where egui drew anything: a plain load, blended as egui blends (premultiplied "over").

@group(0) @binding(0) var ui_texture: texture_2d<f32>;

@vertex
fn vs_tile(@builtin(vertex_index) index: u32, @location(0) rect_ndc: vec4<f32>) -> @builtin(position) vec4<f32> {
    // Two triangles over the tile: corners (0, 0), (1, 0), (0, 1), (0, 1), (1, 0), (1, 1).
    let right = index == 1u || index == 4u || index == 5u;
    let down = index == 2u || index == 3u || index == 5u;
    let x = select(rect_ndc.x, rect_ndc.z, right);
    let y = select(rect_ndc.y, rect_ndc.w, down);
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_tile(@builtin(position) position: vec4<f32>) -> @location(0) vec4<f32> {
    // The window and the layer have the same size, so the pixel centre names the texel.
    return textureLoad(ui_texture, vec2<i32>(position.xy), 0);
}
