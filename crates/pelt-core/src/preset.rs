//! Fur presets: everything about one fur in one TOML file.
//!
//! Every table denies unknown keys and every field has a default, so an empty file is a valid
//! preset (the [`Preset::default`] fur). Image paths are relative to the preset file's folder.
//!
//! ```toml
//! layers = 16          # shells above the base, 1..=MAX_LAYERS
//! length = 0.08        # fraction of the mesh's bounding-sphere radius, 0 < length <= 2
//! [direction]          # fur direction on the mesh (see `DirectionParams`)
//! [texture]            # the strand field (see `texture::TextureParams`)
//! [colour]             # colours are "#rrggbb" strings (see `texture::ColourParams`)
//! [simulation]         # `sim::SimParams`; equation = "pelt" | "paper" (`sim::Equation`)
//! [render]             # how Pelt's commands show it (see `RenderParams`)
//! [groom]              # per-vertex maps: length, density, direction, clump, tint (`groom::GroomParams`)
//! [shading]            # how strands reflect light: model, roughness, pigments (`ShadingParams`)
//! [wet]                # what wetness does: clumps, darkening, shine, weight, drying (`wet::WetParams`)
//! ```

mod shading;
mod strands;

pub use shading::{ShadingModel, ShadingParams};

pub use strands::ROOT_TOLERANCE_FRACTION;

use std::path::{Path, PathBuf};

use glam::Vec3;

use crate::fur::{FurError, FurLength, FurParams, FurStructure, GrowthDirection, MAX_LAYERS};
use crate::groom::{Groom, GroomError, GroomParams};
use crate::mesh::Mesh;
use crate::param::ParamError;
use crate::sim::SimParams;
use crate::texture::{
    self, ColourMode, ColourParams, FurTextures, ImageRgba8, StrandField, TextureInputs, TextureParams,
};
use crate::wet::WetParams;

/// Why a preset could not be read, checked or used. Every message starts with the file.
#[derive(Debug, thiserror::Error)]
pub enum PresetError {
    /// The file could not be read or written.
    #[error("{file}: cannot read or write the preset: {source}")]
    Io {
        /// The preset file.
        file: PathBuf,
        /// Why.
        source: std::io::Error,
    },
    /// TOML syntax, wrong types and unknown keys: toml's own message, with the line and key.
    #[error("{file}: {message}")]
    Parse {
        /// The preset file.
        file: PathBuf,
        /// toml's message.
        message: String,
    },
    /// A value out of range.
    #[error("{file}: {key}: {problem}")]
    Invalid {
        /// The preset file.
        file: PathBuf,
        /// The key.
        key: String,
        /// What is wrong with it.
        problem: String,
    },
    /// An image the preset names could not be loaded.
    #[error("{file}: {key}: cannot load image {image}: {problem}")]
    Image {
        /// The preset file.
        file: PathBuf,
        /// The key naming the image.
        key: String,
        /// The image file.
        image: PathBuf,
        /// Why it could not be loaded.
        problem: String,
    },
    /// The groom the preset names could not be loaded or does not fit the mesh.
    #[error("{file}: {error}")]
    Groom {
        /// The preset file.
        file: PathBuf,
        /// What is wrong, naming the groom's file and key.
        error: GroomError,
    },
    /// The preset could not be written as TOML.
    #[error("cannot write the preset as TOML: {0}")]
    Write(String),
}

/// The `[direction]` table: how fur grows out of the mesh (becomes [`GrowthDirection`]).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DirectionParams {
    /// Each vertex's growing vector tilts from its normal by up to this, degrees. `0..=80`, default 12.
    pub random_angle_deg: f32,
    /// A world-space combing direction `[x, y, z]`; only its part along the surface counts.
    /// Default `[0, -1, 0]` (fur lies down with gravity).
    pub comb: Vec3,
    /// How far fur leans into the comb: 0 = along the normal, 1 = flat. `0..=1`, default 0.3.
    pub comb_blend: f32,
    /// Seed of the random tilt. Default 1.
    pub seed: u64,
}

impl Default for DirectionParams {
    fn default() -> Self {
        Self { random_angle_deg: 12.0, comb: Vec3::NEG_Y, comb_blend: 0.3, seed: 1 }
    }
}

/// The `[render.lod]` table: level of detail, fewer shells and fin segments where the fur is
/// small on screen (`pelt render`, `pelt view` and `pelt bench`; `--no-lod` turns it off).
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct LodParams {
    /// On by default.
    pub enabled: bool,
    /// Screen pixels each drawn shell should span along a strand, `0.25..=16`: strands shorter
    /// on screen than `layers * pixels_per_shell` draw fewer shells. Default 1.
    pub pixels_per_shell: f32,
    /// Shells by view angle (Yang et al.): where the surface faces the eye, the layers the next
    /// coarser level drops fade out (and are not drawn where gone). On by default (with `enabled`).
    pub view_angle: bool,
    /// `|cos|` between the surface normal and the view where that fading starts, `0..1`,
    /// below `facing_full`. Default 0.4.
    pub facing_start: f32,
    /// `|cos|` where those layers are gone, `0..=1`. Default 0.7.
    pub facing_full: f32,
    /// Where strands are too short on screen to show as strands (from 0.6 down to 0.3 pixels),
    /// the shells and fins fade out and the skin takes the coat's mean colour: a far member of a
    /// herd costs its skin alone. On by default (with `enabled`).
    pub coat_fade: bool,
    /// Where strands are two pixels long or less on screen, the fins fade out (gone at one
    /// pixel), and with them their silhouette pass and draw. On by default (with `enabled`).
    pub fin_fade: bool,
}

impl Default for LodParams {
    fn default() -> Self {
        Self {
            enabled: true,
            pixels_per_shell: 1.0,
            view_angle: true,
            facing_start: 0.4,
            facing_full: 0.7,
            coat_fade: true,
            fin_fade: true,
        }
    }
}

/// The `[render]` table: how Pelt's own commands (`pelt render`, `pelt view`) show the fur.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct RenderParams {
    /// The default camera's turn about +Y, degrees: 0 looks from +Z, 90 from +X. Meshes face
    /// different ways (Spot faces -Z, so its preset says 210). Unset: each command's own view.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_azimuth_deg: Option<f32>,
    /// The default camera's height above the horizon, degrees, `-89..=89`. Unset: each
    /// command's own view.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub camera_elevation_deg: Option<f32>,
    /// Level of detail.
    pub lod: LodParams,
}

/// One fur: layer count, length, direction, textures, colour and simulation.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Preset {
    /// Shells above the base, `1..=MAX_LAYERS`. Default 16.
    pub layers: u32,
    /// Fur length as a fraction of the mesh's bounding-sphere radius, so a preset fits every
    /// mesh. `0 < length <= 2`, default 0.08.
    pub length: f32,
    /// How fur grows out of the mesh.
    pub direction: DirectionParams,
    /// The strand texture.
    pub texture: TextureParams,
    /// How strands are coloured.
    pub colour: ColourParams,
    /// Gravity, wind, touch and stepping.
    pub simulation: SimParams,
    /// How Pelt's commands show it.
    pub render: RenderParams,
    /// Fur that differs over the body; empty (and left out of the TOML) for a uniform coat.
    #[serde(skip_serializing_if = "GroomParams::is_empty")]
    pub groom: GroomParams,
    /// What wetness does to the fur, and its wetness at time 0; left out of the TOML at its
    /// defaults.
    #[serde(skip_serializing_if = "WetParams::is_default")]
    pub wet: WetParams,
    /// How the strands reflect light; left out of the TOML at its defaults.
    #[serde(skip_serializing_if = "ShadingParams::is_default")]
    pub shading: ShadingParams,
    /// The preset file (for messages) and its folder (for relative image paths); not in TOML.
    #[serde(skip)]
    file: PathBuf,
}

impl Default for Preset {
    fn default() -> Self {
        Self {
            layers: 16,
            length: 0.08,
            direction: DirectionParams::default(),
            texture: TextureParams::default(),
            colour: ColourParams::default(),
            simulation: SimParams::default(),
            render: RenderParams::default(),
            groom: GroomParams::default(),
            wet: WetParams::default(),
            shading: ShadingParams::default(),
            file: PathBuf::from("<default preset>"),
        }
    }
}

/// Two presets are equal when they describe the same fur, wherever they were read from.
impl PartialEq for Preset {
    fn eq(&self, other: &Self) -> bool {
        self.layers == other.layers
            && self.length == other.length
            && self.direction == other.direction
            && self.texture == other.texture
            && self.colour == other.colour
            && self.simulation == other.simulation
            && self.render == other.render
            && self.groom == other.groom
            && self.wet == other.wet
            && self.shading == other.shading
    }
}

impl Preset {
    /// Reads and checks a preset file; image paths in it are relative to its folder.
    ///
    /// # Errors
    /// [`PresetError`] naming the file (and the key) for a missing file, bad TOML, unknown keys,
    /// wrong types, values out of range and referenced images that do not exist.
    pub fn load(path: impl AsRef<Path>) -> Result<Self, PresetError> {
        let path = path.as_ref();
        let text =
            std::fs::read_to_string(path).map_err(|source| PresetError::Io { file: path.to_path_buf(), source })?;
        let preset = Self::from_toml_str(&text, path)?;
        for (key, image) in preset.image_paths() {
            let resolved = preset.resolve(image);
            if !resolved.is_file() {
                return Err(PresetError::Image {
                    file: preset.file.clone(),
                    key,
                    image: resolved,
                    problem: "no such file".to_owned(),
                });
            }
        }
        Ok(preset)
    }

    /// Parses and checks preset text. `file` names it in messages, and its folder is where
    /// relative image paths resolve (use a path in the current folder for none).
    ///
    /// # Errors
    /// [`PresetError::Parse`] or [`PresetError::Invalid`], naming `file`.
    pub fn from_toml_str(text: &str, file: impl AsRef<Path>) -> Result<Self, PresetError> {
        let file = file.as_ref().to_path_buf();
        let mut preset: Self =
            toml::from_str(text).map_err(|e| PresetError::Parse { file: file.clone(), message: e.to_string() })?;
        preset.file = file;
        preset.validate()?;
        Ok(preset)
    }

    /// The preset as TOML (every field written out, so it doubles as documentation).
    ///
    /// # Errors
    /// [`PresetError::Write`] if a value cannot be written (e.g. a non-finite number).
    pub fn to_toml_string(&self) -> Result<String, PresetError> {
        toml::to_string(self).map_err(|e| PresetError::Write(e.to_string()))
    }

    /// Writes the preset as TOML to `path` (e.g. from an authoring tool). Image paths are written
    /// as they are, so keep them relative to the new file's folder.
    ///
    /// # Errors
    /// [`PresetError::Write`] or [`PresetError::Io`] naming the file.
    pub fn save(&self, path: impl AsRef<Path>) -> Result<(), PresetError> {
        let path = path.as_ref();
        let text = self.to_toml_string()?;
        std::fs::write(path, text).map_err(|source| PresetError::Io { file: path.to_path_buf(), source })
    }

    /// Writes the preset to `path` with `groom` (painted on `mesh`) as a per-vertex groom file
    /// beside it, `<stem>.groom`, which the `[groom]` table then names alone (the file holds every
    /// map, those first read from images included). A uniform groom (or `None`) clears the table.
    /// The groom file is written first, through a temporary file and a rename.
    ///
    /// # Errors
    /// [`PresetError::Groom`] naming the groom file, else as [`Preset::save`].
    pub fn save_with_groom(
        &mut self,
        path: impl AsRef<Path>,
        groom: Option<&Groom>,
        mesh: &Mesh,
    ) -> Result<(), PresetError> {
        let path = path.as_ref();
        self.groom = GroomParams::default();
        if let Some(groom) = groom.filter(|g| !g.is_uniform()) {
            let stem = path.file_stem().map_or_else(|| "fur".into(), |s| s.to_string_lossy().into_owned());
            let name = PathBuf::from(format!("{stem}.groom"));
            groom
                .save(&path.with_file_name(&name), mesh)
                .map_err(|error| PresetError::Groom { file: path.to_path_buf(), error })?;
            self.groom.file = Some(name);
        }
        self.save(path)
    }

    /// The file this preset was read from (or a placeholder name).
    #[must_use]
    pub fn file(&self) -> &Path {
        &self.file
    }

    /// Checks every value against its documented range.
    ///
    /// # Errors
    /// The first problem as [`PresetError::Invalid`], naming the file and the key.
    pub fn validate(&self) -> Result<(), PresetError> {
        let invalid = |ParamError { key, problem }| PresetError::Invalid { file: self.file.clone(), key, problem };
        let check = |ok: bool, key: &str, problem: String| {
            if ok { Ok(()) } else { Err(invalid(ParamError { key: key.to_owned(), problem })) }
        };
        check(
            (1..=MAX_LAYERS).contains(&self.layers),
            "layers",
            format!("must be between 1 and {MAX_LAYERS}, got {}", self.layers),
        )?;
        check(
            self.length.is_finite() && self.length > 0.0 && self.length <= 2.0,
            "length",
            format!("must be above 0 and at most 2 (a fraction of the mesh's radius), got {}", self.length),
        )?;
        let direction = &self.direction;
        check(
            direction.random_angle_deg.is_finite() && (0.0..=80.0).contains(&direction.random_angle_deg),
            "direction.random_angle_deg",
            format!("must be between 0 and 80, got {}", direction.random_angle_deg),
        )?;
        check(
            direction.comb.is_finite(),
            "direction.comb",
            format!("must be a finite vector, got {}", direction.comb),
        )?;
        check(
            direction.comb_blend.is_finite() && (0.0..=1.0).contains(&direction.comb_blend),
            "direction.comb_blend",
            format!("must be between 0 and 1, got {}", direction.comb_blend),
        )?;
        let render = &self.render;
        if let Some(azimuth) = render.camera_azimuth_deg {
            check(azimuth.is_finite(), "render.camera_azimuth_deg", format!("must be a finite angle, got {azimuth}"))?;
        }
        if let Some(elevation) = render.camera_elevation_deg {
            check(
                elevation.is_finite() && (-89.0..=89.0).contains(&elevation),
                "render.camera_elevation_deg",
                format!("must be between -89 and 89, got {elevation}"),
            )?;
        }
        let pixels = render.lod.pixels_per_shell;
        check(
            pixels.is_finite() && (0.25..=16.0).contains(&pixels),
            "render.lod.pixels_per_shell",
            format!("must be between 0.25 and 16, got {pixels}"),
        )?;
        let (start, full) = (render.lod.facing_start, render.lod.facing_full);
        check(
            start.is_finite() && (0.0..1.0).contains(&start),
            "render.lod.facing_start",
            format!("must be at least 0 and below 1, got {start}"),
        )?;
        check(
            full.is_finite() && start < full && full <= 1.0,
            "render.lod.facing_full",
            format!("must be above facing_start ({start}) and at most 1, got {full}"),
        )?;
        self.texture.validate().map_err(invalid)?;
        self.colour.validate().map_err(invalid)?;
        self.wet.validate().map_err(invalid)?;
        self.shading.validate().map_err(invalid)?;
        self.simulation.validate().map_err(invalid)
    }

    /// The fur structure's parameters on `mesh`: the length scaled by its bounding-sphere radius.
    #[must_use]
    pub fn fur_params(&self, mesh: &Mesh) -> FurParams {
        let radius = mesh.bounding_sphere().1;
        FurParams {
            layers: self.layers,
            length: FurLength::Constant(self.length * radius),
            direction: GrowthDirection {
                random_angle_rad: self.direction.random_angle_deg.to_radians(),
                seed: self.direction.seed,
                comb: self.direction.comb,
                comb_blend: self.direction.comb_blend,
            },
        }
    }

    /// Loads the images the preset refers to and generates its shell and fin textures.
    ///
    /// # Errors
    /// [`PresetError`] for out-of-range values or an image that cannot be read, naming the key.
    pub fn generate_textures(&self) -> Result<FurTextures, PresetError> {
        Ok(texture::generate_from(self.layers, &self.strand_field()?))
    }

    /// Loads the images the preset refers to and grows its seeded strand field: what
    /// [`Preset::generate_textures`] rasterises, and what the explicit strand reference places.
    ///
    /// # Errors
    /// As [`Preset::generate_textures`].
    pub fn strand_field(&self) -> Result<StrandField, PresetError> {
        self.validate()?;
        let load = |key: &str, path: &Option<PathBuf>| -> Result<Option<ImageRgba8>, PresetError> {
            let Some(path) = path else { return Ok(None) };
            let image = self.resolve(path);
            ImageRgba8::load(&image).map(Some).map_err(|problem| PresetError::Image {
                file: self.file.clone(),
                key: key.to_owned(),
                image,
                problem,
            })
        };
        let inputs = TextureInputs {
            pattern: load("texture.pattern", &self.texture.pattern)?,
            gradient: match self.colour.mode {
                ColourMode::Height => load("colour.gradient", &self.colour.gradient)?,
                _ => None,
            },
            surface: match self.colour.mode {
                ColourMode::Surface => load("colour.surface", &self.colour.surface)?,
                _ => None,
            },
        };
        StrandField::new(&self.texture, &self.colour, &inputs).map_err(|e| {
            let (key, problem) = match e {
                texture::TextureError::Param(ParamError { key, problem }) => (key, problem),
                texture::TextureError::Layers { got } => {
                    ("layers".to_owned(), format!("must be between 1 and {MAX_LAYERS}, got {got}"))
                }
                texture::TextureError::MissingImage { key, mode } => {
                    (key.to_owned(), format!("{mode} mode needs this image, but none was given"))
                }
            };
            PresetError::Invalid { file: self.file.clone(), key, problem }
        })
    }

    /// `path` resolved against the preset file's folder.
    #[must_use]
    pub fn resolve(&self, path: &Path) -> PathBuf {
        match self.file.parent() {
            Some(folder) if path.is_relative() => folder.join(path),
            _ => path.to_path_buf(),
        }
    }

    /// The image paths the preset uses, with their keys (unused ones, e.g. a gradient outside
    /// height mode, are left out).
    fn image_paths(&self) -> Vec<(String, &Path)> {
        let mut paths = Vec::new();
        if let Some(pattern) = &self.texture.pattern {
            paths.push(("texture.pattern".to_owned(), pattern.as_path()));
        }
        if let (ColourMode::Height, Some(gradient)) = (self.colour.mode, &self.colour.gradient) {
            paths.push(("colour.gradient".to_owned(), gradient.as_path()));
        }
        if let (ColourMode::Surface, Some(surface)) = (self.colour.mode, &self.colour.surface) {
            paths.push(("colour.surface".to_owned(), surface.as_path()));
        }
        paths.extend(self.groom.files());
        paths
    }

    /// Loads the groom the `[groom]` table names for `mesh` (`None` for a uniform coat); images
    /// and groom files resolve against the preset's folder, `mesh_name` names the mesh in messages.
    ///
    /// # Errors
    /// [`PresetError::Groom`] naming the preset, the groom's file and key and the problem.
    pub fn groom(&self, mesh: &Mesh, mesh_name: &str) -> Result<Option<Groom>, PresetError> {
        Ok(self.groom_with_report(mesh, mesh_name)?.0)
    }

    /// Grows the preset's fur on `mesh`, groomed: [`Preset::fur_params`] and [`Preset::groom`]
    /// into [`FurStructure::new_groomed`].
    ///
    /// # Errors
    /// As [`Preset::groom`], and [`PresetError::Invalid`] for values the structure refuses.
    pub fn grow(&self, mesh: Mesh, mesh_name: &str) -> Result<FurStructure, PresetError> {
        self.validate()?;
        let groom = self.groom(&mesh, mesh_name)?;
        let params = self.fur_params(&mesh);
        FurStructure::new_groomed(mesh, &params, groom).map_err(|e| {
            let key = match e {
                FurError::Layers(_) => "layers",
                FurError::Length(_) | FurError::LengthMapSize { .. } => "length",
                FurError::Groom(_) => "groom",
            };
            PresetError::Invalid { file: self.file.clone(), key: key.to_owned(), problem: e.to_string() }
        })
    }
}
