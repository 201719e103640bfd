//! A herd's shadow draws: through a shadow view, the copies made together (consecutive slots of
//! one pool) cast in one draw a pass (`pool_draws.wgsl`: the instance names the slot), so the
//! shadow maps' draws do not grow with the herd (the camera's: `herd_view`). A CPU rasteriser
//! casts each copy alone: it reads a copy's object from storage lane by lane at every vertex,
//! which costs it more than the draws save (a GPU pays per draw).

use std::sync::Arc;

use super::FurRenderer;
use super::shadow::{OPACITY_SHELLS, opacity_shells};
use crate::fur::GpuFur;
use crate::renderer::FurDrawSettings;
use crate::view::{FurView, ShadowPass, ViewRole};

impl FurRenderer {
    /// [`FurRenderer::draw`] for every fur of `furs` (a herd's members), in that order. Through a
    /// [`crate::ShadowMap`]'s views, with [`FurRenderer::pooled_casting`], each run of copies
    /// made together ([`crate::FurDriver::herd_with_asset`], [`GpuFur::herd_from_asset`]) that
    /// follow one another in their pool casts in one draw a pass: a wet copy, one with textures
    /// of its own, one whose coat is hidden or casts fewer than four opacity shells casts its
    /// coat alone. Returns the draws recorded.
    pub fn draw_herd<'a>(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        view: &FurView,
        furs: impl IntoIterator<Item = &'a GpuFur>,
        settings: &FurDrawSettings,
    ) -> usize {
        let shadow_pass = match view.role() {
            ViewRole::Shadow(shadow_pass) if self.pooled_casting => shadow_pass,
            _ => return furs.into_iter().map(|fur| self.draw_counted(pass, view, fur, settings)).sum(),
        };
        let furs: Vec<&GpuFur> = furs.into_iter().collect();
        let mut draws = 0;
        let mut start = 0;
        while start < furs.len() {
            let mut end = start + 1;
            while end < furs.len() && cast_together(shadow_pass, furs[end - 1], furs[end]) {
                end += 1;
            }
            draws += match &furs[start..end] {
                [fur] => self.draw_shadow(pass, (view, shadow_pass), fur, settings),
                run => self.draw_pool_shadow(pass, (view, shadow_pass), run, settings),
            };
            start = end;
        }
        draws
    }

    /// Whether [`FurRenderer::draw_herd`] casts the copies made together in one draw a shadow
    /// pass: by default on a discrete or integrated GPU; not on a CPU rasteriser, where it is
    /// slower, nor where the adapter does not say what it is (a browser's).
    #[must_use]
    pub fn pooled_casting(&self) -> bool {
        self.pooled_casting
    }

    /// Sets [`FurRenderer::pooled_casting`]; the pictures are the same either way.
    pub fn set_pooled_casting(&mut self, pooled: bool) {
        self.pooled_casting = pooled;
    }

    /// Whether the GPU simulations of copies made together
    /// ([`crate::FurDriver::herd_with_asset`]) from now on step in one dispatch a step, not one a
    /// copy ([`crate::FurDriver::record_herd`]): by default on a discrete or integrated GPU, as
    /// [`FurRenderer::pooled_casting`].
    #[must_use]
    pub fn pooled_stepping(&self) -> bool {
        self.pooled_stepping
    }

    /// Sets [`FurRenderer::pooled_stepping`] for the herds made after; the states are the same
    /// bytes either way.
    pub fn set_pooled_stepping(&mut self, pooled: bool) {
        self.pooled_stepping = pooled;
    }

    /// Whether a host poses the bases of a herd bending on the GPU kernel on the GPU
    /// ([`crate::HerdPosing`]: the CPU poses joints only): by default on a discrete or
    /// integrated GPU. A CPU rasteriser runs the skinning on the cores the CPU's posing would
    /// use, and slower.
    #[must_use]
    pub fn herd_posing(&self) -> bool {
        self.herd_posing
    }

    /// Sets [`FurRenderer::herd_posing`].
    pub fn set_herd_posing(&mut self, on: bool) {
        self.herd_posing = on;
    }

    /// A run of copies in consecutive slots of one pool in one pass of a shadow map
    /// ([`cast_together`]): one draw of what each would draw alone.
    fn draw_pool_shadow(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        (view, shadow_pass): (&FurView, ShadowPass),
        run: &[&GpuFur],
        settings: &FurDrawSettings,
    ) -> usize {
        let first = run[0];
        let geometry = first.geometry();
        let walk = usize::from(!geometry.shape.has_uvs);
        let slots = first.slot()..first.slot() + run.len() as u32;
        let draws = match shadow_pass {
            ShadowPass::Opaque => settings.skin,
            ShadowPass::FurDepth | ShadowPass::Opacity => settings.shells || settings.fins,
        };
        if !draws {
            return 0;
        }
        pass.set_bind_group(0, view.bind_group(), &[]);
        pass.set_bind_group(1, first.pool().draw_group(), &[]);
        pass.set_bind_group(2, first.textures_bind_group(), &[]);
        pass.set_bind_group(3, view.shadow_group(), &[]);
        match shadow_pass {
            ShadowPass::Opaque => {
                pass.set_pipeline(&self.pool_casters().skin[walk]);
                geometry.draw_skins(pass, slots);
            }
            ShadowPass::FurDepth => {
                pass.set_pipeline(&self.pool_casters().fur_depth[walk]);
                geometry.draw_shells(pass, slots);
            }
            ShadowPass::Opacity => {
                pass.set_pipeline(&self.pool_opacity(first.coat())[walk]);
                geometry.draw_shells(pass, OPACITY_SHELLS * slots.start..OPACITY_SHELLS * slots.end);
            }
        }
        1
    }
}

/// Whether `next` casts in the same draw as `previous` in `shadow_pass`: the next slot of the
/// same pool; for the fur's passes both casting a coat (shown, with shells), so a hidden one
/// costs no vertex; for the opacity pass (the only one reading the coat) also four opacity
/// shells each (the instances' stride), the same textures and groom shading, and both dry (the
/// pool binds no copy's wetness). The others draw alone.
fn cast_together(shadow_pass: ShadowPass, previous: &GpuFur, next: &GpuFur) -> bool {
    let follows = Arc::ptr_eq(previous.pool(), next.pool()) && next.slot() == previous.slot() + 1;
    let casts =
        |fur: &GpuFur| fur.geometry().shape.layers > 0 && fur.drawn_shells() > 0 && fur.prepared_level().coat_shown();
    let four = |fur: &GpuFur| opacity_shells(fur.drawn_shells()) == OPACITY_SHELLS;
    match shadow_pass {
        ShadowPass::Opaque => follows,
        ShadowPass::FurDepth => follows && casts(previous) && casts(next),
        ShadowPass::Opacity => {
            let (a, b) = (previous.coat(), next.coat());
            follows
                && casts(previous)
                && casts(next)
                && four(previous)
                && four(next)
                && !a.wet
                && !b.wet
                && a.groomed == b.groomed
                && previous.textures_bind_group() == next.textures_bind_group()
        }
    }
}
