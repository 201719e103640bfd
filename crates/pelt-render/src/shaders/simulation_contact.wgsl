// Contact after the bend (`pelt_core::sim::contact`): the skin planes, the colliders and the
// grasp, per strand, root first, on the nodes the bend just wrote. Appended to
// `simulation.wgsl`. A step with contact runs two kernels: `step_strands_with_contact` bends
// every strand and lists those a cheap screen cannot clear; `solve_contact`, dispatched
// indirectly over that list, solves them.
//
// A fur's own `contact` buffer, in vec4s (V strands, `grid.y` the step's slot):
//   [2 s], [2 s + 1] for slot s < CONTACT_SLOTS: (collider count, skin on, grip presence, the
//     longest strand's length), (grip xyz, where the slot's colliders begin as bits);
//   then ceil(V / 4) vec4s of grasp weights, 4 strands each;
//   then, once the skin is found, SKIN_PLANES planes per strand (n xyz in the rest frame, h), a
//     cone per strand (`pelt_core::sim::contact::skin_cone`: axis xyz in the rest frame,
//     spread), and the skin's triangles (`contact::surface`), from `surface_first`: per strand
//     (rest root, first << 6 | count as bits), the lists (each entry its triangle's first vec4
//     from `surface_first`), the triangles of 10 vec4s (a, b, c, face normal, edge ab, bc, ca
//     and corner a, b, c pseudonormals; a bounding ball's centre in a, b, c's w, its radius in
//     the face normal's);
//   then each slot's colliders (as many as the fur's busiest step needs, `contact.rs`), 5 vec4s
//     each: (centre, radius), (half extents, kind as bits), rotation, (travel, friction),
//     (bound, grasp hand, field as bits, -) (a mesh's radius is its scale, its field where it
//     begins in the fields).
// A pool's buffer holds the same parts, the skin once for every copy and each copy's headers,
// weights and colliders in a block of its own (`simulation_pooled.wgsl`).

@group(0) @binding(5) var<storage, read> contact: array<vec4<f32>>;
// What `step_strands_with_contact` lists for `solve_contact`: the indirect dispatch's workgroups
// (x, y, z, copied to the dispatch's arguments), how many strands are listed, then each listed
// strand's index and the first segment its screen did not clear (`listed_word`).
struct ContactWork {
    groups: array<atomic<u32>, 3>,
    count: atomic<u32>,
    strands: array<vec2<u32>>,
}

@group(0) @binding(8) var<storage, read_write> contact_work: ContactWork;
// Mesh colliders' distance fields (`contact.rs`'s `upload_fields`) are read through `sdf_at`,
// each: origin xyz, cell, dims xyz as bits, -, then the values, x fastest. Where the headers,
// planes, weights and triangles begin (`headers_first`, `planes_first`, `weights_first`,
// `surface_first`) is the bindings' file's: a fur's own buffer or its pool's.

// Whether `solve_contact` reads colliders, and mesh colliders' fields: steps without them run a
// pipeline compiled without that code (it costs where lanes diverge even when no lane takes it).
override COLLIDERS: bool = true;
override MESH_COLLIDERS: bool = true;

const CONTACT_SLOTS: u32 = 64u;
const CONTACT_SKIN: u32 = 2u * CONTACT_SLOTS;
const SKIN_PLANES: u32 = 16u;
const COLLIDER_WORDS: u32 = 5u;
const NEAR_COLLIDERS: u32 = 32u;
const CONTACT_MARGIN: f32 = 1e-5;
const CONTACT_SIDE_BIAS: f32 = 1.0;
const CONTACT_FRICTION_DEPTH: f32 = 0.25;
const CONTACT_SKIP_SLACK: f32 = 1.001;

struct Closest {
    surface: vec3<f32>,
    normal: vec3<f32>,
    distance: f32,
}

fn read_node(j: u32, v: u32, k: u32) -> vec3<f32> {
    let index = (k * v + j) * 3u;
    return vec3<f32>(positions[member_base.x + index], positions[member_base.x + index + 1u], positions[member_base.x + index + 2u]);
}

fn conjugate(q: vec4<f32>) -> vec4<f32> {
    return vec4<f32>(-q.xyz, q.w);
}

fn around_ball(x: vec3<f32>, core: vec3<f32>, radius: f32, fallback: vec3<f32>) -> Closest {
    let d = x - core;
    let l = length(d);
    var normal = fallback;
    if l > 0.0 {
        normal = d / l;
    }
    return Closest(core + normal * radius, normal, l - radius);
}

// `StepCollider::closest`: the closest surface point, outward normal, signed distance.
fn collider_closest(c: u32, x: vec3<f32>) -> Closest {
    let centre = contact[c].xyz;
    let radius = contact[c].w;
    let half = contact[c + 1u].xyz;
    let kind = bitcast<u32>(contact[c + 1u].w);
    let turn = contact[c + 2u];
    let up = rotate(turn, vec3<f32>(0.0, 1.0, 0.0));
    if kind == 0u {
        return around_ball(x, centre, radius, up);
    }
    if kind == 1u {
        let t = clamp(dot(up, x - centre), -half.y, half.y);
        return around_ball(x, centre + up * t, radius, up);
    }
    if kind == 2u {
        let local = rotate(conjugate(turn), x - centre);
        let q = abs(local) - half;
        if max(max(q.x, q.y), q.z) > 0.0 {
            let clamped = clamp(local, -half, half);
            let out = local - clamped;
            let l = length(out);
            return Closest(centre + rotate(turn, clamped), rotate(turn, out / l), l);
        }
        var axis = 2u;
        if q.x >= q.y && q.x >= q.z {
            axis = 0u;
        } else if q.y >= q.z {
            axis = 1u;
        }
        let sign = select(1.0, -1.0, local[axis] < 0.0);
        var surface = local;
        surface[axis] = sign * half[axis];
        var normal = vec3<f32>(0.0);
        normal[axis] = sign;
        return Closest(centre + rotate(turn, surface), rotate(turn, normal), q[axis]);
    }
    if MESH_COLLIDERS && kind == 4u {
        return sdf_closest(x, centre, turn, radius, bitcast<u32>(contact[c + 4u].z), up);
    }
    let distance = dot(up, x - centre);
    return Closest(x - up * distance, up, distance);
}

fn sdf_value(field: u32, dims: vec3<u32>, at: vec3<u32>) -> f32 {
    return sdf_at(field + 8u + at.x + dims.x * (at.y + dims.y * at.z));
}

fn sdf_lerp(a: f32, b: f32, t: f32) -> f32 {
    return a + (b - a) * t;
}

// `StepCollider::closest` of a mesh: `MeshSdf::local_distance_gradient` at x in the mesh's
// frame (scaled by `scale`), operation for operation.
fn sdf_closest(x: vec3<f32>, centre: vec3<f32>, turn: vec4<f32>, scale: f32, field: u32, up: vec3<f32>) -> Closest {
    let origin = vec3<f32>(sdf_at(field), sdf_at(field + 1u), sdf_at(field + 2u));
    let cell = sdf_at(field + 3u);
    let dims = vec3<u32>(
        bitcast<u32>(sdf_at(field + 4u)),
        bitcast<u32>(sdf_at(field + 5u)),
        bitcast<u32>(sdf_at(field + 6u)),
    );
    let local = rotate(conjugate(turn), x - centre) / scale;
    let g = (local - origin) / cell;
    let top = vec3<f32>(dims) - 1.0;
    let inside = clamp(g, vec3<f32>(0.0), top);
    let base = max(min(floor(inside), top - 1.0), vec3<f32>(0.0));
    let f = inside - base;
    let b = vec3<u32>(base);
    let v000 = sdf_value(field, dims, b);
    let v100 = sdf_value(field, dims, b + vec3<u32>(1u, 0u, 0u));
    let v010 = sdf_value(field, dims, b + vec3<u32>(0u, 1u, 0u));
    let v110 = sdf_value(field, dims, b + vec3<u32>(1u, 1u, 0u));
    let v001 = sdf_value(field, dims, b + vec3<u32>(0u, 0u, 1u));
    let v101 = sdf_value(field, dims, b + vec3<u32>(1u, 0u, 1u));
    let v011 = sdf_value(field, dims, b + vec3<u32>(0u, 1u, 1u));
    let v111 = sdf_value(field, dims, b + vec3<u32>(1u, 1u, 1u));
    let c00 = sdf_lerp(v000, v100, f.x);
    let c10 = sdf_lerp(v010, v110, f.x);
    let c01 = sdf_lerp(v001, v101, f.x);
    let c11 = sdf_lerp(v011, v111, f.x);
    let c0 = sdf_lerp(c00, c10, f.y);
    let c1 = sdf_lerp(c01, c11, f.y);
    var distance = sdf_lerp(c0, c1, f.z);
    let dx = sdf_lerp(sdf_lerp(v100 - v000, v110 - v010, f.y), sdf_lerp(v101 - v001, v111 - v011, f.y), f.z);
    let dy = sdf_lerp(sdf_lerp(v010 - v000, v110 - v100, f.x), sdf_lerp(v011 - v001, v111 - v101, f.x), f.z);
    let dz = c1 - c0;
    var gradient = vec3<f32>(dx, dy, dz) / cell;
    let outside = (g - inside) * cell;
    if any(outside != vec3<f32>(0.0)) {
        distance += length(outside);
        gradient = normalize(outside);
    }
    let normal = normalize_or(rotate(turn, gradient), up);
    let d = distance * scale;
    return Closest(x - normal * d, normal, d);
}

// Any unit vector perpendicular to unit `n` (`glam::Vec3::any_orthonormal_vector`).
fn any_orthonormal(n: vec3<f32>) -> vec3<f32> {
    let sign = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    return vec3<f32>(b, sign + n.y * n.y * a, -n.y);
}

fn normalize_or(x: vec3<f32>, fallback: vec3<f32>) -> vec3<f32> {
    let l = length(x);
    if l > 0.0 && is_finite(l) {
        return x / l;
    }
    return fallback;
}

// `contact::turn_above`: a unit direction near `u` with `n . result >= floor`, on the side of
// `u` plus `hint` weighed by how far `u` lies below the cone (`CONTACT_SIDE_BIAS`).
fn turn_above(u: vec3<f32>, n: vec3<f32>, floor_in: f32, hint: vec3<f32>) -> vec3<f32> {
    let floor = clamp(floor_in, -1.0, 1.0);
    let along = dot(n, u);
    if along >= floor {
        return u;
    }
    let side = normalize_or((u - n * along) + (hint - n * dot(n, hint)) * (CONTACT_SIDE_BIAS * (floor - along)), any_orthonormal(n));
    return normalize(n * floor + side * sqrt(max(1.0 - floor * floor, 0.0)));
}

fn cones_first(v: u32) -> u32 {
    return planes_first(v) + SKIN_PLANES * v;
}

fn colliders_first(slot: u32) -> u32 {
    return bitcast<u32>(contact[headers_first() + 2u * slot + 1u].w);
}

// One strand's skin triangles, posed with its root and frame.
struct Surface {
    first: u32,
    count: u32,
    rest_root: vec3<f32>,
    root: vec3<f32>,
    frame: vec4<f32>,
}

fn list_entry(base: u32, i: u32) -> u32 {
    return bitcast<u32>(contact[base + i / 4u][i % 4u]);
}

// `surface::closest_feature`: the closest point of triangle abc to p and its feature's word.
fn closest_feature(p: vec3<f32>, a: vec3<f32>, b: vec3<f32>, c: vec3<f32>) -> vec4<f32> {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = dot(ab, ap);
    let d2 = dot(ac, ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return vec4<f32>(a, 7.0);
    }
    let bp = p - b;
    let d3 = dot(ab, bp);
    let d4 = dot(ac, bp);
    if d3 >= 0.0 && d4 <= d3 {
        return vec4<f32>(b, 8.0);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return vec4<f32>(a + ab * (d1 / (d1 - d3)), 4.0);
    }
    let cp = p - c;
    let d5 = dot(ab, cp);
    let d6 = dot(ac, cp);
    if d6 >= 0.0 && d5 <= d6 {
        return vec4<f32>(c, 9.0);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return vec4<f32>(a + ac * (d2 / (d2 - d6)), 6.0);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return vec4<f32>(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))), 5.0);
    }
    let denominator = 1.0 / (va + vb + vc);
    return vec4<f32>(a + ab * (vb * denominator) + ac * (vc * denominator), 3.0);
}

// `SkinSurface::closest_posed`: the closest point, pseudonormal and signed distance of the
// strand's triangles to world point x (distance +inf without triangles).
fn surface_closest(s: Surface, x: vec3<f32>, v: u32) -> Closest {
    var best = Closest(x, vec3<f32>(0.0, 1.0, 0.0), 3.4e38);
    if s.count == 0u {
        return best;
    }
    let origin = surface_first(v);
    let local = s.rest_root + rotate(conjugate(s.frame), x - s.root);
    // What rounding can take off a ball's distance: a few dozen ulps of the coordinates.
    let slack = 4e-6 * max(max(abs(local.x), abs(local.y)), abs(local.z));
    var best_d2 = 3.4e38;
    var found = false;
    for (var i = 0u; i < s.count; i++) {
        let t = origin + list_entry(origin + v + s.first / 4u, s.first % 4u + i);
        let a = contact[t].xyz;
        let b = contact[t + 1u].xyz;
        let c = contact[t + 2u].xyz;
        // `SkinSurface::closest`'s cull: the ball about the centroid (radius in the first word's
        // w) farther than the nearest found, past rounding, holds no nearer point.
        let radius = contact[t].w;
        let ball = length(local - (a + b + c) * (1.0 / 3.0)) - radius * (1.0 + 4e-6) - slack;
        if found && ball > 0.0 && ball * ball >= best_d2 {
            continue;
        }
        let hit = closest_feature(local, a, b, c);
        let gap = local - hit.xyz;
        let d2 = dot(gap, gap);
        if !found || d2 < best_d2 {
            found = true;
            best_d2 = d2;
            best.surface = hit.xyz;
            best.normal = contact[t + u32(hit.w)].xyz;
        }
    }
    let distance = sqrt(best_d2);
    let signed = select(distance, -distance, dot(best.normal, local - best.surface) < 0.0);
    return Closest(s.root + rotate(s.frame, best.surface - s.rest_root), rotate(s.frame, best.normal), signed);
}

// One listed strand's contact in a step, set up by `contact_setup`: its skin planes turned with
// its frame, the colliders that can reach it, its triangles, its grasp weight.
var<private> contact_planes: array<vec4<f32>, SKIN_PLANES>;
var<private> contact_plane_count: u32;
var<private> contact_near: array<u32, NEAR_COLLIDERS>;
var<private> contact_near_count: u32;
var<private> contact_surface: Surface;
var<private> contact_held: f32;

// The screen of `step_strands_with_contact`, fed each node by the bend while it is in registers:
// the strand's cone turned with its frame (axis xyz, spread; zero: the skin is off), the box
// round its nodes, and the first segment whose end the cone did not clear (`layers`: none).
// It does the same few operations at every node: a GPU runs the code of a branch any lane of a
// vector takes for every lane (lavapipe runs every branch), so the exact tests wait for the
// listed strands, where every lane needs them.
var<private> screen_cone: vec4<f32>;
var<private> screen_low: vec3<f32>;
var<private> screen_high: vec3<f32>;
var<private> screen_from: u32;

// How far x is above the strand's lowest skin plane (3.4e38 without planes).
fn plane_clearance(x: vec3<f32>, root: vec3<f32>) -> f32 {
    var least = 3.4e38;
    for (var p = 0u; p < contact_plane_count; p++) {
        least = min(least, dot(contact_planes[p].xyz, x - root) + contact_planes[p].w);
    }
    return least;
}

// `contact::cheap_clearance`: how far x is from touching a skin plane or a collider (negative:
// touching).
fn cheap_clearance(x: vec3<f32>, root: vec3<f32>) -> f32 {
    var least = plane_clearance(x, root);
    for (var i = 0u; COLLIDERS && i < contact_near_count; i++) {
        least = min(least, collider_closest(contact_near[i], x).distance);
    }
    return least;
}

// `Surface::clearance`: the least of `cheap` and x's distance in front of the triangles.
fn surface_clearance(x: vec3<f32>, cheap: f32, v: u32) -> f32 {
    return min(cheap, surface_closest(contact_surface, x, v).distance);
}

fn strand_grasp_weight(j: u32, v: u32) -> f32 {
    let at = weights_first(v) + j / 4u;
    return contact[at][j % 4u];
}

// A step with contact (`ContactStep::is_active`), first kernel: the bend with the screen, then
// the strand listed for `solve_contact` unless the screen cleared every node.
@compute @workgroup_size(64)
fn step_strands_with_contact(@builtin(workgroup_id) group: vec3<u32>, @builtin(local_invocation_index) lane: u32) {
    bend_and_screen(step_strand_index(group, lane));
}

fn bend_and_screen(j: u32) {
    let v = inputs.next_tick_counts.z;
    if j >= v {
        return;
    }
    let layers = inputs.next_tick_counts.w;
    let root = strand_root(j).xyz;
    screen_start(j, v, layers, root, strand_frame(j, v));
    bend_strand(j, true);
    screen_finish(j, v, layers);
}

// The screen's state before the bend. A held strand is solved from its root, and so is one that
// keeps skin triangles (the cone does not bound them).
fn screen_start(j: u32, v: u32, layers: u32, root: vec3<f32>, frame: vec4<f32>) {
    let header = contact[headers_first() + 2u * inputs.grid.y];
    let skin = header.y > 0.0;
    screen_cone = vec4<f32>(0.0);
    screen_from = layers;
    if skin {
        let cone = contact[cones_first(v) + j];
        screen_cone = vec4<f32>(rotate(frame, cone.xyz), cone.w);
        let triangles = bitcast<u32>(contact[surface_first(v) + j].w) & 63u;
        screen_from = select(layers, 0u, triangles > 0u);
    }
    if strand_grasp_weight(j, v) * header.z != 0.0 {
        screen_from = 0u;
    }
    screen_low = root;
    screen_high = root;
}

// The screen of the node ending segment k: a node outside the cone may touch the skin.
fn screen_node(k: u32, node: vec3<f32>, root: vec3<f32>) {
    let d = node - root;
    let clear = dot(screen_cone.xyz, d) >= screen_cone.w * length(d);
    screen_from = min(screen_from, select(k, screen_from, clear));
    screen_low = min(screen_low, node);
    screen_high = max(screen_high, node);
}

// After the bend: a collider whose bounding ball reaches the box round the nodes may touch any
// of them; then the strand is listed when any node was not cleared.
fn screen_finish(j: u32, v: u32, layers: u32) {
    let slot = inputs.grid.y;
    let count = bitcast<u32>(contact[headers_first() + 2u * slot].x);
    let first = colliders_first(slot);
    for (var i = 0u; i < count; i++) {
        let c = first + i * COLLIDER_WORDS;
        let centre = contact[c].xyz;
        // A thousandth over the bound, so rounding never clears a node inside the collider.
        if distance(clamp(centre, screen_low, screen_high), centre) <= contact[c + 4u].x * 1.001 {
            screen_from = 0u;
        }
    }
    if screen_from < layers {
        let listed = atomicAdd(&contact_work.count, 1u);
        contact_work.strands[listed] = vec2<u32>(j, listed_word(screen_from));
        // A workgroup of `solve_contact` per 64 listed, up to the step's cap (`grid.w`: its own
        // grid's width, a pool's times its copies; each invocation then takes every so-many-th
        // strand of the list).
        if listed % WORKGROUP == 0u && listed / WORKGROUP < inputs.grid.w {
            atomicAdd(&contact_work.groups[0], 1u);
            atomicStore(&contact_work.groups[1], 1u);
            atomicStore(&contact_work.groups[2], 1u);
        }
    }
}

// `solve_contact`'s workgroup: how many strands are listed, and the strands of its share that
// touch (index, first touching segment), gathered so the walk runs on as few vectors as it can.
var<workgroup> solve_listed: u32;
var<workgroup> solve_touching: array<vec2<u32>, WORKGROUP>;
var<workgroup> solve_touching_count: atomic<u32>;

// A step with contact, second kernel (dispatched with the groups `screen_finish` counted): each
// listed strand's first touch, then the strands that touch gathered to the workgroup's first
// lanes and walked from it. A vector none of whose lanes walks runs the walk's loops once, not
// once per segment (lavapipe runs every branch; a GPU skips the vector).
@compute @workgroup_size(64)
fn solve_contact(
    @builtin(workgroup_id) group: vec3<u32>,
    @builtin(local_invocation_index) lane: u32,
    @builtin(num_workgroups) groups: vec3<u32>,
) {
    solve_listed_strands(group, lane, groups);
}

// A listed strand's entry (`listed_word`, `take_listed`) also says whose it is in a pool's list,
// so every lane reads its own copy's inputs; the strand count and layers are every copy's.
fn solve_listed_strands(group: vec3<u32>, lane: u32, groups: vec3<u32>) {
    let v = inputs.next_tick_counts.z;
    let layers = inputs.next_tick_counts.w;
    if lane == 0u {
        solve_listed = atomicLoad(&contact_work.count);
    }
    let count = workgroupUniformLoad(&solve_listed);
    for (var first = group.x * WORKGROUP; first < count; first += groups.x * WORKGROUP) {
        let i = first + lane;
        if i < count {
            let listed = contact_work.strands[i];
            let j = listed.x;
            let start = take_listed(listed.y);
            contact_setup(j, v, strand_root(j).xyz, strand_frame(j, v));
            var first_touch = 0u;
            if contact_held == 0.0 {
                first_touch = find_first_touch(j, v, layers, strand_root(j).xyz, start);
            }
            if first_touch < layers {
                solve_touching[atomicAdd(&solve_touching_count, 1u)] = vec2<u32>(j, listed_word(first_touch));
            }
        }
        workgroupBarrier();
        if lane < atomicLoad(&solve_touching_count) {
            let touching = solve_touching[lane];
            let j = touching.x;
            let first_touch = take_listed(touching.y);
            let root = strand_root(j).xyz;
            let frame = strand_frame(j, v);
            contact_setup(j, v, root, frame);
            contact_strand(j, v, layers, root, frame, first_touch);
        }
        workgroupBarrier();
        if lane == 0u {
            atomicStore(&solve_touching_count, 0u);
        }
        workgroupBarrier();
    }
}

// Strand j's contact inputs for this step.
fn contact_setup(j: u32, v: u32, root: vec3<f32>, frame: vec4<f32>) {
    let slot = inputs.grid.y;
    let header = contact[headers_first() + 2u * slot];
    let count = bitcast<u32>(header.x);
    let skin = header.y > 0.0;
    let presence = header.z;
    contact_held = strand_grasp_weight(j, v) * presence;
    contact_plane_count = 0u;
    if skin {
        // A strand's planes fill the first of its slots (`skin_planes`).
        for (var p = 0u; p < SKIN_PLANES; p++) {
            let plane = contact[planes_first(v) + j * SKIN_PLANES + p];
            if all(plane.xyz == vec3<f32>(0.0)) {
                break;
            }
            contact_planes[p] = vec4<f32>(rotate(frame, plane.xyz), plane.w);
            contact_plane_count += 1u;
        }
    }
    // Colliders that can reach the strand (its nodes lie within the longest strand's length of
    // the root).
    let first = colliders_first(slot);
    contact_near_count = 0u;
    for (var i = 0u; COLLIDERS && i < count && contact_near_count < NEAR_COLLIDERS; i++) {
        let c = first + i * COLLIDER_WORDS;
        let bound = contact[c + 4u];
        if bound.y > 0.0 && contact_held != 0.0 {
            continue;
        }
        if distance(root, contact[c].xyz) <= bound.x + header.w {
            contact_near[contact_near_count] = c;
            contact_near_count += 1u;
        }
    }
    contact_surface = Surface(0u, 0u, vec3<f32>(0.0), root, frame);
    if skin {
        let header = contact[surface_first(v) + j];
        let packed = bitcast<u32>(header.w);
        contact_surface = Surface(packed >> 6u, packed & 63u, header.xyz, root, frame);
    }
}

// `Resolve::first_touch` from segment `start` (the nodes before it are clear): the first segment
// whose end touches, or `layers`. Nodes within the last clearance found, less the segments
// since, need no test; clearance grows by at most the arc, so which nodes are tested does not
// change the segment found. The outer loop tests a node each time round and the inner one skips
// the nodes the clearance covers, so a vector runs the tests as often as its lane that needs the
// most of them, not once per segment.
fn find_first_touch(j: u32, v: u32, layers: u32, root: vec3<f32>, start: u32) -> u32 {
    var k = start;
    while k < layers {
        let x = read_node(j, v, k + 1u);
        var budget = surface_clearance(x, cheap_clearance(x, root), v);
        if budget < 0.0 {
            return k;
        }
        k += 1u;
        for (; k < layers; k++) {
            budget -= rest_segments[k * v + j].w * CONTACT_SKIP_SLACK;
            if budget <= 0.0 {
                break;
            }
        }
    }
    return layers;
}

// `Resolve::solve_strand` from `first_touch` on: the nodes before it keep the bend's positions.
fn contact_strand(j: u32, v: u32, layers: u32, root: vec3<f32>, frame: vec4<f32>, first_touch: u32) {
    let held = contact_held;
    let surface = contact_surface;
    let grip = contact[headers_first() + 2u * inputs.grid.y + 1u].xyz;
    let to_grip = grip - root;
    let grip_distance = length(to_grip);
    let has_grip = grip_distance > 0.0;
    let toward = to_grip / select(1.0, grip_distance, has_grip);
    // The arc matters to held strands only, and those start at the root.
    var arc = 0.0;
    var previous_bent = read_node(j, v, first_touch);
    var p = previous_bent;
    // `Resolve::solve_strand`'s hint: the way the segment before went.
    let across = rotate(frame, vec3<f32>(1.0, 0.0, 0.0));
    var hint = across;
    for (var m = first_touch; m > 0u; m--) {
        if rest_segments[(m - 1u) * v + j].w > 0.0 {
            let u = normalize_or(read_node(j, v, m) - read_node(j, v, m - 1u), vec3<f32>(0.0, 1.0, 0.0));
            hint = u + across * 0.5;
            break;
        }
    }
    var walk_budget = 0.0;
    for (var k = first_touch; k < layers; k++) {
        let segment_length = rest_segments[k * v + j].w;
        let bent = read_node(j, v, k + 1u);
        if segment_length <= 0.0 {
            previous_bent = bent;
            write_node(j, v, k + 1u, p);
            continue;
        }
        var u = normalize_or(bent - previous_bent, vec3<f32>(0.0, 1.0, 0.0));
        previous_bent = bent;
        let before_grip = clamp((grip_distance - arc) / segment_length, 0.0, 1.0);
        if held != 0.0 && has_grip && before_grip > 0.0 {
            u = normalize_or(u + (toward - u) * (held * before_grip), u);
        }
        arc += segment_length;
        // Where the start is clear by more than the segment, no end can touch anything.
        let step = segment_length * CONTACT_SKIP_SLACK;
        if walk_budget <= step {
            let cheap = cheap_clearance(p, root);
            if k == 0u {
                // The root lies on its skin: no nearer than 0 to its triangles.
                walk_budget = select(cheap, min(cheap, 0.0), surface.count > 0u);
            } else {
                walk_budget = surface_clearance(p, cheap, v);
            }
        }
        walk_budget -= step;
        for (var round = 0u; round < 8u && walk_budget <= 0.0; round++) {
            var moved = false;
            for (var i = 0u; COLLIDERS && i < contact_near_count; i++) {
                let c = contact_near[i];
                let hit = collider_closest(c, p + u * segment_length);
                if hit.distance >= 0.0 {
                    continue;
                }
                let friction = contact[c + 3u].w;
                if round == 0u && friction > 0.0 {
                    let travel = contact[c + 3u].xyz;
                    let slide = travel - hit.normal * dot(hit.normal, travel);
                    let depth = min(-hit.distance / (CONTACT_FRICTION_DEPTH * segment_length), 1.0);
                    u = normalize_or(u * segment_length + slide * (friction * depth), u);
                }
                var floor = dot(hit.normal, hit.surface - p) / segment_length;
                var normal = hit.normal;
                if floor > 1.0 - CONTACT_MARGIN {
                    let start = collider_closest(c, p);
                    floor = dot(start.normal, start.surface - p) / segment_length;
                    normal = start.normal;
                }
                u = turn_above(u, normal, floor + CONTACT_MARGIN, hint);
                moved = true;
            }
            for (var q = 0u; q < contact_plane_count; q++) {
                let n = contact_planes[q].xyz;
                let floor = (-contact_planes[q].w - dot(n, p - root)) / segment_length;
                if dot(n, u) < floor {
                    u = turn_above(u, n, floor + CONTACT_MARGIN, hint);
                    moved = true;
                }
            }
            let below = surface_closest(surface, p + u * segment_length, v);
            if below.distance < 0.0 {
                var floor = dot(below.normal, below.surface - p) / segment_length;
                var normal = below.normal;
                if floor > 1.0 - CONTACT_MARGIN {
                    let start = surface_closest(surface, p, v);
                    floor = dot(start.normal, start.surface - p) / segment_length;
                    normal = start.normal;
                }
                u = turn_above(u, normal, floor + CONTACT_MARGIN, hint);
                moved = true;
            }
            if !moved {
                break;
            }
        }
        hint = u + across * 0.5;
        p = p + u * segment_length;
        write_node(j, v, k + 1u, p);
    }
}
