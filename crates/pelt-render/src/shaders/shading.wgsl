// Shared by every Pelt pipeline: the view, the per-object uniforms, the fur textures and the
// lighting. `unified.wgsl` and `separated.wgsl` are appended to this file to make one module each.
//
// Bind groups: 0 = one view (`FurView`), 1 = one object (a fur or a plain mesh), 2 = the fur's
// textures (fur pipelines; empty for plain meshes), 3 = the lights' shadows (`shadows.wgsl`).

// One view, written by the host every frame (`ViewData`).
struct View {
    clip_from_world: mat4x4<f32>,
    camera_position: vec3<f32>,
    ambient: f32,
    // Unit vector toward the key light, world space.
    light_direction: vec3<f32>,
    padding_0: f32,
    // Linear RGB.
    light_colour: vec3<f32>,
    padding_1: f32,
}

// One fur or plain mesh (`object.rs`).
struct Object {
    world_from_model: mat4x4<f32>,
    // Inverse transpose of `world_from_model`'s upper 3x3: model normals to world normals.
    world_normal_from_model: mat3x3<f32>,
    // Furs: the colour of the roots, for the opaque skin. Plain meshes: their colour. Linear RGB.
    colour: vec4<f32>,
    // V: base vertices, the stride between layers.
    vertex_count: u32,
    // L: shells above the base (0 for a plain mesh).
    layers: u32,
    triangle_count: u32,
    edge_count: u32,
    has_uvs: u32,
    // 1 when strand colours are grey brightness to be multiplied by the surface texture.
    has_surface: u32,
    // Slices in the shell texture (may differ from `layers` while a viewer edits them).
    shell_slices: u32,
    // Meshes with uvs: the wedges the corner walk draws (`unified.wgsl`).
    wedge_count: u32,
    // Mesh uv -> tiles.
    tiles_per_uv: f32,
    // Model units -> tiles (triplanar projection and fins).
    tiles_per_world: f32,
    // Model units per uv unit (the separated structure recovers mesh uvs with it).
    world_per_uv: f32,
    // Weight of the current state against the previous one (unified structure).
    interpolation: f32,
    // |cos| between the view and a fin's faces below which the fin is fully shown.
    fin_fade_cos: f32,
    // |cos| between the view and the surface below which shells fade out.
    shell_fade_cos: f32,
    // Light left at the roots by self-shadowing (1 = none).
    root_occlusion: f32,
    specular: f32,
    // Kajiya-Kay specular exponent.
    shininess: f32,
    // Level of detail (`lod.rs`): every `lod_stride`-th layer counted down from the tips,
    // `lod_shells` of them, fading toward twice the stride by `lod_blend`.
    lod_blend: f32,
    lod_stride: u32,
    lod_shells: u32,
    // Shells by view angle: 1 when on, and the |n . v| range over which the layers twice the
    // stride drops fade out.
    lod_view: f32,
    lod_view_start: f32,
    lod_view_full: f32,
    // A groomed fur keeps its triangles with fur first and its edges with fins first (bald ones
    // after them, for the skin and the topology's lookups): the shells draw the first
    // `furred_triangle_count` triangles and the fins the first `fin_edge_count` edges.
    furred_triangle_count: u32,
    fin_edge_count: u32,
    // 1 when a groom's density, clump or tint reach the shading (0: none of their code runs).
    groom_shading: u32,
    // Wet fur (`wet.wgsl`): albedo times 1 - wet_darkening * w, the highlight times
    // 1 + wet_shine * w (its exponent 1 + 2 * wet_shine * w), a clump amount of wet_clump * w
    // added to the groom's, in cells of clump_cell_texels shell texels (a groom's too); wet_any
    // is 1 when some vertex is wet (else the wetness is never read).
    wet_darkening: f32,
    wet_shine: f32,
    wet_clump: f32,
    clump_cell_texels: f32,
    wet_any: u32,
    // 1 for the fur model (`fur_bsdf.wgsl`), 0 for Kajiya-Kay.
    shading_model: u32,
    // The fur model: the pigments' colour (multiplying the texel's), the lobes' longitudinal
    // roughness, the cuticle tilt (radians) and the medulla's share.
    fur_pigment: vec3<f32>,
    fur_roughness: f32,
    fur_cuticle_tilt: f32,
    fur_medulla: f32,
    // How much of the coat shows (`FurLevel::coat`): the shells' and fins' opacity.
    coat_fade: f32,
    // How much of the fins show (`FurLevel::fins`): their opacity, on top of the coat's.
    fin_fade: f32,
    // Multiplies the strands' albedo (`FurLook::tint`; the skin's colour is tinted on the CPU).
    tint: vec3<f32>,
    // The strands' lean (`StrandLean`): the share more than a texel off their roots at the tips
    // and their mean offset there, texels. Wet partings are as soft as it makes them.
    lean_share: f32,
    lean_texels: f32,
    // Where the listing passes find this copy in its pool (`pool.rs`), in `u32`s: its current
    // and previous state and its normals in the pool's buffers, and what it lists this frame
    // (`LIST_FINS`, `LIST_SHELLS`). The draws bind its own ranges and read none of it.
    pool: vec4<u32>,
}

// Set per pipeline: shells and fins with alpha-to-coverage output straight colour, blended ones
// premultiplied.
override ALPHA_TO_COVERAGE: bool = false;

// Set per pipeline for the unified coats (`renderer::Coat`): 1 off, 2 on, so a coat without a
// groom's shading or without wetness compiles none of that code (a software rasteriser runs
// every branch of a fragment, taken or not); 0 reads the object's flags instead.
override GROOM: u32 = 0u;
override WET: u32 = 0u;
// The same for the reflectance model: 1 Kajiya-Kay, 2 the fur model; 0 reads the object's.
override SHADING: u32 = 0u;

// Whether the fur model lights the strands (else Kajiya-Kay). Uniform.
fn fur_model() -> bool {
    if SHADING == 0u {
        return object.shading_model != 0u;
    }
    return SHADING == 2u;
}

// Whether the groom's density, clump or tint reach the shading. Uniform.
fn groom_on() -> bool {
    if GROOM == 0u {
        return object.groom_shading != 0u;
    }
    return GROOM == 2u;
}

// Whether some strand of the coat is wet (else the wetness is never read). Uniform.
fn wet_on() -> bool {
    if WET == 0u {
        return object.wet_any != 0u;
    }
    return WET == 2u;
}

@group(0) @binding(0) var<uniform> view: View;
// OBJECT BINDING: the listing passes replace this block (`shaders/mod.rs`).
@group(1) @binding(0) var<uniform> object: Object;
// The offsets of the fur's states and normals in the buffers at bindings 1 to 3: a draw binds
// the fur's own ranges.
fn current_base() -> u32 {
    return 0u;
}
fn previous_base() -> u32 {
    return 0u;
}
fn normals_base() -> u32 {
    return 0u;
}
// END OBJECT BINDING
@group(2) @binding(0) var shell_texture: texture_2d_array<f32>;
@group(2) @binding(1) var fin_texture: texture_2d<f32>;
@group(2) @binding(2) var shell_sampler: sampler;
// Each shell texel's strand keep value (`FurTextures::strand_keep`, R8, no mipmaps); a 1x1
// stand-in that keeps everything for furs without a groom.
@group(2) @binding(5) var strand_keep: texture_2d_array<f32>;
@group(2) @binding(3) var fin_sampler: sampler;
// Each shell texel's strand tilt times its coverage (`FurTextures::strand_tilt`, Rg8Snorm in
// steps of `TILT_STEP_TEXELS`); a 1x1 zero stand-in until a copy of the fur is wet.
@group(2) @binding(6) var strand_tilt: texture_2d_array<f32>;
// The mesh's colour texture (surface colour mode), else 1x1 white.
@group(2) @binding(4) var surface_texture: texture_2d<f32>;

struct Varyings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) world_position: vec3<f32>,
    // Base surface normal in world space (stable while the fur moves).
    @location(1) normal: vec3<f32>,
    // Strand direction from the simulated shared vertices, world space.
    @location(2) tangent: vec3<f32>,
    // Shells: root position in tiles, model space (triplanar lookup). Fins: unused.
    @location(3) tile_position: vec3<f32>,
    // Shells: mesh uv in tiles. Fins: (along the edge in tiles, height).
    @location(4) uv: vec2<f32>,
    // Shell layer (1..=L); 0 for the skin and fins.
    @location(5) @interpolate(flat) layer: u32,
    // 0 at the roots, 1 at the tips.
    @location(6) height: f32,
    // Opacity from the view angle (fin and shell fading).
    @location(7) fade: f32,
    // Shell texture slice.
    @location(8) @interpolate(flat) slice: i32,
    // The mesh uv at the strand's root (surface colour mode).
    @location(9) surface_uv: vec2<f32>,
    // Shells without mesh uvs: the base normal in model space, which picks the axis-aligned
    // projection of the tiles (fixed to the model, so it moves with it).
    @location(10) tile_normal: vec3<f32>,
    // The skin and plain meshes: how many of the view's lights light them (`Lights::count`),
    // handed on by the vertex so no fragment branches on a uniform alone: lavapipe (Mesa 22.3)
    // inlines such uniforms into fragment shaders and compiles anew whenever another view's
    // buffer is bound (alternating views cost a frame five times over).
    @location(11) @interpolate(flat) light_count: u32,
}

// What a shell fragment reads and nothing more, packed four to a location: software
// rasterisers set up and interpolate every declared varying of every triangle, read or not, and
// the shells are most of the fur's triangles. The lighting's geometric terms come from the
// vertex (`hair_terms`), not the normal, tangent and position they are made of. One struct per
// way of finding the texel; the layer rides as a float (the same value at every corner, so
// interpolation keeps it), and `height` and `slice` follow from it.
struct ShellTileVaryings {
    @builtin(position) clip_position: vec4<f32>,
    // `hair_terms` at the vertex.
    @location(0) @interpolate(perspective, centroid) lighting: vec4<f32>,
    // The opacity from the view angle (`shell_fade`), how far the layers the next coarser stride
    // drops have faded here (`lod_vertex_blend`), and the layer.
    @location(1) @interpolate(perspective, centroid) fade_blend_layer: vec3<f32>,
    // The root in tiles, model space, and the base normal picking its projection.
    @location(2) @interpolate(perspective, centroid) tile_position: vec3<f32>,
    @location(3) @interpolate(perspective, centroid) tile_normal: vec3<f32>,
}

struct ShellUvVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) fade_blend_layer: vec3<f32>,
    // The mesh uv in tiles (xy) and at the strand's root (zw, surface colour mode).
    @location(2) @interpolate(perspective, centroid) uvs: vec4<f32>,
}

// The groomed or wet coats' shells: the lean ones' and the groom's terms at the root (its
// clump rides in `fade_blend_layer.w`), and a wet coat's strand (`WetStrand`). Only their
// pipelines pay for the extra locations.
struct GroomedShellTileVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) fade_blend_layer: vec4<f32>,
    @location(2) @interpolate(perspective, centroid) tile_position: vec3<f32>,
    @location(3) @interpolate(perspective, centroid) tile_normal: vec3<f32>,
    // The groom's tint (rgb) and density (`GroomShade`).
    @location(4) @interpolate(perspective, centroid) tint_density: vec4<f32>,
    @location(5) @interpolate(perspective, centroid) column_wetness: vec4<f32>,
    @location(6) @interpolate(perspective, centroid) world_position: vec3<f32>,
    @location(7) @interpolate(perspective, centroid) key: vec4<f32>,
}

struct GroomedShellUvVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) fade_blend_layer: vec4<f32>,
    @location(2) @interpolate(perspective, centroid) uvs: vec4<f32>,
    @location(3) @interpolate(perspective, centroid) tint_density: vec4<f32>,
    // A wet coat's strand (`WetStrand`).
    @location(4) @interpolate(perspective, centroid) column_wetness: vec4<f32>,
    @location(5) @interpolate(perspective, centroid) world_position: vec3<f32>,
    @location(6) @interpolate(perspective, centroid) key: vec4<f32>,
}

// What a wet coat's shell fragment lights its strand with (`wet_strand_terms`): the strand's
// column across the fur's length (world, as long as the fur) and its wetness, where it is, and
// the fur model's key light at the vertex (`wet_key_light`).
struct WetStrand {
    column_wetness: vec4<f32>,
    world_position: vec3<f32>,
    key: vec4<f32>,
}

// A groom's shading terms at a strand's root (`GroomAttributes` of its base vertex): the
// uniform fur's are `GROOM_NONE`.
struct GroomShade {
    tint: vec3<f32>,
    density: f32,
    clump: f32,
    // The strand's wetness (`wet_groom`), read by the vertex only.
    wetness: f32,
}

const GROOM_NONE = GroomShade(vec3<f32>(1.0), 1.0, 0.0, 0.0);

// One vertex's entry in a groom attribute buffer (`groom_attributes` in `unified.wgsl` and
// `separated.wgsl`; written by `geometry.rs`).
struct GroomAttributes {
    tint: vec3<f32>,
    density: f32,
    clump: f32,
}

fn groom_shade(g: GroomAttributes) -> GroomShade {
    return GroomShade(g.tint, g.density, g.clump, 0.0);
}

// The lean shell interfaces from the full surface varyings (the unified and separated shells
// build theirs the same way); `fade` and `lod_blend` are the caller's, computed or carried.
fn shell_lighting(v: Varyings) -> vec4<f32> {
    return hair_terms(v.tangent, v.normal, v.world_position, layer_height(v.layer));
}

fn shell_tile_varyings(v: Varyings, fade: f32, lod_blend: f32) -> ShellTileVaryings {
    let fade_blend_layer = vec3<f32>(fade, lod_blend, f32(v.layer));
    return ShellTileVaryings(v.clip_position, shell_lighting(v), fade_blend_layer, v.tile_position, v.tile_normal);
}

fn shell_uv_varyings(v: Varyings, fade: f32, lod_blend: f32) -> ShellUvVaryings {
    let fade_blend_layer = vec3<f32>(fade, lod_blend, f32(v.layer));
    return ShellUvVaryings(v.clip_position, shell_lighting(v), fade_blend_layer, vec4<f32>(v.uv, v.surface_uv));
}

// `fur_length`: the strand's length in the world at this vertex (0: the wet strands are lit
// along their columns).
fn groomed_shell_tile_varyings(v: Varyings, fade: f32, lod_blend: f32, groom: GroomShade, fur_length: f32) -> GroomedShellTileVaryings {
    let fade_blend_layer = vec4<f32>(fade, lod_blend, f32(v.layer), groom.clump);
    let tint_density = vec4<f32>(groom.tint, groom.density);
    let lighting = coat_terms(v.tangent, v.normal, v.world_position, layer_height(v.layer), groom.wetness);
    let column = vec4<f32>(v.tangent * fur_length, groom.wetness);
    let key = wet_key_light(v.tangent, v.normal, v.world_position, groom.wetness);
    return GroomedShellTileVaryings(v.clip_position, lighting, fade_blend_layer, v.tile_position, v.tile_normal, tint_density, column, v.world_position, key);
}

fn groomed_shell_uv_varyings(v: Varyings, fade: f32, lod_blend: f32, groom: GroomShade, fur_length: f32) -> GroomedShellUvVaryings {
    let fade_blend_layer = vec4<f32>(fade, lod_blend, f32(v.layer), groom.clump);
    let tint_density = vec4<f32>(groom.tint, groom.density);
    let lighting = coat_terms(v.tangent, v.normal, v.world_position, layer_height(v.layer), groom.wetness);
    let column = vec4<f32>(v.tangent * fur_length, groom.wetness);
    let key = wet_key_light(v.tangent, v.normal, v.world_position, groom.wetness);
    return GroomedShellUvVaryings(v.clip_position, lighting, fade_blend_layer, vec4<f32>(v.uv, v.surface_uv), tint_density, column, v.world_position, key);
}

// The layer a shell fragment carries: interpolated from three equal corners, so within rounding.
fn varying_layer(value: f32) -> u32 {
    return u32(round(value));
}

// What a unified fin fragment reads, for the same reason as the shells' structs, in two
// locations (four before: 0.1-0.25 ms less of the bunny's fins on lavapipe, whose `2L` small
// triangles a fin carry each location).
struct FinVaryings {
    @builtin(position) clip_position: vec4<f32>,
    // `hair_terms` at the vertex without the occlusion (the fragment takes it from the height),
    // and the fin's fade.
    @location(0) @interpolate(perspective, centroid) lighting_fade: vec4<f32>,
    // Along the edge in tiles, the height (0 at the roots, 1 at the tips), and the mesh uv at
    // this end of the edge (surface colour mode).
    @location(1) @interpolate(perspective, centroid) uvs: vec4<f32>,
}

// The groomed or wet coats' fins: the lean ones' and the groom's terms.
struct GroomedFinVaryings {
    @builtin(position) clip_position: vec4<f32>,
    @location(0) @interpolate(perspective, centroid) lighting_fade: vec4<f32>,
    @location(1) @interpolate(perspective, centroid) uvs: vec4<f32>,
    // The groom's tint and density, and its clump (`GroomShade`).
    @location(2) @interpolate(perspective, centroid) tint_density: vec4<f32>,
    @location(3) @interpolate(perspective, centroid) clump: f32,
}

// Set per pipeline where every mesh it draws has uvs (1) or none has (2), so the shaders drop
// the other case's varyings and fetches; 0 reads `object.has_uvs`.
override MESH_UVS: u32 = 0u;

fn uses_mesh_uvs() -> bool {
    if MESH_UVS == 0u {
        return object.has_uvs != 0u;
    }
    return MESH_UVS == 1u;
}

// The mesh uv at the strand's root: always the origin for meshes without uvs.
fn root_surface_uv(in: Varyings) -> vec2<f32> {
    if MESH_UVS == 2u {
        return vec2<f32>(0.0);
    }
    return in.surface_uv;
}

fn safe_normalize(v: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let length_squared = dot(v, v);
    if length_squared > 1e-20 {
        return v * inverseSqrt(length_squared);
    }
    return fallback;
}

fn world_from_model_point(p: vec3<f32>) -> vec3<f32> {
    return (object.world_from_model * vec4<f32>(p, 1.0)).xyz;
}

fn world_from_model_direction(d: vec3<f32>) -> vec3<f32> {
    return (object.world_from_model * vec4<f32>(d, 0.0)).xyz;
}

// A model-space normal in world space, unit length (zero stays zero).
fn world_from_model_normal(n: vec3<f32>) -> vec3<f32> {
    return safe_normalize(object.world_normal_from_model * n, vec3<f32>(0.0));
}

// Shell layer i (1..=L) shows slice i - 1, scaled when the texture has another count.
fn shell_slice(layer: u32) -> i32 {
    return i32(((max(layer, 1u) - 1u) * object.shell_slices) / max(object.layers, 1u));
}

fn layer_height(layer: u32) -> f32 {
    return f32(layer) / f32(max(object.layers, 1u));
}

// Shell `k` (0..lod_shells) of the level of detail: counted down from the tips, so they show.
fn lod_shell_layer(k: u32) -> u32 {
    return object.layers - (object.lod_shells - 1u - k) * object.lod_stride;
}

// Fin node `n` (0..=lod_shells): the root, then the level's shells.
fn lod_fin_layer(n: u32) -> u32 {
    if n == 0u {
        return 0u;
    }
    return lod_shell_layer(n - 1u);
}

// Whether the next coarser level drops `layer` (it fades out by `lod_blend`).
fn lod_dropped(layer: u32) -> bool {
    return ((object.layers - layer) / object.lod_stride) % 2u == 1u;
}

// Shells by view angle (Yang et al.): 0..1, how far the layers the next coarser stride drops
// have faded at a strand whose root is at `root` (world) with base normal `normal` (world, unit):
// 0 where the surface is seen edge-on, 1 where it faces the eye (`lod_view_full` of |n . v|).
// `view_lod.wgsl` culls with the same function, so it must stay a function of the root alone.
fn lod_view_weight(normal: vec3<f32>, root: vec3<f32>) -> f32 {
    let to_camera = safe_normalize(view.camera_position - root, normal);
    let facing = abs(dot(normal, to_camera));
    return object.lod_view * smoothstep(object.lod_view_start, object.lod_view_full, facing);
}

// The blend toward the next stride at a shell vertex: the distance level's and the view
// angle's composed, so either alone fades the dropped layers and both together never exceed 1.
fn lod_vertex_blend(view_weight: f32) -> f32 {
    return 1.0 - (1.0 - object.lod_blend) * (1.0 - view_weight);
}

// A shell's alpha at the level of detail: each drawn shell stands for `lod_stride` layers (the
// opacity of that many), the ones the next level drops fade out by `blend` (`lod_vertex_blend`,
// interpolated) while the kept ones take on their opacity. Exactly `alpha` at full detail.
fn lod_alpha(alpha: f32, layer: u32, blend: f32) -> f32 {
    if object.lod_stride == 1u && blend <= 0.0 {
        return alpha;
    }
    let clear = 1.0 - clamp(alpha, 0.0, 1.0);
    let stride = f32(object.lod_stride);
    let b = clamp(blend, 0.0, 1.0);
    if lod_dropped(layer) {
        return (1.0 - pow(clear, stride)) * (1.0 - b);
    }
    return 1.0 - pow(clear, stride * (1.0 + b));
}

// Shells fade where the surface is seen edge-on (where the sheets would show).
fn shell_fade(normal: vec3<f32>, world_position: vec3<f32>) -> f32 {
    let to_camera = safe_normalize(view.camera_position - world_position, normal);
    let facing = abs(dot(normal, to_camera));
    return mix(0.5, 1.0, smoothstep(0.0, object.shell_fade_cos, facing));
}

// Darkening toward the roots: strands shadow each other deeper in the coat.
fn occlusion(height: f32) -> f32 {
    return mix(object.root_occlusion, 1.0, pow(clamp(height, 0.0, 1.0), 0.7));
}

// Kajiya-Kay hair lighting around the strand tangent, gated by the surface normal so the side
// of the body facing away from the light stays dark. Split in two: the geometric terms, smooth
// over a triangle, which the shells compute per vertex (`hair_terms`), and the colour from them
// per fragment (`hair_colour`), which takes the texel's albedo.
fn hair_lighting(albedo: vec3<f32>, tangent: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>, height: f32) -> vec3<f32> {
    return hair_colour(albedo, hair_terms(tangent, normal, world_position, height), height);
}

// (sin of the angle between strand and light, its square toward the half vector, how lit the
// side is, occlusion) for a unit strand tangent and surface normal: the Kajiya-Kay terms
// themselves, so that interpolating them across a shell triangle is exact at the corners and
// unbiased between them (interpolating `t . l` instead reads the shortened interpolated tangent
// and brightens the fur). The fragment is left two square roots, a normalisation, a power and a
// smoothstep fewer (BENCHMARKS.md: a quarter of the shells' frame at 1280x720 on lavapipe).
fn hair_terms(tangent: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>, height: f32) -> vec4<f32> {
    if fur_model() {
        return fur_terms(tangent, normal, world_position, height, 0.0);
    }
    return kajiya_kay_terms(tangent, normal, world_position, height);
}

// The terms of a strand of wetness `wetness`: the fur model's with its wet parameters, or the
// Kajiya-Kay terms with the wet highlight (`wet_terms`).
fn coat_terms(tangent: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>, height: f32, wetness: f32) -> vec4<f32> {
    if fur_model() {
        return fur_terms(tangent, normal, world_position, height, select(0.0, wetness, wet_on()));
    }
    return wet_terms(kajiya_kay_terms(tangent, normal, world_position, height), wetness);
}

fn kajiya_kay_terms(tangent: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>, height: f32) -> vec4<f32> {
    let to_light = view.light_direction;
    // The key light's shadow at the vertex: the fur's transmittance is smooth, and a shell
    // fragment then pays for no lookup.
    let lit_side = smoothstep(-0.25, 0.6, dot(normal, to_light)) * strand_visibility(0u, world_position, normal);
    return vec4<f32>(kajiya_kay_lobes(tangent, normal, world_position), lit_side, occlusion(height));
}

// The Kajiya-Kay terms that follow the strand's tangent: the sine to the light, and its square
// to the half vector.
fn kajiya_kay_lobes(tangent: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>) -> vec2<f32> {
    let to_light = view.light_direction;
    let to_camera = safe_normalize(view.camera_position - world_position, normal);
    let half_vector = safe_normalize(to_light + to_camera, to_light);
    let t_dot_l = dot(tangent, to_light);
    let t_dot_h = dot(tangent, half_vector);
    return vec2<f32>(sqrt(max(1.0 - t_dot_l * t_dot_l, 0.0)), max(1.0 - t_dot_h * t_dot_h, 0.0));
}

fn hair_colour(texel_albedo: vec3<f32>, terms: vec4<f32>, height: f32) -> vec3<f32> {
    let albedo = texel_albedo * object.tint;
    if fur_model() {
        return fur_colour(albedo, terms);
    }
    let diffuse = terms.x;
    // sin^shininess of the angle to the half vector, as (sin^2)^(shininess / 2).
    let specular = pow(max(terms.y, 0.0), 0.5 * object.shininess);
    let ao = terms.w;
    let light = view.light_colour * terms.z;
    let colour = albedo * (view.ambient + light * diffuse * 0.85) * ao;
    // The highlight takes some of the strand's colour, as light scattered in hair does.
    let highlight = mix(vec3<f32>(1.0), albedo / max(max(albedo.r, albedo.g), max(albedo.b, 1e-3)), 0.5);
    return colour + light * highlight * (specular * object.specular * ao * height);
}

// Lambert with a soft terminator for surfaces without fur (the skin, plain meshes): the view's
// lights, each shadowed; its one key light where it has no others or its maps hold the key
// light's view alone (`SHADOW_KEY_ONLY`: Pelt's studio, whose frame the loop slowed on lavapipe).
fn surface_lighting(albedo: vec3<f32>, normal: vec3<f32>, world_position: vec3<f32>, light_count: u32) -> vec3<f32> {
    if SHADOW_KEY_ONLY || light_count == 0u {
        let wrapped = max(dot(normal, view.light_direction) * 0.7 + 0.3, 0.0);
        let visibility = light_visibility(0u, world_position, normal);
        return albedo * (view.ambient + view.light_colour * wrapped * visibility);
    }
    var light = vec3<f32>(0.0);
    for (var i = 0u; i < min(light_count, 8u); i++) {
        let incident = light_incident(i, world_position);
        let wrapped = max(dot(normal, incident.to_light) * 0.7 + 0.3, 0.0);
        light += incident.irradiance * (wrapped * light_visibility(i, world_position, normal));
    }
    // Irradiance / pi: a white surface facing a sun of pi lux shows 1.
    return albedo * (view.ambient + light * 0.31830988);
}

// Shell slices are sampled half a mip level sharper than the hardware's choice: trilinear
// filtering at its level spreads a strand over about twice a pixel's footprint, which `pelt
// fidelity` measures as the largest loss against the explicit strands (FIDELITY.md). A whole
// level sharper measures closer still but makes moving fur flicker (cli_render's fox test).
const SHELL_LOD_BIAS: f32 = -0.5;

fn sample_shell(uv: vec2<f32>, slice: i32) -> vec4<f32> {
    return textureSampleBias(shell_texture, shell_sampler, uv, slice, SHELL_LOD_BIAS);
}

// The axis-aligned projection of the tiles for a surface with model-space normal `n`: the axis it
// faces most (0 = x, 1 = y, 2 = z).
fn tile_axis(n: vec3<f32>) -> u32 {
    let a = abs(n);
    if a.x >= a.y && a.x >= a.z {
        return 0u;
    }
    return select(2u, 1u, a.y >= a.z);
}

// The shell uv (in tiles) of a mesh without uvs at `tile_position` (the root in tiles, model
// space): the one axis-aligned projection the surface faces most, so one texture fetch a
// fragment, the largest part of a shell fragment's cost on software rasterisers (a blend of all
// three cost three). The tiles are strand dots, so the seams where the projection changes do not
// show (SSIM test in tests/lean.rs).
fn tile_uv(tile_position: vec3<f32>, tile_normal: vec3<f32>) -> vec2<f32> {
    let p = tile_position;
    let axis = tile_axis(tile_normal);
    return select(select(p.xy, p.zx, axis == 1u), p.yz, axis == 0u);
}

// Clumping: strands gather toward the centres of clump cells, a jittered grid of
// `cells_per_tile` cells along each side of a tile. `uv` is in tiles, `amount` (0..1) how far
// toward its cell's centre the sampling moves: 0 leaves `uv` as it is, 1 reads the centre
// alone. The texture is sampled closer to the centre than the fragment lies, so the strands near
// a centre spread over its cell and the fur parts into tufts, more toward the tips when
// `amount` grows with the height. Used by a groom's clump map (`groom_clump_amount`); wet fur
// can drive it with its wetness.
fn clump_uv(uv: vec2<f32>, cells_per_tile: f32, amount: f32) -> vec2<f32> {
    let a = clamp(amount, 0.0, 1.0);
    let p = uv * cells_per_tile;
    let cell = floor(p);
    var centre = cell + 0.5;
    var best = 1e30;
    for (var dy = -1; dy <= 1; dy++) {
        for (var dx = -1; dx <= 1; dx++) {
            let c = cell + vec2<f32>(f32(dx), f32(dy));
            let candidate = c + clump_jitter(c);
            let to_candidate = candidate - p;
            let d = dot(to_candidate, to_candidate);
            if d < best {
                best = d;
                centre = candidate;
            }
        }
    }
    return mix(p, centre, a) / cells_per_tile;
}

// A clump cell's centre within it (0.15..0.85 on each axis), seeded by the cell.
fn clump_jitter(cell: vec2<f32>) -> vec2<f32> {
    let c = vec2<u32>(bitcast<u32>(i32(cell.x)), bitcast<u32>(i32(cell.y)));
    let bits = groom_hash((c.x * 0x8da6b343u) ^ groom_hash(c.y ^ 0x68e31da4u));
    let unit = vec2<f32>(f32(bits & 0xffffu), f32(bits >> 16u)) / 65536.0;
    return 0.15 + 0.7 * unit;
}

fn groom_hash(x: u32) -> u32 {
    var h = x * 0x9e3779b9u;
    h = (h ^ (h >> 16u)) * 0x85ebca6bu;
    h = (h ^ (h >> 13u)) * 0xc2b2ae35u;
    return h ^ (h >> 16u);
}

// Clump cells are `object.clump_cell_texels` shell texels wide (`FurLook::clump_size`, 12 by
// default; the textures' own clumps are 10).
fn clump_cells_per_tile() -> f32 {
    return f32(textureDimensions(shell_texture).x) / object.clump_cell_texels;
}

// How far a groom's clump map pulls at `height`: nothing at the roots, growing to
// `CLUMP_MAX_PULL` times the map's value at the tips (a full pull would read one texel for a
// whole cell: flat polygons rather than tufts).
fn groom_clump_amount(clump: f32, height: f32) -> f32 {
    return CLUMP_MAX_PULL * clamp(clump, 0.0, 1.0) * clamp(height, 0.0, 1.0);
}

const CLUMP_MAX_PULL: f32 = 0.8;

// Density: whether the strand covering the shell texel at `uv` (tiles) in `slice` survives a
// density of `density` (its seeded keep value below the density), so 0.5 keeps about half the
// strands, each whole, without new textures.
fn strand_kept(uv: vec2<f32>, slice: i32, density: f32) -> bool {
    let size = textureDimensions(strand_keep);
    let texel = vec2<i32>(floor(fract(uv) * vec2<f32>(size)));
    let layer = min(slice, i32(textureNumLayers(strand_keep)) - 1);
    let clamped = clamp(texel, vec2<i32>(0), vec2<i32>(size) - 1);
    let keep = textureLoad(strand_keep, clamped, layer, 0).r;
    return (round(keep * 255.0) + 0.5) / 256.0 < density;
}

// A groomed shell fragment's texel at `uv` (tiles): clumped, thinned by the density. The
// gradients are the unclumped uv's, so the cells' borders pick no other mip level.
fn groomed_shell_texel(uv: vec2<f32>, slice: i32, groom: GroomShade, height: f32) -> CoatRead {
    let dx = dpdx(uv) * SHELL_GRAD_SCALE;
    let dy = dpdy(uv) * SHELL_GRAD_SCALE;
    let sampled = clump_uv(uv, clump_cells_per_tile(), groom_clump_amount(groom.clump, height));
    var texel = textureSampleGrad(shell_texture, shell_sampler, sampled, slice, dx, dy);
    if !strand_kept(sampled, slice, groom.density) {
        texel.a = 0.0;
    }
    // Only wet fur parts between its clumps.
    if wet_on() {
        texel.a *= clump_parting(uv, clump_cells_per_tile(), groom.clump, height);
    }
    // The groom's clumps tilt no strand here: it reads the strands it pulls in whole.
    return CoatRead(texel, sampled, vec2<f32>(0.0), 1.0);
}

// `SHELL_LOD_BIAS` as a scale on the gradients (2^bias).
const SHELL_GRAD_SCALE: f32 = 0.70710678;

// The groom's terms a shell fragment carries.
fn shell_groom(fade_blend_layer: vec4<f32>, tint_density: vec4<f32>) -> GroomShade {
    return GroomShade(tint_density.rgb, tint_density.a, fade_blend_layer.w, 0.0);
}

// The shell texel of a mesh without uvs at `tile_position` (the root in tiles, model space).
fn tile_texel(tile_position: vec3<f32>, tile_normal: vec3<f32>, layer: u32) -> vec4<f32> {
    return sample_shell(tile_uv(tile_position, tile_normal), shell_slice(layer));
}

// Surface colour mode: the mesh's texture at the strand's root tints the strand's brightness.
fn surface_tint(uv: vec2<f32>) -> vec3<f32> {
    // A uniform branch: furs without a surface texture skip the fetch.
    if object.has_surface == 0u {
        return vec3<f32>(1.0);
    }
    return textureSample(surface_texture, shell_sampler, uv).rgb;
}

fn fur_output(colour: vec3<f32>, alpha: f32) -> vec4<f32> {
    if ALPHA_TO_COVERAGE {
        return vec4<f32>(colour, alpha);
    }
    // Premultiplied for the (One, OneMinusSrcAlpha) blend.
    return vec4<f32>(colour * alpha, alpha);
}

// Plain meshes (no fur, e.g. the body under a furry garment): lit in the object's colour.
@fragment
fn fs_plain(in: Varyings) -> @location(0) vec4<f32> {
    return vec4<f32>(surface_lighting(object.colour.rgb, normalize(in.normal), in.world_position, in.light_count), 1.0);
}

// The opaque skin under the fur, in the colour of the roots.
@fragment
fn fs_skin(in: Varyings) -> @location(0) vec4<f32> {
    return skin_colour(in);
}

fn skin_colour(in: Varyings) -> vec4<f32> {
    let normal = normalize(in.normal);
    let albedo = object.colour.rgb * surface_tint(root_surface_uv(in));
    let colour = surface_lighting(albedo, normal, in.world_position, in.light_count) * object.root_occlusion;
    return vec4<f32>(colour, 1.0);
}

// A shell fragment from its texel: fading, level of detail, the groom's tint and hair lighting.
fn shell_colour(texel: vec4<f32>, surface_uv: vec2<f32>, lighting: vec4<f32>, fade_blend_layer: vec3<f32>, tint: vec3<f32>) -> vec4<f32> {
    let layer = varying_layer(fade_blend_layer.z);
    let alpha = lod_alpha(texel.a * fade_blend_layer.x, layer, fade_blend_layer.y) * object.coat_fade;
    let albedo = texel.rgb * surface_tint(surface_uv) * tint;
    return fur_output(hair_colour(albedo, lighting, layer_height(layer)), alpha);
}

// Shells of meshes without uvs (`vs_shell_indexed`, `vs_separated_shell_tiles`).
@fragment
fn fs_shell_tiles(in: ShellTileVaryings) -> @location(0) vec4<f32> {
    return shell_tiles_colour(in);
}

fn shell_tiles_colour(in: ShellTileVaryings) -> vec4<f32> {
    let texel = tile_texel(in.tile_position, in.tile_normal, varying_layer(in.fade_blend_layer.z));
    return shell_colour(texel, vec2<f32>(0.0), in.lighting, in.fade_blend_layer, vec3<f32>(1.0));
}

// Shells of meshes with uvs (`vs_shell_wedges`, `vs_separated_shell_uvs`).
@fragment
fn fs_shell_uvs(in: ShellUvVaryings) -> @location(0) vec4<f32> {
    return shell_uvs_colour(in);
}

fn shell_uvs_colour(in: ShellUvVaryings) -> vec4<f32> {
    let texel = sample_shell(in.uvs.xy, shell_slice(varying_layer(in.fade_blend_layer.z)));
    return shell_colour(texel, in.uvs.zw, in.lighting, in.fade_blend_layer, vec3<f32>(1.0));
}

// A groomed or wet coat's shell texel at `uv` (tiles): a groom's clumped and thinned one, or a
// wet coat's clumped and parted one.
fn coat_shell_texel(uv: vec2<f32>, layer: u32, groom: GroomShade) -> vec4<f32> {
    return coat_shell_read(uv, layer, groom).texel;
}

// `coat_shell_texel` and where its strands were read (`CoatRead`).
fn coat_shell_read(uv: vec2<f32>, layer: u32, groom: GroomShade) -> CoatRead {
    if groom_on() {
        return groomed_shell_texel(uv, shell_slice(layer), groom, layer_height(layer));
    }
    return wet_shell_texel(uv, shell_slice(layer), groom.clump, layer_height(layer));
}

// A groomed or wet coat's shell fragment: its texel, lit by the vertex's terms, or a wet coat's
// along the strand the texel shows (`wet_strand_terms`).
fn coat_shell_colour(uv: vec2<f32>, surface_uv: vec2<f32>, lighting: vec4<f32>, fade_blend_layer: vec4<f32>, tint_density: vec4<f32>, strand: WetStrand) -> vec4<f32> {
    let layer = varying_layer(fade_blend_layer.z);
    let groom = shell_groom(fade_blend_layer, tint_density);
    let read = coat_shell_read(uv, layer, groom);
    var terms = lighting;
    if wet_on() {
        terms = wet_strand_terms(lighting, uv, read, layer, strand);
    }
    return shell_colour(read.texel, surface_uv, terms, fade_blend_layer.xyz, tint_density.rgb);
}

@fragment
fn fs_shell_tiles_groomed(in: GroomedShellTileVaryings) -> @location(0) vec4<f32> {
    return shell_tiles_groomed_colour(in);
}

fn shell_tiles_groomed_colour(in: GroomedShellTileVaryings) -> vec4<f32> {
    let strand = WetStrand(in.column_wetness, in.world_position, in.key);
    let uv = tile_uv(in.tile_position, in.tile_normal);
    return coat_shell_colour(uv, vec2<f32>(0.0), in.lighting, in.fade_blend_layer, in.tint_density, strand);
}

@fragment
fn fs_shell_uvs_groomed(in: GroomedShellUvVaryings) -> @location(0) vec4<f32> {
    return shell_uvs_groomed_colour(in);
}

fn shell_uvs_groomed_colour(in: GroomedShellUvVaryings) -> vec4<f32> {
    let strand = WetStrand(in.column_wetness, in.world_position, in.key);
    return coat_shell_colour(in.uvs.xy, in.uvs.zw, in.lighting, in.fade_blend_layer, in.tint_density, strand);
}

// Seen from the side the roots are less hidden than from above: fins light and occlude their
// strands as if they stood higher.
fn fin_lighting_height(height: f32) -> f32 {
    return sqrt(max(height, 0.0));
}

// Several fins overlap along a silhouette; thinning them keeps the fringe from reading as a
// solid band, most of all at the roots where the shells already cover.
fn fin_colour(texel: vec4<f32>, lighting_fade: vec4<f32>, uvs: vec4<f32>, tint: vec3<f32>, groom_alpha: f32) -> vec4<f32> {
    let height = uvs.y;
    let alpha = texel.a * lighting_fade.w * mix(0.15, 0.6, height) * groom_alpha * object.coat_fade * object.fin_fade;
    let albedo = texel.rgb * surface_tint(uvs.zw) * tint;
    let lit_height = fin_lighting_height(height);
    let lighting = vec4<f32>(lighting_fade.xyz, occlusion(lit_height));
    return fur_output(hair_colour(albedo, lighting, lit_height), alpha);
}

// Fin texture rows run from the tips (v = 0) to the roots (v = 1).
fn fin_texture_uv(uvs: vec4<f32>) -> vec2<f32> {
    return vec2<f32>(uvs.x, 1.0 - uvs.y);
}

@fragment
fn fs_fin(in: FinVaryings) -> @location(0) vec4<f32> {
    return fin_lean_colour(in);
}

fn fin_lean_colour(in: FinVaryings) -> vec4<f32> {
    let texel = textureSample(fin_texture, fin_sampler, fin_texture_uv(in.uvs));
    return fin_colour(texel, in.lighting_fade, in.uvs, vec3<f32>(1.0), 1.0);
}

// The fin is the side view of a band of strands: clumps gather along the edge, and a thinner
// coat is a fainter fringe (the density scales its opacity).
@fragment
fn fs_fin_groomed(in: GroomedFinVaryings) -> @location(0) vec4<f32> {
    return fin_groomed_colour(in);
}

fn fin_groomed_colour(in: GroomedFinVaryings) -> vec4<f32> {
    let height = in.uvs.y;
    let fin_uv = fin_texture_uv(in.uvs);
    let dx = dpdx(fin_uv);
    let dy = dpdy(fin_uv);
    let cells = clump_cells_per_tile();
    var texel: vec4<f32>;
    if groom_on() {
        let along = clump_uv(vec2<f32>(fin_uv.x, 0.5 / cells), cells, groom_clump_amount(in.clump, height)).x;
        texel = textureSampleGrad(fin_texture, fin_sampler, vec2<f32>(along, fin_uv.y), dx, dy);
    } else {
        // Wet only: the strand the gathering brings here, as the wet shells read it, its coverage
        // compounded along the fin; where nothing clumps, the dry fin's very fetch.
        let gather = wet_gather(vec2<f32>(fin_uv.x, 0.5 / cells), cells, in.clump, height);
        let gathered = textureSampleGrad(fin_texture, fin_sampler, vec2<f32>(gather.x, fin_uv.y), dx, dy);
        texel = select(textureSample(fin_texture, fin_sampler, fin_uv), gathered, gather.w > 0.0);
        let compounded = 1.0 - pow(1.0 - clamp(texel.a, 0.0, 1.0), 1.0 / (1.0 - gather.w));
        texel.a = select(texel.a, compounded, gather.w > 0.0);
    }
    var groom_alpha = clamp(in.tint_density.a, 0.0, 1.0);
    if wet_on() {
        groom_alpha *= clump_parting(vec2<f32>(fin_uv.x, 0.5 / cells), cells, in.clump, height);
    }
    return fin_colour(texel, in.lighting_fade, in.uvs, in.tint_density.rgb, groom_alpha);
}
