//! The presets the page ships, embedded (a static page has no files to read) with the images
//! and grooms they name, and textures made for the web: a smaller tile so start-up stays short
//! on one thread.

use std::path::Path;

use pelt_core::groom::{Groom, GroomError, GroomMap, GroomParams};
use pelt_core::texture::{self, ColourMode, FurTextures, ImageRgba8, TextureInputs};
use pelt_core::{Mesh, Preset, PresetError};

/// Shell tiles on the web are at most this many texels across (presets ask for 512): texture
/// generation runs on the page's one thread, and a 256 tile takes a quarter of the time.
pub const WEB_TILE_PX: u32 = 256;

/// `(name, TOML)` of every preset on the page. `spot` is left out (made for Spot's mesh, which
/// the page does not ship); `fox` and `fox_groomed` are made for the Fox ([`made_for`]).
pub const SHIPPED: [(&str, &str); 9] = [
    ("default", ""),
    ("mink", include_str!("../../../assets/presets/mink.toml")),
    ("shaggy", include_str!("../../../assets/presets/shaggy.toml")),
    ("lamb", include_str!("../../../assets/presets/lamb.toml")),
    ("dyed", include_str!("../../../assets/presets/dyed.toml")),
    ("spotted", include_str!("../../../assets/presets/spotted.toml")),
    ("wet", include_str!("../../../assets/presets/wet.toml")),
    ("fox", include_str!("../../../assets/presets/fox.toml")),
    ("fox_groomed", include_str!("../../../assets/presets/fox_groomed.toml")),
];

/// The scene (`SceneChoice` name) a shipped preset is made for, if one: its colour comes from
/// that mesh's texture through its UVs, or its groom is tied to that mesh.
#[must_use]
pub fn made_for(preset: &str) -> Option<&'static str> {
    matches!(preset, "fox" | "fox_groomed").then_some("fox")
}

/// Images a preset may name on the page, by file name (the only files it can reach).
const IMAGES: [(&str, &[u8]); 2] = [
    ("leopard.png", include_bytes!("../../../assets/patterns/leopard.png")),
    ("fox_texture.png", include_bytes!("../../../assets/meshes/fox_texture.png")),
];

/// Groom files a preset may name on the page, by file name.
const GROOMS: [(&str, &[u8]); 1] = [("fox_groomed.groom", include_bytes!("../../../assets/presets/fox_groomed.groom"))];

/// The groom `preset`'s `[groom]` names on `mesh` (`None` for a uniform coat): its `file` from
/// the grooms the page ships (by file name), its maps from the mesh's vertex colour sets. An
/// image map or another groom file is a clear error (a page reads no files).
///
/// # Errors
/// [`PresetError::Groom`] naming the preset, the groom file or key and the problem.
pub fn web_groom(preset: &Preset, mesh: &Mesh, mesh_name: &str) -> Result<Option<Groom>, PresetError> {
    let params = &preset.groom;
    if params.is_empty() {
        return Ok(None);
    }
    let fail = |error: GroomError| PresetError::Groom { file: preset.file().to_path_buf(), error };
    let shipped = |list: &[(&str, &[u8])]| list.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ");
    let mut groom = match &params.file {
        None => Groom::default(),
        Some(file) => {
            let name = file.file_name().and_then(|n| n.to_str()).unwrap_or_default();
            let Some((_, bytes)) = GROOMS.iter().find(|(n, _)| *n == name) else {
                let problem = format!("a web page cannot read groom files; it ships {}", shipped(&GROOMS));
                return Err(fail(GroomError::Format { file: file.clone(), problem }));
            };
            Groom::from_file_bytes(bytes, file, mesh, mesh_name).map_err(fail)?
        }
    };
    // The maps beside the file: vertex colour sets load as anywhere; images cannot be read here.
    let maps = GroomParams { file: None, ..params.clone() };
    if let Some((key, image)) = maps.files().into_iter().next() {
        let problem =
            format!("a web page cannot read image files; only the images it ships can be named ({})", shipped(&IMAGES));
        let key = key.trim_start_matches("groom.").to_owned();
        return Err(fail(GroomError::Image { key, image: image.to_path_buf(), problem }));
    }
    if let Some(over) = maps.load(mesh, mesh_name, Path::to_path_buf).map_err(fail)? {
        for map in GroomMap::ALL {
            match map {
                GroomMap::Length if over.length.is_some() => groom.length.clone_from(&over.length),
                GroomMap::Density if over.density.is_some() => groom.density.clone_from(&over.density),
                GroomMap::Direction if over.direction.is_some() => groom.direction.clone_from(&over.direction),
                GroomMap::Clump if over.clump.is_some() => groom.clump.clone_from(&over.clump),
                GroomMap::Tint if over.tint.is_some() => groom.tint.clone_from(&over.tint),
                _ => {}
            }
        }
    }
    Ok(Some(groom))
}

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
    fn the_groomed_fox_reads_its_shipped_groom_and_other_groom_files_are_messages() {
        let fox = crate::model::Model::new(crate::model::SceneChoice::Fox, shipped("fox_groomed").unwrap(), 1.0)
            .unwrap_or_else(|e| panic!("{e}"));
        let groom = fox.structure.groom.as_ref().expect("the groomed Fox has a groom");
        let length = groom.length.as_ref().expect("a length map");
        assert!(length.iter().any(|l| *l == 0.0), "no bald vertex");
        assert!(length.iter().any(|l| *l > 1.0), "nothing longer than the preset's length");
        let bald = length.iter().filter(|l| **l == 0.0).count();
        let zero_lengths = fox.structure.lengths.iter().filter(|l| **l == 0.0).count();
        assert_eq!(zero_lengths, bald, "the structure's bald strands are the groom's");

        let mesh = fox.structure.mesh.clone();
        let preset = parse("[groom]\nfile = \"cat.groom\"", "mine.toml").unwrap();
        let error = web_groom(&preset, &mesh, "fox").unwrap_err().to_string();
        assert!(error.contains("mine.toml") && error.contains("cat.groom"), "{error}");
        let preset = parse("[groom]\nlength = \"long.png\"", "mine.toml").unwrap();
        let error = web_groom(&preset, &mesh, "fox").unwrap_err().to_string();
        assert!(error.contains("mine.toml") && error.contains("groom.length") && error.contains("long.png"), "{error}");
        // The Fox's groom on the bunny: the groom file says it was made for another mesh.
        let error = crate::model::Model::new(crate::model::SceneChoice::Bunny, shipped("fox_groomed").unwrap(), 1.0)
            .unwrap_err()
            .to_string();
        assert!(error.contains("fox_groomed.groom") && error.contains("vertices"), "{error}");
        assert_eq!(made_for("fox_groomed"), Some("fox"));
        assert_eq!(made_for("mink"), None);
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
