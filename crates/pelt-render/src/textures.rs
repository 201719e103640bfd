//! Uploading [`FurTextures`]: the shell slices as one 2D array texture and the fin texture, both
//! with mipmaps (pelt-core's alpha-weighted filter) so distant fur averages out instead of
//! sparkling.

use std::sync::{Arc, Mutex, OnceLock};

use pelt_core::texture::{FurTextures, StrandLean, downsample_rgba8};

use crate::RenderError;
use crate::requirements::array_layers;
use crate::shaders::Layouts;

/// What the object uniform reads of a fur's textures (plain meshes: the default, no slices).
#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct TextureShape {
    pub shell_slices: u32,
    pub has_surface: bool,
    pub lean: StrandLean,
}

/// One fur's textures on the GPU with their bind group (group 2 of the fur pipelines).
/// Cloning it clones handles: the copies of one fur share its textures.
#[derive(Clone, Debug)]
pub(crate) struct GpuTextures {
    pub bind_group: wgpu::BindGroup,
    /// What the object uniform reads of them: slices, surface texture, the strands' lean.
    pub shape: TextureShape,
    /// Alpha-weighted mean strand colour of the root slice, linear RGB.
    pub root_colour: glam::Vec3,
    /// Each slice's mean colour and coverage ([`GpuTextures::coat_colour`]): what a fur too small
    /// on screen for its shells is drawn in.
    pub slice_means: std::sync::Arc<[[f32; 4]]>,
    /// Bytes of all textures with their mipmaps.
    pub bytes: u64,
    /// Whether the strands' keep values are on the GPU (a groomed fur's density reads them).
    pub has_keep: bool,
    /// Bytes of the keep values (the 1-byte stand-in without them).
    pub keep_bytes: u64,
    /// The strands' tilts, uploaded the first time a copy is wet ([`GpuTextures::bind_wet`]).
    wet: Arc<WetTilts>,
}

/// A coat's strand tilts (`FurTextures::strand_tilt`): a dry coat never reads them, so they wait
/// on the CPU until a copy of the fur is first wet, then one bind group with them serves every
/// copy (a dry coat's pipelines leave them unread).
struct WetTilts {
    pending: Mutex<Option<PendingTilts>>,
    bound: OnceLock<(wgpu::BindGroup, u64)>,
}

struct PendingTilts {
    device: wgpu::Device,
    layout: wgpu::BindGroupLayout,
    samplers: [wgpu::Sampler; 2],
    /// Shell, fin, surface and keep views.
    views: [wgpu::TextureView; 4],
    size: u32,
    layers: u32,
    texels: Vec<u8>,
}

// Whether they are bound, not the megabytes of tilts.
impl std::fmt::Debug for WetTilts {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("WetTilts").field("bytes", &self.bound.get().map(|(_, bytes)| *bytes)).finish()
    }
}

/// The fur textures' bind group over these views and the tilts' view.
fn textures_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    samplers: &[wgpu::Sampler; 2],
    [shell, fin, surface, keep]: &[wgpu::TextureView; 4],
    tilt: &wgpu::TextureView,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("pelt fur textures"),
        layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: wgpu::BindingResource::TextureView(shell) },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(fin) },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::Sampler(&samplers[0]) },
            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(&samplers[1]) },
            wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::TextureView(surface) },
            wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(keep) },
            wgpu::BindGroupEntry { binding: 6, resource: wgpu::BindingResource::TextureView(tilt) },
        ],
    })
}

impl GpuTextures {
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layouts: &Layouts,
        textures: &FurTextures,
        with_keep: bool,
    ) -> Result<Self, RenderError> {
        validate(textures)?;
        let keep_bytes = textures.size as usize * textures.size as usize * textures.layers as usize;
        if with_keep && textures.strand_keep.len() != keep_bytes {
            return Err(RenderError::Textures(format!(
                "strand keep values have {} bytes, expected {keep_bytes} (one per shell texel)",
                textures.strand_keep.len()
            )));
        }
        let limits = device.limits();
        let side = textures.size.max(textures.fin_width).max(textures.fin_height);
        let surface_side = textures.surface.as_ref().map_or(1, |s| s.width.max(s.height));
        if side.max(surface_side) > limits.max_texture_dimension_2d || textures.layers > limits.max_texture_array_layers
        {
            return Err(RenderError::Textures(format!(
                "{0}x{0}x{1} shell, {2}x{3} fin and a {4}-texel surface image exceed this GPU's texture limits \
                 ({5} texels a side, {6} layers)",
                textures.size,
                textures.layers,
                textures.fin_width,
                textures.fin_height,
                surface_side,
                limits.max_texture_dimension_2d,
                limits.max_texture_array_layers
            )));
        }
        let slice_bytes = textures.size as usize * textures.size as usize * 4;
        let mut slices: Vec<&[u8]> = textures.shell.chunks_exact(slice_bytes).collect();
        // A layer GL needs to make an array (`array_layers`) repeats the outermost slice.
        let array = array_layers(device, (textures.size, textures.size), textures.layers);
        if let Some(&last) = slices.last() {
            slices.resize(array as usize, last);
        }
        let shell = upload(device, queue, "pelt shell slices", (textures.size, textures.size), slices);
        let fin = upload(device, queue, "pelt fin", (textures.fin_width, textures.fin_height), vec![&textures.fin]);
        let shell = shell.create_view(&wgpu::TextureViewDescriptor {
            dimension: Some(wgpu::TextureViewDimension::D2Array),
            ..wgpu::TextureViewDescriptor::default()
        });
        let fin = fin.create_view(&wgpu::TextureViewDescriptor::default());
        let white = [255_u8; 4];
        let (surface_size, surface_pixels): ((u32, u32), &[u8]) = match &textures.surface {
            Some(image) => ((image.width, image.height), &image.pixels),
            None => ((1, 1), &white),
        };
        let surface = upload(device, queue, "pelt surface colour", surface_size, vec![surface_pixels])
            .create_view(&wgpu::TextureViewDescriptor::default());
        // Without a groom a 1x1 stand-in that keeps every strand.
        let (keep_size, keep_layers, keep_texels): (u32, u32, &[u8]) =
            if with_keep { (textures.size, textures.layers, &textures.strand_keep) } else { (1, 1, &[0]) };
        let keep = upload_fetched(device, queue, KEEP, (keep_size, keep_layers), keep_texels);
        // Until a copy is wet, a zero tilt stands in for the strands'.
        let no_tilt = upload_fetched(device, queue, TILT, (1, 1), &[0, 0]);
        let samplers = [layouts.shell_sampler.clone(), layouts.fin_sampler.clone()];
        let views = [shell, fin, surface, keep];
        let bind_group = textures_bind_group(device, &layouts.textures, &samplers, &views, &no_tilt);
        let pending = (!textures.strand_tilt.is_empty()).then(|| PendingTilts {
            device: device.clone(),
            layout: layouts.textures.clone(),
            samplers,
            views,
            size: textures.size,
            layers: textures.layers,
            texels: textures.strand_tilt.clone(),
        });
        let wet = Arc::new(WetTilts { pending: Mutex::new(pending), bound: OnceLock::new() });
        let bytes = mipmapped_bytes(textures.size, textures.size) * u64::from(textures.layers)
            + mipmapped_bytes(textures.fin_width, textures.fin_height)
            + mipmapped_bytes(surface_size.0, surface_size.1)
            + u64::from(keep_size * keep_size * keep_layers);
        Ok(Self {
            bind_group,
            shape: TextureShape {
                shell_slices: textures.layers,
                has_surface: textures.surface.is_some(),
                lean: textures.lean,
            },
            root_colour: root_colour(textures, slice_bytes),
            slice_means: slice_means(textures, slice_bytes).into(),
            bytes,
            has_keep: with_keep,
            keep_bytes: u64::from(keep_size * keep_size * keep_layers),
            wet,
        })
    }

    /// The bind group the fur's draws take: with the strands' tilts once a copy has been wet.
    pub fn bind_group(&self) -> &wgpu::BindGroup {
        self.wet.bound.get().map_or(&self.bind_group, |(group, _)| group)
    }

    /// Uploads the strands' tilts, once, for a copy that is wet: a wet coat's shells light each
    /// texel along its strand. Textures without tilts keep the zero stand-in.
    pub fn bind_wet(&self, queue: &wgpu::Queue) {
        if self.wet.bound.get().is_some() {
            return;
        }
        let Some(pending) = self.wet.pending.lock().unwrap_or_else(std::sync::PoisonError::into_inner).take() else {
            return;
        };
        let PendingTilts { device, layout, samplers, views, size, layers, texels } = pending;
        let tilt = upload_fetched(&device, queue, TILT, (size, layers), &texels);
        let group = textures_bind_group(&device, &layout, &samplers, &views, &tilt);
        let _ = self.wet.bound.set((group, texels.len() as u64));
    }

    /// Bytes of the strands' tilts on the GPU: 0 until a copy has been wet.
    pub fn tilt_bytes(&self) -> u64 {
        self.wet.bound.get().map_or(0, |(_, bytes)| *bytes)
    }
}

/// Bytes of an RGBA8 texture with the full mip chain `upload` makes.
fn mipmapped_bytes(width: u32, height: u32) -> u64 {
    let (mut w, mut h, mut bytes) = (u64::from(width), u64::from(height), 0);
    for _ in 0..32 - width.max(height).leading_zeros() {
        bytes += 4 * w * h;
        (w, h) = ((w / 2).max(1), (h / 2).max(1));
    }
    bytes
}

fn validate(textures: &FurTextures) -> Result<(), RenderError> {
    let bad = |message: String| Err(RenderError::Textures(message));
    if textures.size == 0 || textures.layers == 0 || textures.fin_width == 0 || textures.fin_height == 0 {
        return bad(format!(
            "empty texture: shell {0}x{0}x{1}, fin {2}x{3}",
            textures.size, textures.layers, textures.fin_width, textures.fin_height
        ));
    }
    let shell_bytes = textures.size as usize * textures.size as usize * textures.layers as usize * 4;
    if textures.shell.len() != shell_bytes {
        return bad(format!("shell has {} bytes, expected {shell_bytes}", textures.shell.len()));
    }
    let tilt_bytes = textures.size as usize * textures.size as usize * textures.layers as usize * 2;
    if !textures.strand_tilt.is_empty() && textures.strand_tilt.len() != tilt_bytes {
        return bad(format!(
            "strand tilts have {} bytes, expected {tilt_bytes} (two per shell texel, or none)",
            textures.strand_tilt.len()
        ));
    }
    let fin_bytes = textures.fin_width as usize * textures.fin_height as usize * 4;
    if textures.fin.len() != fin_bytes {
        return bad(format!("fin has {} bytes, expected {fin_bytes}", textures.fin.len()));
    }
    if let Some(surface) = &textures.surface {
        let bytes = surface.width as usize * surface.height as usize * 4;
        if surface.width == 0 || surface.height == 0 || surface.pixels.len() != bytes {
            return bad(format!(
                "surface image {}x{} has {} bytes",
                surface.width,
                surface.height,
                surface.pixels.len()
            ));
        }
    }
    Ok(())
}

/// Creates an sRGB texture with one array layer per slice and a full mip chain.
fn upload(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    label: &str,
    (width, height): (u32, u32),
    slices: Vec<&[u8]>,
) -> wgpu::Texture {
    let mip_level_count = 32 - width.max(height).leading_zeros();
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width, height, depth_or_array_layers: slices.len() as u32 },
        mip_level_count,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format: wgpu::TextureFormat::Rgba8UnormSrgb,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    for (layer, slice) in slices.into_iter().enumerate() {
        let mut level = slice.to_vec();
        let (mut w, mut h) = (width, height);
        for mip_level in 0..mip_level_count {
            queue.write_texture(
                wgpu::TexelCopyTextureInfo {
                    texture: &texture,
                    mip_level,
                    origin: wgpu::Origin3d { x: 0, y: 0, z: layer as u32 },
                    aspect: wgpu::TextureAspect::All,
                },
                &level,
                wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(4 * w), rows_per_image: Some(h) },
                wgpu::Extent3d { width: w, height: h, depth_or_array_layers: 1 },
            );
            level = downsample_rgba8(&level, w, h, 1);
            (w, h) = ((w / 2).max(1), (h / 2).max(1));
        }
    }
    texture
}

/// A fetched array texture: its label, texel format and bytes per texel.
struct Fetched(&'static str, wgpu::TextureFormat, u32);

/// The strands' keep values, fetched by texel.
const KEEP: Fetched = Fetched("pelt strand keep values", wgpu::TextureFormat::R8Unorm, 1);
/// The strands' tilts (two signed bytes), filtered by the shell sampler at level 0.
const TILT: Fetched = Fetched("pelt strand tilts", wgpu::TextureFormat::Rg8Snorm, 2);

/// An array texture of one layer per slice, no mipmaps: the keep values or the tilts.
fn upload_fetched(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    Fetched(label, format, texel_bytes): Fetched,
    (size, layers): (u32, u32),
    texels: &[u8],
) -> wgpu::TextureView {
    // A layer GL needs to make an array (`array_layers`) repeats the last, which the shader's
    // clamp to the last layer then reads as before.
    let array = array_layers(device, (size, size), layers);
    let padded: Vec<u8>;
    let layer_bytes = (size * size * texel_bytes) as usize;
    let texels = match texels.len().checked_sub(layer_bytes) {
        Some(last) if array > layers => {
            padded = [texels, &texels[last..].repeat((array - layers) as usize)].concat();
            &padded[..]
        }
        _ => texels,
    };
    let layers = array;
    let texture = device.create_texture(&wgpu::TextureDescriptor {
        label: Some(label),
        size: wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
        mip_level_count: 1,
        sample_count: 1,
        dimension: wgpu::TextureDimension::D2,
        format,
        usage: wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        view_formats: &[],
    });
    queue.write_texture(
        wgpu::TexelCopyTextureInfo {
            texture: &texture,
            mip_level: 0,
            origin: wgpu::Origin3d::ZERO,
            aspect: wgpu::TextureAspect::All,
        },
        texels,
        wgpu::TexelCopyBufferLayout { offset: 0, bytes_per_row: Some(size * texel_bytes), rows_per_image: Some(size) },
        wgpu::Extent3d { width: size, height: size, depth_or_array_layers: layers },
    );
    texture.create_view(&wgpu::TextureViewDescriptor {
        dimension: Some(wgpu::TextureViewDimension::D2Array),
        ..wgpu::TextureViewDescriptor::default()
    })
}

pub(crate) fn srgb_to_linear(value: f32) -> f32 {
    if value <= 0.04045 { value / 12.92 } else { ((value + 0.055) / 1.055).powf(2.4) }
}

/// Each slice's mean colour (linear, premultiplied by coverage) and mean coverage, roots first.
fn slice_means(textures: &FurTextures, slice_bytes: usize) -> Vec<[f32; 4]> {
    textures
        .shell
        .chunks_exact(slice_bytes)
        .map(|slice| {
            // A table of the 256 sRGB values: millions of texels, no `powf` each.
            let linear: [f32; 256] = std::array::from_fn(|v| srgb_to_linear(v as f32 / 255.0));
            let mut sum = [0.0f32; 4];
            for texel in slice.chunks_exact(4) {
                let alpha = f32::from(texel[3]) / 255.0;
                for c in 0..3 {
                    sum[c] += linear[usize::from(texel[c])] * alpha;
                }
                sum[3] += alpha;
            }
            let texels = (slice_bytes / 4).max(1) as f32;
            sum.map(|v| v / texels)
        })
        .collect()
}

/// The share of a surface's light a coat returns as the skin is lit (wrapped Lambert): Kajiya-Kay's
/// diffuse term, and the fur model's lobes, whose strands absorb and scatter more of it away
/// (measured on the bunny in Pelt's studio: its brown coat's mean colour against its skin's,
/// 0.65-0.8 of Kajiya-Kay's share by channel in linear light; the white highlight makes it less
/// saturated).
const KAJIYA_KAY_REFLECTANCE: f32 = 0.85;
const FUR_MODEL_REFLECTANCE: f32 = 0.6;

impl GpuTextures {
    /// The coat's mean colour seen from above as the shells shade it: the slices' means
    /// composited roots first over the skin, each darkened toward the roots as `occlusion` in
    /// `shading.wgsl` does with `root_occlusion`, times the share of light the shading model's
    /// strands return (`fur_model`: the fur model's, else Kajiya-Kay's).
    pub fn coat_colour(&self, root_occlusion: f32, fur_model: bool) -> glam::Vec3 {
        let n = self.slice_means.len().max(1) as f32;
        let mut colour = self.root_colour * root_occlusion;
        for (i, [r, g, b, alpha]) in self.slice_means.iter().enumerate() {
            let height = (i as f32 + 1.0) / n;
            let occlusion = root_occlusion + (1.0 - root_occlusion) * height.powf(0.7);
            colour = colour * (1.0 - alpha) + glam::Vec3::new(*r, *g, *b) * occlusion;
        }
        colour * if fur_model { FUR_MODEL_REFLECTANCE } else { KAJIYA_KAY_REFLECTANCE }
    }
}

/// The colour of the fur at the roots: the first slice's strands, weighted by coverage.
fn root_colour(textures: &FurTextures, slice_bytes: usize) -> glam::Vec3 {
    for slice in textures.shell.chunks_exact(slice_bytes) {
        let (mut sum, mut weight) = (glam::Vec3::ZERO, 0.0);
        for texel in slice.chunks_exact(4) {
            let alpha = f32::from(texel[3]) / 255.0;
            let rgb = glam::Vec3::new(texel[0].into(), texel[1].into(), texel[2].into()) / 255.0;
            sum += rgb.map(srgb_to_linear) * alpha;
            weight += alpha;
        }
        if weight > 0.0 {
            return sum / weight;
        }
    }
    glam::Vec3::splat(0.2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wrong_sizes_are_errors() {
        let textures = FurTextures {
            size: 4,
            layers: 2,
            shell: vec![0; 4 * 4 * 4],
            fin_width: 2,
            fin_height: 2,
            fin: vec![0; 16],
            strand_keep: vec![0; 16],
            strand_tilt: Vec::new(),
            surface: None,
            lean: StrandLean::default(),
        };
        assert!(matches!(validate(&textures), Err(RenderError::Textures(_))));
        let textures = FurTextures { shell: vec![0; 4 * 4 * 4 * 2], strand_keep: vec![0; 32], ..textures };
        assert!(validate(&textures).is_ok());
        let tilted = FurTextures { strand_tilt: vec![0; 4 * 4 * 2 * 2], ..textures.clone() };
        assert!(validate(&tilted).is_ok());
        let short = FurTextures { strand_tilt: vec![0; 4 * 4 * 2], ..textures.clone() };
        assert!(matches!(validate(&short), Err(RenderError::Textures(m)) if m.contains("strand tilts")));
        let surface = pelt_core::texture::ImageRgba8 { width: 2, height: 2, pixels: vec![0; 12] };
        assert!(validate(&FurTextures { surface: Some(surface), ..textures }).is_err());
    }

    #[test]
    fn mip_chains_are_counted() {
        assert_eq!(mipmapped_bytes(1, 1), 4);
        assert_eq!(mipmapped_bytes(4, 4), 4 * (16 + 4 + 1));
        assert_eq!(mipmapped_bytes(4, 1), 4 * (4 + 2 + 1));
    }
}
