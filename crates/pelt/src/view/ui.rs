//! The viewer's egui side: the side panel and the shortcuts, the 3D view with its camera and
//! touch controls, the brush and the overlay.

use glam::{Vec2, Vec3};
use pelt_core::SeparatedStructure;

use super::camera::OrbitCamera;
use super::model::{Model, TouchDrag};
use super::panel::{self, Changes, Requests};
use crate::format::thousands;

impl Model {
    /// The panel, the 3D view with its overlay, and the shortcuts.
    pub(super) fn ui(&mut self, ui: &mut egui::Ui) -> (Changes, Requests, anyhow::Result<()>) {
        let mut outcome = (Changes::default(), Requests::default());
        let shortcuts = self.shortcuts(ui.ctx());
        outcome.1.frame |= shortcuts.frame;
        outcome.1.screenshot |= shortcuts.screenshot;
        outcome.1.save_preset |= shortcuts.save_preset;
        outcome.1.undo |= shortcuts.undo;
        outcome.1.redo |= shortcuts.redo;
        if !self.panel_hidden {
            egui::Panel::right("settings").resizable(true).default_size(320.0).min_size(260.0).show(ui, |ui| {
                self.show_wetness();
                let placement = super::lights::Placement::of(&self.camera);
                let (changes, requests) =
                    panel::show(ui, &mut self.settings, (&self.mesh_choices, &placement), &self.status);
                outcome.0.merge(changes);
                outcome.1.merge(requests);
            });
        }
        outcome.0.simulation |= shortcuts.simulation;
        let view = egui::CentralPanel::no_frame().show(ui, |ui| self.view_3d(ui));
        (outcome.0, outcome.1, view.inner)
    }

    /// Keys that act anywhere except while typing into a text field.
    fn shortcuts(&mut self, ctx: &egui::Context) -> ShortcutOutcome {
        let mut outcome = ShortcutOutcome::default();
        if ctx.egui_wants_keyboard_input() {
            return outcome;
        }
        let none = egui::Modifiers::NONE;
        let command = egui::Modifiers::COMMAND;
        ctx.input_mut(|input| {
            let settings = &mut self.settings;
            outcome.frame = input.consume_key(none, egui::Key::F);
            if input.consume_key(none, egui::Key::R) {
                self.camera = OrbitCamera::default();
                outcome.frame = true;
            }
            if input.consume_key(none, egui::Key::Space) {
                settings.simulate = !settings.simulate;
                outcome.simulation = true;
            }
            for (key, toggle) in [
                (egui::Key::Num1, &mut settings.draw.skin),
                (egui::Key::Num2, &mut settings.draw.shells),
                (egui::Key::Num3, &mut settings.draw.fins),
                (egui::Key::O, &mut settings.overlay),
            ] {
                if input.consume_key(none, key) {
                    *toggle = !*toggle;
                }
            }
            if input.consume_key(none, egui::Key::W) {
                let wind = &mut settings.preset.simulation.wind;
                if wind.strength > 0.0 {
                    self.wind_strength_on = wind.strength;
                    wind.strength = 0.0;
                } else {
                    wind.strength = self.wind_strength_on;
                }
                outcome.simulation = true;
            }
            if input.consume_key(none, egui::Key::OpenBracket) {
                settings.brush_per_radius = (settings.brush_per_radius / 1.25).max(0.02);
            }
            if input.consume_key(none, egui::Key::CloseBracket) {
                settings.brush_per_radius = (settings.brush_per_radius * 1.25).min(1.0);
            }
            if input.consume_key(none, egui::Key::U) {
                settings.draw.unified = !settings.draw.unified;
            }
            if input.consume_key(none, egui::Key::H) {
                self.panel_hidden = !self.panel_hidden;
            }
            outcome.redo = input.consume_key(command | egui::Modifiers::SHIFT, egui::Key::Z);
            outcome.undo = input.consume_key(command, egui::Key::Z);
            outcome.screenshot = input.consume_key(command, egui::Key::P);
            outcome.save_preset = input.consume_key(command, egui::Key::S);
            self.quit |= input.consume_key(command, egui::Key::Q);
        });
        outcome
    }
}

#[derive(Debug, Default)]
struct ShortcutOutcome {
    frame: bool,
    screenshot: bool,
    save_preset: bool,
    simulation: bool,
    undo: bool,
    redo: bool,
}

impl Model {
    /// The fur image, camera controls and the overlay.
    fn view_3d(&mut self, ui: &mut egui::Ui) -> anyhow::Result<()> {
        let rect = ui.max_rect();
        let pixels_per_point = ui.ctx().pixels_per_point();
        self.viewport_px =
            [rect.width(), rect.height()].map(|points| (points * pixels_per_point).round().max(1.0) as u32);
        // The view itself is copied in under egui's shapes (`Viewport::copy_into`), not painted here.
        self.viewport_origin_px =
            [rect.min.x, rect.min.y].map(|points| (points * pixels_per_point).round().max(0.0) as u32);
        let response = ui.allocate_rect(rect, egui::Sense::click_and_drag());
        let painter = ui.painter_at(rect);

        let size = Vec2::new(rect.width(), rect.height()).max(Vec2::ONE);
        if self.frame_pending {
            self.frame(size.x / size.y);
            self.frame_pending = false;
        }
        let modifiers = ui.input(|input| input.modifiers);
        let delta = response.drag_delta();
        let drag = Vec2::new(delta.x, delta.y);
        let primary = response.dragged_by(egui::PointerButton::Primary);
        let pointer = response.hover_pos().or_else(|| response.interact_pointer_pos());
        let ray = pointer.map(|p| self.camera.ray(Vec2::new(p.x - rect.left(), p.y - rect.top()), size));
        let brush_radius = self.settings.brush_per_radius * self.structure.mesh.bounding_sphere().1;
        // Ctrl+drag moves the key light, except that with the sponge on it dries the fur.
        let lighting = primary && modifiers.ctrl && !self.settings.wet.sponge;
        let hover_hit = ray
            .filter(|_| self.touch.is_none() && !modifiers.alt && !modifiers.shift && !lighting)
            .and_then(|ray| self.stepper.simulation().pick(&self.structure.mesh.triangles, ray.origin, ray.direction));

        let paint = self.settings.paint.on;
        let contact = !paint && self.contact_input(&response, ray, hover_hit.map(|hit| hit.point))?;
        let sponging = !paint && self.settings.wet.sponge && primary && !modifiers.alt && hover_hit.is_some();
        if contact {
            // The ball or the grip holds the pointer: no orbit or touch while it is dragged.
        } else if paint
            && (self.painting || (response.drag_started_by(egui::PointerButton::Primary) && hover_hit.is_some()))
        {
            if (primary || response.drag_started_by(egui::PointerButton::Primary))
                && let Some(ray) = ray
            {
                self.paint_ray(ray.origin, ray.direction)?;
            } else {
                self.paint_end();
            }
        } else if sponging && let Some(hit) = hover_hit {
            // The sponge wets (Ctrl: dries) under the brush while the button is held.
            self.stepper.sponge(hit.point, brush_radius, if modifiers.ctrl { 0.0 } else { 1.0 });
        } else if response.drag_started_by(egui::PointerButton::Primary)
            && let Some(hit) = hover_hit
        {
            self.stepper.simulation_mut().touch_begin(hit.point, brush_radius)?;
            let plane_normal = (self.camera.target - self.camera.eye()).normalize_or(Vec3::NEG_Z);
            self.touch = Some(TouchDrag { hit: hit.point, plane_normal });
        }
        if self.painting || contact {
            // The stroke, the ball or the grip holds the pointer: no orbit.
        } else if let Some(touch) = self.touch {
            if primary && let Some(ray) = ray {
                let along = ray.direction.dot(touch.plane_normal);
                if along.abs() > 1e-6 {
                    let distance = (touch.hit - ray.origin).dot(touch.plane_normal) / along;
                    self.stepper.simulation_mut().touch_drag(ray.origin + ray.direction * distance.max(0.0))?;
                }
            } else {
                self.stepper.simulation_mut().touch_end();
                self.touch = None;
            }
        } else if lighting {
            let following = super::lights::Placement::of(&self.camera).following;
            self.settings.lights.drag_key(drag, following);
        } else if response.dragged_by(egui::PointerButton::Middle) || (primary && modifiers.shift) {
            self.camera.pan(drag, size.y);
        } else if response.dragged_by(egui::PointerButton::Secondary) || (primary && !sponging) {
            self.camera.orbit(drag);
        }
        if response.hovered() {
            let scroll = ui.input(|input| input.smooth_scroll_delta.y);
            if scroll != 0.0 {
                // egui reports about 50 points per wheel notch.
                self.camera.zoom(scroll / 50.0);
            }
        }
        if self.settings.overlay {
            // Ball and grab show their own size; painting, sponging and patting the brush's.
            let mesh_radius = self.structure.mesh.bounding_sphere().1;
            let circle = if paint { None } else { super::contact::tool_radius(&self.settings.contact, mesh_radius) };
            self.brush(&painter, rect, pointer, hover_hit.map(|hit| hit.point), circle.unwrap_or(brush_radius));
            self.overlay(&painter, rect);
        }
        Ok(())
    }

    /// The contact tools' share of the pointer: a press on the fur, the drag and the release
    /// drive the ball or the grab. True while one is dragged.
    fn contact_input(
        &mut self,
        response: &egui::Response,
        ray: Option<super::camera::Ray>,
        hit: Option<Vec3>,
    ) -> anyhow::Result<bool> {
        use super::contact::{PointerEvent, handle};
        let event = if response.drag_started_by(egui::PointerButton::Primary)
            && let Some(hit) = hit
            && self.contact_drag.is_none()
        {
            let view_direction = self.camera.target - self.camera.eye();
            Some(PointerEvent::Press { hit, view_direction })
        } else if self.contact_drag.is_some() {
            match ray {
                Some(ray) if response.dragged_by(egui::PointerButton::Primary) => {
                    Some(PointerEvent::Move { origin: ray.origin, direction: ray.direction })
                }
                _ => Some(PointerEvent::Release),
            }
        } else {
            None
        };
        let Some(event) = event else { return Ok(false) };
        let radius = self.structure.mesh.bounding_sphere().1;
        Ok(handle(self.stepper.simulation_mut(), &self.settings.contact, radius, &mut self.contact_drag, event)?)
    }

    /// The brush under the pointer, sized to `radius` (the touch's, the ball's or the grab's)
    /// at the fur it would touch; while patting, the drag from the hit point.
    fn brush(
        &self,
        painter: &egui::Painter,
        rect: egui::Rect,
        pointer: Option<egui::Pos2>,
        hover: Option<Vec3>,
        radius: f32,
    ) {
        let size = Vec2::new(rect.width(), rect.height()).max(Vec2::ONE);
        let to_screen = |point: Vec3| {
            let ndc = self.camera.clip_from_world(size.x / size.y).project_point3(point);
            egui::pos2(rect.left() + (ndc.x + 1.0) * 0.5 * size.x, rect.top() + (1.0 - ndc.y) * 0.5 * size.y)
        };
        let accent = egui::Color32::from_rgb(255, 190, 90);
        // The simulation's touch, so scripted strokes show as well as the pointer's.
        if let Some(touch) = self.stepper.simulation().touch().filter(|t| t.released_at_secs.is_none()) {
            let centre = to_screen(touch.point);
            let radius_px = touch.radius * self.camera.px_per_world_at(touch.point, size.y);
            painter.circle_stroke(centre, radius_px, egui::Stroke::new(2.0, accent));
            let end = to_screen(touch.drag);
            painter.line_segment([centre, end], egui::Stroke::new(2.0, accent));
            painter.circle_filled(end, 3.0, accent);
        } else if let (Some(pointer), Some(point)) = (pointer, hover) {
            let radius_px = radius * self.camera.px_per_world_at(point, size.y);
            painter.circle_stroke(pointer, radius_px, egui::Stroke::new(1.5, egui::Color32::from_white_alpha(200)));
            painter.circle_filled(pointer, 2.0, egui::Color32::from_white_alpha(200));
        }
    }

    /// Frame time, simulation time, what is drawn and what it costs on the GPU.
    /// The overlay's LOD line: the level, and with view-angle LOD the share of shell triangles
    /// drawn (`LOD 16/16 shells, to 8 facing the eye, 81% of shell triangles`).
    fn lod_line(&self) -> String {
        let level = self.level.describe(self.structure.layers);
        match self.shell_share {
            Some(share) if self.level.facing.is_some() => format!("{level}, {:.0}% of shell triangles", share * 100.0),
            _ => level,
        }
    }

    fn overlay(&self, painter: &egui::Painter, rect: egui::Rect) {
        let draw = self.settings.draw;
        let footprint = if draw.unified {
            self.footprint
        } else {
            SeparatedStructure { layers: self.structure.layers, fin_faces: 2 }.footprint(&self.structure.mesh)
        };
        let mesh = &self.structure.mesh;
        let base_vertices = mesh.vertex_count() as u64;
        let vertices = if draw.shells || draw.fins { footprint.vertices } else { base_vertices * u64::from(draw.skin) };
        let faces = mesh.triangles.len() as u64 * u64::from(draw.skin)
            + footprint.shell_faces * u64::from(draw.shells)
            + footprint.fin_faces * u64::from(draw.fins);
        // The renderers' own counts once built (the separated one also holds uvs and normals per
        // vertex; the unified one a fin strip).
        let renderer_bytes = if draw.unified { self.unified_bytes } else { self.separated_bytes };
        let structure_bytes = renderer_bytes.unwrap_or_else(|| footprint.total_bytes());
        let [frame_secs, sim_secs] = self.shown_times_secs;
        let frame_ms = frame_secs * 1e3;
        let fps = if frame_secs > 0.0 { 1.0 / frame_secs } else { 0.0 };
        let text = format!(
            "frame    {frame_ms:6.2} ms  ({fps:.0} fps)\nsim      {:6.2} ms CPU, bent on the {} ({})\nvertices {:>9}\nfaces    {:>9}\nGPU      {:>9}  {} structure\nmesh     {}  L = {}\nLOD      {}",
            sim_secs * 1e3,
            self.kernel(),
            self.kernel_reason,
            thousands(vertices),
            thousands(faces),
            bytes(structure_bytes),
            if draw.unified { "unified" } else { "separated" },
            self.settings.mesh.label(),
            self.structure.layers,
            if self.no_lod { "off (--no-lod)".to_owned() } else { self.lod_line() },
        );
        let text = match &self.herd {
            Some(herd) => format!("{text}\nherd     {} members, {} in view", herd.len(), self.herd_in_view),
            None => text,
        };
        let galley = painter.layout_no_wrap(text, egui::FontId::monospace(12.0), egui::Color32::from_gray(225));
        let origin = rect.left_top() + egui::vec2(12.0, 12.0);
        painter.rect_filled(
            egui::Rect::from_min_size(origin, galley.size()).expand(6.0),
            4.0,
            egui::Color32::from_black_alpha(150),
        );
        painter.galley(origin, galley, egui::Color32::WHITE);
        let hint = "left-drag: pat  ·  right-drag: orbit  ·  middle or Shift: pan  ·  wheel: zoom  ·  F: frame";
        painter.text(
            rect.center_bottom() - egui::vec2(0.0, 12.0),
            egui::Align2::CENTER_BOTTOM,
            hint,
            egui::FontId::proportional(12.0),
            egui::Color32::from_gray(150),
        );
    }
}

fn bytes(value: u64) -> String {
    let value = value as f64;
    if value >= 1024.0 * 1024.0 {
        format!("{:.2} MiB", value / (1024.0 * 1024.0))
    } else {
        format!("{:.1} KiB", value / 1024.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::view::model::test_model;

    /// One panel pass with `key` pressed.
    fn press(model: &mut Model, key: egui::Key, modifiers: egui::Modifiers) -> (Changes, Requests) {
        let ctx = egui::Context::default();
        let screen = egui::Rect::from_min_size(egui::Pos2::ZERO, egui::vec2(1000.0, 700.0));
        let events = vec![
            egui::Event::ModifiersChanged(modifiers),
            egui::Event::Key { key, physical_key: None, pressed: true, repeat: false, modifiers },
        ];
        let input = egui::RawInput { screen_rect: Some(screen), events, ..egui::RawInput::default() };
        let mut outcome = None;
        let mut output = ctx.run_ui(input, |ui| outcome = Some(model.ui(ui)));
        // No GPU here: the font atlas is not uploaded anywhere.
        output.textures_delta.clear();
        let (changes, requests, result) = outcome.unwrap();
        result.unwrap();
        (changes, requests)
    }

    #[test]
    fn shortcuts_reach_the_app_with_the_panel_shown() {
        let mut model = test_model(&["--builtin", "box"]);
        let none = egui::Modifiers::NONE;
        assert!(press(&mut model, egui::Key::S, egui::Modifiers::COMMAND).1.save_preset);
        assert!(press(&mut model, egui::Key::P, egui::Modifiers::COMMAND).1.screenshot);
        assert!(press(&mut model, egui::Key::F, none).1.frame);
        let (changes, _) = press(&mut model, egui::Key::Space, none);
        assert!(changes.simulation && !model.settings.simulate);
        press(&mut model, egui::Key::U, none);
        assert!(!model.settings.draw.unified);
        let (changes, _) = press(&mut model, egui::Key::W, none);
        assert!(changes.simulation && model.settings.preset.simulation.wind.strength > 0.0);
        press(&mut model, egui::Key::W, none);
        assert_eq!(model.settings.preset.simulation.wind.strength, 0.0);
        let brush = model.settings.brush_per_radius;
        press(&mut model, egui::Key::CloseBracket, none);
        assert!(model.settings.brush_per_radius > brush);
        assert!(press(&mut model, egui::Key::Z, egui::Modifiers::COMMAND).1.undo);
        let redo = press(&mut model, egui::Key::Z, egui::Modifiers::COMMAND | egui::Modifiers::SHIFT).1;
        assert!(redo.redo && !redo.undo);
        press(&mut model, egui::Key::H, none);
        assert!(model.panel_hidden);
        // Plain keys do nothing while they type into a text field; here none is focused.
        press(&mut model, egui::Key::Q, egui::Modifiers::COMMAND);
        assert!(model.quit);
    }

    #[test]
    fn overlay_numbers_read_well() {
        assert_eq!(thousands(0), "0");
        assert_eq!(thousands(5_032), "5,032");
        assert_eq!(thousands(1_234_567), "1,234,567");
        assert_eq!(bytes(2048), "2.0 KiB");
        assert_eq!(bytes(3 * 1024 * 1024), "3.00 MiB");
    }
}
