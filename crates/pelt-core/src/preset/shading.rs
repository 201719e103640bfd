//! The `[shading]` table: how the fur's strands reflect light.
//!
//! ```toml
//! [shading]
//! model = "fur"           # "fur" (default) | "kajiya-kay"
//! roughness = 0.35        # fur: longitudinal width of the lobes, 0.05..=1
//! cuticle_tilt_deg = 3.0  # fur: the scales' tilt, shifting the lobes along the strand, 0..=10
//! medulla = 0.4           # fur: share of light the medulla scatters, 0..=1
//! melanin = 1.0           # fur: eumelanin, 0..=8; with pheomelanin tints the coat's colour
//! pheomelanin = 0.0       # fur: 0..=8
//! ```

use glam::Vec3;

use crate::param::ParamError;

fn check_range(key: &str, value: f32, low: f32, high: f32) -> Result<(), ParamError> {
    if value.is_finite() && (low..=high).contains(&value) {
        Ok(())
    } else {
        Err(ParamError { key: key.to_owned(), problem: format!("must be between {low} and {high}, got {value}") })
    }
}

/// Which reflectance model lights the strands.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum ShadingModel {
    /// Kajiya-Kay's diffuse and highlight about the strand, one key light and an ambient term:
    /// the paper's look.
    #[serde(rename = "kajiya-kay")]
    KajiyaKay,
    /// R, TT and TRT lobes (Karis 2016's cheap form of Marschner et al.) with the medulla's
    /// scattered lobes (after Yan et al. 2017), every light and the environment.
    #[default]
    #[serde(rename = "fur")]
    Fur,
}

/// The `[shading]` table.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ShadingParams {
    /// The model. Default `"fur"`.
    pub model: ShadingModel,
    /// Longitudinal roughness, `0.05..=1`. Default 0.35.
    pub roughness: f32,
    /// Cuticle tilt, degrees, `0..=10`. Default 3.
    pub cuticle_tilt_deg: f32,
    /// Share of the light entering a strand that its medulla scatters, `0..=1`. Default 0.4.
    pub medulla: f32,
    /// Eumelanin concentration, `0..=8`; leave out (with `pheomelanin`) to take the colour from
    /// the texture alone.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub melanin: Option<f32>,
    /// Pheomelanin concentration, `0..=8`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pheomelanin: Option<f32>,
}

impl Default for ShadingParams {
    fn default() -> Self {
        Self {
            model: ShadingModel::Fur,
            roughness: 0.35,
            cuticle_tilt_deg: 3.0,
            medulla: 0.4,
            melanin: None,
            pheomelanin: None,
        }
    }
}

impl ShadingParams {
    /// Whether every field is its default (the table is then left out of a written preset).
    #[must_use]
    pub fn is_default(&self) -> bool {
        *self == Self::default()
    }

    /// Checks the ranges; keys are `shading.*`.
    ///
    /// # Errors
    /// [`ParamError`] naming the key and its range.
    pub fn validate(&self) -> Result<(), ParamError> {
        check_range("shading.roughness", self.roughness, 0.05, 1.0)?;
        check_range("shading.cuticle_tilt_deg", self.cuticle_tilt_deg, 0.0, 10.0)?;
        check_range("shading.medulla", self.medulla, 0.0, 1.0)?;
        if let Some(m) = self.melanin {
            check_range("shading.melanin", m, 0.0, 8.0)?;
        }
        if let Some(m) = self.pheomelanin {
            check_range("shading.pheomelanin", m, 0.0, 8.0)?;
        }
        Ok(())
    }

    /// The strands' colour from their pigments (multiplying the texture's): the transmittance of
    /// one pass through a strand with absorption `eumelanin * (0.419, 0.697, 1.37) +
    /// pheomelanin * (0.187, 0.4, 1.05)` (d'Eon et al. 2011), white without pigments given.
    #[must_use]
    pub fn pigment_colour(&self) -> Vec3 {
        if self.melanin.is_none() && self.pheomelanin.is_none() {
            return Vec3::ONE;
        }
        let absorption = self.melanin.unwrap_or(0.0) * Vec3::new(0.419, 0.697, 1.37)
            + self.pheomelanin.unwrap_or(0.0) * Vec3::new(0.187, 0.4, 1.05);
        (-absorption).exp()
    }
}
