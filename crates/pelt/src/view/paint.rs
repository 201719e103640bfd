//! Groom painting: the panel's brush section, and the model's strokes on the rest surface under
//! the pointer's posed hit, with undo and redo. Length and direction strokes regrow the fur's
//! rest positions (the simulation takes the reshaped strands in place, `FurStepper::regroom`;
//! the GPU its vertex buffers, never the textures); density, clump and tint
//! rewrite the GPU's per-vertex groom in place (`FurDriver::set_groom`).

use glam::Vec3;
use pelt_core::groom::{Axis, Brush, BrushKind, Falloff, GroomEditor, GroomMap, rest_point};
use pelt_core::{FurStructure, Mesh, Preset};

use super::model::Model;

/// The panel's painting settings.
#[derive(Clone, Debug, PartialEq)]
pub struct PaintSettings {
    /// Left-drag on the fur paints (instead of patting it).
    pub on: bool,
    /// The brush; its radius is the panel's brush size (`[ ]`) times the mesh's radius.
    pub brush: Brush,
    /// Strokes that can be undone and redone (shown on the buttons).
    pub history: (usize, usize),
}

impl Default for PaintSettings {
    fn default() -> Self {
        Self { on: false, brush: Brush { strength: 0.5, ..Brush::default() }, history: (0, 0) }
    }
}

/// Buttons of the groom section pressed this pass.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PaintRequests {
    pub undo: bool,
    pub redo: bool,
}

/// The groom section of the panel.
pub fn section_ui(ui: &mut egui::Ui, paint: &mut PaintSettings, brush_per_radius: &mut f32) -> PaintRequests {
    let mut requests = PaintRequests::default();
    ui.checkbox(&mut paint.on, "paint (left-drag on the fur)");
    let brush = &mut paint.brush;
    egui::ComboBox::from_label("brush").selected_text(brush.kind.name()).show_ui(ui, |ui| {
        for kind in BrushKind::ALL {
            ui.selectable_value(&mut brush.kind, kind, kind.name());
        }
    });
    ui.add(egui::Slider::new(brush_per_radius, 0.02..=1.0).logarithmic(true).text("size ([ ])"));
    ui.add(egui::Slider::new(&mut brush.strength, 0.0..=1.0).text("strength"));
    egui::ComboBox::from_label("falloff").selected_text(brush.falloff.name()).show_ui(ui, |ui| {
        for falloff in Falloff::ALL {
            ui.selectable_value(&mut brush.falloff, falloff, falloff.name());
        }
    });
    match brush.kind {
        BrushKind::Density | BrushKind::Clump => {
            ui.add(egui::Slider::new(&mut brush.value, 0.0..=1.0).text("paint toward"));
        }
        BrushKind::Tint => {
            let mut rgb = brush.colour.to_array();
            ui.horizontal(|ui| {
                ui.label("tint (linear)");
                ui.color_edit_button_rgb(&mut rgb);
            });
            brush.colour = Vec3::from_array(rgb);
        }
        BrushKind::Smooth | BrushKind::Erase => {
            egui::ComboBox::from_label("map").selected_text(brush.map.key()).show_ui(ui, |ui| {
                for map in GroomMap::ALL {
                    ui.selectable_value(&mut brush.map, map, map.key());
                }
            });
        }
        _ => {}
    }
    ui.horizontal(|ui| {
        ui.label("mirror");
        ui.selectable_value(&mut brush.mirror, None, "off");
        for axis in Axis::ALL {
            ui.selectable_value(&mut brush.mirror, Some(axis), axis.name());
        }
    });
    ui.horizontal(|ui| {
        let (undo, redo) = paint.history;
        requests.undo |= ui.add_enabled(undo > 0, egui::Button::new(format!("Undo ({undo})"))).clicked();
        requests.redo |= ui.add_enabled(redo > 0, egui::Button::new(format!("Redo ({redo})"))).clicked();
    });
    ui.label(
        egui::RichText::new("Ctrl+Z / Ctrl+Shift+Z; saved with the preset (Ctrl+S) as <preset>.groom").small().weak(),
    );
    requests
}

/// The editor for `structure`'s groom with the preset's comb.
pub(super) fn editor(structure: &FurStructure, preset: &Preset) -> anyhow::Result<GroomEditor> {
    Ok(GroomEditor::new(&structure.mesh, structure.groom.clone(), preset.direction.comb)?)
}

/// The preset's fur on `mesh` with `editor`'s groom (the panel changed the shape, not the groom).
pub(super) fn regrow(mesh: Mesh, preset: &Preset, editor: &GroomEditor) -> anyhow::Result<FurStructure> {
    preset.validate()?;
    let params = preset.fur_params(&mesh);
    Ok(FurStructure::new_groomed(mesh, &params, Some(editor.groom().clone()))?)
}

impl Model {
    /// The brush as the panel sets it, sized to the mesh.
    fn groom_brush(&self) -> Brush {
        let radius = self.settings.brush_per_radius * self.structure.mesh.bounding_sphere().1;
        Brush { radius, ..self.settings.paint.brush }
    }

    /// Paints where the ray from the pointer meets the posed fur's base (mapped onto the rest
    /// surface); true when it met the mesh. Opens a stroke if none is open.
    pub(super) fn paint_ray(&mut self, origin: Vec3, direction: Vec3) -> anyhow::Result<bool> {
        let Some(hit) = self.stepper.simulation().pick(&self.structure.mesh.triangles, origin, direction) else {
            return Ok(false);
        };
        let Some(point) = rest_point(&self.structure.mesh, hit.triangle, hit.barycentric) else { return Ok(false) };
        let brush = self.groom_brush();
        self.painting = true;
        if let Some(map) = self.groom_editor.stroke_to(&brush, point) {
            self.regroom(&[map])?;
        }
        Ok(true)
    }

    /// Ends the stroke in progress.
    pub(super) fn paint_end(&mut self) {
        self.painting = false;
        self.groom_editor.end_stroke();
        self.settings.paint.history = self.groom_editor.history();
    }

    /// Undoes (or with `redo`, redoes) a stroke.
    pub(super) fn undo_groom(&mut self, redo: bool) -> anyhow::Result<()> {
        self.painting = false;
        let maps = if redo { self.groom_editor.redo() } else { self.groom_editor.undo() };
        if let Some(maps) = maps {
            self.regroom(&maps)?;
        }
        self.settings.paint.history = self.groom_editor.history();
        Ok(())
    }

    /// Brings the structure up to the editor's groom: a length or direction change regrows the
    /// rest positions (and restarts the simulation on them); other maps only replace the groom
    /// the structure carries.
    fn regroom(&mut self, maps: &[GroomMap]) -> anyhow::Result<()> {
        let groom = Some(self.groom_editor.groom().clone()).filter(|g| !g.is_uniform());
        if maps.iter().any(|m| matches!(m, GroomMap::Length | GroomMap::Direction)) {
            let regrown = regrow(self.structure.mesh.clone(), &self.settings.preset, &self.groom_editor)?;
            let strands = self.structure.changed_strands(&regrown);
            self.structure = regrown;
            self.footprint = self.structure.footprint();
            // Only the reshaped strands change in the simulation; it keeps its clip, wind and
            // wetness, and an animated fur goes on playing on the new rest pose.
            self.stepper.regroom(&self.structure, &strands)?;
            self.touch = None;
            self.structure_regrown = true;
        } else {
            self.structure.groom = groom;
            self.groom_attributes_changed = true;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::model::test_model;
    use crate::view::panel::Changes;

    fn length_bits(model: &Model) -> Vec<u32> {
        model.structure.lengths.iter().map(|l| l.to_bits()).collect()
    }

    #[test]
    fn a_stroke_on_the_posed_fox_cuts_the_rest_pose_there_and_undo_restores_it() {
        let fox = concat!(env!("CARGO_MANIFEST_DIR"), "/../../assets/meshes/Fox.glb");
        let mut model = test_model(&[fox]);
        let (time_secs, clip_secs) = model.simulate(0.4).unwrap();
        model.stepper.advance_with_clip_at(time_secs, clip_secs).unwrap();
        let posed = model.stepper.moved_pose().expect("the walk poses the fox").positions.clone();
        let before = length_bits(&model);
        // Aim at a posed triangle's centre from outside, along its normal.
        let t = model.structure.mesh.triangles.len() / 3;
        let corners = model.structure.mesh.triangles[t].map(|j| posed[j as usize]);
        let centre = (corners[0] + corners[1] + corners[2]) / 3.0;
        let normal = (corners[1] - corners[0]).cross(corners[2] - corners[0]).normalize();
        let origin = centre + normal * 0.01;
        model.settings.paint.on = true;
        model.settings.paint.brush =
            Brush { kind: BrushKind::Cut, strength: 1.0, falloff: Falloff::Constant, ..Brush::default() };
        model.settings.brush_per_radius = 0.12;
        assert!(model.paint_ray(origin, -normal).unwrap());
        model.paint_end();
        assert!(model.structure_regrown && !model.textures_stale, "new vertex buffers, no new textures");
        let rest = &model.structure.mesh.positions;
        let rest_centre = model.structure.mesh.triangles[t].map(|j| rest[j as usize]).iter().sum::<Vec3>() / 3.0;
        let radius = 0.12 * model.structure.mesh.bounding_sphere().1;
        let mut cut = 0;
        for (j, p) in rest.iter().enumerate() {
            let d = p.distance(rest_centre);
            if d < radius * 0.9 {
                assert_eq!(model.structure.lengths[j], 0.0, "vertex {j} under the brush at the rest pose");
                cut += 1;
            } else if d > radius * 1.1 {
                assert_eq!(model.structure.lengths[j].to_bits(), before[j], "vertex {j} away from the brush");
            }
        }
        assert!(cut >= 3, "{cut} vertices cut");
        assert_eq!(model.settings.paint.history, (1, 0));
        model.undo_groom(false).unwrap();
        assert_eq!(length_bits(&model), before);
        model.undo_groom(true).unwrap();
        assert_ne!(length_bits(&model), before);
    }

    #[test]
    fn a_saved_groom_reloads_to_the_same_bytes() {
        let folder = std::env::temp_dir().join(format!("pelt-paint-save-{}", std::process::id()));
        std::fs::create_dir_all(&folder).unwrap();
        let mut model = test_model(&["--builtin", "bunny"]);
        let mesh = model.structure.mesh.clone();
        let radius = mesh.bounding_sphere().1;
        for (kind, at) in [(BrushKind::Cut, 10), (BrushKind::Tint, 200), (BrushKind::Comb, 400)] {
            let brush = Brush { kind, radius: 0.2 * radius, colour: Vec3::new(0.8, 0.3, 0.1), ..Brush::default() };
            model.groom_editor.begin_stroke();
            for step in 0..4 {
                model.groom_editor.stroke_to(&brush, mesh.positions[at] + Vec3::X * (0.1 * radius * step as f32));
            }
            model.groom_editor.end_stroke();
        }
        let painted = model.groom_editor.groom().to_file_bytes(&mesh).unwrap();
        let path = folder.join("painted.toml");
        model.settings.preset_path = path.display().to_string();
        model.save_preset();
        assert!(model.status.contains("with its groom"), "{}", model.status);
        let groom_file = folder.join("painted.groom");
        let written = std::fs::read(&groom_file).unwrap();
        assert_eq!(written, painted);
        let preset = Preset::load(&path).unwrap();
        assert_eq!(preset.groom.file.as_deref(), Some(std::path::Path::new("painted.groom")));
        let loaded = preset.groom(&mesh, "bunny").unwrap().unwrap();
        assert_eq!(loaded.to_file_bytes(&mesh).unwrap(), painted);
        // Loading it into the viewer paints on from the saved groom; saving again writes the same bytes.
        let changes = model.load_preset();
        assert!(changes.groom);
        model.apply(Changes { ..changes }).unwrap();
        assert_eq!(model.groom_editor.groom().to_file_bytes(&mesh).unwrap(), painted);
        assert_eq!(model.settings.paint.history, (0, 0));
        model.save_preset();
        assert_eq!(std::fs::read(&groom_file).unwrap(), written);
        std::fs::remove_dir_all(&folder).unwrap();
    }
}
