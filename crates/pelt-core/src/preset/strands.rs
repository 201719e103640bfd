//! A preset's strand groom (`[groom] strands`): USD curves baked per vertex against the preset's
//! own fur (its length, growth direction, strand field and colour).

use glam::{Vec2, Vec3};

use super::{Preset, PresetError};
use crate::fur::FurLength;
use crate::groom::{Groom, GroomError, GroomParams, StrandBakeParams, StrandBakeReport, bake_strands, tangent_frames};
use crate::mesh::Mesh;
use crate::reference::{CLUMP_PARTING, TileMapping};

/// Roots farther than this share of the mesh's bounding radius from its surface are off it.
pub const ROOT_TOLERANCE_FRACTION: f32 = 0.01;

impl Preset {
    /// The groom the `[groom]` table names, and with `strands` the bake's report: the curves
    /// baked per vertex ([`bake_strands`], the mesh taken as Y up in metres), each map the table
    /// also names replacing the baked one.
    ///
    /// # Errors
    /// As [`Preset::groom`]; a curve file that cannot be read or baked is a
    /// [`PresetError::Groom`] naming it.
    pub fn groom_with_report(
        &self,
        mesh: &Mesh,
        mesh_name: &str,
    ) -> Result<(Option<Groom>, Option<StrandBakeReport>), PresetError> {
        let groom_error = |error: GroomError| PresetError::Groom { file: self.file.clone(), error };
        let Some(strands) = &self.groom.strands else {
            return Ok((self.groom.load(mesh, mesh_name, |path| self.resolve(path)).map_err(groom_error)?, None));
        };
        if self.groom.file.is_some() {
            return Err(PresetError::Invalid {
                file: self.file.clone(),
                key: "groom.strands".to_owned(),
                problem: "name a strand groom or a groom file, not both".to_owned(),
            });
        }
        let file = self.resolve(strands);
        let curves = crate::usd::read_curves(&file).map_err(|e| groom_error(GroomError::Usd(e.to_string())))?;
        let field = self.strand_field()?;
        let params = self.fur_params(mesh);
        let v = mesh.vertex_count();
        let lengths = match &params.length {
            FurLength::Constant(l) => vec![*l; v],
            FurLength::PerVertex(l) => l.clone(),
        };
        let mean_length_factor = if field.strands.is_empty() {
            1.0
        } else {
            field.strands.iter().map(|s| s.length_factor()).sum::<f32>() / field.strands.len() as f32
        };
        let expected_strands = TileMapping::standard(mesh).expected_strands(mesh, field.strands.len());
        let base_colours = base_colours(mesh, &field);
        let frames = tangent_frames(mesh);
        let direction = params.direction;
        let grow = |j: usize, flow: Vec2| direction.groomed(j, mesh.normals[j], frames[j], flow);
        let bake = StrandBakeParams {
            lengths: &lengths,
            layers: self.layers,
            mean_length_factor,
            expected_strands: &expected_strands,
            max_gather: CLUMP_PARTING,
            base_colours: &base_colours,
            grow: &grow,
            mesh_meters_per_unit: 1.0,
            tolerance: ROOT_TOLERANCE_FRACTION * mesh.bounding_sphere().1,
        };
        let (mut groom, report) = bake_strands(mesh, &curves, &file, &bake).map_err(groom_error)?;
        let named = GroomParams { strands: None, ..self.groom.clone() };
        if let Some(maps) = named.load(mesh, mesh_name, |path| self.resolve(path)).map_err(groom_error)? {
            for map in crate::groom::GroomMap::ALL {
                if let Some(values) = maps.values(map) {
                    groom.set_values(map, values);
                }
            }
        }
        Ok((Some(groom), Some(report)))
    }
}

/// The preset's strand colour at each vertex, linear: the field's mean colour, times the surface
/// texture at the vertex in surface mode.
fn base_colours(mesh: &Mesh, field: &crate::texture::StrandField) -> Vec<Vec3> {
    let decode = |x: f32| if x <= 0.04045 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) };
    let sample: Vec<Vec3> = field
        .strands
        .iter()
        .take(4096)
        .map(|s| field.colour(s, 0.5).clamp(Vec3::ZERO, Vec3::ONE).map(decode))
        .collect();
    let mean = if sample.is_empty() { Vec3::ONE } else { sample.iter().copied().sum::<Vec3>() / sample.len() as f32 };
    let mut colours = vec![mean; mesh.vertex_count()];
    if let (Some(image), Some(uvs)) = (field.surface(), &mesh.corner_uvs) {
        for (corners, uvs) in mesh.triangles.iter().zip(uvs) {
            for (&j, uv) in corners.iter().zip(uvs) {
                colours[j as usize] = mean * image.sample_wrapped(uv.x, uv.y).truncate().map(decode);
            }
        }
    }
    colours
}
