// The fur model (`[shading] model = "fur"`), appended to `shading.wgsl`: per vertex, a sum over
// the view's lights of radiance x visibility x BSDF, and the environment's fill; per fragment,
// the texel's albedo applied. The BSDF has Marschner's R, TT and TRT lobes in Karis' cheap form
// ("Physically Based Hair Shading in Unreal", 2016) and a medulla lobe after Yan et al. 2017: the
// share `object.medulla` of the light entering a strand is scattered into a broad lobe (forward
// and backward at once) instead of following TT and TRT. `fur_bsdf::mirror` is its CPU twin,
// checked for energy there.

// One light as the shaders read it (`GpuLight`).
struct Light {
    // Directional: unit vector toward the light (w = 0). Point and spot: the position (w = 1).
    position_or_direction: vec4<f32>,
    // Spot: unit axis away from the light and the outer cone's half-angle cosine (w); -2 for
    // lights without a cone.
    spot_axis_cos_outer: vec4<f32>,
    // Linear RGB times lux (directional) or candela; the inner cone's half-angle cosine (w).
    intensity_cos_inner: vec4<f32>,
    // Whether it casts shadows, its kind (0 directional, 1 point, 2 spot), unused.
    flags: vec4<u32>,
}

@group(0) @binding(1) var<uniform> lights: Lights;

// The view's lights and environment for the fur model; the kajiya-kay model reads the key light
// in `View`.
struct Lights {
    count: u32,
    padding_0: u32,
    padding_1: u32,
    padding_2: u32,
    // The colours the fur model's lobes are shown in, each of luminance 1: the lights' mean
    // (by luminance) and the environment's mean.
    light_tint: vec4<f32>,
    environment_tint: vec4<f32>,
    // The environment's radiance in 9 SH coefficients (rgb), luminance in w.
    environment_sh: array<vec4<f32>, 9>,
    light: array<Light, 8>,
}

fn luminance(c: vec3<f32>) -> f32 {
    return dot(c, vec3<f32>(0.2126, 0.7152, 0.0722));
}

// The normalised Gaussian of Marschner's longitudinal lobes.
fn hair_gaussian(width: f32, x: f32) -> f32 {
    return exp(-0.5 * x * x / (width * width)) / (2.5066283 * width);
}

// Schlick's Fresnel for a strand (index 1.55).
fn hair_fresnel(cos_theta: f32) -> f32 {
    let f0 = 0.04652;
    let m = 1.0 - cos_theta;
    let m2 = m * m;
    return f0 + (1.0 - f0) * m2 * m2 * m;
}

// The R lobe's albedo toward a view at `cos_v` from the normal plane: Fresnel averaged over the
// strand's width, the integral over h in 0..1 of F(cos_v sqrt(1 - h^2)) by 4-point Gauss-Legendre.
// The tinted lobes take only what R leaves, so a white strand never returns more than it gets
// (Karis' lobes as published reach 1.11 at grazing views).
fn hair_r_albedo(cos_v: f32) -> f32 {
    let c = cos_v;
    return 0.17392742 * (hair_fresnel(c * 0.99759) + hair_fresnel(c * 0.36612))
        + 0.32607258 * (hair_fresnel(c * 0.94398) + hair_fresnel(c * 0.74237));
}

// What a wet cuticle reflects of a dry one's: the air-water and water-keratin interfaces at
// normal incidence (Fresnel 0.020 + 0.006, indices 1.33 and 1.55) against air-keratin (0.047).
fn water_film(wet: f32) -> f32 {
    return 1.0 - 0.45 * wet;
}

// The share of a light's irradiance the coat's strands scatter among themselves and return
// diffusely (times the texel's colour).
const MULTIPLE_SCATTERING: f32 = 0.6;

// The longitudinal roughness at wetness `wet`: water smooths the cuticle.
fn wet_roughness(wet: f32) -> f32 {
    return object.fur_roughness * (1.0 - 0.5 * clamp(object.wet_shine, 0.0, 1.0) * wet);
}

// The BSDF times the cosine for one light: (white R lobe, albedo-tinted lobes), per unit
// irradiance from `l`. `t` strand tangent, `v` toward the eye, `n` surface normal, all unit.
// `wet` (0..1) makes it smoother (lobes narrower by the preset's wet shine, the highlight's
// peak kept) and darker (the tinted lobes).
fn fur_bsdf(t: vec3<f32>, v: vec3<f32>, l: vec3<f32>, n: vec3<f32>, wet: f32) -> vec2<f32> {
    return fur_bsdf_lit(t, v, l, dot(n, l), wet);
}

// `fur_bsdf` with the surface normal's cosine to the light, `n_dot_l`, all it reads of it.
fn fur_bsdf_lit(t: vec3<f32>, v: vec3<f32>, l: vec3<f32>, n_dot_l: f32, wet: f32) -> vec2<f32> {
    let sin_l = clamp(dot(t, l), -1.0, 1.0);
    let sin_v = clamp(dot(t, v), -1.0, 1.0);
    let lp = l - t * sin_l;
    let vp = v - t * sin_v;
    let cos_phi = dot(lp, vp) * inverseSqrt(max(dot(lp, lp) * dot(vp, vp), 1e-8));
    let cos_half_phi = sqrt(clamp(0.5 + 0.5 * cos_phi, 0.0, 1.0));
    let cos_l = sqrt(max(1.0 - sin_l * sin_l, 0.0));
    let cos_v = sqrt(max(1.0 - sin_v * sin_v, 0.0));
    // cos((theta_v - theta_l) / 2) by the half-angle identity.
    let cos_theta_d = sqrt(clamp(0.5 + 0.5 * (cos_v * cos_l + sin_v * sin_l), 1e-4, 1.0));
    let roughness = wet_roughness(wet);
    let b = roughness * roughness;
    let shift = object.fur_cuticle_tilt;
    let s = sin_l + sin_v;
    // The body stands between the light and the strands on its far side: the reflected lobes
    // need the light on the strand's side of the surface, the transmitted one reaches round the
    // rim (the shadow maps, where bound, add the strands' own shadowing).
    let lit_side = smoothstep(-0.25, 0.6, n_dot_l);
    let through = smoothstep(-0.4, 0.05, n_dot_l);
    // R: reflected at the surface, white. Wet, the narrower lobe keeps its dry peak (the
    // highlight sharpens, it does not spread brighter) and the water film reflects less.
    let sharpened = b / max(object.fur_roughness * object.fur_roughness, 1e-6);
    let r = hair_gaussian(b, s + 2.0 * shift) * sharpened * water_film(wet) * 0.25 * cos_half_phi
        * hair_fresnel(sqrt(clamp(0.5 + 0.5 * dot(v, l), 0.0, 1.0))) * lit_side;
    // TT: through the strand, forward (back light at the rim).
    let a = 1.0 / (1.19 / cos_theta_d + 0.36 * cos_theta_d);
    let h = cos_half_phi * (1.0 + a * (0.6 - 0.8 * cos_phi));
    let f_tt = hair_fresnel(cos_theta_d * sqrt(clamp(1.0 - h * h, 0.0, 1.0)));
    let tt = hair_gaussian(0.5 * b, s - shift) * exp(-3.65 * cos_phi - 3.98) * (1.0 - f_tt) * (1.0 - f_tt) * through;
    // TRT: in, reflected inside, out; the secondary, shifted highlight.
    let f_trt = hair_fresnel(0.5 * cos_theta_d);
    let trt = hair_gaussian(2.0 * b, s - 4.0 * shift) * exp(17.0 * cos_phi - 16.78) * (1.0 - f_trt) * (1.0 - f_trt) * f_trt * lit_side;
    // The medulla's scattered lobes: a broad longitudinal lobe, forward-leaning in azimuth
    // (normalised over phi), taking the entering light's medulla share.
    let m = object.fur_medulla;
    let scattered = hair_gaussian(b + 0.6, s) * (1.0 - 0.4 * cos_phi) * 0.15915494 * (1.0 - f_tt) * lit_side;
    // Light scattered from strand to strand through the coat (what Unreal's hair BSDF adds as its
    // diffuse scatter): a soft, wrapped cosine about the surface, as the environment's fill is.
    // Without it a coat under a sun and little sky returns a third of a surface of its colour.
    let multiple = MULTIPLE_SCATTERING * 0.31830988 * clamp((n_dot_l + 0.3) / 1.3, 0.0, 1.0);
    let single = ((1.0 - m) * (tt + trt) + m * scattered) * (1.0 - hair_r_albedo(cos_v));
    let tinted = (single + multiple) * (1.0 - object.wet_darkening * wet);
    return vec2<f32>(r, tinted);
}

// Light `i` arriving at `world_position`: the unit vector toward it and its irradiance (linear
// RGB, lux) on a surface facing it, a point or spot light's falling off with the squared distance
// and a spot's between its cones.
struct Incident {
    to_light: vec3<f32>,
    irradiance: vec3<f32>,
}

fn light_incident(i: u32, world_position: vec3<f32>) -> Incident {
    // Selects, not an `if` on the light's kind: lavapipe (Mesa 22.3) inlines a uniform that alone
    // decides a fragment's branch and compiles anew whenever another view's lights are bound.
    let light = lights.light[i];
    let positional = light.position_or_direction.w != 0.0;
    let offset = light.position_or_direction.xyz - world_position;
    let d2 = max(dot(offset, offset), 1e-8);
    let toward = offset * inverseSqrt(d2);
    let cone = dot(-toward, light.spot_axis_cos_outer.xyz);
    let outer = light.spot_axis_cos_outer.w;
    let fade = clamp((cone - outer) / max(light.intensity_cos_inner.w - outer, 1e-4), 0.0, 1.0);
    let irradiance = light.intensity_cos_inner.xyz;
    return Incident(
        select(light.position_or_direction.xyz, toward, positional),
        select(irradiance, irradiance * (fade * fade / d2), positional),
    );
}

// The environment's SH coefficient `k` (rgb).
fn environment_coefficient(k: u32) -> vec3<f32> {
    return lights.environment_sh[k].xyz;
}

// The environment's luminance from its SH: band weights `b0`, `b1`, `b2` toward `d`.
fn environment_sh(d: vec3<f32>, b0: f32, b1: f32, b2: f32) -> f32 {
    let c = lights.environment_sh;
    let linear = 0.4886025 * (c[1].w * d.y + c[2].w * d.z + c[3].w * d.x);
    let quadratic = 1.0925484 * (c[4].w * d.x * d.y + c[5].w * d.y * d.z + c[7].w * d.x * d.z)
        + 0.31539157 * c[6].w * (3.0 * d.z * d.z - 1.0) + 0.5462742 * c[8].w * (d.x * d.x - d.y * d.y);
    return b0 * 0.2820948 * c[0].w + b1 * linear + b2 * quadratic;
}

// (R, tinted lobes, environment fill, occlusion) for the fur model at a vertex.
fn fur_terms(tangent: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>, height: f32, wetness: f32) -> vec4<f32> {
    let to_camera = safe_normalize(view.camera_position - world_position, normal);
    let wet = clamp(wetness, 0.0, 1.0);
    var sum = vec2<f32>(0.0);
    for (var i = 0u; i < lights.count; i++) {
        let incident = light_incident(i, world_position);
        let visibility = strand_visibility(i, world_position, normal);
        sum += fur_bsdf(tangent, to_camera, incident.to_light, normal, wet) * (luminance(incident.irradiance) * visibility);
    }
    // The environment: irradiance / pi as the scattered fill (a white strand under a uniform
    // environment returns at most its radiance) and a blurred radiance about the mirror
    // direction as the rough highlight, sharing one budget with it.
    let specular = 0.05 * water_film(wet);
    let diffuse = environment_sh(normal, 1.0, 0.6666667, 0.25) * (1.0 - object.wet_darkening * wet);
    let mirror = reflect(-to_camera, normal);
    let width = wet_roughness(wet);
    let w2 = width * width;
    let highlight = environment_sh(mirror, 1.0, exp(-w2), exp(-3.0 * w2));
    return vec4<f32>(sum.x + specular * max(highlight, 0.0), sum.y, (1.0 - specular) * max(diffuse, 0.0), occlusion(height));
}

// The fur model's colour from its terms and the texel's albedo (times the pigments' colour).
fn fur_colour(albedo: vec3<f32>, terms: vec4<f32>) -> vec3<f32> {
    let a = albedo * object.fur_pigment;
    let lit = lights.light_tint.rgb * (terms.x + a * terms.y) + lights.environment_tint.rgb * (a * terms.z);
    return lit * terms.w;
}
