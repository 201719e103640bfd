//! Strand colours: one colour, the mesh's surface texture, or a colour height map.

use std::path::PathBuf;

use glam::Vec3;

use super::image::ImageRgba8;
use crate::param::ParamError;

/// An sRGB colour, written `"#rrggbb"` in presets.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct Rgb(pub [u8; 3]);

impl Rgb {
    /// Parses `"#rrggbb"` (the `#` is required, hex digits in either case).
    ///
    /// # Errors
    /// A message quoting the text and the expected form.
    pub fn parse(text: &str) -> Result<Self, String> {
        let bad = || format!("expected a colour written \"#rrggbb\", got {text:?}");
        let hex = text.strip_prefix('#').ok_or_else(bad)?;
        if hex.len() != 6 || !hex.bytes().all(|b| b.is_ascii_hexdigit()) {
            return Err(bad());
        }
        let channel = |i: usize| u8::from_str_radix(&hex[i..i + 2], 16).map_err(|_| bad());
        Ok(Self([channel(0)?, channel(2)?, channel(4)?]))
    }

    /// The colour as `0..=1` floats.
    #[must_use]
    pub fn to_vec3(self) -> Vec3 {
        Vec3::new(f32::from(self.0[0]), f32::from(self.0[1]), f32::from(self.0[2])) / 255.0
    }
}

impl std::fmt::Display for Rgb {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let [r, g, b] = self.0;
        write!(f, "#{r:02x}{g:02x}{b:02x}")
    }
}

impl serde::Serialize for Rgb {
    fn serialize<S: serde::Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        serializer.collect_str(self)
    }
}

impl<'de> serde::Deserialize<'de> for Rgb {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        let text = String::deserialize(deserializer)?;
        Self::parse(&text).map_err(serde::de::Error::custom)
    }
}

/// Where strand colour comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum ColourMode {
    /// [`ColourParams::colour`] for every strand.
    #[default]
    Single,
    /// The base mesh's surface texture through its UVs: the textures carry a grey brightness per
    /// strand and [`super::FurTextures::surface`] holds the image the renderer multiplies it by.
    Surface,
    /// A colour height map from root to tip: each shell slice gets the colour for its height.
    Height,
}

/// The `[colour]` table of a preset.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ColourParams {
    /// `"single"` (default), `"surface"` or `"height"`.
    pub mode: ColourMode,
    /// Single mode: the strand colour. Default `"#8a5a36"`, a warm brown.
    pub colour: Rgb,
    /// Height mode: colours from root to tip, spread evenly and interpolated into
    /// [`Self::height_levels`] steps. Default empty (then [`Self::gradient`] is needed).
    pub height_colours: Vec<Rgb>,
    /// Height mode: a gradient image instead of `height_colours`, left column = root, right
    /// column = tip (each column averaged over its rows). Relative to the preset file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub gradient: Option<PathBuf>,
    /// Height mode: the number of colour steps from root to tip (the paper uses 32); 2..=256.
    pub height_levels: u32,
    /// Surface mode: the mesh's colour texture (e.g. Spot's `spot_texture.png`), relative to the
    /// preset file. Required in surface mode.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub surface: Option<PathBuf>,
    /// Per-strand brightness spread so fur is not flat: each strand's brightness is
    /// `1 - brightness_variation * u` with `u` uniform in `0..1`. 0..=1, default 0.4.
    pub brightness_variation: f32,
}

impl Default for ColourParams {
    fn default() -> Self {
        Self {
            mode: ColourMode::Single,
            colour: Rgb([0x8a, 0x5a, 0x36]),
            height_colours: Vec::new(),
            gradient: None,
            height_levels: 32,
            surface: None,
            brightness_variation: 0.4,
        }
    }
}

impl ColourParams {
    /// Checks every field against its documented range (keys as in a preset: `colour.*`).
    ///
    /// # Errors
    /// The first [`ParamError`] found.
    pub fn validate(&self) -> Result<(), ParamError> {
        let error = |key: &str, problem: String| Err(ParamError { key: format!("colour.{key}"), problem });
        if !(self.brightness_variation.is_finite() && (0.0..=1.0).contains(&self.brightness_variation)) {
            return error(
                "brightness_variation",
                format!("must be between 0 and 1, got {}", self.brightness_variation),
            );
        }
        if !(2..=256).contains(&self.height_levels) {
            return error("height_levels", format!("must be between 2 and 256, got {}", self.height_levels));
        }
        match self.mode {
            ColourMode::Height if self.height_colours.is_empty() && self.gradient.is_none() => error(
                "height_colours",
                "height mode needs at least one colour in `height_colours` or a `gradient` image".to_owned(),
            ),
            ColourMode::Height if !self.height_colours.is_empty() && self.gradient.is_some() => {
                error("gradient", "give either `height_colours` or `gradient`, not both".to_owned())
            }
            ColourMode::Surface if self.surface.is_none() => {
                error("surface", "surface mode needs the mesh's colour texture in `surface`".to_owned())
            }
            _ => Ok(()),
        }
    }
}

/// The colour height map: `levels` colours from root (index 0) to tip.
///
/// From `colours` (evenly spread stops, linearly interpolated) or, when `colours` is empty, from
/// a gradient image (left = root, columns averaged over their rows). With neither it is white.
#[must_use]
pub fn height_table(colours: &[Rgb], gradient: Option<&ImageRgba8>, levels: u32) -> Vec<Vec3> {
    let levels = levels.max(2);
    (0..levels)
        .map(|level| {
            let t = level as f32 / (levels - 1) as f32;
            if let Some(stop) = interpolate_stops(colours, t) {
                stop
            } else if let Some(image) = gradient {
                let x = ((t * image.width as f32) as u32).min(image.width - 1);
                (0..image.height).map(|y| image.texel(x, y).truncate()).sum::<Vec3>() / image.height as f32
            } else {
                Vec3::ONE
            }
        })
        .collect()
}

fn interpolate_stops(colours: &[Rgb], t: f32) -> Option<Vec3> {
    match colours {
        [] => None,
        [only] => Some(only.to_vec3()),
        _ => {
            let position = t * (colours.len() - 1) as f32;
            let below = (position.floor() as usize).min(colours.len() - 2);
            Some(colours[below].to_vec3().lerp(colours[below + 1].to_vec3(), position - below as f32))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_parse_and_print() {
        assert_eq!(Rgb::parse("#8A5a36"), Ok(Rgb([0x8a, 0x5a, 0x36])));
        assert_eq!(Rgb([1, 2, 255]).to_string(), "#0102ff");
        for bad in ["8a5a36", "#8a5a3", "#8a5a3g", "#8a5a366", ""] {
            assert!(Rgb::parse(bad).unwrap_err().contains("#rrggbb"), "{bad}");
        }
    }

    #[test]
    fn height_table_runs_root_to_tip() {
        let table = height_table(&[Rgb([0, 0, 0]), Rgb([255, 255, 255])], None, 32);
        assert_eq!(table.len(), 32);
        assert_eq!(table[0], Vec3::ZERO);
        assert_eq!(table[31], Vec3::ONE);
        assert!(table.windows(2).all(|w| w[1].x > w[0].x));
        let mut image = ImageRgba8::filled(2, 3, [255, 0, 0, 255]);
        image.pixels[4..8].copy_from_slice(&[0, 0, 255, 255]);
        let from_image = height_table(&[], Some(&image), 4);
        assert_eq!(from_image[0], Vec3::X);
        assert!((from_image[3] - Vec3::new(2.0 / 3.0, 0.0, 1.0 / 3.0)).length() < 1e-6);
    }
}
