//! What the page's JavaScript calls: start on a canvas, one call per animation frame, and one per
//! control and pointer event. Every failure comes back as a message string (a rejected promise
//! or a thrown error the page shows); the app keeps its previous state.

use glam::Vec2;
use wasm_bindgen::prelude::*;
use web_time::Instant;

use crate::gpu::{CanvasGpu, Skipped};
use crate::model::{Model, SceneChoice};
use crate::presets;
use crate::tools::Tool;

fn message(error: impl std::fmt::Display) -> JsValue {
    JsValue::from_str(&error.to_string())
}

/// `text` as a JSON string literal.
fn json_string(text: &str) -> String {
    let mut out = String::with_capacity(text.len() + 2);
    out.push('"');
    for c in text.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            c if (c as u32) < 0x20 => out.push_str(&format!("\\u{:04x}", c as u32)),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// Exponential moving average, so the numbers on the page are readable.
fn smooth(previous: f64, sample: f64) -> f64 {
    if previous == 0.0 { sample } else { previous * 0.9 + sample * 0.1 }
}

/// Pelt on one canvas.
#[wasm_bindgen]
#[derive(Debug)]
pub struct PeltApp {
    model: Model,
    gpu: CanvasGpu,
    preset_name: String,
    last_frame_ms: Option<f64>,
    frame_ms: f64,
    sim_ms: f64,
    texture_ms: f64,
    structure_ms: f64,
    frames_drawn: u64,
    frames_skipped: u64,
    /// The CSS size of the canvas, for pointer rays.
    css_size: Vec2,
}

#[wasm_bindgen]
impl PeltApp {
    /// Opens WebGPU on `canvas` and shows `scene` (`"bunny"`, `"tryon"`, `"fox"` or `"herd"`) with the shipped
    /// preset `preset`.
    ///
    /// # Errors
    /// A message string: no WebGPU, an unusable adapter, an unknown scene or preset.
    pub async fn start(canvas: web_sys::HtmlCanvasElement, scene: String, preset: String) -> Result<PeltApp, JsValue> {
        let choice = SceneChoice::from_name(&scene).ok_or_else(|| message(format!("no scene is called {scene:?}")))?;
        let aspect = canvas.width().max(1) as f32 / canvas.height().max(1) as f32;
        let started = Instant::now();
        let model = Model::new(choice, presets::shipped(&preset).map_err(message)?, aspect).map_err(message)?;
        let structure_ms = started.elapsed().as_secs_f64() * 1e3;
        let started = Instant::now();
        let made = presets::web_textures(&model.preset).map_err(message)?;
        let texture_ms = started.elapsed().as_secs_f64() * 1e3;
        let gpu = CanvasGpu::open(canvas, &model, &made.textures, made.tile_scale).await.map_err(message)?;
        Ok(Self {
            model,
            gpu,
            preset_name: preset,
            last_frame_ms: None,
            frame_ms: 0.0,
            sim_ms: 0.0,
            texture_ms,
            structure_ms,
            frames_drawn: 0,
            frames_skipped: 0,
            css_size: Vec2::ONE,
        })
    }

    /// One animation frame at `now_ms` (the `requestAnimationFrame` time) into a canvas of
    /// `width_px x height_px` device pixels and `css_width x css_height` CSS pixels. Returns
    /// whether a frame was drawn (not for a zero-size canvas or when the canvas gives none).
    ///
    /// # Errors
    /// A message when the device is lost (start again) or the renderer fails.
    pub fn frame(
        &mut self,
        now_ms: f64,
        width_px: u32,
        height_px: u32,
        css_width: f32,
        css_height: f32,
    ) -> Result<bool, JsValue> {
        if let Some(lost) = self.gpu.lost() {
            return Err(message(format!("the GPU device was lost ({lost})")));
        }
        let frame_secs = self.last_frame_ms.map_or(0.0, |last| (now_ms - last) / 1e3);
        if self.last_frame_ms.is_some() {
            self.frame_ms = smooth(self.frame_ms, frame_secs * 1e3);
        }
        self.last_frame_ms = Some(now_ms);
        self.css_size = Vec2::new(css_width, css_height);
        let started = Instant::now();
        self.gpu.advance(&mut self.model, frame_secs).map_err(message)?;
        self.sim_ms = smooth(self.sim_ms, started.elapsed().as_secs_f64() * 1e3);
        let drawn = match self.gpu.draw(&self.model, width_px, height_px).map_err(message)? {
            Ok(()) => true,
            Err(Skipped::ZeroSize | Skipped::NoFrame) => false,
        };
        if drawn {
            self.frames_drawn += 1;
        } else {
            self.frames_skipped += 1;
        }
        match self.gpu.take_error() {
            Some(error) => Err(message(format!("GPU error: {error}"))),
            None => Ok(drawn),
        }
    }

    /// Shows `"bunny"`, `"tryon"`, `"fox"` or `"herd"`. A shipped preset made for another mesh gives way:
    /// the Fox takes `fox_groomed`, the others `default` after a Fox preset.
    ///
    /// # Errors
    /// A message; the scene stays.
    pub fn set_scene(&mut self, name: &str) -> Result<(), JsValue> {
        let choice = SceneChoice::from_name(name).ok_or_else(|| message(format!("no scene is called {name:?}")))?;
        let shipped = presets::SHIPPED.iter().any(|(n, _)| *n == self.preset_name);
        let made_for = presets::made_for(&self.preset_name);
        let swap = match choice {
            SceneChoice::Fox if shipped && made_for != Some("fox") => Some("fox_groomed"),
            _ if made_for.is_some_and(|scene| scene != name) => Some("default"),
            _ => None,
        };
        match swap {
            Some(preset) => self.switch(choice, preset),
            None => {
                let started = Instant::now();
                self.model.set_scene(choice, self.aspect()).map_err(message)?;
                self.structure_ms = started.elapsed().as_secs_f64() * 1e3;
                self.gpu.set_structure(&self.model).map_err(message)
            }
        }
    }

    /// Uses the shipped preset `name` (fur length and colour come from it); one made for a mesh
    /// (the Fox's) shows that mesh.
    ///
    /// # Errors
    /// A message; the preset stays.
    pub fn set_preset(&mut self, name: &str) -> Result<(), JsValue> {
        if let Some(scene) = presets::made_for(name).and_then(SceneChoice::from_name)
            && scene != self.model.scene
        {
            return self.switch(scene, name);
        }
        let preset = presets::shipped(name).map_err(message)?;
        self.use_preset(preset)?;
        name.clone_into(&mut self.preset_name);
        Ok(())
    }

    /// Shows `scene` with the shipped preset `name`.
    fn switch(&mut self, scene: SceneChoice, name: &str) -> Result<(), JsValue> {
        let preset = presets::shipped(name).map_err(message)?;
        // Textures first: a preset whose textures fail leaves everything as it was.
        let started = Instant::now();
        let made = presets::web_textures(&preset).map_err(message)?;
        let texture_ms = started.elapsed().as_secs_f64() * 1e3;
        let started = Instant::now();
        self.model.set_scene_and_preset(scene, preset, self.aspect()).map_err(message)?;
        self.structure_ms = started.elapsed().as_secs_f64() * 1e3;
        self.texture_ms = texture_ms;
        name.clone_into(&mut self.preset_name);
        self.gpu.set_structure(&self.model).map_err(message)?;
        self.gpu.set_textures(&self.model, &made.textures, made.tile_scale).map_err(message)
    }

    /// Uses a preset file the user picked (`text`, named `file_name` in messages).
    ///
    /// # Errors
    /// A message naming the file and the key; the preset stays.
    pub fn load_preset_text(&mut self, text: &str, file_name: &str) -> Result<(), JsValue> {
        let preset = presets::parse(text, file_name).map_err(message)?;
        self.use_preset(preset)?;
        file_name.clone_into(&mut self.preset_name);
        Ok(())
    }

    fn use_preset(&mut self, preset: pelt_core::Preset) -> Result<(), JsValue> {
        // Textures first: a preset whose textures fail leaves everything as it was.
        let started = Instant::now();
        let made = presets::web_textures(&preset).map_err(message)?;
        let texture_ms = started.elapsed().as_secs_f64() * 1e3;
        self.model.set_preset(preset).map_err(message)?;
        self.texture_ms = texture_ms;
        self.gpu.set_structure(&self.model).map_err(message)?;
        self.gpu.set_textures(&self.model, &made.textures, made.tile_scale).map_err(message)
    }

    /// Fur length as a fraction of the mesh's bounding radius.
    ///
    /// # Errors
    /// A message for a length outside `(0, 2]`; the length stays.
    pub fn set_length(&mut self, length: f32) -> Result<(), JsValue> {
        self.model.set_length(length).map_err(message)?;
        self.gpu.set_structure(&self.model).map_err(message)
    }

    /// One colour (`#rrggbb`) for every strand; remakes the textures.
    ///
    /// # Errors
    /// A message for text that is not a colour.
    pub fn set_colour(&mut self, hex: &str) -> Result<(), JsValue> {
        let before = self.model.preset.colour.clone();
        self.model.set_colour(hex).map_err(message)?;
        let started = Instant::now();
        match presets::web_textures(&self.model.preset) {
            Ok(made) => {
                self.texture_ms = started.elapsed().as_secs_f64() * 1e3;
                self.gpu.set_textures(&self.model, &made.textures, made.tile_scale).map_err(message)
            }
            Err(error) => {
                self.model.preset.colour = before;
                Err(message(error))
            }
        }
    }

    /// Wind of `strength` toward `direction_deg` in the ground plane (0 = +X, 90 = +Z).
    ///
    /// # Errors
    /// A message for a negative or non-finite value; the wind stays.
    pub fn set_wind(&mut self, strength: f32, direction_deg: f32) -> Result<(), JsValue> {
        self.model.set_wind(strength, direction_deg).map_err(message)
    }

    /// A pointer went down at CSS pixel `(x, y)` of the canvas: true when it takes the tool on
    /// the fur, false when it missed (the page orbits with it).
    pub fn pointer_down(&mut self, pointer_id: i32, x: f32, y: f32) -> bool {
        self.model.pointer_down(pointer_id, Vec2::new(x, y), self.css_size)
    }

    /// A pointer moved (pressed, or hovering with the finger); true when it acts on the fur.
    pub fn pointer_move(&mut self, pointer_id: i32, x: f32, y: f32) -> bool {
        self.model.pointer_move(pointer_id, Vec2::new(x, y), self.css_size)
    }

    /// A pointer went up, was cancelled or left the canvas.
    pub fn pointer_up(&mut self, pointer_id: i32) {
        self.model.pointer_up(pointer_id);
    }

    /// What a pointer landing on the fur does: `"touch"` (pat), `"finger"`, `"grab"` or
    /// `"sponge"`. Every pointer on the fur lets go.
    ///
    /// # Errors
    /// A message for an unknown tool; the tool stays.
    pub fn set_tool(&mut self, name: &str) -> Result<(), JsValue> {
        let tool = Tool::from_name(name).ok_or_else(|| message(format!("no tool is called {name:?}")))?;
        self.model.set_tool(tool);
        Ok(())
    }

    /// Fixes the key light in the world at `azimuth_deg` (about +Y from +Z toward +X) and
    /// `elevation_deg` (above the horizon), as `pelt render --light` does.
    ///
    /// # Errors
    /// A message for a non-finite angle or an elevation outside -90 to 90; the light stays.
    pub fn set_light(&mut self, azimuth_deg: f32, elevation_deg: f32) -> Result<(), JsValue> {
        self.model.light.set(azimuth_deg, elevation_deg).map_err(message)
    }

    /// Turns the key light by a drag of CSS pixels: right turns it, up raises it. A light that
    /// followed the camera stays fixed in the world from then on.
    pub fn drag_light(&mut self, dx: f32, dy: f32) {
        let camera = self.model.orbit.camera();
        self.model.light.drag(Vec2::new(dx, dy), &camera);
    }

    /// Lets the key light follow the camera, as the paper lights its fur.
    pub fn follow_camera_light(&mut self) {
        self.model.light.follow_camera();
    }

    /// The key light's azimuth and elevation in degrees, or nothing while it follows the camera.
    #[must_use]
    pub fn light_angles(&self) -> Vec<f32> {
        self.model.light.angles().map_or_else(Vec::new, |(azimuth, elevation)| vec![azimuth, elevation])
    }

    /// Switches the key light's shadows (the fur's own included) on or off.
    pub fn set_shadows(&mut self, on: bool) {
        self.model.light.shadows = on;
    }

    /// Switches the ground under the meshes on or off.
    pub fn set_ground(&mut self, on: bool) {
        self.model.light.ground = on;
    }

    /// Dries the whole coat at once.
    pub fn dry(&mut self) {
        self.model.dry();
    }

    /// The scene shown (`"bunny"`, `"tryon"`, `"fox"` or `"herd"`), for the page's controls.
    #[must_use]
    pub fn scene(&self) -> String {
        self.model.scene.name().to_owned()
    }

    /// The preset's name (a shipped one's, or the picked file's), for the page's menu.
    #[must_use]
    pub fn preset_name(&self) -> String {
        self.preset_name.clone()
    }

    /// Orbits by a drag of CSS pixels.
    pub fn orbit(&mut self, dx: f32, dy: f32) {
        self.model.orbit.rotate(Vec2::new(dx, dy));
    }

    /// Zooms by `factor` (below 1 comes closer).
    pub fn zoom(&mut self, factor: f32) {
        self.model.zoom(factor);
    }

    /// Frames the scene again.
    pub fn reset_view(&mut self) {
        self.model.frame(self.aspect());
    }

    /// The preset's fur length (a fraction of the mesh's bounding radius), for the page's slider.
    #[must_use]
    pub fn length(&self) -> f32 {
        self.model.preset.length
    }

    /// The preset's strand colour as `#rrggbb`, for the page's colour input.
    #[must_use]
    pub fn colour(&self) -> String {
        let [r, g, b] = self.model.preset.colour.colour.0;
        format!("#{r:02x}{g:02x}{b:02x}")
    }

    /// Figures for the page and the tests, as JSON.
    #[must_use]
    pub fn stats(&self) -> String {
        let structure = &self.model.structure;
        let pointers = self.model.stats();
        format!(
            concat!(
                "{{\"frame_ms\":{:.3},\"sim_ms\":{:.3},\"texture_ms\":{:.1},\"structure_ms\":{:.1},",
                "\"frames_drawn\":{},\"frames_skipped\":{},\"vertices\":{},\"layers\":{},\"tile_px\":{},",
                "\"touches\":{},\"tool\":{},\"fingers\":{},\"grabbing\":{},\"wettest\":{:.3},",
                "\"scene\":{},\"preset\":{},\"adapter\":{},\"walk_secs\":{},\"walk_cycle_secs\":{}}}"
            ),
            self.frame_ms,
            self.sim_ms,
            self.texture_ms,
            self.structure_ms,
            self.frames_drawn,
            self.frames_skipped,
            structure.positions.len(),
            structure.layers,
            presets::WEB_TILE_PX.min(self.model.preset.texture.size),
            pointers.touches,
            json_string(pointers.tool.name()),
            pointers.fingers,
            pointers.grabbing,
            pointers.wettest,
            json_string(self.model.scene.name()),
            json_string(&self.preset_name),
            json_string(&self.gpu.adapter_name),
            // Where the try-on body or the herd is in its walk cycle; null on other scenes.
            self.model.walk_secs().map_or_else(|| "null".to_owned(), |t| format!("{t:.3}")),
            self.model.walk_cycle_secs().map_or_else(|| "null".to_owned(), |t| format!("{t:.3}")),
        )
    }

    fn aspect(&self) -> f32 {
        self.css_size.x.max(1.0) / self.css_size.y.max(1.0)
    }
}

/// Names of the shipped presets, for the page's menu.
#[wasm_bindgen]
#[must_use]
pub fn preset_names() -> Vec<String> {
    presets::SHIPPED.iter().map(|(name, _)| (*name).to_owned()).collect()
}

/// The tile edge the page makes textures at (presets ask for more; said on the page).
#[wasm_bindgen]
#[must_use]
pub fn web_tile_px() -> u32 {
    presets::WEB_TILE_PX
}
