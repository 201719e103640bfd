//! The environment: light from every direction, given as a sky/ground colour pair or an
//! equirectangular image (PNG, Radiance HDR or OpenEXR), reduced to spherical harmonics.
//!
//! An image's columns run once around +Y (column 0 toward -Z, turning from -Z toward +X as the
//! column grows) and its rows from straight up (+Y, row 0) to straight down.

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use glam::{Quat, Vec3};

use super::sh::{Sh9, sh9_basis};

/// An `[environment]` table.
///
/// ```toml
/// [environment]
/// sky = [0.45, 0.55, 0.7]     # radiance from above the horizon (linear RGB)
/// ground = [0.2, 0.17, 0.14]  # from below
/// # or: image = "studio.hdr"  # equirectangular PNG, HDR or EXR, beside the script
/// intensity = 1.0             # scales the radiance (default 1)
/// rotation_deg = 0.0          # turns the image around +Y (default 0)
/// ```
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EnvironmentSpec {
    /// Radiance from above the horizon (with `ground`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub sky: Option<Vec3>,
    /// Radiance from below the horizon (with `sky`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ground: Option<Vec3>,
    /// An equirectangular image, relative to the file that names it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub image: Option<PathBuf>,
    /// Scales the radiance.
    #[serde(default = "one")]
    pub intensity: f32,
    /// Turns the image around +Y, degrees.
    #[serde(default)]
    pub rotation_deg: f32,
}

fn one() -> f32 {
    1.0
}

/// Why an environment could not be made; every message names the file (or the key).
#[derive(Debug, thiserror::Error)]
pub enum EnvironmentError {
    /// A value out of range or a missing one.
    #[error("{key}: {problem}")]
    Invalid {
        /// The key.
        key: String,
        /// What is wrong.
        problem: String,
    },
    /// The image could not be read or is not an image.
    #[error("environment image {}: {problem}", file.display())]
    Image {
        /// The image file.
        file: PathBuf,
        /// Why.
        problem: String,
    },
}

/// The environment as the renderer takes it: its radiance in 9 SH coefficients per channel.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Environment {
    /// The radiance's projection.
    pub sh: Sh9,
}

impl Environment {
    /// Radiance `sky` from every direction above the horizon (y > 0) and `ground` below, in
    /// closed form: only the constant and the vertical linear term are not zero.
    #[must_use]
    pub fn sky_ground(sky: Vec3, ground: Vec3) -> Self {
        let mut sh = Sh9::default();
        sh.coefficients[0] = (sky + ground) * (2.0 * PI * 0.282_094_8);
        sh.coefficients[1] = (sky - ground) * (PI * 0.488_602_5);
        Self { sh }
    }

    /// A uniform environment of radiance `radiance`.
    #[must_use]
    pub fn uniform(radiance: Vec3) -> Self {
        Self { sh: Sh9::uniform(radiance) }
    }

    /// The direction of an equirectangular image's texel centre `(column, row)` of `width` x
    /// `height` texels.
    #[must_use]
    pub fn equirect_direction(column: f32, row: f32, width: u32, height: u32) -> Vec3 {
        let phi = (column + 0.5) / width as f32 * 2.0 * PI;
        let theta = (row + 0.5) / height as f32 * PI;
        Vec3::new(theta.sin() * phi.sin(), theta.cos(), -theta.sin() * phi.cos())
    }

    /// Projects an equirectangular image of linear RGB radiance (`width * height` texels, row
    /// after row from the top), each texel weighted by its solid angle.
    ///
    /// # Errors
    /// [`EnvironmentError::Invalid`] for an empty image, a size that does not match, or a texel
    /// that is negative or not finite.
    pub fn from_equirect(texels: &[Vec3], width: u32, height: u32) -> Result<Self, EnvironmentError> {
        if width == 0 || height == 0 || texels.len() != width as usize * height as usize {
            return Err(EnvironmentError::Invalid {
                key: "image".into(),
                problem: format!("{} texels for a {width}x{height} image", texels.len()),
            });
        }
        if let Some(i) = texels.iter().position(|t| !t.is_finite() || t.min_element() < 0.0) {
            return Err(EnvironmentError::Invalid {
                key: "image".into(),
                problem: format!("texel {i} is negative or not finite ({})", texels[i]),
            });
        }
        Ok(Self { sh: project(texels, width, height) })
    }

    /// Loads an equirectangular image (PNG as sRGB, HDR and EXR as linear radiance).
    ///
    /// # Errors
    /// [`EnvironmentError::Image`] naming the file when it cannot be read or is not an image.
    pub fn load_image(path: &Path) -> Result<Self, EnvironmentError> {
        let image_error = |problem: String| EnvironmentError::Image { file: path.to_path_buf(), problem };
        let reader = image::ImageReader::open(path)
            .map_err(|e| image_error(e.to_string()))?
            .with_guessed_format()
            .map_err(|e| image_error(e.to_string()))?;
        if reader.format().is_none() {
            return Err(image_error("not a PNG, HDR or EXR image".into()));
        }
        let decoded = reader.decode().map_err(|e| image_error(e.to_string()))?;
        // 8-bit images are sRGB-encoded colours; float images hold linear radiance.
        let srgb = matches!(
            decoded.color(),
            image::ColorType::L8 | image::ColorType::La8 | image::ColorType::Rgb8 | image::ColorType::Rgba8
        );
        let rgb = decoded.to_rgb32f();
        let (width, height) = rgb.dimensions();
        let decode = |v: f32| if srgb { srgb_to_linear(v) } else { v };
        let texels: Vec<Vec3> =
            rgb.pixels().map(|p| Vec3::new(decode(p.0[0]), decode(p.0[1]), decode(p.0[2]))).collect();
        Self::from_equirect(&texels, width, height).map_err(|e| image_error(e.to_string()))
    }

    /// The environment an `[environment]` table describes; image paths relative to `folder`.
    ///
    /// # Errors
    /// [`EnvironmentError`] naming the key (`environment.sky`...) or the image file.
    pub fn from_spec(spec: &EnvironmentSpec, folder: &Path) -> Result<Self, EnvironmentError> {
        let invalid =
            |key: &str, problem: String| EnvironmentError::Invalid { key: format!("environment.{key}"), problem };
        if !spec.intensity.is_finite() || spec.intensity < 0.0 {
            return Err(invalid("intensity", format!("must be a finite number at least 0, got {}", spec.intensity)));
        }
        if !spec.rotation_deg.is_finite() {
            return Err(invalid("rotation_deg", format!("must be finite, got {}", spec.rotation_deg)));
        }
        for (key, colour) in [("sky", spec.sky), ("ground", spec.ground)] {
            if let Some(c) = colour
                && (!c.is_finite() || c.min_element() < 0.0)
            {
                return Err(invalid(key, format!("must be finite and at least 0, got {c}")));
            }
        }
        let environment = match (&spec.image, spec.sky, spec.ground) {
            (Some(image), None, None) => Self::load_image(&folder.join(image))?.rotated(spec.rotation_deg),
            (Some(_), _, _) => return Err(invalid("image", "give an image or sky and ground, not both".into())),
            (None, Some(sky), Some(ground)) => Self::sky_ground(sky, ground),
            (None, _, _) => return Err(invalid("sky", "give sky and ground, or an image".into())),
        };
        Ok(Self { sh: environment.sh.scaled(spec.intensity) })
    }

    /// This environment turned `degrees` around +Y, by reprojecting its band-limited radiance.
    #[must_use]
    pub fn rotated(&self, degrees: f32) -> Self {
        if degrees == 0.0 {
            return *self;
        }
        let turn = Quat::from_rotation_y(degrees.to_radians());
        // Band 0-2 rotations are exact on a fine enough grid of directions.
        let (width, height) = (64u32, 32u32);
        let texels: Vec<Vec3> = (0..height)
            .flat_map(|row| (0..width).map(move |column| (column, row)))
            .map(|(column, row)| {
                let d = Self::equirect_direction(column as f32, row as f32, width, height);
                self.sh.radiance(turn.inverse() * d)
            })
            .collect();
        Self { sh: project(&texels, width, height) }
    }
}

/// The SH projection of an equirectangular image, each texel weighted by its exact solid angle.
fn project(texels: &[Vec3], width: u32, height: u32) -> Sh9 {
    let mut coefficients = [Vec3::ZERO; 9];
    let (dphi, dtheta) = (2.0 * PI / width as f32, PI / height as f32);
    for row in 0..height {
        let solid_angle = dphi * ((row as f32 * dtheta).cos() - ((row + 1) as f32 * dtheta).cos());
        for column in 0..width {
            let d = Environment::equirect_direction(column as f32, row as f32, width, height);
            let texel = texels[(row * width + column) as usize];
            for (c, b) in coefficients.iter_mut().zip(sh9_basis(d)) {
                *c += texel * (b * solid_angle);
            }
        }
    }
    Sh9 { coefficients }
}

fn srgb_to_linear(v: f32) -> f32 {
    if v <= 0.040_45 { v / 12.92 } else { ((v + 0.055) / 1.055).powf(2.4) }
}
