//! What Pelt is measured against, not what a host draws with (the `lab` feature, off by
//! default): the separated structure of Lengyel et al. 2001 on the same views and textures
//! (Table 2's baseline), the explicit strands drawn as ribbons (the fidelity reference), and the
//! silhouette decided on the CPU (the compute pass's alternative, for timing both).
//!
//! Everything here sits on the product's public pieces and the renderer's pipeline plumbing;
//! nothing below imports it.

mod cpu_silhouette;
mod separated;
mod strands;

pub use cpu_silhouette::CpuSilhouette;
pub use separated::{SeparatedFur, SeparatedRenderer};
pub use strands::{StrandRenderer, StrandRibbons};
