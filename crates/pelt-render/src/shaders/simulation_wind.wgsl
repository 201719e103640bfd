// The wind of pelt-core's `sim::wind` on the GPU, bit for bit in its hashing: WGSL has no 64-bit
// integers, so a u64 is a vec2<u32> (x = low word, y = high word) and SplitMix64's arithmetic is
// done in 32-bit halves. The f64 parts of the CPU's noise (time times speed, far from the
// origin) are split on the CPU into a whole-cell offset (i64) and a fraction per step.

// 32 x 32 -> 64-bit product from 16-bit halves.
fn mul32_wide(a: u32, b: u32) -> vec2<u32> {
    let a_lo = a & 0xffffu;
    let a_hi = a >> 16u;
    let b_lo = b & 0xffffu;
    let b_hi = b >> 16u;
    let ll = a_lo * b_lo;
    let lh = a_lo * b_hi;
    let hl = a_hi * b_lo;
    let hh = a_hi * b_hi;
    let mid = (ll >> 16u) + (lh & 0xffffu) + (hl & 0xffffu);
    return vec2<u32>((ll & 0xffffu) | (mid << 16u), hh + (lh >> 16u) + (hl >> 16u) + (mid >> 16u));
}

// Wrapping 64-bit product.
fn mul64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let low = mul32_wide(a.x, b.x);
    return vec2<u32>(low.x, low.y + a.x * b.y + a.y * b.x);
}

// Wrapping 64-bit sum.
fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let low = a.x + b.x;
    return vec2<u32>(low, a.y + b.y + select(0u, 1u, low < a.x));
}

// Right shift by 0 < s < 32.
fn shr64(a: vec2<u32>, s: u32) -> vec2<u32> {
    return vec2<u32>((a.x >> s) | (a.y << (32u - s)), a.y >> s);
}

// `rng::mix64` (SplitMix64's finaliser).
fn mix64(value: vec2<u32>) -> vec2<u32> {
    var x = add64(value, vec2<u32>(0x7f4a7c15u, 0x9e3779b9u));
    x = mul64(x ^ shr64(x, 30u), vec2<u32>(0x1ce4e5b9u, 0xbf58476du));
    x = mul64(x ^ shr64(x, 27u), vec2<u32>(0x133111ebu, 0x94d049bbu));
    return x ^ shr64(x, 31u);
}

// The multipliers `corner_bits` spreads x, y and z by.
const CORNER_X = vec2<u32>(0x7f4a7c15u, 0x9e3779b9u);
const CORNER_Y = vec2<u32>(0x27d4eb4fu, 0xc2b2ae3du);
const CORNER_Z = vec2<u32>(0x9e3779f9u, 0x165667b1u);

// `rng::unit_f32(bits) * 2 - 1`: the top 24 bits.
fn signed_unit(bits: vec2<u32>) -> f32 {
    return f32(bits.y >> 8u) * (1.0 / 16777216.0) * 2.0 - 1.0;
}

fn smoothstep01(t: f32) -> f32 {
    return t * t * (3.0 - 2.0 * t);
}

// An i32 as a wrapping i64.
fn widen(value: i32) -> vec2<u32> {
    return vec2<u32>(bitcast<u32>(value), select(0u, 0xffffffffu, value < 0));
}

// `wind::value_noise3` at `local - fraction - whole` (whole cells as i64), with `seed` already
// mixed once as the CPU does.
fn value_noise3(seed: vec2<u32>, local: vec3<f32>, fraction_offset: vec3<f32>, whole_x: vec2<u32>, whole_y: vec2<u32>, whole_z: vec2<u32>) -> f32 {
    let point = local - fraction_offset;
    let cell = floor(point);
    let fraction = point - cell;
    // Cell coordinates times the corner multipliers, and the next cell's (one addition more).
    let x0 = mul64(add64(widen(i32(cell.x)), whole_x), CORNER_X);
    let y0 = mul64(add64(widen(i32(cell.y)), whole_y), CORNER_Y);
    let z0 = mul64(add64(widen(i32(cell.z)), whole_z), CORNER_Z);
    let x1 = add64(x0, CORNER_X);
    let y1 = add64(y0, CORNER_Y);
    let z1 = add64(z0, CORNER_Z);
    let u = smoothstep01(fraction.x);
    let v = smoothstep01(fraction.y);
    let w = smoothstep01(fraction.z);
    let c000 = signed_unit(mix64(seed ^ x0 ^ y0 ^ z0));
    let c100 = signed_unit(mix64(seed ^ x1 ^ y0 ^ z0));
    let c010 = signed_unit(mix64(seed ^ x0 ^ y1 ^ z0));
    let c110 = signed_unit(mix64(seed ^ x1 ^ y1 ^ z0));
    let c001 = signed_unit(mix64(seed ^ x0 ^ y0 ^ z1));
    let c101 = signed_unit(mix64(seed ^ x1 ^ y0 ^ z1));
    let c011 = signed_unit(mix64(seed ^ x0 ^ y1 ^ z1));
    let c111 = signed_unit(mix64(seed ^ x1 ^ y1 ^ z1));
    let x00 = c000 + (c100 - c000) * u;
    let x10 = c010 + (c110 - c010) * u;
    let x01 = c001 + (c101 - c001) * u;
    let x11 = c011 + (c111 - c011) * u;
    let y_0 = x00 + (x10 - x00) * v;
    let y_1 = x01 + (x11 - x01) * v;
    return y_0 + (y_1 - y_0) * w;
}

// `wind::random_vector` from `mixed` = mix64(jitter seed ^ mix64(vertex)) and a tick:
// 21 bits per axis of `rng::hash(seed, vertex, tick, 0)`.
fn random_vector(mixed: vec2<u32>, tick: vec2<u32>) -> vec3<f32> {
    let bits = mix64(mix64(mixed ^ tick));
    let x = bits.x & 0x1fffffu;
    let y = ((bits.x >> 21u) | (bits.y << 11u)) & 0x1fffffu;
    let z = (bits.y >> 10u) & 0x1fffffu;
    return vec3<f32>(f32(x), f32(y), f32(z)) * (2.0 / 2097152.0) - 1.0;
}
