// The explicit strand reference: every strand of the seeded field as a camera-facing ribbon, lit
// by the same `hair_lighting` as the shells and fins, darkened and shining when wet (`wet.wgsl`).
// Appended to `shading.wgsl` and `wet.wgsl`; reads the view (group 0) and the fur's object
// uniform (group 1, binding 0: transform and look), no textures.

struct StrandVertex {
    // Strand node, model space.
    @location(0) position: vec3<f32>,
    // Strand direction at the node (model space).
    @location(1) tangent: vec3<f32>,
    // Base surface normal at the strand's root (model space).
    @location(2) normal: vec3<f32>,
    // Linear RGB albedo and the node's height (0 at the root, 1 at the fur's tip layer).
    @location(3) colour_height: vec4<f32>,
    // Half the ribbon's width (world units), signed: the side of the strand this vertex is on.
    @location(4) half_width: f32,
    // The coat's wetness at the strand's root (0 dry).
    @location(5) wetness: f32,
}

@vertex
fn vs_strand(in: StrandVertex) -> Varyings {
    let centre = world_from_model_point(in.position);
    let normal = world_from_model_normal(in.normal);
    let tangent = safe_normalize(world_from_model_direction(in.tangent), normal);
    let to_camera = safe_normalize(view.camera_position - centre, normal);
    // Facing the camera: widen across the strand, in the plane that faces the eye.
    let side = safe_normalize(cross(tangent, to_camera), safe_normalize(cross(tangent, normal), vec3<f32>(1.0, 0.0, 0.0)));
    let position = centre + side * in.half_width;
    var out: Varyings;
    out.clip_position = view.clip_from_world * vec4<f32>(position, 1.0);
    out.world_position = position;
    out.normal = normal;
    out.tangent = tangent;
    out.tile_position = in.colour_height.rgb;
    out.tile_normal = vec3<f32>(0.0);
    out.uv = vec2<f32>(0.0);
    out.layer = 0u;
    out.slice = 0;
    out.height = in.colour_height.a;
    out.fade = 1.0;
    // The wetness travels in `surface_uv.x`, which strands do not otherwise use.
    out.surface_uv = vec2<f32>(in.wetness, 0.0);
    return out;
}

// Opaque: the supersampled target resolves a strand's partial coverage of a pixel.
@fragment
fn fs_strand(in: Varyings) -> @location(0) vec4<f32> {
    // The albedo travels in `tile_position`, which strands do not otherwise use.
    var albedo = in.tile_position;
    var terms = hair_terms(normalize(in.tangent), normalize(in.normal), in.world_position, in.height);
    // A uniform branch: a wet strand darkens and shines as `wet_groom` and `coat_terms` make the
    // shells do (either model); a dry coat keeps `hair_lighting`'s very arithmetic.
    if wet_on() {
        let w = clamp(in.surface_uv.x, 0.0, 1.0);
        albedo *= 1.0 - object.wet_darkening * w;
        terms = coat_terms(normalize(in.tangent), normalize(in.normal), in.world_position, in.height, w);
    }
    return vec4<f32>(hair_colour(albedo, terms, in.height), 1.0);
}
