//! The separated structure of Lengyel et al. 2001, drawn on the same scene as the unified one
//! for side-by-side comparisons: shells as `(L + 1) * V` full vertices (position, normal, uv;
//! 32 bytes each) reused by one index buffer with a base-vertex offset per layer, and fins as
//! geometry of their own, `N` faces per fin, built once on the CPU (they do not bend).
//!
//! Each fin is a strip of `N / 2` quads up the rest strands with vertices of its own (they carry
//! the fin's plane normal for Lengyel's fade and uvs along the fin), stored as a plain triangle
//! list: 6 vertices a quad. (The paper counts `N` vertices a fin, sharing strip vertices; the
//! drawn cost is the same.)

use glam::{Vec2, Vec3};
use pelt_core::FurStructure;
use pelt_core::fur::SEPARATED_VERTEX_BYTES;
use pelt_core::texture::FurTextures;
use wgpu::util::DeviceExt as _;

use crate::RenderError;
use crate::camera::Camera;
use crate::renderer::{
    ErrorScope, PassKind, RenderSettings, Renderer, SHADING_WGSL, Transparency, begin_pass, create_pipeline,
    layout_entry, world_per_uv,
};
use crate::targets::{RenderTargets, TargetFormat};

const SEPARATED_WGSL: &str = include_str!("separated.wgsl");

/// The WGSL module of the separated renderer (the shared shading plus `separated.wgsl`).
#[must_use]
pub fn separated_shader_source() -> String {
    format!("{SHADING_WGSL}\n{SEPARATED_WGSL}")
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct Vertex {
    position: Vec3,
    normal: Vec3,
    uv: Vec2,
}
const _: () = assert!(size_of::<Vertex>() as u64 == SEPARATED_VERTEX_BYTES, "Footprint counts 32-byte vertices");

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct SeparatedUniform {
    tiles_per_world: f32,
    layers: u32,
    shell_slices: u32,
    has_uvs: u32,
    world_per_uv: f32,
    _padding: [u32; 3],
}
const _: () = assert!(size_of::<SeparatedUniform>() == 32, "matches `Separated` in separated.wgsl");

/// Draws the separated structure with the unified renderer's textures, globals and skin.
#[derive(Debug)]
pub struct SeparatedRenderer {
    /// Supplies the globals, textures and the skin pass.
    unified: Renderer,
    uniform: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    shell_vertices: wgpu::Buffer,
    shell_indices: wgpu::Buffer,
    fin_vertices: wgpu::Buffer,
    fin_vertex_count: u32,
    shells: [wgpu::RenderPipeline; 2],
    fins: [wgpu::RenderPipeline; 2],
    vertex_count: u32,
    index_count: u32,
    layers: u32,
    has_uvs: bool,
    world_per_uv: f32,
    radius: f32,
    shell_slices: u32,
    gpu_bytes: u64,
}

impl SeparatedRenderer {
    /// Builds the separated buffers for the rest pose of `fur`, with `fin_faces` faces per fin
    /// (2 as Lengyel, or `N`; rounded up to even).
    ///
    /// # Errors
    /// As [`Renderer::new`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: TargetFormat,
        fur: &FurStructure,
        textures: &FurTextures,
        fin_faces: u32,
    ) -> Result<Self, RenderError> {
        let unified = Renderer::new(device, queue, format, fur, textures)?;
        let scope = ErrorScope::push(device);
        let mesh = &fur.mesh;
        let v = mesh.vertex_count();
        let world_per_uv = world_per_uv(mesh);
        // One uv per vertex (the first corner that uses it): the separated structure has no
        // per-corner data, so uv seams stretch here and only here.
        let mut vertex_uvs = vec![Vec2::ZERO; v];
        if let Some(uvs) = &mesh.corner_uvs {
            for (triangle, corner_uvs) in mesh.triangles.iter().zip(uvs).rev() {
                for (&j, uv) in triangle.iter().zip(corner_uvs) {
                    vertex_uvs[j as usize] = *uv * world_per_uv;
                }
            }
        }
        let mut shell = Vec::with_capacity(fur.positions.len());
        for layer in 0..=fur.layers {
            let start = fur.index(layer, 0) as usize;
            for ((position, normal), uv) in fur.positions[start..start + v].iter().zip(&fur.directions).zip(&vertex_uvs)
            {
                shell.push(Vertex { position: *position, normal: *normal, uv: *uv });
            }
        }
        let quads_per_fin = fin_faces.max(2).div_ceil(2);
        let mut fin = Vec::with_capacity(mesh.edges.len() * 6 * quads_per_fin as usize);
        for &[a, b] in &mesh.edges {
            let (a, b) = (a as usize, b as usize);
            let root = |j: usize| fur.positions[j];
            let tip = |j: usize| fur.positions[fur.index(fur.layers, j as u32) as usize];
            let along = root(b) - root(a);
            let up = (tip(a) - root(a) + tip(b) - root(b)) * 0.5;
            let normal = along.cross(up).normalize_or(fur.directions[a]);
            let u_b = along.length();
            let point = |side: usize, t: f32| {
                let j = if side == 0 { a } else { b };
                let position = root(j).lerp(tip(j), t);
                Vertex { position, normal, uv: Vec2::new(if side == 0 { 0.0 } else { u_b }, t) }
            };
            for q in 0..quads_per_fin {
                let (t0, t1) = (q as f32 / quads_per_fin as f32, (q + 1) as f32 / quads_per_fin as f32);
                fin.extend([point(0, t0), point(1, t0), point(1, t1), point(0, t0), point(1, t1), point(0, t1)]);
            }
        }
        let limit = device.limits().max_buffer_size;
        for (what, bytes) in [("separated shells", shell.len() as u64 * 32), ("separated fins", fin.len() as u64 * 32)]
        {
            if bytes > limit {
                return Err(RenderError::TooLarge { what, bytes, limit });
            }
        }
        let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let buffer = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor { label: Some(label), contents, usage })
        };
        let shell_vertices = buffer("pelt separated shells", bytemuck::cast_slice(&shell), wgpu::BufferUsages::VERTEX);
        let shell_indices = buffer("pelt separated indices", bytemuck::cast_slice(&indices), wgpu::BufferUsages::INDEX);
        let fin_vertices = buffer("pelt separated fins", bytemuck::cast_slice(&fin), wgpu::BufferUsages::VERTEX);
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt separated"),
            size: size_of::<SeparatedUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt separated"),
            entries: &[layout_entry(
                0,
                wgpu::BindingType::Buffer {
                    ty: wgpu::BufferBindingType::Uniform,
                    has_dynamic_offset: false,
                    min_binding_size: None,
                },
            )],
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt separated"),
            layout: &layout,
            entries: &[wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() }],
        });
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pelt separated"),
            source: wgpu::ShaderSource::Wgsl(separated_shader_source().into()),
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pelt separated"),
            bind_group_layouts: &[Some(unified.globals_layout()), Some(&layout)],
            immediate_size: 0,
        });
        let vertex_layout = [Some(wgpu::VertexBufferLayout {
            array_stride: SEPARATED_VERTEX_BYTES,
            step_mode: wgpu::VertexStepMode::Vertex,
            attributes: &wgpu::vertex_attr_array![0 => Float32x3, 1 => Float32x3, 2 => Float32x2],
        })];
        let build = |label, entries, kind| {
            create_pipeline(device, &pipeline_layout, &module, format, label, entries, kind, &vertex_layout)
        };
        let shell_entries = ("vs_separated_shell", "fs_shell");
        let fin_entries = ("vs_separated_fin", "fs_separated_fin");
        let shells = [
            build("pelt separated shells", shell_entries, PassKind::Shells(Transparency::Blend)),
            build("pelt separated shells a2c", shell_entries, PassKind::Shells(Transparency::Coverage)),
        ];
        let fins = [
            build("pelt separated fins", fin_entries, PassKind::Fins(Transparency::Blend)),
            build("pelt separated fins a2c", fin_entries, PassKind::Fins(Transparency::Coverage)),
        ];
        scope.pop("uploading the separated structure")?;
        let gpu_bytes = (shell.len() + fin.len()) as u64 * SEPARATED_VERTEX_BYTES + indices.len() as u64 * 4;
        Ok(Self {
            unified,
            uniform,
            bind_group,
            shell_vertices,
            shell_indices,
            fin_vertices,
            fin_vertex_count: fin.len() as u32,
            shells,
            fins,
            vertex_count: v as u32,
            index_count: indices.len() as u32,
            layers: fur.layers,
            has_uvs: mesh.corner_uvs.is_some(),
            world_per_uv,
            radius: mesh.bounding_sphere().1.max(1e-6),
            shell_slices: textures.layers,
            gpu_bytes,
        })
    }

    /// Adds a mesh drawn without fur (e.g. the body under a furred garment), as
    /// [`Renderer::add_plain_mesh`], so both structures can draw the same scene.
    ///
    /// # Errors
    /// As [`Renderer::add_plain_mesh`].
    pub fn add_plain_mesh(
        &mut self,
        device: &wgpu::Device,
        mesh: &pelt_core::Mesh,
        colour: Vec3,
    ) -> Result<(), RenderError> {
        self.unified.add_plain_mesh(device, mesh, colour)
    }

    /// Bytes of the separated geometry on the GPU (shell and fin vertices, shell indices).
    #[must_use]
    pub fn gpu_bytes(&self) -> u64 {
        self.gpu_bytes
    }

    /// Records one frame, like [`Renderer::render`].
    pub fn render(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        targets: &RenderTargets,
        output: &wgpu::TextureView,
        camera: &Camera,
        settings: &RenderSettings,
    ) {
        let tiles_per_world = settings.tiles_per_radius / self.radius;
        let uniform = SeparatedUniform {
            tiles_per_world,
            layers: self.layers,
            shell_slices: self.shell_slices,
            has_uvs: u32::from(self.has_uvs),
            world_per_uv: self.world_per_uv,
            _padding: [0; 3],
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
        // The unified renderer draws the skin (and plain meshes) and sets the globals.
        self.unified.prepare(queue, camera, targets.aspect_ratio(), settings);
        let mut pass = begin_pass(encoder, targets, output, settings);
        self.unified.draw(&mut pass, &RenderSettings { shells: false, fins: false, ..settings.clone() });
        let which = usize::from(settings.alpha_to_coverage);
        pass.set_bind_group(0, self.unified.globals_bind_group(), &[]);
        pass.set_bind_group(1, &self.bind_group, &[]);
        if settings.shells {
            pass.set_pipeline(&self.shells[which]);
            pass.set_vertex_buffer(0, self.shell_vertices.slice(..));
            pass.set_index_buffer(self.shell_indices.slice(..), wgpu::IndexFormat::Uint32);
            for layer in 1..=self.layers {
                pass.draw_indexed(0..self.index_count, (layer * self.vertex_count) as i32, layer..layer + 1);
            }
        }
        if settings.fins {
            pass.set_pipeline(&self.fins[which]);
            pass.set_vertex_buffer(0, self.fin_vertices.slice(..));
            pass.draw(0..self.fin_vertex_count, 0..1);
        }
    }
}
