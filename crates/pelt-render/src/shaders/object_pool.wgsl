// A pool's object binding (in place of `shading.wgsl`'s): every copy of a fur in one pool
// (`pool.rs`) is listed by one dispatch, workgroup z being the copy's slot, and a herd's shadow
// casters drawn by one draw a pass (`pool_draws.wgsl`). Each entry point loads its copy's object
// first (`load_member`); bindings 1 to 3 are the pool's whole buffers.

// One copy's object, `OBJECT_SLOT_BYTES` (`shaders/mod.rs`) apart: the uniform ranges the draws
// bind. Padded by a member, not `@size`: naga's GLSL drops a last member's `@size`, and GL then
// read every copy past the first at the wrong offset.
struct ObjectSlot {
    object: Object,
    // Where the listing passes also write this copy's fin draw (x) and shell draws (y) for a
    // herd's gathered camera draws (`HerdDraws`), or `NOT_GATHERED`.
    gather: vec4<u32>,
    padding: array<vec4<f32>, 10>,
}

const NOT_GATHERED = 0xffffffffu;

@group(1) @binding(0) var<storage, read> objects: array<ObjectSlot>;
var<private> object: Object;

// What a copy lists this frame (`Object::pool.w`).
const LIST_FINS = 1u;
const LIST_SHELLS = 2u;

fn current_base() -> u32 {
    return object.pool.x;
}
fn previous_base() -> u32 {
    return object.pool.y;
}
fn normals_base() -> u32 {
    return object.pool.z;
}

// Loads slot `member`'s object; whether it lists `what` this frame.
fn load_member(member: u32, what: u32) -> bool {
    object = objects[member].object;
    return (object.pool.w & what) != 0u;
}
