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

// `transmittance` (its own vertex buffer): how much of the key light reaches the node through
// the other strands and the skin, traced offline (`pelt_core::reference::shadow`); 1 unshadowed.
@vertex
fn vs_strand(in: StrandVertex, @location(6) transmittance: f32) -> Varyings {
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
    // The wetness and the key light's transmittance travel in `surface_uv`, which strands do
    // not otherwise use.
    out.surface_uv = vec2<f32>(in.wetness, transmittance);
    return out;
}

// Opaque: the supersampled target resolves a strand's partial coverage of a pixel.
@fragment
fn fs_strand(in: Varyings) -> @location(0) vec4<f32> {
    // The albedo travels in `tile_position`, which strands do not otherwise use.
    var albedo = in.tile_position;
    let tangent = normalize(in.tangent);
    let normal = normalize(in.normal);
    var terms = hair_terms(tangent, normal, in.world_position, in.height);
    // A uniform branch: a wet strand darkens and shines as `wet_groom` and `coat_terms` make the
    // shells do (either model); a dry coat keeps `hair_lighting`'s very arithmetic.
    var wet = 0.0;
    if wet_on() {
        wet = clamp(in.surface_uv.x, 0.0, 1.0);
        // As `wet_groom`: the fur model darkens through its BSDF's parameters, not the albedo.
        albedo *= 1.0 - select(object.wet_darkening * wet, 0.0, fur_model());
        terms = coat_terms(tangent, normal, in.world_position, in.height, wet);
    }
    // The strands' own shadow takes its share of the key light (light 0) only; the
    // environment's fill stays unshadowed, as on the shells. Unshadowed strands keep their bytes.
    let transmittance = clamp(in.surface_uv.y, 0.0, 1.0);
    if transmittance < 1.0 {
        if fur_model() {
            let key = key_light_lobes(tangent, normal, in.world_position, wet);
            terms = vec4<f32>(max(terms.xy - (1.0 - transmittance) * key, vec2<f32>(0.0)), terms.zw);
        } else {
            terms.z *= transmittance;
        }
    }
    return vec4<f32>(hair_colour(albedo, terms, in.height), 1.0);
}

// The fur model's lobes from the key light (light 0) alone, as `fur_terms` sums them (the strand
// pipeline has no shadow maps: its visibility is 1).
fn key_light_lobes(tangent: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>, wet: f32) -> vec2<f32> {
    if lights.count == 0u {
        return vec2<f32>(0.0);
    }
    let to_camera = safe_normalize(view.camera_position - world_position, normal);
    let incident = light_incident(0u, world_position);
    return fur_bsdf(tangent, to_camera, incident.to_light, normal, wet) * luminance(incident.irradiance);
}
