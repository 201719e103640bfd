// The vertex-path experiment (`vertex_path.rs`): the bunny's shells with the same varyings and a
// near-constant fragment, their positions fetched three ways. Not the product's shader. Follows
// `profile/shells.wgsl` (the uniform `u`, the positions and `load3`).

// Base normals as packed xyz triples (as the product keeps them).
@group(0) @binding(2) var<storage, read> normals: array<f32>;
// The positions and normals padded to vec4 (the packed-load variant; more memory).
@group(0) @binding(3) var<storage, read> positions4: array<vec4<f32>>;
@group(0) @binding(4) var<storage, read> normals4: array<vec4<f32>>;

struct Out {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) tangent: vec3<f32>,
    @location(1) tile_position: vec3<f32>,
    @location(2) normal: vec3<f32>,
    @location(3) @interpolate(flat) layer: u32,
}

// `other` is layer + 1's node, or layer - 1's at the tips.
fn finish(here: vec3<f32>, other: vec3<f32>, root: vec3<f32>, normal: vec3<f32>, layer: u32) -> Out {
    var out: Out;
    out.clip_position = u.clip_from_world * vec4<f32>(here, 1.0);
    var segment = other - here;
    if layer >= u.layers {
        segment = here - other;
    }
    out.tangent = normalize(segment);
    out.tile_position = root * u.tiles_per_world;
    out.normal = normal;
    out.layer = layer;
    return out;
}

fn other_layer(layer: u32) -> u32 {
    return select(layer + 1u, layer - 1u, layer >= u.layers);
}

// Storage loads of scalars (the product's path today): instance k is layer k + 1.
@vertex
fn vs_storage(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> Out {
    let layer = instance + 1u;
    let here = load3(layer * u.vertex_count + vertex);
    let other = load3(other_layer(layer) * u.vertex_count + vertex);
    let root = load3(vertex);
    let normal = vec3<f32>(normals[3u * vertex], normals[3u * vertex + 1u], normals[3u * vertex + 2u]);
    return finish(here, other, root, normal, layer);
}

// Packed vec4 storage loads.
@vertex
fn vs_storage4(@builtin(vertex_index) vertex: u32, @builtin(instance_index) instance: u32) -> Out {
    let layer = instance + 1u;
    let here = positions4[layer * u.vertex_count + vertex].xyz;
    let other = positions4[other_layer(layer) * u.vertex_count + vertex].xyz;
    return finish(here, other, positions4[vertex].xyz, normals4[vertex].xyz, layer);
}

// Vertex buffers: slices of the one position buffer at layers i, i +- 1 and 0; one draw per layer
// with the layer as its first instance.
@vertex
fn vs_buffers(
    @location(0) here: vec3<f32>,
    @location(1) other: vec3<f32>,
    @location(2) root: vec3<f32>,
    @location(3) normal: vec3<f32>,
    @builtin(instance_index) layer: u32,
) -> Out {
    return finish(here, other, root, normal, layer);
}

@fragment
fn fs_main(v: Out) -> @location(0) vec4<f32> {
    // Reads every varying so none is dropped, at the cost of a few adds.
    let c = 0.05 * (abs(v.tangent) + fract(v.tile_position) + abs(v.normal)) + vec3<f32>(f32(v.layer) * 0.01);
    return vec4<f32>(c * 0.5, 0.5);
}
