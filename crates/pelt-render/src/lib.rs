//! Pelt's wgpu renderer for the unified shell-and-fin fur structure (Lee et al. 2010).
//!
//! The shared vertex array `NV[i*V + j]` lives once on the GPU as a storage buffer; the skin,
//! the shells (instance = layer) and the fins (instance = edge) all fetch it in their vertex
//! shaders, so fins bend with the simulated strands and nothing is copied per layer.
//!
//! - [`Renderer`] draws into any [`wgpu::TextureView`] of its [`TargetFormat`] (a window's
//!   surface or an offscreen texture), with [`RenderTargets`] holding the MSAA colour and depth.
//! - [`Headless`] owns a [`Gpu`], a target and a readback: frames come back as images.
//! - [`SeparatedRenderer`] draws the separated structure of Lengyel et al. 2001 (fins as their own
//!   static geometry) for side-by-side comparisons.
//!
//! Shell tile coordinates: meshes with uvs use them (scaled so a tile covers the same world size
//! as without uvs); meshes without uvs use a triplanar projection of the rest root positions with
//! sharp blend weights. Either way [`RenderSettings::tiles_per_radius`] sets the strand density
//! relative to the mesh's bounding radius, so any mesh gets a sensible density.

mod camera;
mod error;
mod gpu;
mod headless;
mod renderer;
mod separated;
mod targets;
mod textures;

pub use camera::Camera;
pub use error::RenderError;
pub use gpu::{Backend, Gpu};
pub use headless::{HEADLESS_FORMAT, Headless};
pub use renderer::{RenderSettings, Renderer, unified_shader_source};
pub use separated::{SeparatedRenderer, separated_shader_source};
pub use targets::{DEPTH_FORMAT, RenderTargets, SAMPLE_COUNT, TargetFormat};
