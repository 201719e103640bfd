//! A herd's draws: through a shadow view, the copies made together (consecutive slots of one
//! pool) cast in one draw a pass (`pool_draws.wgsl`: the instance names the slot), so the shadow
//! maps' draws do not grow with the herd; through the camera each copy draws as a lone fur
//! (blending needs each copy's shells in order, farthest copy first).

use std::sync::Arc;

use super::FurRenderer;
use super::shadow::OPACITY_SHELLS;
use crate::fur::GpuFur;
use crate::renderer::FurDrawSettings;
use crate::view::{FurView, ShadowPass, ViewRole};

impl FurRenderer {
    /// [`FurRenderer::draw`] for every fur of `furs` (a herd's members), in that order. Through a
    /// [`crate::ShadowMap`]'s views, each run of copies made together
    /// ([`crate::FurDriver::herd_with_asset`], [`GpuFur::herd_from_asset`]) that follow one
    /// another in their pool casts in one draw a pass: a wet copy, or one with textures of its
    /// own, casts its coat alone. Returns the draws recorded.
    pub fn draw_herd<'a>(
        &self,
        pass: &mut wgpu::RenderPass<'_>,
        view: &FurView,
        furs: impl IntoIterator<Item = &'a GpuFur>,
        settings: &FurDrawSettings,
    ) -> usize {
        let ViewRole::Shadow(shadow_pass) = view.role() else {
            return furs.into_iter().map(|fur| self.draw_counted(pass, view, fur, settings)).sum();
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

    /// A run of copies in consecutive slots of one pool in one pass of a shadow map: one draw,
    /// each copy's vertices deciding from its own object what it casts (as `draw_shadow` does).
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
        let furred = geometry.shape.layers > 0 && (settings.shells || settings.fins);
        let draws = match shadow_pass {
            ShadowPass::Opaque => settings.skin,
            ShadowPass::FurDepth | ShadowPass::Opacity => furred,
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
/// same pool; for the opacity pass (the only one reading the coat) also the same textures and
/// groom shading, both dry (the pool binds no copy's wetness).
fn cast_together(shadow_pass: ShadowPass, previous: &GpuFur, next: &GpuFur) -> bool {
    let follows = Arc::ptr_eq(previous.pool(), next.pool()) && next.slot() == previous.slot() + 1;
    if shadow_pass != ShadowPass::Opacity {
        return follows;
    }
    let (a, b) = (previous.coat(), next.coat());
    follows
        && !a.wet
        && !b.wet
        && a.groomed == b.groomed
        && previous.textures_bind_group() == next.textures_bind_group()
}
