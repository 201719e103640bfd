//! Meshes drawn without fur (e.g. the body under a furry garment), lit like the fur's skin.

use glam::{Mat4, Vec3};
use pelt_core::Mesh;

use crate::RenderError;
use crate::geometry::UnifiedGeometry;
use crate::object::{FurFrame, GpuBytes};
use crate::requirements::ErrorScope;
use crate::shaders::Layouts;
use crate::textures::TextureShape;

/// A furless mesh on the GPU, drawn with [`FurRenderer::draw_plain`](crate::FurRenderer::draw_plain)
/// before the furs.
#[derive(Debug)]
pub struct PlainMesh {
    geometry: UnifiedGeometry,
    colour: Vec3,
}

impl PlainMesh {
    /// [`PlainMesh::new`] with the renderer's layouts.
    pub(crate) fn upload(
        device: &wgpu::Device,
        layouts: &Layouts,
        mesh: &Mesh,
        colour: Vec3,
    ) -> Result<Self, RenderError> {
        let scope = ErrorScope::push(device);
        let geometry = UnifiedGeometry::new(device, layouts, (mesh, None, None), 0, &mesh.positions, 1);
        scope.pop("uploading a plain mesh")?;
        Ok(Self { geometry: geometry?, colour })
    }

    /// Writes this frame's model transform (takes effect at the next submission).
    pub fn prepare(&self, queue: &wgpu::Queue, world_from_model: Mat4) {
        let frame = FurFrame { world_from_model, ..FurFrame::default() };
        self.geometry.write_uniform(
            queue,
            &self.geometry.shape.uniform(&frame, self.colour, TextureShape::default()),
            0,
        );
    }

    /// Moves the mesh's vertices (a skinned body's pose this frame, in model space).
    ///
    /// # Errors
    /// [`RenderError::Count`] when `positions` or `normals` has another length than the mesh.
    pub fn set_pose(&self, queue: &wgpu::Queue, positions: &[Vec3], normals: &[Vec3]) -> Result<(), RenderError> {
        self.geometry.set_positions(queue, positions)?;
        self.geometry.set_normals(queue, normals)
    }

    /// Bytes the mesh holds on the GPU.
    #[must_use]
    pub fn gpu_bytes(&self) -> GpuBytes {
        self.geometry.bytes()
    }

    pub(crate) fn geometry(&self) -> &UnifiedGeometry {
        &self.geometry
    }
}
