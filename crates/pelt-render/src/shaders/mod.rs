//! Every WGSL source of the renderer and what pins the Rust side to it: the bind group layouts
//! (and samplers) the pipelines share, and the Rust mirrors of the WGSL structs the host side
//! writes. Nothing here depends on the rest of the crate but the error type, so every other
//! module may import it.
//!
//! A module of WGSL is its files concatenated in order (`shading.wgsl` first): WGSL has no
//! imports, and one module per pipeline family keeps each `ShaderModule` self-contained.

mod layouts;
mod mirrors;

pub(crate) use layouts::Layouts;
pub(crate) use layouts::{SHADOW_DEPTH_FORMAT, SHADOW_OPACITY_FORMAT, array_view, shadow_texture};
#[cfg(all(test, feature = "lab"))]
pub(crate) use mirrors::assert_vertex_mirrors;
pub(crate) use mirrors::{
    GpuLight, LightsUniform, OBJECT_UNIFORM_BYTES, ObjectUniform, SHADOW_VIEWS, ShadowUniform, ShadowViewUniform,
    ViewUniform,
};
#[cfg(test)]
pub(crate) use mirrors::{RustLayout, assert_mirrors, rust_layout};

/// The view, the object uniform, the fur textures and the lighting every fur pipeline shares.
pub(crate) const SHADING_WGSL: &str = include_str!("shading.wgsl");
/// The wet look and the clumps, appended to the shading wherever it goes.
const WET_WGSL: &str = include_str!("wet.wgsl");
/// The fur model's lights, environment and BSDF, likewise appended.
const FUR_BSDF_WGSL: &str = include_str!("fur_bsdf.wgsl");
/// The lights' visibility (shadow maps and deep opacity maps) and the shadow views' opacity
/// fragments, appended to the shading wherever it goes.
const SHADOWS_WGSL: &str = include_str!("shadows.wgsl");
/// The unified structure's vertex and fragment shaders, over the shared vertex array.
const UNIFIED_WGSL: &str = include_str!("unified.wgsl");
/// A pool's object binding: every copy in a pool (`pool.rs`), in place of the one object
/// uniform, for the listing passes and a herd's shadow casters.
const OBJECT_POOL_WGSL: &str = include_str!("object_pool.wgsl");
/// A pool's shadow casters, every copy in one draw a pass.
const POOL_DRAWS_WGSL: &str = include_str!("pool_draws.wgsl");
/// The ordered listing both listing passes share.
const SCAN_WGSL: &str = include_str!("scan.wgsl");
/// The silhouette pass: which fins show.
const SILHOUETTE_WGSL: &str = include_str!("silhouette.wgsl");
/// The view-angle pass: which triangles the thinned shells still need.
const VIEW_LOD_WGSL: &str = include_str!("view_lod.wgsl");
/// Depth-only and motion-vector draws (prepasses, shadow maps).
const PREPASS_WGSL: &str = include_str!("prepass.wgsl");
/// The wind's noise, shared by the simulation's step.
const SIMULATION_WIND_WGSL: &str = include_str!("simulation_wind.wgsl");
/// One simulation step, one invocation a strand.
const SIMULATION_WGSL: &str = include_str!("simulation.wgsl");
/// The step's per-strand inputs the GPU keeps and computes (inertia, the touch's weights).
const SIMULATION_INPUTS_WGSL: &str = include_str!("simulation_inputs.wgsl");
/// Contact after the bend (skin, colliders, grasp), called by the simulation's step.
const SIMULATION_CONTACT_WGSL: &str = include_str!("simulation_contact.wgsl");
/// A fur's own step's bindings: its ranges, its step's uniform.
const SIMULATION_LONE_WGSL: &str = include_str!("simulation_lone.wgsl");
/// A pool's step: every copy stepping without contact in one dispatch.
const SIMULATION_POOLED_WGSL: &str = include_str!("simulation_pooled.wgsl");
/// A host's shadow map copied into one of Pelt's layers (`HostShadows`).
const SHADOW_COPY_WGSL: &str = include_str!("shadow_copy.wgsl");
/// Linear blend skinning of many instances (`GpuSkin`).
const SKINNING_WGSL: &str = include_str!("skinning.wgsl");
/// A herd's skinned bases placed into its members' inputs (`HerdPosing`).
const HERD_POSING_WGSL: &str = include_str!("herd_posing.wgsl");
/// The separated structure of Lengyel et al. 2001 (the `lab` feature's baseline).
#[cfg(feature = "lab")]
const SEPARATED_WGSL: &str = include_str!("separated.wgsl");
/// The explicit strands as ribbons (the `lab` feature's reference).
#[cfg(feature = "lab")]
const STRANDS_WGSL: &str = include_str!("strands.wgsl");

/// The WGSL module of the unified renderer (the shared shading plus `unified.wgsl`).
#[must_use]
pub fn unified_shader_source() -> String {
    format!("{SHADING_WGSL}\n{WET_WGSL}\n{FUR_BSDF_WGSL}\n{SHADOWS_WGSL}\n{UNIFIED_WGSL}")
}

/// The WGSL module of the prepass and shadow draws (the shared shading, `unified.wgsl` and
/// `prepass.wgsl`).
#[must_use]
pub fn prepass_shader_source() -> String {
    format!("{SHADING_WGSL}\n{WET_WGSL}\n{FUR_BSDF_WGSL}\n{SHADOWS_WGSL}\n{UNIFIED_WGSL}\n{PREPASS_WGSL}")
}

/// The bytes between two copies' objects in a pool (`ObjectSlot` in `object_pool.wgsl`): the
/// object uniform rounded up to the uniform offset alignment every device allows (256).
pub(crate) const OBJECT_SLOT_BYTES: u64 = OBJECT_UNIFORM_BYTES.next_multiple_of(256);

/// The shared shading with its object binding over a pool: every copy's object, read by slot
/// (`object_pool.wgsl`). The object is then a private copy, which a browser's WGSL compiler
/// counts as varying between invocations: the shading's texture reads would fail its derivative
/// check, so the module turns it off (a listing pass runs no fragment code, and a pooled draw's
/// copy is the same over each triangle).
fn pooled_shading() -> String {
    let (start, end) = ("// OBJECT BINDING", "// END OBJECT BINDING\n");
    let (Some(from), Some(to)) = (SHADING_WGSL.find(start), SHADING_WGSL.find(end)) else {
        unreachable!("shading.wgsl marks its object binding");
    };
    format!(
        "diagnostic(off, derivative_uniformity);\n{}{OBJECT_POOL_WGSL}{}",
        &SHADING_WGSL[..from],
        &SHADING_WGSL[to + end.len()..]
    )
}

/// The WGSL module of the silhouette pass (the shared shading over a pool, `unified.wgsl`,
/// `scan.wgsl` and `silhouette.wgsl`).
#[must_use]
pub fn silhouette_shader_source() -> String {
    let shading = pooled_shading();
    format!("{shading}\n{WET_WGSL}\n{FUR_BSDF_WGSL}\n{SHADOWS_WGSL}\n{UNIFIED_WGSL}\n{SCAN_WGSL}\n{SILHOUETTE_WGSL}")
}

/// The WGSL module of the view-angle pass (the shared shading over a pool, `unified.wgsl`,
/// `scan.wgsl` and `view_lod.wgsl`).
#[must_use]
pub fn view_lod_shader_source() -> String {
    let shading = pooled_shading();
    format!("{shading}\n{WET_WGSL}\n{FUR_BSDF_WGSL}\n{SHADOWS_WGSL}\n{UNIFIED_WGSL}\n{SCAN_WGSL}\n{VIEW_LOD_WGSL}")
}

/// The WGSL module of a pool's shadow casters (the shared shading over a pool, `unified.wgsl`
/// and `pool_draws.wgsl`).
#[must_use]
pub fn pool_draw_shader_source() -> String {
    let shading = pooled_shading();
    format!("{shading}\n{WET_WGSL}\n{FUR_BSDF_WGSL}\n{SHADOWS_WGSL}\n{UNIFIED_WGSL}\n{POOL_DRAWS_WGSL}")
}

/// The WGSL module that copies a host's shadow map into Pelt's (`shadow_copy.wgsl`).
#[must_use]
pub fn shadow_copy_shader_source() -> String {
    SHADOW_COPY_WGSL.to_owned()
}

/// The WGSL module of the GPU skinning (`skinning.wgsl`).
#[must_use]
pub fn skinning_shader_source() -> String {
    SKINNING_WGSL.to_owned()
}

/// The WGSL module skinning a herd's bases into its members' inputs (`skinning.wgsl` and
/// `herd_posing.wgsl`).
#[must_use]
pub fn herd_posing_shader_source() -> String {
    format!("{SKINNING_WGSL}\n{HERD_POSING_WGSL}")
}

/// The WGSL module of the GPU simulation (`simulation_wind.wgsl`, `simulation.wgsl` and
/// `simulation_inputs.wgsl` and `simulation_contact.wgsl`) over a fur's own bindings
/// (`simulation_lone.wgsl`).
#[must_use]
pub fn simulation_shader_source() -> String {
    simulation_module(SIMULATION_LONE_WGSL)
}

/// The WGSL module of a pool's step (`step_pooled`): the simulation's files over the pool's
/// bindings.
#[must_use]
pub fn simulation_pooled_shader_source() -> String {
    simulation_module(SIMULATION_POOLED_WGSL)
}

fn simulation_module(bindings: &str) -> String {
    format!(
        "{SIMULATION_WIND_WGSL}\n{SIMULATION_WGSL}\n{SIMULATION_INPUTS_WGSL}\n{SIMULATION_CONTACT_WGSL}\n{bindings}"
    )
}

/// The WGSL module of the separated renderer (the shared shading plus `separated.wgsl`).
#[must_use]
#[cfg(feature = "lab")]
pub fn separated_shader_source() -> String {
    format!("{SHADING_WGSL}\n{WET_WGSL}\n{FUR_BSDF_WGSL}\n{SHADOWS_WGSL}\n{SEPARATED_WGSL}")
}

/// The WGSL module of the strand renderer (the shared shading plus `strands.wgsl`).
#[must_use]
#[cfg(feature = "lab")]
pub fn strands_shader_source() -> String {
    format!("{SHADING_WGSL}\n{WET_WGSL}\n{FUR_BSDF_WGSL}\n{SHADOWS_WGSL}\n{STRANDS_WGSL}")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `ObjectSlot` in `object_pool.wgsl` is `OBJECT_SLOT_BYTES` long by members alone (no
    /// `@size`, which naga's GLSL drops), and the listing modules read the pool's objects in
    /// place of the uniform.
    #[test]
    fn the_pool_prelude_matches_the_slots() {
        let source = view_lod_shader_source();
        let module = naga::front::wgsl::parse_str(&source).expect("the listing module");
        let slot = module.types.iter().find(|(_, ty)| ty.name.as_deref() == Some("ObjectSlot"));
        let Some((_, naga::Type { inner: naga::TypeInner::Struct { members, span }, .. })) = slot else {
            panic!("no ObjectSlot");
        };
        assert_eq!(u64::from(*span), OBJECT_SLOT_BYTES, "ObjectSlot's size");
        let end = members.iter().map(|m| m.offset + module.types[m.ty].inner.size(module.to_ctx())).max();
        assert_eq!(end.map(u64::from), Some(OBJECT_SLOT_BYTES), "ObjectSlot's members fill it");
        assert!(!OBJECT_POOL_WGSL.contains("@size("));
        for source in [silhouette_shader_source(), view_lod_shader_source(), pool_draw_shader_source()] {
            assert!(source.contains("var<storage, read> objects: array<ObjectSlot>"));
            assert!(!source.contains("var<uniform> object: Object"));
        }
        assert!(unified_shader_source().contains("var<uniform> object: Object"));
    }
}
