// How much of light `light_index` reaches `world_position` (1 = unshadowed). No shadow maps are
// bound: every light reaches every fragment.
fn light_visibility(light_index: u32, world_position: vec3<f32>, world_normal: vec3<f32>) -> f32 {
    return 1.0;
}
