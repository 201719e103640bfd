//! The environment: light from every direction, given as a sky/ground colour pair, an
//! equirectangular image (PNG, Radiance HDR or OpenEXR) or a cube map's six faces, reduced to
//! spherical harmonics.
//!
//! An image's columns run once around +Y (column 0 toward -Z, turning from -Z toward +X as the
//! column grows) and its rows from straight up (+Y, row 0) to straight down.
//!
//! A cube map's faces follow the cube textures of wgpu, Vulkan and Direct3D: see
//! [`Environment::cube_direction`].

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use glam::{Mat3, Quat, Vec3};

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

/// What a cube map's texels hold.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CubeContent {
    /// The radiance arriving from each texel's direction.
    Radiance,
    /// The cosine-weighted mean of the radiance about each texel's direction (the irradiance of
    /// a surface facing it, over pi): what prefiltered diffuse ("irradiance") maps hold, so that
    /// a white Lambertian surface of normal `n` shows the texel toward `n`.
    Irradiance,
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

    /// The direction (unit, in the cube's own frame) of the centre of texel `(column, row)` of
    /// face `face` (0 to 5: +X, -X, +Y, -Y, +Z, -Z) of a cube map `size` texels square, each
    /// face's rows from the top. With `s` and `t` the texel centre's column and row mapped to
    /// -1..1, the faces look along `(1, -t, -s)`, `(-1, -t, s)`, `(s, 1, t)`, `(s, -1, -t)`,
    /// `(s, -t, 1)` and `(-s, -t, -1)`: the layout of wgpu's, Vulkan's and Direct3D's cube
    /// textures, whose lookup direction this is.
    #[must_use]
    pub fn cube_direction(face: usize, column: f32, row: f32, size: u32) -> Vec3 {
        let s = 2.0 * (column + 0.5) / size as f32 - 1.0;
        let t = 2.0 * (row + 0.5) / size as f32 - 1.0;
        let d = match face {
            0 => Vec3::new(1.0, -t, -s),
            1 => Vec3::new(-1.0, -t, s),
            2 => Vec3::new(s, 1.0, t),
            3 => Vec3::new(s, -1.0, -t),
            4 => Vec3::new(s, -t, 1.0),
            _ => Vec3::new(-s, -t, -1.0),
        };
        d.normalize()
    }

    /// Projects a cube map's six faces of linear RGB (`6 * size * size` texels: face after face
    /// in [`Environment::cube_direction`]'s order, each row after row from the top), each texel
    /// weighted by its exact solid angle. The environment's directions are the cube's lookup
    /// directions (see [`Environment::transformed`] to place it in a world). An
    /// [`CubeContent::Irradiance`] map is turned back into the band-limited radiance whose
    /// irradiance it holds (bands 1 and 2 scaled by 3/2 and 4, the inverse of the cosine lobe's
    /// convolution).
    ///
    /// # Errors
    /// [`EnvironmentError::Invalid`] for an empty cube, a size that does not match, or a texel
    /// that is negative or not finite.
    pub fn from_cube_faces(texels: &[Vec3], size: u32, content: CubeContent) -> Result<Self, EnvironmentError> {
        let face_texels = size as usize * size as usize;
        if size == 0 || texels.len() != 6 * face_texels {
            return Err(EnvironmentError::Invalid {
                key: "cube".into(),
                problem: format!("{} texels for six faces of {size}x{size}", texels.len()),
            });
        }
        if let Some(i) = texels.iter().position(|t| !t.is_finite() || t.min_element() < 0.0) {
            return Err(EnvironmentError::Invalid {
                key: "cube".into(),
                problem: format!(
                    "texel {} of face {} is negative or not finite ({})",
                    i % face_texels,
                    i / face_texels,
                    texels[i]
                ),
            });
        }
        let mut coefficients = [Vec3::ZERO; 9];
        for (i, &texel) in texels.iter().enumerate() {
            let (face, within) = (i / face_texels, i % face_texels);
            let (column, row) = ((within % size as usize) as f32, (within / size as usize) as f32);
            let d = Self::cube_direction(face, column, row, size);
            let weight = cube_texel_solid_angle(column, row, size);
            for (c, b) in coefficients.iter_mut().zip(sh9_basis(d)) {
                *c += texel * (b * weight);
            }
        }
        if content == CubeContent::Irradiance {
            // The cosine lobe's band weights over pi: 1, 2/3 and 1/4.
            for (k, c) in coefficients.iter_mut().enumerate() {
                *c *= [1.0, 1.5, 1.5, 1.5, 4.0, 4.0, 4.0, 4.0, 4.0][k];
            }
        }
        Ok(Self { sh: Sh9 { coefficients } })
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
        self.transformed(Mat3::from_quat(Quat::from_rotation_y(degrees.to_radians())))
    }

    /// This environment carried by the rotation or reflection `new_from_old` (an orthogonal
    /// matrix): the radiance it held toward `d` now arrives from `new_from_old * d`. Its
    /// band-limited radiance is reprojected; a matrix that is not orthogonal (or not finite)
    /// leaves the environment as it is.
    #[must_use]
    pub fn transformed(&self, new_from_old: Mat3) -> Self {
        let orthogonal = (new_from_old.transpose() * new_from_old).abs_diff_eq(Mat3::IDENTITY, 1e-3);
        if !new_from_old.is_finite() || !orthogonal || new_from_old == Mat3::IDENTITY {
            return *self;
        }
        let old_from_new = new_from_old.transpose();
        // Band 0-2 rotations are exact on a fine enough grid of directions.
        let (width, height) = (64u32, 32u32);
        let texels: Vec<Vec3> = (0..height)
            .flat_map(|row| (0..width).map(move |column| (column, row)))
            .map(|(column, row)| {
                let d = Self::equirect_direction(column as f32, row as f32, width, height);
                self.sh.radiance(old_from_new * d)
            })
            .collect();
        Self { sh: project(&texels, width, height) }
    }
}

/// The solid angle of a cube map's texel `(column, row)` on a face `size` texels square: the
/// area on the unit sphere of its square on the face at distance 1, by the closed form of the
/// integral of `(1 + x^2 + y^2)^(-3/2)` from a corner.
fn cube_texel_solid_angle(column: f32, row: f32, size: u32) -> f32 {
    let corner = |x: f32, y: f32| (x * y).atan2((x * x + y * y + 1.0).sqrt());
    let edge = |i: f32| 2.0 * i / size as f32 - 1.0;
    let (x0, x1, y0, y1) = (edge(column), edge(column + 1.0), edge(row), edge(row + 1.0));
    corner(x1, y1) - corner(x0, y1) - corner(x1, y0) + corner(x0, y0)
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
