//! Pelt's wgpu renderer for the unified shell-and-fin fur structure (Lee et al. 2010), built to
//! draw inside a host's own frame: the host's device, camera, depth buffer and render pass.
//!
//! The shared vertex array `NV[i*V + j]` lives on the GPU as storage buffers; the skin, the shells
//! (instance = layer) and the fins (instance = edge) all fetch it in their vertex shaders, so fins
//! bend with the simulated strands and nothing is copied per layer.
//!
//! # The pieces (after re_renderer's split of renderers from draw data)
//! - [`FurTarget`]: the host's attachments (colour and depth formats, depth comparison, MSAA).
//!   Reverse-Z hosts use [`FurTarget::reverse_z`] and clear depth to 0.
//! - [`FurRenderer`]: every pipeline for one target, created once and shared by all furs.
//!   [`SeparatedRenderer`] adds the separated structure of Lengyel et al. 2001 on the same views
//!   and textures, for comparisons.
//! - [`GpuFur`]: one fur's GPU data (shared array in one or two simulation states, topology,
//!   uvs, base normals, textures, uniform); [`SeparatedFur`] the same for the separated structure;
//!   [`PlainMesh`] a furless mesh. Each has a model transform.
//! - [`FurView`]: one view's uniform buffer, written from [`ViewData`] (`clip_from_world`, camera
//!   position, [`Light`]); several views in one submission each have their own.
//! - [`Stage`]: the light, exposure and background of Pelt's own pictures, one default that
//!   `pelt render`, the viewer, the web page and the examples share.
//!
//! # The order a host calls things in
//! 1. When creating the device: request [`required_features`], [`required_limits`] and check
//!    [`required_downlevel_flags`] (or [`check_adapter`]).
//! 2. Once per target description: [`FurRenderer::new`]. Once per fur: [`GpuFur::new`]. Once per
//!    camera: [`FurView::new`].
//! 3. Each simulation step: [`GpuFur::push_state`] (or [`GpuFur::set_positions`] each frame, or a
//!    compute pass writing [`GpuFur::current_positions`]: [`GpuSimulation`] is Pelt's, which
//!    bends the strands on the GPU from a `pelt_core::Simulation`'s inputs, so nothing is
//!    uploaded per step but those inputs).
//! 4. Each frame, before submitting: [`FurView::prepare`] for each view, [`GpuFur::prepare`]
//!    (model transform, interpolation, look) for each fur.
//! 5. In the host's encoder, before the render pass: [`FurRenderer::prepare_fins`] for each fur
//!    and view (the silhouette pass, a compute pass) when drawing with
//!    [`FurDrawSettings::silhouette_fins`].
//! 6. In the host's render pass, after its opaque geometry: [`FurRenderer::draw_plain`] for
//!    plain meshes, then [`FurRenderer::draw`] for each fur (farthest first when blending).
//!
//! Nothing in the library path blocks, spawns threads or needs `image`/`pollster`: those are in
//! the default `headless` feature ([`Gpu`], [`Headless`]), which Pelt's commands and tests use.
//!
//! Shell tile coordinates: meshes with uvs use them (scaled so a tile covers the same model size
//! as without uvs); meshes without uvs use a triplanar projection of the root positions in model
//! space with sharp blend weights. Either way [`FurLook::tiles_per_radius`] sets the strand density
//! relative to the mesh's bounding radius, so any mesh gets a sensible density.
//!
//! # Example
//! ```no_run
//! # fn frame(
//! #     device: &wgpu::Device,
//! #     queue: &wgpu::Queue,
//! #     encoder: &mut wgpu::CommandEncoder,
//! #     colour: &wgpu::TextureView,
//! #     depth: &wgpu::TextureView,
//! #     clip_from_world: glam::Mat4,
//! #     world_from_view: glam::Mat4,
//! # ) -> Result<(), Box<dyn std::error::Error>> {
//! use pelt_core::{Builtin, FurStructure, Preset, Simulation};
//! use pelt_render::{FurDrawSettings, FurFrame, FurRenderer, FurStates, FurTarget, FurView, GpuFur, Light, ViewData};
//!
//! // Once: the pipelines for the host's attachments (here reverse-Z depth), a fur and a view.
//! let target = FurTarget::new(wgpu::TextureFormat::Bgra8UnormSrgb).reverse_z();
//! let renderer = FurRenderer::new(device, target)?;
//! let (mesh, _report) = Builtin::Bunny.mesh();
//! let preset = Preset::default();
//! let params = preset.fur_params(&mesh);
//! let structure = FurStructure::new(mesh, &params)?;
//! let mut simulation = Simulation::new(&structure, &preset.simulation)?;
//! let fur = GpuFur::new(device, queue, &renderer, &structure, &preset.generate_textures()?, FurStates::One)?;
//! let view = FurView::new(device, &renderer);
//!
//! // Each frame: simulate, upload, prepare, then draw into the host's pass.
//! simulation.advance_to(0.5);
//! fur.set_positions(queue, simulation.positions())?;
//! fur.prepare(queue, &FurFrame::default());
//! view.prepare(queue, &ViewData::new(clip_from_world, world_from_view, &Light::default()));
//! // The silhouette pass (compute) into the host's encoder, before the render pass.
//! renderer.prepare_fins(encoder, &view, &fur);
//! let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
//!     color_attachments: &[Some(wgpu::RenderPassColorAttachment {
//!         view: colour,
//!         depth_slice: None,
//!         resolve_target: None,
//!         ops: wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store },
//!     })],
//!     depth_stencil_attachment: Some(wgpu::RenderPassDepthStencilAttachment {
//!         view: depth,
//!         depth_ops: Some(wgpu::Operations { load: wgpu::LoadOp::Load, store: wgpu::StoreOp::Store }),
//!         stencil_ops: None,
//!     }),
//!     ..Default::default()
//! });
//! renderer.draw(&mut pass, &view, &fur, &FurDrawSettings::SILHOUETTE);
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]

mod camera;
mod driver;
mod error;
mod fur;
mod geometry;
#[cfg(feature = "headless")]
mod gpu;
#[cfg(feature = "headless")]
mod headless;
mod lod;
mod object;
mod pipeline;
mod plain;
mod renderer;
mod requirements;
mod separated;
mod silhouette;
mod silhouette_cpu;
mod simulation;
mod stage;
mod strands;
mod targets;
mod textures;
mod view;
mod view_lod;

pub use camera::Camera;
pub use driver::{FurDriver, KernelChoice, SimKernel, cpu_secs_per_step, gpu_secs_per_step};
pub use error::RenderError;
pub use fur::{FurStates, GpuFur};
pub use geometry::POSITIONS_USAGE;
#[cfg(feature = "headless")]
pub use gpu::{Backend, Gpu};
#[cfg(feature = "headless")]
pub use headless::{HEADLESS_FORMAT, Headless};
pub use lod::{FurLevel, LodSettings, strand_pixels, strand_pixels_in_view};
pub use object::{FurFrame, FurLook, GpuBytes, tile_mapping};
pub use plain::PlainMesh;
pub use renderer::{FurDrawSettings, FurRenderer, unified_shader_source};
pub use requirements::{check_adapter, required_downlevel_flags, required_features, required_limits};
pub use separated::{SeparatedFur, SeparatedRenderer, separated_shader_source};
pub use silhouette::silhouette_shader_source;
pub use silhouette_cpu::CpuSilhouette;
pub use simulation::{GpuSimulation, simulation_shader_source};
pub use stage::Stage;
pub use strands::{StrandRenderer, StrandRibbons, strands_shader_source};
pub use targets::{DEFAULT_BACKGROUND, DEPTH_FORMAT, FurTarget, RenderTargets, SAMPLE_COUNT, default_sample_count};
pub use view::{FurView, Light, LightDirection, ViewData};
pub use view_lod::view_lod_shader_source;
