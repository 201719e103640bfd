//! The level of detail Pelt's commands draw a fur at: the preset's `[render.lod]`, unless
//! `--no-lod`, from how many pixels its strands span in the camera.

use glam::Vec3;
use pelt_core::{FurStructure, LodParams};
use pelt_render::{FurLevel, LodSettings, strand_pixels_in_view};

/// The settings `[render.lod]` and `--no-lod` give.
pub fn settings(params: &LodParams, no_lod: bool) -> LodSettings {
    LodSettings {
        enabled: params.enabled && !no_lod,
        pixels_per_shell: params.pixels_per_shell,
        facing: params.view_angle.then_some([params.facing_start, params.facing_full]),
        coat_fade: params.coat_fade.then_some(LodSettings::DEFAULT_COAT_FADE),
        fin_fade: params.fin_fade.then_some(LodSettings::DEFAULT_FIN_FADE),
    }
}

/// The level for `fur` (model space = world space, as Pelt's commands draw it) seen from `eye`
/// with a vertical field of view `fov_y_rad` in a viewport `viewport_height` pixels high.
pub fn level(settings: &LodSettings, fur: &FurStructure, eye: Vec3, fov_y_rad: f32, viewport_height: u32) -> FurLevel {
    let length = fur.lengths.iter().copied().fold(0.0, f32::max);
    let (centre, radius) = fur.mesh.bounding_sphere();
    let pixels = strand_pixels_in_view(length, (centre, radius + length), eye, fov_y_rad, viewport_height);
    settings.level(fur.layers, pixels)
}
