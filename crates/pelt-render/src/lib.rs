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
//! - [`GpuFur`]: one fur's GPU data (shared array in one or two simulation states, topology,
//!   uvs, base normals, textures, uniform); [`PlainMesh`] a furless mesh. Each has a model
//!   transform.
//! - [`FurAsset`]: what the copies of one fur share (topology, uvs, fin strip, groom attributes,
//!   textures), uploaded once; [`GpuFur::from_asset`] and [`FurDriver::with_asset`] make one more
//!   copy of it (a herd's member) holding only its own state.
//! - [`FurView`]: one view's uniform buffer, written from [`ViewData`] (`clip_from_world`, camera
//!   position, [`Light`]); several views in one submission each have their own.
//! - [`Studio`]: the lights, environment, exposure and background of Pelt's own pictures (its
//!   key light fixed in the world and a sky-ground fill by default), one default that
//!   `pelt render`, the viewer, the web page and the examples share.
//!
//! # The order a host calls things in
//! 1. When creating the device: request [`required_features`] (and the [`optional_features`] the
//!    adapter has), [`required_limits`] and check
//!    [`required_downlevel_flags`] (or [`check_adapter`]).
//! 2. Once per target description: [`FurRenderer::new`]. Once per fur: [`FurDriver::new`] (its
//!    [`GpuFur`] and the kernel that bends it) and a `pelt_core::sim::FurStepper` (the CPU half:
//!    simulation, posing, script). Once per camera: [`FurView::new`].
//! 3. Each frame, before recording: [`FurDriver::advance_to`] for each fur (pose, script,
//!    simulation step, queue writes) and [`FurView::prepare`] for each view.
//! 4. In the host's encoder, before the render pass: [`FurDriver::record`] for each fur (the GPU
//!    kernel's steps), then [`FurDriver::record_view`] for each fur and view (the silhouette
//!    pass, when drawing with [`FurDrawSettings::silhouette_fins`]).
//! 5. In the host's render pass, after its opaque geometry: [`FurRenderer::draw_plain`] for
//!    plain meshes, then [`FurDriver::draw`] for each fur (farthest first when blending).
//!
//! Below the driver the pieces stay public for hosts with other needs: [`GpuFur::push_state`]
//! or [`GpuFur::set_positions`] upload states simulated elsewhere, [`GpuSimulation`] writes
//! [`GpuFur::current_positions`] in a compute pass, [`GpuFur::prepare`] and
//! [`FurRenderer::prepare_fins`] / [`FurRenderer::draw`] are what the driver calls.
//!
//! Nothing in the library path blocks, spawns threads or needs `image`/`pollster`: those are in
//! the default `headless` feature ([`Gpu`], [`Headless`]), which Pelt's commands and tests use.
//! The `lab` feature (off by default) adds what Pelt is measured against: the separated structure
//! of Lengyel et al. 2001 on the same views and textures (`SeparatedRenderer`, `SeparatedFur`),
//! the explicit strands as ribbons (`StrandRenderer`, `StrandRibbons`) and the silhouette decided
//! on the CPU (`CpuSilhouette`, `GpuFur::prepare_fins_on_cpu`).
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
//! use pelt_core::sim::FurStepper;
//! use pelt_core::{Builtin, FurStructure, Preset};
//! use pelt_render::{FurDrawSettings, FurDriver, FurRenderer, FurTarget, FurView, KernelChoice, Light, ViewData};
//!
//! // Once: the pipelines for the host's attachments (here reverse-Z depth), a fur and a view.
//! let target = FurTarget::new(wgpu::TextureFormat::Bgra8UnormSrgb).reverse_z();
//! let renderer = FurRenderer::new(device, target)?;
//! let (mesh, _report) = Builtin::Bunny.mesh();
//! let preset = Preset::default();
//! let params = preset.fur_params(&mesh);
//! let structure = FurStructure::new(mesh, &params)?;
//! let textures = preset.generate_textures()?;
//! let mut driver =
//!     FurDriver::new(device, queue, &renderer, &structure, &textures, &preset.simulation, KernelChoice::Cpu)?;
//! let mut stepper = FurStepper::new(&structure, &preset.simulation)?;
//! let view = FurView::new(device, &renderer);
//!
//! // Each frame: step and write, record the GPU work, then draw into the host's pass.
//! driver.advance_to(device, queue, &mut stepper, 0.5)?;
//! view.prepare(queue, &ViewData::new(clip_from_world, world_from_view, &Light::default()));
//! driver.record(encoder)?;
//! // The silhouette pass (compute) into the host's encoder, before the render pass.
//! driver.record_view(encoder, &renderer, &view);
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
//! driver.draw(&mut pass, &renderer, &view, &FurDrawSettings::SILHOUETTE);
//! # Ok(())
//! # }
//! ```

#![warn(missing_docs)]

mod asset;
mod camera;
mod colliders;
mod contact;
mod driver;
mod error;
mod fur;
pub mod fur_bsdf;
mod geometry;
#[cfg(feature = "headless")]
mod gpu;
#[cfg(feature = "headless")]
mod headless;
mod host_shadows;
#[cfg(feature = "lab")]
mod lab;
mod listing;
mod lod;
mod object;
mod plain;
mod pool;
mod renderer;
mod requirements;
mod shaders;
mod shadows;
mod sim_pipelines;
mod simulation;
mod skinning;
mod studio;
mod surroundings;
mod targets;
mod textures;
mod view;

pub use asset::FurAsset;
pub use camera::Camera;
pub use colliders::{COLLIDER_COLOUR, ColliderMeshes, HAND_COLOUR, ground_mesh};
pub use driver::{
    AUTO_GPU_MARGIN, FurDriver, HerdPosing, KernelChoice, SimKernel, cpu_secs_per_step, gpu_secs_per_step,
    gpu_secs_per_step_of,
};
pub use error::RenderError;
pub use fur::{FurStates, GpuFur};
pub use geometry::POSITIONS_USAGE;
#[cfg(feature = "headless")]
pub use gpu::{Backend, Gpu};
#[cfg(feature = "headless")]
pub use headless::{HEADLESS_FORMAT, Headless};
pub use host_shadows::{HostLight, HostShadowView, HostShadows};
#[cfg(feature = "lab")]
pub use lab::{CpuSilhouette, SeparatedFur, SeparatedRenderer, StrandRenderer, StrandRibbons};
pub use lod::{FurLevel, LodSettings, strand_pixels, strand_pixels_in_view};
pub use object::FurShading;
pub use object::{FurFrame, FurLook, GpuBytes, tile_mapping};
pub use plain::PlainMesh;
pub use renderer::{FurDrawSettings, FurMotion, FurPrepass, FurRenderer, HerdDraws, MotionData, PrepassTarget};
pub use requirements::{
    check_adapter, optional_features, required_downlevel_flags, required_features, required_limits,
};
pub use shaders::{
    herd_posing_shader_source, pool_draw_shader_source, prepass_shader_source, shadow_copy_shader_source,
    silhouette_shader_source, simulation_pooled_shader_source, simulation_shader_source, skinning_shader_source,
    unified_shader_source, view_lod_shader_source,
};
#[cfg(feature = "lab")]
pub use shaders::{separated_shader_source, strands_shader_source};
pub use shadows::{MAX_FITTED_SIZE, MAX_SHADOW_VIEWS, ShadowCaster, ShadowMap, ShadowSettings, fitted_shadow_size};
pub use simulation::GpuSimulation;
pub use skinning::GpuSkin;
pub use studio::{GROUND_RADIANCE, KEY_LIGHT_ANGLES, SKY_RADIANCE, Studio};
pub use surroundings::{GROUND_COLOUR, Surroundings};
pub use targets::{DEFAULT_BACKGROUND, DEPTH_FORMAT, FurTarget, RenderTargets, SAMPLE_COUNT, default_sample_count};
pub use view::{FurView, Light, LightDirection, LightSet, ViewData};
