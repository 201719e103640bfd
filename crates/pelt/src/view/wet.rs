//! The panel's wet section and what it drives: the coat's wetness (shown and set), rain, a
//! water level, the sponge brush, and the preset's `[wet]` (drying, look, weight).

use glam::Vec3;
use pelt_core::Scene;
use pelt_core::wet::{RainKey, WaterKey, WetParams};

/// The live wet controls (the preset's `[wet]` is edited beside them).
#[derive(Clone, Debug, PartialEq)]
pub struct WetControls {
    /// Left-drag on the fur wets it (Ctrl dries) instead of patting it.
    pub sponge: bool,
    /// Rain falling straight down at this rate (wetness per second); 0 is none.
    pub rain_rate: f32,
    pub water: bool,
    /// The water level as a fraction of the mesh's height, 0 at its lowest point.
    pub water_level: f32,
    /// The mean and largest wetness of the coat at the last frame (shown, not edited).
    pub shown: [f32; 2],
}

impl Default for WetControls {
    fn default() -> Self {
        Self { sponge: false, rain_rate: 0.0, water: false, water_level: 0.3, shown: [0.0; 2] }
    }
}

/// What the wet section changed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WetChanges {
    /// Rain or the water level: the scene's wet keys.
    pub sources: bool,
    /// The preset's `[wet]`.
    pub params: bool,
    /// The whole coat set to the wetness slider's value.
    pub uniform: bool,
}

impl WetChanges {
    pub fn merge(&mut self, other: Self) {
        self.sources |= other.sources;
        self.params |= other.params;
        self.uniform |= other.uniform;
    }

    pub fn any(self) -> bool {
        self.sources || self.params || self.uniform
    }
}

pub fn wet_ui(ui: &mut egui::Ui, controls: &mut WetControls, wet: &mut WetParams) -> WetChanges {
    let mut changes = WetChanges::default();
    let [mean, largest] = controls.shown;
    ui.label(format!("wetness now: mean {mean:.2}, largest {largest:.2}"));
    changes.uniform |= ui.add(egui::Slider::new(&mut wet.wetness, 0.0..=1.0).text("whole coat")).changed();
    changes.params |= changes.uniform;
    changes.sources |= ui.add(egui::Slider::new(&mut controls.rain_rate, 0.0..=3.0).text("rain (per s)")).changed();
    ui.horizontal(|ui| {
        changes.sources |= ui.checkbox(&mut controls.water, "water").changed();
        changes.sources |= ui
            .add_enabled(controls.water, egui::Slider::new(&mut controls.water_level, 0.0..=1.0).text("level"))
            .changed();
    });
    ui.checkbox(&mut controls.sponge, "sponge: left-drag wets (Ctrl dries)");
    let before = wet.clone();
    ui.add(egui::Slider::new(&mut wet.drying_per_sec, 0.0..=2.0).text("drying (per s)"));
    ui.add(egui::Slider::new(&mut wet.darkening, 0.0..=1.0).text("darkening"));
    ui.add(egui::Slider::new(&mut wet.shine, 0.0..=4.0).text("shine"));
    ui.add(egui::Slider::new(&mut wet.clump_strength, 0.0..=1.0).text("clumping"));
    ui.add(egui::Slider::new(&mut wet.clump_size, 2.0..=128.0).logarithmic(true).text("clump size (texels)"));
    ui.add(egui::Slider::new(&mut wet.added_weight, 0.0..=5.0).text("added weight"));
    ui.add(egui::Slider::new(&mut wet.softening, 0.0..=0.9).text("softening"));
    ui.add(egui::Slider::new(&mut wet.wicking, 0.0..=1.0).text("wicking band"));
    changes.params |= *wet != before;
    changes
}

/// The scene the stepper plays: the command line's script with the panel's rain and water
/// added. `heights` is the mesh's lowest and highest y.
pub fn scene_with_sources(script: Option<&Scene>, controls: &WetControls, heights: [f32; 2]) -> Option<Scene> {
    let mut scene = script.cloned().unwrap_or_default();
    if controls.rain_rate > 0.0 {
        scene.rain.push(RainKey { start_secs: 0.0, end_secs: 1e12, direction: Vec3::NEG_Y, rate: controls.rain_rate });
    }
    if controls.water {
        let y = heights[0] + controls.water_level * (heights[1] - heights[0]);
        scene.water = vec![WaterKey { time_secs: 0.0, point: Vec3::new(0.0, y, 0.0), normal: Vec3::Y }];
    }
    (script.is_some() || !scene.rain.is_empty() || !scene.water.is_empty()).then_some(scene)
}
