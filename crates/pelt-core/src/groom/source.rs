//! The preset's `[groom]` table and the sources it names: images through the mesh's UVs, glTF
//! vertex colour sets, and the per-vertex groom file.

use std::path::{Path, PathBuf};

use glam::{Vec2, Vec4};

use super::{Groom, GroomError, GroomMap};
use crate::mesh::Mesh;

/// The largest image side a map may have.
const MAX_IMAGE_SIDE: u32 = 16_384;

/// The preset's `[groom]` table. Each map key names an 8- or 16-bit PNG (relative to the
/// preset file) sampled through the mesh's UVs, or `"COLOR_n"`, the mesh's glTF vertex colour set
/// `n`. `file` names a per-vertex groom file; a map key also given replaces the file's map.
///
/// ```toml
/// [groom]
/// file = "fox.groom"          # per-vertex maps written by the viewer
/// # strands = "groom.usda"    # or USD hair curves, baked per vertex (not with `file`)
/// length = "fox_length.png"   # 0 = bald, 1 = the preset's length (grey, or the red channel)
/// direction = "fox_flow.png"  # red = right, green = up in the image; 0.5 = no flow
/// density = "COLOR_0"         # the red channel of the vertex colours
/// ```
///
/// Length, density and clump read grey or the red channel as stored (no sRGB decoding). A
/// direction map needs colour: red and green map `0..=1` to a flow component `-1..=1`, values
/// within one 8-bit step of 0.5 counting as 0. Tint reads RGB, an 8- or 16-bit PNG as sRGB
/// (decoded to linear), vertex colours as linear (glTF's convention). Alpha is ignored. Where a
/// vertex has several UVs (a seam), it takes the mean of its samples; UVs clamp to the image's edge.
#[derive(Clone, Debug, Default, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GroomParams {
    /// A per-vertex groom file.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub file: Option<PathBuf>,
    /// A strand groom: USD curves (`.usda`) baked per vertex when the preset grows its fur
    /// ([`crate::Preset::groom`]); a map key also given replaces the baked map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub strands: Option<PathBuf>,
    /// Length factor map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub length: Option<PathBuf>,
    /// Density map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub density: Option<PathBuf>,
    /// Tangent-space flow map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub direction: Option<PathBuf>,
    /// Clump map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub clump: Option<PathBuf>,
    /// Tint map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tint: Option<PathBuf>,
    /// The direction map's green points down the image (DirectX-style maps), not up. Default false.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub direction_green_down: bool,
}

/// Where one map comes from.
enum Source<'a> {
    Image(&'a Path),
    ColourSet(u32),
}

impl GroomParams {
    /// Whether the table names nothing (the uniform fur).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.file.is_none() && self.strands.is_none() && GroomMap::ALL.iter().all(|&map| self.map(map).is_none())
    }

    /// The source the table names for `map`.
    #[must_use]
    pub fn map(&self, map: GroomMap) -> Option<&Path> {
        match map {
            GroomMap::Length => self.length.as_deref(),
            GroomMap::Density => self.density.as_deref(),
            GroomMap::Direction => self.direction.as_deref(),
            GroomMap::Clump => self.clump.as_deref(),
            GroomMap::Tint => self.tint.as_deref(),
        }
    }

    /// The files the table names, with their keys (`groom.file`, `groom.length`, ...), vertex
    /// colour sets left out.
    #[must_use]
    pub fn files(&self) -> Vec<(String, &Path)> {
        let mut files: Vec<(String, &Path)> =
            self.file.as_deref().map(|f| ("groom.file".to_owned(), f)).into_iter().collect();
        if let Some(strands) = &self.strands {
            files.push(("groom.strands".to_owned(), strands));
        }
        for map in GroomMap::ALL {
            if let Some(Source::Image(path)) = self.map(map).map(source) {
                files.push((format!("groom.{}", map.key()), path));
            }
        }
        files
    }

    /// Builds the groom the table describes on `mesh` (`None` for an empty table). `resolve`
    /// turns a path in the table into a file to open (the preset resolves against its folder);
    /// `mesh_name` names the mesh in messages.
    ///
    /// # Errors
    /// A [`GroomError`] naming the file (and key) for anything that cannot be read or used.
    pub fn load(
        &self,
        mesh: &Mesh,
        mesh_name: &str,
        resolve: impl Fn(&Path) -> PathBuf,
    ) -> Result<Option<Groom>, GroomError> {
        self.load_with(mesh, mesh_name, resolve, |path| std::fs::read(path))
    }

    /// [`GroomParams::load`] reading each file's bytes with `read` (a host with its own asset
    /// I/O, such as Bevy's asset server, hands over the bytes it read for the resolved path).
    ///
    /// # Errors
    /// As [`GroomParams::load`]; `read`'s error becomes [`GroomError::Io`] (the groom file) or
    /// [`GroomError::Image`] (a map) naming the file.
    pub fn load_with(
        &self,
        mesh: &Mesh,
        mesh_name: &str,
        resolve: impl Fn(&Path) -> PathBuf,
        read: impl Fn(&Path) -> std::io::Result<Vec<u8>>,
    ) -> Result<Option<Groom>, GroomError> {
        if self.is_empty() {
            return Ok(None);
        }
        if let Some(strands) = &self.strands {
            return Err(GroomError::Strands {
                file: resolve(strands),
                problem: "groom.strands: a strand groom is baked with the preset's fur (Preset::groom), \
                          or into a .groom file by `pelt groom bake`, which groom.file then names"
                    .to_owned(),
            });
        }
        let mut groom = match &self.file {
            Some(file) => {
                let file = resolve(file);
                let bytes = read(&file).map_err(|error| GroomError::Io { file: file.clone(), error })?;
                Groom::from_file_bytes(&bytes, &file, mesh, mesh_name)?
            }
            None => Groom::default(),
        };
        for map in GroomMap::ALL {
            let Some(named) = self.map(map) else { continue };
            let key = map.key().to_owned();
            let (colours, origin) = match source(named) {
                Source::Image(path) => {
                    let image = resolve(path);
                    let error = |problem: String| GroomError::Image { key: key.clone(), image: image.clone(), problem };
                    if mesh.corner_uvs.is_none() {
                        return Err(GroomError::NoUvs { key, image, mesh: mesh_name.to_owned() });
                    }
                    let bytes = read(&image).map_err(|e| error(e.to_string()))?;
                    let decoded = MapImage::decode(&bytes).map_err(error)?;
                    if map == GroomMap::Direction && !decoded.has_colour {
                        return Err(error(
                            "a direction map needs red and green channels, but this image is grey".to_owned(),
                        ));
                    }
                    let mut colours = decoded.at_vertices(mesh);
                    if map == GroomMap::Tint {
                        colours.iter_mut().for_each(|c| *c = srgb_to_linear(*c));
                    }
                    (colours, image.display().to_string())
                }
                Source::ColourSet(set) => {
                    let Some(colours) = mesh.colour_set(set) else {
                        let sets: Vec<String> = mesh.colour_sets.iter().map(|c| format!("COLOR_{}", c.set)).collect();
                        let available = if sets.is_empty() {
                            "it has none".to_owned()
                        } else {
                            format!("it has {}", sets.join(", "))
                        };
                        return Err(GroomError::NoColourSet { key, set, mesh: mesh_name.to_owned(), available });
                    };
                    (colours.to_vec(), format!("{mesh_name} COLOR_{set}"))
                }
            };
            let values = map_values(map, &colours, self.direction_green_down);
            let mut single = Groom::default();
            single.set_values(map, values.clone());
            single.validate(mesh.vertex_count(), &origin)?;
            groom.set_values(map, values);
        }
        Ok(Some(groom))
    }
}

/// `"COLOR_n"` is a vertex colour set, anything else a file.
fn source(named: &Path) -> Source<'_> {
    named
        .to_str()
        .and_then(|s| s.strip_prefix("COLOR_"))
        .filter(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit()))
        .and_then(|n| n.parse().ok())
        .map_or(Source::Image(named), Source::ColourSet)
}

/// One map's flat values from per-vertex RGBA.
fn map_values(map: GroomMap, colours: &[Vec4], green_down: bool) -> Vec<f32> {
    match map {
        GroomMap::Direction => colours
            .iter()
            .flat_map(|c| {
                let flow = Vec2::new(flow_component(c.x), flow_component(c.y));
                (if green_down { Vec2::new(flow.x, -flow.y) } else { flow }).to_array()
            })
            .collect(),
        GroomMap::Tint => colours.iter().flat_map(|c| c.truncate().to_array()).collect(),
        _ => colours.iter().map(|c| c.x).collect(),
    }
}

/// `0..=1` to `-1..=1`, with a dead zone of one 8-bit step either side of 0.5 (which 8 bits
/// cannot hold: 127 and 128 both mean no flow).
fn flow_component(channel: f32) -> f32 {
    let component = (channel * 2.0 - 1.0).clamp(-1.0, 1.0);
    if component.abs() <= 2.0 / 255.0 { 0.0 } else { component }
}

fn srgb_to_linear(c: Vec4) -> Vec4 {
    let decode = |x: f32| if x <= 0.04045 { x / 12.92 } else { ((x + 0.055) / 1.055).powf(2.4) };
    Vec4::new(decode(c.x), decode(c.y), decode(c.z), c.w)
}

/// A decoded map image: `0..=1` RGBA per texel, rows top to bottom.
struct MapImage {
    width: u32,
    height: u32,
    texels: Vec<Vec4>,
    /// Whether it has colour channels (not grey).
    has_colour: bool,
}

impl MapImage {
    /// Decodes an 8- or 16-bit PNG.
    fn decode(bytes: &[u8]) -> Result<Self, String> {
        let reader =
            image::ImageReader::new(std::io::Cursor::new(bytes)).with_guessed_format().map_err(|e| e.to_string())?;
        if reader.format() != Some(image::ImageFormat::Png) {
            return Err("not a PNG (groom maps are 8- or 16-bit PNG)".to_owned());
        }
        let decoded = reader.decode().map_err(|e| e.to_string())?;
        use image::ColorType as C;
        let has_colour = match decoded.color() {
            C::L8 | C::La8 | C::L16 | C::La16 => false,
            C::Rgb8 | C::Rgba8 | C::Rgb16 | C::Rgba16 => true,
            other => return Err(format!("pixel format {other:?} (groom maps are 8- or 16-bit PNG)")),
        };
        let (width, height) = (decoded.width(), decoded.height());
        if width == 0 || height == 0 {
            return Err("the image is empty".to_owned());
        }
        if width > MAX_IMAGE_SIDE || height > MAX_IMAGE_SIDE {
            return Err(format!("{width} x {height} is larger than {MAX_IMAGE_SIDE} on a side"));
        }
        let texels = decoded.to_rgba32f().into_raw().chunks_exact(4).map(Vec4::from_slice).collect();
        Ok(Self { width, height, texels, has_colour })
    }

    /// Bilinear sample at `uv` (`v = 0` is the top row), clamped to the edge: a groom map is
    /// painted for one mesh, not tiled, so its left edge must not bleed into its right.
    fn sample(&self, uv: Vec2) -> Vec4 {
        let x = uv.x.clamp(0.0, 1.0) * self.width as f32 - 0.5;
        let y = uv.y.clamp(0.0, 1.0) * self.height as f32 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        let clamp = |c: f32, n: u32| (c.max(0.0) as usize).min(n as usize - 1);
        let (xa, xb) = (clamp(x0, self.width), clamp(x0 + 1.0, self.width));
        let (ya, yb) = (clamp(y0, self.height), clamp(y0 + 1.0, self.height));
        let texel = |x: usize, y: usize| self.texels[y * self.width as usize + x];
        let top = texel(xa, ya).lerp(texel(xb, ya), fx);
        let bottom = texel(xa, yb).lerp(texel(xb, yb), fx);
        top.lerp(bottom, fy)
    }

    /// Each vertex's mean sample over its distinct UVs (its wedges).
    fn at_vertices(&self, mesh: &Mesh) -> Vec<Vec4> {
        let mut sums = vec![(Vec4::ZERO, 0u32); mesh.vertex_count()];
        if let Some(wedges) = mesh.wedges() {
            for (&vertex, &uv) in wedges.vertices.iter().zip(&wedges.uvs) {
                let (sum, count) = &mut sums[vertex as usize];
                *sum += self.sample(uv);
                *count += 1;
            }
        }
        sums.into_iter().map(|(sum, count)| if count == 0 { Vec4::ONE } else { sum / count as f32 }).collect()
    }
}
