//! [`FurAsset`]: what every copy of one fur shares on the GPU, uploaded once: the topology, the
//! wedges' uvs, the fin strip, the groom's attributes and the textures. Each [`GpuFur`] made
//! from it (`GpuFur::from_asset`) adds only its own state: the shared array's states, base
//! normals, wetness, object uniform and the per-view fin and shell lists.
//!
//! [`GpuFur`]: crate::GpuFur

use std::sync::{Arc, OnceLock};

use glam::Vec3;
use pelt_core::FurStructure;
use pelt_core::texture::FurTextures;

use crate::RenderError;
use crate::geometry::{Furred, SharedGeometry};
use crate::object::GpuBytes;
use crate::requirements::ErrorScope;
use crate::shaders::Layouts;
use crate::textures::GpuTextures;

/// One fur's shared GPU data, for any number of copies of it (a herd): a hundred Foxes of one
/// mesh and preset upload their topology and textures once. Cloning it clones handles.
///
/// Made with [`FurAsset::new`]; each copy is a [`GpuFur`](crate::GpuFur) from
/// [`GpuFur::from_asset`](crate::GpuFur::from_asset) (or a [`FurDriver`](crate::FurDriver) from
/// [`FurDriver::with_asset`](crate::FurDriver::with_asset)), drawn, posed and simulated on its own.
#[derive(Clone, Debug)]
pub struct FurAsset {
    pub(crate) geometry: SharedGeometry,
    pub(crate) textures: GpuTextures,
    /// The rest pose every copy starts from: `(L + 1) * V` positions and `V` normals.
    pub(crate) rest: Arc<(Vec<Vec3>, Vec<Vec3>)>,
    /// The GPU simulation's rest segments of this structure, made by the first copy simulated
    /// on the GPU, shared by every copy grown the same.
    pub(crate) simulation_rest: Arc<OnceLock<wgpu::Buffer>>,
}

impl FurAsset {
    /// Uploads what the copies of `structure` with `textures` share.
    pub(crate) fn upload(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        layouts: &Layouts,
        structure: &FurStructure,
        textures: &FurTextures,
    ) -> Result<Self, RenderError> {
        let scope = ErrorScope::push(device);
        let furred = Furred::of(structure);
        let geometry =
            SharedGeometry::new(device, (&structure.mesh, furred.as_ref(), structure.groom.as_ref()), structure.layers);
        let textures = GpuTextures::new(device, queue, layouts, textures, structure.groom.is_some());
        scope.pop("uploading the fur")?;
        Ok(Self::from_parts(geometry?, textures?, structure))
    }

    /// The asset of `structure` from its uploaded parts.
    pub(crate) fn from_parts(geometry: SharedGeometry, textures: GpuTextures, structure: &FurStructure) -> Self {
        Self {
            geometry,
            textures,
            rest: Arc::new((structure.positions.clone(), structure.mesh.normals.clone())),
            simulation_rest: Arc::default(),
        }
    }

    /// The same geometry with other textures: a new asset (the old one's copies keep theirs).
    pub(crate) fn with_textures(&self, textures: GpuTextures) -> Self {
        Self { textures, rest: Arc::new((*self.rest).clone()), ..self.clone() }
    }

    /// Bytes uploaded once for every copy: the uvs, topology, fin strip and textures (the
    /// groom's attributes and keep values are [`GpuFur::groom_bytes`](crate::GpuFur::groom_bytes)),
    /// and once a copy simulates on the GPU, its rest segments (in `positions`).
    #[must_use]
    pub fn gpu_bytes(&self) -> GpuBytes {
        let geometry = self.geometry.bytes();
        let rest = self.simulation_rest.get().map_or(0, wgpu::Buffer::size);
        GpuBytes {
            textures: self.textures.bytes + self.textures.tilt_bytes(),
            positions: geometry.positions + rest,
            ..geometry
        }
    }

    /// Whether `structure` is the one this asset was uploaded from (its copies may share the
    /// GPU simulation's rest segments), not a copy grown to another length.
    pub(crate) fn grown_as(&self, structure: &FurStructure) -> bool {
        self.rest.0 == structure.positions
    }

    /// `L`, the shell layers above the base.
    #[must_use]
    pub fn layers(&self) -> u32 {
        self.geometry.shape.layers
    }

    /// `V`, the base vertices (strands).
    #[must_use]
    pub fn vertex_count(&self) -> u32 {
        self.geometry.shape.vertex_count
    }

    /// Whether `other` is this asset or a clone of it (the same buffers and textures).
    #[must_use]
    pub fn shares_with(&self, other: &Self) -> bool {
        Arc::ptr_eq(&self.rest, &other.rest)
    }
}
