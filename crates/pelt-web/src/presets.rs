//! The presets the page ships, embedded (a static page has no files to read), and textures made
//! for the web: a smaller tile so start-up stays short on one thread.

use std::path::Path;

use pelt_core::texture::{self, ColourMode, FurTextures, ImageRgba8, TextureInputs};
use pelt_core::{Preset, PresetError};

/// Shell tiles on the web are at most this many texels across (presets ask for 512): texture
/// generation runs on the page's one thread, and a 256 tile takes a quarter of the time.
pub const WEB_TILE_PX: u32 = 256;

/// `(name, TOML)` of every preset on the page. `spot` and `fox` are left out: they are made for
/// Spot's and the Fox's meshes and textures, and the page has the bunny and the try-on scene.
pub const SHIPPED: [(&str, &str); 6] = [
    ("default", ""),
    ("mink", include_str!("../../../assets/presets/mink.toml")),
    ("shaggy", include_str!("../../../assets/presets/shaggy.toml")),
    ("lamb", include_str!("../../../assets/presets/lamb.toml")),
    ("dyed", include_str!("../../../assets/presets/dyed.toml")),
    ("spotted", include_str!("../../../assets/presets/spotted.toml")),
];

/// Images a preset may name on the page, by file name (the only files it can reach).
const IMAGES: [(&str, &[u8]); 1] = [("leopard.png", include_bytes!("../../../assets/patterns/leopard.png"))];

/// A shipped preset by name.
///
/// # Errors
/// [`PresetError`] for an unknown name, or (never for the shipped files, which a test parses) a
/// parse error.
pub fn shipped(name: &str) -> Result<Preset, PresetError> {
    let Some((_, text)) = SHIPPED.iter().find(|(n, _)| *n == name) else {
        return Err(PresetError::Invalid {
            file: name.into(),
            key: "preset".to_owned(),
            problem: format!("no shipped preset is called {name:?}"),
        });
    };
    Preset::from_toml_str(text, format!("assets/presets/{name}.toml"))
}

/// Reads a preset file the user picked: `file_name` names it in messages.
///
/// # Errors
/// [`PresetError`] naming the file and the key, as for a preset read from disk.
pub fn parse(text: &str, file_name: &str) -> Result<Preset, PresetError> {
    Preset::from_toml_str(text, file_name)
}

/// Textures as made on the web, and how many times smaller the tile is than the preset's (the
/// renderer repeats a smaller tile more often, so strands keep their size on the mesh).
#[derive(Debug)]
pub struct WebTextures {
    /// The shell and fin textures.
    pub textures: FurTextures,
    /// `preset tile / web tile` (1 when the preset asks for `WEB_TILE_PX` or less).
    pub tile_scale: f32,
}

/// Generates `preset`'s textures with the tile capped at [`WEB_TILE_PX`]; images it names are
/// taken from the page's own (by file name), and any other image is a clear error.
///
/// # Errors
/// [`PresetError`] naming the preset file, the key and the problem.
pub fn web_textures(preset: &Preset) -> Result<WebTextures, PresetError> {
    preset.validate()?;
    let mut params = preset.texture.clone();
    let tile_scale = (params.size as f32 / WEB_TILE_PX as f32).max(1.0);
    params.size = params.size.min(WEB_TILE_PX);
    let image = |key: &str, path: Option<&Path>| -> Result<Option<ImageRgba8>, PresetError> {
        let Some(path) = path else { return Ok(None) };
        let problem = |problem: String| PresetError::Image {
            file: preset.file().to_path_buf(),
            key: key.to_owned(),
            image: path.to_path_buf(),
            problem,
        };
        let name = path.file_name().and_then(|n| n.to_str()).unwrap_or_default();
        let Some((_, bytes)) = IMAGES.iter().find(|(n, _)| *n == name) else {
            let shipped: Vec<&str> = IMAGES.iter().map(|(n, _)| *n).collect();
            return Err(problem(format!(
                "a web page cannot read image files; only the images it ships can be named ({})",
                shipped.join(", ")
            )));
        };
        let decoded = image::load_from_memory(bytes).map_err(|e| problem(e.to_string()))?.to_rgba8();
        let (width, height) = decoded.dimensions();
        Ok(Some(ImageRgba8 { width, height, pixels: decoded.into_raw() }))
    };
    let colour = &preset.colour;
    let inputs = TextureInputs {
        pattern: image("texture.pattern", params.pattern.as_deref())?,
        gradient: match colour.mode {
            ColourMode::Height => image("colour.gradient", colour.gradient.as_deref())?,
            _ => None,
        },
        surface: match colour.mode {
            ColourMode::Surface => image("colour.surface", colour.surface.as_deref())?,
            _ => None,
        },
    };
    let textures = texture::generate(preset.layers, &params, colour, &inputs).map_err(|e| PresetError::Invalid {
        file: preset.file().to_path_buf(),
        key: "texture".to_owned(),
        problem: e.to_string(),
    })?;
    Ok(WebTextures { textures, tile_scale })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_shipped_preset_parses_and_makes_web_textures() {
        for (name, _) in SHIPPED {
            let preset = shipped(name).unwrap_or_else(|e| panic!("{name}: {e}"));
            let mut small = preset.clone();
            // Fewer layers keep the test quick; the tile cap is what is checked.
            small.layers = small.layers.min(4);
            let made = web_textures(&small).unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(made.textures.size <= WEB_TILE_PX, "{name}");
            assert_eq!(made.tile_scale * made.textures.size as f32, preset.texture.size as f32, "{name}");
        }
        assert!(shipped("nope").unwrap_err().to_string().contains("nope"));
    }

    #[test]
    fn a_picked_preset_with_bad_values_or_an_unknown_image_is_a_message_naming_file_and_key() {
        let error = parse("length = 7.0", "mine.toml").unwrap_err().to_string();
        assert!(error.contains("mine.toml") && error.contains("length"), "{error}");
        let error = parse("[texture]\nsize = 12\nnot_a_key = 1", "mine.toml").unwrap_err().to_string();
        assert!(error.contains("mine.toml"), "{error}");
        let preset = parse("layers = 2\n[texture]\npattern = \"cat.png\"", "mine.toml").unwrap();
        let error = web_textures(&preset).unwrap_err().to_string();
        assert!(
            error.contains("mine.toml") && error.contains("texture.pattern") && error.contains("cat.png"),
            "{error}"
        );
        // A picked preset may name the page's own pattern.
        let preset = parse("layers = 2\n[texture]\nsize = 64\npattern = \"x/leopard.png\"", "mine.toml").unwrap();
        assert_eq!(web_textures(&preset).unwrap().tile_scale, 1.0);
    }
}
