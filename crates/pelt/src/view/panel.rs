//! The side panel: every setting of the fur, live, plus the keyboard shortcuts.

use glam::Vec3;
use pelt_core::Builtin;
use pelt_core::sim::SimParams;

/// The keyboard shortcuts, shown in the panel (and in the README).
pub const SHORTCUTS: &[(&str, &str)] = &[
    ("F", "frame the fur"),
    ("R", "reset the view"),
    ("Space", "pause or resume the simulation"),
    ("1 / 2 / 3", "skin / shells / fins on or off"),
    ("W", "wind on or off"),
    ("[ / ]", "smaller / larger brush"),
    ("H", "hide or show the panel"),
    ("O", "overlay on or off"),
    ("Ctrl+P", "save a screenshot"),
    ("Ctrl+Q", "quit"),
];

/// The mouse, shown under the shortcuts.
pub const MOUSE: &[(&str, &str)] = &[
    ("left-drag on fur", "pat the fur (release restores it)"),
    ("left-drag off fur, right-drag", "orbit"),
    ("middle-drag, Shift+drag", "pan"),
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
            Self::TryOn => "try-on (skirt on a body)".to_owned(),
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
}

impl Default for DrawToggles {
    fn default() -> Self {
        Self { skin: true, shells: true, fins: true, unified: true }
    }
}

/// Everything the panel edits.
#[derive(Clone, Debug, PartialEq)]
pub struct Settings {
    pub mesh: MeshChoice,
    pub layers: u32,
    /// Fur length as a fraction of the mesh's bounding radius, so any mesh starts sensible.
    pub length_per_radius: f32,
    pub random_angle_deg: f32,
    pub direction_seed: u64,
    pub comb: Vec3,
    pub comb_blend: f32,
    pub sim: SimParams,
    pub simulate: bool,
    /// Touch brush radius as a fraction of the mesh's bounding radius.
    pub brush_per_radius: f32,
    pub draw: DrawToggles,
    pub overlay: bool,
}

impl Settings {
    pub fn new(mesh: MeshChoice) -> Self {
        Self {
            mesh,
            layers: 16,
            length_per_radius: 0.12,
            random_angle_deg: 0.0,
            direction_seed: 1,
            comb: Vec3::NEG_Y,
            comb_blend: 0.0,
            sim: SimParams::default(),
            simulate: true,
            brush_per_radius: 0.25,
            draw: DrawToggles::default(),
            overlay: true,
        }
    }
}

/// What a panel pass changed, so the app rebuilds only what depends on it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Changes {
    pub mesh: bool,
    pub structure: bool,
    pub simulation: bool,
}

/// Buttons pressed this pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Requests {
    pub frame: bool,
    pub screenshot: bool,
}

/// Draws the panel's contents; returns what changed and what was asked for.
pub fn show(
    ui: &mut egui::Ui,
    settings: &mut Settings,
    mesh_choices: &[MeshChoice],
    status: &str,
) -> (Changes, Requests) {
    let mut changes = Changes::default();
    let mut requests = Requests::default();
    ui.heading("Pelt");
    ui.weak("real-time fur: shells and fins on one shared vertex array");
    ui.separator();
    egui::ScrollArea::vertical().auto_shrink([false, false]).show(ui, |ui| {
        section(ui, "Mesh", true, |ui| {
            egui::ComboBox::from_label("mesh").selected_text(settings.mesh.label()).show_ui(ui, |ui| {
                for choice in mesh_choices {
                    changes.mesh |= ui.selectable_value(&mut settings.mesh, choice.clone(), choice.label()).changed();
                }
            });
            requests.frame |= ui.button("Frame (F)").clicked();
        });
        section(ui, "Fur", true, |ui| {
            changes.structure |= ui.add(egui::Slider::new(&mut settings.layers, 1..=64).text("layers")).changed();
            changes.structure |= ui
                .add(egui::Slider::new(&mut settings.length_per_radius, 0.0..=0.5).text("length (x radius)"))
                .changed();
        });
        section(ui, "Direction", false, |ui| {
            changes.structure |=
                ui.add(egui::Slider::new(&mut settings.random_angle_deg, 0.0..=80.0).text("randomise (deg)")).changed();
            changes.structure |= ui.add(egui::DragValue::new(&mut settings.direction_seed).prefix("seed ")).changed();
            changes.structure |= ui.add(egui::Slider::new(&mut settings.comb_blend, 0.0..=1.0).text("comb")).changed();
            ui.horizontal(|ui| {
                ui.label("comb toward");
                for (axis, value) in
                    [("x", &mut settings.comb.x), ("y", &mut settings.comb.y), ("z", &mut settings.comb.z)]
                {
                    changes.structure |=
                        ui.add(egui::DragValue::new(value).speed(0.02).range(-1.0..=1.0).prefix(axis)).changed();
                }
            });
        });
        section(ui, "Simulation", true, |ui| {
            let sim = &mut settings.sim;
            changes.simulation |= ui.checkbox(&mut settings.simulate, "running (Space)").changed();
            changes.simulation |= ui
                .add(egui::Slider::new(&mut sim.stability, 0.5..=100.0).logarithmic(true).text("stability"))
                .changed();
            changes.simulation |=
                ui.add(egui::Slider::new(&mut sim.gravity_strength, 0.0..=5.0).text("gravity")).changed();
            changes.simulation |=
                ui.add(egui::Slider::new(&mut sim.rate_hz, 1.0..=240.0).logarithmic(true).text("rate (Hz)")).changed();
            changes.simulation |= ui.checkbox(&mut sim.interpolate, "interpolate between steps").changed();
            ui.label(egui::RichText::new("Wind").strong());
            let wind = &mut sim.wind;
            changes.simulation |=
                ui.add(egui::Slider::new(&mut wind.strength, 0.0..=5.0).text("strength (W)")).changed();
            ui.horizontal(|ui| {
                ui.label("direction");
                for (axis, value) in
                    [("x ", &mut wind.direction.x), ("y ", &mut wind.direction.y), ("z ", &mut wind.direction.z)]
                {
                    changes.simulation |=
                        ui.add(egui::DragValue::new(value).speed(0.02).range(-1.0..=1.0).prefix(axis)).changed();
                }
            });
            if wind.direction.length_squared() == 0.0 {
                wind.direction = glam::Vec3::X;
            }
            changes.simulation |= ui.add(egui::Slider::new(&mut wind.gust_strength, 0.0..=1.0).text("gusts")).changed();
            changes.simulation |= ui
                .add(egui::Slider::new(&mut wind.gust_scale, 0.05..=4.0).logarithmic(true).text("gust size"))
                .changed();
            changes.simulation |=
                ui.add(egui::Slider::new(&mut wind.gust_speed, 0.0..=8.0).text("gust speed")).changed();
            changes.simulation |= ui.add(egui::Slider::new(&mut wind.jitter, 0.0..=1.0).text("shake")).changed();
            ui.label(egui::RichText::new("Touch").strong());
            changes.simulation |=
                ui.add(egui::Slider::new(&mut sim.touch.strength, 0.0..=20.0).text("strength")).changed();
            changes.simulation |=
                ui.add(egui::Slider::new(&mut sim.touch.release_secs, 0.0..=3.0).text("release (s)")).changed();
            ui.add(egui::Slider::new(&mut settings.brush_per_radius, 0.02..=1.0).logarithmic(true).text("brush ([ ])"));
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
                ui.radio_value(&mut draw.unified, false, "separated");
            });
            ui.checkbox(&mut settings.overlay, "overlay (O)");
        });
        section(ui, "Capture", true, |ui| {
            requests.screenshot |= ui.button("Screenshot (Ctrl+P)").clicked();
            if !status.is_empty() {
                ui.weak(status);
            }
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

fn section(ui: &mut egui::Ui, title: &str, open: bool, contents: impl FnOnce(&mut egui::Ui)) {
    egui::CollapsingHeader::new(egui::RichText::new(title).strong()).default_open(open).show(ui, contents);
}
