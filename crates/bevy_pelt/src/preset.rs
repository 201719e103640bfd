//! Fur presets as Bevy assets: a `.toml` preset file (pelt-core's format) loads into a
//! [`FurPreset`] with its shell and fin textures already generated, off the main thread.
//!
//! Images a preset names (`texture.pattern`, `colour.gradient`, `colour.surface`) and the files
//! of its `[groom]` table (a `.groom` file, PNG maps) are read through the asset server relative
//! to the preset's folder, so they are hot-reload dependencies of the preset and work from any
//! asset source. The groom itself is made when the fur is grown, as it needs the mesh.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use bevy::asset::io::Reader;
use bevy::asset::{Asset, AssetLoader, LoadContext};
use bevy::reflect::TypePath;
use pelt_core::groom::Groom;
use pelt_core::texture::{self, ColourMode, FurTextures, ImageRgba8, TextureError, TextureInputs};
use pelt_core::{Preset, PresetError};

/// One fur preset: the parsed [`Preset`], the textures it generates and the bytes of its groom's
/// files.
///
/// Load it with `asset_server.load("presets/mink.toml")`; a bad file becomes the asset server's
/// load error (the message names the file and, where it can, the key), never a panic.
#[derive(Asset, TypePath, Debug, Clone)]
pub struct FurPreset {
    /// The preset as read (layers, length, direction, texture, colour, simulation, groom, wet).
    pub preset: Preset,
    /// Its shell and fin textures.
    pub textures: Arc<FurTextures>,
    /// The `[groom]` table's files: the path as the table names it, the asset path it resolved
    /// to, and the bytes read.
    groom_files: Arc<Vec<GroomFile>>,
}

#[derive(Debug)]
struct GroomFile {
    named: PathBuf,
    asset: PathBuf,
    bytes: Vec<u8>,
}

impl FurPreset {
    /// The groom the preset's `[groom]` table describes on `mesh` (`None` for a uniform coat),
    /// from the files read with the preset; `mesh_name` names the mesh in messages.
    ///
    /// # Errors
    /// [`PresetError::Groom`] naming the preset, the groom's file and the problem (a groom file
    /// made for another mesh, a bad map).
    pub fn groom(&self, mesh: &pelt_core::Mesh, mesh_name: &str) -> Result<Option<Groom>, PresetError> {
        let file = |named: &Path| self.groom_files.iter().find(|f| f.named == named);
        let resolve = |named: &Path| file(named).map_or_else(|| named.to_path_buf(), |f| f.asset.clone());
        let read = |asset: &Path| {
            self.groom_files
                .iter()
                .find(|f| f.asset == asset)
                .map(|f| f.bytes.clone())
                .ok_or_else(|| std::io::Error::new(std::io::ErrorKind::NotFound, "not read with the preset"))
        };
        self.preset
            .groom
            .load_with(mesh, mesh_name, resolve, read)
            .map_err(|error| PresetError::Groom { file: self.preset.file().to_path_buf(), error })
    }
}

/// Loads `.toml` fur presets into [`FurPreset`]s (registered by [`crate::PeltPlugin`]).
#[derive(Debug, Default, TypePath)]
pub struct FurPresetLoader;

impl AssetLoader for FurPresetLoader {
    type Asset = FurPreset;
    type Settings = ();
    type Error = PresetError;

    async fn load(
        &self,
        reader: &mut dyn Reader,
        _settings: &(),
        load_context: &mut LoadContext<'_>,
    ) -> Result<FurPreset, PresetError> {
        let file = load_context.path().path().to_path_buf();
        let mut bytes = Vec::new();
        reader.read_to_end(&mut bytes).await.map_err(|source| PresetError::Io { file: file.clone(), source })?;
        let text = String::from_utf8(bytes)
            .map_err(|e| PresetError::Parse { file: file.clone(), message: format!("not UTF-8 text: {e}") })?;
        let preset = Preset::from_toml_str(&text, &file)?;
        let inputs = TextureInputs {
            pattern: load_image(load_context, &preset, "texture.pattern", preset.texture.pattern.as_deref()).await?,
            gradient: match preset.colour.mode {
                ColourMode::Height => {
                    load_image(load_context, &preset, "colour.gradient", preset.colour.gradient.as_deref()).await?
                }
                _ => None,
            },
            surface: match preset.colour.mode {
                ColourMode::Surface => {
                    load_image(load_context, &preset, "colour.surface", preset.colour.surface.as_deref()).await?
                }
                _ => None,
            },
        };
        let textures = texture::generate(preset.layers, &preset.texture, &preset.colour, &inputs)
            .map_err(|e| texture_error(&file, e))?;
        let mut groom_files = Vec::new();
        for (key, named) in preset.groom.files() {
            let (asset, bytes) = read_relative(load_context, &preset, &key, named).await?;
            groom_files.push(GroomFile { named: named.to_path_buf(), asset, bytes });
        }
        Ok(FurPreset { preset, textures: Arc::new(textures), groom_files: Arc::new(groom_files) })
    }

    fn extensions(&self) -> &[&str] {
        &["toml"]
    }
}

/// Reads and decodes one image the preset names, through the asset server (relative to the
/// preset's folder).
async fn load_image(
    load_context: &mut LoadContext<'_>,
    preset: &Preset,
    key: &str,
    path: Option<&Path>,
) -> Result<Option<ImageRgba8>, PresetError> {
    let Some(path) = path else { return Ok(None) };
    let (image, bytes) = read_relative(load_context, preset, key, path).await?;
    let image_error = |image: PathBuf, problem: String| PresetError::Image {
        file: preset.file().to_path_buf(),
        key: key.to_owned(),
        image,
        problem,
    };
    let decoded = image::load_from_memory(&bytes).map_err(|e| image_error(image.clone(), e.to_string()))?.to_rgba8();
    let (width, height) = decoded.dimensions();
    if width == 0 || height == 0 {
        return Err(image_error(image, "the image is empty".to_owned()));
    }
    Ok(Some(ImageRgba8 { width, height, pixels: decoded.into_raw() }))
}

/// Reads a file the preset names at `key` (relative to the preset's folder) through the asset
/// server, which makes it a dependency of the preset: its asset path and bytes.
async fn read_relative(
    load_context: &mut LoadContext<'_>,
    preset: &Preset,
    key: &str,
    path: &Path,
) -> Result<(PathBuf, Vec<u8>), PresetError> {
    let error = |file: PathBuf, problem: String| PresetError::Image {
        file: preset.file().to_path_buf(),
        key: key.to_owned(),
        image: file,
        problem,
    };
    let relative = path.to_string_lossy().replace('\\', "/");
    let asset_path =
        load_context.path().resolve_embed_str(&relative).map_err(|e| error(path.to_path_buf(), e.to_string()))?;
    let file = asset_path.path().to_path_buf();
    let bytes = load_context.read_asset_bytes(asset_path).await.map_err(|e| error(file.clone(), e.to_string()))?;
    Ok((file, bytes))
}

/// The texture generator's error as a preset error naming the file and key.
fn texture_error(file: &Path, error: TextureError) -> PresetError {
    let (key, problem) = match error {
        TextureError::Param(param) => (param.key, param.problem),
        TextureError::Layers { got } => ("layers".to_owned(), format!("must be at least 1, got {got}")),
        TextureError::MissingImage { key, mode } => {
            (key.to_owned(), format!("{mode} mode needs this image, but none was given"))
        }
    };
    PresetError::Invalid { file: file.to_path_buf(), key, problem }
}
