//! Level of detail: fewer shells and fin segments where the fur is small on screen (the paper's
//! future work). The host measures how many pixels a strand spans ([`strand_pixels`]), picks a
//! [`FurLevel`] with [`LodSettings::level`] and passes it in [`crate::FurFrame::level`].
//!
//! A level draws every `stride`-th layer counted down from the tips (so the tips always show),
//! and each drawn shell stands for `stride` layers: its alpha is raised to the opacity of that
//! many (`1 - (1 - a)^stride`). Strides are powers of two; between two strides `blend` fades the
//! layers the coarser stride drops (and moves the fins' dropped nodes onto the line between their
//! neighbours) while the kept layers gain the dropped ones' opacity, so the picture changes
//! continuously with distance and nothing pops.
//!
//! Shells by view angle (after Yang et al.): where the surface faces the eye the shells' slices
//! lie over one another and fewer of them look the same, so a level with
//! [`FurLevel::facing`] also fades, per vertex, the layers the next coarser stride drops as
//! `|n . v|` at the strand's root rises, with the same alpha compensation (the two blends
//! compose: `1 - (1 - blend) (1 - view weight)`). Triangles where those layers have faded out at
//! all three corners are not drawn in them: a per-frame compute pass lists the rest
//! (`listing/shells.rs`).

/// The level a fur is drawn at in one frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FurLevel {
    /// Draw every `stride`-th layer (a power of two, at least 1).
    pub stride: u32,
    /// `0..1`: how far toward twice the stride (the layers `2 * stride` drops fade out).
    pub blend: f32,
    /// Shells by view angle: `[start, full]`, `0 <= start < full <= 1`. Where `|n . v|` at a
    /// strand's root rises from `start` to `full`, the layers twice the stride drops fade out
    /// there (and are not drawn where they are gone). `None`: off.
    pub facing: Option<[f32; 2]>,
    /// `0..=1`: how much of the coat shows. 1 draws the shells and fins; below 1 they fade and
    /// the skin takes the coat's mean colour; 0 draws the skin alone in that colour (a fur too
    /// small on screen for its strands, say a far member of a herd).
    pub coat: f32,
    /// `0..=1`: how much of the fins show, on top of [`FurLevel::coat`]. A fin is as tall as a
    /// strand is long on screen; at a pixel or two it adds little to the shells' silhouette but
    /// costs its silhouette pass and draw, so far furs fade their fins first. 0 skips both.
    pub fins: f32,
}

impl FurLevel {
    /// Every layer and every fin segment.
    pub const FULL: Self = Self { stride: 1, blend: 0.0, facing: None, coat: 1.0, fins: 1.0 };

    /// The level with `stride` made a power of two no coarser than `layers` allow and `blend`
    /// clamped to `0..1` (0 at the coarsest stride).
    #[must_use]
    pub fn clamped(self, layers: u32) -> Self {
        let max_stride = max_stride(layers);
        let stride = self.stride.clamp(1, max_stride).next_power_of_two().min(max_stride);
        let blend = if stride >= max_stride || !self.blend.is_finite() { 0.0 } else { self.blend.clamp(0.0, 1.0) };
        // Nothing to fade toward at the coarsest stride.
        let facing = self.facing.filter(|&[start, full]| stride < max_stride && valid_facing(start, full));
        let coat = if self.coat.is_finite() { self.coat.clamp(0.0, 1.0) } else { 1.0 };
        let fins = if self.fins.is_finite() { self.fins.clamp(0.0, 1.0) } else { 1.0 };
        Self { stride, blend, facing, coat, fins }
    }

    /// How often a fur drawn at this level needs its simulation stepped
    /// (`FurStepper::set_step_stride`): every step while it draws every shell or every second
    /// one, every second step from every fourth shell on, every fourth once its coat fades
    /// (strands shorter than a pixel, whose motion spans less). Hosts of herds use it.
    #[must_use]
    pub fn step_stride(self) -> u32 {
        if self.coat < 1.0 {
            4
        } else if self.stride >= 4 {
            2
        } else {
            1
        }
    }

    /// Shells drawn at this level for a fur of `layers` layers (also its fin segments).
    #[must_use]
    pub fn shells(self, layers: u32) -> u32 {
        if layers == 0 { 0 } else { (layers / self.clamped(layers).stride).max(1) }
    }

    /// The level as the viewer and `pelt bench` show it: `shells drawn / layers`.
    #[must_use]
    pub fn describe(self, layers: u32) -> String {
        let level = self.clamped(layers);
        let mut text = format!("{}/{} shells", level.shells(layers), layers);
        if level.blend > 0.0 {
            text += &format!(" (fading to {})", layers / (2 * level.stride).max(1));
        }
        if level.facing.is_some() {
            text += &format!(", to {} facing the eye", layers / (2 * level.stride).max(1));
        }
        if level.fins <= 0.0 {
            text += ", no fins";
        } else if level.fins < 1.0 {
            text += &format!(", the fins at {:.0}%", 100.0 * level.fins);
        }
        if level.coat <= 0.0 {
            text = "the skin alone in the coat's colour".to_owned();
        } else if level.coat < 1.0 {
            text += &format!(", the coat at {:.0}%", 100.0 * level.coat);
        }
        text
    }
}

/// Whether `[start, full]` is a usable view-angle range (`0 <= start < full <= 1`).
fn valid_facing(start: f32, full: f32) -> bool {
    start.is_finite() && full.is_finite() && 0.0 <= start && start < full && full <= 1.0
}

impl Default for FurLevel {
    fn default() -> Self {
        Self::FULL
    }
}

/// The coarsest power-of-two stride that still leaves two shells (one for `layers` < 2).
fn max_stride(layers: u32) -> u32 {
    let mut stride = 1;
    while layers / (stride * 2) >= 2 {
        stride *= 2;
    }
    stride
}

/// How a level is picked from the fur's size on screen (`[render] lod` in presets).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSettings {
    /// Off: every frame draws [`FurLevel::FULL`].
    pub enabled: bool,
    /// Screen pixels each drawn shell should span along a strand: a fur whose strands cover
    /// fewer than `layers * pixels_per_shell` pixels drops layers.
    pub pixels_per_shell: f32,
    /// Shells by view angle ([`FurLevel::facing`]); `None`: by size on screen only.
    pub facing: Option<[f32; 2]>,
    /// Strand pixels `[gone, full]` over which the coat fades to the skin alone
    /// ([`FurLevel::coat`]), `0 <= gone < full`; `None`: the coat always drawn.
    pub coat_fade: Option<[f32; 2]>,
    /// Strand pixels `[gone, full]` over which the fins fade out ([`FurLevel::fins`]),
    /// `0 <= gone < full`; `None`: the fins drawn wherever the coat is.
    pub fin_fade: Option<[f32; 2]>,
}

impl Default for LodSettings {
    fn default() -> Self {
        Self {
            enabled: true,
            pixels_per_shell: 1.0,
            facing: Some(Self::DEFAULT_FACING),
            coat_fade: Some(Self::DEFAULT_COAT_FADE),
            fin_fade: Some(Self::DEFAULT_FIN_FADE),
        }
    }
}

impl LodSettings {
    /// No level of detail.
    pub const OFF: Self = Self { enabled: false, pixels_per_shell: 1.0, facing: None, coat_fade: None, fin_fade: None };

    /// The default coat fade ([`LodSettings::coat_fade`]): the shells and fins fade out as a
    /// strand shrinks from 0.6 to 0.3 pixels long, where a strand no longer shows as one.
    pub const DEFAULT_COAT_FADE: [f32; 2] = [0.3, 0.6];

    /// The default fin fade ([`LodSettings::fin_fade`]): the fins fade out as a strand shrinks
    /// from 2 to 1 pixel long, where a fin is a fringe a pixel or two wide that the outer shells
    /// already cover (BENCHMARKS.md: a herd of 1,000 Foxes draws in well under its time with fins).
    pub const DEFAULT_FIN_FADE: [f32; 2] = [1.0, 2.0];

    /// The default view-angle range ([`FurLevel::facing`]): layers start fading where the
    /// surface is within about 66 degrees of facing the eye and are gone within about 46
    /// (BENCHMARKS.md: SSIM 0.995 at the default framing, about 15% of the bunny's frame saved).
    pub const DEFAULT_FACING: [f32; 2] = [0.4, 0.7];

    /// The level for a fur of `layers` layers whose strands span `strand_pixels` on screen.
    #[must_use]
    pub fn level(&self, layers: u32, strand_pixels: f32) -> FurLevel {
        if !self.enabled || layers < 2 || !strand_pixels.is_finite() {
            return FurLevel::FULL;
        }
        let coat = fade(self.coat_fade, strand_pixels);
        let fins = fade(self.fin_fade, strand_pixels);
        let by_view = FurLevel { facing: self.facing, coat, fins, ..FurLevel::FULL };
        let wanted = (strand_pixels / self.pixels_per_shell.max(1e-3)).max(1e-3);
        let stride = f64::from(layers) / f64::from(wanted);
        if stride <= 1.0 {
            return by_view.clamped(layers);
        }
        let octave = stride.log2();
        let whole = octave.floor();
        FurLevel { stride: 1 << (whole as u32).min(16), blend: (octave - whole) as f32, ..by_view }.clamped(layers)
    }
}

/// A smooth step from 0 at `gone` strand pixels to 1 at `full`; 1 without a (valid) range.
fn fade(range: Option<[f32; 2]>, strand_pixels: f32) -> f32 {
    match range {
        Some([gone, full]) if gone.is_finite() && full.is_finite() && 0.0 <= gone && gone < full => {
            let t = ((strand_pixels - gone) / (full - gone)).clamp(0.0, 1.0);
            t * t * (3.0 - 2.0 * t)
        }
        _ => 1.0,
    }
}

/// How many pixels a strand of `length` world units spans at most on a fur inside the sphere
/// (`centre`, `radius`, world units) seen from `eye` (the sphere's nearest point counts).
#[must_use]
pub fn strand_pixels_in_view(
    length: f32,
    (centre, radius): (glam::Vec3, f32),
    eye: glam::Vec3,
    fov_y_rad: f32,
    viewport_height: u32,
) -> f32 {
    let distance = (eye.distance(centre) - radius).max(1e-3 * radius.max(1e-6));
    strand_pixels(length, distance, fov_y_rad, viewport_height)
}

/// How many pixels a strand of `length` world units spans at `distance` from a camera with
/// vertical field of view `fov_y_rad` and a viewport `viewport_height` pixels high (seen side on,
/// the most it can span).
#[must_use]
pub fn strand_pixels(length: f32, distance: f32, fov_y_rad: f32, viewport_height: u32) -> f32 {
    let pixels_per_unit = viewport_height as f32 / (2.0 * (fov_y_rad * 0.5).tan() * distance.max(1e-6));
    length * pixels_per_unit
}

/// The stride a fur was last prepared with, read back when its draw is recorded (`prepare` takes
/// `&self`, so hosts can prepare and draw through shared references).
#[derive(Debug)]
pub(crate) struct PreparedLevel {
    stride: std::sync::atomic::AtomicU32,
    /// Whether the level thins shells by view angle.
    by_view: std::sync::atomic::AtomicBool,
    /// Whether any of the coat shows ([`FurLevel::coat`] above 0).
    coat_shown: std::sync::atomic::AtomicBool,
    /// Whether any of the fins show (the coat and [`FurLevel::fins`] above 0).
    fins_shown: std::sync::atomic::AtomicBool,
}

impl PreparedLevel {
    pub fn new() -> Self {
        Self {
            stride: std::sync::atomic::AtomicU32::new(1),
            by_view: std::sync::atomic::AtomicBool::new(false),
            coat_shown: std::sync::atomic::AtomicBool::new(true),
            fins_shown: std::sync::atomic::AtomicBool::new(true),
        }
    }

    pub fn set(&self, level: FurLevel, layers: u32) {
        let level = level.clamped(layers);
        self.stride.store(level.stride, std::sync::atomic::Ordering::Relaxed);
        self.by_view.store(level.facing.is_some(), std::sync::atomic::Ordering::Relaxed);
        self.coat_shown.store(level.coat > 0.0, std::sync::atomic::Ordering::Relaxed);
        self.fins_shown.store(level.coat > 0.0 && level.fins > 0.0, std::sync::atomic::Ordering::Relaxed);
    }

    /// Whether any of the fins show: without, their silhouette pass and draw are skipped.
    pub fn fins_shown(&self) -> bool {
        self.fins_shown.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Whether any of the coat shows: without, the shells, fins and their passes are skipped.
    pub fn coat_shown(&self) -> bool {
        self.coat_shown.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// The stride (blend and facing left out: the draws need only the layers).
    pub fn get(&self) -> FurLevel {
        FurLevel { stride: self.stride.load(std::sync::atomic::Ordering::Relaxed), ..FurLevel::FULL }
    }

    /// Whether the level thins shells by view angle.
    pub fn by_view(&self) -> bool {
        self.by_view.load(std::sync::atomic::Ordering::Relaxed)
    }

    /// Whether shell `k` (0..shells) is one the next coarser stride drops (as `lod_dropped`).
    pub fn dropped_shell(&self, layers: u32, k: u32) -> bool {
        let shells = self.get().shells(layers);
        (shells - 1 - k) % 2 == 1
    }

    /// The layers drawn (as `lod_shell_layer` in `shading.wgsl`), innermost first.
    #[cfg(any(test, feature = "lab"))]
    pub fn shell_layers(&self, layers: u32) -> impl Iterator<Item = u32> {
        let level = self.get().clamped(layers);
        let shells = level.shells(layers);
        (0..shells).map(move |k| layers - (shells - 1 - k) * level.stride)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn full_until_strands_are_small_then_powers_of_two() {
        let lod = LodSettings { facing: None, coat_fade: None, ..LodSettings::default() };
        assert_eq!(lod.level(16, 40.0), FurLevel::FULL);
        assert_eq!(lod.level(16, 16.0), FurLevel::FULL);
        let half = lod.level(16, 8.0);
        assert_eq!((half.stride, half.blend), (2, 0.0));
        assert_eq!(half.shells(16), 8);
        let between = lod.level(16, 6.0);
        assert_eq!(between.stride, 2);
        assert!(between.blend > 0.0 && between.blend < 1.0, "{between:?}");
        // Never fewer than two shells.
        let far = lod.level(16, 0.01);
        assert_eq!((far.stride, far.blend, far.shells(16)), (8, 0.0, 2));
        assert_eq!(LodSettings::OFF.level(16, 0.01), FurLevel::FULL);
        assert_eq!(lod.level(1, 0.01), FurLevel::FULL);
    }

    #[test]
    fn view_angle_needs_a_coarser_stride_and_a_valid_range() {
        let lod = LodSettings::default();
        // Near: every layer, thinned by view angle toward every second one.
        let near = lod.level(16, 40.0);
        assert_eq!((near.stride, near.facing), (1, Some(LodSettings::DEFAULT_FACING)));
        assert_eq!(near.describe(16), "16/16 shells, to 8 facing the eye");
        // At the coarsest stride there is nothing to thin toward.
        assert_eq!(lod.level(16, 0.01).facing, None);
        assert_eq!(LodSettings::OFF.level(16, 40.0).facing, None);
        for bad in [[0.8, 0.8], [0.9, 0.5], [-0.1, 0.5], [0.2, 1.5], [f32::NAN, 0.5]] {
            let level = FurLevel { facing: Some(bad), ..FurLevel::FULL };
            assert_eq!(level.clamped(16).facing, None, "{bad:?}");
        }
        let prepared = PreparedLevel::new();
        prepared.set(near, 16);
        assert!(prepared.by_view());
        // Counted from the tips: shells 15, 13, .. are kept, 14, 12, .. dropped by stride 2.
        let dropped: Vec<u32> = (0..16).filter(|&k| prepared.dropped_shell(16, k)).collect();
        assert_eq!(dropped, [0, 2, 4, 6, 8, 10, 12, 14]);
    }

    #[test]
    fn blend_rises_continuously_with_distance() {
        // As strands shrink, (stride, blend) read as stride * 2^blend grows without jumps.
        let lod = LodSettings::default();
        let mut last = 1.0_f32;
        for step in 0..400 {
            let pixels = 16.0 * 0.99_f32.powi(step);
            let level = lod.level(16, pixels);
            let effective = level.stride as f32 * 2_f32.powf(level.blend);
            assert!(effective >= last - 1e-4, "at {pixels} px: {effective} after {last}");
            assert!(effective - last < 0.02 * last, "a jump at {pixels} px: {last} -> {effective}");
            last = effective;
        }
    }

    #[test]
    fn odd_layer_counts_and_bad_input() {
        assert_eq!(
            FurLevel { stride: 3, blend: 2.0, facing: None, coat: 1.0, fins: 1.0 }.clamped(16),
            FurLevel { stride: 4, blend: 1.0, facing: None, coat: 1.0, fins: 1.0 }
        );
        // 12 layers keep at least two shells: stride 4 is the coarsest, with nothing to blend to.
        assert_eq!(
            FurLevel { stride: 3, blend: 0.5, facing: None, coat: 1.0, fins: 1.0 }.clamped(12),
            FurLevel { stride: 4, blend: 0.0, facing: None, coat: 1.0, fins: 1.0 }
        );
        assert_eq!(
            FurLevel { stride: 64, blend: 0.5, facing: None, coat: 1.0, fins: 1.0 }.clamped(12),
            FurLevel { stride: 4, blend: 0.0, facing: None, coat: 1.0, fins: 1.0 }
        );
        assert_eq!(
            FurLevel { stride: 0, blend: f32::NAN, facing: None, coat: 1.0, fins: 1.0 }.clamped(12),
            FurLevel { stride: 1, blend: 0.0, facing: None, coat: 1.0, fins: 1.0 }
        );
        assert_eq!(FurLevel { stride: 4, blend: 0.0, facing: None, coat: 1.0, fins: 1.0 }.shells(12), 3);
        assert_eq!(LodSettings::default().level(16, f32::NAN), FurLevel::FULL);
        assert!(strand_pixels(0.1, 0.0, 0.8, 720).is_finite());
    }

    /// `share` of strand pixels falls from 1 above `full` to 0 as strands shrink by 1% a step,
    /// never rising and never by 0.05 or more in one step.
    fn assert_fades_without_a_jump(full: f32, share: impl Fn(f32) -> f32) {
        let mut last = 1.0_f32;
        for step in 0..200 {
            let pixels = full * 1.2 * 0.99_f32.powi(step);
            let now = share(pixels);
            assert!(now <= last && last - now < 0.05, "a jump at {pixels} px: {last} -> {now}");
            last = now;
        }
        assert_eq!(last, 0.0);
    }

    #[test]
    fn the_coat_fades_to_the_skin_continuously_as_strands_shrink() {
        let lod = LodSettings::default();
        let [gone, full] = LodSettings::DEFAULT_COAT_FADE;
        assert_eq!(lod.level(16, full).coat, 1.0);
        assert_eq!(lod.level(16, 40.0).coat, 1.0);
        assert_eq!(lod.level(16, gone).coat, 0.0);
        assert_eq!(lod.level(16, 0.01).describe(16), "the skin alone in the coat's colour");
        assert_fades_without_a_jump(full, |pixels| lod.level(16, pixels).coat);
        assert_eq!(LodSettings { coat_fade: None, ..lod }.level(16, 0.01).coat, 1.0);
        assert_eq!(LodSettings { coat_fade: Some([0.5, 0.5]), ..lod }.level(16, 0.01).coat, 1.0);
        assert_eq!(FurLevel { coat: f32::NAN, ..FurLevel::FULL }.clamped(16).coat, 1.0);
    }

    #[test]
    fn the_fins_fade_out_continuously_before_the_coat_and_then_skip_their_passes() {
        let lod = LodSettings::default();
        let [gone, full] = LodSettings::DEFAULT_FIN_FADE;
        assert!(gone > LodSettings::DEFAULT_COAT_FADE[1], "the fins go while the coat still shows");
        assert_eq!(lod.level(16, full).fins, 1.0);
        assert_eq!(lod.level(16, gone).fins, 0.0);
        assert_eq!(lod.level(16, gone).coat, 1.0);
        assert!(lod.level(16, gone).describe(16).ends_with(", no fins"), "{}", lod.level(16, gone).describe(16));
        assert_fades_without_a_jump(full, |pixels| lod.level(16, pixels).fins);
        assert_eq!(LodSettings { fin_fade: None, ..lod }.level(16, 0.5).fins, 1.0);
        assert_eq!(FurLevel { fins: f32::INFINITY, ..FurLevel::FULL }.clamped(16).fins, 1.0);
        // What the renderer reads back: the fins' pass and draw go with the fins or the coat.
        let prepared = PreparedLevel::new();
        assert!(prepared.fins_shown());
        prepared.set(lod.level(16, 0.5 * (gone + full)), 16);
        assert!(prepared.fins_shown() && prepared.coat_shown());
        prepared.set(lod.level(16, gone), 16);
        assert!(!prepared.fins_shown() && prepared.coat_shown());
        prepared.set(FurLevel { coat: 0.0, ..FurLevel::FULL }, 16);
        assert!(!prepared.fins_shown());
    }

    #[test]
    fn drawn_layers_end_at_the_tips() {
        let prepared = PreparedLevel::new();
        assert_eq!(prepared.shell_layers(4).collect::<Vec<_>>(), [1, 2, 3, 4]);
        prepared.set(FurLevel { stride: 4, blend: 0.3, facing: None, coat: 1.0, fins: 1.0 }, 12);
        assert_eq!(prepared.shell_layers(12).collect::<Vec<_>>(), [4, 8, 12]);
        prepared.set(FurLevel { stride: 4, blend: 0.0, facing: None, coat: 1.0, fins: 1.0 }, 10);
        assert_eq!(prepared.shell_layers(10).collect::<Vec<_>>(), [6, 10]);
    }

    #[test]
    fn far_furs_are_stepped_less_often() {
        let lod = LodSettings::default();
        // Near: every step; strands a few pixels long: every second; a fading coat: every fourth.
        assert_eq!(lod.level(16, 40.0).step_stride(), 1);
        assert_eq!(lod.level(16, 8.0).step_stride(), 1);
        assert_eq!(lod.level(16, 2.0).step_stride(), 2);
        assert_eq!(lod.level(16, 0.4).step_stride(), 4);
        // The stride never falls as the fur shrinks.
        let strides: Vec<u32> = (0..200).map(|k| lod.level(16, 40.0 * 0.97f32.powi(k)).step_stride()).collect();
        assert!(strides.windows(2).all(|w| w[0] <= w[1]), "{strides:?}");
    }
}
