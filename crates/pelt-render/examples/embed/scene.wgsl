// The host's own geometry in the embed example: flat-coloured, Lambert-lit triangles.

struct Camera {
    clip_from_world: mat4x4<f32>,
    // Unit vector toward the light, world space.
    light_direction: vec3<f32>,
    padding: f32,
}

@group(0) @binding(0) var<uniform> camera: Camera;

struct VertexIn {
    @location(0) position: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // Linear RGB.
    @location(2) colour: vec3<f32>,
}

struct VertexOut {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) normal: vec3<f32>,
    @location(1) colour: vec3<f32>,
}

@vertex
fn vs_main(in: VertexIn) -> VertexOut {
    var out: VertexOut;
    out.clip_position = camera.clip_from_world * vec4<f32>(in.position, 1.0);
    out.normal = in.normal;
    out.colour = in.colour;
    return out;
}

@fragment
fn fs_main(in: VertexOut) -> @location(0) vec4<f32> {
    let lit = max(dot(normalize(in.normal), camera.light_direction), 0.0);
    return vec4<f32>(in.colour * (0.3 + 0.7 * lit), 1.0);
}
