// Wet fur, appended to `shading.wgsl`: a strand's wetness (0 dry, 1 soaked) darkens its tint,
// raises its Kajiya-Kay highlight term (sharper and stronger) and adds to its clump amount, all
// per vertex; the fragments clump through the groom's `clump_uv` and part between clumps
// (`clump_parting`). Every term here is the dry one at wetness 0, and only the wet coats'
// pipelines run it (`wet_on`).

// A strand's groom terms with its wetness `w`: the tint darkened, the clump amount raised.
fn wet_groom(groom: GroomShade, wetness: f32) -> GroomShade {
    let w = clamp(wetness, 0.0, 1.0);
    // The fur model darkens through its BSDF's parameters instead (`fur_bsdf`).
    let tint = groom.tint * (1.0 - select(object.wet_darkening * w, 0.0, fur_model()));
    let clump = min(groom.clump + object.wet_clump * w, 1.0);
    return GroomShade(tint, groom.density, clump, w);
}

// The Kajiya-Kay terms (`hair_terms`) of a strand of wetness `w`: the highlight term
// sin^2 raised so that `hair_colour`'s pow(., shininess / 2) gives a lobe 1 + 2 shine w times
// sharper and 1 + shine w times stronger: pow(x, k) * pow(s, 2 / shininess) to the
// shininess / 2 is x^(k shininess / 2) * s. The terms themselves at w = 0.
fn wet_terms(terms: vec4<f32>, wetness: f32) -> vec4<f32> {
    if !wet_on() || wetness <= 0.0 {
        return terms;
    }
    let shine = 1.0 + object.wet_shine * clamp(wetness, 0.0, 1.0);
    let sharper = 2.0 * shine - 1.0;
    let raised = pow(max(terms.y, 0.0), sharper) * pow(shine, 2.0 / max(object.shininess, 1e-3));
    return vec4<f32>(terms.x, raised, terms.z, terms.w);
}

// A groomed or wet shell fragment's texel and where its strands were read: the uv (tiles) of
// the strands it shows, how the coat's clumping tilts them there (texels per fur length) and
// what is left of their own tilt (`wet_strand_terms`).
struct CoatRead {
    texel: vec4<f32>,
    read_uv: vec2<f32>,
    clump_tilt: vec2<f32>,
    own_tilt: f32,
}

// A wet, ungroomed shell fragment's texel at `uv` (tiles): the strands gathered toward their
// clump's centre as the strand reference gathers them (`wet_gather`), parted between clumps.
// Where nothing clumps (a dry strand of a wet coat) it is the dry fragment's very fetch, so dry
// parts of a wet coat keep their bytes.
fn wet_shell_texel(uv: vec2<f32>, slice: i32, clump: f32, height: f32) -> CoatRead {
    let cells = clump_cells_per_tile();
    let gather = wet_gather(uv, cells, clump, height);
    // The texel of the strand the gathering brings here, read over the fragment's own footprint
    // (the gathered position's gradients would blur the strands by the spread). Both reads run
    // so that neither sits in non-uniform control flow; the wet coats alone pay for the second.
    let dx = dpdx(uv) * SHELL_GRAD_SCALE;
    let dy = dpdy(uv) * SHELL_GRAD_SCALE;
    let gathered = textureSampleGrad(shell_texture, shell_sampler, gather.xy, slice, dx, dy);
    var texel = select(sample_shell(uv, slice), gathered, gather.w > 0.0);
    // The same strands keep their width in a (1 - a)^2 share of their cell: their coverage
    // compounds there as that many layers of it would.
    let spread = 1.0 / (1.0 - gather.w);
    let compounded = 1.0 - pow(1.0 - clamp(texel.a, 0.0, 1.0), spread * spread);
    texel.a = select(texel.a, compounded, gather.w > 0.0) * gather.z;
    // A strand at `centre + (q(t) - centre) * (1 - a(t))` moves by `q'(1 - a) - (q - centre) a'`
    // up its height: its own tilt shrunk by the gathering, and a pull toward the centre, which
    // is `(source - p) / a` away from the source in cells (`p` here, `source` its root).
    let a = gather.w;
    let toward = (gather.xy - uv) * cells / max(a, 1e-6);
    let pull = -toward * (CLUMP_PARTING * clamp(clump, 0.0, 1.0) * 0.65) * object.clump_cell_texels;
    return CoatRead(texel, gather.xy, select(vec2<f32>(0.0), pull, a > 0.0), 1.0 - a);
}

// A wet coat's lighting at a shell fragment, along the tangent of the strand it shows: the
// column tilted by that strand's own tilt (`strand_tilt`, read where the gathering reads it, the
// texels' tilts weighed by their coverage) and its clump's pull, in texels per fur length, which
// the fragment's uv derivatives turn into the world. A shell's vertex lights a whole triangle
// along one tangent, where the wet highlight, sharp, follows each strand's (FIDELITY.md): the
// strand's own lobes take over from the vertex's as the wetness sharpens it, wholly from
// `STRAND_LIT_WETNESS` (dry strands of a wet coat keep the dry coat's bytes). What the tangent
// does not decide (the shadow, the environment, other lights) stays the vertex's: Kajiya-Kay's
// lobes, or the fur model's key light lobes (`wet_key_light`).
fn wet_strand_terms(terms: vec4<f32>, uv: vec2<f32>, read: CoatRead, layer: u32, strand: WetStrand) -> vec4<f32> {
    let slice = shell_slice(layer);
    let premultiplied = textureSampleLevel(strand_tilt, shell_sampler, read.read_uv, slice, 0.0).rg;
    let coverage = textureSampleLevel(shell_texture, shell_sampler, read.read_uv, slice, 0.0).a;
    let own = premultiplied * (127.0 * TILT_STEP_TEXELS) / max(coverage, 1.0 / 255.0);
    let tilt = own * read.own_tilt + read.clump_tilt;
    // The world per tile along u and v at this fragment, from its screen-space derivatives.
    let dp_x = dpdx(strand.world_position);
    let dp_y = dpdy(strand.world_position);
    let duv_x = dpdx(uv);
    let duv_y = dpdy(uv);
    let det = duv_x.x * duv_y.y - duv_y.x * duv_x.y;
    let column = strand.column_wetness.xyz;
    let wetness = strand.column_wetness.w;
    // Without a frame or a length (the separated structure's shells) the vertex's terms.
    if abs(det) < 1e-20 || dot(column, column) < 1e-20 {
        return terms;
    }
    let along_u = (dp_x * duv_y.y - dp_y * duv_x.y) / det;
    let along_v = (dp_y * duv_x.x - dp_x * duv_y.x) / det;
    let texels = f32(textureDimensions(shell_texture).x);
    let base = normalize(column);
    let tangent = safe_normalize(column + (along_u * tilt.x + along_v * tilt.y) / texels, base);
    let share = clamp(wetness / STRAND_LIT_WETNESS, 0.0, 1.0);
    if fur_model() {
        let to_camera = safe_normalize(view.camera_position - strand.world_position, base);
        let to_light = light_incident(0u, strand.world_position).to_light;
        let lobes = fur_bsdf_lit(tangent, to_camera, to_light, strand.key.z, wetness) * strand.key.w;
        return vec4<f32>(max(terms.xy + (lobes - strand.key.xy) * share, vec2<f32>(0.0)), terms.zw);
    }
    let lobes = wet_terms(vec4<f32>(kajiya_kay_lobes(tangent, base, strand.world_position), terms.zw), wetness);
    return vec4<f32>(mix(terms.xy, lobes.xy, share), terms.zw);
}

// The fur model's key light (light 0) at a wet coat's shell vertex: its lobes along the
// column, as `fur_terms` adds them in, the normal's cosine to it and its luminance reaching the
// strands, shadow and all; 0 for Kajiya-Kay, a dry coat or a studio without lights.
fn wet_key_light(tangent: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>, wetness: f32) -> vec4<f32> {
    if !wet_on() || !fur_model() || lights.count == 0u {
        return vec4<f32>(0.0);
    }
    let incident = light_incident(0u, world_position);
    let to_camera = safe_normalize(view.camera_position - world_position, normal);
    let n_dot_l = dot(normal, incident.to_light);
    let weight = luminance(incident.irradiance) * strand_visibility(0u, world_position, normal);
    let wet = clamp(wetness, 0.0, 1.0);
    let lobes = fur_bsdf_lit(tangent, to_camera, incident.to_light, n_dot_l, wet) * weight;
    return vec4<f32>(lobes, n_dot_l, weight);
}

// The wetness from which a wet coat's shells light each texel along its strand alone.
const STRAND_LIT_WETNESS: f32 = 0.5;

// `FurTextures::strand_tilt`'s step (`pelt_core::texture::TILT_STEP_TEXELS`).
const TILT_STEP_TEXELS: f32 = 0.25;

// How much of a clumped fragment at `uv` (tiles) still shows strands: wet strands gather toward
// their cell's centre (the nearest jittered centre of `clump_uv`'s cells), so a fragment shows
// the strand rooted at `centre + (p - centre) / (1 - a)`, and where that root lies in another
// clump's cell no strand reaches it: the parting, down to the skin. `a` grows with the clump
// amount and the height (the roots part a little, so the skin shows along the partings); the
// edge is soft as the strands' lean makes it (`rooted_share`), so the partings close as the
// clump goes to 0.
fn clump_parting(uv: vec2<f32>, cells_per_tile: f32, clump: f32, height: f32) -> f32 {
    return wet_gather(uv, cells_per_tile, clump, height).z;
}

// `clump_parting`'s gathering at `uv` (tiles): the point the fragment's strands grow through at
// this height before gathering (in tiles), the coverage left by the parting, and `a`;
// `(uv, 1, 0)` where nothing gathers.
fn wet_gather(uv: vec2<f32>, cells_per_tile: f32, clump: f32, height: f32) -> vec4<f32> {
    let h = clamp(height, 0.0, 1.0);
    let a = CLUMP_PARTING * clamp(clump, 0.0, 1.0) * mix(0.35, 1.0, h);
    if a <= 0.0 {
        return vec4<f32>(uv, 1.0, 0.0);
    }
    let p = uv * cells_per_tile;
    let cell = floor(p);
    var centres: array<vec2<f32>, 9>;
    var nearest = 0u;
    var nearest_d2 = 3.4e38;
    for (var k = 0u; k < 9u; k++) {
        let c = cell + vec2<f32>(f32(k % 3u) - 1.0, f32(k / 3u) - 1.0);
        let centre = c + clump_jitter(c);
        centres[k] = centre;
        let d2 = dot(p - centre, p - centre);
        if d2 < nearest_d2 {
            nearest_d2 = d2;
            nearest = k;
        }
    }
    let centre = centres[nearest];
    let source = centre + (p - centre) / (1.0 - a);
    // How far the source lies inside its cell (negative: past the border), across the nearest
    // of the borders with the other cells.
    var inside = 3.4e38;
    for (var k = 0u; k < 9u; k++) {
        if k != nearest {
            let other = centres[k];
            let across = dot(source - other, source - other) - dot(source - centre, source - centre);
            inside = min(inside, across / (2.0 * distance(other, centre)));
        }
    }
    // The strands' mean lean at this height, in cells.
    let lean = object.lean_texels * h * cells_per_tile / f32(textureDimensions(shell_texture).x);
    return vec4<f32>(source / cells_per_tile, rooted_share(inside, a, lean), a);
}

// The share of the strands crossing a point `inside` cells within a clump cell's border
// (negative: past it) that grow from that cell, where the clump is chosen at the root (as the
// strand reference chooses it): of the strands that stand straight, those on its side (a soft
// step as wide as the gathering); of the leaning share (`Object::lean_share`), those whose root
// `lean` cells away in a direction all ways alike lies on its side.
fn rooted_share(inside: f32, a: f32, lean: f32) -> f32 {
    let straight = clamp(0.5 + inside / (0.125 * a), 0.0, 1.0);
    let leaning = 1.0 - acos(clamp(inside / max(lean, 1e-6), -1.0, 1.0)) / 3.14159265;
    return mix(straight, select(leaning, straight, lean <= 1e-6), clamp(object.lean_share, 0.0, 1.0));
}

// The most a soaked strand's clump gathers (in cell units, at the tips).
const CLUMP_PARTING: f32 = 0.6;
