//! The side panel: every setting of the fur, live, plus the keyboard shortcuts.

use pelt_core::texture::{ColourMode, Rgb, Style};
use pelt_core::{Builtin, Preset};

use super::wet::{WetChanges, WetControls, wet_ui};

/// The keyboard shortcuts, shown in the panel (and in the README).
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("F", "frame the fur"),
    ("R", "reset the view"),
    ("Space", "pause or resume the simulation"),
    ("1 / 2 / 3", "skin / shells / fins on or off"),
    ("U", "unified or separated structure"),
    ("W", "wind on or off"),
    ("[ / ]", "smaller / larger brush"),
    ("Ctrl+Z / Ctrl+Shift+Z", "undo / redo a groom stroke"),
    ("H", "hide or show the panel"),
    ("O", "overlay on or off"),
    ("Ctrl+S", "save the preset"),
    ("Ctrl+P", "save a screenshot"),
    ("Ctrl+Q", "quit"),
];

/// The mouse, shown under the shortcuts.
pub const MOUSE: &[(&str, &str)] = &[
    ("left-drag on fur", "pat the fur (release restores it), or paint the groom"),
    ("left-drag off fur, right-drag", "orbit"),
    ("middle-drag, Shift+drag", "pan"),
    ("Ctrl+drag", "move the key light (with the sponge on: dry the fur)"),
    ("wheel", "zoom"),
    ("Alt+left-drag", "orbit, even over fur"),
];

/// Which mesh the fur grows on.
#[derive(Clone, Debug, PartialEq)]
pub enum MeshChoice {
    Builtin(Builtin),
    /// The paper's virtual try-on: a furry skirt on a body.
    TryOn,
    /// The mesh given on the command line.
    File(String),
}

impl MeshChoice {
    pub fn label(&self) -> String {
        match self {
            Self::Builtin(builtin) => builtin.name().to_owned(),
            Self::TryOn => "tryon (skirt on a body)".to_owned(),
            Self::File(name) => name.clone(),
        }
    }
}

/// What draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DrawToggles {
    pub skin: bool,
    pub shells: bool,
    pub fins: bool,
    /// The unified structure (true) or the separated one of Lengyel et al. (false).
    pub unified: bool,
    /// A body's collision capsules over the body (a script's colliders are always drawn).
    pub body_colliders: bool,
    /// The key light's shadow maps (the fur's deep opacity map included).
    pub shadows: bool,
    /// A ground under the meshes, taking their shadow.
    pub ground: bool,
}

impl Default for DrawToggles {
    fn default() -> Self {
        Self {
            skin: true,
            shells: true,
            fins: true,
            unified: true,
            body_colliders: false,
            shadows: false,
            ground: false,
        }
    }
}

/// Everything the panel edits.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub mesh: MeshChoice,
    pub preset: Preset,
    pub simulate: bool,
    /// Touch brush radius as a fraction of the mesh's bounding radius.
    pub brush_per_radius: f32,
    pub draw: DrawToggles,
    /// Bend the strands on the GPU (a compute pass) rather than the CPU.
    pub gpu_sim: bool,
    pub overlay: bool,
    /// Where Load and Save read and write the preset.
    pub preset_path: String,
    /// The animated file's clips and what plays.
    pub animation: AnimationSettings,
    /// Groom painting.
    pub paint: super::paint::PaintSettings,
    /// Rain, water, the sponge and the coat's wetness.
    pub wet: WetControls,
    /// The ball and the grab.
    pub contact: super::contact::ContactControls,
    /// The lights and the environment.
    pub lights: super::lights::LightSettings,
}

/// The animation controls: which clip, playing or not, speed and the timeline.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AnimationSettings {
    /// `(name, duration in seconds)` of every clip of the file (empty: no animation section).
    pub clips: Vec<(String, f32)>,
    /// The clip that plays; `None` is the rest pose.
    pub clip: Option<usize>,
    pub playing: bool,
    pub speed: f32,
    /// Time in the clip, seconds.
    pub time_secs: f32,
}

impl Settings {
    pub fn new(mesh: MeshChoice, preset: Preset, preset_path: String) -> Self {
        Self {
            mesh,
            preset,
            simulate: true,
            brush_per_radius: 0.25,
            draw: DrawToggles::default(),
            gpu_sim: false,
            overlay: true,
            preset_path,
            animation: AnimationSettings::default(),
            paint: super::paint::PaintSettings::default(),
            wet: WetControls::default(),
            contact: super::contact::ContactControls::default(),
            lights: super::lights::LightSettings::default(),
        }
    }
}

/// What a panel pass changed, so the app rebuilds only what depends on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Changes {
    pub mesh: bool,
    /// Layers, length or direction: the shared vertex array.
    pub structure: bool,
    /// The strand field or its colours.
    pub textures: bool,
    pub simulation: bool,
    /// Another clip: the fur starts over from its first pose.
    pub animation: bool,
    /// The CPU/GPU simulation toggle.
    pub kernel: bool,
    /// The groom is the preset's again (a preset was loaded): painting starts over from it.
    pub groom: bool,
    /// Wetness, rain, water or `[wet]`.
    pub wet: WetChanges,
}

impl Changes {
    pub fn merge(&mut self, other: Self) {
        self.animation |= other.animation;
        self.mesh |= other.mesh;
        self.structure |= other.structure;
        self.textures |= other.textures;
        self.simulation |= other.simulation;
        self.kernel |= other.kernel;
        self.groom |= other.groom;
        self.wet.merge(other.wet);
    }
}

/// Buttons pressed this pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Requests {
    pub frame: bool,
    pub screenshot: bool,
    pub save_preset: bool,
    pub load_preset: bool,
    /// Undo or redo a groom stroke.
    pub undo: bool,
    pub redo: bool,
    /// Take the ball out of the fur.
    pub remove_ball: bool,
}

impl Requests {
    pub fn merge(&mut self, other: Self) {
        self.frame |= other.frame;
        self.screenshot |= other.screenshot;
        self.save_preset |= other.save_preset;
        self.load_preset |= other.load_preset;
        self.undo |= other.undo;
        self.redo |= other.redo;
        self.remove_ball |= other.remove_ball;
    }
}

/// The clip picker, play/pause, speed and timeline; true when another clip was picked.
fn animation_ui(ui: &mut egui::Ui, animation: &mut AnimationSettings) -> bool {
    const REST: &str = "none (rest pose)";
    let names: Vec<String> = animation.clips.iter().map(|(name, secs)| format!("{name} ({secs:.2} s)")).collect();
    let selected = animation.clip.map_or(REST.to_owned(), |k| names[k].clone());
    let mut changed = false;
    egui::ComboBox::from_label("animation").selected_text(selected).show_ui(ui, |ui| {
        changed |= ui.selectable_value(&mut animation.clip, None, REST).changed();
        for (k, name) in names.iter().enumerate() {
            changed |= ui.selectable_value(&mut animation.clip, Some(k), name.as_str()).changed();
        }
    });
    ui.checkbox(&mut animation.playing, "playing");
    ui.add(egui::Slider::new(&mut animation.speed, 0.0..=3.0).text("speed"));
    let duration = animation.clip.map_or(0.0, |k| animation.clips[k].1);
    ui.add_enabled(
        duration > 0.0,
        egui::Slider::new(&mut animation.time_secs, 0.0..=duration.max(1e-3)).text("time (s)"),
    );
    changed
}

/// Draws the panel's contents; returns what changed and what was asked for.
pub fn show(
    ui: &mut egui::Ui,
    settings: &mut Settings,
    (mesh_choices, placement): (&[MeshChoice], &super::lights::Placement),
    status: &str,
) -> (Changes, Requests) {
    let mut changes = Changes::default();
    let mut requests = Requests::default();
    ui.add_space(4.0);
    ui.heading("Pelt");
    ui.weak("shells and fins on one shared vertex array");
    ui.separator();
    egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
        section(ui, "Mesh and preset", true, |ui| {
            egui::ComboBox::from_label("mesh").selected_text(settings.mesh.label()).show_ui(ui, |ui| {
                for choice in mesh_choices {
                    changes.mesh |= ui.selectable_value(&mut settings.mesh, choice.clone(), choice.label()).changed();
                }
            });
            ui.horizontal(|ui| {
                ui.label("preset");
                let width = ui.available_width();
                ui.add(egui::TextEdit::singleline(&mut settings.preset_path).desired_width(width));
            });
            ui.horizontal_wrapped(|ui| {
                requests.load_preset |= ui.button("Load").clicked();
                requests.save_preset |= ui.button("Save (Ctrl+S)").clicked();
                requests.screenshot |= ui.button("Screenshot (Ctrl+P)").clicked();
                requests.frame |= ui.button("Frame (F)").clicked();
            });
            if !status.is_empty() {
                ui.label(egui::RichText::new(status).small().weak());
            }
        });
        if !settings.animation.clips.is_empty() {
            section(ui, "Animation", true, |ui| changes.animation |= animation_ui(ui, &mut settings.animation));
        }
        let preset = &mut settings.preset;
        section(ui, "Shape", true, |ui| {
            let layers = ui.add(egui::Slider::new(&mut preset.layers, 1..=64).text("layers")).changed();
            changes.structure |= layers;
            changes.textures |= layers;
            changes.structure |=
                ui.add(egui::Slider::new(&mut preset.length, 0.01..=0.6).text("length (x radius)")).changed();
            let direction = &mut preset.direction;
            changes.structure |= ui
                .add(egui::Slider::new(&mut direction.random_angle_deg, 0.0..=80.0).text("randomise (deg)"))
                .changed();
            changes.structure |= ui.add(egui::Slider::new(&mut direction.comb_blend, 0.0..=1.0).text("comb")).changed();
            ui.horizontal(|ui| {
                ui.label("comb toward");
                for (axis, value) in
                    [("x ", &mut direction.comb.x), ("y ", &mut direction.comb.y), ("z ", &mut direction.comb.z)]
                {
                    changes.structure |=
                        ui.add(egui::DragValue::new(value).speed(0.02).range(-1.0..=1.0).prefix(axis)).changed();
                }
            });
            changes.structure |= ui.add(egui::DragValue::new(&mut direction.seed).prefix("direction seed ")).changed();
        });
        section(ui, "Groom", false, |ui| {
            let painted = super::paint::section_ui(ui, &mut settings.paint, &mut settings.brush_per_radius);
            requests.undo |= painted.undo;
            requests.redo |= painted.redo;
        });
        section(ui, "Strands", true, |ui| {
            let texture = &mut preset.texture;
            let before = texture.clone();
            egui::ComboBox::from_label("tile size").selected_text(texture.size.to_string()).show_ui(ui, |ui| {
                for size in [64, 128, 256, 512, 1024] {
                    ui.selectable_value(&mut texture.size, size, size.to_string());
                }
            });
            ui.add(egui::Slider::new(&mut texture.density, 0.0..=1.0).text("density"));
            ui.add(egui::Slider::new(&mut texture.thickness, 0.25..=16.0).logarithmic(true).text("thickness"));
            ui.add(egui::Slider::new(&mut texture.taper, 0.0..=1.0).text("taper"));
            ui.add(egui::Slider::new(&mut texture.root_blur, 0.0..=8.0).text("root blur"));
            ui.add(egui::Slider::new(&mut texture.length_variation, 0.0..=0.95).text("length variation"));
            ui.horizontal(|ui| {
                ui.label("style");
                ui.selectable_value(&mut texture.style, Style::Straight, "straight");
                ui.selectable_value(&mut texture.style, Style::Random, "random");
                ui.selectable_value(&mut texture.style, Style::Mixed, "mixed");
            });
            if texture.style == Style::Mixed {
                ui.add(egui::Slider::new(&mut texture.mixed_ratio, 0.0..=1.0).text("mixed ratio"));
            }
            ui.add(egui::Slider::new(&mut texture.lean, 0.0..=64.0).text("lean"));
            ui.add(egui::Slider::new(&mut texture.curl_radius, 0.0..=32.0).text("curl radius"));
            ui.add(egui::Slider::new(&mut texture.curl_turns, 0.0..=16.0).text("curl turns"));
            ui.add(egui::Slider::new(&mut texture.clump, 0.0..=1.0).text("clumping"));
            let largest_clump = texture.size as f32;
            ui.add(
                egui::Slider::new(&mut texture.clump_size, 2.0..=largest_clump).logarithmic(true).text("clump size"),
            );
            ui.add(egui::DragValue::new(&mut texture.seed).prefix("strand seed "));
            changes.textures |= *texture != before;
        });
        section(ui, "Colour", true, |ui| {
            changes.textures |= colour_ui(ui, &mut preset.colour);
        });
        section(ui, "Simulation", true, |ui| {
            changes.simulation |= ui.checkbox(&mut settings.simulate, "running (Space)").changed();
            changes.kernel |= ui.checkbox(&mut settings.gpu_sim, "on the GPU (compute pass)").changed();
            let sim = &mut preset.simulation;
            let before = sim.clone();
            ui.add(egui::Slider::new(&mut sim.stability, 0.5..=200.0).logarithmic(true).text("stability"));
            ui.add(egui::Slider::new(&mut sim.gravity_strength, 0.0..=5.0).text("gravity"));
            ui.horizontal(|ui| {
                ui.label("gravity toward");
                let down = &mut sim.gravity_direction;
                for (axis, value) in [("x ", &mut down.x), ("y ", &mut down.y), ("z ", &mut down.z)] {
                    ui.add(egui::DragValue::new(value).speed(0.02).range(-1.0..=1.0).prefix(axis));
                }
            });
            if sim.gravity_direction.length_squared() == 0.0 {
                sim.gravity_direction = before.gravity_direction;
            }
            ui.add(egui::Slider::new(&mut sim.rate_hz, 1.0..=240.0).logarithmic(true).text("rate (Hz)"));
            ui.checkbox(&mut sim.interpolate, "interpolate between steps");
            ui.label(egui::RichText::new("Wind").strong());
            let wind = &mut sim.wind;
            ui.add(egui::Slider::new(&mut wind.strength, 0.0..=5.0).text("strength (W)"));
            ui.horizontal(|ui| {
                ui.label("direction");
                for (axis, value) in
                    [("x ", &mut wind.direction.x), ("y ", &mut wind.direction.y), ("z ", &mut wind.direction.z)]
                {
                    ui.add(egui::DragValue::new(value).speed(0.02).range(-1.0..=1.0).prefix(axis));
                }
            });
            ui.add(egui::Slider::new(&mut wind.gust_strength, 0.0..=1.0).text("gusts"));
            ui.add(egui::Slider::new(&mut wind.gust_scale, 0.05..=4.0).logarithmic(true).text("gust size"));
            ui.add(egui::Slider::new(&mut wind.gust_speed, 0.0..=8.0).text("gust speed"));
            ui.add(egui::Slider::new(&mut wind.jitter, 0.0..=1.0).text("shake"));
            ui.label(egui::RichText::new("Touch").strong());
            ui.add(egui::Slider::new(&mut sim.touch.strength, 0.0..=20.0).text("strength"));
            ui.add(egui::Slider::new(&mut sim.touch.release_secs, 0.0..=3.0).text("release (s)"));
            ui.add(egui::Slider::new(&mut settings.brush_per_radius, 0.02..=1.0).logarithmic(true).text("brush ([ ])"));
            if wind.direction.length_squared() == 0.0 {
                wind.direction = before.wind.direction;
            }
            changes.simulation |= *sim != before;
        });
        section(ui, "Wet", true, |ui| changes.wet.merge(wet_ui(ui, &mut settings.wet, &mut settings.preset.wet)));
        section(ui, "Contact", true, |ui| {
            requests.remove_ball |= super::contact::contact_ui(ui, &mut settings.contact)
        });
        section(ui, "Drawing", true, |ui| {
            let draw = &mut settings.draw;
            ui.horizontal(|ui| {
                ui.checkbox(&mut draw.skin, "skin (1)");
                ui.checkbox(&mut draw.shells, "shells (2)");
                ui.checkbox(&mut draw.fins, "fins (3)");
            });
            ui.horizontal(|ui| {
                ui.radio_value(&mut draw.unified, true, "unified");
                ui.radio_value(&mut draw.unified, false, "separated (U)");
            });
            ui.checkbox(&mut draw.body_colliders, "the body's collision capsules");
            ui.horizontal(|ui| {
                ui.checkbox(&mut draw.shadows, "shadows").on_hover_text("the key light's, the fur's own included");
                ui.checkbox(&mut draw.ground, "ground");
            });
            ui.checkbox(&mut settings.overlay, "overlay (O)");
        });
        section(ui, "Lights", false, |ui| {
            super::lights::lights_ui(ui, &mut settings.lights, placement);
        });
        section(ui, "Shortcuts", false, |ui| {
            egui::Grid::new("shortcuts").num_columns(2).striped(true).show(ui, |ui| {
                for (key, action) in SHORTCUTS.iter().chain(MOUSE) {
                    ui.monospace(*key);
                    ui.label(*action);
                    ui.end_row();
                }
            });
        });
    });
    (changes, requests)
}

/// Colour mode, the single colour, and the height map's gradient editor; true when changed.
fn colour_ui(ui: &mut egui::Ui, colour: &mut pelt_core::texture::ColourParams) -> bool {
    let before = colour.clone();
    ui.horizontal(|ui| {
        ui.label("mode");
        ui.selectable_value(&mut colour.mode, ColourMode::Single, "single");
        ui.selectable_value(&mut colour.mode, ColourMode::Height, "height map");
        ui.add_enabled_ui(colour.surface.is_some(), |ui| {
            ui.selectable_value(&mut colour.mode, ColourMode::Surface, "surface")
                .on_disabled_hover_text("a preset with colour.surface (an image) enables this");
        });
    });
    match colour.mode {
        ColourMode::Single | ColourMode::Surface => {
            ui.horizontal(|ui| {
                ui.color_edit_button_srgb(&mut colour.colour.0);
                ui.label("strand colour");
            });
        }
        ColourMode::Height => {
            if colour.height_colours.is_empty() && colour.gradient.is_none() {
                // Start the map from the single colour: darker roots, lighter tips.
                let [r, g, b] = colour.colour.0;
                let scale = |c: u8, f: f32| (f32::from(c) * f).min(255.0) as u8;
                colour.height_colours = vec![
                    Rgb([scale(r, 0.45), scale(g, 0.45), scale(b, 0.45)]),
                    colour.colour,
                    Rgb([scale(r, 1.6), scale(g, 1.6), scale(b, 1.6)]),
                ];
            }
            gradient_editor(ui, &mut colour.height_colours);
            if colour.gradient.is_some() {
                ui.weak("the preset's gradient image is used while the list is empty");
            }
            ui.add(egui::Slider::new(&mut colour.height_levels, 2..=256).text("levels"));
        }
    }
    ui.add(egui::Slider::new(&mut colour.brightness_variation, 0.0..=1.0).text("brightness variation"));
    *colour != before
}

/// A root-to-tip bar of the stops, and a row per stop to recolour, move or remove it.
fn gradient_editor(ui: &mut egui::Ui, stops: &mut Vec<Rgb>) {
    let width = ui.available_width().min(260.0);
    let (rect, _) = ui.allocate_exact_size(egui::vec2(width, 16.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    let steps = 64;
    for i in 0..steps {
        let t = (i as f32 + 0.5) / steps as f32;
        let x0 = rect.left() + rect.width() * i as f32 / steps as f32;
        let x1 = rect.left() + rect.width() * (i + 1) as f32 / steps as f32;
        let [r, g, b] = sample_gradient(stops, t);
        painter.rect_filled(
            egui::Rect::from_x_y_ranges(x0..=x1 + 0.5, rect.y_range()),
            0.0,
            egui::Color32::from_rgb(r, g, b),
        );
    }
    ui.horizontal(|ui| {
        ui.weak("root");
        ui.add_space((width - 60.0).max(0.0));
        ui.weak("tip");
    });
    let mut remove = None;
    let mut swap = None;
    let count = stops.len();
    for (i, stop) in stops.iter_mut().enumerate() {
        ui.horizontal(|ui| {
            ui.color_edit_button_srgb(&mut stop.0);
            ui.monospace(stop.to_string());
            if ui.add_enabled(i > 0, egui::Button::new("^").small()).on_hover_text("toward the root").clicked() {
                swap = Some(i - 1);
            }
            if ui.add_enabled(i + 1 < count, egui::Button::new("v").small()).on_hover_text("toward the tip").clicked() {
                swap = Some(i);
            }
            if ui.add_enabled(count > 2, egui::Button::new("x").small()).on_hover_text("remove").clicked() {
                remove = Some(i);
            }
        });
    }
    if let Some(i) = swap {
        stops.swap(i, i + 1);
    }
    if let Some(i) = remove {
        stops.remove(i);
    }
    if ui.button("+ add a tip colour").clicked() {
        let last = stops.last().copied().unwrap_or(Rgb([200, 180, 150]));
        stops.push(last);
    }
}

/// The colour at `t` (0 = root, 1 = tip) of evenly spread stops.
pub fn sample_gradient(stops: &[Rgb], t: f32) -> [u8; 3] {
    match stops {
        [] => [0, 0, 0],
        [only] => only.0,
        _ => {
            let position = t.clamp(0.0, 1.0) * (stops.len() - 1) as f32;
            let index = (position.floor() as usize).min(stops.len() - 2);
            let fraction = position - index as f32;
            let (a, b) = (stops[index].0, stops[index + 1].0);
            [0, 1, 2].map(|c| (f32::from(a[c]) + (f32::from(b[c]) - f32::from(a[c])) * fraction).round() as u8)
        }
    }
}

fn section(ui: &mut egui::Ui, title: &str, open: bool, contents: impl FnOnce(&mut egui::Ui)) {
    egui::CollapsingHeader::new(egui::RichText::new(title).strong()).default_open(open).show(ui, contents);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_gradient_preview_runs_from_the_root_stop_to_the_tip_stop() {
        let stops = [Rgb([0, 0, 0]), Rgb([100, 200, 50]), Rgb([200, 0, 250])];
        assert_eq!(sample_gradient(&stops, 0.0), [0, 0, 0]);
        assert_eq!(sample_gradient(&stops, 0.5), [100, 200, 50]);
        assert_eq!(sample_gradient(&stops, 1.0), [200, 0, 250]);
        assert_eq!(sample_gradient(&stops, 0.25), [50, 100, 25]);
        assert_eq!(sample_gradient(&[Rgb([9, 8, 7])], 0.7), [9, 8, 7]);
    }
}
