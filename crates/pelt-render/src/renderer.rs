//! The unified renderer: one shared vertex array on the GPU, shells and fins drawn from it.
//!
//! Per frame the caller uploads the simulated positions (`(L + 1) * V` of them) with
//! [`Renderer::update_positions`]; everything else is static. Draws, in order:
//! 1. plain meshes (no fur) and the opaque skin (layer 0, coloured like the roots);
//! 2. shells, instanced per layer from the innermost out, over the same `3F` triangle corners,
//!    alpha-blended with depth test on and depth writes off (or alpha-to-coverage), faded where
//!    the surface turns edge-on;
//! 3. fins, instanced per edge over one shared strip of `6L` indices, faded in near the silhouette.

use glam::{Mat4, Vec2, Vec3, Vec4};
use pelt_core::mesh::Mesh;
use pelt_core::texture::FurTextures;
use pelt_core::{FurStructure, fur::POSITION_BYTES};
use wgpu::util::DeviceExt as _;

use crate::RenderError;
use crate::camera::Camera;
use crate::targets::{DEPTH_FORMAT, RenderTargets, TargetFormat};
use crate::textures::GpuTextures;

pub(crate) const SHADING_WGSL: &str = include_str!("shading.wgsl");
pub(crate) const UNIFIED_WGSL: &str = include_str!("unified.wgsl");

/// The WGSL module of the unified renderer (the shared shading plus `unified.wgsl`).
#[must_use]
pub fn unified_shader_source() -> String {
    format!("{SHADING_WGSL}\n{UNIFIED_WGSL}")
}

/// How a frame looks; everything here can change every frame.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderSettings {
    /// Draw the opaque skin under the fur.
    pub skin: bool,
    pub shells: bool,
    pub fins: bool,
    /// Shells and fins with alpha-to-coverage (order independent, writes depth) instead of
    /// blending. Needs MSAA.
    pub alpha_to_coverage: bool,
    /// Unit vector toward the key light in view space (x right, y up, z toward the viewer), so
    /// the light follows the camera.
    pub light_from_view: Vec3,
    /// Linear RGB.
    pub light_colour: Vec3,
    pub ambient: f32,
    pub specular: f32,
    /// Kajiya-Kay specular exponent.
    pub shininess: f32,
    /// Brightness left at the roots (1 = no darkening toward the roots).
    pub root_occlusion: f32,
    /// Fins are fully shown where the faces beside the edge turn below this |cos| to the view.
    pub fin_fade_cos: f32,
    /// Shells fade where the surface turns below this |cos| to the view.
    pub shell_fade_cos: f32,
    /// Shell texture tiles across the mesh's bounding radius, so strands have the same density
    /// relative to the mesh whatever its size. (A larger tile holds more, finer strands: the
    /// texture's resolution sets how fine the fur is, as in the paper's "resizing".)
    pub tiles_per_radius: f32,
    /// Linear RGB clear colour.
    pub background: Vec3,
}

impl Default for RenderSettings {
    fn default() -> Self {
        Self {
            skin: true,
            shells: true,
            fins: true,
            alpha_to_coverage: false,
            light_from_view: Vec3::new(-0.45, 0.65, 0.6).normalize(),
            light_colour: Vec3::splat(1.0),
            ambient: 0.25,
            specular: 0.2,
            shininess: 40.0,
            root_occlusion: 0.3,
            fin_fade_cos: 0.1,
            shell_fade_cos: 0.25,
            tiles_per_radius: 0.4,
            background: Vec3::new(0.045, 0.05, 0.06),
        }
    }
}

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct GlobalsUniform {
    clip_from_world: Mat4,
    camera_position: Vec3,
    alpha_to_coverage: u32,
    light_direction: Vec3,
    ambient: f32,
    light_colour: Vec3,
    specular: f32,
    root_colour: Vec4,
    fin_fade_cos: f32,
    shell_fade_cos: f32,
    root_occlusion: f32,
    shininess: f32,
    has_surface: u32,
    _padding: [u32; 3],
}
const _: () = assert!(size_of::<GlobalsUniform>() == 160, "matches `Globals` in shading.wgsl");

#[repr(C)]
#[derive(Clone, Copy, Debug, bytemuck::Pod, bytemuck::Zeroable)]
struct ObjectUniform {
    colour: Vec4,
    vertex_count: u32,
    layers: u32,
    triangle_count: u32,
    edge_count: u32,
    has_uvs: u32,
    tiles_per_uv: f32,
    tiles_per_world: f32,
    shell_slices: u32,
}
const _: () = assert!(size_of::<ObjectUniform>() == 48, "matches `Object` in unified.wgsl");

/// One mesh on the GPU in the unified layout: shared positions, rest normals, corner uvs and
/// topology (triangles, edges, edge faces) as storage buffers.
#[derive(Debug)]
struct GpuObject {
    uniform: wgpu::Buffer,
    /// The fin strip of one edge (`6L` indices into `2(L + 1)` strip vertices), shared by all
    /// edges: indexed, each strip vertex is shaded once however many triangles use it.
    fin_indices: wgpu::Buffer,
    positions: wgpu::Buffer,
    topology: wgpu::Buffer,
    bind_group: wgpu::BindGroup,
    vertex_count: u32,
    layers: u32,
    triangle_count: u32,
    edge_count: u32,
    has_uvs: bool,
    /// World units per uv unit (sqrt of surface area over uv area): uv tiles match world tiles.
    world_per_uv: f32,
    radius: f32,
    colour: Vec3,
}

impl GpuObject {
    fn new(
        device: &wgpu::Device,
        layout: &wgpu::BindGroupLayout,
        mesh: &Mesh,
        layers: u32,
        positions: &[Vec3],
        colour: Vec3,
    ) -> Result<Self, RenderError> {
        let limit = device.limits().max_storage_buffer_binding_size.min(device.limits().max_buffer_size);
        let check = |what, bytes: u64| {
            if bytes > limit { Err(RenderError::TooLarge { what, bytes, limit }) } else { Ok(()) }
        };
        check("shared vertex array", positions.len() as u64 * POSITION_BYTES)?;
        let mut topology: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        topology.extend(mesh.edges.iter().flatten());
        topology.extend(mesh.edge_faces.iter().flatten());
        check("mesh topology", topology.len() as u64 * 4)?;
        let corner_uvs: Vec<Vec2> = match &mesh.corner_uvs {
            Some(uvs) => uvs.iter().flatten().copied().collect(),
            None => vec![Vec2::ZERO],
        };
        check("mesh uvs", corner_uvs.len() as u64 * 8)?;

        let storage = |label, contents: &[u8], usage| {
            device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
                label: Some(label),
                contents,
                usage: wgpu::BufferUsages::STORAGE | usage,
            })
        };
        let positions = storage("pelt shared vertices", bytemuck::cast_slice(positions), wgpu::BufferUsages::COPY_DST);
        let normals = storage("pelt rest normals", bytemuck::cast_slice(&mesh.normals), wgpu::BufferUsages::empty());
        let uvs = storage("pelt corner uvs", bytemuck::cast_slice(&corner_uvs), wgpu::BufferUsages::empty());
        // Also the index buffer of the base triangles for meshes without uvs.
        let topology = storage("pelt topology", bytemuck::cast_slice(&topology), wgpu::BufferUsages::INDEX);
        let strip: Vec<u32> = (0..layers.max(1))
            .flat_map(|i| {
                let (a, b, a_up, b_up) = (2 * i, 2 * i + 1, 2 * i + 2, 2 * i + 3);
                [a, b, b_up, a, b_up, a_up]
            })
            .collect();
        let fin_indices = device.create_buffer_init(&wgpu::util::BufferInitDescriptor {
            label: Some("pelt fin strip"),
            contents: bytemuck::cast_slice(&strip),
            usage: wgpu::BufferUsages::INDEX,
        });
        let uniform = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt object"),
            size: size_of::<ObjectUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let bind_group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("pelt object"),
            layout,
            entries: &[
                wgpu::BindGroupEntry { binding: 0, resource: uniform.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 1, resource: positions.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 2, resource: normals.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 3, resource: uvs.as_entire_binding() },
                wgpu::BindGroupEntry { binding: 4, resource: topology.as_entire_binding() },
            ],
        });
        Ok(Self {
            uniform,
            fin_indices,
            positions,
            topology,
            bind_group,
            vertex_count: mesh.vertex_count() as u32,
            layers,
            triangle_count: mesh.triangles.len() as u32,
            edge_count: mesh.edges.len() as u32,
            has_uvs: mesh.corner_uvs.is_some(),
            world_per_uv: world_per_uv(mesh),
            radius: mesh.bounding_sphere().1.max(1e-6),
            colour,
        })
    }

    /// Draws the base triangles (`instances` = layers): by corner with uvs, else indexed.
    fn draw_surface(&self, pass: &mut wgpu::RenderPass<'_>, instances: std::ops::Range<u32>) {
        if self.has_uvs {
            pass.draw(0..3 * self.triangle_count, instances);
        } else {
            // The topology buffer starts with the base triangles.
            pass.set_index_buffer(
                self.topology.slice(..u64::from(self.triangle_count) * 12),
                wgpu::IndexFormat::Uint32,
            );
            pass.draw_indexed(0..3 * self.triangle_count, 0, instances);
        }
    }

    fn write_uniform(&self, queue: &wgpu::Queue, tiles_per_radius: f32, shell_slices: u32) {
        let tiles_per_world = tiles_per_radius / self.radius;
        let uniform = ObjectUniform {
            colour: self.colour.extend(1.0),
            vertex_count: self.vertex_count,
            layers: self.layers,
            triangle_count: self.triangle_count,
            edge_count: self.edge_count,
            has_uvs: u32::from(self.has_uvs),
            tiles_per_uv: tiles_per_world * self.world_per_uv,
            tiles_per_world,
            shell_slices,
        };
        queue.write_buffer(&self.uniform, 0, bytemuck::bytes_of(&uniform));
    }
}

impl Pipelines {
    fn surface(&self, object: &GpuObject) -> &SurfacePipelines {
        if object.has_uvs { &self.corners } else { &self.indexed }
    }
}

/// sqrt(surface area / uv area), or 1 without uvs.
pub(crate) fn world_per_uv(mesh: &Mesh) -> f32 {
    let Some(uvs) = &mesh.corner_uvs else { return 1.0 };
    let uv_area: f32 = uvs.iter().map(|[a, b, c]| (*b - *a).perp_dot(*c - *a).abs() * 0.5).sum();
    if uv_area > 1e-12 { (mesh.surface_area() / uv_area).sqrt() } else { 1.0 }
}

/// Pipelines for one way of walking the base triangles (see `unified.wgsl`).
#[derive(Debug)]
struct SurfacePipelines {
    plain: wgpu::RenderPipeline,
    skin: wgpu::RenderPipeline,
    shells_blended: wgpu::RenderPipeline,
    shells_coverage: wgpu::RenderPipeline,
}

#[derive(Debug)]
struct Pipelines {
    /// Meshes with uvs: non-indexed over the triangle corners.
    corners: SurfacePipelines,
    /// Meshes without uvs: indexed by the base triangles.
    indexed: SurfacePipelines,
    fins_blended: wgpu::RenderPipeline,
    fins_coverage: wgpu::RenderPipeline,
}

/// Draws one furry mesh (the unified structure) plus any plain meshes into a view.
///
/// Works with any colour format and target: a window's surface or [`crate::Headless`]'s texture.
#[derive(Debug)]
pub struct Renderer {
    format: TargetFormat,
    globals: wgpu::Buffer,
    globals_layout: wgpu::BindGroupLayout,
    object_layout: wgpu::BindGroupLayout,
    globals_bind_group: wgpu::BindGroup,
    shell_sampler: wgpu::Sampler,
    fin_sampler: wgpu::Sampler,
    pipelines: Pipelines,
    textures: GpuTextures,
    fur: GpuObject,
    plain: Vec<GpuObject>,
}

impl Renderer {
    /// Uploads `fur` (its rest pose) and `textures` and builds the pipelines for `format`.
    ///
    /// # Errors
    /// [`RenderError::TooLarge`] when the structure exceeds the device's buffer limits,
    /// [`RenderError::Textures`] for malformed textures, [`RenderError::OutOfMemory`].
    pub fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        format: TargetFormat,
        fur: &FurStructure,
        textures: &FurTextures,
    ) -> Result<Self, RenderError> {
        let scope = ErrorScope::push(device);
        let globals_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt globals"),
            entries: &[
                layout_entry(
                    0,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                layout_entry(1, texture_binding(wgpu::TextureViewDimension::D2Array)),
                layout_entry(2, texture_binding(wgpu::TextureViewDimension::D2)),
                layout_entry(3, wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering)),
                layout_entry(4, wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering)),
                layout_entry(5, texture_binding(wgpu::TextureViewDimension::D2)),
            ],
        });
        let storage = wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only: true },
            has_dynamic_offset: false,
            min_binding_size: None,
        };
        let object_layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("pelt object"),
            entries: &[
                layout_entry(
                    0,
                    wgpu::BindingType::Buffer {
                        ty: wgpu::BufferBindingType::Uniform,
                        has_dynamic_offset: false,
                        min_binding_size: None,
                    },
                ),
                layout_entry(1, storage),
                layout_entry(2, storage),
                layout_entry(3, storage),
                layout_entry(4, storage),
            ],
        });
        let globals = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("pelt globals"),
            size: size_of::<GlobalsUniform>() as u64,
            usage: wgpu::BufferUsages::UNIFORM | wgpu::BufferUsages::COPY_DST,
            mapped_at_creation: false,
        });
        let sampler = |label, v_mode| {
            device.create_sampler(&wgpu::SamplerDescriptor {
                label: Some(label),
                address_mode_u: wgpu::AddressMode::Repeat,
                address_mode_v: v_mode,
                mag_filter: wgpu::FilterMode::Linear,
                min_filter: wgpu::FilterMode::Linear,
                mipmap_filter: wgpu::MipmapFilterMode::Linear,
                ..wgpu::SamplerDescriptor::default()
            })
        };
        let shell_sampler = sampler("pelt shell sampler", wgpu::AddressMode::Repeat);
        // Fins do not wrap from the tips back to the roots.
        let fin_sampler = sampler("pelt fin sampler", wgpu::AddressMode::ClampToEdge);
        let textures = GpuTextures::new(device, queue, textures)?;
        let globals_bind_group =
            globals_bind_group(device, &globals_layout, &globals, &textures, &shell_sampler, &fin_sampler);
        let pipelines = Pipelines::new(device, format, &globals_layout, &object_layout);
        let fur = GpuObject::new(device, &object_layout, &fur.mesh, fur.layers, &fur.positions, Vec3::ONE)?;
        scope.pop("uploading the fur")?;
        Ok(Self {
            format,
            globals,
            globals_layout,
            object_layout,
            globals_bind_group,
            shell_sampler,
            fin_sampler,
            pipelines,
            textures,
            fur,
            plain: Vec::new(),
        })
    }

    /// The target format the pipelines were built for.
    #[must_use]
    pub fn format(&self) -> TargetFormat {
        self.format
    }

    /// Replaces the furry structure (new mesh, layer count or rest pose).
    ///
    /// # Errors
    /// As [`Renderer::new`].
    pub fn set_structure(&mut self, device: &wgpu::Device, fur: &FurStructure) -> Result<(), RenderError> {
        let scope = ErrorScope::push(device);
        let object = GpuObject::new(device, &self.object_layout, &fur.mesh, fur.layers, &fur.positions, Vec3::ONE)?;
        scope.pop("uploading the fur")?;
        self.fur = object;
        Ok(())
    }

    /// Replaces the shell and fin textures (any slice count: slices are spread over the layers).
    ///
    /// # Errors
    /// [`RenderError::Textures`] for malformed textures, [`RenderError::OutOfMemory`].
    pub fn set_textures(
        &mut self,
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        textures: &FurTextures,
    ) -> Result<(), RenderError> {
        let scope = ErrorScope::push(device);
        let textures = GpuTextures::new(device, queue, textures)?;
        scope.pop("uploading the fur textures")?;
        self.globals_bind_group = globals_bind_group(
            device,
            &self.globals_layout,
            &self.globals,
            &textures,
            &self.shell_sampler,
            &self.fin_sampler,
        );
        self.textures = textures;
        Ok(())
    }

    /// Adds a mesh drawn without fur (e.g. the body under a furry garment), in linear RGB `colour`.
    ///
    /// # Errors
    /// As [`Renderer::new`].
    pub fn add_plain_mesh(&mut self, device: &wgpu::Device, mesh: &Mesh, colour: Vec3) -> Result<(), RenderError> {
        let scope = ErrorScope::push(device);
        let object = GpuObject::new(device, &self.object_layout, mesh, 0, &mesh.positions, colour)?;
        scope.pop("uploading a plain mesh")?;
        self.plain.push(object);
        Ok(())
    }

    /// Removes every plain mesh.
    pub fn clear_plain_meshes(&mut self) {
        self.plain.clear();
    }

    /// Uploads this frame's shared vertex array (e.g. the simulation's interpolated positions).
    ///
    /// # Errors
    /// [`RenderError::PositionCount`] unless there are exactly `(L + 1) * V` positions.
    pub fn update_positions(&self, queue: &wgpu::Queue, positions: &[Vec3]) -> Result<(), RenderError> {
        let expected = (self.fur.layers as usize + 1) * self.fur.vertex_count as usize;
        if positions.len() != expected {
            return Err(RenderError::PositionCount { expected, got: positions.len() });
        }
        queue.write_buffer(&self.fur.positions, 0, bytemuck::cast_slice(positions));
        Ok(())
    }

    /// Records one frame into `encoder`: clears `targets`, draws, and resolves into `output`
    /// (a view of `targets`' size and colour format).
    pub fn render(
        &self,
        queue: &wgpu::Queue,
        encoder: &mut wgpu::CommandEncoder,
        targets: &RenderTargets,
        output: &wgpu::TextureView,
        camera: &Camera,
        settings: &RenderSettings,
    ) {
        self.prepare(queue, camera, targets.aspect_ratio(), settings);
        let mut pass = begin_pass(encoder, targets, output, settings);
        self.draw(&mut pass, settings);
    }

    /// Writes this frame's uniforms (camera, light, settings); call before [`Renderer::draw`].
    pub fn prepare(&self, queue: &wgpu::Queue, camera: &Camera, aspect_ratio: f32, settings: &RenderSettings) {
        let world_from_view = camera.view_from_world().inverse();
        let globals = GlobalsUniform {
            clip_from_world: camera.clip_from_world(aspect_ratio),
            camera_position: camera.eye,
            alpha_to_coverage: u32::from(settings.alpha_to_coverage),
            light_direction: world_from_view.transform_vector3(settings.light_from_view).normalize_or(Vec3::Y),
            ambient: settings.ambient,
            light_colour: settings.light_colour,
            specular: settings.specular,
            root_colour: self.textures.root_colour.extend(1.0),
            fin_fade_cos: settings.fin_fade_cos.max(1e-3),
            shell_fade_cos: settings.shell_fade_cos.max(1e-3),
            root_occlusion: settings.root_occlusion,
            shininess: settings.shininess,
            has_surface: u32::from(self.textures.has_surface),
            _padding: [0; 3],
        };
        queue.write_buffer(&self.globals, 0, bytemuck::bytes_of(&globals));
        let tiles_per_radius = settings.tiles_per_radius;
        self.fur.write_uniform(queue, tiles_per_radius, self.textures.shell_slices);
        for plain in &self.plain {
            plain.write_uniform(queue, tiles_per_radius, self.textures.shell_slices);
        }
    }

    /// Records the draws into a pass begun on a target of this renderer's format (e.g. a
    /// viewer's pass that also draws a UI afterwards).
    pub fn draw(&self, pass: &mut wgpu::RenderPass<'_>, settings: &RenderSettings) {
        pass.set_bind_group(0, &self.globals_bind_group, &[]);
        for plain in &self.plain {
            pass.set_bind_group(1, &plain.bind_group, &[]);
            pass.set_pipeline(&self.pipelines.surface(plain).plain);
            plain.draw_surface(pass, 0..1);
        }
        let fur = &self.fur;
        let surface = self.pipelines.surface(fur);
        pass.set_bind_group(1, &fur.bind_group, &[]);
        if settings.skin {
            pass.set_pipeline(&surface.skin);
            fur.draw_surface(pass, 0..1);
        }
        if settings.shells && fur.layers > 0 {
            pass.set_pipeline(if settings.alpha_to_coverage {
                &surface.shells_coverage
            } else {
                &surface.shells_blended
            });
            fur.draw_surface(pass, 0..fur.layers);
        }
        // Fins after the shells: at the silhouette, where fins matter, they stand outside the
        // shells and must not be covered by the faded outer layers.
        if settings.fins && fur.layers > 0 {
            let fins =
                if settings.alpha_to_coverage { &self.pipelines.fins_coverage } else { &self.pipelines.fins_blended };
            pass.set_pipeline(fins);
            pass.set_index_buffer(fur.fin_indices.slice(..), wgpu::IndexFormat::Uint32);
            pass.draw_indexed(0..6 * fur.layers, 0, 0..fur.edge_count);
        }
    }

    pub(crate) fn globals_layout(&self) -> &wgpu::BindGroupLayout {
        &self.globals_layout
    }

    pub(crate) fn globals_bind_group(&self) -> &wgpu::BindGroup {
        &self.globals_bind_group
    }
}

/// Begins the frame's pass on `targets`, cleared to the background, resolving into `output`.
pub(crate) fn begin_pass<'e>(
    encoder: &'e mut wgpu::CommandEncoder,
    targets: &RenderTargets,
    output: &wgpu::TextureView,
    settings: &RenderSettings,
) -> wgpu::RenderPass<'e> {
    let background = settings.background.as_dvec3();
    let clear = wgpu::Color { r: background.x, g: background.y, b: background.z, a: 1.0 };
    encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
        label: Some("pelt fur"),
        color_attachments: &[Some(targets.colour_attachment(output, clear))],
        depth_stencil_attachment: Some(targets.depth_attachment()),
        ..wgpu::RenderPassDescriptor::default()
    })
}

impl Pipelines {
    fn new(
        device: &wgpu::Device,
        format: TargetFormat,
        globals_layout: &wgpu::BindGroupLayout,
        object_layout: &wgpu::BindGroupLayout,
    ) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("pelt unified"),
            source: wgpu::ShaderSource::Wgsl(unified_shader_source().into()),
        });
        let layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("pelt unified"),
            bind_group_layouts: &[Some(globals_layout), Some(object_layout)],
            immediate_size: 0,
        });
        let build = |label: &str, vertex: &str, fragment: &str, kind| {
            create_pipeline(device, &layout, &module, format, label, (vertex, fragment), kind, &[])
        };
        let surface = |walk: &str| {
            let skin = format!("vs_skin_{walk}");
            let shell = format!("vs_shell_{walk}");
            SurfacePipelines {
                plain: build("pelt plain", &skin, "fs_plain", PassKind::Opaque),
                skin: build("pelt skin", &skin, "fs_skin", PassKind::Opaque),
                shells_blended: build("pelt shells", &shell, "fs_shell", PassKind::Shells(Transparency::Blend)),
                shells_coverage: build("pelt shells a2c", &shell, "fs_shell", PassKind::Shells(Transparency::Coverage)),
            }
        };
        Self {
            corners: surface("corners"),
            indexed: surface("indexed"),
            fins_blended: build("pelt fins", "vs_fin", "fs_fin", PassKind::Fins(Transparency::Blend)),
            fins_coverage: build("pelt fins a2c", "vs_fin", "fs_fin", PassKind::Fins(Transparency::Coverage)),
        }
    }
}

/// How the fur's transparency is resolved.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum Transparency {
    /// Premultiplied alpha blending, depth writes off (drawn in order, inner to outer).
    Blend,
    /// Alpha-to-coverage with depth writes on (order independent).
    Coverage,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum PassKind {
    Opaque,
    Shells(Transparency),
    Fins(Transparency),
}

#[expect(clippy::too_many_arguments, reason = "a pipeline really has this many independent parts")]
pub(crate) fn create_pipeline(
    device: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    format: TargetFormat,
    label: &str,
    (vertex_entry, fragment_entry): (&str, &str),
    kind: PassKind,
    buffers: &[Option<wgpu::VertexBufferLayout<'_>>],
) -> wgpu::RenderPipeline {
    let transparency = match kind {
        PassKind::Opaque => None,
        PassKind::Shells(t) | PassKind::Fins(t) => Some(t),
    };
    let blend = (transparency == Some(Transparency::Blend)).then_some(wgpu::BlendState::PREMULTIPLIED_ALPHA_BLENDING);
    let depth_write = transparency != Some(Transparency::Blend);
    // Shells facing away lie behind the skin; fins are seen from both sides.
    let cull_mode = match kind {
        PassKind::Fins(_) => None,
        PassKind::Opaque | PassKind::Shells(_) => Some(wgpu::Face::Back),
    };
    device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
        label: Some(label),
        layout: Some(layout),
        vertex: wgpu::VertexState {
            module,
            entry_point: Some(vertex_entry),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            buffers,
        },
        primitive: wgpu::PrimitiveState {
            topology: wgpu::PrimitiveTopology::TriangleList,
            front_face: wgpu::FrontFace::Ccw,
            cull_mode,
            ..wgpu::PrimitiveState::default()
        },
        depth_stencil: Some(wgpu::DepthStencilState {
            format: DEPTH_FORMAT,
            depth_write_enabled: Some(depth_write),
            depth_compare: Some(wgpu::CompareFunction::LessEqual),
            stencil: wgpu::StencilState::default(),
            bias: wgpu::DepthBiasState::default(),
        }),
        multisample: wgpu::MultisampleState {
            count: format.sample_count,
            mask: !0,
            alpha_to_coverage_enabled: transparency == Some(Transparency::Coverage) && format.sample_count > 1,
        },
        fragment: Some(wgpu::FragmentState {
            module,
            entry_point: Some(fragment_entry),
            compilation_options: wgpu::PipelineCompilationOptions::default(),
            targets: &[Some(wgpu::ColorTargetState {
                format: format.colour,
                blend,
                write_mask: wgpu::ColorWrites::ALL,
            })],
        }),
        multiview_mask: None,
        cache: None,
    })
}

pub(crate) fn layout_entry(binding: u32, ty: wgpu::BindingType) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::VERTEX | wgpu::ShaderStages::FRAGMENT,
        ty,
        count: None,
    }
}

fn texture_binding(view_dimension: wgpu::TextureViewDimension) -> wgpu::BindingType {
    wgpu::BindingType::Texture {
        sample_type: wgpu::TextureSampleType::Float { filterable: true },
        view_dimension,
        multisampled: false,
    }
}

fn globals_bind_group(
    device: &wgpu::Device,
    layout: &wgpu::BindGroupLayout,
    globals: &wgpu::Buffer,
    textures: &GpuTextures,
    shell_sampler: &wgpu::Sampler,
    fin_sampler: &wgpu::Sampler,
) -> wgpu::BindGroup {
    device.create_bind_group(&wgpu::BindGroupDescriptor {
        label: Some("pelt globals"),
        layout,
        entries: &[
            wgpu::BindGroupEntry { binding: 0, resource: globals.as_entire_binding() },
            wgpu::BindGroupEntry { binding: 1, resource: wgpu::BindingResource::TextureView(&textures.shell) },
            wgpu::BindGroupEntry { binding: 2, resource: wgpu::BindingResource::TextureView(&textures.fin) },
            wgpu::BindGroupEntry { binding: 3, resource: wgpu::BindingResource::Sampler(shell_sampler) },
            wgpu::BindGroupEntry { binding: 4, resource: wgpu::BindingResource::Sampler(fin_sampler) },
            wgpu::BindGroupEntry { binding: 5, resource: wgpu::BindingResource::TextureView(&textures.surface) },
        ],
    })
}

/// Catches out-of-memory and validation errors of the GPU calls between `push` and `pop` and
/// turns them into [`RenderError`]s instead of a panic in wgpu's default handler.
pub(crate) struct ErrorScope {
    validation: wgpu::ErrorScopeGuard,
    memory: wgpu::ErrorScopeGuard,
}

impl ErrorScope {
    pub fn push(device: &wgpu::Device) -> Self {
        let memory = device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let validation = device.push_error_scope(wgpu::ErrorFilter::Validation);
        Self { validation, memory }
    }

    pub fn pop(self, during: &'static str) -> Result<(), RenderError> {
        let validation = pollster::block_on(self.validation.pop());
        let memory = pollster::block_on(self.memory.pop());
        if let Some(error) = memory {
            return Err(RenderError::OutOfMemory { during, message: error.to_string() });
        }
        if let Some(error) = validation {
            return Err(RenderError::Gpu { during, message: error.to_string() });
        }
        Ok(())
    }
}
