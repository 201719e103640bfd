//! Runs the batched kernel on every strand, in parallel, with the best instructions the CPU has.
//!
//! The kernel ([`super::kernel`]) is one source compiled twice: inside [`bend_pairs_avx2`], with
//! AVX2 and FMA enabled (256-bit lanes, fused multiply-adds in hardware), and as plain code for
//! any other CPU. Both perform the same IEEE operations in the same order, so they give the same
//! bytes (a test compares them). Contact's screen ([`screen`]) is compiled twice the same way.
//! An AVX2 copy is only called after `is_x86_feature_detected!` says the CPU has both features:
//! those calls are the only `unsafe` in the crate.
#![allow(unsafe_code)]

use rayon::prelude::*;

use glam::{Quat, Vec3};

use super::contact::screen::{self, Batch, BatchPlanes};
use super::contact::{Near, Resolve};
use super::kernel::{Step, VecLanes};

/// Which instructions the CPU bend uses ([`Simulation::set_cpu_kernel`](super::Simulation::set_cpu_kernel)).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum CpuKernel {
    /// AVX2 + FMA where the CPU has them, else portable.
    #[default]
    Auto,
    /// 256-bit AVX2 with fused multiply-adds (x86-64 CPUs that have both).
    Avx2Fma,
    /// Plain Rust for any CPU; the same bytes as [`CpuKernel::Avx2Fma`], slower where the CPU
    /// lacks hardware FMA (each fused multiply-add is a libm call then).
    Portable,
}

impl CpuKernel {
    /// Whether this CPU can run [`CpuKernel::Avx2Fma`].
    #[must_use]
    pub fn avx2_fma_available() -> bool {
        #[cfg(target_arch = "x86_64")]
        {
            is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            false
        }
    }

    /// The kernel that runs when this one is asked for: [`CpuKernel::Auto`] and an unavailable
    /// [`CpuKernel::Avx2Fma`] resolve to what the CPU has.
    #[must_use]
    pub fn resolve(self) -> Self {
        match self {
            Self::Auto | Self::Avx2Fma if Self::avx2_fma_available() => Self::Avx2Fma,
            _ => Self::Portable,
        }
    }

    /// A short name for reports: `avx2+fma` or `portable`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self.resolve() {
            Self::Avx2Fma => "avx2+fma",
            _ => "portable",
        }
    }
}

/// Pairs of batches per parallel task: enough work to pay for the task, small enough to balance.
const PAIRS_PER_TASK: usize = 4;

/// Bends every strand of `step` into `nodes` (batch-major, `L + 1` nodes per batch), then
/// applies `contact` to each batch in the same task, while its nodes are still in cache.
pub(crate) fn bend_all(kernel: CpuKernel, step: &Step<'_>, contact: Option<&Resolve<'_>>, nodes: &mut [VecLanes]) {
    let avx2 = kernel.resolve() == CpuKernel::Avx2Fma;
    let pair_nodes = 2 * (step.layers + 1);
    let contact = contact.filter(|c| c.step.is_active());
    nodes.par_chunks_mut(pair_nodes * PAIRS_PER_TASK).enumerate().for_each(|(task, chunk)| {
        let first_pair = task * PAIRS_PER_TASK;
        bend_chunk(avx2, step, first_pair, pair_nodes, chunk);
        if let Some(contact) = contact {
            for (i, batch) in chunk.chunks_mut(step.layers + 1).enumerate() {
                contact.batch(2 * first_pair + i, batch);
            }
        }
    });
}

fn bend_chunk(avx2: bool, step: &Step<'_>, first_pair: usize, pair_nodes: usize, chunk: &mut [VecLanes]) {
    #[cfg(target_arch = "x86_64")]
    if avx2 && CpuKernel::avx2_fma_available() {
        // SAFETY: `bend_pairs_avx2` needs AVX2 and FMA, and the CPU has both (checked on the
        // line above); it is otherwise safe code.
        unsafe { bend_pairs_avx2(step, first_pair, pair_nodes, chunk) };
        return;
    }
    let _ = avx2;
    bend_pairs(step, first_pair, pair_nodes, chunk);
}

#[inline(always)]
fn bend_pairs(step: &Step<'_>, first_pair: usize, pair_nodes: usize, nodes: &mut [VecLanes]) {
    for (p, pair) in nodes.chunks_mut(pair_nodes).enumerate() {
        step.bend_pair(first_pair + p, pair);
    }
}

/// The kernel compiled with AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn bend_pairs_avx2(step: &Step<'_>, first_pair: usize, pair_nodes: usize, nodes: &mut [VecLanes]) {
    bend_pairs(step, first_pair, pair_nodes, nodes);
}

/// The lanes of a batch contact solves ([`screen::lanes_to_solve`]), with the best instructions
/// the CPU has (the same answer either way: plain IEEE arithmetic, no fused operations).
pub(crate) fn screen(
    kernel: CpuKernel,
    batch: &Batch<'_>,
    skin: Option<&BatchPlanes>,
    roots: &[Vec3],
    frames: &[Quat],
    near: Near<'_>,
) -> u32 {
    #[cfg(target_arch = "x86_64")]
    if kernel.resolve() == CpuKernel::Avx2Fma && CpuKernel::avx2_fma_available() {
        // SAFETY: `screen_avx2` needs AVX2 and FMA, and the CPU has both (checked on the line
        // above); it is otherwise safe code.
        return unsafe { screen_avx2(batch, skin, roots, frames, near) };
    }
    let _ = kernel;
    screen::lanes_to_solve(batch, skin, roots, frames, near)
}

/// The screen compiled with AVX2 and FMA.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn screen_avx2(batch: &Batch<'_>, skin: Option<&BatchPlanes>, roots: &[Vec3], frames: &[Quat], near: Near<'_>) -> u32 {
    screen::lanes_to_solve(batch, skin, roots, frames, near)
}
