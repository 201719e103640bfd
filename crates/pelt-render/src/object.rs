//! What every drawn object shares: the per-object uniform (group 1, binding 0 of every pipeline:
//! model transform, interpolation, fur look), the per-frame data a host gives for it, and the
//! byte counts objects report.

use glam::{Mat3, Mat4, Vec3};
use pelt_core::Mesh;

use crate::lod::FurLevel;
use crate::shaders::ObjectUniform;
use crate::textures::TextureShape;

/// How one fur looks, beyond its textures: lighting response, fading and strand density.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FurLook {
    /// Strength of the Kajiya-Kay highlight.
    pub specular: f32,
    /// Kajiya-Kay specular exponent.
    pub shininess: f32,
    /// Brightness left at the roots (1 = no darkening toward the roots).
    pub root_occlusion: f32,
    /// Fins are fully shown where the faces beside the edge turn below this |cos| to the view.
    pub fin_fade_cos: f32,
    /// Shells fade where the surface turns below this |cos| to the view.
    pub shell_fade_cos: f32,
    /// Shell texture tiles across the mesh's bounding radius, so strands have the same density
    /// relative to the mesh whatever its size. (A larger tile holds more, finer strands: the
    /// texture's resolution sets how fine the fur is, as in the paper's "resizing".)
    pub tiles_per_radius: f32,
    /// Wet albedo is `1 - wet_darkening * wetness` of the dry one (`[wet] darkening`).
    pub wet_darkening: f32,
    /// The wet highlight grows by `1 + wet_shine * w`, its exponent by `1 + 2 * wet_shine * w`
    /// (`[wet] shine`).
    pub wet_shine: f32,
    /// Clump cells, in shell texels, for wet fur and a groom's clump map alike
    /// (`[wet] clump_size`).
    pub clump_size: f32,
    /// How strongly a soaked strand clumps, 0..1 (`[wet] clump_strength`).
    pub clump_strength: f32,
    /// The reflectance model and its parameters (`[shading]`).
    pub shading: FurShading,
    /// Multiplies the coat's colour, strands and skin (linear RGB; white keeps the textures'):
    /// one member of a herd in its own colour on the shared textures.
    pub tint: Vec3,
}

/// The reflectance model a fur is lit with and the fur model's parameters (`[shading]`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FurShading {
    /// The fur model (R, TT, TRT and medulla lobes, every light and the environment), else
    /// Kajiya-Kay with the key light and the ambient.
    pub fur_model: bool,
    /// The pigments' colour, multiplying the texture's (white: the texture's alone).
    pub pigment: Vec3,
    /// Longitudinal roughness of the lobes.
    pub roughness: f32,
    /// Cuticle tilt, radians.
    pub cuticle_tilt: f32,
    /// Share of the entering light the medulla scatters.
    pub medulla: f32,
}

impl Default for FurShading {
    /// Kajiya-Kay; the fur model's parameters at the `[shading]` defaults.
    fn default() -> Self {
        Self::from_params(&pelt_core::preset::ShadingParams::default())
    }
}

impl FurShading {
    /// The shading a preset's `[shading]` table describes.
    #[must_use]
    pub fn from_params(params: &pelt_core::preset::ShadingParams) -> Self {
        Self {
            fur_model: params.model == pelt_core::preset::ShadingModel::Fur,
            pigment: params.pigment_colour(),
            roughness: params.roughness,
            cuticle_tilt: params.cuticle_tilt_deg.to_radians(),
            medulla: params.medulla,
        }
    }
}

impl FurLook {
    /// This look with `wet`'s darkening, shine and clumps.
    #[must_use]
    pub fn with_wet(self, wet: &pelt_core::wet::WetParams) -> Self {
        Self {
            wet_darkening: wet.darkening,
            wet_shine: wet.shine,
            clump_size: wet.clump_size,
            clump_strength: wet.clump_strength,
            ..self
        }
    }
}

impl Default for FurLook {
    fn default() -> Self {
        Self {
            specular: 0.2,
            shininess: 40.0,
            root_occlusion: 0.3,
            fin_fade_cos: 0.1,
            shell_fade_cos: 0.25,
            tiles_per_radius: pelt_core::reference::STANDARD_TILES_PER_RADIUS,
            wet_darkening: 0.5,
            wet_shine: 0.6,
            clump_size: 12.0,
            clump_strength: 0.8,
            shading: FurShading::default(),
            tint: Vec3::ONE,
        }
    }
}

/// One fur's data for the coming frame, written by [`crate::GpuFur::prepare`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FurFrame {
    /// The model transform (any affine transform; the shared array is in model space).
    pub world_from_model: Mat4,
    /// Where the frame falls between the previous and the current simulation state: 0 draws the
    /// previous state, 1 the current one (see [`crate::GpuFur::push_state`]).
    pub interpolation: f32,
    /// Lighting, fading and density.
    pub look: FurLook,
    /// Level of detail: which shells and fin segments to draw ([`FurLevel::FULL`]: all).
    pub level: FurLevel,
    /// Whether any vertex of the fur is wet ([`crate::GpuFur::set_wetness`]): only then do the
    /// shaders read the wetness (a dry fur draws the bytes of one that never was wet).
    pub wet: bool,
}

impl Default for FurFrame {
    fn default() -> Self {
        Self {
            world_from_model: Mat4::IDENTITY,
            interpolation: 1.0,
            look: FurLook::default(),
            level: FurLevel::FULL,
            wet: false,
        }
    }
}

/// Where an object keeps its bytes on the GPU.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct GpuBytes {
    /// Vertex positions: the shared array (once per kept state) or the separated vertices'
    /// positions.
    pub positions: u64,
    /// Other per-vertex or per-corner data: normals, uvs (the separated structure's 20 bytes a
    /// vertex).
    pub attributes: u64,
    /// Topology and index buffers.
    pub indices: u64,
    /// Shell, fin and surface textures with their mipmaps, and the strands' tilts once a copy of
    /// the fur has been wet.
    pub textures: u64,
}

impl GpuBytes {
    /// Positions, attributes and indices: the structure's bytes (what
    /// `pelt_core::fur::Footprint::total_bytes` predicts for one state).
    #[must_use]
    pub fn structure(&self) -> u64 {
        self.positions + self.attributes + self.indices
    }

    /// Everything.
    #[must_use]
    pub fn total(&self) -> u64 {
        self.structure() + self.textures
    }
}

/// The constant part of an object's uniform: what its mesh and textures fix.
#[derive(Clone, Copy, Debug)]
pub(crate) struct ObjectShape {
    pub vertex_count: u32,
    pub layers: u32,
    pub triangle_count: u32,
    pub edge_count: u32,
    /// The triangles the shells draw and the edges the fins draw: the first ones of the GPU's
    /// topology (`geometry.rs` keeps a groomed fur's furred triangles and fin edges first).
    pub furred_triangle_count: u32,
    pub fin_edge_count: u32,
    pub has_uvs: bool,
    /// Meshes with uvs on the GPU: the wedges the shells walk (`geometry.rs`); 0 otherwise.
    pub wedge_count: u32,
    /// Model units per uv unit (sqrt of surface area over uv area): uv tiles match model tiles.
    pub world_per_uv: f32,
    /// Bounding radius of the base mesh, model units.
    pub radius: f32,
    /// Whether the fur has a groom (its attribute buffer holds one entry per vertex).
    pub groomed: bool,
    /// Whether the groom's density, clump or tint reach the shading.
    pub groom_shading: bool,
}

impl ObjectShape {
    pub fn new(mesh: &Mesh, layers: u32) -> Self {
        Self {
            vertex_count: mesh.vertex_count() as u32,
            layers,
            triangle_count: mesh.triangles.len() as u32,
            edge_count: mesh.edges.len() as u32,
            furred_triangle_count: mesh.triangles.len() as u32,
            fin_edge_count: mesh.edges.len() as u32,
            has_uvs: mesh.corner_uvs.is_some(),
            wedge_count: 0,
            world_per_uv: world_per_uv(mesh),
            radius: mesh.bounding_sphere().1.max(1e-6),
            groomed: false,
            groom_shading: false,
        }
    }

    /// The vertex indices one shell walks: the wedges of a mesh with uvs, else the base vertices.
    pub fn vertices_per_shell(&self) -> u32 {
        if self.has_uvs { self.wedge_count } else { self.vertex_count }
    }

    /// Where the index buffer of the base triangles starts in the topology buffer, in `u32`s:
    /// the corners' wedges at its end with uvs, else the base triangles at its start.
    pub fn surface_indices_first(&self) -> u64 {
        if self.has_uvs {
            3 * u64::from(self.triangle_count) + 4 * u64::from(self.edge_count) + u64::from(self.wedge_count)
        } else {
            0
        }
    }

    /// The uniform for one frame. `colour`: the skin's (furs) or the mesh's (plain) colour.
    pub fn uniform(&self, frame: &FurFrame, colour: Vec3, textures: TextureShape) -> ObjectUniform {
        let TextureShape { shell_slices, has_surface, lean } = textures;
        let look = &frame.look;
        let level = frame.level.clamped(self.layers);
        let tiles_per_world = look.tiles_per_radius / self.radius;
        // The inverse transpose keeps normals perpendicular under non-uniform scale; a singular
        // transform (a flattened model) keeps the plain 3x3 rather than producing infinities.
        let linear = Mat3::from_mat4(frame.world_from_model);
        let normal_matrix = if linear.determinant().abs() > 1e-30 { linear.inverse().transpose() } else { linear };
        ObjectUniform {
            world_from_model: frame.world_from_model,
            world_normal_from_model: [
                normal_matrix.x_axis.extend(0.0),
                normal_matrix.y_axis.extend(0.0),
                normal_matrix.z_axis.extend(0.0),
            ],
            colour: colour.extend(1.0),
            vertex_count: self.vertex_count,
            layers: self.layers,
            triangle_count: self.triangle_count,
            edge_count: self.edge_count,
            has_uvs: u32::from(self.has_uvs),
            has_surface: u32::from(has_surface),
            shell_slices,
            wedge_count: self.wedge_count,
            tiles_per_uv: tiles_per_world * self.world_per_uv,
            tiles_per_world,
            world_per_uv: self.world_per_uv,
            interpolation: frame.interpolation.clamp(0.0, 1.0),
            fin_fade_cos: look.fin_fade_cos.max(1e-3),
            shell_fade_cos: look.shell_fade_cos.max(1e-3),
            // The skin stands in for a fading coat: no roots to darken where it is gone.
            root_occlusion: look.root_occlusion + (1.0 - look.root_occlusion) * (1.0 - level.coat),
            specular: look.specular,
            shininess: look.shininess,
            lod_blend: level.blend,
            lod_stride: level.stride,
            lod_shells: level.shells(self.layers),
            lod_view: if level.facing.is_some() { 1.0 } else { 0.0 },
            lod_view_start: level.facing.map_or(0.0, |[start, _]| start),
            lod_view_full: level.facing.map_or(1.0, |[_, full]| full),
            furred_triangle_count: self.furred_triangle_count,
            fin_edge_count: self.fin_edge_count,
            groom_shading: u32::from(self.groom_shading),
            wet_darkening: look.wet_darkening,
            wet_shine: look.wet_shine,
            wet_clump: look.clump_strength.clamp(0.0, 1.0),
            clump_cell_texels: look.clump_size.clamp(2.0, 128.0),
            wet_any: u32::from(frame.wet),
            shading_model: u32::from(look.shading.fur_model),
            fur_pigment: look.shading.pigment,
            fur_roughness: look.shading.roughness.clamp(0.05, 1.0),
            fur_cuticle_tilt: look.shading.cuticle_tilt,
            fur_medulla: look.shading.medulla.clamp(0.0, 1.0),
            coat_fade: level.coat,
            fin_fade: level.fins,
            tint: if look.tint.is_finite() { look.tint.max(Vec3::ZERO) } else { Vec3::ONE },
            lean_share: lean.share.clamp(0.0, 1.0),
            lean_texels: lean.texels.max(0.0),
            _padding_3: [0.0; 3],
            pool: [0; 4],
        }
    }
}

/// How the shells lay the tile on `mesh` with `look`: what the explicit strand reference
/// (`pelt_core::reference::StrandReference`) needs to place the same strands where the shells
/// show them.
#[must_use]
pub fn tile_mapping(mesh: &Mesh, look: &FurLook) -> pelt_core::reference::TileMapping {
    let shape = ObjectShape::new(mesh, 1);
    let uniform = shape.uniform(
        &FurFrame { look: *look, ..FurFrame::default() },
        Vec3::ONE,
        TextureShape { shell_slices: 1, ..TextureShape::default() },
    );
    pelt_core::reference::TileMapping { tiles_per_uv: uniform.tiles_per_uv, tiles_per_world: uniform.tiles_per_world }
}

/// sqrt(surface area / uv area), or 1 without uvs.
pub(crate) fn world_per_uv(mesh: &Mesh) -> f32 {
    let Some(uvs) = &mesh.corner_uvs else { return 1.0 };
    let uv_area: f32 = uvs.iter().map(|[a, b, c]| (*b - *a).perp_dot(*c - *a).abs() * 0.5).sum();
    if uv_area > 1e-12 { (mesh.surface_area() / uv_area).sqrt() } else { 1.0 }
}

/// Creates the uniform buffer of one object (the separated structure's: a unified fur's lives in
/// its pool).
#[cfg(feature = "lab")]
pub(crate) fn uniform_buffer(device: &wgpu::Device) -> wgpu::Buffer {
    device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("pelt object"),
        size: crate::shaders::OBJECT_UNIFORM_BYTES,
        usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normals_follow_non_uniform_scale() {
        let (mesh, _) = pelt_core::Builtin::Box.mesh();
        let shape = ObjectShape::new(&mesh, 4);
        let frame = FurFrame { world_from_model: Mat4::from_scale(Vec3::new(2.0, 1.0, 1.0)), ..FurFrame::default() };
        let uniform = shape.uniform(&frame, Vec3::ONE, TextureShape { shell_slices: 4, ..TextureShape::default() });
        let normal_matrix = Mat3::from_cols(
            uniform.world_normal_from_model[0].truncate(),
            uniform.world_normal_from_model[1].truncate(),
            uniform.world_normal_from_model[2].truncate(),
        );
        // A plane x = y in model space is stretched along x; its normal turns toward y.
        let normal = (normal_matrix * Vec3::new(1.0, -1.0, 0.0)).normalize();
        let in_plane = frame.world_from_model.transform_vector3(Vec3::new(1.0, 1.0, 0.0));
        assert!(normal.dot(in_plane).abs() < 1e-6, "normal {normal} stays perpendicular to {in_plane}");
        let flat = FurFrame { world_from_model: Mat4::from_scale(Vec3::new(1.0, 0.0, 1.0)), ..frame };
        let uniform = shape.uniform(&flat, Vec3::ONE, TextureShape { shell_slices: 4, ..TextureShape::default() });
        assert!(uniform.world_normal_from_model.iter().all(|c| c.is_finite()));
    }
}
