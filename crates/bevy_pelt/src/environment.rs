//! Bevy's environment map light on the fur: a camera's `EnvironmentMapLight` diffuse cube map,
//! read from the main world's `Assets<Image>` and reduced to pelt-core's spherical harmonics
//! once per image (again when the image changes), then placed in the world with Bevy's
//! left-handed cube lookup and the light's rotation and scaled by its intensity each frame.

use std::collections::{HashMap, HashSet};

use bevy::asset::{AssetEvent, AssetId, Assets};
use bevy::camera::Camera3d;
use bevy::ecs::message::MessageReader;
use bevy::ecs::prelude::*;
use bevy::image::Image;
use bevy::light::EnvironmentMapLight;
use bevy::log::error;
use bevy::render::Extract;
use bevy::render::render_resource::{TextureDataOrder, TextureDimension, TextureFormat};
use bevy::render::sync_world::RenderEntity;
use glam::{Mat3, Vec3};
use pelt_core::light::{CubeContent, Environment};

/// Main world: how often each image has changed, so the render world knows when to read it again.
#[derive(Resource, Default)]
pub(crate) struct ImageVersions(HashMap<AssetId<Image>, u64>);

/// Counts each image's changes (`PostUpdate`).
pub(crate) fn track_image_versions(mut events: MessageReader<AssetEvent<Image>>, mut versions: ResMut<ImageVersions>) {
    for event in events.read() {
        if let AssetEvent::Added { id } | AssetEvent::Modified { id } = event {
            *versions.0.entry(*id).or_default() += 1;
        }
    }
}

/// Render world: the environments read from Bevy's diffuse maps, and each camera's this frame.
#[derive(Resource, Default)]
pub(crate) struct FurEnvironments {
    /// By image: the version read and its environment in the cube's own frame, unit intensity.
    read: HashMap<AssetId<Image>, (u64, Environment)>,
    /// Images (and versions) that could not be read, reported once.
    failed: HashSet<(AssetId<Image>, u64)>,
    /// By render-world camera: its environment map light in world space, before exposure.
    cameras: HashMap<Entity, Environment>,
}

impl FurEnvironments {
    /// The environment map light of a camera (render-world entity), before exposure.
    pub(crate) fn camera(&self, camera: Entity) -> Option<&Environment> {
        self.cameras.get(&camera)
    }
}

/// Reads each 3D camera's `EnvironmentMapLight` (its diffuse map) into the fur's environment.
/// Runs before Bevy's asset extraction, which takes the data of an image kept for the render
/// world only: such a map is read in the frame it is added or changed, if a camera uses it then.
pub(crate) fn extract_environments(
    mut environments: ResMut<FurEnvironments>,
    cameras: Extract<Query<(RenderEntity, &EnvironmentMapLight), With<Camera3d>>>,
    images: Extract<Res<Assets<Image>>>,
    versions: Extract<Res<ImageVersions>>,
) {
    let environments = &mut *environments;
    environments.cameras.clear();
    let mut used = HashSet::new();
    for (camera, light) in &cameras {
        let id = light.diffuse_map.id();
        used.insert(id);
        let version = versions.0.get(&id).copied().unwrap_or_default();
        let current = environments.read.get(&id).filter(|(read, _)| *read == version).map(|(_, e)| *e);
        let in_cube = match current {
            Some(environment) => environment,
            None => {
                if environments.failed.contains(&(id, version)) {
                    continue;
                }
                // Not loaded yet: no environment until it is.
                let Some(image) = images.get(id) else { continue };
                let handed_over = environments.read.get(&id).filter(|_| image.data.is_none()).map(|(_, e)| *e);
                match (cube_environment(image), handed_over) {
                    // Or read before Bevy took its data for the render world, unchanged since.
                    (Ok(environment), _) | (Err(_), Some(environment)) => {
                        environments.read.insert(id, (version, environment));
                        environment
                    }
                    (Err(problem), None) => {
                        error!(
                            "Pelt's fur cannot take the environment map light of {camera}: its diffuse map \
                             {id}: {problem}; the fur takes the ambient light alone"
                        );
                        environments.failed.insert((id, version));
                        continue;
                    }
                }
            }
        };
        let intensity = light.intensity;
        if !intensity.is_finite() || intensity < 0.0 || !light.rotation.is_finite() {
            continue;
        }
        let rotation = glam::Quat::from_array(light.rotation.normalize().to_array());
        let world = world_from_cube(rotation);
        environments.cameras.insert(camera, Environment { sh: in_cube.transformed(world).sh.scaled(intensity) });
    }
    environments.read.retain(|id, _| used.contains(id));
}

/// Where Bevy's cube lookup direction `c` of an environment map light turned by `rotation` lies
/// in the world: Bevy looks up a world direction `d` at `c = (q^-1 d) * (1, 1, -1)` (cube maps
/// are left-handed), so `d = q (c * (1, 1, -1))`.
pub(crate) fn world_from_cube(rotation: glam::Quat) -> Mat3 {
    Mat3::from_quat(rotation) * Mat3::from_diagonal(Vec3::new(1.0, 1.0, -1.0))
}

/// The environment a Bevy diffuse cube map (six layers, each face's first mip) holds, in its
/// cube's own frame at unit intensity.
pub(crate) fn cube_environment(image: &Image) -> Result<Environment, String> {
    let descriptor = &image.texture_descriptor;
    let size = descriptor.size;
    if descriptor.dimension != TextureDimension::D2 || size.depth_or_array_layers != 6 || size.width != size.height {
        return Err(format!(
            "a cube map has six square layers, this image is {}x{}x{} ({:?})",
            size.width, size.height, size.depth_or_array_layers, descriptor.dimension
        ));
    }
    let format = descriptor.format;
    let (texel_bytes, decode): (usize, fn(&[u8]) -> Vec3) = match format {
        TextureFormat::Rgba16Float => (8, rgba16_float),
        TextureFormat::Rgba32Float => (16, rgba32_float),
        TextureFormat::Rgb9e5Ufloat => (4, rgb9e5),
        other => {
            return Err(format!("its format {other:?} is not read (Rgba16Float, Rgba32Float and Rgb9e5Ufloat are)"));
        }
    };
    let Some(data) = image.data.as_deref() else {
        return Err("its data is not kept on the CPU (RenderAssetUsages::RENDER_WORLD only) and was handed \
                    to the render world before a camera used it; give it RenderAssetUsages::default()"
            .into());
    };
    let side = size.width as usize;
    let face_bytes = side * side * texel_bytes;
    // The first mip of each face: faces follow each other (mip-major data, as KTX2's), or each
    // face's whole mip chain follows the last (layer-major, wgpu's default).
    let layer_stride = match image.data_order {
        TextureDataOrder::MipMajor => face_bytes,
        _ => (0..descriptor.mip_level_count).map(|mip| (side >> mip).max(1).pow(2) * texel_bytes).sum(),
    };
    let needed = 5 * layer_stride + face_bytes;
    if data.len() < needed {
        return Err(format!("{} bytes of data where six {side}x{side} faces of {format:?} need {needed}", data.len()));
    }
    let texels: Vec<Vec3> = (0..6)
        .flat_map(|face| data[face * layer_stride..face * layer_stride + face_bytes].chunks_exact(texel_bytes))
        .map(decode)
        .collect();
    Environment::from_cube_faces(&texels, size.width, CubeContent::Irradiance).map_err(|e| e.to_string())
}

/// Half-precision bits as a float (subnormals, infinities and NaN included).
fn f16_to_f32(bits: u16) -> f32 {
    let sign = if bits & 0x8000 == 0 { 1.0 } else { -1.0 };
    let exponent = i32::from((bits >> 10) & 0x1f);
    let mantissa = f32::from(bits & 0x3ff);
    match exponent {
        0 => sign * mantissa * 2f32.powi(-24),
        31 if mantissa == 0.0 => sign * f32::INFINITY,
        31 => f32::NAN,
        _ => sign * (1.0 + mantissa / 1024.0) * 2f32.powi(exponent - 15),
    }
}

/// Negative radiance (a filter's ringing) is no light; not finite stays, for the error.
fn light(v: Vec3) -> Vec3 {
    Vec3::select(v.cmplt(Vec3::ZERO), Vec3::ZERO, v)
}

fn rgba16_float(texel: &[u8]) -> Vec3 {
    let channel = |i: usize| f16_to_f32(u16::from_le_bytes([texel[2 * i], texel[2 * i + 1]]));
    light(Vec3::new(channel(0), channel(1), channel(2)))
}

fn rgba32_float(texel: &[u8]) -> Vec3 {
    let channel = |i: usize| f32::from_le_bytes([texel[4 * i], texel[4 * i + 1], texel[4 * i + 2], texel[4 * i + 3]]);
    light(Vec3::new(channel(0), channel(1), channel(2)))
}

/// Three 9-bit mantissas sharing a 5-bit exponent (bias 15), red in the low bits.
fn rgb9e5(texel: &[u8]) -> Vec3 {
    let bits = u32::from_le_bytes([texel[0], texel[1], texel[2], texel[3]]);
    let scale = 2f32.powi((bits >> 27) as i32 - 15 - 9);
    Vec3::new((bits & 0x1ff) as f32, ((bits >> 9) & 0x1ff) as f32, ((bits >> 18) & 0x1ff) as f32) * scale
}

#[cfg(test)]
mod tests {
    use bevy::asset::RenderAssetUsages;
    use bevy::render::render_resource::{Extent3d, TextureViewDescriptor, TextureViewDimension};

    use super::*;

    #[test]
    fn half_floats_and_shared_exponents_decode_to_their_values() {
        // Bit patterns from the IEEE 754 binary16 table.
        for (bits, want) in [(0x3c00, 1.0), (0xc000, -2.0), (0x3800, 0.5), (0x0001, 2f32.powi(-24)), (0x7bff, 65504.0)]
        {
            assert_eq!(f16_to_f32(bits), want, "{bits:#06x}");
        }
        assert!(f16_to_f32(0x7c00).is_infinite() && f16_to_f32(0x7e00).is_nan());
        // 1.0 is mantissa 256 at exponent 16 (256 * 2^(16 - 24)); 0.5 mantissa 128; 1.5 mantissa 384.
        let bits: u32 = 256 | (128 << 9) | (384 << 18) | (16 << 27);
        assert_eq!(rgb9e5(&bits.to_le_bytes()), Vec3::new(1.0, 0.5, 1.5));
        let bytes: Vec<u8> = [0x3c00u16, 0xbc00, 0x4000, 0].iter().flat_map(|h| h.to_le_bytes()).collect();
        assert_eq!(rgba16_float(&bytes), Vec3::new(1.0, 0.0, 2.0), "negative radiance is none");
    }

    /// A cube image of `format` whose `bright` layer holds `value` (the others nothing), with
    /// `mips` mips after it (layer-major, zeros).
    fn cube_image(format: TextureFormat, texel: &dyn Fn(f32) -> Vec<u8>, bright: usize, mips: u32) -> Image {
        let side = 4usize;
        let chain: usize = (0..mips).map(|m| (side >> m).max(1).pow(2)).sum();
        let data: Vec<u8> = (0..6)
            .flat_map(|layer| (0..chain).map(move |i| (layer, i)))
            .flat_map(|(layer, i)| texel(if layer == bright && i < side * side { 1.0 } else { 0.0 }))
            .collect();
        let mut image = Image::new(
            Extent3d { width: side as u32, height: side as u32, depth_or_array_layers: 6 },
            TextureDimension::D2,
            vec![0; 6 * side * side * texel(0.0).len()],
            format,
            RenderAssetUsages::default(),
        );
        image.texture_descriptor.mip_level_count = mips;
        image.data = Some(data);
        image.texture_view_descriptor =
            Some(TextureViewDescriptor { dimension: Some(TextureViewDimension::Cube), ..Default::default() });
        image
    }

    /// Bevy's lookup of world direction `d` for a light turned by `rotation`, as its shader
    /// writes it (`quat_rotate(rotation^-1, d)`, then z negated), and the cube face it lands on.
    fn bevy_face(rotation: glam::Quat, d: Vec3) -> usize {
        let mut c = rotation.inverse() * d;
        c.z = -c.z;
        let a = c.abs();
        let axis = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        2 * axis + usize::from(c[axis] < 0.0)
    }

    #[test]
    fn the_fur_takes_the_light_from_where_bevy_looks_up_each_face() {
        let half = |v: f32| -> Vec<u8> {
            let h: u16 = if v == 1.0 { 0x3c00 } else { 0 };
            [h, h, h, 0x3c00].iter().flat_map(|h| h.to_le_bytes()).collect()
        };
        let nine = |v: f32| -> Vec<u8> {
            (if v == 1.0 { 256 | (256 << 9) | (256 << 18) | (16 << 27) } else { 0u32 }).to_le_bytes().to_vec()
        };
        let axes = [Vec3::X, Vec3::NEG_X, Vec3::Y, Vec3::NEG_Y, Vec3::Z, Vec3::NEG_Z];
        let rotations = [glam::Quat::IDENTITY, glam::Quat::from_rotation_y(1.2), glam::Quat::from_rotation_x(-0.7)];
        for (format, texel, mips) in
            [(TextureFormat::Rgba16Float, &half as &dyn Fn(f32) -> Vec<u8>, 3), (TextureFormat::Rgb9e5Ufloat, &nine, 1)]
        {
            for bright in 0..6 {
                let image = cube_image(format, texel, bright, mips);
                let in_cube = cube_environment(&image).unwrap();
                for rotation in rotations {
                    let world = in_cube.transformed(world_from_cube(rotation));
                    // The world direction Bevy looks up at the bright face's centre.
                    let toward = (0..4000)
                        .map(|i| {
                            let (y, phi) = (1.0 - 2.0 * (i as f32 + 0.5) / 4000.0, i as f32 * 2.399_963);
                            let r = (1.0 - y * y).sqrt();
                            Vec3::new(r * phi.cos(), y, r * phi.sin())
                        })
                        .filter(|&d| bevy_face(rotation, d) == bright)
                        .fold(Vec3::ZERO, |sum, d| sum + d)
                        .normalize();
                    let brightest = axes
                        .iter()
                        .map(|&n| rotation * n)
                        .max_by(|a, b| world.sh.irradiance(*a).x.total_cmp(&world.sh.irradiance(*b).x))
                        .unwrap();
                    assert!(
                        brightest.distance(toward) < 0.05,
                        "{format:?}, face {bright}, turned {rotation}: brightest toward {brightest}, Bevy's {toward}"
                    );
                }
            }
        }
    }

    #[test]
    fn images_that_are_not_readable_cube_maps_are_errors_naming_the_problem() {
        let half = |_: f32| vec![0u8; 8];
        let mut flat = cube_image(TextureFormat::Rgba16Float, &half, 0, 1);
        flat.texture_descriptor.size.depth_or_array_layers = 1;
        assert!(cube_environment(&flat).unwrap_err().contains("six square layers"));
        let mut gpu_only = cube_image(TextureFormat::Rgba16Float, &half, 0, 1);
        gpu_only.data = None;
        assert!(cube_environment(&gpu_only).unwrap_err().contains("RENDER_WORLD"));
        let mut short = cube_image(TextureFormat::Rgba16Float, &half, 0, 1);
        short.data.as_mut().unwrap().truncate(10);
        assert!(cube_environment(&short).unwrap_err().contains("10 bytes"));
        let mut compressed = cube_image(TextureFormat::Rgba16Float, &half, 0, 1);
        compressed.texture_descriptor.format = TextureFormat::Bc6hRgbUfloat;
        assert!(cube_environment(&compressed).unwrap_err().contains("Bc6hRgbUfloat"));
        let mut nan = cube_image(TextureFormat::Rgba16Float, &half, 0, 1);
        nan.data.as_mut().unwrap()[0..2].copy_from_slice(&0x7e00u16.to_le_bytes());
        assert!(cube_environment(&nan).unwrap_err().contains("not finite"));
    }
}
