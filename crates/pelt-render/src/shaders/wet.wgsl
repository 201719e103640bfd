// Wet fur, appended to `shading.wgsl`: the wet look (darker albedo, a sharper and stronger
// Kajiya-Kay highlight) and the clumps (strands gathering toward clump centres as they wet,
// parting the coat), all blended by the strand's wetness. Called only when `object.wet_any`
// is set, so a dry fur's bytes never depend on this file.

// `hair_colour` for wetness `wetness`: exactly its terms at 0, darker and shinier up to 1.
fn wet_hair_colour(albedo: vec3<f32>, terms: vec4<f32>, height: f32, wetness: f32) -> vec3<f32> {
    let w = clamp(wetness, 0.0, 1.0);
    // The water film: a narrower lobe (exponent times 1 + 2 shine w) and more light in it.
    let shine = 1.0 + object.wet_shine * w;
    let specular = pow(max(terms.y, 0.0), 0.5 * object.shininess * (2.0 * shine - 1.0));
    let ao = terms.w;
    let light = view.light_colour * terms.z;
    let dark = albedo * (1.0 - object.wet_darkening * w);
    let colour = dark * (view.ambient + light * terms.x * 0.85) * ao;
    let highlight = mix(vec3<f32>(1.0), albedo / max(max(albedo.r, albedo.g), max(albedo.b, 1e-3)), 0.5);
    return colour + light * highlight * (specular * object.specular * shine * ao * height);
}

// How far strands have gathered toward their clump's centre at `height` (0 roots, 1 tips):
// the tips most, the roots a little, so the skin shows along the partings.
fn clump_amount(height: f32, wetness: f32) -> f32 {
    return object.clump_strength * clamp(wetness, 0.0, 1.0) * mix(0.35, 1.0, clamp(height, 0.0, 1.0));
}

fn clump_hash(x: u32) -> u32 {
    var h = x * 0x9e3779b9u;
    h = (h ^ (h >> 16u)) * 0x85ebca6bu;
    h = (h ^ (h >> 13u)) * 0xc2b2ae35u;
    return h ^ (h >> 16u);
}

// The centre of clump cell `cell` (integer-valued), in tiles: jittered inside its cell.
fn clump_centre(cell: vec2<f32>) -> vec2<f32> {
    let c = vec2<i32>(cell);
    let h = clump_hash(bitcast<u32>(c.x) * 0x8da6b343u + bitcast<u32>(c.y) * 0xd8163841u);
    let jitter = vec2<f32>(f32(h & 0xffffu), f32(h >> 16u)) / 65536.0;
    return (cell + 0.15 + 0.7 * jitter) * object.clump_size;
}

// A shell fragment at tile position `uv` shows the strand rooted where the clump pulled it
// from: `centre + (uv - centre) / (1 - amount)`, the clump being the nearest centre (cells
// of `clump_size` tiles, one jittered centre each). Where that root lies in another clump's
// cell, no strand of this clump reaches here: a parting. Returns (the uv to sample, coverage).
fn clump_uv(uv: vec2<f32>, height: f32, wetness: f32) -> vec3<f32> {
    let amount = clump_amount(height, wetness);
    let cell = floor(uv / object.clump_size);
    var centres: array<vec2<f32>, 9>;
    var nearest = 0u;
    var nearest_d2 = 3.4e38;
    for (var k = 0u; k < 9u; k++) {
        let c = clump_centre(cell + vec2<f32>(f32(k % 3u) - 1.0, f32(k / 3u) - 1.0));
        centres[k] = c;
        let d2 = dot(uv - c, uv - c);
        if d2 < nearest_d2 {
            nearest_d2 = d2;
            nearest = k;
        }
    }
    let centre = centres[nearest];
    let source = centre + (uv - centre) / (1.0 - amount);
    let own = distance(source, centre);
    var margin = 3.4e38;
    for (var k = 0u; k < 9u; k++) {
        if k != nearest {
            margin = min(margin, distance(source, centres[k]) - own);
        }
    }
    // A soft parting edge, as wide as the gathering: coverage goes to 1 as the amount goes to 0.
    let edge = max(0.25 * object.clump_size * amount, 1e-6);
    let keep = clamp(margin / edge, 0.0, 1.0);
    return select(vec3<f32>(uv, 1.0), vec3<f32>(source, keep), amount > 0.0);
}

// The same along a fin (u in tiles): the clumps of one row of cells seen from the side.
// Returns (the u to sample, coverage).
fn clump_along(u: f32, height: f32, wetness: f32) -> vec2<f32> {
    let amount = clump_amount(height, wetness);
    let cell = floor(u / object.clump_size);
    var centres: array<f32, 3>;
    var nearest = 0u;
    var nearest_d = 3.4e38;
    for (var k = 0u; k < 3u; k++) {
        let c = clump_centre(vec2<f32>(cell + f32(k) - 1.0, 0.0)).x;
        centres[k] = c;
        if abs(u - c) < nearest_d {
            nearest_d = abs(u - c);
            nearest = k;
        }
    }
    let centre = centres[nearest];
    let source = centre + (u - centre) / (1.0 - amount);
    let own = abs(source - centre);
    var margin = 3.4e38;
    for (var k = 0u; k < 3u; k++) {
        if k != nearest {
            margin = min(margin, abs(source - centres[k]) - own);
        }
    }
    let edge = max(0.25 * object.clump_size * amount, 1e-6);
    let keep = clamp(margin / edge, 0.0, 1.0);
    return select(vec2<f32>(u, 1.0), vec2<f32>(source, keep), amount > 0.0);
}
