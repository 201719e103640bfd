//! Seeded shell and fin textures (docs/paper-notes.md section 3).
//!
//! A strand field over a seamless `size x size` tile: every texel draws a seed; where it passes
//! the density threshold a strand roots, with its lean, curl, clump, thickness, length and
//! brightness drawn from the same seed. Slice `k` (drawn on shell layer `k + 1` of `L`) holds the
//! strands' cross-sections at height `t = (k + 1) / L`, centred on
//! `root + (lean + clump pull) * t + helix(t)`, with a radius tapering toward each strand's tip
//! and optionally a soft halo at the roots (the paper's alpha blur, Figure 10). Geometry is in texels, so a
//! larger tile at the same density holds more, finer strands (the paper's "resizing").
//!
//! Generation runs one slice (and one fin row) per rayon task, each drawing its strands in a
//! fixed order: the bytes depend on the seed only, never on the thread count.

mod colour;
mod image;
mod pattern;
mod strands;

use std::path::PathBuf;

use glam::Vec3;
use rayon::prelude::*;

pub use self::colour::{ColourMode, ColourParams, Rgb, height_table};
pub use self::image::{ImageRgba8, downsample_rgba8, mip_level_count};
pub use self::pattern::leopard_pattern;
pub use self::strands::Strand;
use crate::param::ParamError;

/// Smallest tile edge (texels).
pub const MIN_TILE_SIZE: u32 = 32;
/// Largest tile edge (texels).
pub const MAX_TILE_SIZE: u32 = 2048;

/// The step of [`FurTextures::strand_tilt`]'s bytes, texels per fur length: a quarter texel,
/// so a byte holds up to about 32 texels either way.
pub const TILT_STEP_TEXELS: f32 = 0.25;

/// The generated textures of one fur, in the layout the renderer uploads directly.
///
/// Every size is a power of two and alpha is straight, so a mip chain is a repeated
/// [`downsample_rgba8`] (alpha-weighted 2x2 box): see [`FurTextures::shell_mips`].
#[derive(Clone, PartialEq, Eq)]
pub struct FurTextures {
    /// Shell tiles are `size x size` texels and wrap seamlessly.
    pub size: u32,
    /// Number of shell slices: slice `k` is drawn on shell layer `k + 1` (`k = 0..L`).
    pub layers: u32,
    /// RGBA8, slice-major (`layers * size * size * 4` bytes): one upload as a 2D array texture.
    /// RGB is the strand colour (straight, not premultiplied), A its coverage.
    pub shell: Vec<u8>,
    /// The fin texture: the side view of the same strands, u along the edge, v up the strand
    /// (row 0 = tips, last row = roots).
    pub fin_width: u32,
    /// Height of the fin texture (texels, root to tip).
    pub fin_height: u32,
    /// RGBA8, `fin_width * fin_height * 4` bytes.
    pub fin: Vec<u8>,
    /// One byte per shell texel, slice-major like [`Self::shell`] (`layers * size * size`): the
    /// seeded keep value (`0..=254`) of the strand covering the texel most. A groom's density
    /// keeps a texel where `(value + 0.5) / 256 < density`, so 0.5 keeps about half the strands,
    /// each whole, without new textures. Uploaded for groomed furs only.
    pub strand_keep: Vec<u8>,
    /// Two signed bytes per shell texel, slice-major like [`Self::shell`]: how far the strand
    /// covering the texel most leans there per fur length (`d centre / dt`, texels:
    /// [`Strand::tilt`]) times the texel's coverage, in steps of [`TILT_STEP_TEXELS`]. A wet coat's
    /// shells light each texel along its own strand's tangent with it; uploaded once a coat is wet.
    /// Empty for none: a wet coat's shells are then lit along their columns.
    pub strand_tilt: Vec<u8>,
    /// Surface colour mode only: the base mesh's colour texture. Shell and fin RGB then hold a
    /// grey per-strand brightness; the renderer multiplies it by this image sampled with the
    /// mesh's corner UVs. `None` in the other modes (the RGB is the final strand colour).
    pub surface: Option<ImageRgba8>,
    /// How far the strands stand off their roots at the tips (wet clumps read it).
    pub lean: StrandLean,
}

/// How far the strands' cross-sections stand off their roots at the tip layer (lean, clumping
/// pull and curl together): the share of strands more than a texel off, and their mean offset.
/// A wet coat's clumps are chosen at the roots (`reference::clumps`), so near a clump's border a
/// shell fragment shows strands rooted on either side this far in (`wet.wgsl`).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct StrandLean {
    /// Share of the strands more than a texel off their roots at the tips, `0..=1`.
    pub share: f32,
    /// Their mean offset there, texels (0 when none is).
    pub texels: f32,
}

// Both are finite: measured from finite strands.
impl Eq for StrandLean {}

impl StrandLean {
    /// The lean of `strands` (in row order: the same sum on any machine).
    #[must_use]
    pub fn of(strands: &[Strand]) -> Self {
        let (count, sum) = strands
            .iter()
            .map(|strand| (strand.centre(1.0) - strand.root()).length())
            .filter(|offset| *offset > 1.0)
            .fold((0usize, 0.0f64), |(count, sum), offset| (count + 1, sum + f64::from(offset)));
        if count == 0 {
            return Self::default();
        }
        Self { share: count as f32 / strands.len() as f32, texels: (sum / count as f64) as f32 }
    }
}

impl FurTextures {
    /// The smallest valid textures (4x4 texels, one slice, fully transparent): for a fur that is
    /// simulated or measured but never looked at.
    #[must_use]
    pub fn blank() -> Self {
        Self {
            size: 4,
            layers: 1,
            shell: vec![0; 64],
            fin_width: 4,
            fin_height: 4,
            fin: vec![0; 64],
            strand_keep: vec![0; 16],
            strand_tilt: vec![0; 32],
            surface: None,
            lean: StrandLean::default(),
        }
    }
}

// Sizes only: the derived form would print megabytes of texels.
impl std::fmt::Debug for FurTextures {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FurTextures")
            .field("size", &self.size)
            .field("layers", &self.layers)
            .field("shell_bytes", &self.shell.len())
            .field("fin_size", &(self.fin_width, self.fin_height))
            .field("strand_keep_bytes", &self.strand_keep.len())
            .field("strand_tilt_bytes", &self.strand_tilt.len())
            .field("surface", &self.surface)
            .field("lean", &self.lean)
            .finish()
    }
}

impl FurTextures {
    /// Bytes of one shell slice.
    #[must_use]
    pub fn slice_bytes(&self) -> usize {
        self.size as usize * self.size as usize * 4
    }

    /// Slice `k` (shell layer `k + 1`), RGBA8.
    ///
    /// # Panics
    /// If `k >= layers`.
    #[must_use]
    pub fn slice(&self, k: u32) -> &[u8] {
        assert!(k < self.layers, "slice {k} of {}", self.layers);
        let bytes = self.slice_bytes();
        &self.shell[k as usize * bytes..(k as usize + 1) * bytes]
    }

    /// Mean alpha of slice `k` in `0..=1`: how much of the tile the strands cover there.
    ///
    /// # Panics
    /// If `k >= layers`.
    #[must_use]
    pub fn coverage(&self, k: u32) -> f32 {
        let slice = self.slice(k);
        let sum: u64 = slice.chunks_exact(4).map(|p| u64::from(p[3])).sum();
        sum as f32 / (255.0 * (slice.len() / 4) as f32)
    }

    /// Levels of a full shell mip chain (`log2(size) + 1`).
    #[must_use]
    pub fn mip_levels(&self) -> u32 {
        mip_level_count(self.size)
    }

    /// The shell mip chain below level 0: entry `m` is level `m + 1`, slice-major like
    /// [`Self::shell`], `(size >> (m + 1))^2 * layers * 4` bytes, filtered with alpha weighting.
    #[must_use]
    pub fn shell_mips(&self) -> Vec<Vec<u8>> {
        let mut levels: Vec<Vec<u8>> = Vec::new();
        let mut size = self.size;
        while size > 1 {
            let previous = levels.last().unwrap_or(&self.shell);
            let next = downsample_rgba8(previous, size, size, self.layers);
            levels.push(next);
            size /= 2;
        }
        levels
    }

    /// The fin mip chain below level 0, like [`Self::shell_mips`] (down to one texel high).
    #[must_use]
    pub fn fin_mips(&self) -> Vec<Vec<u8>> {
        let mut levels: Vec<Vec<u8>> = Vec::new();
        let (mut width, mut height) = (self.fin_width, self.fin_height);
        while width > 1 || height > 1 {
            let previous = levels.last().unwrap_or(&self.fin);
            let next = downsample_rgba8(previous, width, height, 1);
            levels.push(next);
            (width, height) = ((width / 2).max(1), (height / 2).max(1));
        }
        levels
    }

    /// Every slice, root first, left to right in rows of 8, composited over `background` so
    /// alpha shows; tiles larger than `max_tile` are mip-filtered down to it.
    #[must_use]
    pub fn contact_sheet(&self, max_tile: u32, background: [u8; 3]) -> ImageRgba8 {
        const COLUMNS: u32 = 8;
        const GAP: u32 = 6;
        let mut tile = self.size;
        let mut slices = std::borrow::Cow::Borrowed(&self.shell);
        while tile > max_tile.max(1) {
            slices = std::borrow::Cow::Owned(downsample_rgba8(&slices, tile, tile, self.layers));
            tile /= 2;
        }
        let columns = self.layers.min(COLUMNS);
        let rows = self.layers.div_ceil(columns);
        let width = columns * tile + (columns + 1) * GAP;
        let height = rows * tile + (rows + 1) * GAP;
        let [r, g, b] = background;
        let mut sheet = ImageRgba8::filled(width, height, [r, g, b, 255]);
        for (k, slice) in slices.chunks_exact((tile * tile * 4) as usize).enumerate() {
            let k = k as u32;
            let left = GAP + (k % columns) * (tile + GAP);
            let top = GAP + (k / columns) * (tile + GAP);
            for (y, row) in slice.chunks_exact((tile * 4) as usize).enumerate() {
                let start = ((top as usize + y) * width as usize + left as usize) * 4;
                for (source, target) in row.chunks_exact(4).zip(sheet.pixels[start..].chunks_exact_mut(4)) {
                    let alpha = u32::from(source[3]);
                    for c in 0..3 {
                        let blended = u32::from(source[c]) * alpha + u32::from(target[c]) * (255 - alpha);
                        target[c] = ((blended + 127) / 255) as u8;
                    }
                }
            }
        }
        sheet
    }
}

/// Growing styles (the paper's Figure 4 D-F).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Style {
    /// Every strand grows straight up its shell column (no lean).
    Straight,
    /// Every strand leans by a seeded vector.
    Random,
    /// A share ([`TextureParams::mixed_ratio`]) of the strands lean, the rest grow straight.
    #[default]
    Mixed,
}

/// The `[texture]` table of a preset. Lengths are in texels of the tile.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TextureParams {
    /// Tile edge in texels: a power of two in `32..=2048`. Default 512.
    pub size: u32,
    /// Root coverage before overlaps: 1 = the strands' root cross-sections add up to the whole
    /// tile. `0..=1`, default 0.55.
    pub density: f32,
    /// Strand radius at the root, texels (each strand varies by +-20 %). `0.25..=16`, default 1.4.
    pub thickness: f32,
    /// How much the radius shrinks from root to the strand's tip: 0 = cylinder, 1 = a point.
    /// `0..=1`, default 0.75.
    pub taper: f32,
    /// Extra soft width at the roots, texels, fading out by 40 % of the height (the paper's
    /// alpha blur, Figure 10; e.g. 1.0). `0..=8`, default 0: `pelt fidelity` measures every
    /// model closer to its explicit strands without it, as it hides the skin between them.
    pub root_blur: f32,
    /// Spread of strand lengths, as a fraction of the fur's length: lengths are uniform in
    /// `1 - length_variation ..= 1 + length_variation / 3` (a quarter of the strands reach past
    /// the tip layer, so the outermost shell still shows tips). `0..=0.95`, default 0.3.
    pub length_variation: f32,
    /// `"straight"`, `"random"` or `"mixed"` (default).
    pub style: Style,
    /// Mixed style: the share of strands that lean. `0..=1`, default 0.6.
    pub mixed_ratio: f32,
    /// Leaning strands' tip offset from the root, texels (each between half and all of it).
    /// `0..=64`, default 5.
    pub lean: f32,
    /// Curl (a helix around the lean line) radius, texels; 0 = no curl. `0..=32`, default 0.
    pub curl_radius: f32,
    /// Curl turns from root to tip. `0..=16`, default 0.
    pub curl_turns: f32,
    /// Clumping: how far each tip moves toward its clump centre. `0..=1`, default 0.2.
    pub clump: f32,
    /// Distance between clump centres, texels. `2..=size`, default 10.
    pub clump_size: f32,
    /// Texture seed. Default 1.
    pub seed: u64,
    /// A pattern image (relative to the preset file) that replaces the random density: black
    /// grows no strands, texels whose brightest channel reaches 25 % grow full density, alpha
    /// scales it too. Default none.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub pattern: Option<PathBuf>,
    /// Tint each strand with the pattern's colour at its root. Default true.
    pub pattern_tint: bool,
}

impl Default for TextureParams {
    fn default() -> Self {
        Self {
            size: 512,
            density: 0.55,
            thickness: 1.4,
            taper: 0.75,
            root_blur: 0.0,
            length_variation: 0.3,
            style: Style::Mixed,
            mixed_ratio: 0.6,
            lean: 5.0,
            curl_radius: 0.0,
            curl_turns: 0.0,
            clump: 0.2,
            clump_size: 10.0,
            seed: 1,
            pattern: None,
            pattern_tint: true,
        }
    }
}

impl TextureParams {
    /// Checks every field against its documented range (keys as in a preset: `texture.*`).
    ///
    /// # Errors
    /// The first [`ParamError`] found.
    pub fn validate(&self) -> Result<(), ParamError> {
        if !(self.size.is_power_of_two() && (MIN_TILE_SIZE..=MAX_TILE_SIZE).contains(&self.size)) {
            return Err(ParamError {
                key: "texture.size".to_owned(),
                problem: format!("must be a power of two from {MIN_TILE_SIZE} to {MAX_TILE_SIZE}, got {}", self.size),
            });
        }
        let ranges = [
            ("density", self.density, 0.0, 1.0),
            ("thickness", self.thickness, 0.25, 16.0),
            ("taper", self.taper, 0.0, 1.0),
            ("root_blur", self.root_blur, 0.0, 8.0),
            ("length_variation", self.length_variation, 0.0, 0.95),
            ("mixed_ratio", self.mixed_ratio, 0.0, 1.0),
            ("lean", self.lean, 0.0, 64.0),
            ("curl_radius", self.curl_radius, 0.0, 32.0),
            ("curl_turns", self.curl_turns, 0.0, 16.0),
            ("clump", self.clump, 0.0, 1.0),
            ("clump_size", self.clump_size, 2.0, self.size as f32),
        ];
        for (key, value, low, high) in ranges {
            if !(value.is_finite() && (low..=high).contains(&value)) {
                return Err(ParamError {
                    key: format!("texture.{key}"),
                    problem: format!("must be between {low} and {high}, got {value}"),
                });
            }
        }
        Ok(())
    }
}

/// The decoded images a texture set is made from (the preset resolves and loads them).
#[derive(Clone, Debug, Default)]
pub struct TextureInputs {
    /// Replaces the random density (and tints, see [`TextureParams::pattern_tint`]).
    pub pattern: Option<ImageRgba8>,
    /// Height mode without `height_colours`: the root-to-tip gradient.
    pub gradient: Option<ImageRgba8>,
    /// Surface mode: the mesh's colour texture, passed through to [`FurTextures::surface`].
    pub surface: Option<ImageRgba8>,
}

/// Why a texture set could not be generated.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum TextureError {
    /// Invalid texture parameters.
    #[error("{0}")]
    Param(#[from] ParamError),
    /// A layer count out of range.
    #[error("layers: must be between 1 and {max}, got {got}", max = crate::fur::MAX_LAYERS)]
    Layers {
        /// The count given.
        got: u32,
    },
    /// A colour mode without the image it needs.
    #[error("{key}: {mode} mode needs this image, but none was given")]
    MissingImage {
        /// The key that names the image.
        key: &'static str,
        /// The colour mode.
        mode: &'static str,
    },
}

/// The seeded strand field of a texture set, as data: every strand the shell slices and the fin
/// are drawn from, and the colour each has at each height. [`generate`] rasterises it; the
/// explicit strand reference ([`crate::reference`]) places the same strands on a mesh.
#[derive(Clone, Debug)]
pub struct StrandField {
    /// The texture parameters the field was grown with (tile size, taper, ...).
    pub params: TextureParams,
    /// The strands in row order of their root texels.
    pub strands: Vec<Strand>,
    mode: ColourMode,
    single: Vec3,
    /// Height mode: the colour table from root to tip.
    heights: Vec<Vec3>,
    /// Surface mode: the mesh's colour texture.
    surface: Option<ImageRgba8>,
}

impl StrandField {
    /// Grows the field of these parameters (validated as [`generate`] does).
    ///
    /// # Errors
    /// As [`generate`].
    pub fn new(params: &TextureParams, colour: &ColourParams, inputs: &TextureInputs) -> Result<Self, TextureError> {
        params.validate()?;
        colour.validate()?;
        let heights = match colour.mode {
            ColourMode::Height => {
                if colour.height_colours.is_empty() && inputs.gradient.is_none() {
                    return Err(TextureError::MissingImage { key: "colour.gradient", mode: "height" });
                }
                height_table(&colour.height_colours, inputs.gradient.as_ref(), colour.height_levels)
            }
            _ => Vec::new(),
        };
        let surface = match colour.mode {
            ColourMode::Surface => Some(
                inputs.surface.clone().ok_or(TextureError::MissingImage { key: "colour.surface", mode: "surface" })?,
            ),
            _ => None,
        };
        let strands = strands::seed_strands(params, inputs.pattern.as_ref(), colour.brightness_variation);
        Ok(Self {
            params: params.clone(),
            strands,
            mode: colour.mode,
            single: colour.colour.to_vec3(),
            heights,
            surface,
        })
    }

    /// The colour `strand` has at height `t` (straight RGB, `0..=1`; the textures' RGB). In
    /// surface mode this is the grey brightness that the mesh's texture multiplies.
    #[must_use]
    pub fn colour(&self, strand: &Strand, t: f32) -> Vec3 {
        let base = match self.mode {
            ColourMode::Single => self.single,
            ColourMode::Surface => Vec3::ONE,
            ColourMode::Height => self.heights[((t * self.heights.len() as f32) as usize).min(self.heights.len() - 1)],
        };
        base * strand.tint * strand.brightness
    }

    /// Surface mode: the mesh's colour texture (see [`FurTextures::surface`]).
    #[must_use]
    pub fn surface(&self) -> Option<&ImageRgba8> {
        self.surface.as_ref()
    }
}

/// Generates the shell slices and the fin texture of `layers` shells.
///
/// # Errors
/// [`TextureError`] for parameters outside their ranges or an image the colour mode needs but
/// `inputs` lacks.
pub fn generate(
    layers: u32,
    params: &TextureParams,
    colour: &ColourParams,
    inputs: &TextureInputs,
) -> Result<FurTextures, TextureError> {
    if layers == 0 || layers > crate::fur::MAX_LAYERS {
        return Err(TextureError::Layers { got: layers });
    }
    let field = StrandField::new(params, colour, inputs)?;
    Ok(generate_from(layers, &field))
}

/// Rasterises `field` into the shell slices of `layers` shells and the fin texture.
#[must_use]
pub fn generate_from(layers: u32, field: &StrandField) -> FurTextures {
    let params = &field.params;
    let colour_at = |strand: &Strand, t: f32| field.colour(strand, t);
    let strands = &field.strands;
    let size = params.size;
    let slice_bytes = size as usize * size as usize * 4;
    let mut shell = vec![0u8; slice_bytes * layers as usize];
    let mut strand_keep = vec![0u8; slice_bytes / 4 * layers as usize];
    let mut strand_tilt = vec![0u8; slice_bytes / 2 * layers as usize];
    shell
        .par_chunks_mut(slice_bytes)
        .zip(strand_keep.par_chunks_mut(slice_bytes / 4))
        .zip(strand_tilt.par_chunks_mut(slice_bytes / 2))
        .enumerate()
        .for_each(|(k, ((slice, keep), tilt))| {
            let t = (k + 1) as f32 / layers as f32;
            strands::draw_slice(params, strands, (t, k as u64), &colour_at, (slice, keep, tilt));
        });
    let fin_height = (size / 2).max(MIN_TILE_SIZE);
    let mut fin = vec![0u8; size as usize * fin_height as usize * 4];
    strands::draw_fin(params, strands, fin_height, &colour_at, &mut fin);
    FurTextures {
        size,
        layers,
        shell,
        fin_width: size,
        fin_height,
        fin,
        strand_keep,
        strand_tilt,
        surface: field.surface.clone(),
        lean: StrandLean::of(strands),
    }
}
