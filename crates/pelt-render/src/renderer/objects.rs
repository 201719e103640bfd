//! The constructors of what a [`FurRenderer`] draws ([`GpuFur`], [`PlainMesh`], [`FurView`]).
//! Each takes the renderer for its bind group layouts; they live here, with the renderer, because
//! the renderer sits above the data it draws (the types themselves know only the layouts).

use pelt_core::texture::FurTextures;
use pelt_core::{FurStructure, Mesh};

use super::FurRenderer;
use crate::RenderError;
use crate::asset::FurAsset;
use crate::fur::{FurStates, GpuFur};
use crate::plain::PlainMesh;
use crate::view::FurView;

impl GpuFur {
    /// Uploads `structure` (its rest pose into every state) and `textures` for drawing with
    /// `renderer`.
    ///
    /// # Errors
    /// [`RenderError::TooLarge`] when the structure exceeds the device's buffer limits,
    /// [`RenderError::Textures`] for malformed textures, [`RenderError::OutOfMemory`] or
    /// [`RenderError::Gpu`] where the device reports one.
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        structure: &FurStructure,
        textures: &FurTextures,
        states: FurStates,
    ) -> Result<Self, RenderError> {
        Self::upload(device, queue, renderer.layouts(), structure, textures, states)
    }

    /// One more copy of `asset`'s fur, at its rest pose: its own states, normals, wetness and
    /// uniform; the topology, uvs, fin strip, groom attributes and textures are the asset's
    /// (a groom painted with [`GpuFur::set_groom`] on any copy shows on all).
    ///
    /// # Errors
    /// As [`GpuFur::new`].
    pub fn from_asset(
        device: &wgpu::Device,
        renderer: &FurRenderer,
        asset: &FurAsset,
        states: FurStates,
    ) -> Result<Self, RenderError> {
        Self::instance(device, renderer.layouts(), asset, states)
    }

    /// `count` more copies of `asset`'s fur, as [`GpuFur::from_asset`] makes
    /// one, made together: their own state shares a few buffers (a pool as large as the device
    /// binds), so [`FurRenderer::prepare_fins_of`] lists them in a few dispatches, not a few a
    /// copy.
    ///
    /// # Errors
    /// As [`GpuFur::new`].
    pub fn herd_from_asset(
        device: &wgpu::Device,
        renderer: &FurRenderer,
        asset: &FurAsset,
        states: FurStates,
        count: usize,
    ) -> Result<Vec<Self>, RenderError> {
        Self::copies(device, renderer.layouts(), asset, states, count)
    }

    /// Replaces the structure (new mesh, layer count or rest pose), keeping the textures and the
    /// number of states; the fur leaves its asset for one of its own.
    ///
    /// # Errors
    /// As [`GpuFur::new`].
    pub fn set_structure(
        &mut self,
        device: &wgpu::Device,
        renderer: &FurRenderer,
        structure: &FurStructure,
    ) -> Result<(), RenderError> {
        self.upload_structure(device, renderer.layouts(), structure)
    }

    /// Replaces the shell and fin textures (any slice count: slices are spread over the layers).
    ///
    /// # Errors
    /// [`RenderError::Textures`] for malformed textures, [`RenderError::OutOfMemory`].
    pub fn set_textures(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        textures: &FurTextures,
    ) -> Result<(), RenderError> {
        self.upload_textures(device, queue, renderer.layouts(), textures)
    }
}

impl FurAsset {
    /// Uploads what every copy of `structure` with `textures` shares, once.
    ///
    /// # Errors
    /// As [`GpuFur::new`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        renderer: &FurRenderer,
        structure: &FurStructure,
        textures: &FurTextures,
    ) -> Result<Self, RenderError> {
        Self::upload(device, queue, renderer.layouts(), structure, textures)
    }
}

impl PlainMesh {
    /// Uploads `mesh`, drawn in linear RGB `colour`.
    ///
    /// # Errors
    /// [`RenderError::TooLarge`] when the mesh exceeds the device's buffer limits,
    /// [`RenderError::OutOfMemory`] or [`RenderError::Gpu`].
    pub fn new(
        device: &wgpu::Device,
        renderer: &FurRenderer,
        mesh: &Mesh,
        colour: glam::Vec3,
    ) -> Result<Self, RenderError> {
        Self::upload(device, renderer.layouts(), mesh, colour)
    }
}

impl FurView {
    /// A view for passes drawn with `renderer` (or a `SeparatedRenderer` made from it).
    #[must_use]
    pub fn new(device: &wgpu::Device, renderer: &FurRenderer) -> Self {
        Self::create(device, renderer.layouts())
    }
}
