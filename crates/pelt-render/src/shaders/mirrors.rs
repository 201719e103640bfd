//! The Rust mirrors of the WGSL uniform structs the host side writes, and (in tests) the check
//! that a mirror matches its WGSL struct member by member as naga lays it out.

use glam::{Mat4, Vec3, Vec4};

/// One view; the layout of `View` in `shading.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ViewUniform {
    pub clip_from_world: Mat4,
    pub camera_position: Vec3,
    pub ambient: f32,
    pub light_direction: Vec3,
    pub _padding_0: f32,
    pub light_colour: Vec3,
    pub _padding_1: f32,
}

/// One fur or plain mesh; the layout of `Object` in `shading.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ObjectUniform {
    pub world_from_model: Mat4,
    /// A `mat3x3<f32>` in a uniform: three 16-byte columns.
    pub world_normal_from_model: [Vec4; 3],
    pub colour: Vec4,
    pub vertex_count: u32,
    pub layers: u32,
    pub triangle_count: u32,
    pub edge_count: u32,
    pub has_uvs: u32,
    pub has_surface: u32,
    pub shell_slices: u32,
    pub wedge_count: u32,
    pub tiles_per_uv: f32,
    pub tiles_per_world: f32,
    pub world_per_uv: f32,
    pub interpolation: f32,
    pub fin_fade_cos: f32,
    pub shell_fade_cos: f32,
    pub root_occlusion: f32,
    pub specular: f32,
    pub shininess: f32,
    pub lod_blend: f32,
    pub lod_stride: u32,
    pub lod_shells: u32,
    pub lod_view: f32,
    pub lod_view_start: f32,
    pub lod_view_full: f32,
    pub furred_triangle_count: u32,
    pub fin_edge_count: u32,
    pub groom_shading: u32,
    pub wet_darkening: f32,
    pub wet_shine: f32,
    pub wet_clump: f32,
    pub clump_cell_texels: f32,
    pub wet_any: u32,
    pub shading_model: u32,
    pub fur_pigment: Vec3,
    pub fur_roughness: f32,
    pub fur_cuticle_tilt: f32,
    pub fur_medulla: f32,
    pub coat_fade: f32,
    pub fin_fade: f32,
    pub tint: Vec3,
    pub lean_share: f32,
    pub lean_texels: f32,
    /// WGSL aligns `pool` to 16 bytes.
    pub _padding_3: [f32; 3],
    /// The copy's place in its pool for the listing passes ([`crate::pool`]).
    pub pool: [u32; 4],
}

/// One light; the layout of `Light` in `fur_bsdf.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct GpuLight {
    pub position_or_direction: Vec4,
    pub spot_axis_cos_outer: Vec4,
    pub intensity_cos_inner: Vec4,
    pub flags: [u32; 4],
}

/// A view's lights and environment; the layout of `Lights` in `fur_bsdf.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct LightsUniform {
    pub count: u32,
    pub padding_0: u32,
    pub padding_1: u32,
    pub padding_2: u32,
    pub light_tint: Vec4,
    pub environment_tint: Vec4,
    pub environment_sh: [Vec4; 9],
    pub light: [GpuLight; 8],
}

/// One view from a shadowing light; the layout of `ShadowView` in `shadows.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ShadowViewUniform {
    pub light_clip_from_world: Mat4,
    pub light: Vec4,
    pub texel_world: f32,
    pub bias_world: f32,
    pub perspective: f32,
    pub near: f32,
    pub far: f32,
    pub texel: f32,
    pub _padding_0: f32,
    pub _padding_1: f32,
}

/// The most light views one shadow map holds (`SHADOW_VIEWS` in `shadows.wgsl`).
pub(crate) const SHADOW_VIEWS: usize = 12;

/// Every shadowing light's maps; the layout of `Shadow` in `shadows.wgsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
pub(crate) struct ShadowUniform {
    pub extinction: f32,
    pub pass_view: u32,
    pub layers: u32,
    pub _padding_1: u32,
    pub layer_ends: Vec4,
    pub light_views: [[u32; 4]; 8],
    pub views: [ShadowViewUniform; SHADOW_VIEWS],
}

pub(crate) const OBJECT_UNIFORM_BYTES: u64 = size_of::<ObjectUniform>() as u64;

/// A Rust struct's fields as `offset_of!` and `size_of` see them, for [`assert_mirrors`].
#[cfg(test)]
#[derive(Debug)]
pub(crate) struct RustLayout {
    pub name: &'static str,
    pub size: usize,
    /// `(name, offset, size)` of every field, in declaration order.
    pub fields: Vec<(&'static str, usize, usize)>,
}

/// The [`RustLayout`] of struct `$ty`, naming every one of its fields (the list is checked
/// against the struct: a field left out does not compile).
#[cfg(test)]
macro_rules! rust_layout {
    ($ty:ident { $($field:ident),+ $(,)? }) => {{
        fn every_field(value: &$ty) {
            let $ty { $($field: _),+ } = value;
        }
        fn size_of_field<T, F>(_: impl Fn(&T) -> &F) -> usize {
            size_of::<F>()
        }
        let _: fn(&$ty) = every_field;
        $crate::shaders::RustLayout {
            name: stringify!($ty),
            size: size_of::<$ty>(),
            fields: vec![$(
                (stringify!($field), std::mem::offset_of!($ty, $field), size_of_field(|value: &$ty| &value.$field))
            ),+],
        }
    }};
}
#[cfg(test)]
pub(crate) use rust_layout;

/// One member of a WGSL struct as naga lays it out.
#[cfg(test)]
#[derive(Debug)]
struct WgslMember {
    name: String,
    offset: u32,
    size: u32,
    /// A vertex input's location.
    #[cfg_attr(not(feature = "lab"), expect(dead_code, reason = "read by the lab's vertex input checks"))]
    location: Option<u32>,
}

/// Parses `source` with naga and returns the members and the size of its struct `name`.
#[cfg(test)]
fn wgsl_struct(source: &str, name: &str) -> (Vec<WgslMember>, u32) {
    let module =
        naga::front::wgsl::parse_str(source).unwrap_or_else(|error| panic!("{}", error.emit_to_string(source)));
    let found = module.types.iter().find(|(_, ty)| ty.name.as_deref() == Some(name));
    let Some((_, naga::Type { inner: naga::TypeInner::Struct { members, span }, .. })) = found else {
        panic!("no struct `{name}` in the WGSL module");
    };
    let members = members
        .iter()
        .map(|member| WgslMember {
            name: member.name.clone().unwrap_or_default(),
            offset: member.offset,
            size: module.types[member.ty].inner.size(module.to_ctx()),
            location: match member.binding {
                Some(naga::Binding::Location { location, .. }) => Some(location),
                _ => None,
            },
        })
        .collect();
    (members, *span)
}

/// Asserts that `rust` mirrors the WGSL struct `wgsl` of `source` as a uniform or storage
/// buffer holds it: every WGSL member has a Rust field of the same name (a leading `_` aside)
/// at the same offset with the same size, every other Rust field is `_padding...`, and both
/// structs have the same size.
#[cfg(test)]
pub(crate) fn assert_mirrors(source: &str, wgsl: &str, rust: &RustLayout) {
    let (members, span) = wgsl_struct(source, wgsl);
    let name = |field: &str| field.trim_start_matches('_').to_owned();
    for WgslMember { name: member, offset, size, .. } in &members {
        let field = rust.fields.iter().find(|(field, ..)| name(field) == *member);
        let Some(&(field, rust_offset, rust_size)) = field else {
            panic!("`{wgsl}.{member}` has no field in `{}`", rust.name);
        };
        assert_eq!(
            (rust_offset, rust_size),
            (*offset as usize, *size as usize),
            "`{}.{field}` (offset, size) against `{wgsl}.{member}`",
            rust.name
        );
    }
    for (field, offset, _) in &rust.fields {
        assert!(
            field.starts_with("_padding") || members.iter().any(|member| member.name == name(field)),
            "`{}.{field}` (offset {offset}) is in no member of `{wgsl}` and is not padding",
            rust.name
        );
    }
    assert_eq!(rust.size, span as usize, "size of `{}` against `{wgsl}`", rust.name);
}

/// Asserts that `rust`, read through the vertex `attributes`, mirrors the WGSL vertex input
/// `wgsl` of `source`: each member's location has an attribute at the offset of the Rust field
/// of the member's name, and member, field and attribute format have the same size.
#[cfg(all(test, feature = "lab"))]
pub(crate) fn assert_vertex_mirrors(source: &str, wgsl: &str, rust: &RustLayout, attributes: &[wgpu::VertexAttribute]) {
    let (members, _) = wgsl_struct(source, wgsl);
    assert_eq!(members.len(), rust.fields.len(), "fields of `{}` against `{wgsl}`", rust.name);
    assert_eq!(attributes.len(), members.len(), "attributes against `{wgsl}`");
    for WgslMember { name: member, size, location, .. } in &members {
        let location = location.unwrap_or_else(|| panic!("`{wgsl}.{member}` has no location"));
        let attribute = attributes
            .iter()
            .find(|a| a.shader_location == location)
            .unwrap_or_else(|| panic!("no attribute at location {location} (`{wgsl}.{member}`)"));
        let &(_, offset, rust_size) = rust
            .fields
            .iter()
            .find(|(field, ..)| field == member)
            .unwrap_or_else(|| panic!("`{wgsl}.{member}` has no field in `{}`", rust.name));
        assert_eq!(attribute.offset, offset as u64, "offset of `{}.{member}` and its attribute", rust.name);
        assert_eq!(
            (rust_size as u64, attribute.format.size()),
            (u64::from(*size), u64::from(*size)),
            "size of `{}.{member}`, its attribute's format and `{wgsl}.{member}`",
            rust.name
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::shaders::{silhouette_shader_source, unified_shader_source, view_lod_shader_source};
    use wgpu::util::DrawIndexedIndirectArgs;

    #[test]
    fn shadow_uniform_mirrors_shadow() {
        let rust =
            rust_layout!(ShadowUniform { extinction, pass_view, layers, _padding_1, layer_ends, light_views, views });
        assert_mirrors(&unified_shader_source(), "Shadow", &rust);
        let rust = rust_layout!(ShadowViewUniform {
            light_clip_from_world,
            light,
            texel_world,
            bias_world,
            perspective,
            near,
            far,
            texel,
            _padding_0,
            _padding_1
        });
        assert_mirrors(&unified_shader_source(), "ShadowView", &rust);
        assert!(unified_shader_source().contains(&format!("const SHADOW_VIEWS = {SHADOW_VIEWS}u;")));
    }

    #[test]
    fn view_uniform_mirrors_view() {
        let rust = rust_layout!(ViewUniform {
            clip_from_world,
            camera_position,
            ambient,
            light_direction,
            _padding_0,
            light_colour,
            _padding_1
        });
        assert_mirrors(&unified_shader_source(), "View", &rust);
    }

    #[test]
    fn object_uniform_mirrors_object() {
        let rust = rust_layout!(ObjectUniform {
            world_from_model,
            world_normal_from_model,
            colour,
            vertex_count,
            layers,
            triangle_count,
            edge_count,
            has_uvs,
            has_surface,
            shell_slices,
            wedge_count,
            tiles_per_uv,
            tiles_per_world,
            world_per_uv,
            interpolation,
            fin_fade_cos,
            shell_fade_cos,
            root_occlusion,
            specular,
            shininess,
            lod_blend,
            lod_stride,
            lod_shells,
            lod_view,
            lod_view_start,
            lod_view_full,
            furred_triangle_count,
            fin_edge_count,
            groom_shading,
            wet_darkening,
            wet_shine,
            wet_clump,
            clump_cell_texels,
            wet_any,
            shading_model,
            fur_pigment,
            fur_roughness,
            fur_cuticle_tilt,
            fur_medulla,
            coat_fade,
            fin_fade,
            tint,
            lean_share,
            lean_texels,
            _padding_3,
            pool
        });
        assert_mirrors(&unified_shader_source(), "Object", &rust);
    }

    #[test]
    fn lights_uniform_mirrors_lights() {
        let rust = rust_layout!(LightsUniform {
            count,
            padding_0,
            padding_1,
            padding_2,
            light_tint,
            environment_tint,
            environment_sh,
            light
        });
        assert_mirrors(&unified_shader_source(), "Lights", &rust);
        let rust = rust_layout!(GpuLight { position_or_direction, spot_axis_cos_outer, intensity_cos_inner, flags });
        assert_mirrors(&unified_shader_source(), "Light", &rust);
    }

    #[test]
    fn indirect_draws_mirror_the_listing_passes_draws() {
        let rust = rust_layout!(DrawIndexedIndirectArgs {
            index_count,
            instance_count,
            first_index,
            base_vertex,
            first_instance
        });
        assert_mirrors(&silhouette_shader_source(), "FinDraw", &rust);
        assert_mirrors(&view_lod_shader_source(), "ShellDraw", &rust);
    }

    /// `View` with two members swapped, and one left out.
    #[repr(C)]
    struct Swapped {
        clip_from_world: Mat4,
        ambient: f32,
        camera_position: Vec3,
        light_direction: Vec3,
        _padding_0: f32,
        light_colour: Vec3,
        _padding_1: f32,
    }

    #[repr(C)]
    struct Short {
        clip_from_world: Mat4,
        camera_position: Vec3,
        ambient: f32,
        light_direction: Vec3,
        _padding_0: f32,
        light_colour: Vec3,
    }

    #[test]
    #[should_panic(expected = "`Swapped.camera_position` (offset, size) against `View.camera_position`")]
    fn a_reordered_mirror_fails() {
        let rust = rust_layout!(Swapped {
            clip_from_world,
            ambient,
            camera_position,
            light_direction,
            _padding_0,
            light_colour,
            _padding_1
        });
        assert_eq!(size_of::<Swapped>(), size_of::<ViewUniform>(), "the size alone cannot tell");
        assert_mirrors(&unified_shader_source(), "View", &rust);
    }

    #[test]
    #[should_panic(expected = "`View.padding_1` has no field in `Short`")]
    fn a_mirror_without_a_member_fails() {
        let rust = rust_layout!(Short {
            clip_from_world,
            camera_position,
            ambient,
            light_direction,
            _padding_0,
            light_colour
        });
        assert_mirrors(&unified_shader_source(), "View", &rust);
    }
}
